//! Property tests of the case loader on hostile input (issue 5, "Bad input"). Every field of
//! every shipped case (`cases/*.toml`) and of the seeds in `tests/data/case_fuzz/` (which use
//! the fields no shipped case does) is replaced by zero, negative, NaN, infinite, huge, tiny,
//! arbitrary and mistyped values, deleted, or joined by an unknown field; vectors get the wrong
//! length; a `--set` override must do what the same edit of the file does; arbitrary text and
//! bytes are read as a case file.
//!
//! Asserted (`check.rs`): no input panics; a rejected input's message starts with the file's
//! name, names the field (`names_field`) and gives a fix; what must fail fails, naming the
//! field's full dotted path (NaN, infinity or a string in a number, a missing required field,
//! an unknown field, a vector of the wrong length); what must pass passes; an accepted case
//! builds a sane scenario (`check_sane`).
//!
//! Since issue 64 the loader also refuses what a run could not step (f32 overflow and underflow
//! of the derived quantities, intervals at both extremes, names that are paths), and a sample
//! of accepted edits runs the solver a few steps (`accepted_edits_run_a_few_steps`, on the
//! test adapter: lavapipe in CI); the rest is CPU only. Each property prints how many inputs
//! it tried. CI runs the `CASES_*` below; `PROPTEST_CASES=100000 cargo test --release --test
//! case_fuzz -- --skip accepted_edits` runs the loader longer (every property then tries that
//! many; the solver's sample too, unless skipped), `CASE_FUZZ_SEED=n` repeats a run.

mod check;
mod doc;
mod values;

use proptest::prelude::*;
use proptest::sample::Index;
use proptest::test_runner::TestCaseError;
use toml::Value;

use check::{check, check_sane, expectation, load, run, write, Expect};
use doc::{edit, node_mut, nodes, seeds, tables, vector_len, Node, Seg};
use values::{any_value, apply, change, gentle_change, number, token};

/// Particle budget of the cases built here, instead of the engine's 200 million: an accepted
/// mutation (a ten times larger tank, say) stays small and fast, and larger ones exercise the
/// budget check, which must name `particles.dx_m`. The largest seed (dam_break_3d) has about
/// 304 thousand particles: the budget leaves an edited part of it (an obstacle eight metres
/// long, say) room to be judged by its own checks.
const MAX_PARTICLES: f64 = 700_000.0;

// Inputs per property in CI (`PROPTEST_CASES` overrides them all).
const CASES_FIELDS: u32 = 3000;
const CASES_VECTORS: u32 = 500;
const CASES_DELETE_ADD: u32 = 1000;
const CASES_OVERRIDES: u32 = 500;
const CASES_COMPOUND: u32 = 1000;
const CASES_TEXT: u32 = 3000;
const CASES_EXTREMES: u32 = 1500;
const CASES_NAMES: u32 = 300;
const CASES_SOLVER: u32 = 30;

/// The largest accepted edit `accepted_edits_run_a_few_steps` runs (a few seconds on lavapipe).
const SOLVER_PARTICLES: usize = 25_000;

#[test]
fn every_seed_builds_and_survives_a_round_trip() {
    for seed in seeds() {
        let direct = load(&seed.text, &seed.file, &[]).unwrap();
        let sc = direct.unwrap_or_else(|e| panic!("{e:#}"));
        check_sane(&sc).unwrap_or_else(|e| panic!("{}: {e}", seed.file));
        // What we ship raises no doubts of its own.
        if seed.file.contains("/cases/") {
            assert!(sc.warnings.is_empty(), "{}: {:?}", seed.file, sc.warnings);
        }
        // The same document written by the toml crate (as every mutation below is).
        let text = toml::to_string(&seed.doc).unwrap();
        let again = load(&text, &seed.file, &[]).unwrap().unwrap();
        assert_eq!(sc, again, "{}", seed.file);
    }
}

/// One field of one seed replaced by a hostile number, a mistyped value, a scaled value, or
/// deleted.
#[test]
fn every_field_with_hostile_values() {
    let strategy = (any::<Index>(), any::<Index>(), change());
    run(
        "every_field_with_hostile_values",
        CASES_FIELDS,
        strategy,
        |(s, f, change)| {
            let seed = s.get(seeds());
            let nodes = nodes(&seed.doc);
            let node = f.get(&nodes);
            let new = apply(&change, &node.value);
            let expect = expectation(seed, node, new.as_ref());
            let doc = edit(&seed.doc, &node.segs, new);
            check(seed, &doc, &[], &node.segs, expect, &format!("{change:?}"))
        },
    );
}

/// The time control and what sets the time step, at both extremes of the f64 and f32 ranges
/// (issue 64: `time.cfl = 1e-50`, `sound_speed_coef = 1e40`, `nu_m2_s = 1e40` ran "completed"
/// with no step; a probe interval of 1e-300 s never advanced; one of 1e9 s sampled nothing):
/// refused naming the field, or accepted as a case whose f32 quantities and first time step
/// are sound (`check_sane`).
#[test]
fn time_and_speeds_at_both_extremes() {
    let fields = prop::sample::select(vec![
        "time.end_s",
        "time.output_every_s",
        "time.probe_every_s",
        "time.cfl",
        "physics.sound_speed_coef",
        "physics.sound_speed_m_s",
        "physics.rho0_kg_m3",
        "physics.nu_m2_s",
        "physics.gamma",
        "particles.dx_m",
    ]);
    let extreme = prop::sample::select(vec![
        5e-324,
        1e-300,
        1e-50,
        1e-38,
        1e-30,
        1e-20,
        1e-12,
        5e-8,
        1e-6,
        1e6,
        1e9,
        1e20,
        1e30,
        1e38,
        1e40,
        1e300,
        f64::MAX,
    ]);
    run(
        "time_and_speeds_at_both_extremes",
        CASES_EXTREMES,
        (any::<Index>(), fields, extreme),
        |(s, field, v)| {
            let seed = s.get(seeds());
            let segs: Vec<Seg> = field.split('.').map(|k| Seg::Key(k.into())).collect();
            // A field the seed leaves out is added; the loader may then refuse the pair.
            let doc = edit(&seed.doc, &segs, Some(Value::Float(v)));
            check(
                seed,
                &doc,
                &[],
                &segs,
                Expect::Either,
                &format!("{field} = {v:e}"),
            )
        },
    );
}

/// Names are file and folder names (`out/<name>`, `probes/<name>.csv`): "..", ".", paths and
/// names too long for a file system are refused naming the field (issue 64: a case named ".."
/// ran into the working directory and deleted the user's files there).
#[test]
fn names_that_are_paths_are_refused() {
    let bad = prop::sample::select(vec![
        "..".to_string(),
        ".".to_string(),
        " .. ".to_string(),
        "../../etc".to_string(),
        "a/b".to_string(),
        "a\\b".to_string(),
        "/tmp/x".to_string(),
        "x\u{0}y".to_string(),
        "".to_string(),
        "n".repeat(300),
    ]);
    run(
        "names_that_are_paths_are_refused",
        CASES_NAMES,
        (any::<Index>(), any::<Index>(), bad),
        |(s, f, name)| {
            let seed = s.get(seeds());
            let named: Vec<Node> = nodes(&seed.doc)
                .into_iter()
                .filter(|n| {
                    let part = n.path.split('[').next().unwrap_or_default();
                    n.path == "name"
                        || (n.path.ends_with("].name") && ["probe", "body"].contains(&part))
                })
                .collect();
            let node = f.get(&named);
            let doc = edit(&seed.doc, &node.segs, Some(Value::String(name)));
            check(
                seed,
                &doc,
                &[],
                &node.segs,
                Expect::Reject,
                "a name that is a path",
            )
        },
    );
}

/// The solver on a sample of accepted edits (issue 64: the fuzzing ran the loader only, and
/// cases it accepted made runs panic, hang or "complete" with no step): a few steps of each, its
/// probes sampled and its particles read back. An edit may make a run that stops (unstable,
/// too large for the adapter), with an error; none may panic. Small cases only (at most
/// `SOLVER_PARTICLES` particles), on the test adapter (lavapipe in CI).
#[test]
fn accepted_edits_run_a_few_steps() {
    let strategy = (any::<Index>(), any::<Index>(), gentle_change());
    let ran = std::cell::Cell::new(0usize);
    run(
        "accepted_edits_run_a_few_steps",
        CASES_SOLVER,
        strategy,
        |(s, f, change)| {
            let seed = s.get(seeds());
            let nodes = nodes(&seed.doc);
            let node = f.get(&nodes);
            let doc = edit(&seed.doc, &node.segs, apply(&change, &node.value));
            let Some(text) = write(&doc) else {
                return Ok(());
            };
            let Ok(sc) = load(&text, &seed.file, &[]).map_err(TestCaseError::fail)? else {
                return Ok(());
            };
            if sc.particles.len() > SOLVER_PARTICLES {
                return Ok(());
            }
            ran.set(ran.get() + 1);
            let what = format!("{change:?} of {} in {}", node.path, seed.file);
            let steps = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                let mut solver = wgsph::sph::Solver::new(crate::common::gpu(), &sc)?;
                solver.run_steps(3)?;
                solver.sample_probes()?;
                solver.read_particles()?;
                anyhow::Ok(solver.steps())
            }));
            match steps {
                Err(_) => Err(TestCaseError::fail(format!("the solver panicked: {what}"))),
                // Three steps taken, or an error that says why not.
                Ok(Ok(n)) => {
                    prop_assert_eq!(n, 3, "{}", what);
                    Ok(())
                }
                Ok(Err(e)) => {
                    prop_assert!(!format!("{e:#}").is_empty(), "{}", what);
                    Ok(())
                }
            }
        },
    );
    eprintln!(
        "case_fuzz accepted_edits_run_a_few_steps: {} runs",
        ran.get()
    );
    assert!(ran.get() > 0, "no accepted edit was small enough to run");
}

/// Vector fields with the wrong number of components (of any values) must be refused naming
/// the field; with the right number of finite numbers they may pass.
#[test]
fn vectors_of_every_length() {
    let strategy = (
        any::<Index>(),
        any::<Index>(),
        prop::collection::vec(number(), 0..7),
    );
    run(
        "vectors_of_every_length",
        CASES_VECTORS,
        strategy,
        |(s, f, items)| {
            let seed = s.get(seeds());
            let vectors: Vec<Node> = nodes(&seed.doc)
                .into_iter()
                .filter(|n| n.value.is_array() && vector_len(&n.path, seed.dim).is_some())
                .collect();
            let node = f.get(&vectors);
            let new = Value::Array(items);
            let expect = expectation(seed, node, Some(&new));
            let doc = edit(&seed.doc, &node.segs, Some(new));
            check(seed, &doc, &[], &node.segs, expect, "a vector")
        },
    );
}

/// Deleting a field (required ones must be named as missing) and adding an unknown one to any
/// table (must be refused, naming it).
#[test]
fn deleted_and_unknown_fields() {
    let strategy = (any::<Index>(), any::<Index>(), any::<bool>(), any_value());
    run(
        "deleted_and_unknown_fields",
        CASES_DELETE_ADD,
        strategy,
        |(s, f, delete, value)| {
            let seed = s.get(seeds());
            if delete {
                let nodes = nodes(&seed.doc);
                let node = f.get(&nodes);
                let expect = expectation(seed, node, None);
                let doc = edit(&seed.doc, &node.segs, None);
                check(seed, &doc, &[], &node.segs, expect, "deleted")
            } else {
                let mut segs = f.get(&tables(&seed.doc)).clone();
                segs.push(Seg::Key("zz_unknown".into()));
                let mut root = Value::Table(seed.doc.clone());
                let (last, parent) = segs.split_last().unwrap();
                if let (Seg::Key(k), Some(t)) = (last, node_mut(&mut root, parent).as_table_mut()) {
                    t.insert(k.clone(), value);
                }
                let doc = root.as_table().unwrap().clone();
                check(seed, &doc, &[], &segs, Expect::Reject, "an unknown field")
            }
        },
    );
}

/// `--set KEY=VALUE` must give what the same edit of the file gives: the same scenario, or an
/// error about the same field.
#[test]
fn overrides_agree_with_editing_the_file() {
    let strategy = (any::<Index>(), any::<Index>(), any_value());
    run(
        "overrides_agree_with_editing_the_file",
        CASES_OVERRIDES,
        strategy,
        |(s, f, value)| {
            let seed = s.get(seeds());
            // --set addresses fields, not vector components.
            let fields: Vec<Node> = nodes(&seed.doc)
                .into_iter()
                .filter(|n| matches!(n.segs.last(), Some(Seg::Key(_))))
                .collect();
            let node = f.get(&fields);
            let doc = edit(&seed.doc, &node.segs, Some(value.clone()));
            let Some(text) = write(&doc) else {
                return Ok(());
            };
            let arg = format!("{}={value}", node.path);
            let edited = load(&text, &seed.file, &[]).map_err(TestCaseError::fail)?;
            let set = load(&seed.text, &seed.file, std::slice::from_ref(&arg))
                .map_err(TestCaseError::fail)?;
            match (&edited, &set) {
                (Ok(a), Ok(b)) => prop_assert_eq!(a, b, "--set {}", arg),
                (Err(a), Err(b)) => {
                    prop_assert_eq!(a.field(), b.field(), "--set {}: {:#} / {:#}", arg, a, b);
                    let msg = format!("{b:#}");
                    prop_assert!(
                        msg.starts_with(&seed.file) && msg.contains("fix: "),
                        "{}",
                        msg
                    );
                }
                _ => prop_assert!(
                    false,
                    "--set {} gives {:?}, editing the file gives {:?}",
                    arg,
                    set.as_ref()
                        .map(|_| "a scenario")
                        .map_err(|e| format!("{e:#}")),
                    edited
                        .as_ref()
                        .map(|_| "a scenario")
                        .map_err(|e| format!("{e:#}"))
                ),
            }
            Ok(())
        },
    );
}

/// Several changes at once, anywhere, plus `--set` arguments with arbitrary keys: nothing
/// panics, a refusal names the file and gives a fix, an acceptance is sane.
#[test]
fn compound_changes_and_arbitrary_overrides() {
    let key = prop_oneof![
        "[a-z_]{1,8}(\\.[a-z_0-9]{1,8}){0,3}",
        "(tank|body|probe|fluid_block|obstacle|particles|time)([.\\[][0-9]{1,2}\\]?){0,3}(\\.[a-z_]{1,6}){0,2}",
        ".{0,16}",
        // Deep keys: every part becomes a table.
        (1..300usize).prop_map(|n| vec!["tank"; n].join(".")),
    ];
    let set = (key, any_value()).prop_map(|(k, v)| format!("{k}={v}"));
    let strategy = (
        any::<Index>(),
        prop::collection::vec((any::<Index>(), gentle_change()), 1..5),
        // Mostly none: a random key is an unknown field, refused before the builder.
        prop_oneof![3 => Just(Vec::new()), 1 => prop::collection::vec(set, 1..3)],
    );
    run(
        "compound_changes_and_arbitrary_overrides",
        CASES_COMPOUND,
        strategy,
        |(s, changes, sets)| {
            let seed = s.get(seeds());
            let mut doc = seed.doc.clone();
            let mut last = Vec::new();
            for (f, change) in &changes {
                let nodes = nodes(&doc);
                if nodes.is_empty() {
                    break;
                }
                let node = f.get(&nodes);
                doc = edit(&doc, &node.segs, apply(change, &node.value));
                last = node.segs.clone();
            }
            let Some(text) = write(&doc) else {
                return Ok(());
            };
            match load(&text, &seed.file, &sets).map_err(TestCaseError::fail)? {
                Ok(sc) => check_sane(&sc).map_err(|e| {
                    TestCaseError::fail(format!("unsound: {e}: --set {sets:?} {last:?}\n{text}"))
                }),
                Err(e) => {
                    let msg = format!("{e:#}");
                    prop_assert!(
                        msg.starts_with(&seed.file) && msg.contains("fix: "),
                        "{}\n--set {:?}\n{}",
                        msg,
                        sets,
                        text
                    );
                    Ok(())
                }
            }
        },
    );
}

/// Arbitrary text and bytes as a case file: no panic, and an error naming the file with a fix.
#[test]
fn arbitrary_text() {
    let text = prop_oneof![
        any::<String>(),
        prop::collection::vec(any::<u8>(), 0..400)
            .prop_map(|b| String::from_utf8_lossy(&b).into_owned()),
        prop::collection::vec(token(), 0..80).prop_map(|t| t.concat()),
        // Deep nesting (the parser has a recursion limit; the loader must not recurse more).
        (
            prop::sample::select(vec![("[", "]"), ("{ a = ", "}"), ("[{a=[", "]}]")]),
            0..3000usize
        )
            .prop_map(|((open, close), n)| format!(
                "dimension = {}{}\n",
                open.repeat(n),
                close.repeat(n)
            )),
        // A seed with a stray token inserted.
        (any::<Index>(), any::<Index>(), token()).prop_map(|(s, at, t)| {
            let text = &s.get(seeds()).text;
            let mut cut = at.index(text.len() + 1);
            while !text.is_char_boundary(cut) {
                cut -= 1;
            }
            format!("{}{t}{}", &text[..cut], &text[cut..])
        }),
    ];
    run("arbitrary_text", CASES_TEXT, text, |text| {
        let file = "fuzz/arbitrary.toml";
        match load(&text, file, &[]).map_err(TestCaseError::fail)? {
            Ok(sc) => check_sane(&sc).map_err(TestCaseError::fail),
            Err(e) => {
                let msg = format!("{e:#}");
                prop_assert!(
                    msg.starts_with(file) && msg.contains("fix: "),
                    "{}\n{:?}",
                    msg,
                    text
                );
                Ok(())
            }
        }
    });
}

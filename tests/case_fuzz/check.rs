//! Loading an input (panics caught), what it must give, the checks of a refusal and of an
//! accepted scenario, and the runner that counts the inputs.

use std::cell::Cell;
use std::panic::{catch_unwind, AssertUnwindSafe};

use proptest::strategy::Strategy;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};
use toml::{Table, Value};
use wgsph::case::{load_str_limited, CaseError};
use wgsph::grid::Grid;
use wgsph::layout::Params;
use wgsph::scenario::{Kind, Motion, RepulsiveForm, Scenario};

use super::doc::{generic, last_key, path_of, required, vector_len, Node, Seed, Seg};
use super::values::{finite_number, is_number};
use super::MAX_PARTICLES;

// What the loads of the current property gave: (accepted, refused, edits that the toml crate
// could not write, so never loaded). Each property runs on its own test thread.
thread_local! {
    static TALLY: Cell<(usize, usize, usize)> = const { Cell::new((0, 0, 0)) };
}

pub(crate) fn tally(accepted: usize, refused: usize, unwritable: usize) {
    TALLY.with(|t| {
        let (a, r, u) = t.get();
        t.set((a + accepted, r + refused, u + unwritable));
    });
}

/// `doc` as TOML text; `None` (counted) when the toml crate cannot write it (a number in an
/// array of tables, say): such a document is no file a user could have.
pub(crate) fn write(doc: &Table) -> Option<String> {
    let text = toml::to_string(doc).ok();
    if text.is_none() {
        tally(0, 0, 1);
    }
    text
}

/// Loads `text` as the case file `file`; a panic becomes an error naming the input.
pub(crate) fn load(
    text: &str,
    file: &str,
    sets: &[String],
) -> Result<Result<Scenario, CaseError>, String> {
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        load_str_limited(text, file, sets, MAX_PARTICLES)
    }));
    if let Ok(r) = &outcome {
        tally(r.is_ok() as usize, r.is_err() as usize, 0);
    }
    outcome.map_err(|p| {
        let why = p
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| p.downcast_ref::<&str>().copied())
            .unwrap_or("?");
        format!("the loader panicked ({why}) on {file} with --set {sets:?}:\n{text}")
    })
}

/// What an input must give.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Expect {
    /// An error naming the field's full dotted path.
    Reject,
    /// A scenario.
    Accept,
    /// Either; an error must name the field (`names_field`).
    Either,
}

/// A rejected input's message names the field at `segs`: its dotted path, its key, or the
/// part of the geometry it belongs to (`tank`, `body[1]`, `body[1].motion`: "the tank leaves
/// the domain"). Not the settings tables `particles`, `physics`, `time` and `walls`, whose
/// fields are independent of each other: an error there must name the field.
pub(crate) fn names_field(msg: &str, segs: &[Seg]) -> bool {
    let key = last_key(segs);
    let part = (1..segs.len())
        .map(|n| path_of(&segs[..n]))
        .filter(|p| !matches!(p.as_str(), "particles" | "physics" | "time" | "walls"))
        .any(|p| msg.contains(&p));
    msg.contains(&path_of(segs)) || (!key.is_empty() && msg.contains(key)) || part
}

/// Loads an edited document and checks the outcome against `expect`.
pub(crate) fn check(
    seed: &Seed,
    doc: &Table,
    sets: &[String],
    segs: &[Seg],
    expect: Expect,
    what: &str,
) -> Result<(), TestCaseError> {
    let Some(text) = write(doc) else {
        return Ok(());
    };
    let outcome = load(&text, &seed.file, sets).map_err(TestCaseError::fail)?;
    let path = path_of(segs);
    let context = || format!("{what} ({path}) in {}:\n{text}", seed.file);
    match outcome {
        Ok(sc) => {
            if expect == Expect::Reject {
                return Err(TestCaseError::fail(format!(
                    "accepted, but must be refused: {}",
                    context()
                )));
            }
            check_sane(&sc).map_err(|e| {
                TestCaseError::fail(format!("accepted an unsound scenario: {e}: {}", context()))
            })
        }
        Err(e) => {
            let msg = format!("{e:#}");
            let fail = |why: &str| Err(TestCaseError::fail(format!("{why}: {msg}\n{}", context())));
            if expect == Expect::Accept {
                return fail("refused, but must be accepted");
            }
            if !msg.starts_with(&seed.file) {
                return fail("the message does not start with the file name");
            }
            if !msg.contains("fix: ") {
                return fail("the message gives no fix");
            }
            if expect == Expect::Reject && !msg.contains(&path) {
                return fail(&format!("the message does not name `{path}`"));
            }
            if !names_field(&msg, segs) {
                return fail(&format!("the message names neither `{path}` nor its key"));
            }
            Ok(())
        }
    }
}

/// An accepted case is one a run can start from: particles (fluid among them) within the
/// budget, every number finite, particles inside the domain, bodies with particles (and a
/// free body with a mass and inertia to divide by), a neighbour grid that fits the domain.
pub(crate) fn check_sane(sc: &Scenario) -> Result<(), String> {
    let ph = &sc.physics;
    let dim = ph.dim as usize;
    let n = sc.particles.len();
    if n == 0 || n as f64 > MAX_PARTICLES {
        return Err(format!("{n} particles"));
    }
    // A case moves fluid (from blocks or inlets) or elastic solids (the oscillating plate has
    // no fluid).
    if sc.count(Kind::Fluid) + sc.count(Kind::Inlet) + sc.count(Kind::Solid) == 0 {
        return Err("no fluid, inlet or free solid particle".into());
    }
    let positive = |name: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(format!("{name} = {v}"))
        }
    };
    positive("dx", ph.dx)?;
    positive("h", ph.h)?;
    positive("rho0", ph.rho0)?;
    positive("c0", ph.c0)?;
    positive("gamma", ph.gamma)?;
    positive("particle mass", ph.particle_mass)?;
    positive("Tait B", ph.tait_b())?;
    positive("end_s", sc.time.end_s)?;
    positive("output_every_s", sc.time.output_every_s)?;
    positive("probe_every_s", sc.time.probe_every_s)?;
    positive("cfl", sc.time.cfl)?;
    // Repulsive walls need their force law; other cases never use it.
    if sc.count(Kind::Repulsive) > 0 {
        let w = &sc.walls;
        positive("repulsive_r0", w.repulsive_r0)?;
        positive("repulsive_beta", w.repulsive_beta)?;
        match w.repulsive_form {
            RepulsiveForm::LennardJones => positive("repulsive_d", w.repulsive_d)?,
            RepulsiveForm::MonaghanKajtar => positive("repulsive_k", w.repulsive_k)?,
        }
    }
    if !ph.gravity.iter().all(|g| g.is_finite()) {
        return Err(format!("gravity {:?}", ph.gravity));
    }
    let (lo, hi) = (sc.domain.min, sc.domain.max);
    if !(0..dim).all(|a| lo[a].is_finite() && hi[a].is_finite() && lo[a] < hi[a]) {
        return Err(format!("domain {lo:?} to {hi:?}"));
    }
    for (i, p) in sc.particles.iter().enumerate() {
        let inside = (0..dim).all(|a| {
            let tol = 1e-9 * (hi[a] - lo[a]);
            lo[a] - tol <= p.pos[a] && p.pos[a] <= hi[a] + tol
        });
        if !(inside && p.vel.iter().all(|v| v.is_finite()) && p.rho.is_finite() && p.rho > 0.0) {
            return Err(format!("particle {i}: {p:?}"));
        }
    }
    for b in &sc.bodies {
        let finite = b.mass.is_finite()
            && b.mass >= 0.0
            && b.center.iter().all(|c| c.is_finite())
            && b.inertia.iter().flatten().all(|c| c.is_finite());
        // The equations of a free body divide by its mass and (in 2D) its zz inertia.
        let used: &[usize] = if dim == 2 { &[2] } else { &[0, 1, 2] };
        let divisible = !matches!(b.motion, Motion::Free { .. })
            || (b.mass > 0.0 && used.iter().all(|&a| b.inertia[a][a] > 0.0));
        if !finite || !divisible || b.particles.is_empty() || b.particles.end > n {
            return Err(format!(
                "body {}: mass {}, centre {:?}, inertia {:?}, particles {:?}",
                b.name, b.mass, b.center, b.inertia, b.particles
            ));
        }
    }
    let grid = Grid::new(&sc.domain, ph.h, ph.dim, n, sc.periodic, ph.cell)
        .map_err(|e| format!("grid: {e}"))?;
    f32_sane(sc, &grid)?;
    // A probe interval the run can step through, in a number of samples it can hold.
    let samples = sc.time.end_s / sc.time.probe_every_s;
    if samples.is_nan() || samples > 1e7 {
        return Err(format!("{samples} probe samples"));
    }
    Ok(())
}

/// What the GPU computes with (issue 64: the loader checked f64 overflow only): the uniform's
/// f32 quantities are finite, and those the kernels divide by or step with are normal numbers.
fn f32_sane(sc: &Scenario, grid: &Grid) -> Result<(), String> {
    let p = Params::from_scenario(sc, grid).map_err(|e| format!("params: {e:#}"))?;
    let positive = [
        ("h", p.h),
        ("kernel_norm", p.kernel_norm),
        ("eta2", p.eta2),
        ("mass", p.mass),
        ("rho0", p.rho0),
        ("tait_b", p.tait_b),
        ("gamma", p.gamma),
        ("c0", p.c0),
        ("cfl", p.cfl),
    ];
    for (name, v) in positive {
        if !(v.is_normal() && v > 0.0) {
            return Err(format!("f32 {name} = {v:e}"));
        }
    }
    let finite = [
        ("alpha", p.alpha),
        ("nu", p.nu),
        ("delta_coef", p.delta_coef),
        ("gravity x", p.gravity[0]),
        ("gravity y", p.gravity[1]),
        ("gravity z", p.gravity[2]),
    ];
    if let Some((name, v)) = finite.iter().find(|(_, v)| !v.is_finite()) {
        return Err(format!("f32 {name} = {v:e}"));
    }
    // The time step the GPU's `timestep` starts from: c0 alone bounds it from above.
    let dt = p.cfl * p.h / p.c0;
    if !(dt.is_normal() && (sc.time.end_s / dt as f64) <= 1e10) {
        return Err(format!(
            "the first time step {dt:e} s to {} s",
            sc.time.end_s
        ));
    }
    Ok(())
}

// ---------------------------------------------------------------- the runner

/// The seed of a property's random inputs: `CASE_FUZZ_SEED` when set (to replay a failure),
/// else a fresh one. Every run prints it, and a failure names it with the command to rerun.
fn seed() -> u64 {
    std::env::var("CASE_FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| {
            let nanos = std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_nanos());
            // Fold the clock with the thread id: the properties start in the same instant.
            let thread = format!("{:?}", std::thread::current().id());
            thread.bytes().fold(nanos as u64, |h, b| {
                (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
            })
        })
}

pub(crate) fn cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Runs `test` on `cases(default)` inputs of `strategy` and prints how many were tried.
pub(crate) fn run<S: Strategy>(
    name: &str,
    default: u32,
    strategy: S,
    test: impl Fn(S::Value) -> Result<(), TestCaseError>,
) {
    let config = Config {
        cases: cases(default),
        // Shrinking rebuilds cases; a bounded search still gives a small input.
        max_shrink_iters: 512,
        failure_persistence: None,
        ..Config::default()
    };
    let seed = seed();
    let mut key = [0u8; 32];
    key[..8].copy_from_slice(&seed.to_le_bytes());
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &key);
    let mut runner = TestRunner::new_with_rng(config.clone(), rng);
    let tried = Cell::new(0usize);
    let started = std::time::Instant::now();
    let result = runner.run(&strategy, |v| {
        tried.set(tried.get() + 1);
        test(v)
    });
    let (accepted, refused, unwritable) = TALLY.with(Cell::take);
    eprintln!(
        "case_fuzz {name} (seed {seed}): {} inputs tried ({} required) in {:.1} s; loads: \
         {accepted} accepted, {refused} refused; {unwritable} edits not writable as TOML",
        tried.get(),
        config.cases,
        started.elapsed().as_secs_f64()
    );
    if let Err(e) = result {
        panic!(
            "{name}: {e}\nreplay with: CASE_FUZZ_SEED={seed} PROPTEST_CASES={} cargo test \
             --test all case_fuzz::{name}",
            config.cases
        );
    }
}

/// A seed, one of its nodes, and the loader's expectation for `new` there.
pub(crate) fn expectation(seed: &Seed, node: &Node, new: Option<&Value>) -> Expect {
    let old = &node.value;
    let Some(new) = new else {
        // Elastic solids may stand without fluid (alone, or in a tank, among obstacles and
        // bodies, which they touch), and inlets and fills bring their own: then the fluid
        // blocks are not required.
        let solids_without_fluid = node.path == "fluid_block"
            && ["solid", "inlet", "fill"]
                .iter()
                .any(|k| seed.doc.contains_key(*k));
        return if required(&node.path) && !solids_without_fluid {
            Expect::Reject
        } else if matches!(generic(&node.path).as_str(), "name" | "probe" | "probe[]") {
            // Nothing depends on the name or on a probe.
            Expect::Accept
        } else {
            Expect::Either
        };
    };
    let same_type = match old {
        Value::Float(_) => is_number(new),
        Value::Integer(_) => matches!(new, Value::Integer(_)),
        Value::String(_) => new.is_str(),
        Value::Boolean(_) => new.is_bool(),
        Value::Table(_) => new.is_table(),
        Value::Array(_) => new.is_array(),
        Value::Datetime(_) => false,
    };
    if !same_type || (old.is_float() && !finite_number(new)) {
        return Expect::Reject;
    }
    if let (Some(len), Value::Array(items)) = (vector_len(&node.path, seed.dim), new) {
        if items.len() != len || !items.iter().all(finite_number) {
            return Expect::Reject;
        }
    }
    Expect::Either
}

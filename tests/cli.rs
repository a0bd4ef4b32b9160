//! The `wgsph` command as a user runs it: a short real run writes every output; bad case files
//! fail with a message naming file, line and field, never a panic.

use std::process::Command;

fn wgsph() -> Command {
    crate::common::lavapipe_for_tests();
    Command::new(env!("CARGO_BIN_EXE_wgsph"))
}

fn temp_dir(name: &str) -> crate::common::Scratch {
    crate::common::Scratch::new(&format!("cli-{name}"))
}

#[test]
fn run_writes_snapshots_probes_and_summary() {
    let out = temp_dir("run");
    let o = wgsph()
        .args([
            "run",
            "cases/hydrostatic_2d.toml",
            "--set",
            "time.end_s=0.05",
            "--set",
            "time.output_every_s=0.025",
        ])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("completed"), "{stdout}");
    let pvd = std::fs::read_to_string(out.join("particles.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 3, "t = 0, 0.025, 0.05");
    for f in [
        "particles/particles_000002.vtu",
        "probes/p_bottom.csv",
        "probes/height.csv",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let csv = std::fs::read_to_string(out.join("probes/p_bottom.csv")).unwrap();
    assert!(csv.starts_with("t_s,pressure_pa\n"));
    assert_eq!(
        csv.lines().count(),
        1 + 6,
        "header + t = 0, 0.01, ..., 0.05"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "completed");
    assert!(summary["steps"].as_u64().unwrap() > 10);
    assert!(summary["particle_steps_per_s"].as_f64().unwrap() > 0.0);
    assert!(summary["gpu_bytes_per_particle"].as_f64().unwrap() > 0.0);
}

/// Runs `wgsph run cases/hydrostatic_2d.toml` to t = 0.04 s with outputs every 0.02 s, output
/// captured (so off a terminal), RUST_LOG set to `rust_log`; returns (output, out dir).
fn run_hydrostatic(
    name: &str,
    rust_log: &str,
    args: &[&str],
) -> (std::process::Output, crate::common::Scratch) {
    let out = temp_dir(name);
    let o = wgsph()
        .args(["run", "cases/hydrostatic_2d.toml"])
        .args([
            "--set",
            "time.end_s=0.04",
            "--set",
            "time.output_every_s=0.02",
        ])
        .arg("--out")
        .arg(&out)
        .args(args)
        .env("RUST_LOG", rust_log)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    (o, out)
}

/// A headless run prints no Wayland complaint: Mesa's device-select layer, which connects to a
/// display to choose a default device and printed "error: XDG_RUNTIME_DIR is invalid or not
/// set in the environment." twice on every command, is off (`without_mesa_device_select`).
#[test]
fn a_headless_run_prints_no_display_errors() {
    let out = temp_dir("headless");
    let o = wgsph()
        .args(["run", "cases/hydrostatic_2d.toml", "--quiet"])
        .args(["--set", "time.end_s=0.002", "--out"])
        .arg(&out)
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("NODEVICE_SELECT")
        .env_remove("MESA_VK_DEVICE_SELECT")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(!stderr.contains("XDG_RUNTIME_DIR"), "{stderr}");
}

#[test]
fn snapshots_are_pngs_and_log_lines_go_to_stderr_off_a_terminal() {
    let (o, out) = run_hydrostatic("pngs", "wgsph=debug", &["--snapshots"]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    // The set-up line, the first progress line (later ones come every 10 s of wall time) and,
    // with RUST_LOG=wgsph=debug, one line per output.
    for line in [
        "INFO ] hydrostatic_2d: 1598 particles",
        "INFO ] t = 0.0100/0.04 s (25 %)",
        "particle-steps/s",
        "DEBUG] output 2 at t = 0.0400 s",
    ] {
        assert!(stderr.contains(line), "{line:?} not in stderr:\n{stderr}");
    }
    assert!(String::from_utf8_lossy(&o.stdout).starts_with("completed: "));
    // One PNG per VTU, all the same size, and nothing else (no temporary file).
    let mut names: Vec<String> = std::fs::read_dir(out.join("snapshots"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(names, ["000000.png", "000001.png", "000002.png"]);
    let sizes: Vec<(u32, u32)> = names
        .iter()
        .map(|n| {
            let file = std::fs::File::open(out.join("snapshots").join(n)).unwrap();
            let info = png::Decoder::new(std::io::BufReader::new(file))
                .read_info()
                .unwrap()
                .info()
                .clone();
            (info.width, info.height)
        })
        .collect();
    assert!(sizes[0].0 > 400 && sizes[0].1 > 400, "{sizes:?}");
    assert!(sizes.iter().all(|s| *s == sizes[0]), "{sizes:?}");
    assert!(out.join("particles/particles_000002.vtu").is_file());
}

/// `wgsph plot DIR --snapshots` draws, from the particle files, the PNGs the run drew: byte for
/// byte. The case comes from run.json (or `--case`); a case that no longer gives the run's
/// particles is refused with a message.
#[test]
fn plot_snapshots_draws_from_the_particle_files_what_the_run_drew() {
    let (_, out) = run_hydrostatic("plot-pngs", "warn", &["--snapshots"]);
    let names = ["000000.png", "000001.png", "000002.png"];
    let read = |name: &str| std::fs::read(out.join("snapshots").join(name)).unwrap();
    let drawn_by_the_run: Vec<Vec<u8>> = names.iter().map(|n| read(n)).collect();
    std::fs::remove_dir_all(out.join("snapshots")).unwrap();
    let plot = |args: &[&str]| {
        let o = wgsph()
            .arg("plot")
            .arg(&*out)
            .args(args)
            .env("RUST_LOG", "warn")
            .output()
            .unwrap();
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        (o.status.success(), text)
    };
    let (ok, text) = plot(&["--snapshots"]);
    assert!(ok && text.contains("wrote 3 snapshots"), "{text}");
    for (name, run) in names.iter().zip(&drawn_by_the_run) {
        assert!(read(name) == *run, "{name} differs from the run's");
    }
    let (ok, text) = plot(&["--snapshots", "--snapshot-field", "speed"]);
    assert!(ok, "{text}");
    assert!(
        read(names[2]) != drawn_by_the_run[2],
        "speed drawn as pressure"
    );
    // A run.json that does not name its case file: --case names it.
    let json = out.join("run.json");
    let mut summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    summary.as_object_mut().unwrap().remove("case_file");
    std::fs::write(&json, summary.to_string()).unwrap();
    let (ok, text) = plot(&["--snapshots"]);
    assert!(!ok && text.contains("--case FILE"), "{text}");
    let (ok, text) = plot(&["--snapshots", "--case", "cases/hydrostatic_2d.toml"]);
    assert!(ok, "{text}");
    assert!(read(names[0]) == drawn_by_the_run[0]);
    // Another case: other particles, refused.
    let (ok, text) = plot(&["--snapshots", "--case", "cases/dam_break_2d.toml"]);
    assert!(
        !ok && text.contains("the case changed since the run"),
        "{text}"
    );
}

/// `time.output_boundary = "first"`: the later particle files leave out the tank's walls,
/// which have not moved, and keep the fluid and the floating box's particles, which have; the
/// pictures drawn from them afterwards are the run's own.
/// `hydrostatic_3d` at dx = 0.04 m to `end_s`, an output every 0.01 s, with `args`, in a
/// scratch folder named after `name`; the run must succeed.
fn run_tank_3d(name: &str, end_s: &str, args: &[&str]) -> crate::common::Scratch {
    let out = temp_dir(name);
    let o = wgsph()
        .args(["run", "cases/hydrostatic_3d.toml", "--quiet"])
        .args(args)
        .args([
            "--set",
            "particles.dx_m=0.04",
            "--set",
            &format!("time.end_s={end_s}"),
        ])
        .args(["--set", "time.output_every_s=0.01", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    out
}

/// Removes the `count` snapshots a run in `out` drew, draws them again from its particle files
/// with `wgsph plot DIR --snapshots`, and asserts that each is the run's, byte for byte.
fn redrawn_snapshots_are_the_runs(out: &std::path::Path, count: usize) {
    let read = |k: usize| std::fs::read(out.join(format!("snapshots/{k:06}.png"))).unwrap();
    let by_the_run: Vec<Vec<u8>> = (0..count).map(read).collect();
    std::fs::remove_dir_all(out.join("snapshots")).unwrap();
    let o = wgsph()
        .arg("plot")
        .arg(out)
        .arg("--snapshots")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for (k, png) in by_the_run.iter().enumerate() {
        assert!(read(k) == *png, "snapshot {k} differs from the run's");
    }
}

#[test]
fn later_outputs_leave_out_the_unmoved_walls() {
    let out = temp_dir("output-boundary");
    let o = wgsph()
        .args([
            "run",
            "cases/floating_box_2d.toml",
            "--snapshots",
            "--quiet",
        ])
        .args(["--set", "particles.dx_m=0.02", "--set", "time.end_s=0.08"])
        .args(["--set", "time.output_every_s=0.04"])
        .args(["--set", "time.output_boundary=\"first\""])
        .arg("--out")
        .arg(&*out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let read = |k: usize| {
        let file = out.join(format!("particles/particles_{k:06}.vtu"));
        wgsph::output::ParticleFile::read(&file).unwrap().particles
    };
    let (first, last) = (read(0), read(2));
    let count =
        |p: &wgsph::output::Particles, kind: u32| p.kind.iter().filter(|k| **k == kind).count();
    // The fluid (kind 0) and the box's fixed-ghost particles (kind 2) in both, the tank's
    // dynamic walls (kind 1) only in the first.
    assert!(count(&first, 1) > 100, "{} walls", count(&first, 1));
    assert_eq!(count(&last, 1), 0);
    assert_eq!(count(&last, 0), count(&first, 0));
    assert!(count(&last, 2) > 0 && count(&last, 2) == count(&first, 2));
    assert_eq!(last.id.len(), count(&last, 0) + count(&last, 2));
    redrawn_snapshots_are_the_runs(&out, 3);
    // Without the first file the walls are nowhere: refused, not drawn without them.
    std::fs::remove_file(out.join("particles/particles_000000.vtu")).unwrap();
    let o = wgsph()
        .arg("plot")
        .arg(&*out)
        .arg("--snapshots")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && stderr.contains("the first output"),
        "{stderr}"
    );
}

#[test]
fn quiet_prints_nothing_but_errors() {
    // --quiet wins over RUST_LOG.
    let (o, out) = run_hydrostatic("quiet", "debug", &["--quiet"]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        o.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    for word in ["INFO", "DEBUG", "WARN", "t = "] {
        assert!(!stderr.contains(word), "{word:?} in stderr:\n{stderr}");
    }
    let summary = std::fs::read_to_string(out.join("run.json")).unwrap();
    assert!(summary.contains("\"completed\""));
    assert!(!out.join("snapshots").exists());
}

/// A case's warnings (here a fixed-ghost baffle 0.04 m thick, under 4h − dx = 0.084 m) go to
/// the log as WARN lines and into run.json; the run goes on.
#[test]
fn case_warnings_go_to_the_log_and_run_json() {
    let dir = temp_dir("warnings");
    std::fs::create_dir_all(&*dir).unwrap();
    let case = dir.join("baffle.toml");
    let text = std::fs::read_to_string("cases/hydrostatic_2d.toml").unwrap()
        + "\n[[obstacle]]\nmin_m = [0.6, 0.1]\nmax_m = [0.64, 0.4]\nwall = \"fixed_ghost\"\n";
    std::fs::write(&case, text).unwrap();
    let out = dir.join("out");
    let o = wgsph()
        .arg("run")
        .arg(&case)
        .args([
            "--set",
            "time.end_s=0.01",
            "--set",
            "time.output_every_s=0.01",
        ])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let expected = "obstacle[0] ([0.6, 0.1] to [0.64, 0.4]) has fixed ghosts and is 0.04 m thick";
    assert!(
        stderr
            .lines()
            .any(|l| l.contains("WARN") && l.contains(expected)),
        "{stderr}"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "completed");
    let warnings = summary["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].as_str().unwrap().starts_with(expected),
        "{warnings:?}"
    );
}

#[test]
fn snapshot_field_needs_snapshots_and_a_known_field() {
    for (args, word) in [
        (&["--snapshot-field", "speed"][..], "--snapshots"),
        (
            &["--snapshots", "--snapshot-field", "density"][..],
            "pressure or speed",
        ),
    ] {
        let o = wgsph()
            .args(["run", "cases/hydrostatic_2d.toml"])
            .args(args)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(word), "{args:?}: {stderr}");
    }
}

/// Writes `text` as a case file and runs it; returns (exit code, stderr).
fn run_bad(name: &str, text: &str) -> (i32, String) {
    let dir = temp_dir(name);
    std::fs::create_dir_all(&dir).unwrap();
    let case = dir.join(format!("{name}.toml"));
    std::fs::write(&case, text).unwrap();
    let o = wgsph()
        .arg("run")
        .arg(&case)
        .arg("--out")
        .arg(dir.join("out"))
        .output()
        .unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn good_case() -> String {
    std::fs::read_to_string("cases/hydrostatic_2d.toml").unwrap()
}

#[test]
fn bad_case_files_fail_with_file_line_and_field() {
    let good = good_case();
    let cases = [
        (
            "missing_field",
            good.replace("end_s = 2.0", ""),
            vec!["time", "end_s"],
        ),
        (
            "wrong_type",
            good.replace("dx_m = 0.02", "dx_m = \"fine\""),
            vec![":", "particles.dx_m"],
        ),
        (
            "negative_dx",
            good.replace("dx_m = 0.02", "dx_m = -0.02"),
            vec![":", "particles.dx_m", "> 0"],
        ),
        (
            "fluid_outside_tank",
            good.replace("max_m = [1.0, 0.5]", "max_m = [1.5, 0.5]"),
            vec!["fluid_block", "tank"],
        ),
    ];
    for (name, text, words) in cases {
        let (code, err) = run_bad(name, &text);
        assert_eq!(code, 1, "{name}: {err}");
        assert!(!err.contains("panicked"), "{name} panicked: {err}");
        assert!(
            err.contains(&format!("{name}.toml")),
            "{name}: message must name the file: {err}"
        );
        for w in words {
            assert!(err.contains(w), "{name}: message must mention '{w}': {err}");
        }
    }
}

#[test]
fn a_solid_case_runs_and_writes_the_stress() {
    let out = temp_dir("plate");
    let o = wgsph()
        .args([
            "run",
            "cases/oscillating_plate_2d.toml",
            "--set",
            "time.end_s=0.01",
            "--set",
            "time.output_every_s=0.01",
            "--quiet",
        ])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    let vtu = std::fs::read(out.join("particles/particles_000001.vtu")).unwrap();
    let head = String::from_utf8_lossy(&vtu[..vtu.len().min(4096)]);
    for name in ["tau_xx", "tau_yy", "tau_xy", "pressure"] {
        assert!(head.contains(&format!("Name=\"{name}\"")), "{name} missing");
    }
}

/// `wgsph validate --quick` on the 2D dam break, as a user runs it: the report has the case's
/// rows with numeric errors, bounds and verdicts ("info" for the rows reported, not judged),
/// links the plot, the PNG and the probe table exist, the table is printed, and the exit status
/// is 0 exactly when every judged row passes. And they pass: the front's speed over
/// T ∈ [1, 3], once the column has collapsed and before it reaches the far wall, within the
/// quick mode's bound of Martin & Moyce's (independent of the experiment's time origin). (Once
/// tests/validation/cases.rs's `dam_break_2d_front_speed_matches_martin_moyce`, through the
/// library: one run of the case in CI, not two.)
#[test]
fn validate_quick_writes_the_report_and_plots_and_the_front_speed_passes() {
    let out = temp_dir("validate");
    let o = wgsph()
        .args(["validate", "--quick", "--case", "dam_break_2d", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    let report = std::fs::read_to_string(out.join("report.md"))
        .unwrap_or_else(|e| panic!("{e}\n{stdout}\n{}", String::from_utf8_lossy(&o.stderr)));
    assert!(report.contains("quick mode"), "{report}");
    assert!(report.contains("--case dam_break_2d"), "{report}");
    // The results table: the case's rows before the wall-time table.
    let rows: Vec<&str> = (report.lines())
        .take_while(|l| !l.starts_with("## "))
        .filter(|l| l.starts_with("| dam_break_2d |"))
        .collect();
    let verdict = |l: &str| l.split('|').map(str::trim).nth(5).unwrap_or("").to_string();
    assert!(rows.len() >= 6, "{report}");
    assert!(
        rows.iter()
            .all(|r| ["PASS", "FAIL", "info"].contains(&verdict(r).as_str())),
        "{report}"
    );
    let judged = || rows.iter().filter(|r| verdict(r) != "info");
    assert_eq!(
        o.status.success(),
        judged().all(|r| verdict(r) == "PASS"),
        "{report}"
    );
    let row = *rows
        .iter()
        .find(|l| l.starts_with("| dam_break_2d | front speed dZ/dT over T ∈ [1, 3] |"))
        .unwrap_or_else(|| panic!("no front speed row in\n{report}"));
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    // ["", case, metric, error, bound, result, ""]
    let error: f64 = cells[3].trim_end_matches('%').trim().parse().unwrap();
    assert!(error.is_finite(), "{row}");
    assert_eq!(cells[4], "±10 %", "{row}");
    assert_eq!(cells[5] == "PASS", error.abs() < 10.0, "{row}");
    assert!(
        report.contains("](dam_break_2d/plots/front.png)"),
        "{report}"
    );
    let png = std::fs::read(out.join("dam_break_2d/plots/front.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert!(out.join("dam_break_2d/probes/front.csv").is_file());
    // The table is also printed.
    assert!(stdout.contains(row), "{stdout}");
    // The validation itself.
    assert!(judged().count() >= 1 && o.status.success(), "{report}");
}

/// An unknown case, or one its mode does not run, is refused before anything runs, naming the
/// cases; --quick and --full exclude each other.
#[test]
fn validate_refuses_unknown_cases_and_both_modes() {
    let out = temp_dir("validate-bad");
    let o = wgsph()
        .args(["validate", "--case", "nope", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        stderr.contains("'nope'") && stderr.contains("floating_box_2d"),
        "{stderr}"
    );
    let o = wgsph()
        .args([
            "validate",
            "--case",
            "water_entry_cylinder_2d_rho1000",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("not run in quick mode"), "{stderr}");
    assert!(!out.join("report.md").exists());
    let o = wgsph()
        .args(["validate", "--quick", "--full", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot be used with"));
}

/// `bench` reports the throughput and memory, the work (simulated time per wall second, the
/// mean step, candidates and neighbours per particle, dispatches per step); with `--stages`, a
/// table of each stage's GPU time whose shares add up to the whole.
#[test]
fn bench_reports_throughput_and_the_stages() {
    let o = wgsph()
        .args([
            "bench",
            "cases/hydrostatic_2d.toml",
            "--steps",
            "10",
            "--warmup",
            "2",
            "--stages",
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let value = |key: &str| -> f64 {
        let line = stdout.lines().find(|l| l.starts_with(key)).unwrap();
        let first = line[key.len()..].split_whitespace().next().unwrap();
        first.parse().unwrap()
    };
    assert!(value("particle-steps/s") > 0.0, "{stdout}");
    assert!(value("bytes/particle") > 0.0, "{stdout}");
    // 10 steps of about dt: simulated time per wall time is their sum over the wall time.
    let dt = value("mean dt s");
    assert!(dt > 1e-6 && dt < 1e-2, "{stdout}");
    let speed = value("simulated s/wall s");
    assert!(
        (speed / (10.0 * dt / value("wall seconds")) - 1.0).abs() < 5e-3,
        "{stdout}"
    );
    // h = 1.3 dx in 2D: 21 lattice points within 2h in the bulk, fewer at the walls and the
    // surface; cells of h hold some 1.7 particles each, at most 25 cells are tested (21.6 on
    // average once the rows are cut to the support's reach).
    let (candidates, neighbours) = (value("candidates/particle"), value("neighbours/particle"));
    assert!(neighbours > 10.0 && neighbours < 21.5, "{stdout}");
    assert!(
        candidates > 1.2 * neighbours && candidates < 25.0 * 1.7,
        "{stdout}"
    );
    // At least one dispatch for each stage of the table.
    let dispatches = value("dispatches/step");
    let n_stages = stdout
        .lines()
        .skip_while(|l| !l.starts_with("stage "))
        .count()
        - 2;
    assert!(dispatches >= n_stages as f64, "{stdout}");
    // Rows after the table's header: name, ms/step, share, "%", ns/particle, the estimated
    // bytes per particle-step and the GB/s they imply.
    let rows: Vec<Vec<&str>> = stdout
        .lines()
        .skip_while(|l| !l.starts_with("stage "))
        .skip(1)
        .map(|l| l.split_whitespace().collect())
        .collect();
    let column = |r: &Vec<&str>, after_percent: isize| -> f64 {
        let percent = r.iter().position(|t| *t == "%").unwrap() as isize;
        r[(percent + after_percent) as usize].parse().unwrap()
    };
    let share = |r: &Vec<&str>| column(r, -1);
    let (all, stages) = rows.split_last().expect("a stage table");
    assert_eq!(all[..2], ["all", "stages"], "{stdout}");
    for name in ["predict", "sort_key", "interaction", "correct"] {
        assert!(stages.iter().any(|r| r[0] == name), "{name}: {stdout}");
    }
    let sum: f64 = stages.iter().map(share).sum();
    assert!((sum - 100.0).abs() < 0.05 * stages.len() as f64, "{stdout}");
    assert_eq!(share(all), 100.0, "{stdout}");
    // The estimated bytes: the stages' add up to the step's, which the line above the table
    // gives read and written; the interaction loads at least a position per candidate.
    let estimate = |r: &Vec<&str>| column(r, 2);
    let stage_sum: f64 = stages.iter().map(estimate).sum();
    assert!((stage_sum / estimate(all) - 1.0).abs() < 1e-3, "{stdout}");
    let line = (stdout.lines())
        .find(|l| l.starts_with("bytes/particle-step"))
        .unwrap();
    let words: Vec<&str> = line.split_whitespace().collect();
    let (read, written): (f64, f64) = (words[1].parse().unwrap(), words[3].parse().unwrap());
    assert!((read + written - estimate(all)).abs() <= 1.0, "{stdout}");
    let interaction = stages.iter().find(|r| r[0] == "interaction").unwrap();
    assert!(estimate(interaction) > 16.0 * candidates, "{stdout}");
    assert!(column(interaction, 3) > 0.0, "GB/s: {stdout}");
}

/// A wave gauge in a domain tall compared with h, at 10× finer dx than the shipped
/// hydrostatic case (issue 36): the tank 0.1 m wide and 0.6 m high (1.2 m of domain with the
/// open top's room), 0.02 m of water, dx = 2 mm; far more cells than particles, so the grid is
/// hashed. The gauge once walked down from the domain top by h/4 and read exactly 0 at every
/// sample (lavapipe ends an invocation's loops after 65535 iterations); it must read the
/// water's depth.
#[test]
fn a_height_gauge_reads_the_surface_of_a_tall_tank_at_a_fine_dx() {
    let out = temp_dir("tall-gauge");
    let o = wgsph()
        .args(["run", "-q", "cases/hydrostatic_2d.toml"])
        .args(["--set", "particles.dx_m=0.002"])
        .args(["--set", "tank.max_m=[0.1, 0.6]"])
        .args(["--set", "fluid_block[0].max_m=[0.1, 0.02]"])
        .args(["--set", "probe[0].point_m=[0.05, 0.01]"])
        .args(["--set", "probe[1].base_m=[0.05, 0.0]"])
        .args(["--set", "probe[2].point_m=[0.05, 0.0]"])
        .args(["--set", "probe[2].radius_m=0.01"])
        .args(["--set", "time.end_s=0.001"])
        .args(["--set", "time.probe_every_s=0.0005"])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("probes/height.csv")).unwrap();
    let rows: Vec<f64> = (csv.lines().skip(1))
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(rows.len(), 3, "{csv}");
    for h in rows {
        assert!(
            (h - 0.02).abs() < 0.002,
            "the gauge reads {h} m over 0.02 m of water\n{csv}"
        );
    }
}

/// Probes that can never measure (issue 36): a pressure point and a gauge inside an obstacle
/// that reaches the lid of a closed tank, and a pressure point inside the tank's wall. Each is
/// named in a warning at set-up (log and run.json) and reads `nan` at every sample, never a
/// silent 0; the probes in reach of the water read numbers.
#[test]
fn probes_that_cannot_measure_warn_and_read_nan() {
    let dir = temp_dir("blind");
    std::fs::create_dir_all(&*dir).unwrap();
    let case = dir.join("blind.toml");
    std::fs::write(
        &case,
        r#"name = "blind"
dimension = 2
[particles]
dx_m = 0.005
[physics]
gravity_m_s2 = [0.0, -9.81]
sound_speed_coef = 10.0
[time]
end_s = 0.002
output_every_s = 1.0
probe_every_s = 0.001
[tank]
min_m = [0.0, 0.0]
max_m = [0.2, 0.1]
open_top = false
[[fluid_block]]
min_m = [0.0, 0.0]
max_m = [0.1, 0.05]
[[obstacle]]
min_m = [0.15, 0.0]
max_m = [0.18, 0.1]
[[probe]]
name = "in_obstacle"
kind = "pressure"
point_m = [0.165, 0.03]
[[probe]]
name = "gauge_in_obstacle"
kind = "height"
base_m = [0.165, 0.0]
[[probe]]
name = "in_wall"
kind = "pressure"
point_m = [-0.0075, 0.05]
[[probe]]
name = "gauge"
kind = "height"
base_m = [0.05, 0.0]
[[probe]]
name = "air"
kind = "pressure"
point_m = [0.12, 0.09]
"#,
    )
    .unwrap();
    let out = dir.join("out");
    let o = wgsph()
        .arg("run")
        .arg(&case)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    let warnings: Vec<&str> = (summary["warnings"].as_array().unwrap().iter())
        .map(|w| w.as_str().unwrap())
        .collect();
    for (name, blind) in [
        ("in_obstacle", true),
        ("gauge_in_obstacle", true),
        ("in_wall", true),
        ("gauge", false),
        ("air", false),
    ] {
        let said = format!("probe '{name}'");
        let warned = warnings
            .iter()
            .any(|w| w.contains(&said) && w.contains("reads nan"));
        assert_eq!(warned, blind, "{name}: {warnings:#?}");
        assert_eq!(stderr.contains(&said), blind, "{name}: {stderr}");
        let csv = std::fs::read_to_string(out.join(format!("probes/{name}.csv"))).unwrap();
        let values: Vec<&str> = (csv.lines().skip(1))
            .map(|l| l.split(',').nth(1).unwrap())
            .collect();
        assert_eq!(values.len(), 3, "{csv}");
        for v in values {
            assert_eq!(v == "nan", blind, "{name}: {csv}");
        }
    }
}

/// The output folder's lock (issue 36): a live process's lock (this test's own pid) makes
/// `run` and a resume of the folder refuse, naming the folder and the process, and leaves the
/// lock as it was; a dead process's lock (a pid above Linux's pid_max) is taken over; after a
/// run no lock is left.
/// A run never deletes or overwrites a file it did not write (issue 64). A case named ".."
/// ran, without --out, into `out/..` (the working directory) and its clean-up of an earlier
/// run's outputs deleted the user's `probes/*.csv` and `plots/*.png` there and overwrote their
/// `run.json`. Now such a name is refused, an --out folder holding files by the names a run
/// writes that no run wrote is refused with every file intact, and a run into its own earlier
/// folder removes what the earlier run wrote (its manifest) and nothing else.
#[test]
fn a_run_never_deletes_or_overwrites_files_it_did_not_write() {
    let home = temp_dir("foreign");
    let mine = [
        "run.json",
        "probes/p_bottom.csv",
        "plots/mine.png",
        "notes.txt",
    ];
    for f in mine {
        let p = home.join(f);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(&p, format!("the user's {f}")).unwrap();
    }
    let intact = |what: &str| {
        for f in mine {
            let text = std::fs::read_to_string(home.join(f)).unwrap();
            assert_eq!(text, format!("the user's {f}"), "{what}: {f}");
        }
    };
    let case = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/hydrostatic_2d.toml");
    let short = ["--set", "particles.dx_m=0.05", "--set", "time.end_s=0.02"];
    for name in ["..", ".", " .. "] {
        let o = wgsph()
            .current_dir(home.join("probes"))
            .arg("run")
            .arg(&case)
            .args(short)
            .args(["--set", &format!("name=\"{name}\"")])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "name {name:?} ran: {err}");
        assert!(
            err.contains("name") && err.contains("fix: "),
            "{name:?}: {err}"
        );
        intact(&format!("name {name:?}"));
    }
    let run = |out: &std::path::Path| {
        wgsph()
            .arg("run")
            .arg(&case)
            .args(short)
            .args(["-q", "--out"])
            .arg(out)
            .output()
            .unwrap()
    };
    let o = run(&home);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "ran into a folder of the user's files");
    for f in [
        "run.json",
        "probes/p_bottom.csv",
        "plots/mine.png",
        "did not write",
    ] {
        assert!(err.contains(f), "the refusal names {f}: {err}");
    }
    assert!(!err.contains("notes.txt"), "{err}");
    intact("--out the user's folder");
    assert!(
        !home.join("particles").exists(),
        "the refused run wrote nothing"
    );
    // Its own folder, twice: the second run replaces the first's files and keeps the user's.
    let out = temp_dir("own-folder");
    let o = run(&out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::write(out.join("notes.txt"), "kept").unwrap();
    std::fs::write(out.join("probes/readme.md"), "kept").unwrap();
    std::fs::write(out.join("particles/particles_000099.vtu"), "stale").unwrap();
    let o = run(&out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("particles_000099.vtu"),
        "{err}"
    );
    std::fs::remove_file(out.join("particles/particles_000099.vtu")).unwrap();
    let o = run(&out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in [
        "notes.txt",
        "probes/readme.md",
        "run.json",
        "probes/height.csv",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
}

#[test]
fn a_locked_output_folder_is_refused_and_a_stale_lock_taken_over() {
    let out = temp_dir("lock");
    std::fs::create_dir_all(&*out).unwrap();
    let lock = out.join(".wgsph.lock");
    let me = std::process::id().to_string();
    let run = || {
        wgsph()
            .args(["run", "-q", "cases/hydrostatic_2d.toml"])
            .args([
                "--set",
                "time.end_s=0.01",
                "--checkpoint-every",
                "0.005s",
                "--out",
            ])
            .arg(&*out)
            .output()
            .unwrap()
    };
    let refused = |o: std::process::Output, what: &str| {
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{what}: {stderr}");
        let says = format!(
            "{} is in use by another wgsph run (process {me}",
            out.display()
        );
        assert!(stderr.contains(&says), "{what}: {stderr}");
        assert_eq!(
            std::fs::read_to_string(&lock).unwrap(),
            format!("{me}\n"),
            "{what}"
        );
    };
    std::fs::write(&lock, format!("{me}\n")).unwrap();
    refused(run(), "run");
    assert!(
        !out.join("probes").exists(),
        "the refused run wrote nothing"
    );
    std::fs::write(&lock, "4194305\n").unwrap();
    let o = run();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("probes/height.csv").is_file());
    let left: Vec<_> = (std::fs::read_dir(&*out).unwrap().flatten())
        .map(|e| e.file_name())
        .filter(|n| n.to_string_lossy().starts_with(".wgsph.lock"))
        .collect();
    assert!(
        left.is_empty(),
        "the lock is removed when the run ends: {left:?}"
    );
    // A resume takes the lock before it reads the checkpoint (the CLI reads it first for the
    // case file, and a completed run keeps none): through the library.
    std::fs::write(&lock, format!("{me}\n")).unwrap();
    let sc = wgsph::case::load(std::path::Path::new("cases/hydrostatic_2d.toml"), &[]).unwrap();
    let Err(e) = wgsph::run::resume(
        crate::common::gpu(),
        &sc,
        &out,
        &Default::default(),
        &mut wgsph::progress::LogLines::default(),
    ) else {
        panic!("the resume of a locked folder went ahead");
    };
    let says = format!(
        "{} is in use by another wgsph run (process {me}",
        out.display()
    );
    assert!(format!("{e:#}").contains(&says), "resume: {e:#}");
    assert_eq!(std::fs::read_to_string(&lock).unwrap(), format!("{me}\n"));
}

/// `wgsph surface` on a short run of the 3D hydrostatic tank (dx = 0.04 m, water 0.4 m deep,
/// still): one mesh per particle output in surface.pvd, each flat at the water's height within
/// a fifth of a spacing over the tank's middle; a 2D run is refused with a message.
#[test]
fn surface_meshes_the_water_of_a_3d_run() {
    let out = run_tank_3d("surface", "0.02", &[]);
    let o = wgsph().arg("surface").arg(&out).output().unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("particle radius 0.02 m"), "{stdout}");
    let pvd = std::fs::read_to_string(out.join("surface.pvd")).unwrap();
    assert_eq!(
        pvd.matches("<DataSet").count(),
        3,
        "t = 0, 0.01, 0.02: {pvd}"
    );
    for i in 0..3 {
        let path = out.join(format!("surface/surface_{i:06}.vtu"));
        let mesh = wgsph::output::SurfaceMesh::read(&path).unwrap();
        let top: Vec<f64> = (mesh.vertices.iter())
            .filter(|v| (0.12..0.28).contains(&v[0]) && (0.12..0.28).contains(&v[1]) && v[2] > 0.2)
            .map(|v| v[2])
            .collect();
        assert!(top.len() > 10, "output {i}: {} top vertices", top.len());
        for z in top {
            assert!(
                (z - 0.4).abs() < 0.2 * 0.04,
                "output {i}: top vertex at z = {z}"
            );
        }
    }
    let flat = temp_dir("surface-2d");
    let (code, stderr) = {
        let o = wgsph()
            .args(["run", "cases/hydrostatic_2d.toml", "--quiet"])
            .args(["--set", "time.end_s=0.005", "--out"])
            .arg(&flat)
            .output()
            .unwrap();
        assert!(o.status.success());
        let o = wgsph().arg("surface").arg(&flat).output().unwrap();
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).to_string(),
        )
    };
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("2D run") && !stderr.contains("panicked"),
        "{stderr}"
    );
}

/// 3D snapshots are perspective views on the adapter (lavapipe here): the still tank of
/// `hydrostatic_3d` seen from the front left and above, the near walls cut away. Where the
/// camera puts the water's surface and the near edge's middle, the picture shows fluid
/// colours (never grey: viridis has no grey), where it puts the back wall, a wall's grey;
/// with the fluid excluded the water's pixels are no longer fluid; the same snapshot renders
/// to the same bytes. Then `run --snapshots` and `plot --snapshots` draw the same PNGs.
#[test]
fn snapshots_3d_are_perspective_views_of_the_particles() {
    use wgsph::plot::color_scale::SnapshotField;
    use wgsph::plot::perspective::{PerspectiveView, PICTURE};
    let set = ["particles.dx_m=0.04".to_string()];
    let sc = wgsph::case::load(std::path::Path::new("cases/hydrostatic_3d.toml"), &set).unwrap();
    let view =
        PerspectiveView::for_scenario(crate::common::gpu(), &sc, SnapshotField::Pressure).unwrap();
    let n = sc.particles.len();
    let pos: Vec<[f64; 3]> = sc.particles.iter().map(|p| p.pos).collect();
    let kind: Vec<u32> = sc.particles.iter().map(|p| p.kind as u32).collect();
    let rho: Vec<f32> = sc.particles.iter().map(|p| p.rho as f32).collect();
    let pressure: Vec<f32> = pos.iter().map(|p| (9810.0 * (0.4 - p[2])) as f32).collect();
    let (vel, id) = (vec![[0.0f32; 3]; n], (0..n as u32).collect::<Vec<_>>());
    let snapshot = |kind: &[u32]| -> Vec<u8> {
        let snap = wgsph::output::Snapshot {
            time_s: 0.0,
            pos: &pos,
            vel: &vel,
            rho: &rho,
            pressure: &pressure,
            kind,
            id: &id,
            extra: &[],
        };
        view.picture(&snap).unwrap()
    };
    let picture = snapshot(&kind);
    assert_eq!(picture.len(), (PICTURE.0 * PICTURE.1 * 3) as usize);
    let at = |img: &[u8], p: [f64; 3]| -> [u8; 3] {
        let (c, r) = (view.camera())
            .pixel(glam::DVec3::from(p), PICTURE)
            .unwrap();
        let i = 3 * (r as usize * PICTURE.0 as usize + c as usize);
        [img[i], img[i + 1], img[i + 2]]
    };
    let grey = |c: [u8; 3]| c.iter().max().unwrap() - c.iter().min().unwrap() < 8;
    let white = |c: [u8; 3]| c.iter().all(|&v| v > 250);
    // Particle centres (the lattice at dx = 0.04 m is at 0.02 + 0.04 k): the top layer of the
    // water, the middle of the water's near vertical edge.
    let surface = [0.22, 0.22, 0.38];
    let near_edge = [0.02, 0.02, 0.22];
    for p in [surface, near_edge] {
        let c = at(&picture, p);
        assert!(!grey(c) && !white(c), "{p:?}: {c:?} is not the water's");
    }
    // The back wall's inner face, above the water.
    let back_wall = [0.22, 0.42, 0.46];
    let c = at(&picture, back_wall);
    assert!(grey(c) && !white(c), "back wall {c:?}: not a wall");
    let excluded: Vec<u32> = (kind.iter())
        .map(|&k| if k == 0 { wgsph::sph::EXCLUDED } else { k })
        .collect();
    let dry = snapshot(&excluded);
    assert!(grey(at(&dry, surface)), "{:?}", at(&dry, surface));
    assert!(
        snapshot(&kind) == picture,
        "the same snapshot drew other pixels"
    );

    let out = run_tank_3d("perspective", "0.01", &["--snapshots"]);
    redrawn_snapshots_are_the_runs(&out, 2);
    let info = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(out.join("snapshots/000001.png")).unwrap(),
    ))
    .read_info()
    .unwrap()
    .info()
    .clone();
    assert!(info.width > PICTURE.0 && info.height > PICTURE.1);
}

/// Under a launcher with several ranks (its environment says how many), a build without MPI
/// refuses `run` and `resume` rather than run N times into one folder; one rank runs as
/// without a launcher. (Runs over ranks, in a build with MPI: tests/mpi.rs.)
#[test]
fn a_launch_over_several_ranks_needs_a_build_with_mpi() {
    let out = temp_dir("ranks");
    let command = |args: &[&str], var: &str, ranks: &str| {
        wgsph().args(args).env(var, ranks).output().unwrap()
    };
    let run = [
        "run",
        "cases/hydrostatic_2d.toml",
        "--set",
        "time.end_s=0.01",
        "--out",
    ];
    let run: Vec<&str> = run.into_iter().chain(out.to_str()).collect();
    for (var, ranks) in [("OMPI_COMM_WORLD_SIZE", "2"), ("PMI_SIZE", "4")] {
        if cfg!(feature = "mpi") {
            // Launched without the launcher it names, MPI would look for it: not tried here.
            break;
        }
        for args in [&run[..], &["resume", out.to_str().unwrap()]] {
            let o = command(args, var, ranks);
            let stderr = String::from_utf8_lossy(&o.stderr);
            assert!(!o.status.success());
            assert!(
                stderr.contains(&format!(
                    "launched on {ranks} ranks, but this wgsph was built without MPI"
                )),
                "{stderr}"
            );
        }
        assert!(!out.join("run.json").exists(), "nothing may be written");
    }
    let o = command(&run, "OMPI_COMM_WORLD_SIZE", "1");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

//! Restart and crash safety: a run split by a checkpoint and resumed is bit-identical to an
//! uninterrupted one (fluid with density filter and energy equation; a floating body; elastic
//! plates of both formulations in one case; an injection through a velocity inlet); a real
//! run killed with SIGKILL leaves only complete files behind and resumes from its last
//! checkpoint to the same result; Ctrl-C (SIGINT) checkpoints and stops; a lost GPU device and
//! a case too large for the adapter give clear errors instead of panics.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use crate::common::gpu;
use wgsph::progress::LogLines;
use wgsph::run::RunOptions;
use wgsph::scenario::{Motion, Scenario};

fn temp_dir(name: &str) -> crate::common::Scratch {
    crate::common::Scratch::new(&format!("restart-{name}"))
}

fn load(case: &str, set: &[&str]) -> Scenario {
    let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    wgsph::case::load(Path::new(case), &set).unwrap()
}

/// Every file of a run's outputs that must match between two runs: the snapshots, the probe
/// and body CSVs (run.json differs by its wall times, the checkpoint by its history).
fn result_files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    for sub in ["particles", "probes", "maps"] {
        let Ok(entries) = std::fs::read_dir(dir.join(sub)) else {
            assert_ne!(sub, "particles", "no particle files");
            continue;
        };
        let mut names: Vec<_> = entries
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        for n in names {
            let rel = format!("{sub}/{n}");
            out.push((rel.clone(), std::fs::read(dir.join(&rel)).unwrap()));
        }
    }
    out.push((
        "particles.pvd".into(),
        std::fs::read(dir.join("particles.pvd")).unwrap(),
    ));
    out
}

fn assert_same_results(a: &Path, b: &Path) {
    let (fa, fb) = (result_files(a), result_files(b));
    let names = |f: &[(String, Vec<u8>)]| f.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>();
    assert_eq!(names(&fa), names(&fb), "the runs wrote different files");
    for ((name, x), (_, y)) in fa.iter().zip(&fb) {
        assert!(
            x == y,
            "{name} differs between the uninterrupted and the resumed run"
        );
    }
}

fn steps(dir: &Path) -> u64 {
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("run.json")).unwrap()).unwrap();
    s["steps"].as_u64().unwrap()
}

/// Runs `sc` into `dir` to its end, with the default options.
fn run_to_end(sc: &Scenario, dir: &Path) -> wgsph::run::RunReport {
    let opts = RunOptions::default();
    wgsph::run::run(gpu(), sc, dir, &opts, &mut LogLines::default()).unwrap()
}

/// Resumes the run of `sc` in `dir` to its end, with the default options.
fn resume_to_end(sc: &Scenario, dir: &Path) -> wgsph::run::RunReport {
    let opts = RunOptions::default();
    wgsph::run::resume(gpu(), sc, dir, &opts, &mut LogLines::default()).unwrap()
}

/// Runs `sc` once straight through and once halted at `halt` and resumed; every output must be
/// the same bytes.
fn split_run_matches(tag: &str, sc: &Scenario, halt: f64) {
    let straight = temp_dir(&format!("{tag}-straight"));
    let split = temp_dir(&format!("{tag}-split"));
    let opts = RunOptions::default();
    let a = wgsph::run::run(gpu(), sc, &straight, &opts, &mut LogLines::default()).unwrap();
    assert!(a.stopped.is_none() && a.interrupted_at_s.is_none());
    let halted = RunOptions {
        halt_at_s: Some(halt),
        ..RunOptions::default()
    };
    let b = wgsph::run::run(gpu(), sc, &split, &halted, &mut LogLines::default()).unwrap();
    let t_halt = b.interrupted_at_s.expect("the split run halts");
    assert!((t_halt - halt).abs() < 1e-9, "halted at {t_halt}");
    assert!(
        b.summary.status.starts_with("interrupted"),
        "{}",
        b.summary.status
    );
    let first_half = b.summary.steps;
    let c = resume_to_end(sc, &split);
    assert!(c.stopped.is_none() && c.interrupted_at_s.is_none());
    println!(
        "{tag}: {} steps straight; {first_half} + {} split",
        a.summary.steps,
        c.summary.steps - first_half
    );
    assert!(first_half > 100 && c.summary.steps > first_half + 100);
    assert_eq!(steps(&straight), steps(&split));
    assert_same_results(&straight, &split);
}

/// A 3D dam break with flood maps (`[maps]`), halted mid-run: the maps' records come from the
/// checkpoint, so the resumed run's maps (maxima, arrival, final depth) are the uninterrupted
/// run's, byte for byte.
#[test]
fn resume_is_bit_identical_for_flood_maps() {
    let text = r#"
name = "maps_dam_break"
dimension = 3
[particles]
dx_m = 0.04
[physics]
gravity_m_s2 = [0.0, 0.0, -9.81]
sound_speed_coef = 10.0
viscosity = "artificial"
alpha = 0.02
[time]
end_s = 0.24
output_every_s = 0.08
probe_every_s = 0.02
[tank]
min_m = [0.0, 0.0, 0.0]
max_m = [0.6, 0.2, 0.3]
layers = 3
open_top = true
[[fluid_block]]
min_m = [0.0, 0.0, 0.0]
max_m = [0.2, 0.2, 0.2]
[maps]
cell_m = 0.05
wet_depth_m = 0.02
"#;
    let sc = wgsph::case::load_str(text, "maps_dam_break.toml", &[]).unwrap();
    split_run_matches("flood-maps", &sc, 0.1);
}

/// Sets the run's interrupt flag (as Ctrl-C and SIGTERM do) once the progress it hears has
/// passed `at_steps` steps, and counts the reports before it.
struct SignalAt {
    at_steps: u64,
    flag: std::sync::Arc<std::sync::atomic::AtomicBool>,
    reports: usize,
}

impl wgsph::progress::Progress for SignalAt {
    fn update(&mut self, status: &wgsph::progress::RunStatus) {
        if status.steps >= self.at_steps {
            self.flag.store(true, std::sync::atomic::Ordering::Relaxed);
        } else {
            self.reports += 1;
        }
    }

    fn finish(&mut self, _: &wgsph::progress::RunStatus) {}
}

/// A signal between two probe times (issue 64: at dx = 5 mm and probe_every_s = 0.1, SIGTERM
/// took 24 s and the first progress line 30 s). The run reports after every batch of steps
/// and stops at the next batch with a checkpoint, short of the probe time, whatever the probe
/// interval (here one interval, the whole run); the resumed run finishes that interval as the
/// uninterrupted one does, every output the same bytes. With a body (a step at a time) too.
#[test]
fn a_signal_between_probe_times_stops_at_once_and_resumes_bit_identically() {
    for (tag, case, set) in [
        (
            "mid-dam",
            "cases/dam_break_2d.toml",
            vec!["particles.dx_m=0.0146"],
        ),
        (
            "mid-box",
            "cases/floating_box_2d.toml",
            vec!["particles.dx_m=0.02"],
        ),
    ] {
        let mut set = set;
        set.extend([
            "time.end_s=0.08",
            "time.output_every_s=0.08",
            "time.probe_every_s=0.08",
        ]);
        let sc = load(case, &set);
        let straight = temp_dir(&format!("{tag}-straight"));
        let split = temp_dir(&format!("{tag}-split"));
        let a = run_to_end(&sc, &straight);
        let flag = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let opts = RunOptions {
            interrupt: Some(flag.clone()),
            ..RunOptions::default()
        };
        let mut signal = SignalAt {
            at_steps: a.summary.steps / 2,
            flag,
            reports: 0,
        };
        let b = wgsph::run::run(gpu(), &sc, &split, &opts, &mut signal).unwrap();
        let t = b.interrupted_at_s.expect("the signal stops the run");
        assert!(
            0.0 < t && t < 0.08,
            "{tag}: stopped at t = {t} s, not between probe times"
        );
        // Within one batch of the signal: at most 64 steps.
        let stopped_at = b.summary.steps;
        assert!(
            (signal.at_steps..signal.at_steps + 64).contains(&stopped_at),
            "{tag}: signalled at step {}, stopped at {stopped_at}",
            signal.at_steps
        );
        assert!(
            signal.reports > 1,
            "{tag}: {} progress reports before the signal",
            signal.reports
        );
        let c = resume_to_end(&sc, &split);
        assert!(c.stopped.is_none() && c.interrupted_at_s.is_none());
        assert_eq!(a.summary.steps, c.summary.steps, "{tag}");
        assert_eq!(
            a.summary.max_density_variation.map(f64::to_bits),
            c.summary.max_density_variation.map(f64::to_bits),
            "{tag}"
        );
        assert_same_results(&straight, &split);
    }
}

#[test]
fn resume_is_bit_identical_for_a_dam_break_with_filter_and_energy() {
    let sc = load(
        "cases/dam_break_2d.toml",
        &[
            "particles.dx_m=0.0146",
            "physics.density_filter=\"shepard\"",
            "physics.density_filter_every=7",
            "physics.energy=true",
            "time.end_s=0.2",
            "time.output_every_s=0.05",
            "time.probe_every_s=0.01",
        ],
    );
    split_run_matches("dam-break", &sc, 0.1);
}

/// Also with the later particle files leaving out the unmoved walls: the resumed run reads the
/// first file back to know them.
#[test]
fn resume_is_bit_identical_for_a_floating_body() {
    let sc = load(
        "cases/floating_box_2d.toml",
        &[
            "particles.dx_m=0.02",
            "time.end_s=0.16",
            "time.output_every_s=0.04",
            "time.probe_every_s=0.01",
            "time.output_boundary=\"first\"",
        ],
    );
    split_run_matches("floating-box", &sc, 0.07);
}

/// The same box held until t = 0.1 s (`release_s`), halted while held: the resumed run
/// releases it at the same step.
#[test]
fn resume_is_bit_identical_for_a_body_held_across_the_halt() {
    let sc = load(
        "cases/floating_box_2d.toml",
        &[
            "particles.dx_m=0.02",
            "body[0].motion.kind=\"free\"",
            "body[0].motion.release_s=0.1",
            "time.end_s=0.16",
            "time.output_every_s=0.04",
            "time.probe_every_s=0.01",
        ],
    );
    assert!(matches!(sc.bodies[0].motion, Motion::Free { release_s, .. } if release_s == 0.1));
    split_run_matches("held-box", &sc, 0.07);
}

/// A cylinder falling into water, halted while it moves through the cells: every particle
/// changes place in the sorted arrays between the start and the halt, so the resumed run must
/// find its body particles in the restored arrays, not where the warm-up's sort left them.
#[test]
fn resume_is_bit_identical_for_a_body_moving_through_the_cells() {
    let sc = load(
        "cases/water_entry_cylinder_2d.toml",
        &[
            "particles.dx_m=0.02",
            "body[0].wall=\"dynamic\"",
            "time.end_s=0.12",
            "time.output_every_s=0.03",
            "time.probe_every_s=0.01",
        ],
    );
    split_run_matches("falling-cylinder", &sc, 0.05);
}

/// Elastic plates of both formulations in one case (tests/common `both_plates_case`): the
/// updated-Lagrangian plate's τ and ρ come from the checkpoint; the total-Lagrangian plate's
/// reference lattice and lists come from the case, not the checkpoint, and F, T, P are
/// recomputed each step, so a resumed run continues exactly.
#[test]
fn resume_is_bit_identical_for_elastic_plates_of_both_formulations() {
    let set: Vec<String> = [
        "time.end_s=0.02",
        "time.output_every_s=0.005",
        "time.probe_every_s=0.0025",
    ]
    .map(String::from)
    .to_vec();
    let sc =
        wgsph::case::load_str(&crate::common::both_plates_case(), "plates.toml", &set).unwrap();
    split_run_matches("plates", &sc, 0.01);
}

/// Velocity inlets place their particles from the time alone (and count the joined ones in
/// the checkpointed state), so a resumed injection continues exactly.
#[test]
fn resume_is_bit_identical_for_an_injection() {
    let sc = load(
        "cases/water_injection_2d.toml",
        &[
            "particles.dx_m=0.01",
            "time.end_s=0.1",
            "time.output_every_s=0.025",
            "time.probe_every_s=0.01",
        ],
    );
    split_run_matches("injection", &sc, 0.05);
}

fn wgsph() -> Command {
    crate::common::lavapipe_for_tests();
    Command::new(env!("CARGO_BIN_EXE_wgsph"))
}

/// The CLI case of the process tests: a coarse dam break, checkpoints every 0.02 s.
const CLI_CASE: [&str; 10] = [
    "cases/dam_break_2d.toml",
    "--set",
    "particles.dx_m=0.0146",
    "--set",
    "time.end_s=0.4",
    "--set",
    "time.output_every_s=0.02",
    "--set",
    "time.probe_every_s=0.01",
    "--quiet",
];

/// The uninterrupted CLI run every process test compares with.
fn reference_run() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = temp_dir("cli-reference");
        let o = wgsph()
            .arg("run")
            .args(CLI_CASE)
            .args(["--checkpoint-every", "never", "--out"])
            .arg(&dir)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        // Shared by the process tests, so it stays (one small run).
        dir.keep()
    })
}

/// Starts the CLI run into `dir` with a checkpoint every 0.02 s.
fn spawn_run(dir: &Path) -> std::process::Child {
    wgsph()
        .arg("run")
        .args(CLI_CASE)
        .args(["--checkpoint-every", "0.02s", "--out"])
        .arg(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap()
}

/// Waits until `dir` has a checkpoint and `more` further snapshots beyond the first.
fn wait_for_checkpoint(dir: &Path, child: &mut std::process::Child) {
    let start = Instant::now();
    while !dir.join("checkpoint.bin").is_file()
        || !dir.join("particles/particles_000002.vtu").is_file()
    {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the run ended before a checkpoint"
        );
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no checkpoint after 2 min"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// The files a killed run left: every snapshot the .pvd lists is the reference run's snapshot
/// of the same index, byte for byte (complete, never truncated), and every CSV is a prefix of
/// the reference CSV ending at a line end.
fn assert_consistent_prefix(dir: &Path, reference: &Path) {
    let pvd = std::fs::read_to_string(dir.join("particles.pvd")).unwrap();
    let listed: Vec<&str> = pvd
        .split("file=\"")
        .skip(1)
        .map(|s| s.split('"').next().unwrap())
        .collect();
    assert!(!listed.is_empty());
    for f in &listed {
        let got = std::fs::read(dir.join(f)).unwrap();
        let want = std::fs::read(reference.join(f)).unwrap();
        assert!(
            got == want,
            "{f}: listed by particles.pvd but not the complete snapshot"
        );
    }
    for e in std::fs::read_dir(dir.join("probes")).unwrap() {
        let e = e.unwrap();
        let name = e.file_name().into_string().unwrap();
        if name.contains(".csv.tmp-") {
            continue; // killed while rewriting this CSV: not referenced, removed on resume
        }
        assert!(name.ends_with(".csv"), "stray file probes/{name}");
        let got = std::fs::read_to_string(e.path()).unwrap();
        let want = std::fs::read_to_string(reference.join("probes").join(&name)).unwrap();
        assert!(
            got.ends_with('\n') && want.starts_with(&got),
            "probes/{name} is not a clean prefix"
        );
    }
}

/// `wgsph resume DIR`; its standard output.
fn resume_cli(dir: &Path) -> String {
    let o = wgsph().arg("resume").arg(dir).output().unwrap();
    assert!(
        o.status.success(),
        "resume failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn a_run_killed_with_sigkill_leaves_complete_files_and_resumes_to_the_same_result() {
    let reference = reference_run();
    for (k, extra_ms) in [0u64, 150].into_iter().enumerate() {
        let dir = temp_dir(&format!("sigkill-{k}"));
        let mut child = spawn_run(&dir);
        wait_for_checkpoint(&dir, &mut child);
        std::thread::sleep(Duration::from_millis(extra_ms));
        child.kill().unwrap(); // SIGKILL on Unix
        child.wait().unwrap();
        assert_consistent_prefix(&dir, reference);
        resume_cli(&dir);
        // result_files() lists every file: no temporary file is left after the resume.
        assert_same_results(reference, &dir);
        assert_eq!(steps(reference), steps(&dir));
        // The resumed run kept checkpointing every 0.02 s, as the run was told (the default,
        // every 30 wall minutes, would have left the killed run's early checkpoint).
        let ck = wgsph::checkpoint::Checkpoint::read(&dir.join("checkpoint.bin")).unwrap();
        assert_eq!(ck.policy.and_then(|p| p.every_sim_s), Some(0.02));
        assert!(
            ck.time_s > 0.35,
            "the last checkpoint is at t = {} s",
            ck.time_s
        );
    }
}

#[cfg(unix)]
#[test]
fn ctrl_c_writes_a_checkpoint_and_stops_then_resume_completes() {
    let reference = reference_run();
    let dir = temp_dir("sigint");
    let mut child = spawn_run(&dir);
    wait_for_checkpoint(&dir, &mut child);
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "exit status after Ctrl-C");
    let summary = std::fs::read_to_string(dir.join("run.json")).unwrap();
    assert!(
        summary.contains("interrupted") && summary.contains("wgsph resume"),
        "{summary}"
    );
    // The checkpoint is the one taken when the run stopped, not an earlier periodic one.
    let json: serde_json::Value = serde_json::from_str(&summary).unwrap();
    let ck = wgsph::checkpoint::Checkpoint::read(&dir.join("checkpoint.bin")).unwrap();
    assert_eq!(ck.time_s, json["simulated_time_s"].as_f64().unwrap());
    assert_eq!(ck.solver.steps, json["steps"].as_u64().unwrap());
    assert_consistent_prefix(&dir, reference);
    resume_cli(&dir);
    assert_same_results(reference, &dir);
    // Resuming the completed run says so and computes nothing: every file stays as it is
    // (run.json's wall time included), with or without a checkpoint left.
    let before = result_files(&dir);
    let summary = std::fs::read(dir.join("run.json")).unwrap();
    for done in [&dir as &Path, reference] {
        let out = resume_cli(done);
        assert!(out.contains("already complete"), "{out}");
    }
    assert!(result_files(&dir) == before);
    assert_eq!(std::fs::read(dir.join("run.json")).unwrap(), summary);
}

#[test]
fn resume_refuses_a_different_case() {
    let sc = load(
        "cases/hydrostatic_2d.toml",
        &["time.end_s=0.05", "time.probe_every_s=0.01"],
    );
    let dir = temp_dir("other-case");
    let halted = RunOptions {
        halt_at_s: Some(0.02),
        ..RunOptions::default()
    };
    wgsph::run::run(gpu(), &sc, &dir, &halted, &mut LogLines::default()).unwrap();
    let resume = |set: &[&str]| {
        let sc = load("cases/hydrostatic_2d.toml", set);
        let opts = RunOptions::default();
        wgsph::run::resume(gpu(), &sc, &dir, &opts, &mut LogLines::default())
    };
    let refusal = |set: &[&str]| match resume(set) {
        Ok(_) => panic!("{set:?} must be refused"),
        Err(e) => format!("{e:#}"),
    };
    let msg = refusal(&["time.end_s=0.05", "particles.dx_m=0.025"]);
    assert!(
        msg.contains("different case") && msg.contains("checkpoint.bin"),
        "{msg}"
    );
    // An end before the checkpoint: nothing to compute, and said so rather than "completed"
    // (issue 64).
    let msg = refusal(&["time.end_s=0.01", "time.probe_every_s=0.01"]);
    assert!(msg.contains("past time.end_s = 0.01 s"), "{msg}");
    // A later end time is the same case: it extends the run.
    let r = resume(&["time.end_s=0.08", "time.probe_every_s=0.01"]).unwrap();
    assert!((r.summary.simulated_time_s - 0.08).abs() < 1e-12);
}

#[test]
fn a_lost_device_stops_the_solver_with_a_message() {
    crate::common::lavapipe_for_tests();
    let ctx =
        wgsph::gpu::GpuContext::new(wgsph::gpu::AdapterChoice::resolve(None).unwrap()).unwrap();
    let sc = load("cases/hydrostatic_2d.toml", &["time.end_s=0.05"]);
    let mut solver = wgsph::sph::Solver::new(&ctx, &sc).unwrap();
    solver.advance_to(0.01).unwrap();
    solver.lose_device();
    let e = solver
        .advance_to(0.02)
        .expect_err("stepping on a lost device must fail");
    let msg = format!("{e:#}");
    println!("{msg}");
    assert!(msg.contains("device was lost"), "{msg}");
}

/// A device lost in the middle of a run (driver reset): the run stops with the reason, writes
/// run.json saying how to resume, keeps its last checkpoint, and resuming on a working device
/// gives the uninterrupted run's result.
#[test]
fn a_device_lost_mid_run_keeps_the_last_checkpoint_and_resumes() {
    let sc = load(
        "cases/dam_break_2d.toml",
        &[
            "particles.dx_m=0.0146",
            "time.end_s=0.16",
            "time.output_every_s=0.04",
            "time.probe_every_s=0.01",
        ],
    );
    let straight = temp_dir("lost-straight");
    run_to_end(&sc, &straight);
    // Its own device: this one gets destroyed.
    crate::common::lavapipe_for_tests();
    let ctx =
        wgsph::gpu::GpuContext::new(wgsph::gpu::AdapterChoice::resolve(None).unwrap()).unwrap();
    let dir = temp_dir("lost");
    let opts = RunOptions {
        checkpoint: wgsph::checkpoint::CheckpointPolicy {
            every_sim_s: Some(0.04),
            every_wall_s: None,
        },
        lose_device_after_s: Some(0.1),
        ..RunOptions::default()
    };
    let r = wgsph::run::run(&ctx, &sc, &dir, &opts, &mut LogLines::default()).unwrap();
    let msg = format!("{:#}", r.stopped.expect("the run must stop"));
    assert!(msg.contains("device was lost"), "{msg}");
    let summary = std::fs::read_to_string(dir.join("run.json")).unwrap();
    assert!(
        summary.contains("stopped") && summary.contains("wgsph resume"),
        "{summary}"
    );
    let ck = wgsph::checkpoint::Checkpoint::read(&dir.join("checkpoint.bin")).unwrap();
    assert!(
        (ck.time_s - 0.08).abs() < 1e-9,
        "last checkpoint at {}",
        ck.time_s
    );
    let c = resume_to_end(&sc, &dir);
    assert!(c.stopped.is_none());
    assert_same_results(&straight, &dir);
}

#[test]
fn a_case_too_large_for_the_adapter_fails_before_the_run_starts() {
    crate::common::lavapipe_for_tests();
    let ctx = wgsph::gpu::GpuContext::with_limits(
        wgsph::gpu::AdapterChoice::resolve(None).unwrap(),
        |l| l.max_storage_buffer_binding_size = 16 * 1000,
    )
    .unwrap();
    let sc = load("cases/hydrostatic_2d.toml", &[]);
    assert!(sc.particles.len() > 1000);
    let dir = temp_dir("too-large");
    let e = wgsph::run::run(
        &ctx,
        &sc,
        &dir,
        &RunOptions::default(),
        &mut LogLines::default(),
    )
    .err()
    .expect("the case must not fit");
    let msg = format!("{e:#}");
    println!("{msg}");
    assert!(
        msg.contains(&format!("{} particles", sc.particles.len()))
            && msg.contains("fits at most 1000")
            && msg.contains("max_storage_buffer_binding_size"),
        "{msg}"
    );
    assert!(!dir.exists(), "nothing is written before the check");
}

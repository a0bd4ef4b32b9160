//! Sloshing in a pitching tank against Akyildiz & Unal (2006), Fig. 5 (layer 3): pressure at
//! transducers 2 and 8 (`cases/sloshing_2d.toml`). The comparison (of the fluctuations, with
//! the offset reported and transducer 2's mean checked against hydrostatics), its windows and
//! bounds are `wgsph validate`'s, src/validation/sloshing.rs.

use std::path::Path;

use wgsph::progress::LogLines;
use wgsph::run::RunOptions;
use wgsph::validation::sloshing::{
    dx_m, transducers, window, Comparison, MEAN_BOUND, P2_HYDROSTATIC_KPA,
};
use wgsph::validation::Mode;

fn run(case: &str, dx: &str, end: f64, tag: &str) -> crate::common::Scratch {
    let set = vec![
        format!("particles.dx_m={dx}"),
        format!("time.end_s={end}"),
        "time.output_every_s=1".to_string(),
    ];
    let sc = wgsph::case::load(Path::new(case), &set).unwrap();
    let dir = crate::common::Scratch::new(&format!("sloshing-{tag}"));
    let report = wgsph::run::run(
        crate::common::gpu(),
        &sc,
        &dir,
        &RunOptions::default(),
        &mut LogLines::default(),
    )
    .unwrap();
    assert!(report.stopped.is_none(), "{}", report.summary.status);
    dir
}

/// Transducers 2 and 8 of the run in `dir` over the window of `mode`, printed.
fn report(dir: &Path, mode: Mode) -> (Comparison, Comparison) {
    let w = window(mode);
    let (p2, p8) = transducers(dir, &w).unwrap();
    for (name, c) in [("transducer 2", &p2), ("transducer 8", &p8)] {
        println!(
            "{name}, t in [{}, {}] s, {} samples: fluctuation error {:.1} % of the \
             measured fluctuation, offset {:+.3} kPa, simulated mean {:.3} kPa",
            w.from_s,
            w.to_s,
            c.samples,
            100.0 * c.fluctuation_error,
            c.offset_kpa,
            c.sim_mean_kpa
        );
    }
    (p2, p8)
}

/// The bounds are `wgsph validate`'s (src/validation/sloshing.rs): quick here, full in the
/// ignored tests.
#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 2.5 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn sloshing_transducer_2_follows_the_experiment_coarse() {
    let w = window(Mode::Quick);
    let dir = run(
        "cases/sloshing_2d.toml",
        dx_m(Mode::Quick),
        w.to_s,
        "coarse",
    );
    // The first pitch period (t < π s) without the first half second of start-up.
    let (p2, _) = report(&dir, Mode::Quick);
    assert!(p2.samples >= 7);
    assert!(
        p2.fluctuation_error < w.bound_2,
        "transducer 2: fluctuation error {:.1} %",
        100.0 * p2.fluctuation_error
    );
    assert!(
        (p2.sim_mean_kpa - P2_HYDROSTATIC_KPA).abs() < MEAN_BOUND * P2_HYDROSTATIC_KPA,
        "mean {:.3} kPa vs hydrostatic {P2_HYDROSTATIC_KPA:.3} kPa",
        p2.sim_mean_kpa
    );
}

#[test]
#[ignore = "10 s of sloshing at dx = 0.465/46: 16 min on lavapipe; passes (measured 12.8 % and 21.5 %, docs/validation.md)"]
fn sloshing_transducers_follow_the_experiment_fine() {
    let w = window(Mode::Full);
    let dir = run("cases/sloshing_2d.toml", dx_m(Mode::Full), w.to_s, "fine");
    // As in the PySPH comparison of this case: after the start-up, t in [3, 10] s.
    let (p2, p8) = report(&dir, Mode::Full);
    assert!(p2.fluctuation_error < w.bound_2, "transducer 2");
    assert!(p8.fluctuation_error < w.bound_8.unwrap(), "transducer 8");
}

/// The experiment's own geometry, 3D (`cases/sloshing_3d.toml`), at its shipped dx = 0.02 m,
/// judged as the fine 2D run.
#[test]
#[ignore = "a GPU job: 10 s of the 3D tank at dx = 0.02 m (43 000 particles) is about 8 h on lavapipe; passes on an H200 in 26 s (2026-12-04: transducer 2 14.1 %, 8 28.3 %); at dx = 0.04 transducer 2 is 16.1 % off, 8 35.9 % (docs/validation.md)"]
fn sloshing_3d_transducers_follow_the_experiment() {
    let w = window(Mode::Full);
    let dir = run("cases/sloshing_3d.toml", "0.02", w.to_s, "3d");
    let (p2, p8) = report(&dir, Mode::Full);
    assert!(p2.fluctuation_error < w.bound_2, "transducer 2");
    assert!(p8.fluctuation_error < w.bound_8.unwrap(), "transducer 8");
}

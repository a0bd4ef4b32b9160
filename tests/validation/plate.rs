//! Oscillating cantilever plate (Gray, Monaghan & Swift 2001, section 6) against
//! Euler–Bernoulli theory: the measurement (the tip's zero crossings), the theory and the
//! bounds are `wgsph validate`'s, src/validation/plate.rs.

use crate::common::*;
use wgsph::scenario::*;
use wgsph::sph::Solver;
use wgsph::validation::plate::{
    zero_crossings, Cantilever, Oscillation, AMPLITUDE_BOUND, HALF_PERIOD_BOUND, PERIOD_BOUND,
    SHIPPED,
};

use std::path::Path;

/// The shipped plate (updated-Lagrangian, the seed's hypoelastic scheme).
const UL: &str = "cases/oscillating_plate_2d.toml";
/// The same plate with the total-Lagrangian formulation.
const TL: &str = "cases/oscillating_plate_tl_2d.toml";
/// A 3D beam of the plate's length and thickness, square cross-section, total-Lagrangian.
const BEAM_3D: &str = "cases/oscillating_beam_tl_3d.toml";
/// A plate half as thick (L/H = 20), of the default formulation (total Lagrangian).
const THIN: &str = "cases/oscillating_plate_thin_2d.toml";

/// The plate case `file` with `--set` overrides.
fn plate(file: &str, set: &[&str]) -> Scenario {
    let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    wgsph::case::load(Path::new(file), &set).unwrap()
}

/// The free-end particle nearest the mid-plane y = `mid` (the tip of a plate along x).
fn tip_of(sc: &Scenario, mid: f64) -> usize {
    sc.particles
        .iter()
        .enumerate()
        .max_by(|(_, a), (_, b)| {
            let key = |p: &Particle| p.pos[0] - 1e-3 * (p.pos[1] - mid).abs();
            key(a).partial_cmp(&key(b)).unwrap()
        })
        .unwrap()
        .0
}

/// Euler–Bernoulli's first-mode period of the plate of `sc` [s].
fn theory_period(sc: &Scenario) -> f64 {
    let m = &sc.solids.as_ref().unwrap().materials[0];
    Cantilever::of(sc).unwrap().period(m, sc.physics.dim)
}

/// Runs the plate to `end` and returns the tip's (t, y-displacement) every `every` seconds;
/// the tip is the free-end particle nearest the mid-plane.
fn tip_history(sc: &Scenario, end: f64, every: f64) -> Vec<(f64, f64)> {
    let tip = tip_of(sc, 0.5 * Cantilever::of(sc).unwrap().thickness);
    histories(sc, &[tip], end, every).remove(0)
}

/// Runs `sc` to `end` and returns the (t, y-displacement) of each particle of `ids` every
/// `every` seconds.
fn histories(sc: &Scenario, ids: &[usize], end: f64, every: f64) -> Vec<Vec<(f64, f64)>> {
    let mut solver = Solver::new(gpu(), sc).unwrap();
    let mut out = vec![vec![(0.0, 0.0)]; ids.len()];
    let steps = (end / every).round() as usize;
    for k in 1..=steps {
        let t = k as f64 * every;
        solver.advance_to(t).unwrap();
        let p = solver.read_particles().unwrap();
        for (h, &id) in out.iter_mut().zip(ids) {
            h.push((t, p.pos[id][1] - sc.particles[id].pos[1]));
        }
    }
    println!("{} steps, last dt {:.3e} s", solver.steps(), solver.dt());
    out
}

/// A plate run: the tip's oscillation (src/validation/plate.rs, as `wgsph validate` measures
/// it from the tracked point), here sampled from the particles every T/200 to 1.65 T.
struct PlateRun(Oscillation);

impl PlateRun {
    fn new(set: &[&str]) -> Self {
        Self::of(UL, set)
    }

    fn of(file: &str, set: &[&str]) -> Self {
        let sc = plate(file, set);
        let t_theory = theory_period(&sc);
        let history = tip_history(&sc, 1.65 * t_theory, t_theory / 200.0);
        Self(Oscillation::new(t_theory, history).unwrap())
    }

    /// A steady free oscillation: the two half periods of the first full cycle agree to 3 %,
    /// and the amplitude changes by less than `amplitude` (relative) over the cycle.
    fn assert_steady(&self, amplitude: f64) {
        let (h1, h2) = self.0.half_periods();
        assert!(
            self.0.half_period_mismatch().abs() < HALF_PERIOD_BOUND,
            "half periods {h1:.4} and {h2:.4} s"
        );
        let (first, third) = self.0.first_and_third_peaks();
        assert!(
            self.0.amplitude_change().abs() < amplitude,
            "amplitude went from {first:.4} to {third:.4} m in one period"
        );
    }

    fn error(&self) -> f64 {
        self.0.error()
    }

    fn report(&self, label: &str) {
        println!("{label}: {}", self.0.summary());
    }
}

/// The shipped case (H/dx = 5, tip velocity 0.01 c_s) runs through a full cycle and a half:
/// the tip crosses its rest position at least three times within 1.65 theory periods.
#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 1.5 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn plate_oscillates() {
    let run = PlateRun::new(&[]);
    run.report("H/dx = 5");
}

/// A steady free oscillation: the two half periods of the first full cycle agree to 3 %, and
/// the amplitude neither decays nor grows by more than 20 % over a cycle.
#[test]
#[ignore = "not met at H/dx = 5: half periods 0.1402 / 0.1449 s (3.4 %), tip peaks 0.0211 / 0.0268 / 0.0292 m (growing): the artificial stress does net work, +6.2 E0 in 1.65 T against −4.4 E0 by the viscosity (docs/validation.md)"]
fn plate_oscillates_steadily_h_over_dx_5() {
    let run = PlateRun::new(&[]);
    run.report("H/dx = 5");
    run.assert_steady(0.2);
}

/// Gray, Monaghan & Swift's test at the shipped resolution: the first-mode period within 5 %
/// of Euler–Bernoulli theory.
#[test]
#[ignore = "not met at H/dx = 5: period +12.2 %; without α and ε the plate is −6.5 % at H/dx = 5 but +21 to +25 % at even H/dx, not understood; ε, α move the period by ±20 % (docs/validation.md)"]
fn plate_period_within_5_percent_h_over_dx_5() {
    let run = PlateRun::new(&[]);
    run.report("H/dx = 5");
    assert!(
        run.error().abs() < PERIOD_BOUND,
        "period error {:.1} %",
        100.0 * run.error()
    );
}

/// The same at H/dx = 10 (dx = 2 mm): about 8 times the work of the shipped case.
#[test]
#[ignore = "not met: ≈ +23.6 % in the f64 twin (tools/plate_twin, same scheme); tens of CPU minutes on lavapipe"]
fn plate_period_within_5_percent_h_over_dx_10() {
    let run = PlateRun::new(&["particles.dx_m=0.002"]);
    run.report("H/dx = 10");
    assert!(
        run.error().abs() < PERIOD_BOUND,
        "period error {:.1} %",
        100.0 * run.error()
    );
}

/// The total-Lagrangian formulation (cases/oscillating_plate_tl_2d.toml) at the shipped
/// resolution: the first-mode period within 5 % of Euler–Bernoulli theory, and a steady
/// oscillation (no artificial viscosity or stress: nothing damps or feeds it), half periods
/// within 3 % and the amplitude within 5 % over the cycle.
#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 1.5 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn tl_plate_period_within_5_percent_h_over_dx_5() {
    tl_plate("TL, H/dx = 5", &[]);
}

/// Runs the total-Lagrangian plate with `overrides` and asserts its period, the agreement of
/// its half periods and the amplitude kept over the cycle.
fn tl_plate(label: &str, overrides: &[&str]) {
    tl_plate_of(TL, label, overrides);
}

/// [`tl_plate`] of the case `file`.
fn tl_plate_of(file: &str, label: &str, overrides: &[&str]) {
    let start = std::time::Instant::now();
    let run = PlateRun::of(file, overrides);
    run.report(label);
    println!("{:.1} s", start.elapsed().as_secs_f64());
    assert!(
        run.error().abs() < PERIOD_BOUND,
        "period error {:.1} %",
        100.0 * run.error()
    );
    run.assert_steady(AMPLITUDE_BOUND);
}

/// The tip's first zero crossing of the plate `file` (with `set`), run to 0.6 of its theory
/// period, against T/2: (crossing, error relative to T/2).
fn first_crossing(file: &str, set: &[&str]) -> (f64, f64) {
    let sc = plate(file, set);
    let t_theory = theory_period(&sc);
    let history = tip_history(&sc, 0.6 * t_theory, t_theory / 200.0);
    let first = *zero_crossings(&history)
        .first()
        .expect("the tip crossed its rest position");
    (first, 2.0 * first / t_theory - 1.0)
}

/// The thin plate (cases/oscillating_plate_thin_2d.toml, L = 0.2 m, H = 0.01 m, H/dx = 5, T =
/// 0.5081 s), of the default formulation, through half a period: the first zero crossing within
/// 5 % of T/2 (measured: 0.2591 s, +2.0 %; the full cycle is the next test).
#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 4 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn thin_plate_half_period_within_5_percent() {
    half_period_within_5_percent(THIN, "thin plate");
}

/// The first zero crossing of the plate `file` within 5 % of T/2 ([`first_crossing`]).
fn half_period_within_5_percent(file: &str, label: &str) {
    let (first, error) = first_crossing(file, &[]);
    println!(
        "{label}: first crossing {first:.4} s, {:+.1} % of T/2",
        100.0 * error
    );
    assert!(
        error.abs() < PERIOD_BOUND,
        "half-period error {:.1} %",
        100.0 * error
    );
}

/// The thin plate through a cycle and a half: period within 5 %, half periods within 3 % and
/// the amplitude within 5 % (measured: +2.0 %, half periods 0.2589 / 0.2592 s, peaks 0.02313 /
/// 0.02315 / 0.02311 m).
#[test]
#[ignore = "met but slow for CI: period +2.0 % at constant amplitude, 105 288 steps in 163 s on lavapipe; its first half period runs in CI"]
fn thin_plate_period_within_5_percent() {
    tl_plate_of(THIN, "thin plate, TL, H/dx = 5", &[]);
}

/// The thin plate with the seed's updated-Lagrangian solid (its default α = 0.1, ε = 0.3).
#[test]
#[ignore = "fails: period −18 % (crossings 0.154 / 0.418 / 0.570 s against T = 0.5081 s), the tip drifting off zero (peaks +12.4 / −25.8 mm); 225 s on lavapipe; docs/validation.md"]
fn ul_thin_plate_period_within_5_percent() {
    let run = PlateRun::of(THIN, &["solid[0].formulation=updated_lagrangian"]);
    run.report("thin plate, UL, H/dx = 5");
    assert!(
        run.error().abs() < PERIOD_BOUND,
        "period error {:.1} %",
        100.0 * run.error()
    );
}

/// The 3D beam (cases/oscillating_beam_tl_3d.toml, H/dx = 5, 1 625 particles) through half a
/// period: the tip's first zero crossing, T/2, within 5 % of Euler–Bernoulli beam theory's
/// (T = 0.2769 s). Half a period includes the start-up from the approximate mode shape; the
/// full-cycle run is the next test (measured: crossings at 0.1436 / 0.2872 s, +3.7 % both ways,
/// peaks ±0.0222 m).
#[test]
#[ignore = "met but slow for CI: first crossing +3.7 %, about 7 min on lavapipe beside another test (1 625 particles, the TL passes cost 13 us per particle-step); the 2D TL plate's period runs in CI"]
fn tl_beam_3d_half_period_within_5_percent() {
    half_period_within_5_percent(BEAM_3D, "TL 3D beam");
}

/// The 3D beam through a cycle and a half: period and steadiness as for the 2D plate.
#[test]
#[ignore = "met but slow: period +3.7 %, about 4 min on lavapipe"]
fn tl_beam_3d_period_within_5_percent() {
    tl_plate_of(BEAM_3D, "TL 3D beam, H/dx = 5", &[]);
}

/// The same at H/dx = 10 (dx = 2 mm; about 8 times the work).
#[test]
#[ignore = "met but slow: period +2.3 %, 46 427 steps in 210 s on lavapipe (2 shared cores)"]
fn tl_plate_period_within_5_percent_h_over_dx_10() {
    tl_plate("TL, H/dx = 10", &["particles.dx_m=0.002"]);
}

/// Two total-Lagrangian cantilevers of one shape in one case, of two materials: A (ρ = 1000,
/// E = 2 MPa) and B (ρ = 500, E = 4 MPa), ν = 0.3975 both, each set moving in its first mode
/// at 0.01 of its own sound speed. They are short (0.06 m free beyond a 0.02 m clamp, H/dx = 5,
/// 100 particles each) to keep the run short; beam theory does not describe such stubby
/// plates well, and nothing here needs it. With ν equal, the discrete equations of B are those
/// of A with time scaled by sqrt((ρ_B/E_B)/(ρ_A/E_A)) = 1/2 (the SVK stress is linear in E at
/// fixed ν; the mass is ρ dx^d), whatever the discretisation error (A's period is 21 % above
/// Euler–Bernoulli's for its free length): their half periods must
/// be in the ratio 2, which only holds if each body's particles use their own material. Left
/// to differ: the time integration (one dt for both, set by B's P-wave speed) and the
/// amplitude's nonlinearity (equal strains).
#[test]
fn plates_of_two_materials_ring_in_the_ratio_of_their_wave_speeds() {
    let plate = |name: &str, y0: f64, rho: f64, e: f64, tip: f64| {
        format!(
            r#"
[[solid]]
name = "{name}"
min_m = [0.0, {y0}]
max_m = [0.08, {y1}]
density_kg_m3 = {rho}
youngs_modulus_pa = {e}
poisson_ratio = 0.3975
formulation = "total_lagrangian"
clamped_min_m = [0.0, {y0}]
clamped_max_m = [0.02, {y1}]
[solid.initial_velocity]
kind = "cantilever_mode"
root_m = [0.02, {mid}]
axis = [1.0, 0.0]
direction = [0.0, 1.0]
length_m = 0.06
tip_velocity_m_s = {tip}
"#,
            y1 = y0 + SHIPPED.thickness,
            mid = y0 + 0.5 * SHIPPED.thickness
        )
    };
    let case = r#"name = "two_plates_2d"
dimension = 2
[particles]
dx_m = 0.004
h_over_dx = 1.3
kernel = "wendland_c2"
[physics]
gravity_m_s2 = [0.0, 0.0]
[time]
end_s = 0.1
output_every_s = 0.1
# Solids that could touch need a contact strength without gravity (they do not touch).
[walls]
repulsive_d_m2_s2 = 1.0
"#
    .to_string()
        // Tip velocities 0.01 c_s: c_s = 57.03 m/s for A, twice that for B.
        + &plate("a", 0.0, 1000.0, 2.0e6, 0.5703)
        + &plate("b", 0.06, 500.0, 4.0e6, 1.1406);
    let sc = wgsph::case::load_str(&case, "two_plates_2d.toml", &[]).unwrap();
    let mats = &sc.solids.as_ref().unwrap().materials;
    let (c_a, c_b) = (mats[0].sound_speed(), mats[1].sound_speed());
    assert!((c_b / c_a - 2.0).abs() < 1e-12, "{c_a} {c_b}");
    // Euler–Bernoulli for the free length, as a time scale.
    let t_a = SHIPPED.period(&mats[0], 2) * (0.06f64 / SHIPPED.length).powi(2);
    let h = SHIPPED.thickness;
    let tips = [tip_of(&sc, 0.5 * h), tip_of(&sc, 0.06 + 0.5 * h)];
    assert!(sc.particles[tips[1]].pos[1] > 0.06);
    let h = histories(&sc, &tips, 1.35 * t_a, t_a / 400.0);
    // Half periods after the start-up: A between its first two crossings, B over three.
    let (ca, cb) = (zero_crossings(&h[0]), zero_crossings(&h[1]));
    assert!(ca.len() >= 2 && cb.len() >= 4, "crossings {ca:?} {cb:?}");
    let half_a = ca[1] - ca[0];
    let half_b = (cb[3] - cb[0]) / 3.0;
    let ratio = half_a / half_b;
    println!(
        "half periods: A {half_a:.5} s, B {half_b:.5} s (Euler-Bernoulli for A {:.5} s); ratio \
         {ratio:.4}, of the wave speeds 2",
        0.5 * t_a
    );
    assert!(
        (ratio / 2.0 - 1.0).abs() < 0.01,
        "half-period ratio {ratio}"
    );
}

/// Solids of both formulations in one case: the shipped total-Lagrangian plate and, 0.1 m above
/// it, the shipped updated-Lagrangian one, each started in its first mode. Each tip follows the
/// run of its own case alone to 1e-4 of the swing, sampled every 0.01 s to 0.04 s (0.16 of a
/// period; measured: 7e-7 and 1.4e-5 of it to 0.06 s): the two passes each take their own solid,
/// with its own material. The runs differ only in their time steps (the shared one sees both
/// plates' velocities).
#[test]
fn plates_of_both_formulations_in_one_case_move_as_alone() {
    let both = both_plates_case();
    let sc = wgsph::case::load_str(&both, "plates.toml", &[]).unwrap();
    let tips = |sc: &Scenario| -> Vec<Vec<f64>> {
        let mut solver = Solver::new(gpu(), sc).unwrap();
        let x0: Vec<[f64; 3]> = sc
            .points
            .iter()
            .map(|p| sc.particles[p.particle as usize].pos)
            .collect();
        (1..=4)
            .map(|k| {
                solver.advance_to(0.01 * k as f64).unwrap();
                let x = solver.sample_points(None).unwrap();
                x.iter().zip(&x0).map(|(x, x0)| x[1] - x0[1]).collect()
            })
            .collect()
    };
    let mixed = tips(&sc);
    let tl_alone = tips(&plate(TL, &[]));
    let ul_alone = tips(&plate(UL, &[]));
    let mut worst = [0.0f64; 2];
    for k in 0..4 {
        for (w, (m, alone)) in worst
            .iter_mut()
            .zip([(mixed[k][0], tl_alone[k][0]), (mixed[k][1], ul_alone[k][0])])
        {
            assert!(m.is_finite());
            *w = w.max((m - alone).abs());
        }
    }
    let peak = mixed
        .iter()
        .map(|t| t[0].abs().max(t[1].abs()))
        .fold(0.0, f64::max);
    println!(
        "both formulations in one case: tip displacements at 0.01 … 0.04 s (TL, UL) {mixed:?}; \
         largest difference from the case alone: TL {:.2e} m, UL {:.2e} m (peak {peak:.4} m)",
        worst[0], worst[1]
    );
    assert!(peak > 0.015, "the plates did not swing: {peak} m");
    assert!(
        worst[0] < 1e-4 * peak && worst[1] < 1e-4 * peak,
        "the tips differ from their cases alone by {worst:?} m"
    );
}

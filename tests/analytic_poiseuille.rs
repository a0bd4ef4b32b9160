//! Start-up plane Poiseuille flow (Morris, Fox & Zhu 1997) in a channel periodic in x, with
//! no-slip walls as fixed ghosts (Shepard and MLS) and as mirror planes. Compared with the
//! series solution (tests/data/analytic_poiseuille_startup.csv: d = 1, ν = 100, F = 1000,
//! u_max = 1.25; the same parameters as jax-sph's validation).

use crate::common::*;
use wgsph::scenario::*;
use wgsph::sph::Solver;

const D: f64 = 1.0;
const NU: f64 = 100.0;
const F: f64 = 1000.0;

/// The series solution (the formula in the data file's header).
fn exact(y: f64, t: f64) -> f64 {
    let mut u = F / (2.0 * NU) * y * (D - y);
    for n in 0..200 {
        let k = (2 * n + 1) as f64;
        u -= 4.0 * F * D * D / (NU * std::f64::consts::PI.powi(3) * k.powi(3))
            * (k * std::f64::consts::PI * y / D).sin()
            * (-k * k * std::f64::consts::PI.powi(2) * NU * t / (D * D)).exp();
    }
    u
}

#[test]
fn series_matches_the_data_file() {
    let text = std::fs::read_to_string("tests/data/analytic_poiseuille_startup.csv").unwrap();
    let times = [0.0002, 0.001, 0.002, 0.01, 1.0];
    let mut rows = 0;
    for line in text.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        for (k, t) in times.iter().enumerate() {
            assert!(
                (exact(v[0], *t) - v[k + 1]).abs() < 1e-6,
                "y {} t {t}",
                v[0]
            );
        }
        rows += 1;
    }
    assert_eq!(rows, 21);
}

enum Walls {
    Ghost(GhostCorrection),
    Mirror,
}

/// L2 error (relative to the exact profile's norm) at each of `times`.
fn poiseuille(walls: Walls, times: &[f64]) -> Vec<f64> {
    let dx = D / 20.0;
    let mut ph = physics(2, dx, 12.5);
    ph.rho0 = 1.0;
    ph.particle_mass = dx * dx;
    ph.gravity = [F, 0.0, 0.0];
    ph.viscosity = Viscosity::Laminar { nu: NU };
    let lx = 0.5;
    let mut parts: Vec<Particle> = lattice(2, dx, [0.0; 3], [lx, D, 0.0])
        .into_iter()
        .map(|p| Particle {
            pos: p,
            vel: [0.0; 3],
            rho: 1.0,
            kind: Kind::Fluid,
        })
        .collect();
    let mut planes = Vec::new();
    match walls {
        Walls::Ghost(_) => {
            for layer in lattice(2, dx, [0.0, -3.0 * dx, 0.0], [lx, 0.0, 0.0])
                .into_iter()
                .chain(lattice(2, dx, [0.0, D, 0.0], [lx, D + 3.0 * dx, 0.0]))
            {
                parts.push(Particle {
                    pos: layer,
                    vel: [0.0; 3],
                    rho: 1.0,
                    kind: Kind::GhostNoSlip,
                });
            }
        }
        Walls::Mirror => {
            planes.push(MirrorPlane {
                point: [0.0; 3],
                normal: [0.0, 1.0, 0.0],
                no_slip: true,
            });
            planes.push(MirrorPlane {
                point: [0.0, D, 0.0],
                normal: [0.0, -1.0, 0.0],
                no_slip: true,
            });
        }
    }
    let domain = Domain {
        min: [0.0, -0.2, 0.0],
        max: [lx, D + 0.2, 0.0],
    };
    let mut sc = scenario(ph, parts, domain, vec![]);
    sc.periodic = [true, false, false];
    sc.walls.mirror_planes = planes;
    if let Walls::Ghost(c) = walls {
        sc.walls.ghost_correction = c;
    }
    let mut solver = Solver::new(gpu(), &sc).unwrap();
    let mut errors = Vec::new();
    for &t in times {
        solver.advance_to(t).unwrap();
        let p = solver.read_particles().unwrap();
        let (mut num, mut den) = (0.0, 0.0);
        for ((x, v), k) in p.pos.iter().zip(&p.vel).zip(&p.kind) {
            if *k == 0 {
                let u = exact(x[1], t);
                num += (v[0] as f64 - u).powi(2);
                den += u * u;
                assert!(
                    x[1] > 0.0 && x[1] < D,
                    "fluid particle left the channel: {x:?}"
                );
            }
        }
        errors.push((num / den).sqrt());
    }
    errors
}

const TIMES: [f64; 3] = [0.002, 0.005, 0.01];

fn check(name: &str, errors: &[f64]) {
    println!(
        "Poiseuille, {name}: L2 error {}",
        TIMES
            .iter()
            .zip(errors)
            .map(|(t, e)| format!("t = {t}: {:.2} %", 100.0 * e))
            .collect::<Vec<_>>()
            .join(", ")
    );
    for e in errors {
        assert!(*e < 0.05, "L2 error {:.2} % above 5 %", 100.0 * e);
    }
}

#[test]
fn poiseuille_fixed_ghost_mls() {
    check(
        "fixed_ghost MLS",
        &poiseuille(Walls::Ghost(GhostCorrection::Mls), &TIMES),
    );
}

#[test]
fn poiseuille_fixed_ghost_shepard() {
    check(
        "fixed_ghost Shepard",
        &poiseuille(Walls::Ghost(GhostCorrection::Shepard), &TIMES),
    );
}

#[test]
fn poiseuille_mirror() {
    check("mirror", &poiseuille(Walls::Mirror, &TIMES));
}

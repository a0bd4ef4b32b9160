//! The optional energy equation: GPU de/dt against the f64 reference, and conservation of
//! kinetic + internal energy in a closed block (pressure work and artificial-viscosity heating
//! appear in both the momentum and the energy sums, so their total is constant).

use crate::common::*;
use wgsph::reference;
use wgsph::scenario::*;
use wgsph::sph::Solver;

fn block(dim: u32, seed: u64, jitter: f64) -> Scenario {
    let dx = 0.02;
    let mut ph = physics(dim, dx, 15.0);
    ph.energy = true;
    ph.delta_sph = 0.0;
    ph.gravity = [0.0; 3];
    ph.viscosity = Viscosity::Artificial { alpha: 0.1 };
    let mut rng = Rng(seed);
    let max = if dim == 2 { [0.5, 0.5, 0.0] } else { [0.4; 3] };
    let min = if dim == 2 {
        [0.3, 0.3, 0.0]
    } else {
        [0.3, 0.3, 0.3]
    };
    let parts = lattice(dim, dx, min, max)
        .into_iter()
        .map(|p| {
            let mut pos = p;
            let mut vel = [0.0; 3];
            for a in 0..dim as usize {
                pos[a] += rng.range(-jitter, jitter) * dx;
                vel[a] = rng.range(-0.3, 0.3);
            }
            Particle {
                pos,
                vel,
                rho: 1000.0 * (1.0 + rng.range(0.0, 0.01)),
                kind: Kind::Fluid,
            }
        })
        .collect();
    let dmax = if dim == 2 { [0.8, 0.8, 0.0] } else { [0.7; 3] };
    scenario(
        ph,
        parts,
        Domain {
            min: [0.0; 3],
            max: dmax,
        },
        vec![],
    )
}

#[test]
fn energy_rate_matches_reference() {
    for dim in [2, 3] {
        let sc = block(dim, 3 + dim as u64, 0.2);
        let solver = Solver::new(gpu(), &sc).unwrap();
        let parts = gpu_particles(&solver);
        solver.rerun_interaction(false).unwrap();
        let gpu_de = solver.read_energy_rates().unwrap();
        let cpu = reference::interaction::interaction(
            &sc.physics,
            &sc.walls,
            &reference::Space::of(&sc),
            &parts,
        );
        let rms = (cpu.iter().map(|(_, e)| e * e).sum::<f64>() / cpu.len() as f64).sqrt();
        let worst = gpu_de
            .iter()
            .zip(&cpu)
            .map(|(g, (_, c))| {
                assert!(g.is_finite());
                (*g as f64 - c).abs() / rms
            })
            .fold(0.0, f64::max);
        println!("{dim}D: de/dt error {worst:.1e} of RMS {rms:.3e}");
        assert!(worst < 2e-4, "de/dt error {worst}");
    }
}

#[test]
fn kinetic_plus_internal_energy_is_conserved() {
    for dim in [2, 3] {
        let sc = block(dim, 17, 0.0);
        let m = sc.physics.particle_mass;
        let mut solver = Solver::new(gpu(), &sc).unwrap();
        let total = |s: &Solver| {
            let p = s.read_particles().unwrap();
            let e = p.energy.as_ref().expect("energy output");
            let kin: f64 = p
                .vel
                .iter()
                .map(|v| 0.5 * m * v.iter().map(|x| (*x as f64).powi(2)).sum::<f64>())
                .sum();
            let int: f64 = e.iter().map(|x| m * *x as f64).sum();
            (kin, int)
        };
        let (k0, i0) = total(&solver);
        let mut worst: f64 = 0.0;
        for k in 1..=10 {
            solver.advance_to(0.005 * k as f64).unwrap();
            let (kin, int) = total(&solver);
            worst = worst.max(((kin + int) - (k0 + i0)).abs() / k0);
        }
        let (kin, int) = total(&solver);
        println!("{dim}D: kinetic {k0:.4e} -> {kin:.4e} J, internal {i0:.1e} -> {int:.4e} J, worst drift {:.2e} of the initial kinetic energy, {} steps", worst, solver.steps());
        assert!(
            int.abs() > 1e-3 * k0,
            "the energy equation must exchange energy"
        );
        assert!(
            worst < 0.01,
            "total energy drifted by {:.2} %",
            100.0 * worst
        );
    }
}

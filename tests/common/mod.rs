//! Shared helpers of the GPU tests: one device per test binary, small scenarios built in code.
#![allow(dead_code)]

use std::sync::OnceLock;

use wgsph::gpu::{AdapterChoice, GpuContext};
use wgsph::scenario::*;

/// The adapter for tests: WGSPH_ADAPTER if set, else auto (lavapipe in CI). A missing adapter
/// is a failure, not a skip.
pub fn gpu() -> &'static GpuContext {
    static CTX: OnceLock<GpuContext> = OnceLock::new();
    CTX.get_or_init(|| {
        let choice = AdapterChoice::resolve(None).expect("WGSPH_ADAPTER");
        GpuContext::new(choice)
            .expect("a GPU or software (lavapipe) adapter is required for the tests")
    })
}

pub fn physics(dim: u32, dx: f64, c0: f64) -> Physics {
    let h = 1.3 * dx;
    let mut gravity = [0.0; 3];
    gravity[dim as usize - 1] = -9.81;
    Physics {
        dim,
        dx,
        h,
        kernel: KernelKind::WendlandC2,
        rho0: 1000.0,
        c0,
        gamma: 7.0,
        gravity,
        viscosity: Viscosity::Artificial { alpha: 0.02 },
        delta_sph: 0.1,
        particle_mass: 1000.0 * dx.powi(dim as i32),
        density_filter: DensityFilter::None,
        energy: false,
    }
}

/// Lattice points min + (i + ½)dx inside [min, max] (3 components, the unused one 0 in 2D).
pub fn lattice(dim: u32, dx: f64, min: [f64; 3], max: [f64; 3]) -> Vec<[f64; 3]> {
    let n: Vec<usize> = (0..3)
        .map(|a| {
            if a < dim as usize {
                ((max[a] - min[a]) / dx).round() as usize
            } else {
                1
            }
        })
        .collect();
    let mut out = Vec::new();
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let idx = [i, j, k];
                let p = [0, 1, 2].map(|a| {
                    if a < dim as usize {
                        min[a] + (idx[a] as f64 + 0.5) * dx
                    } else {
                        0.0
                    }
                });
                out.push(p);
            }
        }
    }
    out
}

pub fn scenario(
    physics: Physics,
    particles: Vec<Particle>,
    domain: Domain,
    probes: Vec<Probe>,
) -> Scenario {
    let physics_dx = physics.dx;
    Scenario {
        name: "test".into(),
        physics,
        time: TimeControl {
            end_s: 1.0,
            output_every_s: 0.1,
            probe_every_s: 0.1,
            cfl: 0.2,
        },
        walls: WallParams::defaults(physics_dx, 0.5, 9.81),
        periodic: [false; 3],
        domain,
        particles,
        probes,
    }
}

/// Simple xorshift so tests are reproducible without a dependency.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_f64(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }
}

//! Twin of shaders/lib/water_fraction.wgsl: the water's share of what the walls leave of the
//! kernel, the flood maps' and the depth gauges' criterion.

use super::{dot, kernel, sub, RefParticle, EXCLUDED, FLUID, INLET};
use crate::scenario::Physics;

/// The walls' share of the kernel beyond which ψ is not formed (`MAP_MAX_SOLID_SHARE`).
pub const MAP_MAX_SOLID_SHARE: f64 = 0.9;

/// The fluid's and the walls' shares of the kernel at a point, and the fluid's Σ v W V in plan.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MapSums {
    pub fluid: f64,
    pub solid: f64,
    pub momentum: [f64; 2],
}

pub fn map_sums(ph: &Physics, parts: &[RefParticle], x: [f64; 3]) -> MapSums {
    let mut s = MapSums::default();
    for p in parts {
        let d = sub(x, p.pos);
        let r2 = dot(d, d);
        if r2 >= 4.0 * ph.h * ph.h || p.kind == EXCLUDED || p.kind == INLET {
            continue;
        }
        let w = kernel::w(ph.kernel, ph.dim, ph.h, r2.sqrt());
        if p.kind == FLUID {
            let wv = w * ph.particle_mass / p.rho;
            s.fluid += wv;
            s.momentum[0] += wv * p.vel[0];
            s.momentum[1] += wv * p.vel[1];
        } else {
            s.solid += w * ph.particle_mass / ph.rho0;
        }
    }
    s
}

/// ψ = φ_f / (1 − φ_s), 0 inside the walls.
pub fn water_fraction(s: MapSums) -> f64 {
    if s.solid > MAP_MAX_SOLID_SHARE {
        return 0.0;
    }
    s.fluid / (1.0 - s.solid)
}

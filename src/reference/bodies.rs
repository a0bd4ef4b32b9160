//! Twin of shaders/bodies.wgsl: rigid placement of body particles and the per-body force and
//! torque sums, f64.

use glam::DVec3;

use super::{RefParticle, EXCLUDED};
use crate::body::{Load, Pose};
use crate::scenario::Physics;

/// Position and velocity of the body particle whose offset from the centre of mass at t = 0
/// is `r`: x = x_c + R r, u = u_c + ω × (R r).
pub fn body_move(pose: &Pose, r: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let arm = pose.rotation * DVec3::from_array(r);
    (
        (pose.center + arm).to_array(),
        (pose.velocity + pose.omega.cross(arm)).to_array(),
    )
}

/// Force Σ m a_a and torque Σ (x_a − x_c) × m a_a on each body from the rates of its particles
/// (excluded particles left out); `centers` are the bodies' centres of mass.
pub fn body_force(
    ph: &Physics,
    parts: &[RefParticle],
    rates: &[[f64; 4]],
    centers: &[DVec3],
) -> Vec<Load> {
    let mut out = vec![Load::default(); centers.len()];
    for (p, r) in parts.iter().zip(rates) {
        let Some(b) = p.body else { continue };
        if p.kind == EXCLUDED {
            continue;
        }
        let f = ph.particle_mass * DVec3::new(r[0], r[1], r[2]);
        let arm = DVec3::from_array(p.pos) - centers[b as usize];
        out[b as usize].force += f;
        out[b as usize].torque += arm.cross(f);
    }
    out
}

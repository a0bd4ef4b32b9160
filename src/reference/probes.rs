//! Twin of shaders/probes.wgsl.

use super::{dot, kernel, pressure, sub, RefParticle, EXCLUDED, FLUID, INLET};
use crate::scenario::{Physics, WallParams, WallPatch};

/// (Σ W V, Σ P W V) over fluid particles at x.
fn sums(ph: &Physics, parts: &[RefParticle], x: [f64; 3]) -> (f64, f64) {
    let mut vol = 0.0;
    let mut pw = 0.0;
    for p in parts.iter().filter(|p| p.kind == FLUID) {
        let d = sub(x, p.pos);
        let r2 = dot(d, d);
        if r2 < 4.0 * ph.h * ph.h {
            let wv = kernel::w(ph.kernel, ph.dim, ph.h, r2.sqrt()) * ph.particle_mass / p.rho;
            vol += wv;
            pw += pressure(ph, p.rho) * wv;
        }
    }
    (vol, pw)
}

/// Shepard-interpolated pressure; 0 where Σ W V < 0.1.
pub fn probe_pressure(ph: &Physics, parts: &[RefParticle], x: [f64; 3]) -> f64 {
    let (vol, pw) = sums(ph, parts, x);
    if vol < 0.1 {
        0.0
    } else {
        pw / vol
    }
}

/// Height above `base` of the highest point of the vertical line where Σ W V reaches ½,
/// stepping down by h/4 from `top` (the domain top) and interpolating linearly.
pub fn probe_height(ph: &Physics, parts: &[RefParticle], base: [f64; 3], top: f64) -> f64 {
    let up = ph.dim as usize - 1;
    let step = 0.25 * ph.h;
    let mut x = base;
    let (mut above, mut above_z) = (0.0, top);
    let mut z = top;
    while z >= base[up] {
        x[up] = z;
        let v = sums(ph, parts, x).0;
        if v >= 0.5 {
            if z == top {
                return z - base[up];
            }
            let t = (v - 0.5) / (v - above).max(1e-6);
            return z + (above_z - z) * t - base[up];
        }
        above = v;
        above_z = z;
        z -= step;
    }
    0.0
}

/// max over fluid of (x − origin)·axis (axis normalised).
pub fn probe_front(parts: &[RefParticle], origin: [f64; 3], axis: [f64; 3]) -> f64 {
    let n = dot(axis, axis).sqrt();
    parts
        .iter()
        .filter(|p| p.kind == FLUID)
        .map(|p| dot(sub(p.pos, origin), axis) / n)
        .fold(f64::NEG_INFINITY, f64::max)
}

/// Pressure on a wall patch: −m Σ_j a_j·n / area over the patch's boundary particles j
/// (`WallPatch`), a_j their rates from `interaction::rates` with `walls.reactions`; a fixed
/// wall's particle that belongs to a sensor of another face (`WallParams::sensor_of`) is left
/// out.
pub fn wall_pressure(
    ph: &Physics,
    walls: &WallParams,
    parts: &[RefParticle],
    rates: &[[f64; 4]],
    patch: &WallPatch,
) -> f64 {
    let elsewhere = |p: &RefParticle| {
        p.body.is_none()
            && walls
                .sensor_of(p.pos, ph.h)
                .is_some_and(|k| !walls.sensors[k].same_face(patch))
    };
    let sum: f64 = parts
        .iter()
        .zip(rates)
        .filter(|(p, _)| {
            !matches!(p.kind, FLUID | EXCLUDED | INLET) && !super::elastic::is_solid(p.kind)
        })
        .filter(|(p, _)| patch.holds(p.pos, ph.h) && !elsewhere(p))
        .map(|(_, r)| (0..3).map(|a| r[a] * patch.normal[a]).sum::<f64>())
        .sum();
    -ph.particle_mass * sum / patch.area
}

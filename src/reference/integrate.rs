//! Twin of shaders/integrate.wgsl: predictor, corrector and the time-step choice.

use super::{laminar_nu, sound_speed, RefParticle, FLUID, INLET, WALL};
use crate::scenario::Physics;

/// x_{n+1} = x + dt v + ½dt² a, v* = v + dt a, ρ* = ρ + dt Dρ (walls: only ρ, ≥ ρ0).
pub fn predict(ph: &Physics, p: &RefParticle, rate: [f64; 4], dt: f64) -> RefParticle {
    let mut out = *p;
    if p.kind == FLUID {
        for a in 0..3 {
            out.pos[a] += dt * p.vel[a] + 0.5 * dt * dt * rate[a];
            out.vel[a] += dt * rate[a];
        }
        out.rho += dt * rate[3];
    } else if p.kind == WALL {
        out.rho = (p.rho + dt * rate[3]).max(ph.rho0);
    }
    out
}

/// After the predictor: a fluid particle that crossed a mirror plane is reflected back,
/// position and normal velocity (as `predict` in integrate.wgsl).
pub fn reflect_at_mirrors(walls: &crate::scenario::WallParams, p: &RefParticle) -> RefParticle {
    let mut out = *p;
    if p.kind != FLUID {
        return out;
    }
    for plane in &walls.mirror_planes {
        let n = plane.normal;
        let d: f64 = (0..3).map(|a| (out.pos[a] - plane.point[a]) * n[a]).sum();
        if d < 0.0 {
            let vn: f64 = (0..3).map(|a| out.vel[a] * n[a]).sum();
            for a in 0..3 {
                out.pos[a] -= 2.0 * d * n[a];
                out.vel[a] -= 2.0 * vn * n[a];
            }
        }
    }
    out
}

/// v_{n+1} = v* + ½dt (a_{n+1} − a_n), likewise ρ (walls: only ρ, ≥ ρ0).
pub fn correct(
    ph: &Physics,
    predicted: &RefParticle,
    rate_new: [f64; 4],
    rate_old: [f64; 4],
    dt: f64,
) -> RefParticle {
    let mut out = *predicted;
    if predicted.kind == FLUID {
        for a in 0..3 {
            out.vel[a] += 0.5 * dt * (rate_new[a] - rate_old[a]);
        }
        out.rho += 0.5 * dt * (rate_new[3] - rate_old[3]);
    } else if predicted.kind == WALL {
        out.rho = (predicted.rho + 0.5 * dt * (rate_new[3] - rate_old[3])).max(ph.rho0);
    }
    out
}

/// CFL-limited dt: cfl·min(h / max(c_i + |v_i|) over fluid and walls, sqrt(h / max|a_i|)), and 0.125 h²/ν (laminar).
/// `rates` are the rates of the same particles.
pub fn timestep(ph: &Physics, cfl: f64, parts: &[RefParticle], rates: &[[f64; 4]]) -> f64 {
    let mut max_speed: f64 = 0.0;
    let mut max_accel: f64 = 0.0;
    for (p, r) in parts.iter().zip(rates) {
        let v = (p.vel[0] * p.vel[0] + p.vel[1] * p.vel[1] + p.vel[2] * p.vel[2]).sqrt();
        if p.kind == FLUID {
            max_speed = max_speed.max(sound_speed(ph, p.rho) + v);
            max_accel = max_accel.max((r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt());
        } else if p.kind == WALL || p.kind == INLET {
            // Moving walls (bodies) and inlet buffers count with their speed.
            max_speed = max_speed.max(sound_speed(ph, p.rho) + v);
        }
    }
    if max_speed == 0.0 {
        max_speed = ph.c0;
    }
    let mut dt = cfl * ph.h / max_speed;
    if max_accel > 0.0 {
        dt = dt.min(cfl * (ph.h / max_accel).sqrt());
    }
    if let Some(nu) = laminar_nu(ph) {
        dt = dt.min(0.125 * ph.h * ph.h / nu);
    }
    dt
}

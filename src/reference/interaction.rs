//! Twin of shaders/interaction.wgsl, brute force over all pairs (no cell list), f64.

use super::{dot, kernel, laminar_nu, pressure, sub, RefParticle, FLUID};
use crate::scenario::{Physics, Viscosity};

/// (dv/dt, dρ/dt) of every particle; walls get only dρ/dt.
pub fn rates(ph: &Physics, parts: &[RefParticle]) -> Vec<[f64; 4]> {
    let h = ph.h;
    let m = ph.particle_mass;
    let eta2 = 0.01 * h * h;
    let delta_coef = ph.delta_sph * h * ph.c0;
    let alpha = match ph.viscosity {
        Viscosity::Artificial { alpha } => alpha,
        Viscosity::Laminar { .. } => 0.0,
    };
    let nu = laminar_nu(ph);
    parts
        .iter()
        .enumerate()
        .map(|(i, pi)| {
            let fluid_i = pi.kind == FLUID;
            let p_i = pressure(ph, pi.rho) / (pi.rho * pi.rho);
            let mut acc = [0.0; 3];
            let mut drho = 0.0;
            for (j, pj) in parts.iter().enumerate() {
                let x_ij = sub(pi.pos, pj.pos);
                let r2 = dot(x_ij, x_ij);
                let fluid_j = pj.kind == FLUID;
                if j == i || r2 >= 4.0 * h * h || (!fluid_i && !fluid_j) {
                    continue;
                }
                let f_ij = kernel::f(ph.kernel, ph.dim, h, r2.sqrt());
                let dw = x_ij.map(|x| x * f_ij);
                let v_ij = sub(pi.vel, pj.vel);
                drho += m * dot(v_ij, dw);
                if !fluid_i {
                    continue;
                }
                if fluid_j {
                    drho +=
                        delta_coef * 2.0 * (pi.rho - pj.rho) * f_ij * r2 / (r2 + eta2) * m / pj.rho;
                }
                let mut pi_ij = 0.0;
                match nu {
                    None => {
                        let vx = dot(v_ij, x_ij);
                        if vx < 0.0 {
                            let mu = h * vx / (r2 + eta2);
                            pi_ij = -alpha * ph.c0 * mu / (0.5 * (pi.rho + pj.rho));
                        }
                    }
                    Some(nu) => {
                        let c = m * 4.0 * nu * r2 * f_ij / ((pi.rho + pj.rho) * (r2 + eta2));
                        for a in 0..3 {
                            acc[a] += c * v_ij[a];
                        }
                    }
                }
                let p_j = pressure(ph, pj.rho) / (pj.rho * pj.rho);
                for a in 0..3 {
                    acc[a] -= m * (p_i + p_j + pi_ij) * dw[a];
                }
            }
            if fluid_i {
                for a in 0..3 {
                    acc[a] += ph.gravity[a];
                }
            }
            [acc[0], acc[1], acc[2], drho]
        })
        .collect()
}

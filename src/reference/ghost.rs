//! Twin of shaders/ghost.wgsl: ghost pressure (as ρ) and velocity interpolated from the fluid.

use super::mls::{mls_add, mls_basis, mls_solve};
use super::{dot, kernel, pressure, RefParticle, Space, FLUID, GHOST_FREE_SLIP, GHOST_NO_SLIP};
use crate::scenario::{GhostCorrection, Physics, WallParams};

/// The MLS moment matrix Σ_j W_gj V_j b bᵀ, b = [1, x_gj/h], over fluid particles.
pub fn moment_matrix(
    ph: &Physics,
    space: &Space,
    parts: &[RefParticle],
    x: [f64; 3],
) -> [[f64; 4]; 4] {
    let mut a = [[0.0; 4]; 4];
    for j in parts.iter().filter(|p| p.kind == FLUID) {
        let d = space.sub(x, j.pos);
        let r = dot(d, d).sqrt();
        if r < 2.0 * ph.h {
            let wv = kernel::w(ph.kernel, ph.dim, ph.h, r) * ph.particle_mass / j.rho;
            mls_add(&mut a, ph.dim as usize, ph.h, d, wv);
        }
    }
    a
}

/// The fluid's pressure (with the hydrostatic correction along `g_eff` = g − a_wall) and
/// velocity interpolated at `x` with W^I (Shepard, or MLS where asked and well conditioned);
/// zeros with no fluid in reach.
pub fn fluid_at(
    ph: &Physics,
    walls: &WallParams,
    space: &Space,
    parts: &[RefParticle],
    x: [f64; 3],
    g_eff: [f64; 3],
) -> (f64, [f64; 3]) {
    let dim = ph.dim as usize;
    let h = ph.h;
    let mut a = [[0.0; 4]; 4];
    let mut m_p = [0.0; 4];
    let mut m_v = [[0.0; 4]; 3];
    for j in parts.iter().filter(|p| p.kind == FLUID) {
        let d = space.sub(x, j.pos);
        let r2 = dot(d, d);
        if r2 >= 4.0 * h * h {
            continue;
        }
        let wv = kernel::w(ph.kernel, ph.dim, h, r2.sqrt()) * ph.particle_mass / j.rho;
        let b = mls_basis(dim, h, d);
        let p = pressure(ph, j.rho) + j.rho * dot(g_eff, d);
        mls_add(&mut a, dim, h, d, wv);
        for r in 0..4 {
            m_p[r] += p * wv * b[r];
            for k in 0..3 {
                m_v[k][r] += j.vel[k] * wv * b[r];
            }
        }
    }
    if a[0][0] <= 1e-6 {
        return (0.0, [0.0; 3]);
    }
    let mut beta = [1.0 / a[0][0], 0.0, 0.0, 0.0];
    if walls.ghost_correction == GhostCorrection::Mls {
        if let Some(b) = mls_solve(dim, a) {
            beta = b;
        }
    }
    let d4 = |m: [f64; 4]| (0..4).map(|k| beta[k] * m[k]).sum::<f64>();
    (d4(m_p), [d4(m_v[0]), d4(m_v[1]), d4(m_v[2])])
}

/// Sets (v, ρ) of every ghost from the fluid; other particles are returned unchanged.
pub fn ghost_interpolate(
    ph: &Physics,
    walls: &WallParams,
    space: &Space,
    parts: &[RefParticle],
) -> Vec<RefParticle> {
    parts
        .iter()
        .map(|g| {
            if g.kind != GHOST_NO_SLIP && g.kind != GHOST_FREE_SLIP {
                return *g;
            }
            // A body's ghost carries the pressure along g − a_wall.
            let g_eff = [0, 1, 2].map(|a| ph.gravity[a] - g.wall_acc[a]);
            let (p, v) = fluid_at(ph, walls, space, parts, g.pos, g_eff);
            // The interpolated fluid velocity; interaction.rs makes the ghost velocities.
            let mut out = *g;
            out.vel = v;
            out.rho = ph.rho0 * (1.0 + p / ph.tait_b()).max(0.5).powf(1.0 / ph.gamma);
            out
        })
        .collect()
}

/// The interface pressure P_g of every elastic solid particle (the fluid pressure
/// interpolated at it, as for a ghost), 0 for the others.
pub fn solid_interface_pressure(
    ph: &Physics,
    walls: &WallParams,
    space: &Space,
    parts: &[RefParticle],
) -> Vec<f64> {
    parts
        .iter()
        .map(|s| {
            if super::is_solid(s.kind) {
                fluid_at(ph, walls, space, parts, s.pos, ph.gravity).0
            } else {
                0.0
            }
        })
        .collect()
}

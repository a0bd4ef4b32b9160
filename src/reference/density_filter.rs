//! Twin of shaders/density_filter.wgsl: density re-initialisation of the fluid by a Shepard or a
//! first-order MLS kernel interpolation (Colagrossi & Landrini 2003), brute force over all pairs.
//!
//! Shepard: ρ_i = Σ_j m_j W_ij / Σ_j W_ij V_j, V_j = m_j/ρ_j.
//! MLS:     ρ_i = Σ_j m_j W^MLS_ij, W^MLS_ij = (β0 + β·x_ij/h) W_ij, β = A⁻¹ e1,
//!          A = Σ_j W_ij V_j b_ij b_ijᵀ, b_ij = [1, x_ij/h] (`mls::mls_add`, as for the ghosts' `ghost::moment_matrix`).
//! j runs over i itself and every fluid, dynamic-wall and ghost particle within 2h; repulsive
//! and excluded particles carry no density and do not count. MLS falls back to Shepard when a
//! pivot of A is below `MLS_MIN_PIVOT`·A00 or when the MLS density is not positive and finite.

use super::mls::{mls_add, mls_solve, mls_weight};
use super::{dot, kernel, RefParticle, Space, FLUID, GHOST_FREE_SLIP, GHOST_NO_SLIP, INLET, WALL};
use crate::scenario::Physics;

/// Whether a neighbour of this kind enters the filter's sums.
pub fn counts(kind: u32) -> bool {
    matches!(kind, FLUID | WALL | INLET | GHOST_NO_SLIP | GHOST_FREE_SLIP)
}

/// (j, x_ij, W_ij V_j) of every counted particle within 2h of particle `i` (i itself included);
/// x_ij is the nearest image on periodic axes.
fn neighbours(
    ph: &Physics,
    space: &Space,
    parts: &[RefParticle],
    i: usize,
) -> Vec<(usize, [f64; 3], f64)> {
    let xi = parts[i].pos;
    parts
        .iter()
        .enumerate()
        .filter(|(j, p)| *j == i || counts(p.kind))
        .filter_map(|(j, p)| {
            let x = space.sub(xi, p.pos);
            let r = dot(x, x).sqrt();
            (r < 2.0 * ph.h).then(|| {
                (
                    j,
                    x,
                    kernel::w(ph.kernel, ph.dim, ph.h, r) * ph.particle_mass / p.rho,
                )
            })
        })
        .collect()
}

/// The MLS correction β of particle `i` (in the basis [1, x/h]), None where the moment matrix is
/// ill-conditioned (the Shepard fallback).
pub fn mls_beta(ph: &Physics, space: &Space, parts: &[RefParticle], i: usize) -> Option<[f64; 4]> {
    let dim = ph.dim as usize;
    let mut a = [[0.0; 4]; 4];
    for (_, x, wv) in neighbours(ph, space, parts, i) {
        mls_add(&mut a, dim, ph.h, x, wv);
    }
    mls_solve(dim, a)
}

/// W^MLS_ij V_j for every neighbour j of `i` (None where MLS falls back to Shepard): the weights
/// with which Σ_j f_j W^MLS_ij V_j reproduces linear fields f exactly.
pub fn mls_weights(
    ph: &Physics,
    space: &Space,
    parts: &[RefParticle],
    i: usize,
) -> Option<Vec<(usize, f64)>> {
    let beta = mls_beta(ph, space, parts, i)?;
    let dim = ph.dim as usize;
    Some(
        neighbours(ph, space, parts, i)
            .into_iter()
            .map(|(j, x, wv)| (j, mls_weight(beta, dim, ph.h, x) * wv))
            .collect(),
    )
}

/// The filtered density of particle `i` and whether MLS was used (false: Shepard).
pub fn filter_density(
    ph: &Physics,
    space: &Space,
    parts: &[RefParticle],
    i: usize,
    mls: bool,
) -> (f64, bool) {
    let nb = neighbours(ph, space, parts, i);
    // m_j W_ij = ρ_j (W_ij V_j).
    let (mw, wv) = nb.iter().fold((0.0, 0.0), |(mw, wv), &(j, _, w)| {
        (mw + parts[j].rho * w, wv + w)
    });
    let shepard = mw / wv;
    let shepard = if shepard.is_finite() && shepard > 0.0 {
        shepard
    } else {
        parts[i].rho
    };
    if mls {
        if let Some(w) = mls_weights(ph, space, parts, i) {
            let rho: f64 = w.iter().map(|&(j, w)| parts[j].rho * w).sum();
            if rho.is_finite() && rho > 0.0 {
                return (rho, true);
            }
        }
    }
    (shepard, false)
}

/// The densities after one filter: fluid particles filtered, all others unchanged.
pub fn filter(ph: &Physics, space: &Space, parts: &[RefParticle], mls: bool) -> Vec<f64> {
    (0..parts.len())
        .map(|i| {
            if parts[i].kind == FLUID {
                filter_density(ph, space, parts, i, mls).0
            } else {
                parts[i].rho
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{DensityFilter, KernelKind, Viscosity};

    fn physics(dim: u32, kernel: KernelKind) -> Physics {
        let dx = 0.02;
        Physics {
            dim,
            dx,
            h: 1.3 * dx,
            kernel,
            cell: None,
            id_low_bits: None,
            rho0: 1000.0,
            c0: 20.0,
            gamma: 7.0,
            gravity: [0.0; 3],
            viscosity: Viscosity::Artificial { alpha: 0.02 },
            delta_sph: 0.0,
            delta_sph_form: Default::default(),
            particle_mass: 1000.0 * dx.powi(dim as i32),
            density_filter: DensityFilter::Mls { every: 1 },
            energy: false,
        }
    }

    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        fn range(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.next()
        }
    }

    /// A jittered lattice block of n^dim fluid particles of spacing dx from the origin (so the
    /// block has free surfaces on every side), with random densities around ρ0.
    fn block(ph: &Physics, n: usize, jitter: f64, seed: u64) -> Vec<RefParticle> {
        let mut rng = Rng(seed);
        let dim = ph.dim as usize;
        let nz = if dim == 3 { n } else { 1 };
        let mut out = Vec::new();
        for k in 0..nz {
            for j in 0..n {
                for i in 0..n {
                    let idx = [i, j, k];
                    let pos = [0, 1, 2].map(|a| {
                        if a < dim {
                            (idx[a] as f64 + 0.5 + rng.range(-jitter, jitter)) * ph.dx
                        } else {
                            0.0
                        }
                    });
                    out.push(RefParticle {
                        pos,
                        vel: [0.0; 3],
                        rho: 1000.0 * (1.0 + rng.range(-0.02, 0.02)),
                        kind: FLUID,
                        body: None,
                        body_kinematic: false,
                        wall_vel: [0.0; 3],
                        wall_acc: [0.0; 3],
                    });
                }
            }
        }
        out
    }

    /// Distance from particle i to the nearest face of the block [0, n dx]^dim.
    fn depth(ph: &Physics, n: usize, p: &RefParticle) -> f64 {
        (0..ph.dim as usize)
            .map(|a| p.pos[a].min(n as f64 * ph.dx - p.pos[a]))
            .fold(f64::MAX, f64::min)
    }

    #[test]
    fn mls_reproduces_constant_and_linear_fields() {
        for dim in [2, 3] {
            for kernel in [KernelKind::WendlandC2, KernelKind::CubicSpline] {
                let ph = physics(dim, kernel);
                let n = if dim == 2 { 14 } else { 7 };
                let parts = block(&ph, n, 0.3, 11 + dim as u64);
                let f = |x: [f64; 3]| 2.5 + 3.0 * x[0] - 7.0 * x[1] + 4.0 * x[2];
                let (mut worst, mut used, mut near_surface) = (0.0f64, 0, 0);
                for i in 0..parts.len() {
                    let Some(w) = mls_weights(&ph, &Space::OPEN, &parts, i) else {
                        continue;
                    };
                    used += 1;
                    if depth(&ph, n, &parts[i]) < ph.h {
                        near_surface += 1;
                    }
                    let one: f64 = w.iter().map(|&(_, w)| w).sum();
                    let lin: f64 = w.iter().map(|&(j, w)| f(parts[j].pos) * w).sum();
                    worst = worst
                        .max((one - 1.0).abs())
                        .max((lin - f(parts[i].pos)).abs() / f(parts[i].pos).abs());
                }
                println!(
                    "dim {dim} {kernel:?}: MLS on {used}/{} particles ({near_surface} within h \
                     of a surface), worst error {worst:.1e}",
                    parts.len()
                );
                assert!(worst < 1e-12, "MLS reproduction error {worst}");
                assert!(
                    near_surface > parts.len() / 5,
                    "{near_surface} near the surface"
                );
                assert!(used > parts.len() * 3 / 4, "MLS used on {used}");
            }
        }
    }

    #[test]
    fn mls_reproduces_a_one_sided_neighbourhood() {
        // A particle on the free surface of a half-space: all its neighbours on one side.
        for dim in [2, 3] {
            let ph = physics(dim, KernelKind::WendlandC2);
            let n = if dim == 2 { 14 } else { 7 };
            let mut parts = block(&ph, n, 0.2, 5);
            let up = dim as usize - 1;
            let top = n as f64 * ph.dx;
            let mut i = 0;
            // The highest particle nearest the middle of the top face.
            for (k, p) in parts.iter().enumerate() {
                let d = |q: &RefParticle| {
                    (0..up).map(|a| (q.pos[a] - top / 2.0).abs()).sum::<f64>() - q.pos[up]
                };
                if d(p) < d(&parts[i]) {
                    i = k;
                }
            }
            parts[i].pos[up] = top;
            let lin = |x: [f64; 3]| 1000.0 * (1.0 + 0.3 * x[up]);
            for p in parts.iter_mut() {
                p.rho = lin(p.pos);
            }
            let (rho, used_mls) = filter_density(&ph, &Space::OPEN, &parts, i, true);
            let (shepard, _) = filter_density(&ph, &Space::OPEN, &parts, i, false);
            println!(
                "{dim}D surface particle: exact {:.6}, MLS {rho:.6}, Shepard {shepard:.6}",
                lin(parts[i].pos)
            );
            assert!(used_mls);
            assert!((rho - lin(parts[i].pos)).abs() < 1e-9);
            assert!((shepard - lin(parts[i].pos)).abs() > 1e-3);
        }
    }

    #[test]
    fn shepard_reproduces_constants_and_isolated_particles_keep_their_density() {
        for dim in [2, 3] {
            let ph = physics(dim, KernelKind::WendlandC2);
            let mut parts = block(&ph, 6, 0.3, 3);
            for p in parts.iter_mut() {
                p.rho = 1234.5;
            }
            for mls in [false, true] {
                for rho in filter(&ph, &Space::OPEN, &parts, mls) {
                    assert!((rho - 1234.5).abs() < 1e-9, "{rho}");
                }
            }
            // Alone, or with one neighbour: MLS is singular and falls back to Shepard.
            let far = RefParticle {
                pos: [1.0, 1.0, 0.0],
                vel: [0.0; 3],
                rho: 1010.0,
                kind: FLUID,
                body: None,
                body_kinematic: false,
                wall_vel: [0.0; 3],
                wall_acc: [0.0; 3],
            };
            let mut pair = vec![far, far];
            pair[1].pos[0] += 0.5 * ph.h;
            pair[1].rho = 990.0;
            let (rho, used_mls) = filter_density(&ph, &Space::OPEN, &pair[..1], 0, true);
            assert!(!used_mls && (rho - 1010.0).abs() < 1e-9, "{rho}");
            let (rho, used_mls) = filter_density(&ph, &Space::OPEN, &pair, 0, true);
            assert!(!used_mls && rho.is_finite() && rho > 990.0 && rho < 1010.0);
        }
    }
}

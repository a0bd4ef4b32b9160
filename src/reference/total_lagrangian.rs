//! Total-Lagrangian (TL) elastic solid, f64: the setup the solver uploads once (reference
//! neighbour lists and gradient weights) and the twin of shaders/total_lagrangian.wgsl's rate
//! (brute force over the fixed lists). The scheme is the one `tools/plate_twin` studied
//! (`tl=1 ls=2 gq=1`, its src/tl.rs): the plate period within +2.4…+4.4 % of Euler–Bernoulli at
//! H/dx = 5…10, energy conserving with velocity Verlet, no artificial viscosity or stress.
//!
//! Everything is measured on the reference lattice X (the initial positions), with a neighbour
//! list fixed at the start (same body, |X_j − X_i| < 2h; clamped particles included).
//!
//! Gradient weights: weighted least squares exact for quadratic fields (plate_twin `ls=2`).
//! With Δ = X_j − X_i, p_ij = [Δ/h, ½Δ⊗Δ/h²] (2D: Δx, Δy, ½Δx², ΔxΔy, ½Δy², over h, h²) and
//! the kernel weights W0_ij = W(|Δ|),
//!   A_i = Σ_j W0_ij p_ij p_ijᵀ,   w_ij = V γ_ij = W0_ij [A_i⁻¹ p_ij]_(first d rows) / h,
//! so that Σ_j (f_j − f_i) w_ij is the exact gradient of any quadratic f at X_i, also at the free
//! surface (where the kernel-corrected gradient of a bending field reads the strain at the
//! neighbours' centroid). The volume V = dx^d cancels: every sum below is written with w.
//!
//! Per evaluation (x the current positions, St Venant–Kirchhoff, plane strain in 2D with λ, G
//! of the 3D material):
//!   (1) H_i = Σ_j ((x_j − x_i) − (X_j − X_i)) ⊗ w_ij,  F_i = I + H_i,
//!       E_i = ½(FᵀF − I) = ½(H + Hᵀ + HᵀH)
//!   (2) D_i^k = Σ_j (E_j − E_i) w_ij^k,  T_i^k = (dx²/12)(λ tr D_i^k I + 2G D_i^k)
//!   (3) S2_i = Σ_j Σ_k (T_j^k w_ji^k − T_i^k w_ij^k),  S_i = λ tr E_i I + 2G E_i,
//!       P_i = F_i (S_i + S2_i)
//!   (4) ρ0 a_i = Σ_j (P_i w_ij − P_j w_ji)   (+ g)
//! (4) is the exact negative gradient of the discrete energy Σ_i V ψ(F_i) + V dx²/24 Σ_k
//! D_i^k : C : D_i^k. The second term is the cell quadrature term (plate_twin `gq=1`): the
//! energy of a strain that varies linearly across the particle's square cell, which the
//! one-point quadrature Σ V ψ(F_i) misses; for bending it restores the second moment of the
//! thickness, Σ dx z_j² = H³/12 (1 − (dx/H)²). Its stress reaches the momentum through S2.
//! Clamped particles are neighbours and get F and stress; the integrator does not move them.

use crate::lagrangian::{cauchy_of, mul, zero, TlSetup, M3};
use crate::scenario::{ElasticMaterial, Physics};

/// Lamé's λ and the shear modulus G of `m` (the 3D material; plane strain in 2D).
pub fn lame(m: &ElasticMaterial) -> (f64, f64) {
    (
        m.lame_lambda(),
        m.youngs_modulus / (2.0 * (1.0 + m.poisson_ratio)),
    )
}

fn mv(a: &M3, v: &[f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| (0..3).map(|c| a[r][c] * v[c]).sum())
}

/// λ tr M I + 2G M.
fn svk(m: &M3, lam: f64, g: f64) -> M3 {
    let t = m[0][0] + m[1][1] + m[2][2];
    let mut s = zero();
    for a in 0..3 {
        for b in 0..3 {
            s[a][b] = 2.0 * g * m[a][b] + if a == b { lam * t } else { 0.0 };
        }
    }
    s
}

/// Green strain ½(H + Hᵀ + HᵀH) of the displacement gradient H = F − I.
fn green(h: &M3) -> M3 {
    let mut e = zero();
    for a in 0..3 {
        for b in 0..3 {
            let hth: f64 = (0..3).map(|k| h[k][a] * h[k][b]).sum();
            e[a][b] = 0.5 * (h[a][b] + h[b][a] + hth);
        }
    }
    e
}

/// The displacement gradient H_i = F_i − I of every TL particle at current positions `x`,
/// step (1) of the header.
fn displacement_gradients(setup: &TlSetup, x: &[[f64; 3]]) -> Vec<M3> {
    (0..setup.len())
        .map(|i| {
            let mut h = zero();
            for p in setup.pairs_of(i) {
                let u = [0, 1, 2].map(|a| (x[p.j][a] - x[i][a]) - p.d0[a]);
                for a in 0..3 {
                    for b in 0..3 {
                        h[a][b] += u[a] * p.w_ij[b];
                    }
                }
            }
            h
        })
        .collect()
}

/// The first Piola–Kirchhoff stress P_i of every TL particle at current positions `x` (TL
/// numbering), steps (1)–(3) of the header, each of its body's material (`mats` indexed by
/// body).
pub fn first_piola(
    setup: &TlSetup,
    ph: &Physics,
    mats: &[ElasticMaterial],
    x: &[[f64; 3]],
) -> Vec<M3> {
    let n = setup.len();
    let dim = ph.dim as usize;
    let lame_of = |i: usize| lame(&mats[setup.body[i] as usize]);
    let k2 = ph.dx * ph.dx / 12.0;
    let hs = displacement_gradients(setup, x);
    let e: Vec<M3> = hs.iter().map(green).collect();
    let t: Vec<[M3; 3]> = (0..n)
        .map(|i| {
            let mut d = [zero(); 3];
            for p in setup.pairs_of(i) {
                for k in 0..dim {
                    for a in 0..3 {
                        for b in 0..3 {
                            d[k][a][b] += (e[p.j][a][b] - e[i][a][b]) * p.w_ij[k];
                        }
                    }
                }
            }
            let (lam, g) = lame_of(i);
            d.map(|dk| svk(&dk, lam, g).map(|r| r.map(|v| k2 * v)))
        })
        .collect();
    (0..n)
        .map(|i| {
            let (lam, g) = lame_of(i);
            let mut s = svk(&e[i], lam, g);
            for p in setup.pairs_of(i) {
                for k in 0..dim {
                    for a in 0..3 {
                        for b in 0..3 {
                            s[a][b] += t[p.j][k][a][b] * p.w_ji[k] - t[i][k][a][b] * p.w_ij[k];
                        }
                    }
                }
            }
            let mut f = hs[i];
            for a in 0..3 {
                f[a][a] += 1.0;
            }
            mul(&f, &s)
        })
        .collect()
}

/// [`cauchy_of`] every TL particle at current positions `x` (TL numbering).
pub fn cauchy(
    setup: &TlSetup,
    ph: &Physics,
    mats: &[ElasticMaterial],
    x: &[[f64; 3]],
) -> Vec<(M3, f64)> {
    let p = first_piola(setup, ph, mats, x);
    displacement_gradients(setup, x)
        .iter()
        .zip(&p)
        .map(|(h, p)| cauchy_of(h, p))
        .collect()
}

/// The discrete elastic energy at current positions `x` (per metre of depth in 2D):
/// Σ_i V [ψ(E_i) + dx²/24 Σ_k D_i^k : C : D_i^k], ψ(E) = ½λ (tr E)² + G E:E, V = dx^d; the
/// accelerations are its negative gradient over the particle masses ρ0 V.
pub fn energy(setup: &TlSetup, ph: &Physics, mats: &[ElasticMaterial], x: &[[f64; 3]]) -> f64 {
    let n = setup.len();
    let dim = ph.dim as usize;
    let vol = ph.dx.powi(ph.dim as i32);
    let k2 = ph.dx * ph.dx / 12.0;
    let dens = |(lam, g): (f64, f64), e: &M3| -> f64 {
        let t = e[0][0] + e[1][1] + e[2][2];
        let ee: f64 = (0..3)
            .flat_map(|a| (0..3).map(move |b| (a, b)))
            .map(|(a, b)| e[a][b] * e[a][b])
            .sum();
        0.5 * lam * t * t + g * ee
    };
    let e: Vec<M3> = (0..n)
        .map(|i| {
            let mut h = zero();
            for p in setup.pairs_of(i) {
                for a in 0..3 {
                    for b in 0..3 {
                        h[a][b] += ((x[p.j][a] - x[i][a]) - p.d0[a]) * p.w_ij[b];
                    }
                }
            }
            green(&h)
        })
        .collect();
    (0..n)
        .map(|i| {
            let lg = lame(&mats[setup.body[i] as usize]);
            let mut u = dens(lg, &e[i]);
            for k in 0..dim {
                let mut d = zero();
                for p in setup.pairs_of(i) {
                    for a in 0..3 {
                        for b in 0..3 {
                            d[a][b] += (e[p.j][a][b] - e[i][a][b]) * p.w_ij[k];
                        }
                    }
                }
                // ½ k2 D:C:D = k2 ψ(D)
                u += k2 * dens(lg, &d);
            }
            vol * u
        })
        .sum()
}

/// dv/dt of every TL particle at current positions `x` (TL numbering), gravity included
/// (clamped particles get theirs too; the integrator ignores it).
pub fn accelerations(
    setup: &TlSetup,
    ph: &Physics,
    mats: &[ElasticMaterial],
    x: &[[f64; 3]],
) -> Vec<[f64; 3]> {
    let p = first_piola(setup, ph, mats, x);
    (0..setup.len())
        .map(|i| {
            let mut f = [0.0; 3];
            for q in setup.pairs_of(i) {
                let a = mv(&p[i], &q.w_ij);
                let b = mv(&p[q.j], &q.w_ji);
                for c in 0..3 {
                    f[c] += a[c] - b[c];
                }
            }
            let rho0 = mats[setup.body[i] as usize].density;
            [0, 1, 2].map(|c| f[c] / rho0 + ph.gravity[c])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{DensityFilter, KernelKind, SolidFormulation, Viscosity};

    fn setup_2d(jitter: f64) -> (Physics, ElasticMaterial, Vec<[f64; 3]>, TlSetup) {
        let dx = 0.01;
        let ph = Physics {
            dim: 2,
            dx,
            h: 1.3 * dx,
            kernel: KernelKind::WendlandC2,
            cell: None,
            id_low_bits: None,
            rho0: 1000.0,
            c0: 10.0,
            gamma: 7.0,
            gravity: [0.0; 3],
            viscosity: Viscosity::Artificial { alpha: 0.0 },
            delta_sph: 0.0,
            delta_sph_form: Default::default(),
            particle_mass: 0.1,
            density_filter: DensityFilter::None,
            energy: false,
        };
        let m = ElasticMaterial {
            density: 1000.0,
            youngs_modulus: 2.0e6,
            poisson_ratio: 0.3975,
            alpha: 0.0,
            artificial_stress: 0.0,
            formulation: SolidFormulation::TotalLagrangian,
        };
        let mut x0 = Vec::new();
        let mut s = 7u64;
        for j in 0..8 {
            for i in 0..12 {
                let mut r = || {
                    s = s
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    ((s >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * jitter * dx
                };
                x0.push([
                    (i as f64 + 0.5) * dx + r(),
                    (j as f64 + 0.5) * dx + r(),
                    0.0,
                ]);
            }
        }
        let setup = TlSetup::new(&ph, &x0, &vec![0; x0.len()]).unwrap();
        (ph, m, x0, setup)
    }

    /// The weights differentiate quadratic fields exactly, at the surface too.
    #[test]
    fn weights_are_exact_for_quadratics() {
        let (_, _, x0, s) = setup_2d(0.3);
        let f = |x: &[f64; 3]| {
            0.3 + 2.0 * x[0] - x[1] + 5.0 * x[0] * x[0] + 3.0 * x[0] * x[1] - 4.0 * x[1] * x[1]
        };
        let grad = |x: &[f64; 3]| {
            [
                2.0 + 10.0 * x[0] + 3.0 * x[1],
                -1.0 + 3.0 * x[0] - 8.0 * x[1],
            ]
        };
        for i in 0..s.len() {
            let mut g = [0.0; 2];
            for p in s.pairs_of(i) {
                for c in 0..2 {
                    g[c] += (f(&x0[p.j]) - f(&x0[i])) * p.w_ij[c];
                }
            }
            let e = grad(&x0[i]);
            for c in 0..2 {
                assert!((g[c] - e[c]).abs() < 1e-9, "particle {i}: {g:?} vs {e:?}");
            }
        }
    }

    /// The same in 3D (the 9-term basis).
    #[test]
    fn weights_are_exact_for_quadratics_3d() {
        let (mut ph, _, _, _) = setup_2d(0.0);
        ph.dim = 3;
        let dx = ph.dx;
        let mut x0 = Vec::new();
        let mut s = 11u64;
        for k in 0..5 {
            for j in 0..6 {
                for i in 0..7 {
                    let mut r = || {
                        s = s
                            .wrapping_mul(6364136223846793005)
                            .wrapping_add(1442695040888963407);
                        ((s >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.3 * dx
                    };
                    x0.push([
                        (i as f64 + 0.5) * dx + r(),
                        (j as f64 + 0.5) * dx + r(),
                        (k as f64 + 0.5) * dx + r(),
                    ]);
                }
            }
        }
        let st = TlSetup::new(&ph, &x0, &vec![0; x0.len()]).unwrap();
        let f = |x: &[f64; 3]| {
            1.0 + x[0] - 2.0 * x[2] + 3.0 * x[0] * x[1] - x[1] * x[2] + 4.0 * x[2] * x[2]
        };
        let grad = |x: &[f64; 3]| {
            [
                1.0 + 3.0 * x[1],
                3.0 * x[0] - x[2],
                -2.0 - x[1] + 8.0 * x[2],
            ]
        };
        for i in 0..st.len() {
            let mut g = [0.0; 3];
            for p in st.pairs_of(i) {
                for c in 0..3 {
                    g[c] += (f(&x0[p.j]) - f(&x0[i])) * p.w_ij[c];
                }
            }
            let e = grad(&x0[i]);
            for c in 0..3 {
                assert!((g[c] - e[c]).abs() < 1e-8, "particle {i}: {g:?} vs {e:?}");
            }
        }
    }

    /// A strip two particles thick has no quadratic fit across it: refused, naming why.
    #[test]
    fn thin_solid_is_refused() {
        let (ph, _, _, _) = setup_2d(0.0);
        let x0: Vec<[f64; 3]> = (0..20)
            .map(|k| [(k / 2) as f64 * ph.dx, (k % 2) as f64 * ph.dx, 0.0])
            .collect();
        let err = TlSetup::new(&ph, &x0, &[0; 20]).unwrap_err();
        assert!(err.contains("singular") && err.contains("three"), "{err}");
    }

    /// A rigid rotation and translation is stress free; a uniform stretch gives the SVK stress.
    #[test]
    fn rigid_motion_is_force_free() {
        let (ph, m, x0, s) = setup_2d(0.3);
        let (c, sn) = (0.6f64.cos(), 0.6f64.sin());
        let x: Vec<[f64; 3]> = x0
            .iter()
            .map(|p| [c * p[0] - sn * p[1] + 0.3, sn * p[0] + c * p[1] - 0.1, 0.0])
            .collect();
        let a = accelerations(&s, &ph, &[m], &x);
        let amax = a
            .iter()
            .flat_map(|v| v.iter())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(amax < 1e-6, "{amax}");
    }

    /// The accelerations are the negative gradient of the discrete energy (checked by finite
    /// differences of the energy: ψ from P along a path, dE = −Σ m a·dx).
    #[test]
    fn force_is_conservative() {
        let (ph, m, x0, s) = setup_2d(0.2);
        let mut x = x0.clone();
        let mut r = 3u64;
        for p in &mut x {
            for a in 0..2 {
                r = r
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                p[a] += ((r >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 1e-3;
            }
        }
        // Work of the forces along x → x + t δ over t ∈ [0, 1] (Simpson) against the same path
        // reversed: a conservative force does none around the closed loop x → x + δ → x +
        // δ + ε → x + ε → x.
        let v = ph.dx * ph.dx;
        let work = |from: &[[f64; 3]], d: &[[f64; 3]]| -> f64 {
            let at = |t: f64| -> f64 {
                let xt: Vec<[f64; 3]> = from
                    .iter()
                    .zip(d)
                    .map(|(p, q)| [p[0] + t * q[0], p[1] + t * q[1], 0.0])
                    .collect();
                accelerations(&s, &ph, &[m], &xt)
                    .iter()
                    .zip(d)
                    .map(|(a, q)| m.density * v * (a[0] * q[0] + a[1] * q[1]))
                    .sum()
            };
            (at(0.0) + 4.0 * at(0.5) + at(1.0)) / 6.0
        };
        let delta: Vec<[f64; 3]> = (0..x.len())
            .map(|i| {
                [
                    1e-4 * ((i % 5) as f64 - 2.0),
                    1e-4 * ((i % 3) as f64 - 1.0),
                    0.0,
                ]
            })
            .collect();
        let eps: Vec<[f64; 3]> = (0..x.len())
            .map(|i| {
                [
                    -1e-4 * ((i % 7) as f64 - 3.0),
                    1e-4 * ((i % 4) as f64 - 1.5),
                    0.0,
                ]
            })
            .collect();
        let neg = |d: &[[f64; 3]]| d.iter().map(|q| q.map(|c| -c)).collect::<Vec<_>>();
        let add = |a: &[[f64; 3]], b: &[[f64; 3]]| {
            a.iter()
                .zip(b)
                .map(|(p, q)| [p[0] + q[0], p[1] + q[1], 0.0])
                .collect::<Vec<_>>()
        };
        let x1 = add(&x, &delta);
        let x2 = add(&x1, &eps);
        let x3 = add(&x, &eps);
        let w1 = work(&x, &delta);
        let loop_work = w1 + work(&x1, &eps) + work(&x2, &neg(&delta)) + work(&x3, &neg(&eps));
        assert!(w1.abs() > 0.0);
        assert!(
            loop_work.abs() < 1e-4 * w1.abs(),
            "loop {loop_work:e} against {w1:e}"
        );
    }
}

//! Twin of shaders/elastic.wgsl (hypoelastic solid particles, Gray, Monaghan & Swift 2001),
//! brute force over all pairs, f64. The equations: docs/equations.md eqs. 7, 8, 25–27.

use super::{dot, is_solid, kernel, RefParticle, Space};
use crate::scenario::{ContactGroup, ElasticMaterial, Physics, SolidFormulation};

type M3 = [[f64; 3]; 3];

/// The state of a solid particle beside its `RefParticle`: deviatoric stress τ
/// (xx, yy, zz, xy, xz, yz) [Pa] and its elastic body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolidRef {
    pub tau: [f64; 6],
    pub body: u32,
}

/// Rates of a solid particle: (dv/dt, dρ/dt) and dτ/dt (xx, yy, zz, xy, xz, yz).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElasticRates {
    pub rate: [f64; 4],
    pub dtau: [f64; 6],
}

/// τ as a symmetric 3×3 matrix.
pub fn tensor(t: &[f64; 6]) -> M3 {
    [[t[0], t[3], t[4]], [t[3], t[1], t[5]], [t[4], t[5], t[2]]]
}

/// The 6 independent components (xx, yy, zz, xy, xz, yz) of a symmetric matrix.
pub fn components(m: &M3) -> [f64; 6] {
    [m[0][0], m[1][1], m[2][2], m[0][1], m[0][2], m[1][2]]
}

fn mul(a: &M3, b: &M3) -> M3 {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            for k in 0..3 {
                c[i][j] += a[i][k] * b[k][j];
            }
        }
    }
    c
}

fn transpose(a: &M3) -> M3 {
    let mut t = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            t[i][j] = a[j][i];
        }
    }
    t
}

/// Eigenvalues and eigenvectors (columns of the second matrix) of the symmetric `a`, by cyclic
/// Jacobi rotations in f64 until the off-diagonal part is below 1e-15 of the norm (Press et
/// al., Numerical Recipes §11.1).
pub fn symmetric_eigen(a: &M3) -> ([f64; 3], M3) {
    let mut a = *a;
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let norm = a.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
    for _ in 0..50 {
        let off = 2.0 * (a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2));
        if off.sqrt() <= 1e-15 * norm {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A ← Jᵀ A J with the plane rotation J (cos, sin at pp, pq; −sin, cos at qp, qq).
            let mut j = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
            j[p][p] = c;
            j[q][q] = c;
            j[p][q] = s;
            j[q][p] = -s;
            a = mul(&transpose(&j), &mul(&a, &j));
            v = mul(&v, &j);
        }
    }
    ([a[0][0], a[1][1], a[2][2]], v)
}

/// Artificial stress R of a particle of total stress σ and density ρ (Monaghan 2000; GMS §4):
/// R = −(ε/ρ²) Σ_a max(σ_a, 0) n_a n_aᵀ over the principal stresses σ_a and directions n_a.
pub fn artificial_stress(eps: f64, sigma: &M3, rho: f64) -> M3 {
    let mut r = [[0.0; 3]; 3];
    if eps == 0.0 {
        return r;
    }
    let (lambda, v) = symmetric_eigen(sigma);
    let k = -eps / (rho * rho);
    for (e, l) in lambda.iter().enumerate() {
        for a in 0..3 {
            for b in 0..3 {
                r[a][b] += k * l.max(0.0) * v[a][e] * v[b][e];
            }
        }
    }
    r
}

/// σ/ρ² and R of a solid particle.
fn stress_terms(mat: &ElasticMaterial, p: &RefParticle, s: &SolidRef) -> (M3, M3) {
    let c2 = mat.sound_speed().powi(2);
    let pressure = c2 * (p.rho - mat.density);
    let mut sigma = tensor(&s.tau);
    for a in 0..3 {
        sigma[a][a] -= pressure;
    }
    let r = artificial_stress(mat.artificial_stress, &sigma, p.rho);
    (sigma.map(|row| row.map(|x| x / (p.rho * p.rho))), r)
}

/// Rates of every updated-Lagrangian solid particle (None for the others, total-Lagrangian
/// solids' included): continuity, momentum with σ = −pI + τ, artificial viscosity and
/// artificial stress, and the Jaumann rate of τ, over the solid particles of the same body, of
/// the body's material (`mats` indexed by body).
pub fn elastic_rates(
    ph: &Physics,
    mats: &[ElasticMaterial],
    space: &Space,
    parts: &[RefParticle],
    solid: &[SolidRef],
) -> Vec<Option<ElasticRates>> {
    let h = ph.h;
    let eta2 = 0.01 * h * h;
    let w_dx = kernel::w(ph.kernel, ph.dim, h, ph.dx);
    let terms: Vec<Option<(M3, M3)>> = parts
        .iter()
        .zip(solid)
        .map(|(p, s)| {
            let mat = &mats[s.body as usize];
            (is_solid(p.kind) && mat.formulation == SolidFormulation::UpdatedLagrangian)
                .then(|| stress_terms(mat, p, s))
        })
        .collect();
    (0..parts.len())
        .map(|i| {
            let pi = &parts[i];
            let (a_i, r_i) = terms[i]?;
            let mat = &mats[solid[i].body as usize];
            let m = mat.particle_mass(ph.dx, ph.dim);
            let c_s = mat.sound_speed();
            let mu_shear = mat.shear_modulus();
            let mut acc = [0.0; 3];
            let mut drho = 0.0;
            let mut grad_v = [[0.0; 3]; 3];
            for (j, pj) in parts.iter().enumerate() {
                if j == i || !is_solid(pj.kind) || solid[j].body != solid[i].body {
                    continue;
                }
                let x_ij = space.sub(pi.pos, pj.pos);
                let r2 = dot(x_ij, x_ij);
                let r = r2.sqrt();
                if r >= 2.0 * h {
                    continue;
                }
                let (a_j, r_j) = terms[j].expect("solid");
                let f = kernel::f(ph.kernel, ph.dim, h, r);
                let dw = x_ij.map(|x| x * f);
                let v_ij = [0, 1, 2].map(|a| pi.vel[a] - pj.vel[a]);
                drho += m * dot(v_ij, dw);
                let vx = dot(v_ij, x_ij);
                let pi_ij = if vx < 0.0 {
                    -mat.alpha * c_s * (h * vx / (r2 + eta2)) / (0.5 * (pi.rho + pj.rho))
                } else {
                    0.0
                };
                let fn4 = (kernel::w(ph.kernel, ph.dim, h, r) / w_dx).powi(4);
                for a in 0..3 {
                    for b in 0..3 {
                        let t = a_i[a][b] + a_j[a][b] + (r_i[a][b] + r_j[a][b]) * fn4
                            - if a == b { pi_ij } else { 0.0 };
                        acc[a] += m * t * dw[b];
                        // (∇v)^ab = Σ_j (m_j/ρ_j)(v_j − v_i)^a ∂_b W_ij
                        grad_v[a][b] += m / pj.rho * (pj.vel[a] - pi.vel[a]) * dw[b];
                    }
                }
            }
            let d = jaumann_stress_rate(&grad_v, &tensor(&solid[i].tau), mu_shear);
            Some(ElasticRates {
                rate: [
                    acc[0] + ph.gravity[0],
                    acc[1] + ph.gravity[1],
                    acc[2] + ph.gravity[2],
                    drho,
                ],
                dtau: components(&d),
            })
        })
        .collect()
}

/// The Jaumann rate of the deviatoric stress, eq. 7 (Gray, Monaghan & Swift 2001;
/// `jaumann_stress_rate`): 2μ (ε̇ − tr ε̇/3 I) + τ Ωᵀ + Ω τ, ε̇ and Ω the symmetric and
/// antisymmetric parts of the velocity gradient (eq. 8).
pub fn jaumann_stress_rate(grad_v: &M3, tau: &M3, mu: f64) -> M3 {
    let g = transpose(grad_v);
    let mut eps = [[0.0; 3]; 3];
    let mut omega = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            eps[a][b] = 0.5 * (grad_v[a][b] + g[a][b]);
            omega[a][b] = 0.5 * (grad_v[a][b] - g[a][b]);
        }
    }
    let tr3 = (eps[0][0] + eps[1][1] + eps[2][2]) / 3.0;
    let t1 = mul(tau, &transpose(&omega));
    let t2 = mul(&omega, tau);
    let mut d = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            let iso = if a == b { tr3 } else { 0.0 };
            d[a][b] = 2.0 * mu * (eps[a][b] - iso) + t1[a][b] + t2[a][b];
        }
    }
    d
}

/// The fluid–solid pair terms of interaction.wgsl (see its header): for every particle, the
/// (dv/dt, dρ/dt) it gets from neighbours of the other material (fluid from solid particles,
/// solid from fluid ones). A solid particle enters with its interface pressure `p_g`
/// (`ghost::solid_interface_pressure`), its own mass (its body's material, `mats` indexed by
/// `solid[k].body`), density and velocity; with the fluid's viscosity, and on the fluid side
/// the seed's density-rate correction ρ_i/ρ_j (a solid's density follows its own body only);
/// zero for the others.
pub fn interface_rates(
    ph: &Physics,
    mats: &[ElasticMaterial],
    space: &Space,
    parts: &[RefParticle],
    solid: &[SolidRef],
    p_g: &[f64],
) -> Vec<[f64; 4]> {
    let h = ph.h;
    let eta2 = 0.01 * h * h;
    let solid_mass = |k: usize| mats[solid[k].body as usize].particle_mass(ph.dx, ph.dim);
    // P/ρ² and mass of each particle that takes part (fluid or solid).
    let side = |k: usize| -> Option<(f64, f64)> {
        let p = &parts[k];
        if p.kind == super::FLUID {
            Some((
                super::pressure(ph, p.rho) / (p.rho * p.rho),
                ph.particle_mass,
            ))
        } else if is_solid(p.kind) {
            Some((p_g[k] / (p.rho * p.rho), solid_mass(k)))
        } else {
            None
        }
    };
    let alpha = match ph.viscosity {
        crate::scenario::Viscosity::Artificial { alpha } => alpha,
        crate::scenario::Viscosity::Laminar { .. } => 0.0,
    };
    (0..parts.len())
        .map(|i| {
            let mut r = [0.0; 4];
            let Some((b_i, _)) = side(i) else {
                return r;
            };
            let pi = &parts[i];
            for (j, pj) in parts.iter().enumerate() {
                if (pi.kind == super::FLUID) == (pj.kind == super::FLUID) {
                    continue;
                }
                let Some((b_j, m_j)) = side(j) else {
                    continue;
                };
                let x_ij = space.sub(pi.pos, pj.pos);
                let r2 = dot(x_ij, x_ij);
                if r2 >= 4.0 * h * h {
                    continue;
                }
                let f = kernel::f(ph.kernel, ph.dim, h, r2.sqrt());
                let dw = x_ij.map(|x| x * f);
                let v_ij = [0, 1, 2].map(|a| pi.vel[a] - pj.vel[a]);
                if pi.kind == super::FLUID {
                    // A solid's density follows its own body only.
                    r[3] += m_j * dot(v_ij, dw) * pi.rho / pj.rho;
                }
                // Π_ij (as −Π in the sum) or the laminar term.
                let (visc, laminar) = match super::laminar_nu(ph) {
                    None => {
                        let vx = dot(v_ij, x_ij);
                        let mu = h * vx / (r2 + eta2);
                        let rho_bar = 0.5 * (pi.rho + pj.rho);
                        (
                            if vx < 0.0 {
                                alpha * ph.c0 * mu / rho_bar
                            } else {
                                0.0
                            },
                            0.0,
                        )
                    }
                    Some(nu) => (0.0, 4.0 * nu * r2 * f / ((pi.rho + pj.rho) * (r2 + eta2))),
                };
                for a in 0..3 {
                    r[a] += m_j * ((visc - b_i - b_j) * dw[a] + laminar * v_ij[a]);
                }
            }
            r
        })
        .collect()
}

/// The factor of the contact law for the side of mass `m_self` whose partner has mass
/// `m_other`: the pair force is 2 m_self m_other/(m_self + m_other) times the law per unit
/// mass, equal and opposite (a moving body's particle carries the fluid's particle mass).
pub fn contact_weight(m_self: f64, m_other: f64) -> f64 {
    2.0 * m_other / (m_self + m_other)
}

/// Contact accelerations of solid particles (as `solid_loads` in interaction.wgsl) and of the
/// moving bodies' particles they touch; zero for the others. A solid particle feels the walls'
/// repulsive law with friction (`interaction::contact`, per unit mass) from every fixed wall particle
/// (times 1), every moving body's particle (whatever its treatment) and every particle of
/// another elastic body within 2h (times `contact_weight` of the two masses, each solid's of
/// its material, `mats` indexed by body); a body's particle the reaction of the solid's.
/// `solid` is indexed like `parts`.
pub fn contact_rates(
    ph: &Physics,
    mats: &[ElasticMaterial],
    walls: &crate::scenario::WallParams,
    space: &Space,
    parts: &[RefParticle],
    solid: &[SolidRef],
) -> Vec<[f64; 3]> {
    let m_s = |k: usize| mats[solid[k].body as usize].particle_mass(ph.dx, ph.dim);
    let m_f = ph.particle_mass;
    let support2 = 4.0 * ph.h * ph.h;
    let fixed_wall = |p: &RefParticle| {
        !matches!(p.kind, super::FLUID | super::EXCLUDED | super::INLET)
            && !is_solid(p.kind)
            && p.body.is_none()
    };
    let on_a_body = |p: &RefParticle| p.body.is_some() && p.kind != super::EXCLUDED;
    (0..parts.len())
        .map(|i| {
            let mut a = [0.0; 3];
            let pi = &parts[i];
            for (j, pj) in parts.iter().enumerate() {
                let solid_group = |k: usize| ContactGroup::Solid(solid[k].body as usize);
                let (k, groups) = if is_solid(pi.kind) {
                    if fixed_wall(pj) {
                        (1.0, [solid_group(i), ContactGroup::Walls])
                    } else if is_solid(pj.kind) && solid[j].body != solid[i].body {
                        (
                            contact_weight(m_s(i), m_s(j)),
                            [solid_group(i), solid_group(j)],
                        )
                    } else if on_a_body(pj) {
                        (
                            contact_weight(m_s(i), m_f),
                            [solid_group(i), super::interaction::contact_group(pj)],
                        )
                    } else {
                        continue;
                    }
                } else if on_a_body(pi) && is_solid(pj.kind) {
                    (
                        contact_weight(m_f, m_s(j)),
                        [super::interaction::contact_group(pi), solid_group(j)],
                    )
                } else {
                    continue;
                };
                let x_ij = space.sub(pi.pos, pj.pos);
                if j == i || dot(x_ij, x_ij) >= support2 {
                    continue;
                }
                let v_ij = [0, 1, 2].map(|a| {
                    super::interaction::contact_velocity(pi)[a]
                        - super::interaction::contact_velocity(pj)[a]
                });
                let mu = walls.friction_between(groups[0], groups[1]);
                let f = super::interaction::contact(ph, walls, mu, x_ij, v_ij);
                for c in 0..3 {
                    a[c] += k * f[c];
                }
            }
            a
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Q diag(λ) Qᵀ for the rotation of the unit quaternion (w, x, y, z).
    fn rotated(q: [f64; 4], lambda: [f64; 3]) -> (M3, M3) {
        let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        let [w, x, y, z] = q.map(|c| c / n);
        let r = [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - w * z),
                2.0 * (x * z + w * y),
            ],
            [
                2.0 * (x * y + w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - w * x),
            ],
            [
                2.0 * (x * z - w * y),
                2.0 * (y * z + w * x),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ];
        let d = [
            [lambda[0], 0.0, 0.0],
            [0.0, lambda[1], 0.0],
            [0.0, 0.0, lambda[2]],
        ];
        (mul(&r, &mul(&d, &transpose(&r))), r)
    }

    /// R is −(ε/ρ²) times the tensile part of σ, for stresses built from known principal
    /// values and directions (3D rotations, a 2D rotation about z, repeated values).
    #[test]
    fn artificial_stress_is_the_tensile_part() {
        let (eps, rho) = (0.3, 1100.0);
        let k = -eps / (rho * rho);
        for (q, lambda) in [
            ([0.9, 0.1, -0.3, 0.2], [3.0e4, -2.0e4, 1.0e4]),
            ([0.2, 0.7, 0.5, -0.4], [-5.0e3, -1.0e3, 2.0e5]),
            ([0.5, -0.5, 0.5, 0.5], [1.0e4, 1.0e4, -3.0e4]),
            ([0.8, 0.0, 0.0, 0.6], [2.0e4, -7.0e4, 0.0]),
            ([1.0, 0.3, 0.2, 0.1], [-1.0e4, -2.0e4, -3.0e4]),
        ] {
            let (sigma, _) = rotated(q, lambda);
            let (want, _) = rotated(q, lambda.map(|l| k * l.max(0.0)));
            let got = artificial_stress(eps, &sigma, rho);
            let scale = lambda.iter().fold(0.0f64, |m, l| m.max(l.abs())) * k.abs();
            for a in 0..3 {
                for b in 0..3 {
                    assert!(
                        (got[a][b] - want[a][b]).abs() <= 1e-12 * scale,
                        "λ {lambda:?}: R[{a}][{b}] = {} against {}",
                        got[a][b],
                        want[a][b]
                    );
                }
            }
        }
        assert_eq!(
            artificial_stress(0.0, &rotated([0.9, 0.1, -0.3, 0.2], [1e4; 3]).0, rho),
            [[0.0; 3]; 3]
        );
    }

    #[test]
    fn symmetric_eigen_diagonalises() {
        let (sigma, _) = rotated([0.3, -0.2, 0.9, 0.1], [7.0, -2.0, 3.5]);
        let (mut lambda, v) = symmetric_eigen(&sigma);
        // Vᵀ σ V is diagonal with the eigenvalues.
        let d = mul(&transpose(&v), &mul(&sigma, &v));
        for a in 0..3 {
            for b in 0..3 {
                let want = if a == b { lambda[a] } else { 0.0 };
                assert!((d[a][b] - want).abs() < 1e-13, "{d:?}");
            }
        }
        lambda.sort_by(f64::total_cmp);
        assert!(
            (lambda[0] + 2.0).abs() < 1e-13 && (lambda[2] - 7.0).abs() < 1e-13,
            "{lambda:?}"
        );
    }
}

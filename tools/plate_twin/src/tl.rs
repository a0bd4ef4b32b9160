//! Total-Lagrangian solid (experiment, not in wgsph; option `tl=1|2`).
//!
//! Everything is measured on the reference lattice X (the initial positions): the neighbour
//! lists, the kernel gradients ∇W0_ij = ∇_i W(|X_i − X_j|), the volumes V = dx² and the
//! correction B_i = M_i⁻¹, M_i = Σ_j V (X_j − X_i) ⊗ ∇W0_ij (identity with `tlb=0`), so that
//! g_ij = B_iᵀ ∇W0_ij reproduces the gradient of any linear field. The deformation gradient
//! comes from the current positions, F_i = Σ_j V (x_j − x_i) ⊗ g_ij, and the momentum is the
//! exact negative gradient of the discrete elastic energy Σ_i V ψ(F_i):
//!
//!   ρ0 a_i = Σ_j V (P_i B_iᵀ + P_j B_jᵀ) ∇W0_ij        (tl=1; P = ∂ψ/∂F, first Piola–Kirchhoff)
//!
//! so that, with a symplectic kick–drift–kick step, the energy is conserved up to the O(dt²)
//! oscillation of velocity Verlet. Materials (plane strain, λ and G of the 3D material):
//! `mat=svk` St Venant–Kirchhoff P = F (λ tr E I + 2G E), E = ½(FᵀF − I) (default);
//! `mat=neo` compressible neo-Hookean P = G (F − F⁻ᵀ) + λ ln J F⁻ᵀ; `mat=lin` P = λ tr ε I + 2G ε,
//! ε = sym(F − I).
//!
//! `ls=1|2` replaces B_iᵀ∇W0 by weighted-least-squares gradient weights (weights W0_ij,
//! basis Δ, ½Δ⊗Δ for ls=2): F_i = Σ_j (x_j − x_i) ⊗ γ_ij is then exact for quadratic
//! displacements also at the free surface, where the B-corrected gradient of a bending field
//! (u_x = −z w′) reads the strain at the neighbours' centroid, below the surface. The momentum
//! stays the exact adjoint: ρ0 V a_i = Σ_j V (P_i γ_ij − P_j γ_ji).
//! `gq=1` adds V dx²/24 Σ_k ∂_kE : C : ∂_kE per particle (E the Green strain, ∂_kE by the same
//! weights), the energy of a strain that varies linearly across the particle's square cell, which
//! the one-point (midpoint) quadrature Σ V ψ(F_i) misses: for bending it restores the second
//! moment of the thickness, Σ dx z_j² = H³/12 (1 − (dx/H)²). Its stress reaches the momentum
//! through S2 (two more neighbour passes: ∂_kE, then S2).
//!
//! tl=2 is the decomposed ("essentially non-hourglass", Wu, Zhang & Adams 2023) form with the
//! neo-Hookean material: ∇·(G F) = G ∇0² x is taken by the pairwise SPH Laplacian
//! 2 Σ_j V (x_i − x_j) W'(R)/R and only the rest, (λ ln J − G) F⁻ᵀ, by the gradient form above
//! (a coefficient `zeta` on the Laplacian, 1 by default). Also variational: the Laplacian is a
//! set of pair springs. It does not work here: with B in the gradient part the reference state
//! is not force free at the surface (the Laplacian is uncorrected), without B it is not stress
//! free; either way the plate collapses or drifts (SPHinXsys uses B in F only, and ζ = 1.07).
//!
//! Hourglass control (Ganzenmüller 2015, stiffness type; `hgc=α`): each pair is pulled towards
//! the relative position that the two deformation gradients predict,
//!   f_i += Σ_j c_ij e_ij,  e_ij = (x_j − x_i) − ½ (F_i + F_j)(X_j − X_i),
//!   c_ij = α E V² W0_ij / R_ij²,
//! (`hgproj=1` keeps only the component of e_ij along x_j − x_i, as in the paper). With
//! `hgx=1` the force is the exact gradient of the penalty energy ½ Σ_pairs c_ij |e_ij|²: it adds
//! the part that goes through F, Q_i = −(1/2V) Σ_j c_ij e_ij ⊗ (X_j − X_i), to P_i in the
//! momentum (one more neighbour pass).
use crate::{fk, w, Kern, E, NU, RHO0};

pub type M2 = [[f64; 2]; 2];

#[derive(Clone, Copy, PartialEq)]
pub enum Mat {
    Svk,
    Neo,
    Lin,
}

#[derive(Clone)]
pub struct TlCfg {
    pub mode: u32,
    pub mat: Mat,
    pub corrected: bool,
    /// 0: B_iᵀ∇W0 (default); 1, 2: weighted least squares (weights V W0) exact for
    /// polynomials of degree 1 or 2
    pub ls: u32,
    pub zeta: f64,
    pub hgc: f64,
    pub hgproj: bool,
    pub hgx: bool,
    /// add the energy of the strain's variation across each particle's square cell,
    /// V dx²/24 Σ_k ∂_kE : C : ∂_kE, so that the particle quadrature of Σ V ψ is exact for
    /// strains linear in space (bending); ∂_kE by the same γ as F
    pub gq: bool,
}

struct Pair {
    j: usize,
    /// X_j − X_i
    dx0: [f64; 2],
    /// B_iᵀ ∇W0_ij and B_jᵀ ∇W0_ij
    gi: [f64; 2],
    gj: [f64; 2],
    /// W0'(R)/R (∇_i W0_ij = −dx0 · fr)
    fr: f64,
    /// hourglass stiffness c_ij
    c: f64,
}

pub struct Tl {
    cfg: TlCfg,
    nb: Vec<Vec<Pair>>,
    vol: f64,
    lam: f64,
    mu: f64,
    lap_ref: f64,
    dx: f64,
}

fn inv(m: &M2) -> M2 {
    let d = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    [[m[1][1] / d, -m[0][1] / d], [-m[1][0] / d, m[0][0] / d]]
}
/// Inverse of the leading n×n block (Gauss–Jordan with partial pivoting).
fn inv_n(a: &[[f64; 5]; 5], n: usize) -> [[f64; 5]; 5] {
    let mut m = *a;
    let mut r = [[0.0; 5]; 5];
    for i in 0..n {
        r[i][i] = 1.0;
    }
    for c in 0..n {
        let p = (c..n)
            .max_by(|&x, &y| m[x][c].abs().partial_cmp(&m[y][c].abs()).unwrap())
            .unwrap();
        m.swap(c, p);
        r.swap(c, p);
        let d = m[c][c];
        for k in 0..n {
            m[c][k] /= d;
            r[c][k] /= d;
        }
        for row in 0..n {
            if row != c {
                let f = m[row][c];
                for k in 0..n {
                    m[row][k] -= f * m[c][k];
                    r[row][k] -= f * r[c][k];
                }
            }
        }
    }
    r
}
fn mul(a: &M2, b: &M2) -> M2 {
    let mut c = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            c[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j];
        }
    }
    c
}
fn tr(a: &M2) -> M2 {
    [[a[0][0], a[1][0]], [a[0][1], a[1][1]]]
}
fn mv(a: &M2, v: &[f64; 2]) -> [f64; 2] {
    [
        a[0][0] * v[0] + a[0][1] * v[1],
        a[1][0] * v[0] + a[1][1] * v[1],
    ]
}
fn det(a: &M2) -> f64 {
    a[0][0] * a[1][1] - a[0][1] * a[1][0]
}

impl Tl {
    /// `x0`: reference positions, `nb`: reference neighbour lists.
    pub fn new(cfg: TlCfg, x0: &[[f64; 2]], nb: &[Vec<usize>], kern: Kern, h: f64, dx: f64) -> Tl {
        let vol = dx * dx;
        let n = x0.len();
        let grad = |i: usize, j: usize| {
            let d = [x0[i][0] - x0[j][0], x0[i][1] - x0[j][1]];
            let r = (d[0] * d[0] + d[1] * d[1]).sqrt();
            let f = fk(kern, h, r);
            ([d[0] * f, d[1] * f], f, r)
        };
        let b: Vec<M2> = (0..n)
            .map(|i| {
                if !cfg.corrected {
                    return [[1.0, 0.0], [0.0, 1.0]];
                }
                let mut m = [[0.0; 2]; 2];
                for &j in &nb[i] {
                    let (dw, _, _) = grad(i, j);
                    for a in 0..2 {
                        for c in 0..2 {
                            m[a][c] += vol * (x0[j][a] - x0[i][a]) * dw[c];
                        }
                    }
                }
                inv(&m)
            })
            .collect();
        // γ_ij/V: F_i = Σ_j (x_j − x_i) ⊗ γ_ij
        let gam: Vec<Vec<[f64; 2]>> = (0..n)
            .map(|i| {
                if cfg.ls == 0 {
                    return nb[i]
                        .iter()
                        .map(|&j| mv(&tr(&b[i]), &grad(i, j).0))
                        .collect();
                }
                let np = if cfg.ls == 1 { 2 } else { 5 };
                let basis = |j: usize| {
                    let d = [(x0[j][0] - x0[i][0]) / h, (x0[j][1] - x0[i][1]) / h];
                    [
                        d[0],
                        d[1],
                        0.5 * d[0] * d[0],
                        d[0] * d[1],
                        0.5 * d[1] * d[1],
                    ]
                };
                let mut a = [[0.0; 5]; 5];
                for &j in &nb[i] {
                    let (_, _, r) = grad(i, j);
                    let pj = basis(j);
                    let wj = w(kern, h, r);
                    for k in 0..np {
                        for l in 0..np {
                            a[k][l] += wj * pj[k] * pj[l];
                        }
                    }
                }
                let ainv = inv_n(&a, np);
                nb[i]
                    .iter()
                    .map(|&j| {
                        let (_, _, r) = grad(i, j);
                        let pj = basis(j);
                        let wj = w(kern, h, r);
                        let mut g = [0.0; 2];
                        for c in 0..2 {
                            for l in 0..np {
                                g[c] += ainv[c][l] * pj[l] * wj / (h * vol);
                            }
                        }
                        g
                    })
                    .collect()
            })
            .collect();
        let nb = (0..n)
            .map(|i| {
                nb[i]
                    .iter()
                    .enumerate()
                    .map(|(k, &j)| {
                        let (_, f, r) = grad(i, j);
                        let kj = nb[j].iter().position(|&q| q == i).unwrap();
                        Pair {
                            j,
                            dx0: [x0[j][0] - x0[i][0], x0[j][1] - x0[i][1]],
                            gi: gam[i][k],
                            gj: [-gam[j][kj][0], -gam[j][kj][1]],
                            fr: f,
                            c: cfg.hgc * E * vol * vol * w(kern, h, r) / (r * r),
                        }
                    })
                    .collect()
            })
            .collect();
        let mu = E / (2.0 * (1.0 + NU));
        let lam = E * NU / ((1.0 + NU) * (1.0 - 2.0 * NU));
        let mut t = Tl {
            cfg,
            nb,
            vol,
            lam,
            mu,
            lap_ref: 0.0,
            dx,
        };
        t.lap_ref = t.lap_energy(x0);
        t
    }

    pub fn deformation(&self, x: &[[f64; 2]]) -> Vec<M2> {
        (0..x.len())
            .map(|i| {
                let mut f = [[0.0; 2]; 2];
                for p in &self.nb[i] {
                    for a in 0..2 {
                        for c in 0..2 {
                            f[a][c] += self.vol * (x[p.j][a] - x[i][a]) * p.gi[c];
                        }
                    }
                }
                f
            })
            .collect()
    }

    /// The stress that enters the gradient-form momentum (P, or for tl=2 the non-Laplacian part).
    fn stress(&self, f: &M2) -> M2 {
        let (l, g) = (self.lam, self.mu);
        if self.cfg.mode == 2 {
            let fit = tr(&inv(f));
            let s = l * det(f).ln() - g;
            return fit.map(|r| r.map(|x| s * x));
        }
        match self.cfg.mat {
            Mat::Svk => {
                let c = mul(&tr(f), f);
                let e = [
                    [0.5 * (c[0][0] - 1.0), 0.5 * c[0][1]],
                    [0.5 * c[1][0], 0.5 * (c[1][1] - 1.0)],
                ];
                let t = e[0][0] + e[1][1];
                let s = [
                    [l * t + 2.0 * g * e[0][0], 2.0 * g * e[0][1]],
                    [2.0 * g * e[1][0], l * t + 2.0 * g * e[1][1]],
                ];
                mul(f, &s)
            }
            Mat::Neo => {
                let fit = tr(&inv(f));
                let lj = det(f).ln();
                let mut p = [[0.0; 2]; 2];
                for a in 0..2 {
                    for b in 0..2 {
                        p[a][b] = g * (f[a][b] - fit[a][b]) + l * lj * fit[a][b];
                    }
                }
                p
            }
            Mat::Lin => {
                let e = [
                    [f[0][0] - 1.0, 0.5 * (f[0][1] + f[1][0])],
                    [0.5 * (f[0][1] + f[1][0]), f[1][1] - 1.0],
                ];
                let t = e[0][0] + e[1][1];
                [
                    [l * t + 2.0 * g * e[0][0], 2.0 * g * e[0][1]],
                    [2.0 * g * e[1][0], l * t + 2.0 * g * e[1][1]],
                ]
            }
        }
    }

    /// Strain energy density of the gradient-form part.
    fn psi(&self, f: &M2) -> f64 {
        let (l, g) = (self.lam, self.mu);
        if self.cfg.mode == 2 {
            let lj = det(f).ln();
            return -g * lj + 0.5 * l * lj * lj;
        }
        match self.cfg.mat {
            Mat::Svk => {
                let c = mul(&tr(f), f);
                let e = [
                    [0.5 * (c[0][0] - 1.0), 0.5 * c[0][1]],
                    [0.5 * c[1][0], 0.5 * (c[1][1] - 1.0)],
                ];
                let t = e[0][0] + e[1][1];
                0.5 * l * t * t
                    + g * (e[0][0] * e[0][0] + e[1][1] * e[1][1] + 2.0 * e[0][1] * e[0][1])
            }
            Mat::Neo => {
                let lj = det(f).ln();
                let i1 =
                    f[0][0] * f[0][0] + f[0][1] * f[0][1] + f[1][0] * f[1][0] + f[1][1] * f[1][1];
                0.5 * g * (i1 - 2.0 - 2.0 * lj) + 0.5 * l * lj * lj
            }
            Mat::Lin => {
                let e = [
                    [f[0][0] - 1.0, 0.5 * (f[0][1] + f[1][0])],
                    [0.5 * (f[0][1] + f[1][0]), f[1][1] - 1.0],
                ];
                let t = e[0][0] + e[1][1];
                0.5 * l * t * t
                    + g * (e[0][0] * e[0][0] + e[1][1] * e[1][1] + 2.0 * e[0][1] * e[0][1])
            }
        }
    }

    fn lap_energy(&self, x: &[[f64; 2]]) -> f64 {
        if self.cfg.mode != 2 {
            return 0.0;
        }
        // Σ_pairs −ζ G V² W'/R |x_i − x_j|² (each pair once: half the double sum)
        let mut e = 0.0;
        for (i, ps) in self.nb.iter().enumerate() {
            for p in ps {
                let d = [x[i][0] - x[p.j][0], x[i][1] - x[p.j][1]];
                e -= 0.5
                    * self.cfg.zeta
                    * self.mu
                    * self.vol
                    * self.vol
                    * p.fr
                    * (d[0] * d[0] + d[1] * d[1]);
            }
        }
        e
    }

    /// Adds F S2 to the stresses and returns the energy of the gradient term.
    fn gradient_quadrature(&self, f: &[M2], ps: &mut [M2]) -> f64 {
        let n = f.len();
        let (l, g) = (self.lam, self.mu);
        let green: Vec<M2> = f
            .iter()
            .map(|fi| {
                let c = mul(&tr(fi), fi);
                [
                    [0.5 * (c[0][0] - 1.0), 0.5 * c[0][1]],
                    [0.5 * c[1][0], 0.5 * (c[1][1] - 1.0)],
                ]
            })
            .collect();
        let k2 = self.dx * self.dx / 12.0;
        let mut energy = 0.0;
        // T_ik = ∂ψ2/∂(∂_kE) = dx²/12 (λ tr D I + 2G D)
        let t: Vec<[M2; 2]> = (0..n)
            .map(|i| {
                let mut d = [[[0.0; 2]; 2]; 2];
                for p in &self.nb[i] {
                    for k in 0..2 {
                        for a in 0..2 {
                            for b in 0..2 {
                                d[k][a][b] +=
                                    self.vol * (green[p.j][a][b] - green[i][a][b]) * p.gi[k];
                            }
                        }
                    }
                }
                let mut t = [[[0.0; 2]; 2]; 2];
                for k in 0..2 {
                    let trd = d[k][0][0] + d[k][1][1];
                    let dd = d[k][0][0] * d[k][0][0]
                        + d[k][1][1] * d[k][1][1]
                        + 2.0 * d[k][0][1] * d[k][0][1];
                    energy += self.vol * 0.5 * k2 * (l * trd * trd + 2.0 * g * dd);
                    for a in 0..2 {
                        for b in 0..2 {
                            t[k][a][b] =
                                k2 * (if a == b { l * trd } else { 0.0 } + 2.0 * g * d[k][a][b]);
                        }
                    }
                }
                t
            })
            .collect();
        for m in 0..n {
            let mut s2 = [[0.0; 2]; 2];
            for p in &self.nb[m] {
                for k in 0..2 {
                    for a in 0..2 {
                        for b in 0..2 {
                            s2[a][b] -=
                                self.vol * (t[p.j][k][a][b] * p.gj[k] + t[m][k][a][b] * p.gi[k]);
                        }
                    }
                }
            }
            let add = mul(&f[m], &s2);
            for a in 0..2 {
                for b in 0..2 {
                    ps[m][a][b] += add[a][b];
                }
            }
        }
        energy
    }

    fn hg_err(&self, x: &[[f64; 2]], f: &[M2], i: usize, p: &Pair) -> [f64; 2] {
        let fm = [
            [
                0.5 * (f[i][0][0] + f[p.j][0][0]),
                0.5 * (f[i][0][1] + f[p.j][0][1]),
            ],
            [
                0.5 * (f[i][1][0] + f[p.j][1][0]),
                0.5 * (f[i][1][1] + f[p.j][1][1]),
            ],
        ];
        let pred = mv(&fm, &p.dx0);
        let d = [x[p.j][0] - x[i][0], x[p.j][1] - x[i][1]];
        let e = [d[0] - pred[0], d[1] - pred[1]];
        if self.cfg.hgproj {
            let r2 = d[0] * d[0] + d[1] * d[1];
            let s = (e[0] * d[0] + e[1] * d[1]) / r2;
            [s * d[0], s * d[1]]
        } else {
            e
        }
    }

    /// Accelerations (zero on clamped particles) and the elastic energy.
    pub fn accel(&self, x: &[[f64; 2]], clamped: &[bool]) -> (Vec<[f64; 2]>, f64) {
        let n = x.len();
        let f = self.deformation(x);
        let mut ps: Vec<M2> = f.iter().map(|fi| self.stress(fi)).collect();
        let mut energy: f64 = f.iter().map(|fi| self.vol * self.psi(fi)).sum();
        if self.cfg.gq {
            energy += self.gradient_quadrature(&f, &mut ps);
        }
        energy += self.lap_energy(x) - self.lap_ref;
        let hg = self.cfg.hgc != 0.0;
        if hg {
            for i in 0..n {
                let mut q = [[0.0; 2]; 2];
                for p in &self.nb[i] {
                    let e = self.hg_err(x, &f, i, p);
                    energy += 0.25 * p.c * (e[0] * e[0] + e[1] * e[1]);
                    for a in 0..2 {
                        for b in 0..2 {
                            q[a][b] -= 0.5 * p.c * e[a] * p.dx0[b] / self.vol;
                        }
                    }
                }
                if self.cfg.hgx {
                    for a in 0..2 {
                        for b in 0..2 {
                            ps[i][a][b] += q[a][b];
                        }
                    }
                }
            }
        }
        let acc = (0..n)
            .map(|i| {
                if clamped[i] {
                    return [0.0; 2];
                }
                let mut fo = [0.0; 2];
                for p in &self.nb[i] {
                    let a1 = mv(&ps[i], &p.gi);
                    let a2 = mv(&ps[p.j], &p.gj);
                    for a in 0..2 {
                        // ∇_i W0_ij = −dx0 W'/R: the stored g are B ∇_i W0_ij
                        fo[a] += self.vol * self.vol * (a1[a] + a2[a]);
                    }
                    if self.cfg.mode == 2 {
                        for a in 0..2 {
                            fo[a] += 2.0
                                * self.cfg.zeta
                                * self.mu
                                * self.vol
                                * self.vol
                                * p.fr
                                * (x[i][a] - x[p.j][a]);
                        }
                    }
                    if hg {
                        let e = self.hg_err(x, &f, i, p);
                        for a in 0..2 {
                            fo[a] += p.c * e[a];
                        }
                    }
                }
                [fo[0] / (RHO0 * self.vol), fo[1] / (RHO0 * self.vol)]
            })
            .collect();
        (acc, energy)
    }
}

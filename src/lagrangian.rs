//! The total-Lagrangian solid's reference lattice, f64: the neighbour lists and quadratic
//! least-squares gradient weights built once on the host (the solver uploads them, the f64
//! reference sums over them), and the Cauchy stress of a particle from its deformation (the
//! solver's particle outputs). Neutral ground: it uses neither the solver nor the reference.
//!
//! Gradient weights: weighted least squares exact for quadratic fields. With Δ = X_j − X_i,
//! p_ij = [Δ/h, ½Δ⊗Δ/h²] and the kernel weights W0_ij = W(|Δ|),
//!   A_i = Σ_j W0_ij p_ij p_ijᵀ,   w_ij = V γ_ij = W0_ij [A_i⁻¹ p_ij]_(first d rows) / h,
//! so that Σ_j (f_j − f_i) w_ij is the exact gradient of any quadratic f at X_i, also at the free
//! surface (docs/equations.md, the total-Lagrangian solid).

// Matrix code reads better with index loops.
#![allow(clippy::needless_range_loop)]

use crate::kernel;
use crate::scenario::Physics;

/// A 3×3 matrix, rows first.
pub type M3 = [[f64; 3]; 3];

/// One entry of particle i's reference neighbour list.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TlPairRef {
    /// Index (in the TL numbering) of the neighbour j.
    pub j: usize,
    /// X_j − X_i.
    pub d0: [f64; 3],
    /// w_ij = V γ_ij and w_ji = V γ_ji (the weight of i in j's list).
    pub w_ij: [f64; 3],
    pub w_ji: [f64; 3],
}

/// The reference neighbour lists of the TL particles, in compressed rows: particle i's pairs
/// are `pairs[start[i]..start[i + 1]]`.
#[derive(Clone, Debug, PartialEq)]
pub struct TlSetup {
    pub start: Vec<usize>,
    pub pairs: Vec<TlPairRef>,
    /// The elastic body of every particle (its material's index).
    pub body: Vec<u32>,
}

/// Solves for the inverse of the n×n matrix `a` (Gauss–Jordan, partial pivoting); None when a
/// pivot falls below 1e-12 of the largest diagonal entry (a singular fit).
fn inverse(mut a: Vec<Vec<f64>>) -> Option<Vec<Vec<f64>>> {
    let n = a.len();
    let scale = (0..n).map(|i| a[i][i].abs()).fold(0.0, f64::max);
    let mut r: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|k| (i == k) as u8 as f64).collect())
        .collect();
    for c in 0..n {
        let p = (c..n)
            .max_by(|&x, &y| a[x][c].abs().total_cmp(&a[y][c].abs()))
            .expect("n > 0");
        if a[p][c].abs() <= 1e-12 * scale {
            return None;
        }
        a.swap(c, p);
        r.swap(c, p);
        let d = a[c][c];
        for k in 0..n {
            a[c][k] /= d;
            r[c][k] /= d;
        }
        for row in 0..n {
            if row != c {
                let f = a[row][c];
                if f != 0.0 {
                    for k in 0..n {
                        a[row][k] -= f * a[c][k];
                        r[row][k] -= f * r[c][k];
                    }
                }
            }
        }
    }
    Some(r)
}

/// The quadratic basis p = [Δ/h, ½Δ⊗Δ/h²] (d + d(d+1)/2 terms: 5 in 2D, 9 in 3D).
fn basis(dim: usize, d: [f64; 3], h: f64) -> Vec<f64> {
    let u: Vec<f64> = (0..dim).map(|a| d[a] / h).collect();
    let mut p = u.clone();
    for a in 0..dim {
        for b in a..dim {
            p.push(if a == b {
                0.5 * u[a] * u[a]
            } else {
                u[a] * u[b]
            });
        }
    }
    p
}

impl TlSetup {
    /// The lists and weights of particles at reference positions `x0` with elastic bodies
    /// `body` (pairs only within a body). Fails, naming the particle, where the quadratic fit
    /// is singular (a solid less than about three particles thick).
    pub fn new(ph: &Physics, x0: &[[f64; 3]], body: &[u32]) -> Result<TlSetup, String> {
        let dim = ph.dim as usize;
        let h = ph.h;
        let support = 2.0 * h;
        // Cell list of cell size 2h over the reference positions.
        let cell =
            |x: &[f64; 3]| -> [i64; 3] { [0, 1, 2].map(|a| (x[a] / support).floor() as i64) };
        let mut cells: std::collections::HashMap<[i64; 3], Vec<usize>> = Default::default();
        for (i, x) in x0.iter().enumerate() {
            cells.entry(cell(x)).or_default().push(i);
        }
        let reach: Vec<i64> = vec![-1, 0, 1];
        let zs: &[i64] = if dim == 3 { &reach } else { &[0] };
        let mut nb: Vec<Vec<(usize, [f64; 3], f64)>> = Vec::with_capacity(x0.len());
        for (i, xi) in x0.iter().enumerate() {
            let c = cell(xi);
            let mut list = Vec::new();
            for dz in zs {
                for dy in &reach {
                    for dxc in &reach {
                        let Some(v) = cells.get(&[c[0] + dxc, c[1] + dy, c[2] + dz]) else {
                            continue;
                        };
                        for &j in v {
                            if j == i || body[j] != body[i] {
                                continue;
                            }
                            let d = [0, 1, 2].map(|a| x0[j][a] - xi[a]);
                            let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                            if r < support {
                                list.push((j, d, r));
                            }
                        }
                    }
                }
            }
            list.sort_by_key(|e| e.0);
            nb.push(list);
        }
        // w_ij for every pair of i's list.
        let nbasis = dim + dim * (dim + 1) / 2;
        let mut w: Vec<Vec<[f64; 3]>> = Vec::with_capacity(x0.len());
        for (i, list) in nb.iter().enumerate() {
            let mut a = vec![vec![0.0; nbasis]; nbasis];
            for &(_, d, r) in list {
                let p = basis(dim, d, h);
                let wk = kernel::w(ph.kernel, ph.dim, h, r);
                for k in 0..nbasis {
                    for l in 0..nbasis {
                        a[k][l] += wk * p[k] * p[l];
                    }
                }
            }
            let ainv = inverse(a).ok_or_else(|| {
                format!(
                    "the quadratic least-squares fit of the total-Lagrangian solid is singular at \
                     the particle at {:?} ({} neighbours): the solid must be at least about three \
                     particles thick everywhere (or use formulation = \"updated_lagrangian\")",
                    x0[i],
                    list.len()
                )
            })?;
            w.push(
                list.iter()
                    .map(|&(_, d, r)| {
                        let p = basis(dim, d, h);
                        let wk = kernel::w(ph.kernel, ph.dim, h, r);
                        let mut g = [0.0; 3];
                        for c in 0..dim {
                            g[c] = (0..nbasis).map(|l| ainv[c][l] * p[l]).sum::<f64>() * wk / h;
                        }
                        g
                    })
                    .collect(),
            );
        }
        let mut start = Vec::with_capacity(x0.len() + 1);
        let mut pairs = Vec::new();
        start.push(0);
        for (i, list) in nb.iter().enumerate() {
            for (k, &(j, d, _)) in list.iter().enumerate() {
                // The lists are symmetric (same body, same distance test), sorted by index.
                let kj = nb[j]
                    .binary_search_by_key(&i, |e| e.0)
                    .expect("symmetric neighbour lists");
                pairs.push(TlPairRef {
                    j,
                    d0: d,
                    w_ij: w[i][k],
                    w_ji: w[j][kj],
                });
            }
            start.push(pairs.len());
        }
        Ok(TlSetup {
            start,
            pairs,
            body: body.to_vec(),
        })
    }

    pub fn len(&self) -> usize {
        self.start.len() - 1
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub(crate) fn pairs_of(&self, i: usize) -> &[TlPairRef] {
        &self.pairs[self.start[i]..self.start[i + 1]]
    }
}

pub(crate) fn zero() -> M3 {
    [[0.0; 3]; 3]
}

pub(crate) fn mul(a: &M3, b: &M3) -> M3 {
    let mut c = zero();
    for i in 0..3 {
        for j in 0..3 {
            for k in 0..3 {
                c[i][j] += a[i][k] * b[k][j];
            }
        }
    }
    c
}

/// The Cauchy stress σ = P Fᵀ / J and J = det F of a particle with displacement gradient
/// H = F − I and first Piola–Kirchhoff stress P (also the GPU solver's particle outputs).
pub fn cauchy_of(h: &M3, p: &M3) -> (M3, f64) {
    let mut f = *h;
    for a in 0..3 {
        f[a][a] += 1.0;
    }
    let j = f[0][0] * (f[1][1] * f[2][2] - f[1][2] * f[2][1])
        - f[0][1] * (f[1][0] * f[2][2] - f[1][2] * f[2][0])
        + f[0][2] * (f[1][0] * f[2][1] - f[1][1] * f[2][0]);
    let mut ft = zero();
    for a in 0..3 {
        for b in 0..3 {
            ft[a][b] = f[b][a];
        }
    }
    (mul(p, &ft).map(|r| r.map(|v| v / j)), j)
}

//! Twin of shaders/lib/mls.wgsl: first-order moving least squares (docs/equations.md eq. 11),
//! for the ghosts' interpolation and the density filter alike.

/// Smallest accepted MLS pivot relative to A00 = Σ W V (as `MLS_MIN_PIVOT` in mls.wgsl).
pub const MLS_MIN_PIVOT: f64 = 0.03;

/// The smallest pivot of the elimination relative to A00 (the conditioning the GPU tests).
pub fn min_pivot_ratio(dim: usize, a: [[f64; 4]; 4]) -> f64 {
    let n = dim + 1;
    let mut m = a;
    let mut worst = f64::MAX;
    for k in 0..n {
        let piv = (k..n)
            .max_by(|&x, &y| m[x][k].abs().total_cmp(&m[y][k].abs()))
            .unwrap();
        m.swap(k, piv);
        worst = worst.min(m[k][k].abs() / a[0][0]);
        if m[k][k] == 0.0 {
            return 0.0;
        }
        for r in k + 1..n {
            let f = m[r][k] / m[k][k];
            for c in 0..n {
                m[r][c] -= f * m[k][c];
            }
        }
    }
    worst
}

/// A += wv b bᵀ with b = [1, x/h] (`mls_add`).
pub fn mls_add(a: &mut [[f64; 4]; 4], dim: usize, h: f64, x: [f64; 3], wv: f64) {
    let b = mls_basis(dim, h, x);
    for r in 0..4 {
        for c in 0..4 {
            a[r][c] += wv * b[r] * b[c];
        }
    }
}

/// β = A⁻¹ e1 of the (d+1)×(d+1) MLS system, None when a pivot is below MLS_MIN_PIVOT·A00
/// (as the GPU).
pub fn mls_solve(dim: usize, a: [[f64; 4]; 4]) -> Option<[f64; 4]> {
    let n = dim + 1;
    let mut m = a;
    let mut rhs = [1.0, 0.0, 0.0, 0.0];
    let tiny = MLS_MIN_PIVOT * a[0][0];
    if a[0][0] <= 0.0 {
        return None;
    }
    for k in 0..n {
        let piv = (k..n)
            .max_by(|&x, &y| m[x][k].abs().total_cmp(&m[y][k].abs()))
            .unwrap();
        if m[piv][k].abs() <= tiny {
            return None;
        }
        m.swap(k, piv);
        rhs.swap(k, piv);
        for r in 0..n {
            if r != k {
                let f = m[r][k] / m[k][k];
                for c in 0..n {
                    m[r][c] -= f * m[k][c];
                }
                rhs[r] -= f * rhs[k];
            }
        }
    }
    let mut beta = [0.0; 4];
    for k in 0..n {
        beta[k] = rhs[k] / m[k][k];
    }
    Some(beta)
}

/// b = [1, x/h] with the unused z left 0 in 2D.
pub fn mls_basis(dim: usize, h: f64, x: [f64; 3]) -> [f64; 4] {
    [
        1.0,
        x[0] / h,
        x[1] / h,
        if dim == 3 { x[2] / h } else { 0.0 },
    ]
}

/// The MLS correction factor β0 + β·x/h of a pair (`mls_weight`).
pub fn mls_weight(beta: [f64; 4], dim: usize, h: f64, x: [f64; 3]) -> f64 {
    let b = mls_basis(dim, h, x);
    (0..4).map(|k| beta[k] * b[k]).sum()
}

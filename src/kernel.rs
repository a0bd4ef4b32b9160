//! Smoothing kernels in f64 (support 2h, q = r/h): the twin of `kernel_w` / `kernel_f` in
//! shaders/lib/common.wgsl. Neutral ground: the solver (its parameters) and the f64 reference
//! both use it, and it uses neither.

use crate::scenario::KernelKind;

/// SPH kernel normalisation α_d (support 2h) of `kernel` in `dim` dimensions.
pub fn kernel_norm(kernel: KernelKind, dim: u32, h: f64) -> f64 {
    use std::f64::consts::PI;
    match (kernel, dim) {
        (KernelKind::CubicSpline, 2) => 10.0 / (7.0 * PI * h * h),
        (KernelKind::CubicSpline, _) => 1.0 / (PI * h * h * h),
        (KernelKind::WendlandC2, 2) => 7.0 / (4.0 * PI * h * h),
        (KernelKind::WendlandC2, _) => 21.0 / (16.0 * PI * h * h * h),
    }
}

/// W(r).
pub fn w(kernel: KernelKind, dim: u32, h: f64, r: f64) -> f64 {
    let q = r / h;
    let a = kernel_norm(kernel, dim, h);
    match kernel {
        KernelKind::CubicSpline if q < 1.0 => a * (1.0 - 1.5 * q * q + 0.75 * q * q * q),
        KernelKind::CubicSpline => a * 0.25 * (2.0 - q).max(0.0).powi(3),
        KernelKind::WendlandC2 => a * (1.0 - 0.5 * q).max(0.0).powi(4) * (2.0 * q + 1.0),
    }
}

/// F(r) = W'(r)/r, so ∇_i W_ij = x_ij F(r_ij).
pub fn f(kernel: KernelKind, dim: u32, h: f64, r: f64) -> f64 {
    let q = r / h;
    let a = kernel_norm(kernel, dim, h);
    match kernel {
        KernelKind::CubicSpline if q < 1.0 => a / (h * h) * (-3.0 + 2.25 * q),
        KernelKind::CubicSpline => -0.75 * a * (2.0 - q).max(0.0).powi(2) / (h * h * q),
        KernelKind::WendlandC2 => -5.0 * a / (h * h) * (1.0 - 0.5 * q).max(0.0).powi(3),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const KERNELS: [KernelKind; 2] = [KernelKind::CubicSpline, KernelKind::WendlandC2];

    /// Lattice points with spacing dx covering the support of a kernel centred at `c`.
    fn lattice(dim: u32, dx: f64, c: [f64; 3], reach: f64) -> Vec<[f64; 3]> {
        let n = (reach / dx).ceil() as i64 + 1;
        let zr = if dim == 3 { n } else { 0 };
        let mut out = Vec::new();
        for k in -zr..=zr {
            for j in -n..=n {
                for i in -n..=n {
                    let p = [i as f64 * dx, j as f64 * dx, k as f64 * dx];
                    out.push([p[0] - c[0], p[1] - c[1], p[2] - c[2]]);
                }
            }
        }
        out
    }

    #[test]
    fn normalised_positive_and_compact() {
        for kernel in KERNELS {
            for dim in [2, 3] {
                let h = 1.0;
                // Σ W dx^d on a fine lattice approximates ∫W = 1.
                let dx = 0.05;
                let sum: f64 = lattice(dim, dx, [0.0; 3], 2.0 * h)
                    .iter()
                    .map(|p| p[0].hypot(p[1]).hypot(p[2]))
                    .filter(|&r| r < 2.0 * h)
                    .map(|r| w(kernel, dim, h, r) * dx.powi(dim as i32))
                    .sum();
                assert!((sum - 1.0).abs() < 1e-3, "{kernel:?} {dim}D integral {sum}");
                for k in 0..=200 {
                    let r = 2.0 * h * k as f64 / 200.0;
                    assert!(w(kernel, dim, h, r) >= 0.0);
                    assert!(f(kernel, dim, h, r.max(1e-9)) <= 0.0, "W decreasing");
                }
                assert_eq!(w(kernel, dim, h, 2.0 * h), 0.0);
                assert_eq!(w(kernel, dim, h, 2.5 * h), 0.0);
            }
        }
    }

    #[test]
    fn gradient_sums_to_zero_on_a_lattice_and_matches_finite_differences() {
        for kernel in KERNELS {
            for dim in [2, 3] {
                let h = 1.3;
                // Σ_j ∇W_ij V_j = 0 at a lattice point (a constant field has zero gradient);
                // Σ_j W_ij V_j ≈ 1 anywhere in the bulk.
                for c in [[0.0, 0.0, 0.0], [0.3, 0.1, 0.2]] {
                    let c = if dim == 2 { [c[0], c[1], 0.0] } else { c };
                    let mut g = [0.0f64; 3];
                    let mut wsum = 0.0;
                    for x in lattice(dim, 1.0, c, 2.0 * h) {
                        let r = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
                        if r < 2.0 * h && r > 0.0 {
                            let fr = f(kernel, dim, h, r);
                            // x_ij = x_i − x_j = −x
                            for a in 0..3 {
                                g[a] += -x[a] * fr;
                            }
                        }
                        wsum += w(kernel, dim, h, r);
                    }
                    let gnorm = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
                    // Exact (by symmetry) at a lattice point; off it the sum is a discretisation
                    // error, not a property of the kernel, so only the Shepard sum is checked.
                    if c == [0.0; 3] {
                        assert!(gnorm < 1e-12, "{kernel:?} {dim}D: |Σ∇W| = {gnorm}");
                    }
                    assert!(
                        (wsum - 1.0).abs() < 0.1,
                        "{kernel:?} {dim}D Shepard sum {wsum}"
                    );
                }
                for k in 1..40 {
                    let r = 2.0 * h * k as f64 / 40.0;
                    let e = 1e-6;
                    let fd = (w(kernel, dim, h, r + e) - w(kernel, dim, h, r - e)) / (2.0 * e);
                    let an = f(kernel, dim, h, r) * r;
                    assert!(
                        (fd - an).abs() < 1e-5 * kernel_norm(kernel, dim, h),
                        "{kernel:?} r={r}"
                    );
                }
            }
        }
    }
}

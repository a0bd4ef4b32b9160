// First-order moving least squares, docs/equations.md eq. 11 (Colagrossi & Landrini 2003,
// §2.3; Rabczuk, Belytschko & Xiao 2004): W^MLS_ij = (β0 + β·(x_i − x_j)/h) W_ij with
// β = A⁻¹ e1, A = Σ_j W_ij V_j [1, x_ij/h][1, x_ij/h]ᵀ. Positions are scaled by h so that every
// entry of A is of order Σ W V ~ 1 and one pivot threshold fits all rows. In 2D the z row and
// column are the identity. No bindings: composed after common.wgsl by the passes that need it.

fn mls_basis(x_ij: vec3<f32>) -> vec4<f32> {
    let y = x_ij / params.h;
    return vec4<f32>(1.0, y.x, y.y, select(0.0, y.z, DIM == 3u));
}

fn mls_zero() -> mat4x4<f32> {
    return mat4x4<f32>(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
}

// A += wv · b bᵀ with b = [1, x_ij/h].
fn mls_add(a: mat4x4<f32>, x_ij: vec3<f32>, wv: f32) -> mat4x4<f32> {
    let b = mls_basis(x_ij);
    return a + mat4x4<f32>(b * (wv * b.x), b * (wv * b.y), b * (wv * b.z), b * (wv * b.w));
}

const MLS_MIN_PIVOT: f32 = 0.03;

struct MlsBeta {
    beta: vec4<f32>,
    ok: bool,
}

// β = A⁻¹ e1 by Gauss–Jordan elimination with partial pivoting. `ok` is false when a pivot
// falls below MLS_MIN_PIVOT·A00 (A00 = Σ W V): too few, collinear or one-sided neighbours,
// where β grows like 1/pivot and amplifies particle noise (a ghost 1 dx outside the fluid with
// h = 1.3 dx has a smallest pivot of ~1 % and β0·A00 ≈ 50). Callers fall back to Shepard.
fn mls_solve(a_in: mat4x4<f32>) -> MlsBeta {
    var a = a_in;
    if (DIM == 2u) {
        a[3] = vec4<f32>(0.0, 0.0, 0.0, 1.0);
        a[0].w = 0.0;
        a[1].w = 0.0;
        a[2].w = 0.0;
    }
    let tiny = MLS_MIN_PIVOT * a[0][0];
    var rhs = vec4<f32>(1.0, 0.0, 0.0, 0.0);
    if (!(a[0][0] > 0.0)) {
        return MlsBeta(vec4<f32>(0.0), false);
    }
    // a[c][r]: column c, row r (WGSL matrices are column-major).
    for (var k = 0; k < 4; k++) {
        var piv = k;
        for (var r = k + 1; r < 4; r++) {
            if (abs(a[k][r]) > abs(a[k][piv])) {
                piv = r;
            }
        }
        if (!(abs(a[k][piv]) > tiny)) {
            return MlsBeta(vec4<f32>(0.0), false);
        }
        // Swap rows k and piv.
        for (var c = 0; c < 4; c++) {
            let t = a[c][k];
            a[c][k] = a[c][piv];
            a[c][piv] = t;
        }
        let t = rhs[k];
        rhs[k] = rhs[piv];
        rhs[piv] = t;
        let inv = 1.0 / a[k][k];
        for (var r = 0; r < 4; r++) {
            if (r == k) {
                continue;
            }
            let f = a[k][r] * inv;
            for (var c = 0; c < 4; c++) {
                a[c][r] -= f * a[c][k];
            }
            rhs[r] -= f * rhs[k];
        }
    }
    let beta = vec4<f32>(rhs[0] / a[0][0], rhs[1] / a[1][1], rhs[2] / a[2][2], rhs[3] / a[3][3]);
    let finite = all(abs(beta) < vec4<f32>(1e30));
    return MlsBeta(beta, finite);
}

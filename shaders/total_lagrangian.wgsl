// Total-Lagrangian (TL) elastic solid: St Venant–Kirchhoff SPH on the reference lattice X (the
// initial positions) with a neighbour list fixed at the start, the formulation that
// tools/plate_twin studied (`tl=1 ls=2 gq=1`, its src/tl.rs; the plate's period within
// +2.4…+4.4 % of Euler–Bernoulli at H/dx = 5…10, energy conserving, no artificial viscosity or
// stress). Its f64 twin is src/reference/total_lagrangian.rs, which also computes the setup
// uploaded here once (lists, weights).
//
// Setup (host, f64): for each solid particle i and neighbour j (same body, |X_j − X_i| < 2h),
// Δ = X_j − X_i, p_ij = [Δ/h, ½Δ⊗Δ/h²], W0_ij = W(|Δ|),
//   A_i = Σ_j W0_ij p_ij p_ijᵀ,  w_ij = V γ_ij = W0_ij [A_i⁻¹ p_ij]_(first d rows) / h,
// the weighted least-squares gradient exact for quadratic fields (also at the free surface).
// Per evaluation, four passes over the TL particles (k below is the TL index, i = tl_slot[k]
// the particle's current slot in the sorted arrays):
//   tl_deform:   H_i = Σ_j ((x_j − x_i) − (X_j − X_i)) ⊗ w_ij,  F_i = I + H_i
//   tl_gradient: E = ½(H + Hᵀ + HᵀH) (= ½(FᵀF − I)),
//                D_i^k = Σ_j (E_j − E_i) w_ij^k,  T_i^k = (dx²/12)(λ tr D_i^k I + 2G D_i^k)
//   tl_stress:   S2_i = Σ_j Σ_k (T_j^k w_ji^k − T_i^k w_ij^k),  S_i = λ tr E_i I + 2G E_i,
//                P_i = F_i (S_i + S2_i)
//   tl_accel:    ρ0 a_i = Σ_j (P_i w_ij − P_j w_ji), added to rate (with g); dρ/dt = 0
// The momentum is the exact negative gradient of the discrete energy Σ_i V ψ(F_i) + V dx²/24
// Σ_k D_i^k : C : D_i^k; the second term is the cell quadrature term (the energy of a strain
// varying linearly across the particle's square cell, which one-point quadrature misses; for
// bending it restores Σ dx z_j² = H³/12 (1 − (dx/H)²)). Plane strain in 2D (F_zz = 1, λ and G
// of the 3D material). With integrate.wgsl's predictor–corrector, which is velocity Verlet when
// a depends on the positions only, the scheme is symplectic.
//
// Particles are re-sorted every step: tl_index (after the sort) records the slot of every TL
// particle (the total-Lagrangian solids' particles have consecutive ids from tlp.first_id), as
// body_index does for body particles. Everything else is indexed by TL index. A case may also
// hold updated-Lagrangian solids (elastic.wgsl), whose particles are not in the TL lists.
// Clamped particles get F and stress (they are neighbours) and a rate that integrate.wgsl
// ignores.

struct TlParams {
    n: u32,
    first_id: u32,
    k2: f32,       // dx²/12
    pad: u32,
}

// One entry of particle i's reference list (w_ij, w_ji = V γ; d0 = X_j − X_i).
struct TlPair {
    w_ij: vec3<f32>,
    j: u32,
    w_ji: vec3<f32>,
    pad0: u32,
    d0: vec3<f32>,
    pad1: u32,
}

@group(0) @binding(1) var<storage, read> pos: array<Pos>;
@group(0) @binding(2) var<storage, read> code: array<u32>;
@group(0) @binding(3) var<storage, read_write> rate: array<vec4<f32>>;
@group(0) @binding(4) var<uniform> tlp: TlParams;
@group(0) @binding(5) var<storage, read> tl_start: array<u32>;
@group(0) @binding(6) var<storage, read> tl_pairs: array<TlPair>;
// Slot of TL particle k in the sorted arrays, as of the last sort.
@group(0) @binding(7) var<storage, read_write> tl_slot: array<u32>;
// H = F − I, T^k (3 per particle) and P, by TL index.
@group(0) @binding(8) var<storage, read_write> tl_h: array<mat3x3<f32>>;
@group(0) @binding(9) var<storage, read_write> tl_t: array<mat3x3<f32>>;
@group(0) @binding(10) var<storage, read_write> tl_p: array<mat3x3<f32>>;
// The solid state, for the material of TL particle k (λ, G and ρ0 of params.solid_materials,
// per body; `tl_material`): the TL particles are the run of solid slots from
// tlp.first_id − params.solid_id_base.
@group(0) @binding(11) var<storage, read> solid: array<SolidState>;

// The material of TL particle k.
fn tl_material(k: u32) -> SolidMaterial {
    return material_of(solid[tlp.first_id - params.solid_id_base + k]);
}

fn zero3() -> mat3x3<f32> {
    return mat3x3<f32>(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
}

fn identity3() -> mat3x3<f32> {
    return mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));
}

// a ⊗ b (row a, column b): column c is a b_c.
fn outer(a: vec3<f32>, b: vec3<f32>) -> mat3x3<f32> {
    return mat3x3<f32>(a * b.x, a * b.y, a * b.z);
}

// Green strain of the displacement gradient H.
fn green(h: mat3x3<f32>) -> mat3x3<f32> {
    return 0.5 * (h + transpose(h) + transpose(h) * h);
}

// λ tr M I + 2G M, of material `mat`.
fn svk(mat: SolidMaterial, m: mat3x3<f32>) -> mat3x3<f32> {
    return (mat.lambda * (m[0].x + m[1].y + m[2].z)) * identity3() + (2.0 * mat.mu) * m;
}

@compute @workgroup_size(WG)
fn tl_index(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles) {
        return;
    }
    let id = code[i] & ID_MASK;
    if (id >= tlp.first_id && id - tlp.first_id < tlp.n) {
        tl_slot[id - tlp.first_id] = i;
    }
}

@compute @workgroup_size(WG)
fn tl_deform(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = linear_index(gid, nwg);
    if (k >= tlp.n) {
        return;
    }
    let xi = pos[tl_slot[k]];
    var h = zero3();
    for (var q = tl_start[k]; q < tl_start[k + 1u]; q++) {
        let p = tl_pairs[q];
        // (x_j − x_i) − (X_j − X_i): the displacement difference, small against Δ.
        let u = rel_pos(pos[tl_slot[p.j]], xi) - p.d0;
        h += outer(u, p.w_ij);
    }
    tl_h[k] = h;
}

@compute @workgroup_size(WG)
fn tl_gradient(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = linear_index(gid, nwg);
    if (k >= tlp.n) {
        return;
    }
    let e_i = green(tl_h[k]);
    var d0 = zero3();
    var d1 = zero3();
    var d2 = zero3();
    for (var q = tl_start[k]; q < tl_start[k + 1u]; q++) {
        let p = tl_pairs[q];
        let de = green(tl_h[p.j]) - e_i;
        d0 += de * p.w_ij.x;
        d1 += de * p.w_ij.y;
        d2 += de * p.w_ij.z;
    }
    let mat = tl_material(k);
    tl_t[3u * k] = tlp.k2 * svk(mat, d0);
    tl_t[3u * k + 1u] = tlp.k2 * svk(mat, d1);
    tl_t[3u * k + 2u] = tlp.k2 * svk(mat, d2);
}

@compute @workgroup_size(WG)
fn tl_stress(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = linear_index(gid, nwg);
    if (k >= tlp.n) {
        return;
    }
    // Σ_j T_j^k w_ji^k, and Σ_j w_ij (T_i^k taken out of the sum).
    var s2 = zero3();
    var w_sum = vec3<f32>(0.0);
    for (var q = tl_start[k]; q < tl_start[k + 1u]; q++) {
        let p = tl_pairs[q];
        let j = 3u * p.j;
        s2 += tl_t[j] * p.w_ji.x + tl_t[j + 1u] * p.w_ji.y + tl_t[j + 2u] * p.w_ji.z;
        w_sum += p.w_ij;
    }
    s2 -= tl_t[3u * k] * w_sum.x + tl_t[3u * k + 1u] * w_sum.y + tl_t[3u * k + 2u] * w_sum.z;
    let h = tl_h[k];
    tl_p[k] = (identity3() + h) * (svk(tl_material(k), green(h)) + s2);
}

@compute @workgroup_size(WG)
fn tl_accel(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = linear_index(gid, nwg);
    if (k >= tlp.n) {
        return;
    }
    let p_i = tl_p[k];
    var f = vec3<f32>(0.0);
    for (var q = tl_start[k]; q < tl_start[k + 1u]; q++) {
        let p = tl_pairs[q];
        f += p_i * p.w_ij - tl_p[p.j] * p.w_ji;
    }
    let i = tl_slot[k];
    rate[i] += vec4<f32>(f / tl_material(k).rho0 + params.gravity, 0.0);
}

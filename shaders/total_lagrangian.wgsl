// Total-Lagrangian (TL) elastic solid, docs/equations.md eq. 29: St Venant–Kirchhoff SPH on
// the reference lattice X, with a neighbour list and quadratic least-squares gradient weights
// w_ij fixed at the start (computed on the host in f64 by src/reference/total_lagrangian.rs,
// also the f64 twin). Per evaluation (k the TL index, i = tl_slot[k] its slot after the sort):
//   tl_index:    the slot of every TL particle, after the sort;
//   tl_gather:   the position of every TL particle the arrays hold, by TL index;
//   tl_deform:   the displacement gradient H = F − I;
//   tl_gradient: the Green strain E and the cell-quadrature stresses T^k;
//   tl_stress:   the first Piola–Kirchhoff stress P = F (S + S2), S of St Venant–Kirchhoff;
//   tl_accel:    ρ0 a_i = Σ_j (P_i w_ij − P_j w_ji), added to rate with g; dρ/dt = 0.
// Plane strain in 2D. Symplectic with integrate.wgsl's predictor–corrector (eq. 30).
// A particle's H reads its reference neighbours' positions, and its acceleration their H
// through T and P: four lists deep, beyond any halo. So the passes read positions by TL index
// (`tl_pos`), where a subdomain has every TL particle's, its own gathered and the others'
// shared by the ranks after its predictor (`Solver::share_tl_positions`), and every rank
// computes the whole solid's stresses alike; `tl_accel` adds to the particles it holds.
// Design notes: docs/design/total_lagrangian.md.

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
// The position of every TL particle and whether the arrays hold it, by TL index
// (`tl_gather`); a subdomain's others are written by the host.
@group(0) @binding(12) var<storage, read_write> tl_pos: array<Pos>;
@group(0) @binding(13) var<storage, read_write> tl_held: array<u32>;
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
    let id = particle_id(i);
    if (id >= tlp.first_id && id - tlp.first_id < tlp.n) {
        tl_slot[id - tlp.first_id] = i;
    }
}

// The position of TL particle k where the arrays hold it, live, at the slot `tl_index` last
// found (a subdomain's slot of a particle it no longer holds is stale: another id is there,
// or a free or excluded entry).
@compute @workgroup_size(WG)
fn tl_gather(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = linear_index(gid, nwg);
    if (k >= tlp.n) {
        return;
    }
    let i = tl_slot[k];
    var held = false;
    if (i < params.n_particles) {
        held = particle_id(i) == tlp.first_id + k && code_kind(code[i]) != KIND_EXCLUDED;
    }
    if (held) {
        tl_pos[k] = pos[i];
    }
    tl_held[k] = select(0u, 1u, held);
}

@compute @workgroup_size(WG)
fn tl_deform(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = linear_index(gid, nwg);
    if (k >= tlp.n) {
        return;
    }
    let xi = tl_pos[k];
    var h = zero3();
    for (var q = tl_start[k]; q < tl_start[k + 1u]; q++) {
        let p = tl_pairs[q];
        // (x_j − x_i) − (X_j − X_i): the displacement difference, small against Δ.
        let u = rel_pos(tl_pos[p.j], xi) - p.d0;
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
    if (tl_held[k] != 0u) {
        let i = tl_slot[k];
        rate[i] += vec4<f32>(f / tl_material(k).rho0 + params.gravity, 0.0);
    }
}

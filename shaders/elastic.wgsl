// Hypoelastic (updated-Lagrangian) solid particles (Gray, Monaghan & Swift 2001, "GMS"), one
// invocation per particle after interaction.wgsl, whose rates of solid particles (the fluid's
// load, contact) this pass adds to; pairs are within one elastic body. Equations as numbered in
// docs/equations.md:
//   σ = −p I + τ, p = c_s² (ρ − ρs), eq. 25 (GMS);
//   continuity and momentum with artificial viscosity and artificial stress, eq. 26 (GMS;
//     Monaghan 1992); artificial stress, eq. 27 (Monaghan 2000; GMS), its principal frame by
//     Jacobi rotations (Press et al., Numerical Recipes §11.1);
//   velocity gradient, strain rate and rotation rate, eq. 8; Jaumann rate of τ, eq. 7 (GMS);
//   τ's predictor and corrector (`stress_predict`, `stress_correct`), eq. 30.
// Plane strain in 2D. The material is the body's (params.solid_materials). Clamped particles
// get all rates; integrate.wgsl holds their position and velocity. docs/design/elastic.md.

@group(0) @binding(1) var<storage, read> pos: array<Pos>;
@group(0) @binding(2) var<storage, read> velrho: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> code: array<u32>;
@group(0) @binding(4) var<storage, read> cell_start: array<u32>;
@group(0) @binding(5) var<storage, read_write> rate: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> solid: array<SolidState>;
@group(0) @binding(7) var<storage, read_write> stress_rate: array<SymRate>;
@group(0) @binding(8) var<storage, read_write> state: SimState;

// What elastic_rates reads of a neighbour, written once per evaluation by solid_stress_terms
// (by solid slot) rather than recomputed for every pair (the artificial stress alone is four
// Jacobi sweeps in 3D): σ/ρ² and R, symmetric as (xx, yy, zz, xy | xz, yz), and the body (so
// that a neighbour's SolidState is not read at all). Pass-local: the host never reads it.
struct SolidTerms {
    a_d: vec4<f32>,     // σ/ρ²: xx, yy, zz, xy
    r_d: vec4<f32>,     // R: xx, yy, zz, xy
    off: vec4<f32>,     // σ/ρ²: xz, yz; R: xz, yz
    body: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}
@group(0) @binding(9) var<storage, read_write> terms: array<SolidTerms>;

// The symmetric matrix of diagonal and xy `d` = (xx, yy, zz, xy) and `o` = (xz, yz), by columns.
fn sym3(d: vec4<f32>, o: vec2<f32>) -> mat3x3<f32> {
    return mat3x3<f32>(
        vec3<f32>(d.x, d.w, o.x),
        vec3<f32>(d.w, d.y, o.y),
        vec3<f32>(o.x, o.y, d.z),
    );
}

fn tau_of(s: SolidState) -> mat3x3<f32> {
    return sym3(s.tau_a, s.tau_b.xy);
}

// p = c_s² (ρ − ρs).
fn solid_pressure(mat: SolidMaterial, rho: f32) -> f32 {
    return mat.c2 * (rho - mat.rho0);
}

// One Jacobi rotation of the symmetric `a` in the plane (p, q), zeroing a_pq, with the
// eigenvector estimates `v` (columns) rotated alongside (Press et al., Numerical Recipes §11.1,
// eqs. 11.1.8–11.1.18; t = tan φ written without θ = (a_qq − a_pp)/(2 a_pq) so that a tiny a_pq
// cannot overflow it).
fn jacobi_rotate(a: ptr<function, mat3x3<f32>>, v: ptr<function, mat3x3<f32>>, p: u32, q: u32) {
    let apq = (*a)[q][p];
    if (apq == 0.0) {
        return;
    }
    let d = (*a)[q][q] - (*a)[p][p];
    let t = select(-1.0, 1.0, d >= 0.0) * 2.0 * apq / (abs(d) + sqrt(d * d + 4.0 * apq * apq));
    let c = inverseSqrt(t * t + 1.0);
    let s = t * c;
    var r = *a;
    r[p][p] = (*a)[p][p] - t * apq;
    r[q][q] = (*a)[q][q] + t * apq;
    r[q][p] = 0.0;
    r[p][q] = 0.0;
    let o = 3u - p - q; // the third axis
    let aop = (*a)[p][o];
    let aoq = (*a)[q][o];
    r[p][o] = c * aop - s * aoq;
    r[o][p] = r[p][o];
    r[q][o] = s * aop + c * aoq;
    r[o][q] = r[q][o];
    *a = r;
    for (var k = 0u; k < 3u; k++) {
        let vp = (*v)[p][k];
        let vq = (*v)[q][k];
        (*v)[p][k] = c * vp - s * vq;
        (*v)[q][k] = s * vp + c * vq;
    }
}

// Artificial stress R_i of a particle with total stress σ and density ρ (Monaghan 2000; GMS §4):
// in the principal frame R'_aa = −ε σ'_aa/ρ² where σ'_aa > 0, else 0, rotated back, i.e.
// R = −(ε/ρ²) σ⁺ with σ⁺ the tensile part of σ. The principal frame comes from cyclic Jacobi
// sweeps (four, a fixed count so that every invocation does the same work; for 3×3 the
// off-diagonal is at f32 rounding after three). In 2D σ_xz = σ_yz = 0 and one rotation in
// the xy-plane is exact: GMS's closed form, tan 2θ = 2σ_xy/(σ_xx − σ_yy); R_zz does not act on
// the in-plane momentum.
fn artificial_stress(eps: f32, sigma: mat3x3<f32>, rho: f32) -> mat3x3<f32> {
    if (eps == 0.0) {
        return mat3x3<f32>(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    }
    var a = sigma;
    var v = mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));
    if (DIM == 2u) {
        jacobi_rotate(&a, &v, 0u, 1u);
    } else {
        for (var sweep = 0u; sweep < 4u; sweep++) {
            jacobi_rotate(&a, &v, 0u, 1u);
            jacobi_rotate(&a, &v, 0u, 2u);
            jacobi_rotate(&a, &v, 1u, 2u);
        }
    }
    let k = -eps / (rho * rho);
    var r = mat3x3<f32>(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    for (var e = 0u; e < 3u; e++) {
        let n = v[e];
        r += mat3x3<f32>(n * n.x, n * n.y, n * n.z) * (k * max(a[e][e], 0.0));
    }
    return r;
}

// What a solid particle contributes to a pair: σ/ρ², R, ρ, v.
struct SolidParticle {
    a: mat3x3<f32>,     // σ/ρ²
    r: mat3x3<f32>,     // artificial stress R
    v: vec3<f32>,
    rho: f32,
}

// Whether particle i is a solid particle of this pass: of an updated-Lagrangian material (a
// total-Lagrangian solid's forces are total_lagrangian.wgsl's, and it has no τ to integrate).
fn is_updated_lagrangian(i: u32) -> bool {
    return is_solid(code_kind(code[i])) && material_of(solid[solid_slot(i)]).total_lagrangian == 0u;
}

// σ/ρ², R and the body of every solid particle, for elastic_rates (one invocation per
// particle, before it).
@compute @workgroup_size(WG)
fn solid_stress_terms(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    // Every solid particle, total-Lagrangian ones too: elastic_rates reads its neighbours'
    // bodies here (a total-Lagrangian body's terms are not used).
    if (i >= params.n_particles || !is_solid(code_kind(code[i]))) {
        return;
    }
    let s = solid[solid_slot(i)];
    let mat = material_of(s);
    let rho = velrho[i].w;
    let p = solid_pressure(mat, rho);
    let sigma = tau_of(s) - mat3x3<f32>(vec3<f32>(p, 0.0, 0.0), vec3<f32>(0.0, p, 0.0), vec3<f32>(0.0, 0.0, p));
    let a = sigma * (1.0 / (rho * rho));
    let r = artificial_stress(mat.eps, sigma, rho);
    terms[solid_slot(i)] = SolidTerms(
        vec4<f32>(a[0].x, a[1].y, a[2].z, a[1].x),
        vec4<f32>(r[0].x, r[1].y, r[2].z, r[1].x),
        vec4<f32>(a[2].x, a[2].y, r[2].x, r[2].y),
        s.body,
        0u,
        0u,
        0u,
    );
}

// Particle k with its terms `t` (solid_stress_terms).
fn solid_particle(k: u32, t: SolidTerms) -> SolidParticle {
    let vr = velrho[k];
    return SolidParticle(sym3(t.a_d, t.off.xy), sym3(t.r_d, t.off.zw), vr.xyz, vr.w);
}

@compute @workgroup_size(WG)
fn elastic_rates(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles || !is_updated_lagrangian(i)) {
        return;
    }
    let slot_i = solid_slot(i);
    let body_i = solid[slot_i].body;
    // Pairs are within the body, so of one material.
    let mat = material_of(solid[slot_i]);
    let pi = solid_particle(i, terms[slot_i]);
    let p_i = pos[i];
    let support2 = 4.0 * params.h * params.h;
    let m = mat.mass;
    let c_s = sqrt(mat.c2);

    var acc = vec3<f32>(0.0);
    var drho = 0.0;
    var grad_v = mat3x3<f32>(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    var ranges: NeighbourRanges;
    let n_ranges = neighbour_ranges(p_i, &ranges);
    for (var s = 0u; s < n_ranges; s++) {
        for (var j = ranges[s].x; j < ranges[s].y; j++) {
            let code_j = code[j];
            if (j == i || !is_solid(code_kind(code_j))) {
                continue;
            }
            let x_ij = rel_pos(p_i, pos[j]);
            let r2 = dot(x_ij, x_ij);
            if (r2 >= support2) {
                continue;
            }
            let t_j = terms[solid_slot(j)];
            if (t_j.body != body_i) {
                continue;
            }
            let q = sqrt(r2) / params.h;
            let dw_ij = x_ij * kernel_f(q);
            let pj = solid_particle(j, t_j);
            let v_ij = pi.v - pj.v;
            drho += m * dot(v_ij, dw_ij);
            var pi_ij = 0.0;
            let vx = dot(v_ij, x_ij);
            if (vx < 0.0) {
                let mu = params.h * vx / (r2 + params.eta2);
                pi_ij = -mat.alpha * c_s * mu / (0.5 * (pi.rho + pj.rho));
            }
            let fw = kernel_w(q) * params.solid_inv_w_dx;
            let fn4 = fw * fw * fw * fw;
            // σ is symmetric, so T·∇W = T ∇W in either index order.
            let t = pi.a + pj.a + (pi.r + pj.r) * fn4;
            acc += m * (t * dw_ij - pi_ij * dw_ij);
            // ∇v: column b gets (m_j/ρ_j)(v_j − v_i) ∂_b W_ij.
            let u = (m / pj.rho) * (pj.v - pi.v);
            grad_v += mat3x3<f32>(u * dw_ij.x, u * dw_ij.y, u * dw_ij.z);
        }
    }
    rate[i] += vec4<f32>(acc + params.gravity, drho);
    let d = jaumann_stress_rate(grad_v, tau_of(solid[slot_i]), mat.mu);
    stress_rate[slot_i] = SymRate(vec4<f32>(d[0].x, d[1].y, d[2].z, 0.5 * (d[1].x + d[0].y)),
                             vec4<f32>(0.5 * (d[2].x + d[0].z), 0.5 * (d[2].y + d[1].z), 0.0, 0.0));
}

// The Jaumann rate of the deviatoric stress, eq. 7 (Gray, Monaghan & Swift 2001): dτ/dt =
// 2μ (ε̇ − tr ε̇/3 I) + τ Ωᵀ + Ω τ, with the strain and rotation rates ε̇, Ω of eq. 8 from
// the velocity gradient `grad_v`.
fn jaumann_stress_rate(grad_v: mat3x3<f32>, tau: mat3x3<f32>, mu: f32) -> mat3x3<f32> {
    let eps = 0.5 * (grad_v + transpose(grad_v));
    let omega = 0.5 * (grad_v - transpose(grad_v));
    let tr3 = (eps[0].x + eps[1].y + eps[2].z) / 3.0;
    let iso = mat3x3<f32>(vec3<f32>(tr3, 0.0, 0.0), vec3<f32>(0.0, tr3, 0.0), vec3<f32>(0.0, 0.0, tr3));
    return 2.0 * mu * (eps - iso) + tau * transpose(omega) + omega * tau;
}

// Predictor for τ (see integrate.wgsl): τ* = τ_n + dt (dτ/dt)_n.
@compute @workgroup_size(WG)
fn stress_predict(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles || !is_updated_lagrangian(i)) {
        return;
    }
    let dt = state.dt;
    let k = solid_slot(i);
    let s = solid[k];
    solid[k].tau_a = s.tau_a + dt * s.rate_a;
    solid[k].tau_b = s.tau_b + dt * vec3<f32>(s.rate_b, 0.0);
}

// Corrector for τ: τ_{n+1} = τ* + ½dt ((dτ/dt)_{n+1} − (dτ/dt)_n); keeps the new rate.
@compute @workgroup_size(WG)
fn stress_correct(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles || !is_updated_lagrangian(i)) {
        return;
    }
    let half_dt = 0.5 * state.dt;
    let k = solid_slot(i);
    let s = solid[k];
    let r = stress_rate[k];
    solid[k].tau_a = s.tau_a + half_dt * (r.a - s.rate_a);
    solid[k].tau_b = s.tau_b + half_dt * vec3<f32>(r.b.xy - s.rate_b, 0.0);
    solid[k].rate_a = r.a;
    solid[k].rate_b = r.b.xy;
}

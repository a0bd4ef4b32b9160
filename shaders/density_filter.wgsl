// Density re-initialisation of the fluid (Colagrossi & Landrini 2003), docs/equations.md
// eq. 9, every N steps after the corrector, on the sorted arrays of the step: Shepard, eq. 10,
// or first-order MLS, eq. 11 (shaders/lib/mls.wgsl; Rabczuk, Belytschko & Xiao 2004), over i
// itself and its fluid, dynamic-wall, inlet-buffer and ghost neighbours within 2h (`counts`).
// MLS falls back to Shepard where A is ill-conditioned or the MLS density is not positive and
// finite; Shepard falls back to the old density.
// Two dispatches, so that no particle reads a filtered neighbour: `density_filter_*` writes
// `filtered`, `apply_density` copies it into velrho.w; `filter_gate` writes their indirect
// dispatch size (the full grid on every `every`-th step, zero otherwise).
// Design notes: docs/design/density_filter.md.

@group(0) @binding(1) var<storage, read> pos: array<Pos>;
@group(0) @binding(2) var<storage, read_write> velrho: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> code: array<u32>;
@group(0) @binding(4) var<storage, read> cell_start: array<u32>;
@group(0) @binding(5) var<storage, read_write> filtered: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> state: SimState;

// Mirrored by `sph::density_filter::FilterCtl`.
struct FilterCtl {
    every: u32,         // filter every `every` steps
    last: u32,          // state.steps of the last filter (0: none yet)
    groups_x: u32,      // the dispatch grid of one invocation per particle
    groups_y: u32,
}

@group(0) @binding(7) var<storage, read_write> ctl: FilterCtl;
// Indirect dispatch arguments (x, y, z) of the two particle kernels.
@group(0) @binding(8) var<storage, read_write> args: array<u32, 3>;

// Neighbours whose density enters the filter.
fn counts(kind: u32) -> bool {
    return kind == KIND_FLUID || kind == KIND_WALL || kind == KIND_INLET || is_ghost(kind);
}

fn positive_finite(x: f32) -> bool {
    return x > 0.0 && x < 3.0e38;
}

// The filtered density of fluid particle i.
fn filter_density(i: u32, mls: bool) -> f32 {
    let p_i = pos[i];
    let support2 = 4.0 * params.h * params.h;
    var sum_mw = 0.0;  // Σ m_j W_ij
    var sum_wv = 0.0;  // Σ W_ij V_j
    var a = mls_zero();
    var m_mw = vec4<f32>(0.0);  // Σ m_j W_ij [1, x_ij/h]: Σ m_j W^MLS_ij = β·m_mw
    var ranges: NeighbourRanges;
    let n_ranges = neighbour_ranges(p_i, &ranges);
    // One pass: the Shepard sums, the MLS moment matrix and the first moments of m W.
    for (var s = 0u; s < n_ranges; s++) {
        for (var j = ranges[s].x; j < ranges[s].y; j++) {
            if (j != i && !counts(code_kind(code[j]))) {
                continue;
            }
            let x_ij = rel_pos(p_i, pos[j]);
            let r2 = dot(x_ij, x_ij);
            if (r2 >= support2) {
                continue;
            }
            let w = kernel_w(sqrt(r2) / params.h);
            let wv = w * params.mass / velrho[j].w;
            sum_mw += params.mass * w;
            sum_wv += wv;
            if (mls) {
                a = mls_add(a, x_ij, wv);
                m_mw += params.mass * w * mls_basis(x_ij);
            }
        }
    }
    let rho_old = velrho[i].w;
    var rho = sum_mw / sum_wv;
    if (!positive_finite(rho)) {
        rho = rho_old;
    }
    if (mls) {
        let sol = mls_solve(a);
        if (sol.ok) {
            // Σ m_j W_ij (β0 + β·x_ij/h), from the moments (no second neighbour pass).
            let rho_mls = dot(sol.beta, m_mw);
            if (positive_finite(rho_mls)) {
                rho = rho_mls;
            }
        }
    }
    return rho;
}

fn filter_all(gid: vec3<u32>, nwg: vec3<u32>, mls: bool) {
    let i = spread_index(gid, nwg);
    if (i >= params.n_particles) {
        return;
    }
    if (code_kind(code[i]) == KIND_FLUID) {
        filtered[i] = vec4<f32>(0.0, 0.0, 0.0, filter_density(i, mls));
    }
}

@compute @workgroup_size(WG)
fn density_filter_shepard(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    filter_all(gid, nwg, false);
}

@compute @workgroup_size(WG)
fn density_filter_mls(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    filter_all(gid, nwg, true);
}

@compute @workgroup_size(WG)
fn apply_density(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles) {
        return;
    }
    if (code_kind(code[i]) == KIND_FLUID) {
        velrho[i].w = filtered[i].w;
    }
}

@compute @workgroup_size(1)
fn filter_gate() {
    let steps = state.steps;
    let on = steps != ctl.last && steps % ctl.every == 0u;
    if (on) {
        ctl.last = steps;
    }
    args[0] = select(0u, ctl.groups_x, on);
    args[1] = select(0u, ctl.groups_y, on);
    args[2] = select(0u, 1u, on);
}

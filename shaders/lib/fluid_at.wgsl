// The fluid interpolated at a point with the corrected kernel W^I (docs/equations.md eq. 13):
// Shepard, eq. 10, or first-order MLS, eq. 11, where the case asks for it
// (walls.ghost_correction) and the moment matrix is well conditioned. Used by the fixed ghosts
// and elastic solids (ghost.wgsl) and by inlet buffers whose pressure is taken from the fluid
// (open_boundaries.wgsl). The pass file declares `pos`, `velrho`, `code` and `cell_start`
// (sorted arrays, after the cell-list sort). Only fluid particles count. Hydrostatic
// correction, eq. 21 (Adami, Hu & Adams 2012): each fluid pressure is carried to the point
// along g_eff before it is interpolated, P_j + ρ_j g_eff·(x − x_j), so a hydrostatic field is
// exact. Fallbacks: MLS → Shepard where the moment matrix is ill-conditioned; no fluid in
// reach → P = 0 and a velocity of 0.

// ρ from P by the inverse Tait equation; the base is kept positive for any pressure.
fn density_of(p: f32) -> f32 {
    return params.rho0 * pow(max(1.0 + p / params.tait_b, 0.5), 1.0 / params.gamma);
}

// The fluid's velocity and pressure interpolated at `pg` with W^I (see the header), each fluid
// pressure carried to `pg` along `g_eff` = g − a_w: (v, P).
fn fluid_at(pg: Pos, g_eff: vec3<f32>) -> vec4<f32> {
    let support2 = 4.0 * params.h * params.h;
    // Moments Σ f_j W V [1, x_gj] of f = 1 (the MLS matrix), P and v.
    var a = mls_zero();
    var m_p = vec4<f32>(0.0);
    var m_vx = vec4<f32>(0.0);
    var m_vy = vec4<f32>(0.0);
    var m_vz = vec4<f32>(0.0);
    // The fluid of each slot around, which comes first in it (shaders/lib/neighbours.wgsl).
    var rows: NeighbourRanges;
    var w = slot_walk(pg, &rows, false);
    for (; walk_on(&w, &rows); w.j++) {
        let j = w.j;
        let x_gj = rel_pos(pg, pos[j]);
        let r2 = dot(x_gj, x_gj);
        if (r2 >= support2) {
            continue;
        }
        let vr = velrho[j];
        let wv = kernel_w(sqrt(r2) / params.h) * params.mass / vr.w;
        let basis = mls_basis(x_gj);
        a = mls_add(a, x_gj, wv);
        m_p += (pressure_of(vr.w) + vr.w * dot(g_eff, x_gj)) * wv * basis;
        m_vx += vr.x * wv * basis;
        m_vy += vr.y * wv * basis;
        m_vz += vr.z * wv * basis;
    }
    let volume = a[0][0];
    if (volume <= 1e-6) {
        return vec4<f32>(0.0);
    }
    // Shepard: the zeroth moments over Σ W V.
    var beta = vec4<f32>(1.0 / volume, 0.0, 0.0, 0.0);
    if (params.ghost_mls == GHOST_MLS) {
        let sol = mls_solve(a);
        if (sol.ok) {
            beta = sol.beta;
        }
    }
    return vec4<f32>(dot(beta, m_vx), dot(beta, m_vy), dot(beta, m_vz), dot(beta, m_p));
}

// The neighbour sum of weakly-compressible SPH, one invocation per particle (gather, no
// atomics), in cell order. Writes rate = (dv/dt, dρ/dt).
//
// Continuity (the seed's eq. 1; Monaghan 1992):  dρ_i/dt = Σ_j m_j v_ij·∇_i W_ij
//   + δ-SPH diffusion between fluid particles (Molteni & Colagrossi 2009, eq. 8):
//     δ h c0 Σ_j 2 (ρ_j − ρ_i) (x_ji·∇_i W_ij)/(r² + η²) V_j
// Momentum (the seed's eq. 2 with σ = −P I; Monaghan 1992):
//   dv_i/dt = −Σ_j m_j (P_i/ρ_i² + P_j/ρ_j² + Π_ij) ∇_i W_ij + g
//   artificial viscosity Π_ij = −α c0 μ_ij / ρ̄_ij, μ_ij = h v_ij·x_ij/(r² + η²) when v_ij·x_ij < 0
//   (Monaghan 1992, eq. 4.2), or laminar viscosity (Lo & Shao 2002, eq. 8; Morris et al. 1997):
//   Σ_j m_j 4ν (x_ij·∇_i W_ij) / ((ρ_i + ρ_j)(r² + η²)) v_ij
// Wall particles (dynamic boundary, Crespo et al. 2007) get only dρ/dt, from fluid neighbours.

@group(0) @binding(1) var<storage, read> pos: array<Pos>;
@group(0) @binding(2) var<storage, read> velrho: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> code: array<u32>;
@group(0) @binding(4) var<storage, read> cell_start: array<u32>;
@group(0) @binding(5) var<storage, read_write> rate: array<vec4<f32>>;

@compute @workgroup_size(WG)
fn interaction(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles) {
        return;
    }
    let kind_i = code_kind(code[i]);
    if (kind_i == KIND_EXCLUDED) {
        rate[i] = vec4<f32>(0.0);
        return;
    }
    let fluid_i = kind_i == KIND_FLUID;
    let pi = pos[i];
    let vi = velrho[i].xyz;
    let rho_i = velrho[i].w;
    let p_over_rho2_i = pressure_of(rho_i) / (rho_i * rho_i);
    let support2 = 4.0 * params.h * params.h;
    let inv_h = 1.0 / params.h;

    var acc = vec3<f32>(0.0);
    var drho = 0.0;
    var slots: array<u32, 27>;
    let n_slots = neighbour_slots(cell_of(pi), &slots);
    for (var s = 0u; s < n_slots; s++) {
        let start = cell_start[slots[s]];
        let end = cell_start[slots[s] + 1u];
        for (var j = start; j < end; j++) {
            let x_ij = rel_pos(pi, pos[j]);
            let r2 = dot(x_ij, x_ij);
            if (r2 >= support2 || j == i) {
                continue;
            }
            let kind_j = code_kind(code[j]);
            let fluid_j = kind_j == KIND_FLUID;
            if (!fluid_i && !fluid_j) {
                continue;
            }
            let vr_j = velrho[j];
            let rho_j = vr_j.w;
            let v_ij = vi - vr_j.xyz;
            let f_ij = kernel_f(sqrt(r2) * inv_h);
            let dw_ij = x_ij * f_ij;
            drho += params.mass * dot(v_ij, dw_ij);
            if (!fluid_i) {
                continue;
            }
            if (fluid_j) {
                drho += params.delta_coef * 2.0 * (rho_i - rho_j) * f_ij * r2 / (r2 + params.eta2)
                    * params.mass / rho_j;
            }
            var pi_ij = 0.0;
            if (VISCOSITY == 0u) {
                let vx = dot(v_ij, x_ij);
                if (vx < 0.0) {
                    let mu = params.h * vx / (r2 + params.eta2);
                    pi_ij = -params.alpha * params.c0 * mu / (0.5 * (rho_i + rho_j));
                }
            } else {
                acc += params.mass * 4.0 * params.nu * r2 * f_ij / ((rho_i + rho_j) * (r2 + params.eta2)) * v_ij;
            }
            let p_over_rho2_j = pressure_of(rho_j) / (rho_j * rho_j);
            acc -= params.mass * (p_over_rho2_i + p_over_rho2_j + pi_ij) * dw_ij;
        }
    }
    if (fluid_i) {
        acc += params.gravity;
    }
    rate[i] = vec4<f32>(acc, drho);
}

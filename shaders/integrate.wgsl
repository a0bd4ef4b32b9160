// Time integration (docs/equations.md eq. 30): velocity Verlet with a predicted velocity for the
// velocity-dependent terms (a predictor–corrector; symplectic for the conservative part):
//   predict:  x_{n+1} = x_n + dt v_n + ½dt² a_n,  v* = v_n + dt a_n,  ρ* = ρ_n + dt Dρ_n
//   (evaluate a_{n+1}, Dρ_{n+1} at x_{n+1}, v*, ρ*)
//   correct:  v_{n+1} = v* + ½dt (a_{n+1} − a_n),  ρ_{n+1} = ρ* + ½dt (Dρ_{n+1} − Dρ_n)
// i.e. v_{n+1} = v_n + ½dt (a_n + a_{n+1}) and likewise for ρ (trapezoidal rule).
// Variable dt from the CFL, force and viscous conditions (eq. 31; Monaghan 1989; Morris et al.
// 1997), computed on the GPU by a max-reduction, so no per-particle data leaves the GPU.

@group(0) @binding(1) var<storage, read_write> pos: array<Pos>;
@group(0) @binding(2) var<storage, read_write> velrho: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> code: array<u32>;
@group(0) @binding(4) var<storage, read> rate: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> rate_old: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> state: SimState;
@group(0) @binding(7) var<storage, read> cell_start: array<u32>;
// (e, de/dt of the last evaluation) and the new de/dt, when ENERGY.
@group(0) @binding(8) var<storage, read_write> energy: array<vec2<f32>>;
@group(0) @binding(9) var<storage, read> energy_rate: array<f32>;

fn all_finite(v: vec4<f32>) -> bool {
    // NaN fails every comparison; |inf| fails the bound.
    return all(abs(v) < vec4<f32>(3.0e38));
}

// Dynamic boundary particles never go below ρ0 (no suction at walls; DualSPHysics does the same).
fn wall_density(rho: f32) -> f32 {
    return max(rho, params.rho0);
}

fn exclude(i: u32) {
    code[i] = with_kind(code[i], KIND_EXCLUDED);
}

@compute @workgroup_size(WG)
fn predict(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles) {
        return;
    }
    let dt = state.dt;
    let kind = code_kind(code[i]);
    let vr = velrho[i];
    let r = rate[i];
    if (kind == KIND_FLUID) {
        var moved = move_by(pos[i], dt * vr.xyz + 0.5 * dt * dt * r.xyz);
        var v = vr.xyz + dt * r.xyz;
        // Mirror walls cannot be crossed: a particle that would cross one (where the pressure
        // near a thin, fast layer is ~0 the images do not push back) is reflected specularly,
        // position and normal velocity, which is what the image method models.
        for (var k = 0u; k < params.n_mirror_planes; k++) {
            let plane = tables.mirror_planes[k];
            let d = dot(domain_pos(moved.pos) - plane.point, plane.normal);
            if (d < 0.0) {
                moved = move_by(moved.pos, -2.0 * d * plane.normal);
                v = reflect_vec(v, plane.normal);
            }
        }
        pos[i] = moved.pos;
        velrho[i] = vec4<f32>(v, vr.w + dt * r.w);
        if (ENERGY) {
            energy[i].x += dt * energy[i].y;
        }
        if (!moved.inside) {
            exclude(i);
        }
    } else if (kind == KIND_WALL) {
        velrho[i].w = wall_density(vr.w + dt * r.w);
    } else if (kind == KIND_SOLID) {
        // Elastic solid (rates from elastic.wgsl): the same predictor as the fluid, no walls.
        let moved = move_by(pos[i], dt * vr.xyz + 0.5 * dt * dt * r.xyz);
        pos[i] = moved.pos;
        velrho[i] = vec4<f32>(vr.xyz + dt * r.xyz, vr.w + dt * r.w);
        if (!moved.inside) {
            exclude(i);
        }
    } else if (kind == KIND_SOLID_CLAMPED) {
        // Held fixed: density (and stress, elastic.wgsl) only.
        velrho[i].w = vr.w + dt * r.w;
    }
}

@compute @workgroup_size(WG)
fn correct(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    let i = linear_index(gid, nwg);
    var speed = 0.0;
    var accel = 0.0;
    var density_variation = 0.0;
    if (i < params.n_particles) {
        let half_dt = 0.5 * state.dt;
        let kind = code_kind(code[i]);
        let r = rate[i];
        let vr = velrho[i];
        if (kind == KIND_FLUID) {
            let v = vec4<f32>(vr.xyz + half_dt * (r.xyz - rate_old[i].xyz), vr.w + half_dt * (r.w - rate_old[i].w));
            velrho[i] = v;
            if (ENERGY) {
                let e = energy[i];
                energy[i] = vec2<f32>(e.x + half_dt * (energy_rate[i] - e.y), energy_rate[i]);
            }
            if (all_finite(v) && all_finite(r) && v.w > 0.0) {
                speed = sound_speed_of(v.w) + length(v.xyz);
                accel = length(r.xyz);
                density_variation = abs(v.w / params.rho0 - 1.0);
                // Counted one by one: rare while the flow is weakly compressible.
                if (density_variation > params.density_warn) {
                    atomicAdd(&state.beyond_warn, 1u);
                    if (density_variation > params.density_stop) {
                        atomicAdd(&state.beyond_stop, 1u);
                    }
                }
            } else {
                atomicAdd(&state.nan_count, 1u);
                exclude(i);
            }
        } else if (is_solid(kind)) {
            var v = vec4<f32>(vr.xyz, vr.w + half_dt * (r.w - rate_old[i].w));
            if (kind == KIND_SOLID) {
                v = vec4<f32>(vr.xyz + half_dt * (r.xyz - rate_old[i].xyz), v.w);
            }
            velrho[i] = v;
            if (all_finite(v) && all_finite(r) && v.w > 0.0) {
                // The time step sees the solid's fastest wave, the P wave:
                // c_p = sqrt((K + 4μ/3)/ρs), above c_s = sqrt(K/ρs) by 13 % (ν = 0.4) to 27 %
                // (ν = 0.3); with c_s the total-Lagrangian solid blew up at cfl 0.2. That of
                // the stiffest material (the solids' bodies differ by at most their |v|).
                speed = params.solid_p_speed + length(v.xyz);
                accel = select(0.0, length(r.xyz), kind == KIND_SOLID);
            } else {
                atomicAdd(&state.nan_count, 1u);
                exclude(i);
            }
        } else if (kind == KIND_WALL) {
            let rho = wall_density(vr.w + half_dt * (r.w - rate_old[i].w));
            velrho[i].w = rho;
            // Moving walls (bodies) count with their speed.
            speed = sound_speed_of(rho) + length(vr.xyz);
        } else if (kind == KIND_INLET) {
            // An inlet particle counts with its inflow velocity (open_boundaries.wgsl). A
            // body's ghost and repulsive particles count with their rigid velocity in
            // bodies.wgsl's `body_move` (a ghost's stored one is the fluid's at it).
            speed = sound_speed_of(vr.w) + length(vr.xyz);
        }
    }
    // Workgroup max, then one atomic per workgroup.
    let largest = workgroup_max(li, vec3<f32>(speed, accel, density_variation));
    if (li == 0u) {
        // Non-negative f32 order like their bit patterns.
        atomicMax(&state.max_speed_bits, bitcast<u32>(largest.x));
        atomicMax(&state.max_accel_bits, bitcast<u32>(largest.y));
        atomicMax(&state.density_variation_bits, bitcast<u32>(largest.z));
    }
}

// One invocation: closes the step (advances time) and chooses the next dt.
@compute @workgroup_size(1)
fn timestep() {
    let taken = state.dt;
    state.t_rel += taken;
    if (taken > 0.0) {
        state.steps += 1u;
    }
    let max_speed = bitcast<f32>(atomicLoad(&state.max_speed_bits));
    let max_accel = bitcast<f32>(atomicLoad(&state.max_accel_bits));
    // With nothing live (an empty domain whose inlet's level has not reached a column yet), the
    // sound speed alone: a step of any length would carry the first columns to flow past
    // their buffer.
    var dt = params.cfl * params.h / select(max_speed, params.c0, max_speed == 0.0);
    if (max_accel > 0.0) {
        dt = min(dt, params.cfl * sqrt(params.h / max_accel));
    }
    if (VISCOSITY == VISCOSITY_LAMINAR) {
        dt = min(dt, 0.125 * params.h * params.h / params.nu);
    }
    state.dt_cfl = dt;
    let remaining = state.t_target_rel - state.t_rel;
    // A remainder of a few ulps counts as arrival, so the last step is never a sliver.
    state.dt = select(min(dt, remaining), 0.0, remaining <= 1e-4 * dt);
    atomicStore(&state.max_speed_bits, 0u);
    atomicStore(&state.max_accel_bits, 0u);
    // For the host's weakly-compressible check (src/sph/mod.rs): the largest of the steps since
    // the host last cleared them.
    let variation = bitcast<f32>(atomicExchange(&state.density_variation_bits, 0u));
    state.density_variation_peak = max(state.density_variation_peak, variation);
    state.beyond_warn_peak = max(state.beyond_warn_peak, atomicExchange(&state.beyond_warn, 0u));
    state.beyond_stop_peak = max(state.beyond_stop_peak, atomicExchange(&state.beyond_stop, 0u));
    let excluded_slot = params.hash_mask + 1u;
    state.excluded = cell_start[excluded_slot + 1u] - cell_start[excluded_slot];
}

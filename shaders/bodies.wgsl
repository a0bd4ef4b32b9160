// Moving bodies (rigid, free or prescribed). The host integrates each body in f64 (src/body/,
// docs/equations.md eqs. 5–6) and uploads its motion for the step; here the GPU
//   body_move:  places every body particle a at x_a = x_c + R r_a with u_a = u_c + ω × (R r_a)
//               (eq. 4), after the predictor and before the sort, and puts c_a + |u_a| into
//               the time step's max-reduction (eq. 31; a ghost's stored velocity is the fluid's);
//   body_index: after the sort, records where each body particle now is (body_slot);
//   body_force: after the interaction, sums per workgroup the force m a_a on each body particle
//               and its moment (R r_a) × m a_a about the centre of mass (eqs. 5–6); the host
//               finishes the sums in f64, in workgroup order (deterministic).
// Body particles are dynamic, fixed-ghost or repulsive boundary particles; the interaction
// gives each the reaction of its fluid neighbours' force (interaction.wgsl), so momentum is
// exchanged pairwise. Design notes: docs/design/bodies.md.

@group(0) @binding(1) var<storage, read_write> pos: array<Pos>;
@group(0) @binding(2) var<storage, read_write> velrho: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> code: array<u32>;
@group(0) @binding(4) var<storage, read> rate: array<vec4<f32>>;
// Index in the particle arrays of body particle k, as of the last sort.
@group(0) @binding(7) var<storage, read_write> body_slot: array<u32>;
// Per workgroup of body_force: (force, 0) then (torque, 0).
@group(0) @binding(8) var<storage, read_write> body_partials: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read_write> state: SimState;

var<workgroup> wg_force: array<vec3<f32>, WG>;
var<workgroup> wg_torque: array<vec3<f32>, WG>;

@compute @workgroup_size(WG)
fn body_move(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    let k = linear_index(gid, nwg);
    var speed = 0.0;
    if (k < params.n_body_particles) {
        let i = body_slot[k];
        if (code_kind(code[i]) != KIND_EXCLUDED) {
            let bp = tables.body_particles[k];
            let m = tables.bodies[bp.body];
            let arm = m.rotation * bp.r;
            let moved = move_by(Pos(m.center_off, m.center_block), arm);
            let vr = vec4<f32>(body_wall_motion(m, bp.r).velocity, velrho[i].w);
            pos[i] = moved.pos;
            velrho[i] = vr;
            if (moved.inside) {
                speed = sound_speed_of(vr.w) + length(vr.xyz);
            } else {
                code[i] = with_kind(code[i], KIND_EXCLUDED);
            }
        }
    }
    // Workgroup max, then one atomic per workgroup, as in integrate.wgsl's `correct` (which
    // runs later in the step, before the time step is chosen from the maximum).
    let largest = workgroup_max(li, vec3<f32>(speed, 0.0, 0.0));
    if (li == 0u) {
        atomicMax(&state.max_speed_bits, bitcast<u32>(largest.x));
    }
}

@compute @workgroup_size(WG)
fn body_index(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles) {
        return;
    }
    let id = code[i] & ID_MASK;
    if (is_body_particle(id)) {
        body_slot[id - params.body_id_base] = i;
    }
}

@compute @workgroup_size(WG)
fn body_force(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    let group = wid.x + wid.y * nwg.x;
    // The body this workgroup belongs to: the last whose first group is not after it.
    var b = 0u;
    for (var c = 1u; c < N_BODIES; c++) {
        if (tables.bodies[c].first_group <= group) {
            b = c;
        }
    }
    let m = tables.bodies[b];
    let local = (group - m.first_group) * WG + li;
    var force = vec3<f32>(0.0);
    var torque = vec3<f32>(0.0);
    if (local < m.count) {
        let k = m.first + local;
        let i = body_slot[k];
        if (code_kind(code[i]) != KIND_EXCLUDED) {
            force = params.mass * rate[i].xyz;
            torque = cross(m.rotation * tables.body_particles[k].r, force);
        }
    }
    // Tree reduction in a fixed order: the same input gives the same sums.
    wg_force[li] = force;
    wg_torque[li] = torque;
    workgroupBarrier();
    for (var s = WG / 2u; s > 0u; s >>= 1u) {
        if (li < s) {
            wg_force[li] += wg_force[li + s];
            wg_torque[li] += wg_torque[li + s];
        }
        workgroupBarrier();
    }
    if (li == 0u) {
        body_partials[2u * group] = vec4<f32>(wg_force[0], 0.0);
        body_partials[2u * group + 1u] = vec4<f32>(wg_torque[0], 0.0);
    }
}

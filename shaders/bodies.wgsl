// Moving bodies (rigid, free or prescribed). The host integrates each body in f64 (src/body/,
// docs/equations.md eqs. 5–6) and uploads its motion for the step; here the GPU
//   body_move:  places every body particle a at x_a = x_c + R r_a with u_a = u_c + ω × (R r_a)
//               (eq. 4), after the predictor and before the sort, and puts c_a + |u_a| into
//               the time step's max-reduction (eq. 31; a ghost's stored velocity is the fluid's);
//   body_forget, body_index: after the sort, record where each live body particle now is
//               (body_slot; BODY_ABSENT where the arrays hold none: over ranks a subdomain holds
//               only some of a body's particles, and a slot left from a particle that migrated
//               would name another particle);
//   body_load:  after the interaction, the force m a_a on each body particle and its moment
//               (R r_a) × m a_a about the centre of mass (eqs. 5–6), per body particle;
//   body_force: sums them per workgroup in a fixed tree; the host finishes the sums in f64, in
//               workgroup order (deterministic). Over ranks the host adds the ranks' per-particle
//               loads and repeats this tree itself (`sph::bodies::workgroup_sums`), so that the
//               sums are one whole run's bit for bit.
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
// Per body particle k (body_load): (force, 0) then (torque, 0); zeros for a particle that is
// excluded or not held.
@group(0) @binding(10) var<storage, read_write> body_loads: array<vec4<f32>>;

// A body_slot entry whose particle the arrays do not hold (live).
const BODY_ABSENT: u32 = 0xffffffffu;

// Where body particle k is live in the arrays, or BODY_ABSENT.
fn live_body_slot(k: u32) -> u32 {
    let i = body_slot[k];
    if (i == BODY_ABSENT || code_kind(code[i]) == KIND_EXCLUDED) {
        return BODY_ABSENT;
    }
    return i;
}

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
        let i = live_body_slot(k);
        if (i != BODY_ABSENT) {
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
fn body_forget(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = linear_index(gid, nwg);
    if (k < params.n_body_particles) {
        body_slot[k] = BODY_ABSENT;
    }
}

// After body_forget: each live body particle is held once, so no two invocations write one
// slot (an excluded entry may repeat an id: it is not indexed).
@compute @workgroup_size(WG)
fn body_index(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles || code_kind(code[i]) == KIND_EXCLUDED) {
        return;
    }
    let id = particle_id(i);
    if (is_body_particle(id)) {
        body_slot[id - params.body_id_base] = i;
    }
}

@compute @workgroup_size(WG)
fn body_load(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = linear_index(gid, nwg);
    if (k >= params.n_body_particles) {
        return;
    }
    let i = live_body_slot(k);
    var force = vec3<f32>(0.0);
    var torque = vec3<f32>(0.0);
    if (i != BODY_ABSENT) {
        let bp = tables.body_particles[k];
        force = params.mass * rate[i].xyz;
        torque = cross(tables.bodies[bp.body].rotation * bp.r, force);
    }
    body_loads[2u * k] = vec4<f32>(force, 0.0);
    body_loads[2u * k + 1u] = vec4<f32>(torque, 0.0);
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
        force = body_loads[2u * k].xyz;
        torque = body_loads[2u * k + 1u].xyz;
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

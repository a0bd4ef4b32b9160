// Fixed ghost particles, the seed's improved fluid–solid interface: ghosts are generated once
// inside walls and bodies and never move relative to their solid. Each step `ghost_interpolate`
// sets their pressure and velocity from the fluid with the corrected kernel W^I (Shepard or
// MLS; lib/fluid_at.wgsl). Equations as numbered in docs/equations.md:
//   P_g, eq. 13, with the hydrostatic correction along g − a_wall, eq. 21 (Adami, Hu & Adams
//     2012); ρ_g from P_g by the inverse Tait equation, eq. 17;
//   the interpolated fluid velocity, from which interaction.wgsl makes the no-slip or
//     free-slip ghost velocity, eq. 15.
// `solid_interface_pressure` gives each elastic solid particle (the seed's third ghost kind)
// the interface pressure P_g of eqs. 13 and 21 for the fluid–solid terms, eq. 28.
// Design notes: docs/design/ghost.md.

@group(0) @binding(1) var<storage, read> pos: array<Pos>;
@group(0) @binding(2) var<storage, read_write> velrho: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> code: array<u32>;
@group(0) @binding(4) var<storage, read> cell_start: array<u32>;

@compute @workgroup_size(WG)
fn ghost_interpolate(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let g = linear_index(gid, nwg);
    if (g >= params.n_particles || !is_ghost(code_kind(code[g]))) {
        return;
    }
    var g_eff = params.gravity;
    let id = particle_id(g);
    if (is_body_particle(id)) {
        let bp = tables.body_particles[id - params.body_id_base];
        g_eff -= body_wall_motion(tables.bodies[bp.body], bp.r).accel;
    }
    let f = fluid_at(pos[g], g_eff);
    // The interpolated fluid velocity is stored; the interaction makes the no-slip ghost
    // velocity 2 v_wall − v (v_wall = 0) from it for the viscous terms, and uses the wall's own
    // velocity in continuity.
    velrho[g] = vec4<f32>(f.xyz, density_of(f.w));
}

// Elastic solid particles are the ghosts of their body for the fluid (the seed's third kind,
// elastic-body ghosts, which move with their solid): each gets the fluid pressure interpolated
// at its position, P_g = Σ_j P_j W^I_gj V_j (with the same hydrostatic correction), stored in
// its `interface_p`. interaction.wgsl uses P_g, not the solid's own stress, in the fluid–solid
// pair terms, so the solid's deviatoric stress never acts on the fluid directly.
@group(0) @binding(5) var<storage, read_write> solid: array<SolidState>;

@compute @workgroup_size(WG)
fn solid_interface_pressure(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let g = linear_index(gid, nwg);
    if (g >= params.n_particles || !is_solid(code_kind(code[g]))) {
        return;
    }
    // (Along g only: the solid's own acceleration is left out of the correction.)
    solid[solid_slot(g)].interface_p = fluid_at(pos[g], params.gravity).w;
}

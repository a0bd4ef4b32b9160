// A subdomain's step that overlaps the exchange (issue 32; docs/scaling.md). The particles
// that read nothing the exchange brings are summed on a first sort's order while the halo
// travels (interaction.wgsl `interaction_interior`); what arrived is written after them and
// the arrays are sorted again, into the order one whole run's sort gives, where the rest are
// summed (`interaction_boundary`). That second sort carries two rates a particle: the last
// evaluation's (`rate_old`, which the corrector reads) and this step's, already summed for the
// interior (`rate`). The sort's gather carries one, `rate` into `rate_old`'s place, so the
// last rates wait in `rate_held` meanwhile. With the energy equation this step's de/dt
// (`energy_rate`, which no sort gathers) goes the same way through `energy_rate_held`.

@group(0) @binding(1) var<storage, read> perm: array<u32>;
@group(0) @binding(2) var<storage, read_write> rate: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> rate_old: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> rate_held: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> energy_rate: array<f32>;
@group(0) @binding(6) var<storage, read_write> energy_rate_held: array<f32>;

// Before the second sort's gather: the last rates, and this step's de/dt, in the new order.
@compute @workgroup_size(WG)
fn hold_old_rates(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = linear_index(gid, nwg);
    if (k < params.n_particles) {
        rate_held[k] = rate_old[perm[k]];
        if (ENERGY) {
            energy_rate_held[k] = energy_rate[perm[k]];
        }
    }
}

// After it: the gather left this step's rates in `rate_old`; each back in its place.
@compute @workgroup_size(WG)
fn settle_rates(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = linear_index(gid, nwg);
    if (k < params.n_particles) {
        rate[k] = rate_old[k];
        rate_old[k] = rate_held[k];
        if (ENERGY) {
            energy_rate[k] = energy_rate_held[k];
        }
    }
}

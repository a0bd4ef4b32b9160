// Cell-list neighbour search, every step: cell key + atomic histogram, (prefix scan in
// prefix_scan.wgsl), scatter, deterministic rank within each slot, reorder of particle arrays.
// The order within a slot is by code word (kind, then particle id: a slot's fluid first): it
// depends neither on the atomics (which only decide a provisional placement) nor on where a
// particle was in the arrays before, so the same particles give the same order however they
// were stored (a subdomain's particles with its neighbours' halo among them sum in the same
// order as in one whole run).

@group(0) @binding(1) var<storage, read> pos: array<Pos>;
@group(0) @binding(2) var<storage, read> code: array<u32>;
@group(0) @binding(4) var<storage, read_write> local_rank: array<u32>;
@group(0) @binding(5) var<storage, read_write> counts: array<atomic<u32>>;
@group(0) @binding(6) var<storage, read> cell_start: array<u32>;
@group(0) @binding(7) var<storage, read_write> provisional: array<u32>;
@group(0) @binding(8) var<storage, read_write> perm: array<u32>;

@group(0) @binding(10) var<storage, read> pos_in: array<Pos>;
@group(0) @binding(11) var<storage, read> velrho_in: array<vec4<f32>>;
@group(0) @binding(12) var<storage, read> rate_in: array<vec4<f32>>;
@group(0) @binding(13) var<storage, read> code_in: array<u32>;
@group(0) @binding(14) var<storage, read_write> pos_out: array<Pos>;
@group(0) @binding(15) var<storage, read_write> velrho_out: array<vec4<f32>>;
@group(0) @binding(16) var<storage, read_write> rate_out: array<vec4<f32>>;
@group(0) @binding(17) var<storage, read_write> code_out: array<u32>;
@group(0) @binding(18) var<storage, read> energy_in: array<vec2<f32>>;
@group(0) @binding(19) var<storage, read_write> energy_out: array<vec2<f32>>;

// The slot of particle i (excluded particles go to the extra slot `hash_mask + 1`, a
// subdomain's free entries, of id FREE_ID, to the last one, `hash_mask + 2`:
// sph::subdomain::FREE_ID). Recomputed by each kernel of the sort rather than stored: a
// stored key would cost 4 bytes a particle for the few loads of its position it saves.
fn sort_slot(i: u32) -> u32 {
    let c = code[i];
    if (code_kind(c) != KIND_EXCLUDED) {
        return slot_of_cell(cell_of(pos[i]));
    }
    return select(params.hash_mask + 1u, params.hash_mask + 2u, particle_id(i) == FREE_ID);
}

// Each particle's provisional place in its slot, counted into the slot.
@compute @workgroup_size(WG)
fn cell_key(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles) {
        return;
    }
    local_rank[i] = atomicAdd(&counts[sort_slot(i)], 1u);
}

@compute @workgroup_size(WG)
fn scatter(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles) {
        return;
    }
    provisional[cell_start[sort_slot(i)] + local_rank[i]] = i;
}

// Final place = slot start + number of particles of the same slot of a smaller (kind, id) (the
// code word's order with narrow ids; ids are unique), so a slot holds its fluid first (shaders/lib/neighbours.wgsl)
// and the order depends only on which particles there are. O(n_slot) per particle; the excluded
// and free slots keep their provisional order (their particles never interact, and outputs are
// written in id order).
@compute @workgroup_size(WG)
fn rank_in_cell(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if (p >= params.n_particles) {
        return;
    }
    let i = provisional[p];
    let key = sort_slot(i);
    let start = cell_start[key];
    if (key > params.hash_mask) {
        perm[p] = i;
        return;
    }
    let end = cell_start[key + 1u];
    let word = code[i];
    var rank = 0u;
    if (WIDE_IDS) {
        // (kind, id): the code word holds only the id's low bits.
        let id = particle_id(i);
        for (var q = start; q < end; q++) {
            let j = provisional[q];
            let kind_j = code_kind(code[j]);
            let before = kind_j < code_kind(word) || (kind_j == code_kind(word) && particle_id(j) < id);
            rank += select(0u, 1u, before);
        }
    } else {
        for (var q = start; q < end; q++) {
            rank += select(0u, 1u, code[provisional[q]] < word);
        }
    }
    perm[start + rank] = i;
}

// Gathers the positions and code words (with wide ids, the ids' high words after them) into
// cell order. The per-particle arrays go in two
// dispatches (this and `reorder_motion`) so that neither binds more than WebGPU's 8 storage
// buffers.
@compute @workgroup_size(WG)
fn reorder(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if (p >= params.n_particles) {
        return;
    }
    let i = perm[p];
    pos_out[p] = pos_in[i];
    code_out[p] = code_in[i];
    if (WIDE_IDS) {
        code_out[params.n_particles + p] = code_in[params.n_particles + i];
    }
}

// Gathers (v, ρ) and the last rates into cell order.
@compute @workgroup_size(WG)
fn reorder_motion(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if (p >= params.n_particles) {
        return;
    }
    let i = perm[p];
    velrho_out[p] = velrho_in[i];
    rate_out[p] = rate_in[i];
}

// Gathers (e, de/dt) into cell order; a separate dispatch, only when the energy equation is on.
@compute @workgroup_size(WG)
fn reorder_energy(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if (p >= params.n_particles) {
        return;
    }
    energy_out[p] = energy_in[perm[p]];
}

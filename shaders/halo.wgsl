// A subdomain's exchange with its neighbours (issue 32; docs/scaling.md): slabs of the global
// cell grid along one axis, each rank owning the cell layers [own_lo, own_hi).
// `halo_pack`, after the predictor: every live particle outside the own layers has crossed a
// cut and migrates (packed with its last rates); every own particle within `layers` of a cut
// with a neighbour is packed as that neighbour's halo. The host reads the records, swaps them
// with the neighbours and writes what it received after `tail`, the first entry of the last
// sort's free slot. Free entries: `halo_forget` gives every entry excluded since the sort (the
// halo copies and migrants sent, a particle the corrector found non-finite) the free id at the
// step's end, so the next sort puts them in the free slot, apart from the excluded slot, where
// the inlet particles waiting behind their buffers keep their ids (`inlet_flow` wakes them by
// id), as do the particles excluded before the sort (drained, or left the domain in the
// predictor), which the rank writes as one whole run writes them.
// A record carries what the receiver's passes read and, for a migrant, what it goes on
// integrating (its last rates, and its energy with the energy equation).
// A migrant stays in the sender's arrays for this step, as a halo copy: it is within one layer
// of the cut it crossed, and the sender's particles there need it; the receiver's halo for the
// sender was packed before it arrived.
// `halo_drop`, after the interaction: the particles outside the own layers (the halo copies and
// the migrants sent) are excluded, so that the corrector, its reductions and the outputs see
// the rank's own particles only.
// `count_layers`: the rank's load per cell layer, from which the ranks move their cuts
// (`Solver::rebalance`: the same packing without halos, then a sort).
// `halo_restore`, on the density filter's steps (which read the neighbours' corrected
// densities): after the corrector the ranks pack their own halo particles again and swap them;
// each copy the sort put in a cell and `halo_drop` excluded gets back its owner's code word
// and corrected density (the one field of a neighbour the filter reads besides its place),
// found by id among the records received (sorted by id, in `halo_out`), until `halo_drop`
// excludes it again after the filter.

@group(0) @binding(1) var<storage, read> pos: array<Pos>;
@group(0) @binding(2) var<storage, read_write> velrho: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> code: array<u32>;
@group(0) @binding(4) var<storage, read> rate: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> cell_start: array<u32>;

// Mirrored by `sph::halo::HaloCounts`.
struct HaloCounts {
    records: atomic<u32>,
    owned: atomic<u32>,     // live own particles at packing
    tail: u32,
    overflow: atomic<u32>,  // records that did not fit
}

// Mirrored by `sph::halo::HaloRecord`.
struct HaloRecord {
    pos: Pos,
    velrho: vec4<f32>,
    rate: vec4<f32>,
    code: u32,
    dest: u32,          // DEST_* bits; with wide ids, the id's high bits from DEST_ID_SHIFT on
    energy: vec2<f32>,  // (e, de/dt of the last evaluation) when ENERGY, else zeros
}

const DEST_UPPER: u32 = 1u;
const DEST_MIGRANT: u32 = 2u;
// The record after a solid particle's: its stress state, which the receiver writes into its
// solid arrays (τ in velrho and pos.off, dτ/dt in rate and energy; the code word names the
// particle; body, material and interface pressure are not sent: the first two never change,
// the ghost pass recomputes the third).
const DEST_SOLID_STATE: u32 = 4u;
const DEST_ID_SHIFT: u32 = 3u;

// A uniform: the packing binds the eight storage buffers every adapter allows.
@group(0) @binding(6) var<uniform> halo_ctl: HaloCtl;
@group(0) @binding(7) var<storage, read_write> halo_counts: HaloCounts;
@group(0) @binding(8) var<storage, read_write> halo_out: array<HaloRecord>;
// Weighted own particles per cell layer along the axis (`count_layers`): 2 for a particle that
// moves, 1 for a boundary particle (decomposition.rs's weights, doubled to be whole).
@group(0) @binding(9) var<storage, read_write> layer_load: array<atomic<u32>>;
// (e, de/dt of the last evaluation); one unused entry without the energy equation.
@group(0) @binding(10) var<storage, read> energy: array<vec2<f32>>;
// The solid particles' stress state, by id − solid_id_base (one unused entry without solids).
@group(0) @binding(11) var<storage, read> solid: array<SolidState>;

fn layer_of(p: Pos) -> u32 {
    return slab_layer(p, halo_ctl.axis);
}

// The id of the particle a record carries.
fn record_id(r: HaloRecord) -> u32 {
    return whole_id(r.code, r.dest >> DEST_ID_SHIFT);
}

fn pack_record(i: u32, flags: u32) {
    var dest = flags;
    if (WIDE_IDS) {
        dest |= (particle_id(i) >> ID_LOW_BITS) << DEST_ID_SHIFT;
    }
    let solid_state = is_solid(code_kind(code[i]));
    let n = select(1u, 2u, solid_state);
    let k = atomicAdd(&halo_counts.records, n);
    if (k + n > halo_ctl.capacity) {
        atomicAdd(&halo_counts.overflow, n);
        return;
    }
    var e = vec2<f32>(0.0);
    if (ENERGY) {
        e = energy[i];
    }
    halo_out[k] = HaloRecord(pos[i], velrho[i], rate[i], code[i], dest, e);
    if (solid_state) {
        let s = solid[solid_slot(i)];
        halo_out[k + 1u] = HaloRecord(
            Pos(s.tau_b, 0u), s.tau_a, s.rate_a, code[i], dest | DEST_SOLID_STATE, s.rate_b);
    }
}

// The free tail for the host (`halo_pack`'s records go after it): the last sort's free slot.
@compute @workgroup_size(1)
fn halo_tail() {
    halo_counts.tail = cell_start[params.hash_mask + 2u];
}

@compute @workgroup_size(WG)
fn halo_pack(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles || code_kind(code[i]) == KIND_EXCLUDED) {
        return;
    }
    let layer = layer_of(pos[i]);
    if (layer < halo_ctl.own_lo || layer >= halo_ctl.own_hi) {
        pack_record(i, DEST_MIGRANT | select(0u, DEST_UPPER, layer >= halo_ctl.own_hi));
        return;
    }
    atomicAdd(&halo_counts.owned, 1u);
    if (halo_ctl.lower != 0u && layer < halo_ctl.own_lo + halo_ctl.layers) {
        pack_record(i, 0u);
    }
    if (halo_ctl.upper != 0u && layer + halo_ctl.layers >= halo_ctl.own_hi) {
        pack_record(i, DEST_UPPER);
    }
}

@compute @workgroup_size(WG)
fn halo_drop(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles || code_kind(code[i]) == KIND_EXCLUDED) {
        return;
    }
    let layer = layer_of(pos[i]);
    if (layer < halo_ctl.own_lo || layer >= halo_ctl.own_hi) {
        code[i] = with_kind(code[i], KIND_EXCLUDED);
    }
}

@compute @workgroup_size(WG)
fn count_layers(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles) {
        return;
    }
    let kind = code_kind(code[i]);
    if (kind == KIND_EXCLUDED) {
        return;
    }
    let moves = kind == KIND_FLUID || kind == KIND_SOLID || kind == KIND_INLET;
    atomicAdd(&layer_load[layer_of(pos[i])], select(1u, 2u, moves));
}

@compute @workgroup_size(WG)
fn halo_restore(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= cell_start[params.hash_mask + 1u] || code_kind(code[i]) != KIND_EXCLUDED) {
        return;
    }
    let id = particle_id(i);
    var lo = 0u;
    var hi = atomicLoad(&halo_counts.records);
    let n = hi;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (record_id(halo_out[mid]) < id) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    if (lo < n && record_id(halo_out[lo]) == id) {
        code[i] = halo_out[lo].code;
        velrho[i].w = halo_out[lo].velrho.w;
    }
}

@compute @workgroup_size(WG)
fn halo_forget(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i < cell_start[params.hash_mask + 1u] && code_kind(code[i]) == KIND_EXCLUDED) {
        code[i] = with_kind(FREE_ID & ID_LOW_MASK, KIND_EXCLUDED);
        if (WIDE_IDS) {
            code[params.n_particles + i] = FREE_ID >> ID_LOW_BITS;
        }
    }
}

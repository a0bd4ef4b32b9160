// A subdomain's exchange with its neighbours (issue 32; docs/scaling.md): slabs of the global
// cell grid along one axis, each rank owning the cell layers [own_lo, own_hi).
// `halo_pack`, after the predictor: every live particle outside the own layers has crossed a
// cut and migrates (packed with its last rates); every own particle within `layers` of a cut
// with a neighbour is packed as that neighbour's halo. `halo_count` counts them first and
// `halo_layout` lays the messages out, so that `halo_pack` writes each neighbour's message as
// it travels (`sph::halo::message_header`): the host reads the messages back and sends them as
// they are, with no loop over particles, and uploads what it received as it came;
// `halo_unpack` writes the arrivals into the arrays after `tail`, the first entry of the last
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
// found by id among the copies received (indexed by `halo_index`), until `halo_drop` excludes
// it again after the filter.

// Mirrored by `layout::HaloCounts`. A stream is one section of one message: 3 × neighbour
// (0 below, 1 above) + section (`SECTION_*`).
struct HaloCounts {
    owned: atomic<u32>,     // live own particles at packing
    tail: u32,              // the first free entry: where `halo_unpack` writes the arrivals
    sizes: array<atomic<u32>, 6>,   // records of each stream (`halo_count`)
    filled: array<atomic<u32>, 6>,  // of them written so far (`halo_pack`)
    starts: array<u32, 6>,  // each stream's first word in `halo_out` (`halo_layout`)
    fits: u32,              // 1: the messages fit `halo_out`
}

// Mirrored by `layout::HaloRecord`.
struct HaloRecord {
    pos: Pos,
    velrho: vec4<f32>,
    rate: vec4<f32>,
    code: u32,
    id_high: u32,       // with wide ids, the id's bits above ID_LOW_BITS; else 0
    energy: vec2<f32>,  // (e, de/dt of the last evaluation) when ENERGY, else zeros
}

// A message to a neighbour, as it travels (`sph::halo::message_header`): a header of three counts,
// one per section, then the sections' records. Migrants go whole (they go on integrating their
// last rates and energy), solid stress states too; a halo copy carries only what the
// receiver's passes read of it (its place, (v, ρ), code word and id_high), which its copy in the
// arrays gets with zero rates and energy: 10 words where a record is 16.
const SECTION_MIGRANTS: u32 = 0u;
// A solid particle's stress state, which the receiver writes into its solid arrays (τ in
// velrho and pos.off, dτ/dt in rate and energy; the code word names the particle; body,
// material and interface pressure are not sent: the first two never change, the ghost pass
// recomputes the third).
const SECTION_STATES: u32 = 1u;
const SECTION_COPIES: u32 = 2u;
const HEADER_WORDS: u32 = 3u;
const RECORD_WORDS: u32 = 16u;
const COPY_WORDS: u32 = 10u;
// The density filter's exchange (`halo_ctl.lean`) sends of a copy only what `halo_restore`
// gives it back, its owner's code word and corrected ρ (the filter reads no other field of a
// neighbour's), with wide ids the id's high bits too; and no stress states.
const LEAN_WORDS: u32 = select(2u, 3u, WIDE_IDS);

// Mirrored by `layout::HaloArrivals`: the messages received, one after the other in `halo_out`
// (at most one per neighbour): each one's first word and its sections' counts; `particles`:
// the migrants and copies of all, `states` the stress states.
struct HaloArrivals {
    messages: array<vec4<u32>, 2>,
    particles: u32,
    states: u32,
    copy_words: u32,    // COPY_WORDS, or LEAN_WORDS for the density filter's
    pad: u32,
}

@group(0) @binding(1) var<storage, read_write> pos: array<Pos>;
@group(0) @binding(2) var<storage, read_write> velrho: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> code: array<u32>;
@group(0) @binding(4) var<storage, read> rate: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> cell_start: array<u32>;
// A uniform: the packing binds the eight storage buffers every adapter allows.
@group(0) @binding(6) var<uniform> halo_ctl: HaloCtl;
@group(0) @binding(7) var<storage, read_write> halo_counts: HaloCounts;
// The messages packed (`halo_pack`), then those received (`halo_unpack`, and on the density
// filter's steps `halo_restore`).
@group(0) @binding(8) var<storage, read_write> halo_out: array<u32>;
// Weighted own particles per cell layer along the axis (`count_layers`): 2 for a particle that
// moves, 1 for a boundary particle (decomposition.rs's weights, doubled to be whole).
@group(0) @binding(9) var<storage, read_write> layer_load: array<atomic<u32>>;
// (e, de/dt of the last evaluation); one unused entry without the energy equation.
@group(0) @binding(10) var<storage, read_write> energy: array<vec2<f32>>;
// The solid particles' stress state, by id − solid_id_base (one unused entry without solids).
@group(0) @binding(11) var<storage, read_write> solid: array<SolidState>;
@group(0) @binding(12) var<uniform> halo_arrivals: HaloArrivals;
// Where the arrivals' last rates go: the sort's input (`rate` before it, `rate_sorted` after
// an overlapped step's first sort).
@group(0) @binding(13) var<storage, read_write> arrival_rate: array<vec4<f32>>;
// The copies received for the density filter by id (`halo_index`): an open-addressing table of
// 1 + the copy's index among the arrivals (0: empty), its size a power of two at least twice
// their number.
@group(0) @binding(14) var<storage, read_write> restore_index: array<atomic<u32>>;

fn layer_of(p: Pos) -> u32 {
    return slab_layer(p, halo_ctl.axis);
}

// The id of the particle a record carries.
fn record_id(r: HaloRecord) -> u32 {
    return whole_id(r.code, r.id_high);
}

// Whether a particle in cell layer `layer` has left the rank's own layers (a migrant).
fn outside(layer: u32) -> bool {
    return layer < halo_ctl.own_lo || layer >= halo_ctl.own_hi;
}

// Whether the packing takes entry i: a live particle; and while the cuts move
// (`halo_ctl.moving`), an excluded one that keeps its id outside the slab, so that the rank
// whose layers hold its place holds it: an inlet particle waiting behind its buffer (whose
// place is where it will join, so that the rank that wakes it owns it then), or one drained
// or gone out of the domain (which the ranks write as one whole run writes them).
fn packs(i: u32) -> bool {
    if (code_kind(code[i]) != KIND_EXCLUDED) {
        return true;
    }
    return halo_ctl.moving != 0u && particle_id(i) != FREE_ID && outside(layer_of(pos[i]));
}

// Makes entry i free: excluded, of the free id.
fn free_entry(i: u32) {
    code[i] = with_kind(FREE_ID & ID_LOW_MASK, KIND_EXCLUDED);
    if (WIDE_IDS) {
        code[params.n_particles + i] = FREE_ID >> ID_LOW_BITS;
    }
}

const NO_STREAM: u32 = 0xffffffffu;

// The streams live particle i goes in (NO_STREAM where fewer than two): a migrant's to the
// neighbour whose layers it entered, or a halo copy to each neighbour within `layers` of it.
fn streams_of(i: u32) -> vec2<u32> {
    let layer = layer_of(pos[i]);
    var s = vec2<u32>(NO_STREAM);
    if (outside(layer)) {
        s.x = select(0u, 3u, layer >= halo_ctl.own_hi) + SECTION_MIGRANTS;
        return s;
    }
    if (halo_ctl.lower != 0u && layer < halo_ctl.own_lo + halo_ctl.layers) {
        s.x = SECTION_COPIES;
    }
    if (halo_ctl.upper != 0u && layer + halo_ctl.layers >= halo_ctl.own_hi) {
        s.y = 3u + SECTION_COPIES;
    }
    return s;
}

// Whether particle i's stress state goes with it: a solid particle's, but for the filter.
fn sends_state(i: u32) -> bool {
    return is_solid(code_kind(code[i])) && halo_ctl.lean == 0u;
}

// The stream of the stress states that go with stream `s`'s particles.
fn states_stream(s: u32) -> u32 {
    return s - s % 3u + SECTION_STATES;
}

// Words of a halo copy as this packing writes it.
fn copy_words() -> u32 {
    return select(COPY_WORDS, LEAN_WORDS, halo_ctl.lean != 0u);
}

// Words of the message to neighbour `nb` (0 below, 1 above).
fn message_words(nb: u32) -> u32 {
    let b = 3u * nb;
    let records = atomicLoad(&halo_counts.sizes[b]) + atomicLoad(&halo_counts.sizes[b + 1u]);
    return HEADER_WORDS + RECORD_WORDS * records + copy_words() * atomicLoad(&halo_counts.sizes[b + 2u]);
}

fn put_vec4(at: u32, v: vec4<f32>) {
    for (var c = 0u; c < 4u; c++) {
        halo_out[at + c] = bitcast<u32>(v[c]);
    }
}

fn get_vec4(at: u32) -> vec4<f32> {
    return bitcast<vec4<f32>>(vec4<u32>(halo_out[at], halo_out[at + 1u], halo_out[at + 2u], halo_out[at + 3u]));
}

fn put_pos(at: u32, p: Pos) {
    put_vec4(at, vec4<f32>(p.off, bitcast<f32>(p.block)));
}

fn get_pos(at: u32) -> Pos {
    let w = get_vec4(at);
    return Pos(w.xyz, bitcast<u32>(w.w));
}

// A whole record's words: pos, velrho, rate, code, id_high, energy (as `HaloRecord`).
fn put_record(at: u32, r: HaloRecord) {
    put_pos(at, r.pos);
    put_vec4(at + 4u, r.velrho);
    put_vec4(at + 8u, r.rate);
    put_vec4(at + 12u, vec4<f32>(bitcast<f32>(r.code), bitcast<f32>(r.id_high), r.energy));
}

fn get_record(at: u32) -> HaloRecord {
    let last = get_vec4(at + 12u);
    return HaloRecord(get_pos(at), get_vec4(at + 4u), get_vec4(at + 8u), bitcast<u32>(last.x),
        bitcast<u32>(last.y), last.zw);
}

// A halo copy's words: pos, velrho, code, id_high (`sph::halo::HaloCopy`); lean: code, ρ and
// with wide ids id_high (`LEAN_WORDS`).
fn put_copy(at: u32, r: HaloRecord) {
    if (halo_ctl.lean != 0u) {
        halo_out[at] = r.code;
        halo_out[at + 1u] = bitcast<u32>(r.velrho.w);
        if (WIDE_IDS) {
            halo_out[at + 2u] = r.id_high;
        }
        return;
    }
    put_pos(at, r.pos);
    put_vec4(at + 4u, r.velrho);
    halo_out[at + 8u] = r.code;
    halo_out[at + 9u] = r.id_high;
}

// The record of a copy received: its rates and energy zero, which no pass reads of a copy
// (a lean copy's: its code word, ρ and id_high, all `halo_restore` reads).
fn get_copy(at: u32) -> HaloRecord {
    if (halo_arrivals.copy_words != COPY_WORDS) {
        var id_high = 0u;
        if (WIDE_IDS) {
            id_high = halo_out[at + 2u];
        }
        let rho = bitcast<f32>(halo_out[at + 1u]);
        return HaloRecord(Pos(), vec4<f32>(0.0, 0.0, 0.0, rho), vec4<f32>(0.0), halo_out[at],
            id_high, vec2<f32>(0.0));
    }
    return HaloRecord(get_pos(at), get_vec4(at + 4u), vec4<f32>(0.0), halo_out[at + 8u],
        halo_out[at + 9u], vec2<f32>(0.0));
}

// Writes particle i's record into the next place of stream `s`, and its stress state (a solid
// particle's) into the next of the states' stream.
fn pack_into(i: u32, s: u32) {
    if (s == NO_STREAM) {
        return;
    }
    var id_high = 0u;
    if (WIDE_IDS) {
        id_high = particle_id(i) >> ID_LOW_BITS;
    }
    var e = vec2<f32>(0.0);
    if (ENERGY) {
        e = energy[i];
    }
    let r = HaloRecord(pos[i], velrho[i], rate[i], code[i], id_high, e);
    let k = atomicAdd(&halo_counts.filled[s], 1u);
    if (s % 3u == SECTION_COPIES) {
        put_copy(halo_counts.starts[s] + copy_words() * k, r);
    } else {
        put_record(halo_counts.starts[s] + RECORD_WORDS * k, r);
    }
    if (sends_state(i)) {
        let t = states_stream(s);
        let st = solid[solid_slot(i)];
        let state = HaloRecord(Pos(st.tau_b, 0u), st.tau_a, st.rate_a, code[i], id_high, st.rate_b);
        put_record(halo_counts.starts[t] + RECORD_WORDS * atomicAdd(&halo_counts.filled[t], 1u), state);
    }
}

// The free tail, where `halo_unpack` writes: the last sort's free slot.
@compute @workgroup_size(1)
fn halo_tail() {
    halo_counts.tail = cell_start[params.hash_mask + 2u];
}

// Counts the rank's own particles and the records of each stream, for `halo_pack`.
@compute @workgroup_size(WG)
fn halo_count(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles || !packs(i)) {
        return;
    }
    if (code_kind(code[i]) != KIND_EXCLUDED && !outside(layer_of(pos[i]))) {
        atomicAdd(&halo_counts.owned, 1u);
    }
    let s = streams_of(i);
    let solid = sends_state(i);
    for (var k = 0u; k < 2u; k++) {
        if (s[k] != NO_STREAM) {
            atomicAdd(&halo_counts.sizes[s[k]], 1u);
            if (solid) {
                atomicAdd(&halo_counts.sizes[states_stream(s[k])], 1u);
            }
        }
    }
}

// Lays out the two messages `halo_count` counted, one after the other: writes their headers
// and where each stream starts; nothing where they do not fit (the host grows `halo_out` and
// packs again).
@compute @workgroup_size(1)
fn halo_layout() {
    let lower = message_words(0u);
    halo_counts.fits = u32(lower + message_words(1u) <= halo_ctl.capacity * RECORD_WORDS);
    if (halo_counts.fits == 0u) {
        return;
    }
    for (var nb = 0u; nb < 2u; nb++) {
        let header = select(0u, lower, nb == 1u);
        var at = header + HEADER_WORDS;
        for (var k = 0u; k < 3u; k++) {
            let size = atomicLoad(&halo_counts.sizes[3u * nb + k]);
            halo_out[header + k] = size;
            halo_counts.starts[3u * nb + k] = at;
            at += select(RECORD_WORDS, copy_words(), k == SECTION_COPIES) * size;
        }
    }
}

// Writes the particles' records into the messages `halo_layout` laid out.
@compute @workgroup_size(WG)
fn halo_pack(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (halo_counts.fits == 0u || i >= params.n_particles || !packs(i)) {
        return;
    }
    let s = streams_of(i);
    pack_into(i, s.x);
    pack_into(i, s.y);
    // An excluded particle goes as it is: no pass excludes it again on its way out.
    if (code_kind(code[i]) == KIND_EXCLUDED) {
        free_entry(i);
    }
}

// Particle k of the arrivals (`HaloArrivals`'s migrants and copies, message by message).
fn arrival(k: u32) -> HaloRecord {
    var r = k;
    for (var m = 0u; m < 2u; m++) {
        let msg = halo_arrivals.messages[m];
        let records = msg.x + HEADER_WORDS;
        if (r < msg.y) {
            return get_record(records + RECORD_WORDS * r);
        }
        if (r < msg.y + msg.w) {
            let copy = halo_arrivals.copy_words * (r - msg.y);
            return get_copy(records + RECORD_WORDS * (msg.y + msg.z) + copy);
        }
        r -= msg.y + msg.w;
    }
    return HaloRecord();
}

// Writes arrival k at the free tail.
fn place_particle(k: u32) {
    let j = halo_counts.tail + k;
    if (j >= params.n_particles) {
        return; // the host checked the room; never written past the arrays
    }
    let a = arrival(k);
    pos[j] = a.pos;
    velrho[j] = a.velrho;
    code[j] = a.code;
    if (WIDE_IDS) {
        code[params.n_particles + j] = a.id_high;
    }
    arrival_rate[j] = a.rate;
    if (ENERGY) {
        energy[j] = a.energy;
    }
}

// Writes stress state k of the arrivals into the solid arrays, by its particle's id.
fn place_state(k: u32) {
    var r = k;
    for (var m = 0u; m < 2u; m++) {
        let msg = halo_arrivals.messages[m];
        if (r < msg.z) {
            let a = get_record(msg.x + HEADER_WORDS + RECORD_WORDS * (msg.y + r));
            let s = record_id(a) - params.solid_id_base;
            solid[s].tau_a = a.velrho;
            solid[s].tau_b = a.pos.off;
            solid[s].rate_a = a.rate;
            solid[s].rate_b = a.energy;
            return;
        }
        r -= msg.z;
    }
}

// Writes what the neighbours sent (uploaded as it came into `halo_out`) into the arrays: the
// particles from the free tail on, in message order (the sort orders them), the stress states
// into the solid arrays.
@compute @workgroup_size(WG)
fn halo_unpack(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = linear_index(gid, nwg);
    if (k < halo_arrivals.particles) {
        place_particle(k);
    } else if (k < halo_arrivals.particles + halo_arrivals.states) {
        place_state(k - halo_arrivals.particles);
    }
}

@compute @workgroup_size(WG)
fn halo_drop(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles || code_kind(code[i]) == KIND_EXCLUDED) {
        return;
    }
    if (outside(layer_of(pos[i]))) {
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

// Multiplicative hashing (Knuth, TAOCP vol. 3, 6.4): odd, so consecutive ids take distinct
// slots of a power-of-two table.
fn id_slot(id: u32, mask: u32) -> u32 {
    return (id * 2654435761u) & mask;
}

// Indexes the copies received for the density filter (uploaded as they came) by id, for
// `halo_restore`: no sort, and the same table whatever order they go in.
@compute @workgroup_size(WG)
fn halo_index(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = linear_index(gid, nwg);
    if (k >= halo_arrivals.particles) {
        return;
    }
    let mask = arrayLength(&restore_index) - 1u;
    var slot = id_slot(record_id(arrival(k)), mask);
    loop {
        let r = atomicCompareExchangeWeak(&restore_index[slot], 0u, k + 1u);
        if (r.exchanged) {
            return;
        }
        if (r.old_value != 0u) {
            slot = (slot + 1u) & mask;
        }
    }
}

// Gives each halo copy that `halo_drop` excluded its owner's code word and corrected density,
// found by id among the copies received (`halo_index`).
@compute @workgroup_size(WG)
fn halo_restore(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= cell_start[params.hash_mask + 1u] || code_kind(code[i]) != KIND_EXCLUDED) {
        return;
    }
    let id = particle_id(i);
    let mask = arrayLength(&restore_index) - 1u;
    var slot = id_slot(id, mask);
    loop {
        let k = atomicLoad(&restore_index[slot]);
        if (k == 0u) {
            return;
        }
        let a = arrival(k - 1u);
        if (record_id(a) == id) {
            code[i] = a.code;
            velrho[i].w = a.velrho.w;
            return;
        }
        slot = (slot + 1u) & mask;
    }
}

@compute @workgroup_size(WG)
fn halo_forget(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i < cell_start[params.hash_mask + 1u] && code_kind(code[i]) == KIND_EXCLUDED) {
        free_entry(i);
    }
}

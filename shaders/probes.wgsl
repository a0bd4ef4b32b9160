// Probes, sampled on the GPU so that no particle data leaves it: pressure at a point, wave
// gauges and wall pressure (one invocation per probe, walking the cell list), the surge
// front (a max over fluid particles) and the discharge through a section (a sum over them). Results are f32 bit patterns in `probe_out`, read back
// by the host.

struct ProbeDef {
    point: vec3<f32>,   // domain coordinates (from the domain's min corner)
    kind: u32,          // PROBE_*
    axis: vec3<f32>,    // unit vector: a front's direction, a wall patch's normal (into the fluid)
    radius: f32,        // a wall patch's radius across its normal
    face: u32,          // a fixed wall patch's face (WallSensor::face_id), else NO_FACE
    bins: u32,          // a continuous front's first word in front_bins
    words: u32,         // its words of bin bits (the end follows them)
    bin_width: f32,     // its bin width along the axis (2h)
}

const NO_FACE: u32 = 0xFFFFFFFFu;


@group(0) @binding(1) var<storage, read> pos: array<Pos>;
@group(0) @binding(2) var<storage, read> velrho: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> code: array<u32>;
@group(0) @binding(4) var<storage, read> cell_start: array<u32>;
@group(0) @binding(5) var<storage, read> probes: array<ProbeDef>;
@group(0) @binding(6) var<storage, read_write> probe_out: array<atomic<u32>>;
@group(0) @binding(9) var<storage, read> rate: array<vec4<f32>>;
@group(0) @binding(10) var<storage, read_write> front_bins: array<atomic<u32>>;
// The discharge probes' sums over each workgroup: workgroup g's of discharge probe `def.bins`
// (of `def.words`) at g · def.words + def.bins.
@group(0) @binding(11) var<storage, read_write> discharge_sums: array<f32>;

struct KernelSums {
    volume: f32,        // Σ_j W V_j over fluid (the Shepard denominator)
    pressure: f32,      // Σ_j P_j W V_j
}

fn fluid_sums(x: vec3<f32>) -> KernelSums {
    let p = pos_of_point(x);
    let support2 = 4.0 * params.h * params.h;
    var sums = KernelSums(0.0, 0.0);
    // The fluid of each slot around, which comes first in it (shaders/lib/neighbours.wgsl).
    var rows: NeighbourRanges;
    var w = slot_walk(p, &rows, false);
    for (; walk_on(&w, &rows); w.j++) {
        let j = w.j;
        let x_ij = rel_pos(p, pos[j]);
        let r2 = dot(x_ij, x_ij);
        if (r2 < support2) {
            let rho_j = velrho[j].w;
            let wv = kernel_w(sqrt(r2) / params.h) * params.mass / rho_j;
            sums.volume += wv;
            sums.pressure += pressure_of(rho_j) * wv;
        }
    }
    return sums;
}

// Shepard-normalised pressure; 0 (gauge pressure of air) where the kernel sees less than 10 %
// fluid, so a dry sensor reads 0 rather than the pressure of one stray droplet.
fn probe_pressure(x: vec3<f32>) -> f32 {
    let s = fluid_sums(x);
    if (s.volume < 0.1) {
        return 0.0;
    }
    return s.pressure / s.volume;
}

// Wave gauges. The free-surface height on the vertical line through a gauge's foot x is the
// highest point of the lattice z_k = x_up + k·h/4 (k = 0 … up to the domain top) where the
// fluid volume fraction Σ W V reaches ½, interpolated linearly towards the point above it.
//
// A serial walk down that lattice from the domain top (as this once was) costs one kernel sum
// per h/4 of air: thousands in a tall domain at a fine dx, and lavapipe (llvmpipe's gallivm)
// silently ends every loop of an invocation after 65535 iterations in all, so a gauge read 0
// with no warning (issue 36). The search is instead spread over the fluid particles
// (`probe_height_search`): a lattice point where Σ W V > 0 lies within 2h of some fluid
// particle, so each particle near the line tries the lattice points within its support,
// from the top down, and keeps the first where Σ W V ≥ ½ (atomicMax of k + 1 in probe_out);
// the largest over particles is the highest such point on the whole line, at a cost per
// invocation bounded by the kernel support, whatever the domain's height. `probe_points` then
// interpolates there (`probe_height`).

const HEIGHT_STEPS_PER_H: f32 = 4.0;

// What a gauge's surface is where half of: the fluid's share of the kernel, Σ W V (a wave
// gauge, `kind = "height"`), or the water's share of what the walls leave of it, ψ (a depth
// gauge, `kind = "depth"`, lib/water_fraction.wgsl: the flood maps' criterion, which finds a
// sheet one particle deep and the surface beside a wall).
fn gauge_fraction(kind: u32, x: vec3<f32>) -> f32 {
    if (kind == PROBE_DEPTH) {
        return water_fraction(map_sums(x));
    }
    return fluid_sums(x).volume;
}

// The gauge's lattice point k on the line through x.
fn height_point(x: vec3<f32>, k: u32) -> vec3<f32> {
    var p = x;
    p[DIM - 1u] = x[DIM - 1u] + f32(k) * (params.h / HEIGHT_STEPS_PER_H);
    return p;
}

// The highest lattice index on the line through x: the last point at or below the domain top.
fn height_top_index(x: vec3<f32>) -> u32 {
    let up = DIM - 1u;
    return u32(max(floor((params.domain_size[up] - x[up]) / (params.h / HEIGHT_STEPS_PER_H)), 0.0));
}

@compute @workgroup_size(WG)
fn probe_height_search(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles || code_kind(code[i]) != KIND_FLUID) {
        return;
    }
    let up = DIM - 1u;
    let xi = domain_pos(pos[i]);
    let step = params.h / HEIGHT_STEPS_PER_H;
    let support2 = 4.0 * params.h * params.h;
    for (var k = 0u; k < params.n_probes; k++) {
        let def = probes[k];
        if (def.kind != PROBE_HEIGHT && def.kind != PROBE_DEPTH) {
            continue;
        }
        var across = xi - def.point;
        across[up] = 0.0;
        let d2 = dot(across, across);
        if (d2 >= support2) {
            continue;
        }
        // The lattice points within the particle's support, one more at each end against f32
        // rounding (a point tried needlessly costs a sum, never a wrong answer).
        let r = sqrt(support2 - d2);
        let rel = xi[up] - def.point[up];
        let hi = i32(floor((rel + r) / step)) + 1;
        let lo = max(i32(ceil((rel - r) / step)) - 1, 0);
        var kk = min(hi, i32(height_top_index(def.point)));
        for (; kk >= lo; kk--) {
            // A point no higher than one already found cannot raise the answer.
            if (u32(kk) + 1u <= atomicLoad(&probe_out[k])) {
                break;
            }
            if (gauge_fraction(def.kind, height_point(def.point, u32(kk))) >= 0.5) {
                atomicMax(&probe_out[k], u32(kk) + 1u);
                break;
            }
        }
    }
}

// The height above the gauge's foot x of the surface `probe_height_search` found (`found`: its
// k + 1, 0 where no point of the line reaches ½: a dry gauge reads 0), interpolated linearly
// between that point and the one above it, and at most the domain top.
fn probe_height(kind: u32, x: vec3<f32>, found: u32) -> f32 {
    if (found == 0u) {
        return 0.0;
    }
    let up = DIM - 1u;
    let p = height_point(x, found - 1u);
    let above = height_point(x, found);
    let v = gauge_fraction(kind, p);
    let v_above = gauge_fraction(kind, above);
    let t = clamp((v - 0.5) / max(v - v_above, 1e-6), 0.0, 1.0);
    return min(mix(p[up], above[up], t), params.domain_size[up]) - x[up];
}

// Σ_j a_j·n over the boundary particles j of a wall patch, a_j their rate (the fluid's force per
// unit fluid mass, interaction.wgsl with WALL_REACTIONS; for a body's particles also any contact
// force); the host multiplies by −m/area. The rates are those of the last step's interaction,
// at its predicted state, in the current cell order; on a fixed wall only the fluid's over the
// face of the sensor the particle belongs to (interaction.wgsl). The patch: no fluid or solid
// particle, `in_wall_patch` (lib/wall_patch.wgsl), and on a fixed wall not a particle that
// belongs to a sensor of another face (`owning_sensor`: at an edge, the one it is nearer).
// The cells of the patch's box are visited once each (a particle counts in its own cell only),
// in a fixed order: the same state gives the same sum.
fn probe_wall_force(def: ProbeDef) -> f32 {
    let e = vec3<f32>(def.radius + 4.0 * params.h);
    var lo = vec3<i32>(floor((def.point - e) * params.inv_cell_size));
    var hi = vec3<i32>(floor((def.point + e) * params.inv_cell_size));
    let n = vec3<i32>(params.grid_cells);
    let periodic = periodic_axes();
    // Each cell once: a periodic axis wraps (at most one period of cells), another is clamped.
    lo = select(max(lo, vec3<i32>(0)), lo, periodic);
    hi = select(min(hi, n - vec3<i32>(1)), min(hi, lo + n - vec3<i32>(1)), periodic);
    if (DIM == 2u) {
        lo.z = 0;
        hi.z = 0;
    }
    var sum = 0.0;
    for (var cz = lo.z; cz <= hi.z; cz++) {
        for (var cy = lo.y; cy <= hi.y; cy++) {
            for (var cx = lo.x; cx <= hi.x; cx++) {
                var c = vec3<i32>(cx, cy, cz);
                c = select(c, ((c % n) + n) % n, periodic);
                let slot = slot_of_cell(c);
                for (var j = cell_start[slot]; j < cell_start[slot + 1u]; j++) {
                    let kind = code_kind(code[j]);
                    if (kind == KIND_FLUID || kind == KIND_EXCLUDED || kind == KIND_INLET || is_solid(kind) || any(cell_of(pos[j]) != c)) {
                        continue;
                    }
                    let x = domain_pos(pos[j]);
                    if (!in_wall_patch(def.point, def.axis, def.radius, x)) {
                        continue;
                    }
                    // A fixed wall's particle that belongs to another face's sensor is its.
                    if (def.face != NO_FACE && !is_body_particle(particle_id(j))) {
                        let owner = owning_sensor(x);
                        if (owner != NO_SENSOR && tables.wall_sensors[owner].face_id != def.face) {
                            continue;
                        }
                    }
                    sum += dot(rate[j].xyz, def.axis);
                }
            }
        }
    }
    return sum;
}

@compute @workgroup_size(WG)
fn probe_points(@builtin(global_invocation_id) gid: vec3<u32>) {
    let k = gid.x;
    if (k >= params.n_probes) {
        return;
    }
    let def = probes[k];
    if (def.kind == PROBE_PRESSURE) {
        atomicStore(&probe_out[k], bitcast<u32>(probe_pressure(def.point)));
    } else if (def.kind == PROBE_HEIGHT || def.kind == PROBE_DEPTH) {
        let found = atomicLoad(&probe_out[k]);
        atomicStore(&probe_out[k], bitcast<u32>(probe_height(def.kind, def.point, found)));
    } else if (def.kind == PROBE_WALL_PRESSURE) {
        atomicStore(&probe_out[k], bitcast<u32>(probe_wall_force(def)));
    }
}

// Order-preserving map of f32 to u32, so atomicMax finds the largest float.
fn ordered_bits(f: f32) -> u32 {
    let b = bitcast<u32>(f);
    return select(b | 0x80000000u, ~b, (b & 0x80000000u) != 0u);
}

// Front probes: max over fluid of (x − origin)·axis. The host zeroes `probe_out` first
// (0 is below every ordered value).
//
// A continuous front is the largest reach of the water that extends from the origin along
// the axis without a gap: the fluid's reaches ≥ 0 are binned in widths of the kernel support
// 2h (one bit a bin, set here), `probe_front_walk` finds the last bin of the first run of wet
// bins, and `probe_front_continuous` takes the largest reach up to it. Two fluid particles
// whose reaches differ by more than 2h cannot be neighbours, so an empty bin is a gap no
// particle bridges: a droplet at least 4h ahead of the tongue is never counted, one less than
// 2h ahead always is.
fn front_bin(def: ProbeDef, reach: f32) -> u32 {
    return u32(floor(reach / def.bin_width));
}

fn in_front_bins(def: ProbeDef, reach: f32) -> bool {
    return reach >= 0.0 && reach < f32(def.words * 32u) * def.bin_width;
}

// The particle of invocation i: whether it is fluid, and its position (none past the end).
struct FluidAt {
    fluid: bool,
    x: vec3<f32>,
}

fn fluid_at(i: u32) -> FluidAt {
    if (i >= params.n_particles) {
        return FluidAt(false, vec3<f32>(0.0));
    }
    return FluidAt(code_kind(code[i]) == KIND_FLUID, domain_pos(pos[i]));
}

@compute @workgroup_size(WG)
fn probe_front(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    let at = fluid_at(linear_index(gid, nwg));
    let fluid = at.fluid;
    let x = at.x;
    for (var k = 0u; k < params.n_probes; k++) {
        let def = probes[k];
        let reach_k = dot(x - def.point, def.axis);
        if (def.kind == PROBE_FRONT_CONTINUOUS) {
            if (fluid && in_front_bins(def, reach_k)) {
                let b = front_bin(def, reach_k);
                atomicOr(&front_bins[def.bins + b / 32u], 1u << (b % 32u));
            }
            continue;
        }
        if (def.kind != PROBE_FRONT) {
            continue;
        }
        let reach = select(-3.0e38, reach_k, fluid);
        let largest = workgroup_max(li, vec3<f32>(reach, 0.0, 0.0));
        if (li == 0u) {
            atomicMax(&probe_out[k], ordered_bits(largest.x));
        }
    }
}

// One invocation a continuous front: the end of its first run of wet bins, stored after its
// bits as the number of bins up to it (0: no fluid binned). A word at a time: a probe's words
// stay below lavapipe's 65535 loop iterations (`FrontBins`).
@compute @workgroup_size(WG)
fn probe_front_walk(@builtin(global_invocation_id) gid: vec3<u32>) {
    let k = gid.x;
    if (k >= params.n_probes || probes[k].kind != PROBE_FRONT_CONTINUOUS) {
        return;
    }
    let def = probes[k];
    var wet = false;
    var end = 0u;
    for (var w = 0u; w < def.words; w++) {
        let bits = atomicLoad(&front_bins[def.bins + w]);
        var dry = ~bits;
        if (!wet) {
            if (bits == 0u) {
                continue;
            }
            wet = true;
            // Only the dry bins above the first wet one end the run.
            dry &= ~0u << countTrailingZeros(bits);
        }
        if (dry != 0u) {
            end = w * 32u + countTrailingZeros(dry);
            break;
        }
        end = (w + 1u) * 32u;
    }
    atomicStore(&front_bins[def.bins + def.words], end);
}

@compute @workgroup_size(WG)
fn probe_front_continuous(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    let at = fluid_at(linear_index(gid, nwg));
    let fluid = at.fluid;
    let x = at.x;
    for (var k = 0u; k < params.n_probes; k++) {
        let def = probes[k];
        if (def.kind != PROBE_FRONT_CONTINUOUS) {
            continue;
        }
        let reach_k = dot(x - def.point, def.axis);
        let end = atomicLoad(&front_bins[def.bins + def.words]);
        let counted = fluid && in_front_bins(def, reach_k) && front_bin(def, reach_k) < end;
        let reach = select(-3.0e38, reach_k, counted);
        let largest = workgroup_max(li, vec3<f32>(reach, 0.0, 0.0));
        if (li == 0u && largest.x > -1.0e38) {
            atomicMax(&probe_out[k], ordered_bits(largest.x));
        }
    }
}

// Tracked points (`kind = "point"` probes): the position of each followed particle. `tracked`
// holds their ids in ascending order; the one invocation whose live particle carries such an id
// (the arrays are re-sorted every step, the ids are stable) copies its position and marks it
// held (`tracked_held`, cleared before: a particle that left the domain, or over ranks one
// another rank holds, is not held). A binary search keeps the cost O(log P) per particle for P
// tracked points.
@group(0) @binding(7) var<storage, read> tracked: array<u32>;
@group(0) @binding(8) var<storage, read_write> tracked_pos: array<Pos>;
@group(0) @binding(9) var<storage, read_write> tracked_held: array<u32>;

@compute @workgroup_size(WG)
fn track_points(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = linear_index(gid, nwg);
    if (k >= params.n_particles || code_kind(code[k]) == KIND_EXCLUDED) {
        return;
    }
    let id = particle_id(k);
    var lo = 0u;
    var hi = arrayLength(&tracked);
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (tracked[mid] < id) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    if (lo < arrayLength(&tracked) && tracked[lo] == id) {
        tracked_pos[lo] = pos[k];
        tracked_held[lo] = 1u;
    }
}

// Discharge through a section (docs/equations.md eq. 33): Q = Σ_j V_j (u_j·n) w(d_j) over the
// fluid, d_j = (x_j − from)·n the distance to the section, w the kernel's 1D form (Wendland
// C2, ∫ w dd = 1, support 2h), for the particles whose place along the section,
// s_j = (x_j − from)·t, lies within it. `def.point` is `from`, `def.axis` the section's normal n
// (horizontal: t = (−n_y, n_x, 0)), `def.radius` its length.
fn section_weight(d: f32) -> f32 {
    let q = abs(d) / params.h;
    if (q >= 2.0) {
        return 0.0;
    }
    let a = 1.0 - 0.5 * q;
    return 5.0 / (8.0 * params.h) * a * a * a * (1.5 * q + 1.0);
}

fn discharge_contribution(def: ProbeDef, i: u32) -> f32 {
    if (code_kind(code[i]) != KIND_FLUID) {
        return 0.0;
    }
    let rel = domain_pos(pos[i]) - def.point;
    let along = dot(rel, vec3<f32>(-def.axis.y, def.axis.x, 0.0));
    if (along < 0.0 || along > def.radius) {
        return 0.0;
    }
    let vr = velrho[i];
    return params.mass / vr.w * dot(vr.xyz, def.axis) * section_weight(dot(rel, def.axis));
}

var<workgroup> wg_sum: array<f32, WG>;

// The sum of `v` over the workgroup, in a fixed tree order (the same particles in the same
// order give the same bits). Barriers: call it in uniform control flow.
fn workgroup_sum(li: u32, v: f32) -> f32 {
    wg_sum[li] = v;
    workgroupBarrier();
    for (var s = WG / 2u; s > 0u; s >>= 1u) {
        if (li < s) {
            wg_sum[li] += wg_sum[li + s];
        }
        workgroupBarrier();
    }
    let total = wg_sum[0];
    workgroupBarrier();
    return total;
}

// Each workgroup's share of every discharge probe, at its linear index among the workgroups.
@compute @workgroup_size(WG)
fn probe_discharge_sums(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    let i = linear_index(gid, nwg);
    let group = i / WG;
    for (var k = 0u; k < params.n_probes; k++) {
        let def = probes[k];
        if (def.kind != PROBE_DISCHARGE) {
            continue;
        }
        var q = 0.0;
        if (i < params.n_particles) {
            q = discharge_contribution(def, i);
        }
        let total = workgroup_sum(li, q);
        let slot = group * def.words + def.bins;
        if (li == 0u && slot < arrayLength(&discharge_sums)) {
            discharge_sums[slot] = total;
        }
    }
}

// One invocation a discharge probe: its workgroups' sums, in their order.
@compute @workgroup_size(WG)
fn probe_discharge_total(@builtin(global_invocation_id) gid: vec3<u32>) {
    let k = gid.x;
    if (k >= params.n_probes || probes[k].kind != PROBE_DISCHARGE) {
        return;
    }
    let def = probes[k];
    let groups = min((params.n_particles + WG - 1u) / WG, arrayLength(&discharge_sums) / def.words);
    var q = 0.0;
    for (var g = 0u; g < groups; g++) {
        q += discharge_sums[g * def.words + def.bins];
    }
    atomicStore(&probe_out[k], bitcast<u32>(q));
}

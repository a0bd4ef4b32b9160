// Flood maps (`[maps]`, docs/cases.md "Flood maps"; docs/equations.md eq. 34): over a plan
// grid of a 3D case, the water's depth and depth-averaged velocity at each sample time, and
// their extremes over the run, kept per cell on the GPU (no particle leaves it).
//
// The surface over a cell is the highest point of the lattice z_k = ground + k·h/4 on the
// vertical line through the cell's centre where the water fills half of what the walls leave
// of the kernel: ψ = φ_f / (1 − φ_s) ≥ ½, with φ_f = Σ_fluid W V and φ_s = Σ_walls W V. The
// wave gauges' criterion, φ_f ≥ ½ (probes.wgsl), finds no surface within 2h of a vertical
// wall, where the fluid fills at most half the kernel, nor over a sheet one or two particles
// deep; normalised by the walls' share it finds both (docs/design/flood_maps.md). The search is
// spread over the fluid particles as the gauges' is (`map_surface_search`): each tries, for the
// cells whose line passes within its support, the lattice points within it from the top down,
// and keeps the first where ψ ≥ ½ with atomicMax of k + 1, which is order-independent; then
// one invocation a cell interpolates the surface and updates the cell's record (`map_sample`).

struct MapGrid {
    origin: vec2<f32>,  // the south-west cell's centre, domain coordinates
    cell: f32,          // the cells' size [m]
    nx: u32,
    ny: u32,
    wet_depth: f32,     // the depth a cell must reach to count as reached (arrival)
    time: f32,          // this sample's time [s]
    pad: u32,
}

// A cell's record: this sample's depth and depth-averaged plan velocity, the run's maxima of
// depth, speed and depth × speed over its wet samples, the first time its depth reached
// `wet_depth` (−1 before), and how many samples found it wet. Mirrored by `layout::MapCell`.
struct MapCell {
    depth: f32,
    u: f32,
    v: f32,
    max_depth: f32,
    max_speed: f32,
    max_hazard: f32,
    arrival: f32,
    wet_samples: u32,
}

@group(0) @binding(1) var<storage, read> pos: array<Pos>;
@group(0) @binding(2) var<storage, read> velrho: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> code: array<u32>;
@group(0) @binding(4) var<storage, read> cell_start: array<u32>;
@group(0) @binding(5) var<storage, read> map_grid: MapGrid;
// The ground under each cell's centre, domain coordinates, row by row from the south.
@group(0) @binding(6) var<storage, read> map_ground: array<f32>;
// Per cell, the k + 1 of the highest lattice point found with ψ ≥ ½ (0: none).
@group(0) @binding(7) var<storage, read_write> map_found: array<atomic<u32>>;
@group(0) @binding(8) var<storage, read_write> map_cells: array<MapCell>;

const MAP_STEPS_PER_H: f32 = 4.0;

fn map_cell_centre(c: u32) -> vec2<f32> {
    let ix = c % map_grid.nx;
    let iy = c / map_grid.nx;
    return map_grid.origin + vec2<f32>(f32(ix), f32(iy)) * map_grid.cell;
}

fn map_step() -> f32 {
    return params.h / MAP_STEPS_PER_H;
}

// The lattice point k over cell c.
fn map_point(c: u32, k: u32) -> vec3<f32> {
    let centre = map_cell_centre(c);
    return vec3<f32>(centre, map_ground[c] + f32(k) * map_step());
}

// The highest lattice index over cell c at or below the domain's top.
fn map_top_index(c: u32) -> u32 {
    return u32(max(floor((params.domain_size.z - map_ground[c]) / map_step()), 0.0));
}

@compute @workgroup_size(WG)
fn map_surface_search(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles || code_kind(code[i]) != KIND_FLUID) {
        return;
    }
    let xi = domain_pos(pos[i]);
    let reach = 2.0 * params.h;
    let support2 = reach * reach;
    let step = map_step();
    // The cells whose centres can lie within the support in plan.
    let lo = max(vec2<i32>(ceil((xi.xy - reach - map_grid.origin) / map_grid.cell)), vec2<i32>(0));
    let hi = min(
        vec2<i32>(floor((xi.xy + reach - map_grid.origin) / map_grid.cell)),
        vec2<i32>(i32(map_grid.nx) - 1, i32(map_grid.ny) - 1),
    );
    for (var iy = lo.y; iy <= hi.y; iy++) {
        for (var ix = lo.x; ix <= hi.x; ix++) {
            let c = u32(iy) * map_grid.nx + u32(ix);
            let across = xi.xy - map_cell_centre(c);
            let d2 = dot(across, across);
            if (d2 >= support2) {
                continue;
            }
            // The lattice points within the particle's support, one more at each end against
            // f32 rounding (as the gauges' search).
            let r = sqrt(support2 - d2);
            let rel = xi.z - map_ground[c];
            let top = i32(floor((rel + r) / step)) + 1;
            let bottom = max(i32(ceil((rel - r) / step)) - 1, 0);
            for (var k = min(top, i32(map_top_index(c))); k >= bottom; k--) {
                // A point no higher than one already found cannot raise the surface.
                if (u32(k) + 1u <= atomicLoad(&map_found[c])) {
                    break;
                }
                if (water_fraction(map_sums(map_point(c, u32(k)))) >= 0.5) {
                    atomicMax(&map_found[c], u32(k) + 1u);
                    break;
                }
            }
        }
    }
}

// The depth over cell c of the surface found at lattice index found − 1 (0: none, a dry
// cell, depth −1): interpolated linearly in ψ towards the point above, at most the domain top.
fn map_depth(c: u32, found: u32) -> f32 {
    if (found == 0u) {
        return -1.0;
    }
    let psi = water_fraction(map_sums(map_point(c, found - 1u)));
    let psi_above = water_fraction(map_sums(map_point(c, found)));
    let t = clamp((psi - 0.5) / max(psi - psi_above, 1e-6), 0.0, 1.0);
    let z = min(map_ground[c] + (f32(found - 1u) + t) * map_step(), params.domain_size.z);
    return z - map_ground[c];
}

// The fluid's plan velocity at x, Shepard-interpolated (0 where no fluid is near).
fn map_velocity(x: vec3<f32>) -> vec2<f32> {
    let s = map_sums(x);
    if (s.fluid <= 1e-6) {
        return vec2<f32>(0.0);
    }
    return s.momentum / s.fluid;
}

// The record of a cell after a sample of depth `depth` (< 0: dry) and depth-averaged plan
// velocity `vel` at time `time`.
fn map_accumulate(cell: MapCell, depth: f32, vel: vec2<f32>, time: f32, wet_depth: f32) -> MapCell {
    var r = cell;
    if (depth < 0.0) {
        r.depth = 0.0;
        r.u = 0.0;
        r.v = 0.0;
        return r;
    }
    let speed = length(vel);
    r.depth = depth;
    r.u = vel.x;
    r.v = vel.y;
    r.max_depth = max(r.max_depth, depth);
    r.max_speed = max(r.max_speed, speed);
    r.max_hazard = max(r.max_hazard, depth * speed);
    if (r.arrival < 0.0 && depth >= wet_depth) {
        r.arrival = time;
    }
    r.wet_samples += 1u;
    return r;
}

// One invocation a cell: its depth from the surface found, the velocity at mid-depth (the
// depth average of a profile close to uniform), the record updated.
@compute @workgroup_size(WG)
fn map_sample(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let c = linear_index(gid, nwg);
    if (c >= map_grid.nx * map_grid.ny) {
        return;
    }
    let depth = map_depth(c, atomicLoad(&map_found[c]));
    var vel = vec2<f32>(0.0);
    if (depth >= 0.0) {
        let centre = map_cell_centre(c);
        vel = map_velocity(vec3<f32>(centre, map_ground[c] + 0.5 * depth));
    }
    map_cells[c] = map_accumulate(map_cells[c], depth, vel, map_grid.time, map_grid.wet_depth);
}

// Open boundaries, docs/equations.md eq. 32, after the predictor and before the cell-list sort:
// velocity inlets place their particles (`inlet_flow`), outlets remove the fluid that entered
// them (`outlet_drain`). An inlet particle's signed distance s(t) from its plane, a function
// of time alone, makes it dormant (excluded), a buffer particle (KIND_INLET, seen by the fluid
// as a dynamic boundary particle, eq. 22) or fluid. `inlet_pressure`, after the sort, sets an
// extrapolated buffer's density from the fluid's pressure at its mirror image (lib/fluid_at.wgsl,
// eqs. 13 and 21, inverse Tait eq. 17; after Tafuni et al. 2018).
// Case syntax: docs/cases.md "Inlets", "Outlets". Design notes: docs/design/open_boundaries.md.

struct InletDef {
    normal: vec3<f32>,          // unit, the direction of the inflow
    first_segment: u32,         // its inflow's first piece in `inflow_segments`
    thickness: f32,             // buffer depth behind the plane [m]
    spacing: f32,               // between layers [m]
    first_id: u32,              // its first particle's id
    n_columns: u32,
    first_column: u32,          // its first entry in `inlet_columns`
    n_segments: u32,            // its inflow's pieces (1 for a constant speed)
    pad0: u32,
    pad1: u32,
    surface: vec3<f32>,         // the buffer's highest point (domain coordinates)
    pressure: u32,              // INLET_ZERO, INLET_HYDROSTATIC or INLET_EXTRAPOLATED
    first_window: u32,          // a level-driven inlet's first entry in `flow_windows`
    n_windows: u32,             // 0: no level, every column flows
    first_level: u32,           // its level's first piece in `inflow_segments`
    n_level: u32,
}

// A time [start, end) a column of a level-driven inlet flows (src/scenario.rs `FlowWindow`):
// the level is above the column's point on the plane, and the water the inflow carries there
// has come D_c(t) = before + D(t); from `end` to its next window it has come `after`.
struct FlowWindow {
    column: u32,
    start: f32,
    end: f32,
    before: f32,
    after: f32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

// A piece of an inlet's inflow speed in time, from its knot t on (src/hydrograph.rs): with
// τ = t' − t, u(t') = speed · (1, τ, τ², τ³) and D(t') = distance + τ moved · (1, τ, τ², τ³),
// the distance travelled since t = 0 (D = ∫ u, so a particle's place is a function of time).
struct InflowSegment {
    t: f32,
    distance: f32,
    pad0: u32,
    pad1: u32,
    speed: vec4<f32>,
    moved: vec4<f32>,
}

// InletDef.pressure: ρ0; the density of ρ0 g·(x − surface) below the surface; the fluid's.
const INLET_ZERO: u32 = 0u;
const INLET_HYDROSTATIC: u32 = 1u;
const INLET_EXTRAPOLATED: u32 = 2u;

@group(0) @binding(1) var<storage, read_write> pos: array<Pos>;
@group(0) @binding(2) var<storage, read_write> velrho: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> code: array<u32>;
// An outlet's box, in domain coordinates (2D: z from −1 to 1).
struct OutletDef {
    min: vec3<f32>,
    pad0: u32,
    max: vec3<f32>,
    pad1: u32,
}

@group(0) @binding(4) var<storage, read_write> state: SimState;
@group(0) @binding(5) var<storage, read> inlets: array<InletDef>;
// Each column's point on its inlet's plane.
@group(0) @binding(6) var<storage, read> inlet_columns: array<Pos>;
@group(0) @binding(7) var<storage, read> outlets: array<OutletDef>;
@group(0) @binding(8) var<storage, read> cell_start: array<u32>;
@group(0) @binding(9) var<storage, read> inflow_segments: array<InflowSegment>;
// The level-driven inlets' windows, by inlet, then column, then time.
@group(0) @binding(10) var<storage, read> flow_windows: array<FlowWindow>;

// The inlet whose particle `id` is (ids are consecutive per inlet, inlets in id order).
fn inlet_of(id: u32) -> u32 {
    var n = 0u;
    while (n + 1u < params.n_inlets && id >= inlets[n + 1u].first_id) {
        n++;
    }
    return n;
}

// The inflow of `inlet` at time t ≥ 0: its speed u(t) and the distance D(t) it has carried the
// water (the last piece whose knot is at or before t; the first piece's knot is 0).
struct Inflow {
    speed: f32,
    distance: f32,
}

fn inflow_at(inlet: InletDef, t: f32) -> Inflow {
    return piecewise_at(inlet.first_segment, inlet.n_segments, t);
}

// The `n` pieces of `inflow_segments` from `first` at time t: their value and its integral
// from 0 (an inflow's speed and distance; a level's height in its `speed`).
fn piecewise_at(first: u32, n: u32, t: f32) -> Inflow {
    var lo = first;
    var hi = first + n;
    while (hi - lo > 1u) {
        let mid = (lo + hi) / 2u;
        if (inflow_segments[mid].t <= t) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let s = inflow_segments[lo];
    let tau = t - s.t;
    let u = s.speed[0] + tau * (s.speed[1] + tau * (s.speed[2] + tau * s.speed[3]));
    let d = s.distance + tau * (s.moved[0] + tau * (s.moved[1] + tau * (s.moved[2] + tau * s.moved[3])));
    return Inflow(u, d);
}

// Whether `column` of `inlet` flows at time t, and how far the inflow has carried its water
// (`inflow` its inflow at t): every column, the whole D(t), without a level; with one, from
// the column's last window that started by t (src/scenario.rs `FlowWindow::travel`).
struct Travel {
    flows: bool,
    distance: f32,
}

fn travel(inlet: InletDef, column: u32, t: f32, inflow: Inflow) -> Travel {
    if (inlet.n_windows == 0u) {
        return Travel(true, inflow.distance);
    }
    // The first window after (column, t), by bisection.
    var lo = inlet.first_window;
    var hi = inlet.first_window + inlet.n_windows;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        let w = flow_windows[mid];
        if (w.column < column || (w.column == column && w.start <= t)) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    if (lo == inlet.first_window || flow_windows[lo - 1u].column != column) {
        return Travel(false, 0.0);
    }
    let w = flow_windows[lo - 1u];
    if (t < w.end) {
        return Travel(true, w.before + inflow.distance);
    }
    return Travel(false, w.after);
}

// Signed distance of inlet particle k (of `inlet`) from the plane when its inflow has carried
// the water `travelled`.
fn inlet_distance(inlet: InletDef, k: u32, travelled: f32) -> f32 {
    let layer = f32(k / inlet.n_columns);
    return -(layer + 0.5) * inlet.spacing + travelled;
}

@compute @workgroup_size(WG)
fn inlet_flow(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles) {
        return;
    }
    let c = code[i];
    let id = particle_id(i);
    let kind = code_kind(c);
    if (id < params.inlet_id_base || id - params.inlet_id_base >= params.n_inlet_particles
        || (kind != KIND_INLET && kind != KIND_EXCLUDED)) {
        return;
    }
    let inlet = inlets[inlet_of(id)];
    let k = id - inlet.first_id;
    let t = state.t_base + state.t_rel + state.dt;
    let inflow = inflow_at(inlet, t);
    let column = k % inlet.n_columns;
    let travelled = travel(inlet, column, t, inflow);
    let s = inlet_distance(inlet, k, travelled.distance);
    let placed = move_by(inlet_columns[inlet.first_column + column], s * inlet.normal).pos;
    if (!travelled.flows) {
        // The level left the column: a buffer particle waits where it stands, out of every
        // cell, and counts as joined no more.
        if (kind == KIND_INLET) {
            pos[i] = placed;
            velrho[i] = vec4<f32>(0.0, 0.0, 0.0, velrho[i].w);
            code[i] = with_kind(c, KIND_EXCLUDED);
            atomicSub(&state.inlet_joined, 1u);
        }
        return;
    }
    if (kind == KIND_EXCLUDED) {
        if (s < -inlet.thickness || s >= 0.0) {
            return;
        }
        atomicAdd(&state.inlet_joined, 1u);
    }
    var rho = params.rho0;
    if (inlet.pressure == INLET_HYDROSTATIC) {
        // Below the buffer's top, or below the level where the inlet has one (its height
        // along −g; the case refuses a level without gravity).
        var surface = inlet.surface;
        if (inlet.n_level > 0u) {
            let up = -normalize(params.gravity);
            surface = piecewise_at(inlet.first_level, inlet.n_level, t).speed * up;
        }
        let p = params.rho0 * max(dot(params.gravity, domain_pos(placed) - surface), 0.0);
        rho = params.rho0 * pow(1.0 + p / params.tait_b, 1.0 / params.gamma);
    } else if (inlet.pressure == INLET_EXTRAPOLATED && kind == KIND_INLET) {
        // The density extrapolated in the last step: a particle that crosses the plane enters
        // with the pressure of the water there (with ρ0 it would open a hole in the pressure
        // field under water); one that just joined starts at ρ0 until `inlet_pressure`.
        rho = velrho[i].w;
    }
    pos[i] = placed;
    velrho[i] = vec4<f32>(inflow.speed * inlet.normal, rho);
    code[i] = with_kind(c, select(KIND_INLET, KIND_FLUID, s >= 0.0));
}

// An extrapolated buffer's pressure (`pressure = "extrapolated"`), on the sorted arrays after
// the cell-list sort: the fluid's pressure interpolated (lib/fluid_at.wgsl) at the particle's
// mirror image across the plane, x_m = x_b − 2 s n (s < 0 its signed distance), carried back
// hydrostatically, P_b = P(x_m) + ρ0 g·(x_b − x_m) = P(x_m) + 2 s ρ0 g·n. The buffer's values
// come from ghost nodes mirrored into the fluid as in the open boundaries of Tafuni,
// Domínguez, Vacondio & Crespo (2018, Comput. Methods Appl. Mech. Engrg. 342), here for the
// pressure only (the velocity stays imposed) and with W^I as the ghosts use it. Not below
// zero: a buffer particle above the water beside it (the free surface) stays at ρ0 rather
// than pulling on the fluid. No fluid in reach of x_m (an empty domain at the start): zero pressure.
@compute @workgroup_size(WG)
fn inlet_pressure(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles || code_kind(code[i]) != KIND_INLET) {
        return;
    }
    let id = particle_id(i);
    let inlet = inlets[inlet_of(id)];
    if (inlet.pressure != INLET_EXTRAPOLATED) {
        return;
    }
    let column = inlet_columns[inlet.first_column + (id - inlet.first_id) % inlet.n_columns];
    let s = dot(rel_pos(pos[i], column), inlet.normal);
    let mirror = move_by(pos[i], -2.0 * s * inlet.normal).pos;
    let p = fluid_at(mirror, params.gravity).w + 2.0 * s * params.rho0 * dot(params.gravity, inlet.normal);
    velrho[i].w = density_of(max(p, 0.0));
}

// Outlets (`[[outlet]]`, docs/cases.md "Outlets"): a fluid particle inside an outlet's box is
// excluded and counted as drained, apart from the particles that escape the domain.
@compute @workgroup_size(WG)
fn outlet_drain(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if (i >= params.n_particles || code_kind(code[i]) != KIND_FLUID) {
        return;
    }
    let x = domain_pos(pos[i]);
    for (var k = 0u; k < params.n_outlets; k++) {
        let o = outlets[k];
        if (all(x >= o.min) && all(x <= o.max)) {
            code[i] = with_kind(code[i], KIND_EXCLUDED);
            atomicAdd(&state.drained, 1u);
            return;
        }
    }
}

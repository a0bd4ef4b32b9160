// Shared declarations for every wgsph pass. Composed after the generated constants
// (DIM, KERNEL, VISCOSITY, WG, the method names) and before the pass's own file; see
// src/sph/shader.rs.

// Run parameters, uploaded once per run. Mirrored by `layout::Params` (size checked by a test
// against naga's reflection of this struct).
struct Params {
    // Neighbour grid. Positions are stored as (block, offset in block) so that f32 offsets stay
    // small anywhere in a large domain; a block is `cells_per_block` cells of `cell_size`.
    grid_cells: vec3<u32>,      // cells of the domain along x, y, z
    hash_mask: u32,             // slots - 1; the slot table has `slots` (power of two) entries
    block_size: vec3<f32>,      // [m] per axis
    cells_per_block: u32,
    inv_cell_size: vec3<f32>,   // cells are 2h, or the period split in whole cells
    periodic: u32,              // bit a: axis a is periodic
    domain_size: vec3<f32>,     // [m], domain extent from its min corner
    n_particles: u32,
    // Kernel
    h: f32,
    kernel_norm: f32,           // α_d of the kernel in DIM dimensions
    eta2: f32,                  // 0.01 h², regularises 1/r² terms
    mass: f32,                  // particle mass [kg]
    // Fluid
    rho0: f32,
    tait_b: f32,                // B = c0² ρ0 / γ
    gamma: f32,
    c0: f32,
    gravity: vec3<f32>,
    alpha: f32,                 // Monaghan artificial viscosity
    nu: f32,                    // laminar kinematic viscosity [m²/s]
    delta_coef: f32,            // δ h c0 for δ-SPH (Molteni & Colagrossi 2009)
    cfl: f32,
    n_probes: u32,
    // Walls
    n_mirror_planes: u32,
    ghost_mls: u32,             // GHOST_MLS or GHOST_SHEPARD: how ghosts interpolate
    repulsive_d: f32,           // Lennard-Jones D [m²/s²] (Monaghan 1994)
    repulsive_r0: f32,          // Lennard-Jones cut-off r0 [m]
    repulsive_form: u32,        // REPULSIVE_LENNARD_JONES (Monaghan 1994) or _MONAGHAN_KAJTAR (2009)
    repulsive_k_over_beta: f32, // Monaghan & Kajtar K/β [m²/s²]
    // Bodies: their particles have the ids body_id_base .. body_id_base + n_body_particles
    body_id_base: u32,          // n_particles when there are no bodies
    n_body_particles: u32,
    // Elastic solids (Gray, Monaghan & Swift 2001); zeros when the case has no solids
    solid_p_speed: f32,         // the fastest P-wave speed of their materials [m/s] (time step)
    solid_inv_w_dx: f32,        // 1/W(Δp), Δp the initial spacing
    solid_id_base: u32,         // the first solid particle's id (solid ids are consecutive)
    // Inlets (open_boundaries.wgsl): their particles have the ids inlet_id_base .. + n_inlet_particles
    inlet_id_base: u32,
    n_inlet_particles: u32,
    n_inlets: u32,
    n_outlets: u32,             // open_boundaries.wgsl
    // 1 when no axis is periodic and no two cells of a neighbourhood share a slot
    // (`Grid::contiguous_rows`): neighbour_ranges then takes a row of cells as one range.
    contiguous_rows: u32,
    friction: f32,              // Coulomb μ of contact (interaction.wgsl `contact`); 0: none
    friction_slip: f32,         // its regularisation speed ε [m/s]
    // With [[friction]] pairs: the number G of contact groups (0 without: every pair has
    // `friction`) and the first solid's (interaction.wgsl `friction_between`).
    friction_groups: u32,
    friction_first_solid: u32,
    // The weakly-compressible check (integrate.wgsl `correct`): fluid particles whose
    // |ρ/ρ0 − 1| is beyond each limit are counted (`time.density_variation_warn`, `_stop`).
    density_warn: f32,
    density_stop: f32,
    // The slot of cell (x, y, z) is x + hash_stride.x y + hash_stride.y z, masked (`Grid::stride`).
    hash_stride: vec2<u32>,
    // The distinct materials of the solids; a solid particle's is SolidState.material.
    solid_materials: array<SolidMaterial, MAX_SOLID_MATERIALS>,
    // μ between contact groups a and b at a·G + b, four to a vector.
    friction_table: array<vec4<f32>, FRICTION_TABLE_VECTORS>,
}

// Mirrored by `layout::MAX_FRICTION_GROUPS` (16 groups: 16 × 16 / 4 vectors).
const FRICTION_TABLE_VECTORS: u32 = 64u;

// Mirrored by `layout::MAX_SOLID_MATERIALS`.
const MAX_SOLID_MATERIALS: u32 = 8u;

// One elastic material. Mirrored by `layout::SolidMaterial`.
struct SolidMaterial {
    rho0: f32,                  // reference density ρs [kg/m³]
    c2: f32,                    // c_s² = K/ρs [m²/s²]
    mu: f32,                    // shear modulus μ [Pa]
    mass: f32,                  // particle mass [kg]
    alpha: f32,                 // Monaghan artificial viscosity α between solid particles
    eps: f32,                   // artificial stress ε (Monaghan 2000)
    lambda: f32,                // Lamé's λ = K − 2μ/3 [Pa] (total-Lagrangian solid)
    total_lagrangian: u32,      // 1: a total-Lagrangian solid's (total_lagrangian.wgsl), 0: elastic.wgsl's
}

// Time-stepping state that lives on the GPU; read back once per batch of steps.
// Mirrored by `layout::SimState`.
struct SimState {
    t_rel: f32,                 // time since the host's base time [s]
    t_target_rel: f32,          // the step sequence stops exactly here (dt clipped, then 0)
    dt: f32,                    // step about to be taken
    dt_cfl: f32,                // unclipped CFL step, for reporting
    max_speed_bits: atomic<u32>,  // max over particles of c_i + |v_i| (f32 bits; non-negative)
    max_accel_bits: atomic<u32>,  // max over fluid of |a_i| (f32 bits)
    nan_count: atomic<u32>,     // fluid and solid particles that became non-finite (cumulative)
    excluded: u32,              // particles in the excluded slot at the last sort
    steps: u32,                 // steps taken with dt > 0 since the host's base
    t_base: f32,                // the host's base time (f32): t = t_base + t_rel, for inlets
    inlet_joined: atomic<u32>,  // dormant inlet particles that joined a buffer, less those that left one (net, two's complement)
    drained: atomic<u32>,       // fluid particles removed by outlets (cumulative)
    // The weakly-compressible check: this step's largest |ρ/ρ0 − 1| over the fluid (f32 bits)
    // and its fluid particles beyond params.density_warn and params.density_stop; then the
    // largest of each over the steps since the host cleared them.
    density_variation_bits: atomic<u32>,
    beyond_warn: atomic<u32>,
    beyond_stop: atomic<u32>,
    density_variation_peak: f32,
    beyond_warn_peak: u32,
    beyond_stop_peak: u32,
}

// Particle position: `off` is the offset from the lower corner of block `block`
// (packed 11/11/10 bits for x/y/z).
struct Pos {
    off: vec3<f32>,
    block: u32,
}

// `code` word: kind in the top 4 bits, stable particle id in the low 28.
const KIND_SHIFT: u32 = 28u;
const ID_MASK: u32 = 0x0FFFFFFFu;
const KIND_FLUID: u32 = 0u;
const KIND_WALL: u32 = 1u;            // dynamic boundary particle
const KIND_GHOST_NO_SLIP: u32 = 2u;   // fixed ghost, no-slip
const KIND_GHOST_FREE_SLIP: u32 = 3u; // fixed ghost, free-slip
const KIND_REPULSIVE: u32 = 4u;       // repulsive-force boundary particle
const KIND_SOLID: u32 = 5u;           // hypoelastic solid particle
const KIND_SOLID_CLAMPED: u32 = 6u;   // solid particle held fixed (in the stress sums)
const KIND_INLET: u32 = 7u;           // inlet buffer particle (open_boundaries.wgsl)
const KIND_EXCLUDED: u32 = 15u;

// A particle of a moving body (rigid or prescribed): where it is in its body's frame.
// Indexed by id − params.body_id_base. Mirrored by `layout::BodyParticle`.
struct BodyParticle {
    r: vec3<f32>,               // offset from the centre of mass at t = 0 [m]
    body: u32,
}

// A body's rigid motion for the step being taken. Mirrored by `layout::BodyMotion`.
struct BodyMotion {
    center_off: vec3<f32>,      // centre of mass, as a Pos: offset in its block
    center_block: u32,
    rotation: mat3x3<f32>,      // from the body's orientation at t = 0
    velocity: vec3<f32>,        // of the centre of mass
    first: u32,                 // its first body-particle index (id − body_id_base)
    omega: vec3<f32>,
    count: u32,                 // its number of particles
    accel: vec3<f32>,           // of the centre of mass
    first_group: u32,           // its first workgroup in body_force
    alpha: vec3<f32>,           // angular acceleration
    flags: u32,                 // BODY_KINEMATIC or 0
}

// BodyMotion.flags: the body moves as prescribed whatever its load (`kind = "fixed"`, `"sine"`,
// `"series"`, the moving tank); see interaction.wgsl's `contact_counts`.
const BODY_KINEMATIC: u32 = 1u;

// The rigid velocity and acceleration of the body particle `id` (id ≥ body_id_base) at its
// place x_c + R r this step: u = u_c + ω × R r, a = a_c + α × R r + ω × (ω × R r).
struct WallMotion {
    velocity: vec3<f32>,
    accel: vec3<f32>,
}

fn body_wall_motion(m: BodyMotion, r: vec3<f32>) -> WallMotion {
    let arm = m.rotation * r;
    let w_arm = cross(m.omega, arm);
    return WallMotion(m.velocity + w_arm, m.accel + cross(m.alpha, arm) + cross(m.omega, w_arm));
}

// The kind tests fold to false, and the branches they guard compile out, where the composed
// constants (SOLIDS, FIXED_GHOSTS, REPULSIVE, BODIES: `shader::Present`) say the case has none.
fn is_body_particle(id: u32) -> bool {
    return BODIES && id >= params.body_id_base;
}

fn is_solid(kind: u32) -> bool {
    return SOLIDS && (kind == KIND_SOLID || kind == KIND_SOLID_CLAMPED);
}

fn is_repulsive(kind: u32) -> bool {
    return REPULSIVE && kind == KIND_REPULSIVE;
}

// Per solid particle, indexed by solid_slot (id order, untouched by the sort, so only solid
// particles pay for it): deviatoric stress τ = (xx, yy, zz, xy | xz, yz) [Pa],
// its elastic body, dτ/dt of the last evaluation (for the corrector: xx, yy, zz, xy | xz, yz),
// the fluid pressure interpolated at it this step (ghost.wgsl), which is what the fluid
// sees of the solid, and its material (an index in params.solid_materials). Mirrored by
// `layout::SolidState`.
struct SolidState {
    tau_a: vec4<f32>,
    tau_b: vec3<f32>,
    body: u32,
    rate_a: vec4<f32>,
    rate_b: vec2<f32>,
    interface_p: f32,
    material: u32,
}

// dτ/dt as written by the elastic pass: (xx, yy, zz, xy | xz, yz, 0, 0). Mirrored by
// `layout::SymRate`.
struct SymRate {
    a: vec4<f32>,
    b: vec4<f32>,
}

fn is_ghost(kind: u32) -> bool {
    return FIXED_GHOSTS && (kind == KIND_GHOST_NO_SLIP || kind == KIND_GHOST_FREE_SLIP);
}

fn code_kind(code: u32) -> u32 {
    return code >> KIND_SHIFT;
}

// The material of a solid particle.
fn material_of(s: SolidState) -> SolidMaterial {
    return params.solid_materials[s.material];
}

// The id of a code word and its high bits (the word after the code words, or a halo record's
// `dest` above its flags) with WIDE_IDS; of the code word alone without.
fn whole_id(code: u32, high: u32) -> u32 {
    if (WIDE_IDS) {
        return (code & ID_MASK) | (high << ID_LOW_BITS);
    }
    return code & ID_MASK;
}

fn with_kind(code: u32, kind: u32) -> u32 {
    return (code & ID_MASK) | (kind << KIND_SHIFT);
}

@group(0) @binding(0) var<uniform> params: Params;

// Linear invocation index for dispatches that may be 2D (more than 65535 workgroups).
fn linear_index(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.x + gid.y * nwg.x * WG;
}

// The particle of invocation `gid` of a neighbour-sum pass: `linear_index`, or with
// SPREAD_CHUNKS > 1 (a CPU adapter: ShaderConfig::for_adapter) the dispatch's workgroups taken
// in SPREAD_CHUNKS chunks of consecutive ones, the chunks in bit-reversed order, so that each
// contiguous share of the dispatch (what llvmpipe gives a thread) holds chunks from all over
// the sorted order. A workgroup's particles, and a chunk's, stay neighbours. Only whole chunks
// of at least SPREAD_MIN_CHUNK workgroups are spread; the workgroups past them (fewer than
// SPREAD_CHUNKS) and a smaller or 2D dispatch keep the dispatch's order, and no workgroup is
// added: on lavapipe, idle workgroups added to make whole chunks doubled a small case's sums,
// and chunks of fewer workgroups gained nothing measurable (docs/performance.md).
fn spread_index(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    let per_chunk = nwg.x / SPREAD_CHUNKS;
    let w = gid.x / WG;
    if (SPREAD_CHUNKS == 1u || nwg.y != 1u || per_chunk < SPREAD_MIN_CHUNK || w >= per_chunk * SPREAD_CHUNKS) {
        return linear_index(gid, nwg);
    }
    return (reversed_chunk(w / per_chunk) * per_chunk + w % per_chunk) * WG + gid.x % WG;
}

// The fewest workgroups a spread chunk holds: 4 × SPREAD_CHUNKS × WG invocations, from 32 768
// particles on at WG = 128.
const SPREAD_MIN_CHUNK: u32 = 4u;

// The lowest log2(SPREAD_CHUNKS) bits of `c` reversed, bit by bit (naga's MSL output at its
// default version has no reverseBits).
fn reversed_chunk(c: u32) -> u32 {
    var r = 0u;
    var rest = c;
    for (var k = 1u; k < SPREAD_CHUNKS; k *= 2u) {
        r = 2u * r + (rest & 1u);
        rest >>= 1u;
    }
    return r;
}

// ---- positions -------------------------------------------------------------------------

fn unpack_block(b: u32) -> vec3<i32> {
    return vec3<i32>(i32(b & 0x7FFu), i32((b >> 11u) & 0x7FFu), i32(b >> 22u));
}

fn pack_block(b: vec3<i32>) -> u32 {
    return u32(b.x) | (u32(b.y) << 11u) | (u32(b.z) << 22u);
}

// The periodic axes: the uniform's bits, or none at compile time in a case without
// (PERIODIC), so that no pass carries the wrap-around code it would never take.
fn periodic_axes() -> vec3<bool> {
    let bits = select(0u, params.periodic, PERIODIC);
    return vec3<bool>((bits & 1u) != 0u, (bits & 2u) != 0u, (bits & 4u) != 0u);
}

fn any_periodic() -> bool {
    return PERIODIC && params.periodic != 0u;
}

// x_i - x_j, exact block difference plus offset difference: precise for neighbours anywhere;
// the nearest image on periodic axes.
fn rel_pos(pi: Pos, pj: Pos) -> vec3<f32> {
    let db = vec3<f32>(unpack_block(pi.block) - unpack_block(pj.block));
    let x = db * params.block_size + (pi.off - pj.off);
    if (!any_periodic()) {
        return x;
    }
    return select(x, x - params.domain_size * round(x / params.domain_size), periodic_axes());
}

// Position from the domain's min corner, in f32 (for bounds checks and probes only).
fn domain_pos(p: Pos) -> vec3<f32> {
    return vec3<f32>(unpack_block(p.block)) * params.block_size + p.off;
}

// A point given in domain coordinates, as a Pos (for probes and mirror images).
fn pos_of_point(x: vec3<f32>) -> Pos {
    let b = clamp(vec3<i32>(floor(x / params.block_size)), vec3<i32>(0), vec3<i32>(2047, 2047, 1023));
    return Pos(x - vec3<f32>(b) * params.block_size, pack_block(b));
}

struct Moved {
    pos: Pos,
    inside: bool,
}

// Displaces a particle by `d` and moves its offset back into [0, block_size) by changing
// block (exact, by Sterbenz, for a shift of one block). `inside` says whether the new position
// lies in the domain; outside it the block is clamped and the particle must be excluded.
fn move_by(p: Pos, d: vec3<f32>) -> Moved {
    let off = p.off + d;
    let shift = floor(off / params.block_size);
    var b = unpack_block(p.block) + vec3<i32>(shift);
    var new_off = off - shift * params.block_size;
    var x = vec3<f32>(b) * params.block_size + new_off;
    let wrap = periodic_axes() & ((x < vec3<f32>(0.0)) | (x >= params.domain_size));
    if (any(wrap)) {
        // Re-entry through the opposite face: re-block from the wrapped domain position (the
        // f32 rounding of the domain coordinate is paid once per crossing).
        x = select(x, x - params.domain_size * floor(x / params.domain_size), wrap);
        let bw = floor(x / params.block_size);
        b = select(b, vec3<i32>(bw), wrap);
        new_off = select(new_off, x - bw * params.block_size, wrap);
    }
    let inside = all(x >= vec3<f32>(0.0)) && all(x <= params.domain_size)
        && all(b >= vec3<i32>(0)) && all(b <= vec3<i32>(2047, 2047, 1023));
    let bc = clamp(b, vec3<i32>(0), vec3<i32>(2047, 2047, 1023));
    return Moved(Pos(new_off, pack_block(bc)), inside);
}

// ---- neighbour grid ----------------------------------------------------------------------

fn cell_of(p: Pos) -> vec3<i32> {
    let k = i32(params.cells_per_block);
    let local = clamp(vec3<i32>(floor(p.off * params.inv_cell_size)), vec3<i32>(0), vec3<i32>(k - 1));
    let c = unpack_block(p.block) * k + local;
    let g = vec3<i32>(params.grid_cells);
    // A particle on the domain's far face belongs to the last cell, so every particle's cell is
    // in the grid (neighbour_ranges' rows); one wrapped to exactly the period's end, to cell 0.
    return select(min(c, g - 1), c % g, periodic_axes());
}

// Hash slot of a cell: x + A y + B z wrapped to the (power of two) slot table, (A, B) the
// linear index's strides or strides under which the cells around any cell have distinct slots
// (`Grid::stride`). Dense domains get no collisions; sparse ones share slots between distant
// cells, which the distance test filters. Wrapping u32 arithmetic is intended.
fn slot_of_cell(c: vec3<i32>) -> u32 {
    let u = vec3<u32>(c);
    return (u.x + params.hash_stride.x * u.y + params.hash_stride.y * u.z) & params.hash_mask;
}

// ---- mirror planes ---------------------------------------------------------------------

// A straight wall with mirrored ghosts; `point` in domain coordinates, `normal` into the fluid.
struct MirrorPlane {
    point: vec3<f32>,
    no_slip: u32,
    normal: vec3<f32>,
    pad: u32,
}

// A wall-pressure probe's patch on a fixed wall, in domain coordinates.
struct WallSensor {
    point: vec3<f32>,   // on the wall's face
    radius: f32,        // across the normal
    normal: vec3<f32>,  // unit, into the fluid
    face: f32,          // (x − point)·normal of the wall's face
    over_lo: vec3<f32>, // the face's extent where an edge is near (WallPatch::over_lo)
    face_id: u32,       // the first sensor on the same face (WallParams::sensor_faces)
    over_hi: vec3<f32>,
}

// The case's small read-only tables in one binding (so that no pass binds more than WebGPU's 8
// storage buffers): the bodies' motions of the step (the host writes them at offset 0 every
// step), the mirror planes, the fixed walls' wall-pressure sensors, and the body particles
// (indexed by id − params.body_id_base). The counts are the case's (at least one each, unused
// stand-ins where it has none), composed in front as N_BODIES, N_MIRROR_PLANES,
// N_WALL_SENSORS. Mirrored by `sph::buffers::CaseTables`.
struct CaseTables {
    bodies: array<BodyMotion, N_BODIES>,
    mirror_planes: array<MirrorPlane, N_MIRROR_PLANES>,
    wall_sensors: array<WallSensor, N_WALL_SENSORS>,
    body_particles: array<BodyParticle>,
}

@group(0) @binding(30) var<storage, read> tables: CaseTables;

fn reflect_vec(v: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return v - 2.0 * dot(v, n) * n;
}

fn reflect_point(x: vec3<f32>, plane: MirrorPlane) -> vec3<f32> {
    return x - 2.0 * dot(x - plane.point, plane.normal) * plane.normal;
}

// ---- smoothing kernels (support 2h, q = r/h) ---------------------------------------------

// W(r) for q in [0, 2].
fn kernel_w(q: f32) -> f32 {
    if (KERNEL == KERNEL_CUBIC_SPLINE) {
        // Cubic spline, Monaghan & Lattanzio (1985).
        if (q < 1.0) {
            return params.kernel_norm * (1.0 - 1.5 * q * q + 0.75 * q * q * q);
        }
        let t = max(2.0 - q, 0.0);
        return params.kernel_norm * 0.25 * t * t * t;
    }
    // Wendland C2 (Wendland 1995): (1 - q/2)^4 (2q + 1).
    let t = max(1.0 - 0.5 * q, 0.0);
    return params.kernel_norm * t * t * t * t * (2.0 * q + 1.0);
}

// F(r) = W'(r) / r, so that ∇_i W_ij = x_ij F(r_ij). Finite at r = 0 for Wendland.
fn kernel_f(q: f32) -> f32 {
    let h2 = params.h * params.h;
    if (KERNEL == KERNEL_CUBIC_SPLINE) {
        if (q < 1.0) {
            return params.kernel_norm / h2 * (-3.0 + 2.25 * q);
        }
        let t = max(2.0 - q, 0.0);
        return -0.75 * params.kernel_norm * t * t / (h2 * max(q, 1e-6));
    }
    let t = max(1.0 - 0.5 * q, 0.0);
    return -5.0 * params.kernel_norm / h2 * t * t * t;
}

// ---- equation of state -------------------------------------------------------------------

// x^γ: by multiplications where γ is a whole number (TAIT_GAMMA, 7 for water), otherwise
// pow. Every pair pays for its neighbour's pressure, and on a CPU adapter pow's exp2(γ log2 x)
// costs several times the 4 multiplications of x^7.
fn tait_power(x: f32) -> f32 {
    if (TAIT_GAMMA == 0u) {
        return pow(x, params.gamma);
    }
    var r = 1.0;
    var b = x;
    for (var e = TAIT_GAMMA; e != 0u; e >>= 1u) {
        if ((e & 1u) != 0u) {
            r *= b;
        }
        b *= b;
    }
    return r;
}

// Tait: P = B((ρ/ρ0)^γ − 1) (Monaghan 1994, Batchelor 1967).
fn pressure_of(rho: f32) -> f32 {
    return params.tait_b * (tait_power(rho / params.rho0) - 1.0);
}

// Local sound speed c = c0 (ρ/ρ0)^((γ−1)/2).
fn sound_speed_of(rho: f32) -> f32 {
    return params.c0 * pow(rho / params.rho0, 0.5 * (params.gamma - 1.0));
}

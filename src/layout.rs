//! Host mirrors of the WGSL structs, `#[repr(C)]` + Pod. Their sizes and field offsets are
//! checked against naga's layout of the composed shaders in the tests below.

use bytemuck::{Pod, Zeroable};

/// Mirrors `Params` in shaders/lib/common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct Params {
    pub grid_cells: [u32; 3],
    pub hash_mask: u32,
    pub block_size: [f32; 3],
    pub cells_per_block: u32,
    pub inv_cell_size: [f32; 3],
    /// Bit a set: axis a is periodic.
    pub periodic: u32,
    pub domain_size: [f32; 3],
    pub n_particles: u32,
    pub h: f32,
    pub kernel_norm: f32,
    pub eta2: f32,
    pub mass: f32,
    pub rho0: f32,
    pub tait_b: f32,
    pub gamma: f32,
    pub c0: f32,
    pub gravity: [f32; 3],
    pub alpha: f32,
    pub nu: f32,
    pub delta_coef: f32,
    pub cfl: f32,
    pub n_probes: u32,
    pub n_mirror_planes: u32,
    pub ghost_mls: u32,
    pub repulsive_d: f32,
    pub repulsive_r0: f32,
    pub repulsive_form: u32,
    pub repulsive_k_over_beta: f32,
    /// Id of the first body particle (bodies' particles come last); n_particles without bodies.
    pub body_id_base: u32,
    pub n_body_particles: u32,
    /// Elastic solids (zeros without solids): the fastest P-wave speed of their materials (for
    /// the time step), 1/W(Δp), the first solid particle's id.
    pub solid_p_speed: f32,
    pub solid_inv_w_dx: f32,
    pub solid_id_base: u32,
    /// Inlets: the ids of their particles, inlet after inlet, and how many inlets.
    pub inlet_id_base: u32,
    pub n_inlet_particles: u32,
    pub n_inlets: u32,
    pub n_outlets: u32,
    /// 1 when every cell has a slot of its own and no axis is periodic (`Grid::dense`).
    pub contiguous_rows: u32,
    /// Coulomb μ of contact and its regularisation speed ε [m/s] (`WallParams::friction`).
    pub friction: f32,
    pub friction_slip: f32,
    /// With `[[friction]]` pairs: the number G of contact groups (the walls, then the bodies,
    /// then the solids; 0 without pairs: every pair has `friction`), and the first solid's.
    pub friction_groups: u32,
    pub friction_first_solid: u32,
    /// `time.density_variation_warn` and `_stop`: the density variations |ρ/ρ0 − 1| beyond
    /// which `correct` counts a fluid particle.
    pub density_warn: f32,
    pub density_stop: f32,
    /// The slot hash's strides (`Grid::stride`); also brings `solid_materials` to its
    /// 16-byte alignment in WGSL.
    pub hash_stride: [u32; 2],
    /// The distinct materials of the elastic solids; a solid particle's is
    /// `SolidState::material`.
    pub solid_materials: [SolidMaterial; MAX_SOLID_MATERIALS],
    /// μ between contact groups a and b at a·G + b (4 to a vector), when friction_groups > 0.
    pub friction_table: [[f32; 4]; MAX_FRICTION_GROUPS * MAX_FRICTION_GROUPS / 4],
}

/// How many contact groups (walls, bodies, solids) a case with `[[friction]]` pairs may hold
/// (`MAX_FRICTION_GROUPS` in shaders/lib/common.wgsl).
pub const MAX_FRICTION_GROUPS: usize = 16;

/// How many different solid materials a case may hold (the length of
/// `Params::solid_materials`; `MAX_SOLID_MATERIALS` in shaders/lib/common.wgsl).
pub const MAX_SOLID_MATERIALS: usize = 8;

/// Mirrors `SolidMaterial` in shaders/lib/common.wgsl: one elastic material as the kernels use
/// it (Gray, Monaghan & Swift 2001; Lamé's λ for the total-Lagrangian solid).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct SolidMaterial {
    /// Reference density ρs [kg/m³].
    pub rho0: f32,
    /// c_s² = K/ρs [m²/s²].
    pub c2: f32,
    /// Shear modulus μ [Pa].
    pub mu: f32,
    /// Particle mass ρs Δp^d [kg].
    pub mass: f32,
    /// Monaghan artificial viscosity α between solid particles.
    pub alpha: f32,
    /// Artificial stress ε (Monaghan 2000).
    pub eps: f32,
    /// Lamé's λ = K − 2μ/3 [Pa].
    pub lambda: f32,
    /// 1 for a total-Lagrangian solid's material, 0 for an updated-Lagrangian one's: which
    /// pass computes the solid's own forces.
    pub total_lagrangian: u32,
}

/// Mirrors `SolidState` in shaders/lib/common.wgsl: the deviatoric stress τ of a solid particle
/// (xx, yy, zz, xy | xz, yz) [Pa], its elastic body, dτ/dt of the last evaluation, the
/// fluid pressure interpolated at it (what the fluid sees of the solid) [Pa] and its material
/// (an index in `Params::solid_materials`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct SolidState {
    pub tau_a: [f32; 4],
    pub tau_b: [f32; 3],
    pub body: u32,
    pub rate_a: [f32; 4],
    pub rate_b: [f32; 2],
    pub interface_p: f32,
    pub material: u32,
}

/// Mirrors `SymRate`: dτ/dt (xx, yy, zz, xy | xz, yz, 0, 0) [Pa/s].
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct SymRate {
    pub a: [f32; 4],
    pub b: [f32; 4],
}

/// Mirrors `SimState` in shaders/lib/common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct SimState {
    pub t_rel: f32,
    pub t_target_rel: f32,
    pub dt: f32,
    pub dt_cfl: f32,
    pub max_speed_bits: u32,
    pub max_accel_bits: u32,
    pub nan_count: u32,
    pub excluded: u32,
    pub steps: u32,
    /// The host's base time as f32 (inlets place their particles at t_base + t_rel).
    pub t_base: f32,
    /// Dormant inlet particles that have joined a buffer since t = 0, less the buffer particles
    /// a level inlet made wait again: a net count, negative in two's complement where more
    /// left than joined ([`SimState::net_joined`]).
    pub inlet_joined: u32,
    /// Fluid particles removed by outlets since t = 0.
    pub drained: u32,
    /// The largest |ρ/ρ0 − 1| over the fluid in the step being taken (f32 bits), and its
    /// fluid particles beyond `Params::density_warn` and `density_stop` (cleared when the step
    /// closes).
    pub density_variation_bits: u32,
    pub beyond_warn: u32,
    pub beyond_stop: u32,
    /// The largest of each over the steps since the host last cleared them.
    pub density_variation_peak: f32,
    pub beyond_warn_peak: u32,
    pub beyond_stop_peak: u32,
}

impl SimState {
    /// `inlet_joined` as the signed count it is.
    pub fn net_joined(&self) -> i64 {
        self.inlet_joined as i32 as i64
    }
}

/// Mirrors `Pos`: offset from the block's lower corner + packed block coordinates.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct Pos {
    pub off: [f32; 3],
    pub block: u32,
}

/// Mirrors `ProbeDef` in shaders/probes.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct ProbeDef {
    pub point: [f32; 3],
    pub kind: u32,
    pub axis: [f32; 3],
    pub radius: f32,
    /// A wall-pressure probe's face on a fixed wall (`WallSensor::face_id`), else `NO_FACE`.
    pub face: u32,
    /// A continuous front's first word in `front_bins` (its `words` of bits, then the end).
    pub bins: u32,
    pub words: u32,
    /// A continuous front's bin width along its axis.
    pub bin_width: f32,
}

/// Mirrors `MapGrid` in shaders/flood_maps.wgsl: a flood map's plan grid in domain
/// coordinates, and the sample's time.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MapGrid {
    pub origin: [f32; 2],
    pub cell: f32,
    pub nx: u32,
    pub ny: u32,
    pub wet_depth: f32,
    pub time: f32,
    pub pad: u32,
}

/// Mirrors `MapCell` in shaders/flood_maps.wgsl: a map cell's record (`arrival` −1 before the
/// cell is reached).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MapCell {
    pub depth: f32,
    pub u: f32,
    pub v: f32,
    pub max_depth: f32,
    pub max_speed: f32,
    pub max_hazard: f32,
    pub arrival: f32,
    pub wet_samples: u32,
}

impl MapCell {
    /// A cell no sample has seen.
    pub const UNSEEN: MapCell = MapCell {
        depth: 0.0,
        u: 0.0,
        v: 0.0,
        max_depth: 0.0,
        max_speed: 0.0,
        max_hazard: 0.0,
        arrival: -1.0,
        wet_samples: 0,
    };
}

/// `ProbeDef::face` of a probe that is not a fixed wall's sensor.
pub const NO_FACE: u32 = u32::MAX;

/// Mirrors `WallSensor` in shaders/lib/wall_patch.wgsl: a wall-pressure probe's patch on a
/// fixed wall (`scenario::WallPatch`), in domain coordinates.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct WallSensor {
    pub point: [f32; 3],
    pub radius: f32,
    pub normal: [f32; 3],
    pub face: f32,
    pub over_lo: [f32; 3],
    pub face_id: u32,
    pub over_hi: [f32; 3],
    pub pad: u32,
}

/// Mirrors `MirrorPlane` in shaders/interaction.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct MirrorPlane {
    /// A point of the plane, in domain coordinates.
    pub point: [f32; 3],
    pub no_slip: u32,
    /// Unit normal into the fluid.
    pub normal: [f32; 3],
    pub pad: u32,
}

/// Mirrors `BodyParticle` in shaders/lib/common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct BodyParticle {
    /// Offset from the body's centre of mass at t = 0 [m].
    pub r: [f32; 3],
    pub body: u32,
}

/// Mirrors `BodyMotion` in shaders/lib/common.wgsl: a body's rigid motion for one step.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct BodyMotion {
    /// Centre of mass: offset in its block and packed block (as `Pos`).
    pub center_off: [f32; 3],
    pub center_block: u32,
    /// Columns of the rotation from the body's orientation at t = 0 (WGSL mat3x3, padded).
    pub rotation: [[f32; 4]; 3],
    pub velocity: [f32; 3],
    /// First body-particle index (id − body_id_base) of the body.
    pub first: u32,
    pub omega: [f32; 3],
    pub count: u32,
    /// Acceleration of the centre of mass.
    pub accel: [f32; 3],
    /// First workgroup of the body in `body_force`.
    pub first_group: u32,
    /// Angular acceleration.
    pub alpha: [f32; 3],
    /// [`BODY_KINEMATIC`] or 0.
    pub flags: u32,
}

/// `BodyMotion::flags`: the body moves as the case prescribes (`[body.motion] kind = "fixed"`,
/// `"sine"` or `"series"`, or the moving tank), whatever its load. Its contact with the fixed
/// walls and with other such bodies, which it may rest against or slide along by design (a
/// building on a street, a paddle on the floor), answers nothing and is left out of its load.
pub const BODY_KINEMATIC: u32 = 1;

pub const KIND_SHIFT: u32 = 28;
pub const ID_MASK: u32 = 0x0FFF_FFFF;
pub const KIND_EXCLUDED: u32 = 15;

/// How a run stores its particle ids (issue 32: runs of 2²⁸ particles or more). Narrow: an id
/// is its code word's low 28 bits. Wide: the code word keeps the id's low `low_bits` bits, and
/// the rest (`id >> low_bits`) is a second word per particle after the n code words of the same
/// buffer (which the sort gathers with them), and a halo record's `id_high`. An id is a u32
/// either way; the free entries' is the largest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IdSplit {
    pub wide: bool,
    pub low_bits: u32,
}

impl IdSplit {
    pub const NARROW: Self = Self {
        wide: false,
        low_bits: KIND_SHIFT,
    };

    /// The ids of a run of `particles` (all it may ever hold, inlets' included): wide with
    /// `forced` low bits (`particles.id_low_bits`), else wide only where narrow ids run out.
    pub fn for_run(particles: u64, forced: Option<u32>) -> Self {
        match forced {
            Some(low_bits) => Self {
                wide: true,
                low_bits,
            },
            None if particles >= Self::NARROW.free_id() as u64 => Self {
                wide: true,
                low_bits: KIND_SHIFT,
            },
            None => Self::NARROW,
        }
    }

    /// The id of a free entry (`sph::subdomain`), above every particle's.
    pub fn free_id(self) -> u32 {
        match self.wide {
            true => u32::MAX,
            false => ID_MASK,
        }
    }

    /// The words a particle takes in the code buffer.
    pub fn words(self) -> usize {
        1 + self.wide as usize
    }

    /// The code word of a particle of `kind` and `id`.
    pub fn code_word(self, kind: u32, id: u32) -> u32 {
        (kind << KIND_SHIFT) | (id & (ID_MASK >> (KIND_SHIFT - self.low_bits)))
    }

    /// The id bits that do not go in the code word (0 with narrow ids).
    pub fn high(self, id: u32) -> u32 {
        match self.wide {
            true => id >> self.low_bits,
            false => 0,
        }
    }

    /// The id of a code word and its [`IdSplit::high`] bits.
    pub fn id(self, code_word: u32, high: u32) -> u32 {
        match self.wide {
            true => (code_word & ID_MASK) | high << self.low_bits,
            false => code_word & ID_MASK,
        }
    }

    /// The id of particle `i` of the `n` a code buffer's words `code` hold.
    pub fn id_at(self, code: &[u32], n: usize, i: usize) -> u32 {
        self.id(code[i], if self.wide { code[n + i] } else { 0 })
    }
}
/// Largest block coordinate per axis (11/11/10 bits).
pub const MAX_BLOCK: [u32; 3] = [2047, 2047, 1023];

pub fn pack_block(b: [u32; 3]) -> u32 {
    b[0] | (b[1] << 11) | (b[2] << 22)
}

pub fn unpack_block(b: u32) -> [u32; 3] {
    [b & 0x7FF, (b >> 11) & 0x7FF, b >> 22]
}

/// Mirrors `InletDef` in shaders/open_boundaries.wgsl: an inlet's plane normal, where its
/// inflow's segments start, buffer depth, layer spacing, where its particles and columns start,
/// how many segments it has, and its buffer's top.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct InletDef {
    pub normal: [f32; 3],
    pub first_segment: u32,
    pub thickness: f32,
    pub spacing: f32,
    pub first_id: u32,
    pub n_columns: u32,
    pub first_column: u32,
    pub n_segments: u32,
    pub pad: [u32; 2],
    /// The buffer's highest point in domain coordinates, read when `pressure` is
    /// `INLET_HYDROSTATIC`.
    pub surface: [f32; 3],
    /// `INLET_ZERO`, `INLET_HYDROSTATIC` or `INLET_EXTRAPOLATED` (the scenario's `InletPressure`).
    pub pressure: u32,
    /// A level-driven inlet's windows in the `FlowWindow` table (none: every column flows).
    pub first_window: u32,
    pub n_windows: u32,
    /// Its level's pieces in the `InflowSegment` table, heights in domain coordinates.
    pub first_level: u32,
    pub n_level: u32,
}

/// Mirrors `FlowWindow` in shaders/open_boundaries.wgsl (`crate::scenario::FlowWindow`): a time
/// a column of a level-driven inlet flows and how far its water has come.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct FlowWindow {
    pub column: u32,
    pub start: f32,
    pub end: f32,
    pub before: f32,
    pub after: f32,
    pub pad: [u32; 3],
}

/// What a probe samples: `ProbeDef::kind` holds its code, the WGSL constant `PROBE_*` of the
/// same number (`crate::sph::shader::WgslEnum`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProbeCode {
    Pressure,
    Height,
    Front,
    WallPressure,
    FrontContinuous,
    Discharge,
    Depth,
}

/// Mirrors `InflowSegment` in shaders/open_boundaries.wgsl: a piece of an inlet's hydrograph
/// (`crate::hydrograph::Segment`), from its knot `t`: the distance travelled there, and the
/// coefficients in τ = t − knot of the speed and of the distance travelled since.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct InflowSegment {
    pub t: f32,
    pub distance: f32,
    pub pad: [u32; 2],
    pub speed: [f32; 4],
    pub moved: [f32; 4],
}

/// `InletDef::pressure` values, as the constants of the same names in
/// shaders/open_boundaries.wgsl.
pub const INLET_ZERO: u32 = 0;
pub const INLET_HYDROSTATIC: u32 = 1;
pub const INLET_EXTRAPOLATED: u32 = 2;

/// Mirrors `OutletDef` in shaders/open_boundaries.wgsl: an outlet's box in domain coordinates
/// (from the grid's origin).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct OutletDef {
    pub min: [f32; 3],
    pub pad0: u32,
    pub max: [f32; 3],
    pub pad1: u32,
}

/// Mirrors `HaloCtl` in shaders/lib/slab.wgsl: a subdomain's own cell layers along the cut axis,
/// its halo thickness, which neighbours it has, and how many records `halo_out` holds.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct HaloCtl {
    pub axis: u32,
    pub own_lo: u32,
    pub own_hi: u32,
    pub layers: u32,
    pub lower: u32,
    pub upper: u32,
    pub capacity: u32,
    /// 1: halo copies packed as the density filter's exchange needs them (`halo::Copies`).
    pub lean: u32,
    /// 1: the cuts move: the packing takes the excluded particles that keep their ids too.
    pub moving: u32,
    pub pad: [u32; 3],
}

/// Mirrors `HaloCounts` in shaders/halo.wgsl: the rank's own particles, the free tail, and the
/// records of each stream of the two messages (3 × neighbour + section: migrants, solid stress
/// states, halo copies), counted and written, where each starts and whether they fit.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct HaloCounts {
    pub owned: u32,
    pub tail: u32,
    pub sizes: [u32; 6],
    pub filled: [u32; 6],
    pub starts: [u32; 6],
    pub fits: u32,
}

/// Mirrors `HaloArrivals` in shaders/halo.wgsl: the messages received, one after the other
/// (each one's first word, then its sections' counts), and their particles and stress states.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct HaloArrivals {
    pub messages: [[u32; 4]; 2],
    pub particles: u32,
    pub states: u32,
    /// Words of a halo copy in the messages: `COPY_WORDS`, or the density filter's lean ones.
    pub copy_words: u32,
    pub pad: u32,
}

/// Mirrors `HaloRecord` in shaders/halo.wgsl: one particle sent to a neighbour as a migrant, or
/// a solid particle's stress state (its message's section says which).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct HaloRecord {
    pub pos: Pos,
    pub velrho: [f32; 4],
    pub rate: [f32; 4],
    pub code: u32,
    /// With wide ids, the id's bits above the code word's ([`IdSplit::high`]); else 0.
    pub id_high: u32,
    /// (e, de/dt of the last evaluation) with the energy equation on (a migrant goes on
    /// integrating it), else zeros.
    pub energy: [f32; 2],
}

/// Mirrors `TlParams` in shaders/total_lagrangian.wgsl: the total-Lagrangian solid's
/// particle count and first particle id (its particles have consecutive ids) and the cell
/// quadrature factor dx²/12 (the materials are `Params::solid_materials`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct TlParams {
    pub n: u32,
    pub first_id: u32,
    pub k2: f32,
    pub pad: u32,
}

/// Mirrors `TlPair` in shaders/total_lagrangian.wgsl: one entry of particle i's fixed
/// reference neighbour list: the weights w_ij = V γ_ij and w_ji = V γ_ji, the neighbour's TL
/// index j and X_j − X_i.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct TlPair {
    pub w_ij: [f32; 3],
    pub j: u32,
    pub w_ji: [f32; 3],
    pub pad0: u32,
    pub d0: [f32; 3],
    pub pad1: u32,
}

/// The particle arrays as the GPU stores them, in id order.
pub struct Packed {
    pub pos: Vec<Pos>,
    /// (v, ρ)
    pub velrho: Vec<[f32; 4]>,
    /// Kind and id (`IdSplit::code_word`).
    pub code: Vec<u32>,
    /// Each entry's whole id.
    pub id: Vec<u32>,
    pub ids: IdSplit,
}

impl Packed {
    /// With wide ids, each entry's id's high word ([`IdSplit::high`]), which the code buffer
    /// holds after its n code words; with narrow ids none.
    pub fn high_words(&self) -> Vec<u32> {
        match self.ids.wide {
            true => self.id.iter().map(|&id| self.ids.high(id)).collect(),
            false => Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::kernel::parse;
    use crate::gpu::shader::Shader;
    use crate::scenario::KernelKind;
    use crate::sph::initial::Present;
    use crate::sph::passes::SHADERS;
    use crate::sph::shader::{compose, ShaderConfig, ViscosityForm};
    use crate::sph::total_lagrangian;
    use crate::sph::{
        bodies, elastic, flood_maps, halo, integrate, interaction, open_boundaries, probes,
    };
    use wgpu::naga;

    /// (size, [(member name, offset)]) of a struct type named `name` in the composed `pass`.
    fn reflect(pass: &Shader, name: &str) -> (u32, Vec<(String, u32)>) {
        let (module, _) = parse(&compose(pass, ShaderConfig::default()), pass.name).unwrap();
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        let (handle, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("{name} not in {}", pass.name));
        let members = match &ty.inner {
            naga::TypeInner::Struct { members, .. } => members
                .iter()
                .map(|m| (m.name.clone().unwrap(), m.offset))
                .collect(),
            _ => panic!("{name} is not a struct"),
        };
        (layouter[handle].size, members)
    }

    fn offset(members: &[(String, u32)], field: &str) -> u32 {
        members.iter().find(|(n, _)| n == field).unwrap().1
    }

    macro_rules! check_layout {
        ($pass:expr, $wgsl:literal, $ty:ty, [$($field:ident),*]) => {{
            let (size, members) = reflect($pass, $wgsl);
            assert_eq!(size as usize, std::mem::size_of::<$ty>(), "size of {}", $wgsl);
            $(
                assert_eq!(
                    offset(&members, stringify!($field)) as usize,
                    std::mem::offset_of!($ty, $field),
                    "offset of {}.{}", $wgsl, stringify!($field)
                );
            )*
        }};
    }

    #[test]
    fn params_matches_wgsl() {
        check_layout!(
            &interaction::SHADER,
            "Params",
            Params,
            [
                grid_cells,
                hash_mask,
                block_size,
                cells_per_block,
                inv_cell_size,
                periodic,
                domain_size,
                n_particles,
                h,
                kernel_norm,
                eta2,
                mass,
                rho0,
                tait_b,
                gamma,
                c0,
                gravity,
                alpha,
                nu,
                delta_coef,
                cfl,
                n_probes,
                n_mirror_planes,
                ghost_mls,
                repulsive_d,
                repulsive_r0,
                repulsive_form,
                repulsive_k_over_beta,
                body_id_base,
                n_body_particles,
                solid_p_speed,
                solid_inv_w_dx,
                solid_id_base,
                inlet_id_base,
                n_inlet_particles,
                n_inlets,
                n_outlets,
                contiguous_rows,
                friction,
                friction_slip,
                friction_groups,
                friction_first_solid,
                density_warn,
                density_stop,
                hash_stride,
                solid_materials,
                friction_table
            ]
        );
        check_layout!(
            &interaction::SHADER,
            "SolidMaterial",
            SolidMaterial,
            [rho0, c2, mu, mass, alpha, eps, lambda, total_lagrangian]
        );
        assert_eq!(
            wgsl_u32(&interaction::SHADER, "MAX_SOLID_MATERIALS") as usize,
            MAX_SOLID_MATERIALS
        );
        assert_eq!(
            4 * wgsl_u32(&interaction::SHADER, "FRICTION_TABLE_VECTORS") as usize,
            MAX_FRICTION_GROUPS * MAX_FRICTION_GROUPS
        );
    }

    #[test]
    fn solid_structs_match_wgsl() {
        check_layout!(
            &elastic::SHADER,
            "SolidState",
            SolidState,
            [tau_a, tau_b, body, rate_a, rate_b, interface_p, material]
        );
        check_layout!(&elastic::SHADER, "SymRate", SymRate, [a, b]);
        // Pass-local, allocated by size only.
        assert_eq!(
            reflect(&elastic::SHADER, "SolidTerms").0 as u64,
            crate::sph::elastic::TERMS_BYTES
        );
    }

    #[test]
    fn total_lagrangian_structs_match_wgsl() {
        check_layout!(
            &total_lagrangian::SHADER,
            "TlParams",
            TlParams,
            [n, first_id, k2, pad]
        );
        check_layout!(
            &total_lagrangian::SHADER,
            "TlPair",
            TlPair,
            [w_ij, j, w_ji, pad0, d0, pad1]
        );
    }

    #[test]
    fn sim_state_matches_wgsl() {
        check_layout!(
            &integrate::SHADER,
            "SimState",
            SimState,
            [
                t_rel,
                t_target_rel,
                dt,
                dt_cfl,
                max_speed_bits,
                max_accel_bits,
                nan_count,
                excluded,
                steps,
                t_base,
                inlet_joined,
                drained,
                density_variation_bits,
                beyond_warn,
                beyond_stop,
                density_variation_peak,
                beyond_warn_peak,
                beyond_stop_peak
            ]
        );
    }

    /// The value of the u32 constant `name` in the composed `pass`.
    fn wgsl_u32(pass: &Shader, name: &str) -> u32 {
        let (module, _) = parse(&compose(pass, ShaderConfig::default()), pass.name).unwrap();
        let (_, c) = module
            .constants
            .iter()
            .find(|(_, c)| c.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("{name} not in {}", pass.name));
        match module.global_expressions[c.init] {
            naga::Expression::Literal(naga::Literal::U32(v)) => v,
            ref e => panic!("{name} is {e:?}"),
        }
    }

    /// The case tables' parts start where `TableSizes` puts them, for any table sizes.
    #[test]
    fn case_tables_match_wgsl() {
        use crate::sph::buffers::TableSizes;
        let sizes = TableSizes {
            bodies: 2,
            mirror_planes: 3,
            wall_sensors: 5,
        };
        let cfg = ShaderConfig {
            tables: sizes,
            ..ShaderConfig::default()
        };
        let (module, _) = parse(&compose(&interaction::SHADER, cfg), "interaction").unwrap();
        let (_, ty) = (module.types.iter())
            .find(|(_, t)| t.name.as_deref() == Some("CaseTables"))
            .unwrap();
        let naga::TypeInner::Struct { members, .. } = &ty.inner else {
            panic!("CaseTables is not a struct");
        };
        let at = |name: &str| {
            members
                .iter()
                .find(|m| m.name.as_deref() == Some(name))
                .unwrap()
        };
        assert_eq!(at("bodies").offset, 0);
        assert_eq!(
            at("mirror_planes").offset as usize,
            sizes.mirror_planes_offset()
        );
        assert_eq!(
            at("wall_sensors").offset as usize,
            sizes.wall_sensors_offset()
        );
        assert_eq!(
            at("body_particles").offset as usize,
            sizes.body_particles_offset()
        );
        let bytes = sizes.pack(&[], &[], &[], &[BodyParticle::default(); 7]);
        assert_eq!(bytes.len(), sizes.body_particles_offset() + 7 * 16);
    }

    /// Every particle kind has the same code in Rust (`scenario::Kind`), in the WGSL `KIND_*`
    /// constants and in the f64 reference.
    #[test]
    fn particle_kinds_match_wgsl_and_the_reference() {
        use crate::reference as r;
        use crate::scenario::Kind;
        let reference = [
            r::FLUID,
            r::WALL,
            r::GHOST_NO_SLIP,
            r::GHOST_FREE_SLIP,
            r::REPULSIVE,
            r::SOLID,
            r::SOLID_CLAMPED,
            r::INLET,
        ];
        let wgsl = [
            "KIND_FLUID",
            "KIND_WALL",
            "KIND_GHOST_NO_SLIP",
            "KIND_GHOST_FREE_SLIP",
            "KIND_REPULSIVE",
            "KIND_SOLID",
            "KIND_SOLID_CLAMPED",
            "KIND_INLET",
        ];
        for ((kind, code), name) in Kind::ALL.into_iter().zip(reference).zip(wgsl) {
            assert_eq!(kind as u32, code, "{kind:?} in the reference");
            assert_eq!(wgsl_u32(&interaction::SHADER, name), kind as u32, "{name}");
        }
        assert_eq!(
            wgsl_u32(&interaction::SHADER, "KIND_EXCLUDED"),
            KIND_EXCLUDED
        );
        assert_eq!(r::EXCLUDED, KIND_EXCLUDED);
        assert_eq!(wgsl_u32(&interaction::SHADER, "KIND_SHIFT"), KIND_SHIFT);
    }

    #[test]
    fn body_flags_match_wgsl() {
        assert_eq!(
            wgsl_u32(&interaction::SHADER, "BODY_KINEMATIC"),
            BODY_KINEMATIC
        );
    }

    #[test]
    fn inlet_pressure_modes_match_wgsl() {
        for (name, v) in [
            ("INLET_ZERO", INLET_ZERO),
            ("INLET_HYDROSTATIC", INLET_HYDROSTATIC),
            ("INLET_EXTRAPOLATED", INLET_EXTRAPOLATED),
        ] {
            assert_eq!(wgsl_u32(&open_boundaries::SHADER, name), v, "{name}");
        }
    }

    #[test]
    fn outlet_def_matches_wgsl() {
        check_layout!(&open_boundaries::SHADER, "OutletDef", OutletDef, [min, max]);
    }

    #[test]
    fn inlet_def_matches_wgsl() {
        check_layout!(
            &open_boundaries::SHADER,
            "InletDef",
            InletDef,
            [
                normal,
                first_segment,
                thickness,
                spacing,
                first_id,
                n_columns,
                first_column,
                n_segments,
                surface,
                pressure,
                first_window,
                n_windows,
                first_level,
                n_level
            ]
        );
        check_layout!(
            &open_boundaries::SHADER,
            "FlowWindow",
            FlowWindow,
            [column, start, end, before, after]
        );
        check_layout!(
            &open_boundaries::SHADER,
            "InflowSegment",
            InflowSegment,
            [t, distance, speed, moved]
        );
    }

    #[test]
    fn halo_structs_match_wgsl() {
        check_layout!(
            &halo::SHADER,
            "HaloCtl",
            HaloCtl,
            [axis, own_lo, own_hi, layers, lower, upper, capacity, lean, moving]
        );
        check_layout!(
            &halo::SHADER,
            "HaloCounts",
            HaloCounts,
            [owned, tail, sizes, filled, starts, fits]
        );
        check_layout!(
            &halo::SHADER,
            "HaloArrivals",
            HaloArrivals,
            [messages, particles, states, copy_words]
        );
        assert_eq!(wgsl_u32(&halo::SHADER, "HEADER_WORDS"), halo::HEADER_WORDS);
        let words = |bytes: usize| (bytes / 4) as u32;
        assert_eq!(
            wgsl_u32(&halo::SHADER, "RECORD_WORDS"),
            words(std::mem::size_of::<HaloRecord>())
        );
        assert_eq!(
            wgsl_u32(&halo::SHADER, "COPY_WORDS"),
            words(std::mem::size_of::<halo::HaloCopy>())
        );
        check_layout!(
            &halo::SHADER,
            "HaloRecord",
            HaloRecord,
            [pos, velrho, rate, code, id_high, energy]
        );
    }

    #[test]
    fn pos_and_probe_match_wgsl() {
        check_layout!(&interaction::SHADER, "Pos", Pos, [off, block]);
        check_layout!(
            &probes::SHADER,
            "ProbeDef",
            ProbeDef,
            [point, kind, axis, radius, face, bins, words, bin_width]
        );
        check_layout!(
            &flood_maps::SHADER,
            "MapGrid",
            MapGrid,
            [origin, cell, nx, ny, wet_depth, time, pad]
        );
        check_layout!(
            &flood_maps::SHADER,
            "MapCell",
            MapCell,
            [
                depth,
                u,
                v,
                max_depth,
                max_speed,
                max_hazard,
                arrival,
                wet_samples
            ]
        );
        check_layout!(
            &interaction::SHADER,
            "WallSensor",
            WallSensor,
            [point, radius, normal, face, over_lo, face_id, over_hi]
        );
        check_layout!(
            &interaction::SHADER,
            "MirrorPlane",
            MirrorPlane,
            [point, no_slip, normal]
        );
    }

    #[test]
    fn body_structs_match_wgsl() {
        check_layout!(&bodies::SHADER, "BodyParticle", BodyParticle, [r, body]);
        check_layout!(
            &bodies::SHADER,
            "BodyMotion",
            BodyMotion,
            [
                center_off,
                center_block,
                rotation,
                velocity,
                first,
                omega,
                count,
                accel,
                first_group,
                alpha,
                flags
            ]
        );
    }

    #[test]
    fn block_packing_round_trips() {
        for b in [[0, 0, 0], [2047, 2047, 1023], [5, 1000, 3]] {
            assert_eq!(unpack_block(pack_block(b)), b);
        }
    }

    #[test]
    fn every_pass_validates_in_2d_and_3d() {
        for pass in SHADERS {
            for dim in [2, 3] {
                for kernel in [KernelKind::CubicSpline, KernelKind::WendlandC2] {
                    for viscosity in [ViscosityForm::Artificial, ViscosityForm::Laminar] {
                        // Each flag on and off (wall reactions with each of the others).
                        for (energy, hydrostatic_diffusion, wall_reactions) in [
                            (false, false, false),
                            (false, true, true),
                            (true, false, true),
                            (true, true, false),
                        ] {
                            // Narrow ids with every particle, wide with none and all.
                            for (present, wide) in [
                                (Present::ALL, false),
                                (Present::NONE, true),
                                (Present::ALL, true),
                            ] {
                                let cfg = ShaderConfig {
                                    dim,
                                    kernel,
                                    viscosity,
                                    energy,
                                    hydrostatic_diffusion,
                                    wall_reactions,
                                    present,
                                    ids: IdSplit::for_run(0, wide.then_some(4)),
                                    ..ShaderConfig::default()
                                };
                                parse(&compose(pass, cfg), pass.name).unwrap();
                            }
                        }
                    }
                }
            }
        }
    }
}

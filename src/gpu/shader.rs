//! WGSL composition: generated constants + `shaders/lib/common.wgsl` + one pass file.
//!
//! The shaders are compiled into the binary (`include_str!`), so an installed `wgsph` needs no
//! shader files at run time. Per-case choices (dimension, kernel, viscosity, which kinds of
//! particle the case has) are constants of the composed source, so the compiler removes the
//! branches not taken.

/// Invocations per workgroup of every 1D kernel.
pub const WORKGROUP_SIZE: u32 = 128;

pub const COMMON: &str = include_str!("../../shaders/lib/common.wgsl");
/// Neighbour search over the cell list (`shaders/lib/neighbours.wgsl`; the pass declares
/// `cell_start`).
pub const NEIGHBOURS: &str = include_str!("../../shaders/lib/neighbours.wgsl");
/// First-order moving least squares (`shaders/lib/mls.wgsl`).
pub const MLS: &str = include_str!("../../shaders/lib/mls.wgsl");
/// The fluid interpolated at a point (`shaders/lib/fluid_at.wgsl`; needs `MLS`).
pub const FLUID_AT: &str = include_str!("../../shaders/lib/fluid_at.wgsl");
/// A maximum over the workgroup before one atomic (`shaders/lib/workgroup_max.wgsl`).
pub const WORKGROUP_MAX: &str = include_str!("../../shaders/lib/workgroup_max.wgsl");
/// A wall-pressure sensor's patch of boundary particles (`shaders/lib/wall_patch.wgsl`).
pub const WALL_PATCH: &str = include_str!("../../shaders/lib/wall_patch.wgsl");

/// One shader file per pass, named like its Rust module in `src/sph`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pass {
    CellList,
    PrefixScan,
    Interaction,
    Integrate,
    Probes,
    Ghost,
    DensityFilter,
    Bodies,
    Elastic,
    TotalLagrangian,
    OpenBoundaries,
}

impl Pass {
    pub const ALL: [Pass; 11] = [
        Pass::CellList,
        Pass::PrefixScan,
        Pass::Interaction,
        Pass::Integrate,
        Pass::Probes,
        Pass::Ghost,
        Pass::DensityFilter,
        Pass::Bodies,
        Pass::Elastic,
        Pass::TotalLagrangian,
        Pass::OpenBoundaries,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Pass::CellList => "cell_list",
            Pass::PrefixScan => "prefix_scan",
            Pass::Interaction => "interaction",
            Pass::Integrate => "integrate",
            Pass::Probes => "probes",
            Pass::Ghost => "ghost",
            Pass::DensityFilter => "density_filter",
            Pass::Bodies => "bodies",
            Pass::Elastic => "elastic",
            Pass::TotalLagrangian => "total_lagrangian",
            Pass::OpenBoundaries => "open_boundaries",
        }
    }

    fn source(self) -> &'static str {
        match self {
            Pass::CellList => include_str!("../../shaders/cell_list.wgsl"),
            Pass::PrefixScan => include_str!("../../shaders/prefix_scan.wgsl"),
            Pass::Interaction => include_str!("../../shaders/interaction.wgsl"),
            Pass::Integrate => include_str!("../../shaders/integrate.wgsl"),
            Pass::Probes => include_str!("../../shaders/probes.wgsl"),
            Pass::Ghost => include_str!("../../shaders/ghost.wgsl"),
            Pass::DensityFilter => include_str!("../../shaders/density_filter.wgsl"),
            Pass::Bodies => include_str!("../../shaders/bodies.wgsl"),
            Pass::Elastic => include_str!("../../shaders/elastic.wgsl"),
            Pass::TotalLagrangian => include_str!("../../shaders/total_lagrangian.wgsl"),
            Pass::OpenBoundaries => include_str!("../../shaders/open_boundaries.wgsl"),
        }
    }

    /// Library files (after common.wgsl) this pass uses.
    pub fn libs(self) -> &'static [&'static str] {
        match self {
            Pass::Ghost | Pass::OpenBoundaries => &[NEIGHBOURS, MLS, FLUID_AT],
            Pass::DensityFilter => &[NEIGHBOURS, MLS],
            Pass::Interaction => &[NEIGHBOURS, WALL_PATCH],
            Pass::Elastic => &[NEIGHBOURS],
            Pass::Probes => &[NEIGHBOURS, WORKGROUP_MAX, WALL_PATCH],
            Pass::Integrate | Pass::Bodies => &[WORKGROUP_MAX],
            _ => &[],
        }
    }
}

/// Compile-time choices of a run, emitted as WGSL constants.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShaderConfig {
    pub dim: u32,
    /// 0 cubic spline, 1 Wendland C2.
    pub kernel: u32,
    /// 0 artificial (Monaghan), 1 laminar (Morris / Lo & Shao).
    pub viscosity: u32,
    /// Whether the energy equation is integrated.
    pub energy: bool,
    /// Whether δ-SPH diffuses only the density's departure from hydrostatics (Fourtakas et al.
    /// 2019) rather than the whole density difference (Molteni & Colagrossi 2009).
    pub hydrostatic_diffusion: bool,
    /// Whether fixed walls' boundary particles get the fluid's force (wall-pressure probes).
    pub wall_reactions: bool,
    /// Which particles and walls the case has: a pass compiles out the pair terms of the others.
    pub present: Present,
}

/// What a case holds, for the branches of the pair sums: the kernels leave out the terms of the
/// kinds it lacks. With every kind's branches compiled in, the interaction pass ran 15–40 %
/// slower on lavapipe (docs/performance.md, "Only the kinds a case has"), most likely from the
/// larger kernel's code and registers: lanes already skip a branch that none of them takes.
/// Every flag on is always correct, only slower.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Present {
    /// Elastic solid particles (`Kind::Solid`, `Kind::SolidClamped`).
    pub solids: bool,
    /// Fixed ghost particles, of walls or of bodies.
    pub fixed_ghosts: bool,
    /// Repulsive boundary particles.
    pub repulsive: bool,
    /// Particles of moving bodies (ids from `params.body_id_base` on).
    pub bodies: bool,
    /// Mirror planes.
    pub mirrors: bool,
    /// Every particle is of one elastic body: no fluid, boundary particle or other solid can
    /// load it, and interaction.wgsl gives its particles zero (rather than searching their
    /// neighbours for nothing: 23 % of the step of the total-Lagrangian plate on lavapipe).
    pub lone_solid: bool,
}

impl Present {
    pub const ALL: Present = Present {
        solids: true,
        fixed_ghosts: true,
        repulsive: true,
        bodies: true,
        mirrors: true,
        lone_solid: false,
    };
    /// A fluid with dynamic boundary particles only.
    pub const NONE: Present = Present {
        solids: false,
        fixed_ghosts: false,
        repulsive: false,
        bodies: false,
        mirrors: false,
        lone_solid: false,
    };
}

impl Default for ShaderConfig {
    fn default() -> Self {
        Self {
            dim: 3,
            kernel: 1,
            viscosity: 0,
            energy: false,
            hydrostatic_diffusion: false,
            wall_reactions: false,
            present: Present::ALL,
        }
    }
}

/// The full WGSL source of `pass` for `cfg`.
pub fn compose(pass: Pass, cfg: ShaderConfig) -> String {
    format!(
        "// wgsph: {name}.wgsl composed with lib/common.wgsl\n\
         const DIM: u32 = {dim}u;\nconst KERNEL: u32 = {kernel}u;\n\
         const VISCOSITY: u32 = {visc}u;\nconst ENERGY: bool = {energy};\n\
         const HYDROSTATIC_DIFFUSION: bool = {hydro};\nconst WALL_REACTIONS: bool = {reactions};\n\
         const SOLIDS: bool = {solids};\nconst FIXED_GHOSTS: bool = {ghosts};\n\
         const REPULSIVE: bool = {repulsive};\nconst BODIES: bool = {bodies};\n\
         const MIRRORS: bool = {mirrors};\nconst LONE_SOLID: bool = {lone_solid};\n\
         const WG: u32 = {wg}u;\n\n{common}\n{libs}\n{pass}",
        name = pass.name(),
        dim = cfg.dim,
        kernel = cfg.kernel,
        visc = cfg.viscosity,
        energy = cfg.energy,
        hydro = cfg.hydrostatic_diffusion,
        reactions = cfg.wall_reactions,
        solids = cfg.present.solids,
        ghosts = cfg.present.fixed_ghosts,
        repulsive = cfg.present.repulsive,
        bodies = cfg.present.bodies,
        mirrors = cfg.present.mirrors,
        lone_solid = cfg.present.lone_solid,
        wg = WORKGROUP_SIZE,
        common = COMMON,
        libs = pass.libs().concat(),
        pass = pass.source(),
    )
}

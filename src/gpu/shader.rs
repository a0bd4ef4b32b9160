//! WGSL composition: generated constants + `shaders/lib/common.wgsl` + one pass file.
//!
//! The shaders are compiled into the binary (`include_str!`), so an installed `wgsph` needs no
//! shader files at run time. Per-case choices (dimension, kernel, viscosity) are constants of
//! the composed source, so the compiler removes the branches not taken.

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
            Pass::Interaction | Pass::Elastic | Pass::Probes => &[NEIGHBOURS],
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
         const WG: u32 = {wg}u;\n\n{common}\n{libs}\n{pass}",
        name = pass.name(),
        dim = cfg.dim,
        kernel = cfg.kernel,
        visc = cfg.viscosity,
        energy = cfg.energy,
        hydro = cfg.hydrostatic_diffusion,
        reactions = cfg.wall_reactions,
        wg = WORKGROUP_SIZE,
        common = COMMON,
        libs = pass.libs().concat(),
        pass = pass.source(),
    )
}

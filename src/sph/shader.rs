//! The physics side of shader composition: the per-case compile-time choices (`ShaderConfig`)
//! emitted as WGSL constants, `shaders/lib/common.wgsl` and the library files. Each pass module
//! owns its `SHADER` (its file and the libraries it uses).
//!
//! Per-case choices (dimension, kernel, viscosity, which kinds of particle the case has) are
//! constants of the composed source, so the compiler removes the branches not taken. Choices
//! among methods are named WGSL constants generated from the Rust enums, never bare codes.

use anyhow::Result;

use super::buffers::TableSizes;
use super::initial::Present;
use crate::gpu::kernel::ShaderModule;
use crate::gpu::shader::{compose as compose_shader, Shader, WORKGROUP_SIZE};
use crate::grid::Grid;
use crate::layout::{IdSplit, ProbeCode};
use crate::scenario::{
    DeltaSphForm, GhostCorrection, KernelKind, RepulsiveForm, Scenario, Viscosity,
};

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
/// A particle's id and the solid arrays' index (`shaders/lib/particle_id.wgsl`; the pass
/// declares `code`).
pub const PARTICLE_ID: &str = include_str!("../../shaders/lib/particle_id.wgsl");
/// A subdomain's slab and which of its particles read nothing the exchange brings
/// (`shaders/lib/slab.wgsl`).
pub const SLAB: &str = include_str!("../../shaders/lib/slab.wgsl");
/// The water's share of what the walls leave of the kernel (`shaders/lib/water_fraction.wgsl`;
/// needs `NEIGHBOURS`).
pub const WATER_FRACTION: &str = include_str!("../../shaders/lib/water_fraction.wgsl");
/// A wall-pressure sensor's patch of boundary particles (`shaders/lib/wall_patch.wgsl`).
pub const WALL_PATCH: &str = include_str!("../../shaders/lib/wall_patch.wgsl");

/// The chunks of a spread dispatch on a CPU adapter ([`ShaderConfig::for_adapter`]): any
/// power-of-two number of threads up to this many gets an equal share of every part of the
/// domain.
pub const SPREAD_CHUNKS: u32 = 64;

/// The viscous term of the momentum equation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViscosityForm {
    /// Monaghan's artificial viscosity Π_ij.
    Artificial,
    /// Laminar viscosity (Morris et al. 1997; Lo & Shao 2002).
    Laminar,
}

/// A Rust enum's variants as WGSL constants: `(prefix)_(VARIANT)` = its index; `code` is the
/// value a run-time choice takes in `Params` (the same number as its WGSL constant).
pub trait WgslEnum: Copy + PartialEq + 'static {
    const PREFIX: &'static str;
    const VARIANTS: &'static [(Self, &'static str)];

    fn code(self) -> u32 {
        Self::VARIANTS
            .iter()
            .position(|(v, _)| *v == self)
            .expect("every variant is listed") as u32
    }

    fn name(self) -> String {
        let (_, name) = Self::VARIANTS[self.code() as usize];
        format!("{}_{name}", Self::PREFIX)
    }

    /// `const PREFIX_VARIANT: u32 = k;` for every variant.
    fn declarations() -> String {
        (Self::VARIANTS.iter().enumerate())
            .map(|(k, (_, name))| format!("const {}_{name}: u32 = {k}u;\n", Self::PREFIX))
            .collect()
    }
}

impl WgslEnum for KernelKind {
    const PREFIX: &'static str = "KERNEL";
    const VARIANTS: &'static [(Self, &'static str)] = &[
        (KernelKind::CubicSpline, "CUBIC_SPLINE"),
        (KernelKind::WendlandC2, "WENDLAND_C2"),
    ];
}

impl WgslEnum for ViscosityForm {
    const PREFIX: &'static str = "VISCOSITY";
    const VARIANTS: &'static [(Self, &'static str)] = &[
        (ViscosityForm::Artificial, "ARTIFICIAL"),
        (ViscosityForm::Laminar, "LAMINAR"),
    ];
}

/// Values of `Params::repulsive_form` (a run-time choice: the uniform holds the code).
impl WgslEnum for RepulsiveForm {
    const PREFIX: &'static str = "REPULSIVE";
    const VARIANTS: &'static [(Self, &'static str)] = &[
        (RepulsiveForm::LennardJones, "LENNARD_JONES"),
        (RepulsiveForm::MonaghanKajtar, "MONAGHAN_KAJTAR"),
    ];
}

/// Values of `ProbeDef::kind`.
impl WgslEnum for ProbeCode {
    const PREFIX: &'static str = "PROBE";
    const VARIANTS: &'static [(Self, &'static str)] = &[
        (ProbeCode::Pressure, "PRESSURE"),
        (ProbeCode::Height, "HEIGHT"),
        (ProbeCode::Front, "FRONT"),
        (ProbeCode::WallPressure, "WALL_PRESSURE"),
        (ProbeCode::FrontContinuous, "FRONT_CONTINUOUS"),
        (ProbeCode::Discharge, "DISCHARGE"),
        (ProbeCode::Depth, "DEPTH"),
    ];
}

/// Values of `Params::ghost_mls`.
impl WgslEnum for GhostCorrection {
    const PREFIX: &'static str = "GHOST";
    const VARIANTS: &'static [(Self, &'static str)] = &[
        (GhostCorrection::Shepard, "SHEPARD"),
        (GhostCorrection::Mls, "MLS"),
    ];
}

/// Compile-time choices of a run, emitted as WGSL constants.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShaderConfig {
    pub dim: u32,
    pub kernel: KernelKind,
    pub viscosity: ViscosityForm,
    /// Whether the energy equation is integrated.
    pub energy: bool,
    /// Whether δ-SPH diffuses only the density's departure from hydrostatics (Fourtakas et al.
    /// 2019) rather than the whole density difference (Molteni & Colagrossi 2009).
    pub hydrostatic_diffusion: bool,
    /// Whether fixed walls' boundary particles get the fluid's force (wall-pressure probes).
    pub wall_reactions: bool,
    /// Which particles and walls the case has: a pass compiles out the pair terms of the others.
    pub present: Present,
    /// The sizes of the case's tables (`CaseTables` in common.wgsl).
    pub tables: TableSizes,
    /// Cells per kernel support (`Grid::reach`): 1 for cells of 2h, 2 for cells of h.
    pub cell_reach: u32,
    /// The chunks a neighbour-sum pass's workgroups are spread in (`spread_index` in
    /// common.wgsl): 1 (the dispatch's order) but on a CPU adapter ([`ShaderConfig::for_adapter`]).
    pub spread_chunks: u32,
    /// Whether the case has a periodic axis (the uniform's `periodic` says which): without one,
    /// no pass carries the nearest-image and wrap-around code, which costs every neighbour
    /// candidate a division per axis where a run-time test leaves it in.
    pub periodic: bool,
    /// The Tait exponent γ where it is a whole number from 1 to 15 (`tait_power` multiplies),
    /// otherwise 0 (pow).
    pub tait_gamma: u32,
    /// How the particles' ids are stored.
    pub ids: IdSplit,
}

impl Default for ShaderConfig {
    fn default() -> Self {
        Self {
            dim: 3,
            kernel: KernelKind::WendlandC2,
            viscosity: ViscosityForm::Artificial,
            energy: false,
            hydrostatic_diffusion: false,
            wall_reactions: false,
            present: Present::ALL,
            tables: TableSizes {
                bodies: 1,
                mirror_planes: 1,
                wall_sensors: 1,
            },
            cell_reach: 2,
            spread_chunks: 1,
            periodic: true,
            tait_gamma: 7,
            ids: IdSplit::NARROW,
        }
    }
}

impl ShaderConfig {
    /// The choices of `sc` on `grid`.
    pub fn of(sc: &Scenario, grid: &Grid) -> Result<ShaderConfig> {
        let ph = &sc.physics;
        Ok(ShaderConfig {
            dim: ph.dim,
            kernel: ph.kernel,
            viscosity: match ph.viscosity {
                Viscosity::Artificial { .. } => ViscosityForm::Artificial,
                Viscosity::Laminar { .. } => ViscosityForm::Laminar,
            },
            energy: ph.energy,
            hydrostatic_diffusion: ph.delta_sph > 0.0
                && ph.delta_sph_form == DeltaSphForm::Fourtakas,
            wall_reactions: sc.walls.reactions,
            present: Present::of(sc)?,
            tables: TableSizes::of(sc),
            cell_reach: grid.reach,
            spread_chunks: 1,
            periodic: grid.periodic.iter().any(|&p| p),
            tait_gamma: whole_exponent(ph.gamma),
            ids: super::initial::id_split(sc),
        })
    }

    /// These choices on the adapter `info`: on a CPU adapter the neighbour sums spread their
    /// workgroups over the sorted order in [`SPREAD_CHUNKS`] chunks. llvmpipe hands each of
    /// its threads one contiguous share of a dispatch's workgroups, and the sorted order keeps
    /// the water, most of the sums' cost, together, so in the dispatch's order one thread takes
    /// most of the water while the others wait (docs/performance.md). A GPU schedules its
    /// workgroups as they finish and keeps the dispatch's order, which neighbouring workgroups'
    /// shared reads favour.
    pub fn for_adapter(self, info: &wgpu::AdapterInfo) -> Self {
        let spread = info.device_type == wgpu::DeviceType::Cpu;
        Self {
            spread_chunks: if spread { SPREAD_CHUNKS } else { 1 },
            ..self
        }
    }

    /// The WGSL constants of these choices, in front of every pass.
    fn constants(&self) -> String {
        let p = &self.present;
        let mut out = String::new();
        out += &KernelKind::declarations();
        out += &ViscosityForm::declarations();
        out += &RepulsiveForm::declarations();
        out += &GhostCorrection::declarations();
        out += &ProbeCode::declarations();
        out += &format!(
            "const DIM: u32 = {dim}u;\nconst KERNEL: u32 = {kernel};\n\
             const VISCOSITY: u32 = {visc};\nconst ENERGY: bool = {energy};\n\
             const HYDROSTATIC_DIFFUSION: bool = {hydro};\nconst WALL_REACTIONS: bool = {reactions};\n\
             const SOLIDS: bool = {solids};\nconst FIXED_GHOSTS: bool = {ghosts};\n\
             const REPULSIVE: bool = {repulsive};\nconst BODIES: bool = {bodies};\n\
             const MIRRORS: bool = {mirrors};\nconst LONE_SOLID: bool = {lone_solid};\n\
             const WG: u32 = {wg}u;\n\
             const N_BODIES: u32 = {bodies_n}u;\nconst N_MIRROR_PLANES: u32 = {planes_n}u;\n\
             const N_WALL_SENSORS: u32 = {sensors_n}u;\nconst CELL_REACH: i32 = {reach};\nconst PERIODIC: bool = {periodic};\n\
             const SPREAD_CHUNKS: u32 = {spread}u;\n\
             const TAIT_GAMMA: u32 = {gamma}u;\n\
             const WIDE_IDS: bool = {wide};\nconst ID_LOW_BITS: u32 = {low_bits}u;\n\
             const FREE_ID: u32 = {free}u;\nconst ID_LOW_MASK: u32 = {low_mask}u;\n",
            dim = self.dim,
            kernel = self.kernel.name(),
            visc = self.viscosity.name(),
            energy = self.energy,
            hydro = self.hydrostatic_diffusion,
            reactions = self.wall_reactions,
            solids = p.solids,
            ghosts = p.fixed_ghosts,
            repulsive = p.repulsive,
            bodies = p.bodies,
            mirrors = p.mirrors,
            lone_solid = p.lone_solid,
            wg = WORKGROUP_SIZE,
            bodies_n = self.tables.bodies,
            planes_n = self.tables.mirror_planes,
            sensors_n = self.tables.wall_sensors,
            reach = self.cell_reach,
            periodic = self.periodic,
            spread = self.spread_chunks,
            gamma = self.tait_gamma,
            wide = self.ids.wide,
            low_bits = self.ids.low_bits,
            free = self.ids.free_id(),
            low_mask = self.ids.code_word(0, u32::MAX),
        );
        out
    }
}

/// `gamma` as a whole number from 1 to 15, or 0 where it is not one.
fn whole_exponent(gamma: f64) -> u32 {
    match gamma.fract() == 0.0 && (1.0..16.0).contains(&gamma) {
        true => gamma as u32,
        false => 0,
    }
}

/// The full WGSL source of `shader` for `cfg`: constants, common.wgsl, libraries, the pass.
pub fn compose(shader: &Shader, cfg: ShaderConfig) -> String {
    compose_shader(shader, &format!("{}\n{COMMON}", cfg.constants()))
}

/// `shader` composed for `cfg`, parsed, validated and created on `device`.
pub fn module(device: &wgpu::Device, shader: &Shader, cfg: ShaderConfig) -> Result<ShaderModule> {
    ShaderModule::new(device, shader.name, compose(shader, cfg))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Water's γ = 7 is raised by multiplications; a fractional or out-of-range γ by pow.
    #[test]
    fn only_whole_exponents_are_multiplied_out() {
        assert_eq!(whole_exponent(7.0), 7);
        assert_eq!(whole_exponent(1.0), 1);
        for gamma in [1.4, 0.0, 16.0, f64::NAN] {
            assert_eq!(whole_exponent(gamma), 0, "{gamma}");
        }
    }

    /// The codes the uniform carries are the WGSL constants' values, variant for variant.
    #[test]
    fn method_codes_are_the_wgsl_constants() {
        let cfg = ShaderConfig::default();
        let src = compose(&super::super::interaction::SHADER, cfg);
        for (form, name) in [
            (RepulsiveForm::LennardJones, "REPULSIVE_LENNARD_JONES"),
            (RepulsiveForm::MonaghanKajtar, "REPULSIVE_MONAGHAN_KAJTAR"),
        ] {
            let decl = format!("const {name}: u32 = {}u;", form.code());
            assert!(src.contains(&decl), "{decl}");
        }
        for (c, name) in [
            (GhostCorrection::Shepard, "GHOST_SHEPARD"),
            (GhostCorrection::Mls, "GHOST_MLS"),
        ] {
            let decl = format!("const {name}: u32 = {}u;", c.code());
            assert!(src.contains(&decl), "{decl}");
        }
        for (c, name) in [
            (ProbeCode::Pressure, "PROBE_PRESSURE"),
            (ProbeCode::Discharge, "PROBE_DISCHARGE"),
        ] {
            let decl = format!("const {name}: u32 = {}u;", c.code());
            assert!(src.contains(&decl), "{decl}");
        }
        assert!(src.contains("const KERNEL: u32 = KERNEL_WENDLAND_C2;"));
        assert!(src.contains("const TAIT_GAMMA: u32 = 7u;"));
        assert!(src.contains("const VISCOSITY: u32 = VISCOSITY_ARTIFICIAL;"));
    }
}

//! The case file as written: serde structs mirroring the TOML, every table with
//! `deny_unknown_fields`, and a one-line help text per field for error messages.
//! The meaning of each field is documented in `docs/cases.md`.

use serde::Deserialize;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawCase {
    pub name: Option<String>,
    pub dimension: i64,
    pub particles: RawParticles,
    #[serde(default)]
    pub physics: RawPhysics,
    pub time: RawTime,
    pub tank: Option<RawTank>,
    pub terrain: Option<RawTerrain>,
    #[serde(default)]
    pub buildings: Vec<RawBuildings>,
    #[serde(default)]
    pub fluid_block: Vec<RawBlock>,
    #[serde(default)]
    pub fill: Vec<RawFill>,
    #[serde(default)]
    pub obstacle: Vec<RawObstacle>,
    #[serde(default)]
    pub surface: Vec<RawSurface>,
    pub domain: Option<RawBox>,
    pub walls: Option<RawWalls>,
    #[serde(default)]
    pub probe: Vec<RawProbe>,
    #[serde(default)]
    pub body: Vec<RawBody>,
    #[serde(default)]
    pub solid: Vec<RawSolid>,
    #[serde(default)]
    pub inlet: Vec<RawInlet>,
    #[serde(default)]
    pub outlet: Vec<RawOutlet>,
    #[serde(default)]
    pub friction: Vec<RawFriction>,
    pub maps: Option<RawMaps>,
}

/// Flood maps: `[maps]` (`docs/cases.md`, "Flood maps").
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawMaps {
    pub cell_m: Option<f64>,
    pub min_m: Option<Vec<f64>>,
    pub max_m: Option<Vec<f64>>,
    pub wet_depth_m: Option<f64>,
}

/// A pair's own friction coefficient: `[[friction]]` (`docs/cases.md`, "Friction").
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawFriction {
    pub between: Vec<String>,
    pub coefficient: f64,
}

/// An outlet: `[[outlet]]` (`docs/cases.md`, "Outlets").
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawOutlet {
    pub name: String,
    pub min_m: Vec<f64>,
    pub max_m: Vec<f64>,
}

/// A velocity inlet: `[[inlet]]` (`docs/cases.md`, "Inlets").
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawInlet {
    pub name: String,
    pub min_m: Vec<f64>,
    pub max_m: Vec<f64>,
    pub direction: Vec<f64>,
    pub velocity_m_s: Option<f64>,
    pub discharge_m3_s: Option<f64>,
    pub velocity_file: Option<String>,
    pub discharge_file: Option<String>,
    pub interpolation: Option<InterpolationName>,
    pub stop_s: Option<f64>,
    pub pressure: Option<InletPressureName>,
    pub level_file: Option<String>,
}

/// How an inlet's hydrograph joins its samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum InterpolationName {
    Linear,
    Cubic,
}

/// The pressure of an inlet's buffer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum InletPressureName {
    Zero,
    Hydrostatic,
    Extrapolated,
}

/// An elastic body: `[[solid]]` (`docs/cases.md`, "Elastic solids").
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSolid {
    pub name: String,
    pub min_m: Vec<f64>,
    pub max_m: Vec<f64>,
    pub density_kg_m3: f64,
    pub youngs_modulus_pa: f64,
    pub poisson_ratio: f64,
    pub alpha: Option<f64>,
    pub artificial_stress: Option<f64>,
    pub formulation: Option<SolidFormulationName>,
    pub clamped_min_m: Option<Vec<f64>>,
    pub clamped_max_m: Option<Vec<f64>>,
    pub initial_velocity: Option<RawSolidVelocity>,
}

/// `[solid.initial_velocity]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSolidVelocity {
    pub kind: SolidVelocityName,
    pub root_m: Option<Vec<f64>>,
    pub axis: Option<Vec<f64>>,
    pub direction: Option<Vec<f64>>,
    pub length_m: Option<f64>,
    pub tip_velocity_m_s: Option<f64>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum SolidFormulationName {
    UpdatedLagrangian,
    TotalLagrangian,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum SolidVelocityName {
    CantileverMode,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawParticles {
    pub dx_m: f64,
    pub h_over_dx: Option<f64>,
    pub kernel: Option<KernelName>,
    pub cell: Option<CellName>,
    pub id_low_bits: Option<u32>,
}

/// The neighbour grid's cell edge (`crate::scenario::CellEdge`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub(super) enum CellName {
    #[serde(rename = "2h")]
    TwoH,
    #[serde(rename = "h")]
    H,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum KernelName {
    CubicSpline,
    WendlandC2,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawPhysics {
    pub rho0_kg_m3: Option<f64>,
    pub gravity_m_s2: Option<Vec<f64>>,
    pub sound_speed_m_s: Option<f64>,
    pub sound_speed_coef: Option<f64>,
    pub gamma: Option<f64>,
    pub viscosity: Option<ViscosityName>,
    pub alpha: Option<f64>,
    pub nu_m2_s: Option<f64>,
    pub delta_sph: Option<f64>,
    pub delta_sph_form: Option<DeltaSphFormName>,
    pub density_filter: Option<DensityFilterName>,
    pub density_filter_every: Option<i64>,
    pub energy: Option<bool>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum DeltaSphFormName {
    Fourtakas,
    MolteniColagrossi,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum DensityFilterName {
    None,
    Shepard,
    Mls,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum ViscosityName {
    Artificial,
    Laminar,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawTime {
    pub end_s: f64,
    pub output_every_s: f64,
    pub probe_every_s: Option<f64>,
    pub cfl: Option<f64>,
    pub output_boundary: Option<OutputBoundaryName>,
    pub density_variation_warn: Option<f64>,
    pub density_variation_stop: Option<f64>,
    pub overlap_exchange: Option<OverlapExchangeName>,
}

/// Whether a run over ranks overlaps the exchange with its interior's sums.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum OverlapExchangeName {
    Auto,
    Always,
    Never,
}

/// Which particle outputs hold the boundary particles that have not moved.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum OutputBoundaryName {
    Every,
    First,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawTank {
    pub min_m: Vec<f64>,
    pub max_m: Vec<f64>,
    pub layers: Option<i64>,
    pub open_top: Option<bool>,
    pub wall: Option<WallName>,
    pub slip: Option<SlipName>,
    pub motion: Option<RawMotion>,
}

/// The ground from an elevation grid: `[terrain]` (`docs/cases.md`, "Terrain").
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawTerrain {
    pub file: String,
    pub origin_m: Option<Vec<f64>>,
    pub nodata: Option<NodataName>,
    pub nodata_elevation_m: Option<f64>,
    pub layers: Option<i64>,
    pub wall: Option<WallName>,
    pub slip: Option<SlipName>,
}

/// Water from a seed up to a level, inside a closed mesh or in a polygon's prism: `[[fill]]`
/// (`docs/cases.md`, "Fills").
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawFill {
    pub seed_m: Option<Vec<f64>>,
    pub mesh: Option<String>,
    pub polygon_m: Option<Vec<Vec<f64>>>,
    pub level_m: Option<f64>,
    pub scale: Option<f64>,
    pub rotate_deg: Option<Vec<f64>>,
    pub translate_m: Option<Vec<f64>>,
    /// `false` leaves the fill out (a case with and without a wet bed, `--set`).
    pub enabled: Option<bool>,
}

/// A wall from a triangle mesh file, open or closed: `[[surface]]` (`docs/cases.md`,
/// "Surfaces").
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSurface {
    pub file: String,
    pub scale: Option<f64>,
    pub rotate_deg: Option<Vec<f64>>,
    pub translate_m: Option<Vec<f64>>,
    pub flip: Option<bool>,
    pub layers: Option<i64>,
    pub wall: Option<WallName>,
    pub slip: Option<SlipName>,
}

/// Buildings from a GeoJSON file of footprints: `[[buildings]]` (`docs/cases.md`, "Buildings").
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawBuildings {
    pub file: String,
    pub height_property: Option<String>,
    pub default_height_m: Option<f64>,
    pub layers: Option<i64>,
    pub wall: Option<WallName>,
    pub slip: Option<SlipName>,
}

/// What a terrain's cells without data become.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum NodataName {
    Refuse,
    Nearest,
    Elevation,
}

/// A moving solid: `[[body]]` (`docs/cases.md`, "Bodies").
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawBody {
    pub name: String,
    pub shape: ShapeName,
    pub min_m: Option<Vec<f64>>,
    pub max_m: Option<Vec<f64>>,
    pub center_m: Option<Vec<f64>>,
    pub radius_m: Option<f64>,
    pub vertices_m: Option<Vec<Vec<f64>>>,
    pub file: Option<String>,
    pub density_kg_m3: Option<f64>,
    pub mass_kg: Option<f64>,
    pub layers: Option<i64>,
    pub wall: Option<WallName>,
    pub slip: Option<SlipName>,
    pub motion: Option<RawMotion>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum ShapeName {
    Box,
    Circle,
    Sphere,
    Polygon,
    Mesh,
}

/// How a body or the tank moves: `[body.motion]`, `[tank.motion]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawMotion {
    pub kind: MotionName,
    pub velocity_m_s: Option<Vec<f64>>,
    pub angular_velocity_rad_s: Option<Vec<f64>>,
    pub release_s: Option<f64>,
    pub pivot_m: Option<Vec<f64>>,
    pub axis: Option<Vec<f64>>,
    pub translation_m: Option<Vec<f64>>,
    pub rotation_deg: Option<f64>,
    pub period_s: Option<f64>,
    pub phase_deg: Option<f64>,
    pub file: Option<String>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum MotionName {
    Free,
    Fixed,
    Sine,
    Series,
}

/// Wall treatment of the tank or of an obstacle (`docs/cases.md`, "Wall treatments").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum WallName {
    Dynamic,
    Repulsive,
    Mirror,
    FixedGhost,
}

impl WallName {
    /// The name as written in a case file.
    pub(super) fn as_str(self) -> &'static str {
        match self {
            WallName::Dynamic => "dynamic",
            WallName::Repulsive => "repulsive",
            WallName::Mirror => "mirror",
            WallName::FixedGhost => "fixed_ghost",
        }
    }
}

/// Velocity condition of mirror and fixed-ghost walls.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum SlipName {
    NoSlip,
    FreeSlip,
}

/// An obstacle: a box and its wall treatment.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawObstacle {
    pub min_m: Vec<f64>,
    pub max_m: Vec<f64>,
    pub wall: Option<WallName>,
    pub slip: Option<SlipName>,
    /// `false` leaves the obstacle out (a case with and without it from one file, `--set`).
    pub enabled: Option<bool>,
}

/// Parameters of the wall treatments: `[walls]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawWalls {
    pub ghost_correction: Option<GhostCorrectionName>,
    pub repulsive_d_m2_s2: Option<f64>,
    pub repulsive_r0_m: Option<f64>,
    pub repulsive_form: Option<RepulsiveFormName>,
    pub repulsive_k_m2_s2: Option<f64>,
    pub repulsive_beta: Option<f64>,
    pub friction_coefficient: Option<f64>,
    pub friction_slip_m_s: Option<f64>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum RepulsiveFormName {
    LennardJones,
    MonaghanKajtar,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum GhostCorrectionName {
    Shepard,
    Mls,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawBlock {
    pub min_m: Vec<f64>,
    pub max_m: Vec<f64>,
    pub velocity_m_s: Option<Vec<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawBox {
    pub min_m: Vec<f64>,
    pub max_m: Vec<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawProbe {
    pub name: String,
    /// `false` leaves the probe out (one that needs an obstacle left out, say).
    pub enabled: Option<bool>,
    pub kind: ProbeName,
    pub point_m: Option<Vec<f64>>,
    /// A pressure probe's point on a wall's face: it samples half a spacing in front of it.
    pub face_m: Option<Vec<f64>>,
    pub base_m: Option<Vec<f64>>,
    pub origin_m: Option<Vec<f64>>,
    pub axis: Option<Vec<f64>>,
    /// A front probe that follows the continuous water rather than the furthest particle.
    pub continuous: Option<bool>,
    /// A wall-pressure probe's (or a pressure probe's on a face) face normal, into the fluid.
    pub normal: Option<Vec<f64>>,
    /// A wall-pressure probe's radius across its normal.
    pub radius_m: Option<f64>,
    /// The body the probe moves with ("tank" for a moving tank).
    pub body: Option<String>,
    /// A discharge probe's section: from this point to `to_m` (in plan, in 3D).
    pub from_m: Option<Vec<f64>>,
    pub to_m: Option<Vec<f64>>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum ProbeName {
    Pressure,
    Height,
    Front,
    Point,
    WallPressure,
    Discharge,
    Depth,
}

/// Help for one field: what it is and an example of a valid line.
pub(super) struct FieldHelp {
    /// Dotted path with array indices written `[]`.
    pub path: &'static str,
    pub meaning: &'static str,
    pub example: &'static str,
}

const fn f(path: &'static str, meaning: &'static str, example: &'static str) -> FieldHelp {
    FieldHelp {
        path,
        meaning,
        example,
    }
}

/// Every field of the schema (tables included), for "missing" and "wrong type" messages.
pub(super) const FIELDS: &[FieldHelp] = &[
    f(
        "name",
        "the case name (a string)",
        "name = \"dam_break_2d\"",
    ),
    f("dimension", "the dimension, 2 or 3", "dimension = 2"),
    f(
        "particles",
        "the [particles] table",
        "[particles] with dx_m = 0.01",
    ),
    f(
        "particles.dx_m",
        "the initial particle spacing in metres",
        "dx_m = 0.01",
    ),
    f(
        "particles.h_over_dx",
        "h / dx, a number in [1, 3]",
        "h_over_dx = 1.3",
    ),
    f(
        "particles.kernel",
        "the kernel name",
        "kernel = \"wendland_c2\"",
    ),
    f(
        "particles.cell",
        "the neighbour grid's cell edge, \"h\" or \"2h\" (by default h where the grid allows)",
        "cell = \"2h\"",
    ),
    f(
        "particles.id_low_bits",
        "wide particle ids (a second id word per particle, which runs of 2^28 particles or more \
         take by themselves) with this many of an id's bits in its code word, 1 to 28: fewer \
         check the wide ids' paths on a small case",
        "id_low_bits = 4",
    ),
    f(
        "physics",
        "the [physics] table",
        "[physics] with sound_speed_coef = 10.0",
    ),
    f(
        "physics.rho0_kg_m3",
        "the reference density in kg/m³",
        "rho0_kg_m3 = 1000.0",
    ),
    f(
        "physics.gravity_m_s2",
        "the gravity vector in m/s²",
        "gravity_m_s2 = [0.0, -9.81]",
    ),
    f(
        "physics.sound_speed_m_s",
        "the numerical speed of sound in m/s",
        "sound_speed_m_s = 20.0",
    ),
    f(
        "physics.sound_speed_coef",
        "c0 / sqrt(|g| H), a positive number",
        "sound_speed_coef = 10.0",
    ),
    f("physics.gamma", "the Tait exponent", "gamma = 7.0"),
    f(
        "physics.viscosity",
        "the viscosity model",
        "viscosity = \"artificial\"",
    ),
    f(
        "physics.alpha",
        "the artificial viscosity coefficient",
        "alpha = 0.01",
    ),
    f(
        "physics.nu_m2_s",
        "the kinematic viscosity in m²/s",
        "nu_m2_s = 1.0e-6",
    ),
    f(
        "physics.delta_sph",
        "the delta-SPH coefficient in [0, 1]",
        "delta_sph = 0.1",
    ),
    f(
        "physics.delta_sph_form",
        "what delta-SPH diffuses: fourtakas or molteni_colagrossi",
        "delta_sph_form = \"fourtakas\"",
    ),
    f(
        "physics.density_filter",
        "the density re-initialisation filter: none, shepard or mls",
        "density_filter = \"shepard\"",
    ),
    f(
        "physics.density_filter_every",
        "the steps between density filters, 1 to 10000",
        "density_filter_every = 30",
    ),
    f(
        "physics.energy",
        "whether to integrate the energy equation",
        "energy = true",
    ),
    f(
        "time",
        "the [time] table",
        "[time] with end_s = 1.0 and output_every_s = 0.02",
    ),
    f("time.end_s", "the end time in seconds", "end_s = 1.0"),
    f(
        "time.output_every_s",
        "the output interval in seconds",
        "output_every_s = 0.02",
    ),
    f(
        "time.probe_every_s",
        "the probe sampling interval in seconds",
        "probe_every_s = 0.005",
    ),
    f("time.cfl", "the Courant number in (0, 1]", "cfl = 0.2"),
    f(
        "time.output_boundary",
        "which particle outputs hold the boundary particles that have not moved: every or first",
        "output_boundary = \"first\"",
    ),
    f(
        "time.overlap_exchange",
        "whether a run over ranks sums its particles away from the cuts while the halo \
         travels: \"auto\" (each rank times both ways and takes the faster), \"always\" or \
         \"never\"; no result changes",
        "overlap_exchange = \"never\"",
    ),
    f(
        "time.density_variation_warn",
        "the fluid's density variation |ρ/ρ0 − 1| beyond which the run warns",
        "density_variation_warn = 0.03",
    ),
    f(
        "time.density_variation_stop",
        "the fluid's density variation |ρ/ρ0 − 1| beyond which the run stops",
        "density_variation_stop = 0.1",
    ),
    f("tank", "the [tank] table", "[tank] with min_m and max_m"),
    f(
        "tank.min_m",
        "the inner lower corner of the tank in metres",
        "min_m = [0.0, 0.0]",
    ),
    f(
        "tank.max_m",
        "the inner upper corner of the tank in metres",
        "max_m = [1.0, 0.6]",
    ),
    f(
        "tank.layers",
        "the number of wall-particle layers, 1 to 8",
        "layers = 3",
    ),
    f(
        "tank.open_top",
        "whether the tank has no lid",
        "open_top = true",
    ),
    f(
        "tank.wall",
        "the tank's wall treatment: dynamic, repulsive, mirror or fixed_ghost",
        "wall = \"dynamic\"",
    ),
    f(
        "tank.slip",
        "the velocity condition of mirror and fixed_ghost walls",
        "slip = \"no_slip\"",
    ),
    f(
        "fluid_block",
        "a list of [[fluid_block]] tables",
        "[[fluid_block]] with min_m and max_m",
    ),
    f(
        "fluid_block[]",
        "a [[fluid_block]] table",
        "[[fluid_block]] with min_m and max_m",
    ),
    f(
        "fluid_block[].min_m",
        "the block's lower corner in metres",
        "min_m = [0.0, 0.0]",
    ),
    f(
        "fluid_block[].max_m",
        "the block's upper corner in metres",
        "max_m = [0.5, 0.5]",
    ),
    f(
        "fluid_block[].velocity_m_s",
        "the initial velocity in m/s",
        "velocity_m_s = [0.0, 0.0]",
    ),
    f(
        "inlet",
        "a list of [[inlet]] tables",
        "[[inlet]] with name, min_m, max_m, direction and velocity_m_s (or a discharge)",
    ),
    f(
        "inlet[]",
        "an [[inlet]] table",
        "[[inlet]] with name, min_m, max_m, direction and velocity_m_s (or a discharge)",
    ),
    f(
        "inlet[].name",
        "the inlet's name, unique among the inlets",
        "name = \"nozzle\"",
    ),
    f(
        "inlet[].min_m",
        "the lower corner of the inlet's buffer box in metres",
        "min_m = [0.0, 0.3]",
    ),
    f(
        "inlet[].max_m",
        "the upper corner of the inlet's buffer box in metres",
        "max_m = [0.04, 0.35]",
    ),
    f(
        "inlet[].direction",
        "the inflow direction, an axis: the fluid leaves the box through the face it points at",
        "direction = [1.0, 0.0]",
    ),
    f(
        "inlet[].velocity_m_s",
        "the inflow speed in m/s, along direction",
        "velocity_m_s = 1.0",
    ),
    f(
        "inlet[].discharge_m3_s",
        "the inflow's discharge in m³/s (2D: m²/s, per metre of width)",
        "discharge_m3_s = 0.05",
    ),
    f(
        "inlet[].velocity_file",
        "a CSV of the inflow speed in time (t_s, u_m_s), relative to the case file",
        "velocity_file = \"inflow_speed.csv\"",
    ),
    f(
        "inlet[].discharge_file",
        "a CSV of the discharge in time, a hydrograph (t_s, q_m3_s; 2D: m²/s), relative to \
         the case file",
        "discharge_file = \"hydrograph.csv\"",
    ),
    f(
        "inlet[].interpolation",
        "how a velocity_file's or discharge_file's samples are joined: linear or cubic \
         (monotone)",
        "interpolation = \"linear\"",
    ),
    f(
        "inlet[].pressure",
        "the buffer's pressure: zero (a free jet) or hydrostatic below the box's top (an open \
         channel's inflow)",
        "pressure = \"hydrostatic\"",
    ),
    f(
        "inlet[].level_file",
        "a CSV of the water level on the inlet's plane in time (t_s, level_m, the height \
         against gravity): only the columns below it flow",
        "level_file = \"stage.csv\"",
    ),
    f(
        "inlet[].stop_s",
        "when the inflow stops, in seconds (default: time.end_s)",
        "stop_s = 0.5",
    ),
    f(
        "maps",
        "flood maps over a plan grid (3D cases)",
        "[maps] with cell_m = 0.1",
    ),
    f(
        "maps.cell_m",
        "the map cells' size in metres, at least particles.dx_m (default: 2 dx)",
        "cell_m = 0.1",
    ),
    f(
        "maps.min_m",
        "the south-west corner of the mapped area in plan, in metres (default: the domain's)",
        "min_m = [0.0, 0.0]",
    ),
    f(
        "maps.max_m",
        "the north-east corner of the mapped area in plan, in metres (default: the domain's)",
        "max_m = [2.0, 1.0]",
    ),
    f(
        "maps.wet_depth_m",
        "the depth a cell must reach for its time of arrival, in metres (default: dx)",
        "wet_depth_m = 0.01",
    ),
    f(
        "outlet",
        "a list of [[outlet]] tables",
        "[[outlet]] with name, min_m and max_m",
    ),
    f(
        "outlet[]",
        "an [[outlet]] table",
        "[[outlet]] with name, min_m and max_m",
    ),
    f(
        "outlet[].name",
        "the outlet's name, unique among the outlets",
        "name = \"downstream\"",
    ),
    f(
        "outlet[].min_m",
        "the lower corner of the outlet's box in metres",
        "min_m = [1.9, -0.1]",
    ),
    f(
        "outlet[].max_m",
        "the upper corner of the outlet's box in metres",
        "max_m = [2.1, 0.5]",
    ),
    f(
        "obstacle",
        "a list of [[obstacle]] tables",
        "[[obstacle]] with min_m and max_m",
    ),
    f(
        "obstacle[]",
        "an [[obstacle]] table",
        "[[obstacle]] with min_m and max_m",
    ),
    f(
        "obstacle[].min_m",
        "the obstacle's lower corner in metres",
        "min_m = [0.6, 0.0]",
    ),
    f(
        "obstacle[].max_m",
        "the obstacle's upper corner in metres",
        "max_m = [0.7, 0.1]",
    ),
    f(
        "obstacle[].wall",
        "the obstacle's wall treatment: dynamic, repulsive or fixed_ghost",
        "wall = \"dynamic\"",
    ),
    f(
        "obstacle[].slip",
        "the velocity condition of a fixed_ghost obstacle",
        "slip = \"no_slip\"",
    ),
    f(
        "obstacle[].enabled",
        "false leaves the obstacle out (true, the default)",
        "enabled = true",
    ),
    f(
        "domain",
        "the [domain] table",
        "[domain] with min_m and max_m",
    ),
    f(
        "domain.min_m",
        "the domain's lower corner in metres",
        "min_m = [-0.1, -0.1]",
    ),
    f(
        "domain.max_m",
        "the domain's upper corner in metres",
        "max_m = [1.1, 1.2]",
    ),
    f(
        "walls",
        "the [walls] table",
        "[walls] with ghost_correction = \"mls\"",
    ),
    f(
        "walls.ghost_correction",
        "the ghost interpolation, shepard or mls",
        "ghost_correction = \"mls\"",
    ),
    f(
        "walls.repulsive_d_m2_s2",
        "the Lennard-Jones strength D of repulsive walls in m²/s²",
        "repulsive_d_m2_s2 = 24.5",
    ),
    f(
        "walls.repulsive_r0_m",
        "the Lennard-Jones cut-off r0 of repulsive walls in metres",
        "repulsive_r0_m = 0.01",
    ),
    f(
        "walls.repulsive_form",
        "the repulsive force law: lennard_jones or monaghan_kajtar",
        "repulsive_form = \"monaghan_kajtar\"",
    ),
    f(
        "walls.repulsive_k_m2_s2",
        "the Monaghan & Kajtar strength K of repulsive walls in m²/s²",
        "repulsive_k_m2_s2 = 4.9",
    ),
    f(
        "walls.friction_coefficient",
        "the Coulomb friction coefficient of contact (bodies and solids), 0 for none",
        "friction_coefficient = 0.3",
    ),
    f(
        "friction",
        "the pairs with a friction coefficient of their own",
        "[[friction]] with between and coefficient",
    ),
    f(
        "friction[]",
        "a pair with a friction coefficient of its own",
        "[[friction]] with between and coefficient",
    ),
    f(
        "friction[].between",
        "the two names of the pair: bodies, solids or \"walls\"",
        "between = [\"box\", \"walls\"]",
    ),
    f(
        "friction[].coefficient",
        "the pair's Coulomb friction coefficient",
        "coefficient = 0.5",
    ),
    f(
        "walls.friction_slip_m_s",
        "the regularisation speed of contact friction in m/s",
        "friction_slip_m_s = 0.001",
    ),
    f(
        "walls.repulsive_beta",
        "the Monaghan & Kajtar ratio of fluid to boundary-particle spacing",
        "repulsive_beta = 1.0",
    ),
    f(
        "probe",
        "a list of [[probe]] tables",
        "[[probe]] with name, kind and its point",
    ),
    f(
        "probe[]",
        "a [[probe]] table",
        "[[probe]] with name, kind and its point",
    ),
    f(
        "probe[].name",
        "the probe name, letters, digits, _ and -",
        "name = \"P1\"",
    ),
    f("probe[].kind", "the probe kind", "kind = \"pressure\""),
    f(
        "tank.motion",
        "the [tank.motion] table",
        "[tank.motion] with kind = \"sine\"",
    ),
    f(
        "body",
        "a list of [[body]] tables",
        "[[body]] with name, shape and its size",
    ),
    f(
        "body[]",
        "a [[body]] table",
        "[[body]] with name, shape and its size",
    ),
    f(
        "body[].name",
        "the body name, letters, digits, _ and -",
        "name = \"box\"",
    ),
    f(
        "body[].shape",
        "the body shape: box, circle or polygon (2D), sphere or mesh (3D, an STL file)",
        "shape = \"box\"",
    ),
    f(
        "body[].min_m",
        "the lower corner of a box body in metres",
        "min_m = [0.4, 0.2]",
    ),
    f(
        "body[].max_m",
        "the upper corner of a box body in metres",
        "max_m = [0.6, 0.3]",
    ),
    f(
        "body[].center_m",
        "the centre of a circle or sphere body in metres",
        "center_m = [0.5, 0.4]",
    ),
    f(
        "body[].radius_m",
        "the radius of a circle or sphere body in metres",
        "radius_m = 0.055",
    ),
    f(
        "body[].vertices_m",
        "the corners of a polygon body in order, in metres",
        "vertices_m = [[0.4, 0.3], [0.5, 0.2], [0.6, 0.3]]",
    ),
    f(
        "body[].file",
        "the STL file of a mesh body, relative to the case file",
        "file = \"hull.stl\"",
    ),
    f(
        "body[].density_kg_m3",
        "the body density in kg/m³",
        "density_kg_m3 = 500.0",
    ),
    f(
        "body[].mass_kg",
        "the body mass in kg (per metre of depth in 2D)",
        "mass_kg = 4.75",
    ),
    f(
        "body[].layers",
        "the particle layers under the body surface, 1 to 64",
        "layers = 3",
    ),
    f(
        "body[].wall",
        "the body's wall treatment: dynamic, repulsive or fixed_ghost",
        "wall = \"dynamic\"",
    ),
    f(
        "body[].slip",
        "the velocity condition of a fixed_ghost body",
        "slip = \"no_slip\"",
    ),
    f(
        "body[].motion",
        "the [body.motion] table",
        "[body.motion] with kind = \"free\"",
    ),
    f(
        "motion.kind",
        "the motion: free or fixed (bodies only), sine or series",
        "kind = \"sine\"",
    ),
    f(
        "motion.velocity_m_s",
        "the initial velocity of a free body's centre in m/s",
        "velocity_m_s = [0.0, -2.955]",
    ),
    f(
        "motion.angular_velocity_rad_s",
        "the initial angular velocity of a free body in rad/s: [w_z] in 2D, [w_x, w_y, w_z] in 3D",
        "angular_velocity_rad_s = [0.0]",
    ),
    f(
        "motion.release_s",
        "how long a free body is held at rest before it is released, in s (the water settles \
         around it meanwhile)",
        "release_s = 2.0",
    ),
    f(
        "motion.pivot_m",
        "the point the prescribed rotation turns about, in metres",
        "pivot_m = [0.46, 0.0]",
    ),
    f(
        "motion.axis",
        "the rotation axis of a prescribed motion (3D only; 2D turns about z)",
        "axis = [0.0, 1.0, 0.0]",
    ),
    f(
        "motion.translation_m",
        "the amplitude of the sinusoidal displacement in metres",
        "translation_m = [0.05, 0.0]",
    ),
    f(
        "motion.rotation_deg",
        "the amplitude of the sinusoidal rotation in degrees",
        "rotation_deg = 4.0",
    ),
    f(
        "motion.period_s",
        "the period of the sinusoidal motion in seconds",
        "period_s = 3.14159",
    ),
    f(
        "motion.phase_deg",
        "the phase of the sinusoidal motion in degrees",
        "phase_deg = 0.0",
    ),
    f(
        "motion.file",
        "the CSV of the motion time series (t_s, dx_m, dy_m[, dz_m], angle_deg), relative to the \
         case file",
        "file = \"excitation.csv\"",
    ),
    f(
        "probe[].point_m",
        "the sampling point of a pressure probe, the centre of a wall-pressure probe's face",
        "point_m = [0.5, 0.05]",
    ),
    f(
        "probe[].face_m",
        "a point on the wall or obstacle face a pressure probe samples in front of (half a \
         spacing out along normal, at the run's dx)",
        "face_m = [0.8245, 0.5, 0.021]",
    ),
    f(
        "probe[].base_m",
        "the foot of a height or depth gauge",
        "base_m = [0.5, 0.0]",
    ),
    f(
        "probe[].origin_m",
        "the origin of a front probe",
        "origin_m = [0.0, 0.0]",
    ),
    f(
        "probe[].axis",
        "the direction of a front probe",
        "axis = [1.0, 0.0]",
    ),
    f(
        "probe[].from_m",
        "one end of a discharge probe's section (3D: of its line in plan)",
        "from_m = [2.0, 0.0, 0.0]",
    ),
    f(
        "probe[].to_m",
        "the other end of a discharge probe's section",
        "to_m = [2.0, 1.0, 0.0]",
    ),
    f(
        "probe[].continuous",
        "whether a front probe follows the continuous water (true) or the furthest fluid \
         particle (false, the default)",
        "continuous = true",
    ),
    f(
        "probe[].enabled",
        "false leaves the probe out (true, the default)",
        "enabled = true",
    ),
    f(
        "probe[].normal",
        "the normal of a wall-pressure probe's face, or of a pressure probe's face_m, into the \
         fluid",
        "normal = [-1.0, 0.0]",
    ),
    f(
        "probe[].radius_m",
        "the radius of a wall-pressure probe's patch across its normal",
        "radius_m = 0.005",
    ),
    f(
        "probe[].body",
        "the body the probe moves with (\"tank\" for a moving tank)",
        "body = \"tank\"",
    ),
    f(
        "solid",
        "a list of [[solid]] tables",
        "[[solid]] with name, min_m, max_m and the material",
    ),
    f(
        "solid[]",
        "a [[solid]] table",
        "[[solid]] with name, min_m, max_m and the material",
    ),
    f(
        "solid[].name",
        "the solid's name, letters, digits, _ and -",
        "name = \"plate\"",
    ),
    f(
        "solid[].min_m",
        "the solid's lower corner in metres",
        "min_m = [0.0, 0.0]",
    ),
    f(
        "solid[].max_m",
        "the solid's upper corner in metres",
        "max_m = [0.26, 0.02]",
    ),
    f(
        "solid[].density_kg_m3",
        "the solid's density in kg/m³",
        "density_kg_m3 = 1000.0",
    ),
    f(
        "solid[].youngs_modulus_pa",
        "Young's modulus in Pa",
        "youngs_modulus_pa = 2.0e6",
    ),
    f(
        "solid[].poisson_ratio",
        "the Poisson ratio, 0 to 0.49",
        "poisson_ratio = 0.3975",
    ),
    f(
        "solid[].alpha",
        "the artificial viscosity between solid particles",
        "alpha = 0.1",
    ),
    f(
        "solid[].artificial_stress",
        "the artificial stress coefficient epsilon",
        "artificial_stress = 0.3",
    ),
    f(
        "solid[].formulation",
        "the solid discretisation: updated_lagrangian or total_lagrangian",
        "formulation = \"total_lagrangian\"",
    ),
    f(
        "solid[].clamped_min_m",
        "the lower corner of the clamped region in metres",
        "clamped_min_m = [0.0, 0.0]",
    ),
    f(
        "solid[].clamped_max_m",
        "the upper corner of the clamped region in metres",
        "clamped_max_m = [0.06, 0.02]",
    ),
    f(
        "solid[].initial_velocity",
        "the [solid.initial_velocity] table",
        "[solid.initial_velocity] with kind = \"cantilever_mode\"",
    ),
    f(
        "solid[].initial_velocity.kind",
        "the initial velocity field: cantilever_mode",
        "kind = \"cantilever_mode\"",
    ),
    f(
        "solid[].initial_velocity.root_m",
        "the clamped end of the cantilever in metres",
        "root_m = [0.06, 0.01]",
    ),
    f(
        "solid[].initial_velocity.axis",
        "the cantilever's axis, root to tip",
        "axis = [1.0, 0.0]",
    ),
    f(
        "solid[].initial_velocity.direction",
        "the direction of the initial velocity",
        "direction = [0.0, 1.0]",
    ),
    f(
        "solid[].initial_velocity.length_m",
        "the cantilever's free length in metres",
        "length_m = 0.2",
    ),
    f(
        "solid[].initial_velocity.tip_velocity_m_s",
        "the initial tip velocity in m/s",
        "tip_velocity_m_s = 0.57",
    ),
];

impl FieldHelp {
    /// The TOML type the field takes, for "wrong type" messages.
    pub(super) fn ty(&self) -> &'static str {
        let value = self.example.split_once('=').map_or("", |(_, v)| v.trim());
        match self.path {
            "dimension" | "tank.layers" | "physics.density_filter_every" => "an integer",
            "fluid_block" | "obstacle" | "probe" | "body" | "solid" | "inlet" | "outlet"
            | "friction" => "an array of tables",
            "body[].layers" => "an integer",
            _ if self.example.starts_with('[') => "a table",
            _ if value.starts_with('"') => "a string",
            _ if value.starts_with('[') => "an array of numbers",
            _ if value == "true" || value == "false" => "a boolean",
            _ => "a number",
        }
    }
}

/// The help for a concrete path such as `probe[3].name`.
pub(super) fn help(path: &str) -> Option<&'static FieldHelp> {
    let mut generic = String::with_capacity(path.len());
    let mut in_index = false;
    for c in path.chars() {
        match c {
            '[' => {
                in_index = true;
                generic.push('[');
            }
            ']' => {
                in_index = false;
                generic.push(']');
            }
            _ if in_index => {}
            _ => generic.push(c),
        }
    }
    // The fields of a motion table are the same under the tank and under every body.
    let shared = generic
        .find("motion.")
        .map_or("", |i| &generic[i..])
        .to_string();
    FIELDS
        .iter()
        .find(|h| h.path == generic)
        .or_else(|| FIELDS.iter().find(|h| h.path == shared))
}

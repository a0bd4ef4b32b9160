//! Field-by-field checks of the deserialised case: finite numbers, ranges, vector lengths,
//! options that go together, defaults. Produces a [`Case`] in SI with 3-component vectors.
//! Geometric checks that need several fields at once live in `build.rs` and `domain.rs`.

use crate::scenario::CellEdge;
use crate::scenario::{
    DeltaSphForm, DensityFilter, FrictionPair, GhostCorrection, KernelKind, OutputBoundary,
    OverlapExchange, Probe, RepulsiveForm, TimeControl, Viscosity, DEFAULT_FRICTION_SLIP,
};

use super::check::{
    aabb, initial_velocity, number, treatment, vector, Aabb, Bound, Treatment, MAX_NAME_BYTES,
};
use super::error::{num, CaseError};
use super::locate::Ctx;
use super::probes::Checked;
use super::schema::{
    CellName, DeltaSphFormName, DensityFilterName, GhostCorrectionName, KernelName,
    OutputBoundaryName, OverlapExchangeName, RawCase, RawPhysics, RepulsiveFormName, ViscosityName,
    WallName,
};

#[derive(Debug, Clone, Copy)]
pub(super) enum Sound {
    Speed(f64),
    Coef(f64),
}

#[derive(Debug, Clone)]
pub(super) struct Tank {
    pub inner: Aabb,
    pub layers: u32,
    pub open_top: bool,
    pub wall: Treatment,
    /// A prescribed motion (the tank and its obstacles move together); `None`: fixed.
    pub motion: Option<crate::scenario::Motion>,
}

/// `[walls]`, with the defaults that need the built particles left as `None`, and the
/// `[[friction]]` pairs.
#[derive(Debug, Clone)]
pub(super) struct WallSettings {
    pub ghost_correction: GhostCorrection,
    /// Lennard-Jones strength D [m²/s²]; default 5 |g| H.
    pub repulsive_d: Option<f64>,
    /// Lennard-Jones cut-off r0 [m]; default dx.
    pub repulsive_r0: Option<f64>,
    pub repulsive_form: RepulsiveForm,
    /// Monaghan & Kajtar K [m²/s²]; default |g| H.
    pub repulsive_k: Option<f64>,
    pub repulsive_beta: f64,
    /// Coulomb μ of contact (0: frictionless) and its regularisation speed ε [m/s].
    pub friction: f64,
    pub friction_slip: f64,
    pub friction_pairs: Vec<FrictionPair>,
}

#[derive(Debug, Clone, Copy)]
pub(super) struct Block {
    pub bx: Aabb,
    pub vel: [f64; 3],
}

/// A case whose every field is individually valid.
#[derive(Debug)]
pub(super) struct Case {
    pub name: String,
    pub dim: usize,
    pub dx: f64,
    pub h_over_dx: f64,
    pub kernel: KernelKind,
    pub cell: Option<CellEdge>,
    /// `particles.id_low_bits`: wide ids forced, with this many bits in the code word.
    pub id_low_bits: Option<u32>,
    pub rho0: f64,
    pub gravity: [f64; 3],
    pub sound: Sound,
    pub gamma: f64,
    pub viscosity: Viscosity,
    pub delta_sph: f64,
    pub delta_sph_form: DeltaSphForm,
    pub density_filter: DensityFilter,
    pub energy: bool,
    pub time: TimeControl,
    pub tank: Option<Tank>,
    /// `[terrain]`: the ground from an elevation grid.
    pub terrain: Option<super::terrain::Terrain>,
    /// `[[buildings]]`: buildings from their footprints.
    pub buildings: Vec<super::buildings::Buildings>,
    pub blocks: Vec<Block>,
    /// `[[fill]]`: water from a seed up to a level.
    pub fills: Vec<super::fill::Fill>,
    /// `[[surface]]`: walls from mesh files.
    pub surfaces: Vec<super::surface::SurfaceWall>,
    pub obstacles: Vec<Aabb>,
    /// The wall treatment of each obstacle (never `Mirror`).
    pub obstacle_walls: Vec<Treatment>,
    /// Each obstacle's place in the file, `obstacle[i]`, for messages (an obstacle with
    /// `enabled = false` is left out, and the ones after it keep their index).
    pub obstacle_paths: Vec<String>,
    pub domain: Option<Aabb>,
    pub walls: WallSettings,
    pub probes: Vec<Probe>,
    /// Each probe's face normal where it is given on a face (`face_m`): its point lies on the
    /// face until the particles are built ([`super::probes::place_on_faces`]).
    pub face_normals: Vec<Option<[f64; 3]>>,
    /// Each probe's place in the file, `probe[i]`, for messages (a probe with `enabled =
    /// false` is left out, and the ones after it keep their index).
    pub probe_paths: Vec<String>,
    /// `kind = "point"` probes; their particles are chosen once the particles are built.
    pub points: Vec<super::probes::PointSpec>,
    pub bodies: Vec<super::bodies::BodySpec>,
    /// Elastic solids, alone or in fluid (held by a fixed tank and obstacles).
    pub solids: Vec<super::solids::SolidSpec>,
    pub inlets: Vec<super::open_boundaries::InletSpec>,
    pub outlets: Vec<crate::scenario::Outlet>,
    /// `[maps]`: flood maps, their ground found once the particles are built.
    pub maps: Option<super::maps::MapsSpec>,
}

impl Case {
    /// Whether the tank moves (`[tank.motion]`): its walls and obstacles are then the body
    /// "tank", body 0.
    pub fn tank_moves(&self) -> bool {
        self.tank.as_ref().is_some_and(|t| t.motion.is_some())
    }
}

/// The checked case, from the deserialised one: field by field, in the order of the file's
/// tables (an error is that of the first field found wrong): dimension, name, `[particles]`,
/// `[physics]`, `[time]`, the geometry (`[tank]`, `[[solid]]`, `[[fluid_block]]`,
/// `[[obstacle]]`, `[walls]`, `[domain]`), then bodies, inlets, outlets, friction pairs and
/// probes.
pub(super) fn validate(
    ctx: &Ctx<'_>,
    raw: &RawCase,
    default_name: &str,
    case_dir: &std::path::Path,
) -> Result<Case, CaseError> {
    let dim = dimension(ctx, raw)?;
    // Before the physics: without fluid or solids nothing else of the case matters.
    let no_fill = raw.fill.iter().all(|f| f.enabled == Some(false));
    let no_fluid = raw.fluid_block.is_empty() && no_fill && raw.inlet.is_empty();
    if no_fluid && raw.solid.is_empty() {
        return Err(ctx.err(
            "fluid_block",
            None,
            "no fluid: at least one [[fluid_block]] (or [[fill]] left enabled, [[inlet]] or \
             [[solid]]) is required",
            "add a [[fluid_block]] table with min_m and max_m",
        ));
    }
    let name = case_name(ctx, raw, default_name)?;
    let (dx, h_over_dx, kernel, cell) = particles(ctx, raw)?;
    let id_low_bits = id_low_bits(ctx, raw)?;
    let physics = physics(ctx, raw, dim)?;
    let time = time(ctx, raw)?;

    // Geometry.
    let tank = tank(ctx, raw, dim, case_dir)?;
    let terrain = super::terrain::terrain(ctx, raw.terrain.as_ref(), dim, h_over_dx, case_dir)?;
    if terrain.is_some() && tank.as_ref().is_some_and(|t| t.motion.is_some()) {
        return Err(ctx.err(
            "terrain",
            None,
            "the ground does not move, but the tank has a [tank.motion]",
            "remove [tank.motion], or draw the moving ground as [[obstacle]] boxes",
        ));
    }
    let solids = solids(ctx, raw, dim)?;
    let origin = terrain.as_ref().map_or([0.0; 3], |t| t.origin);
    let buildings =
        super::buildings::validate(ctx, &raw.buildings, (dim, h_over_dx), case_dir, origin)?;
    if !buildings.is_empty() && terrain.is_none() && tank.is_none() {
        return Err(ctx.err(
            "buildings[0]",
            None,
            "buildings stand on the ground: a [terrain], or a tank's floor",
            "add a [terrain] (or a [tank]) under the buildings",
        ));
    }
    let blocks = blocks(ctx, raw, dim)?;
    let fills = super::fill::validate(ctx, &raw.fill, (dim, dx), case_dir)?;
    let surfaces = super::surface::validate(ctx, &raw.surface, (dim, dx, h_over_dx), case_dir)?;
    let (obstacles, obstacle_walls, obstacle_paths) = obstacles(ctx, raw, dim)?;
    let mut walls = wall_settings(ctx, raw)?;
    let domain = match &raw.domain {
        Some(d) => Some(aabb(ctx, "domain", &d.min_m, &d.max_m, dim, "the domain")?),
        None => None,
    };
    check_probe_names(ctx, raw)?;
    let bodies = super::bodies::validate(ctx, &raw.body, dim, case_dir)?;
    let inlets = super::open_boundaries::validate(ctx, &raw.inlet, (dim, time.end_s), case_dir)?;
    let outlets = super::open_boundaries::validate_outlets(ctx, &raw.outlet, dim)?;
    let maps = super::maps::validate(ctx, raw.maps.as_ref(), dim, dx)?;
    let tank_moves = tank.as_ref().is_some_and(|t| t.motion.is_some());
    walls.friction_pairs =
        super::friction::pairs(ctx, &raw.friction, &bodies, &solids, tank_moves)?;
    let ((probes, face_normals, probe_paths), points) = probes(ctx, raw, dim, tank_moves, &bodies)?;
    let CheckedPhysics {
        rho0,
        gravity,
        sound,
        gamma,
        viscosity,
        delta_sph,
        delta_sph_form,
        density_filter,
        energy,
    } = physics;
    Ok(Case {
        name,
        dim,
        dx,
        h_over_dx,
        kernel,
        cell,
        id_low_bits,
        rho0,
        gravity,
        sound,
        gamma,
        viscosity,
        delta_sph,
        delta_sph_form,
        density_filter,
        energy,
        time,
        tank,
        terrain,
        buildings,
        blocks,
        fills,
        surfaces,
        obstacles,
        obstacle_walls,
        obstacle_paths,
        domain,
        walls,
        probes,
        face_normals,
        probe_paths,
        points,
        bodies,
        solids,
        inlets,
        outlets,
        maps,
    })
}

/// `dimension`: 2 or 3.
fn dimension(ctx: &Ctx<'_>, raw: &RawCase) -> Result<usize, CaseError> {
    Ok(match raw.dimension {
        2 => 2,
        3 => 3,
        d => {
            return Err(ctx.err(
                "dimension",
                Some(d.to_string()),
                "must be 2 or 3",
                "write dimension = 2 (vectors [x, y], y up) or dimension = 3 ([x, y, z], z up)",
            ))
        }
    })
}

/// `name`, or `default_name` without one.
fn case_name(ctx: &Ctx<'_>, raw: &RawCase, default_name: &str) -> Result<String, CaseError> {
    Ok(match &raw.name {
        // "." and ".." name the output folder's parent or itself (`out/..` is the working
        // directory, issue 64).
        Some(n)
            if n.trim().is_empty()
                || n.trim() == "."
                || n.trim() == ".."
                || n.len() > MAX_NAME_BYTES
                || n.chars().any(|c| c.is_control() || c == '/' || c == '\\') =>
        {
            return Err(ctx.err(
                "name",
                Some(format!("{n:?}")),
                format!(
                    "must be a non-empty name of at most {MAX_NAME_BYTES} bytes, not \".\" or \
                     \"..\", without slashes or control characters (it names the output folder)"
                ),
                "use letters, digits, `_` and `-`, e.g. name = \"dam_break_2d\"",
            ))
        }
        Some(n) => n.clone(),
        None => default_name.to_string(),
    })
}

/// `[particles]`: the spacing dx, h / dx, the kernel and the grid's cell edge.
fn particles(
    ctx: &Ctx<'_>,
    raw: &RawCase,
) -> Result<(f64, f64, KernelKind, Option<CellEdge>), CaseError> {
    let p = &raw.particles;
    let dx = number(
        ctx,
        "particles.dx_m",
        p.dx_m,
        Bound::Positive,
        "the particle spacing in metres",
        "give a positive spacing such as 0.01",
    )?;
    let h_over_dx = number(
        ctx,
        "particles.h_over_dx",
        p.h_over_dx.unwrap_or(1.3),
        Bound::Closed(1.0, 3.0),
        "h = h_over_dx * dx; the kernel support is 2h",
        "use a value between 1.0 and 3.0; 1.3 is usual for wendland_c2",
    )?;
    let kernel = match p.kernel.unwrap_or(KernelName::WendlandC2) {
        KernelName::CubicSpline => KernelKind::CubicSpline,
        KernelName::WendlandC2 => KernelKind::WendlandC2,
    };
    let cell = p.cell.map(|c| match c {
        CellName::TwoH => CellEdge::Support,
        CellName::H => CellEdge::Half,
    });
    Ok((dx, h_over_dx, kernel, cell))
}

/// `particles.id_low_bits`, within 1 to 28 (`crate::layout::IdSplit`).
fn id_low_bits(ctx: &Ctx<'_>, raw: &RawCase) -> Result<Option<u32>, CaseError> {
    match raw.particles.id_low_bits {
        Some(bits) if !(1..=crate::layout::KIND_SHIFT).contains(&bits) => Err(ctx.err(
            "particles.id_low_bits",
            Some(bits.to_string()),
            "must be between 1 and 28 (the bits of a particle id its code word keeps; the rest \
             go in a second word)",
            "leave it out (runs of 2^28 particles or more take wide ids with 28 by themselves), \
             or give a small number such as 4 to check the wide ids on a small case",
        )),
        bits => Ok(bits),
    }
}

/// The checked `[physics]` table.
struct CheckedPhysics {
    rho0: f64,
    gravity: [f64; 3],
    sound: Sound,
    gamma: f64,
    viscosity: Viscosity,
    delta_sph: f64,
    delta_sph_form: DeltaSphForm,
    density_filter: DensityFilter,
    energy: bool,
}

/// `[physics]`.
fn physics(ctx: &Ctx<'_>, raw: &RawCase, dim: usize) -> Result<CheckedPhysics, CaseError> {
    let ph = &raw.physics;
    let rho0 = number(
        ctx,
        "physics.rho0_kg_m3",
        ph.rho0_kg_m3.unwrap_or(1000.0),
        Bound::Positive,
        "the reference density in kg/m³",
        "use e.g. 1000.0 for water",
    )?;
    let gravity = gravity(ctx, ph, dim)?;
    let sound = sound(ctx, raw)?;
    let gamma = number(
        ctx,
        "physics.gamma",
        ph.gamma.unwrap_or(7.0),
        Bound::Closed(1.0, 10.0),
        "the Tait exponent",
        "use 7.0 for water",
    )?;
    let viscosity = viscosity(ctx, ph)?;
    let delta_sph = number(
        ctx,
        "physics.delta_sph",
        ph.delta_sph.unwrap_or(0.1),
        Bound::Closed(0.0, 1.0),
        "the delta-SPH density diffusion coefficient; 0 disables it",
        "use 0.1, or 0 to disable",
    )?;
    let delta_sph_form = delta_sph_form(ctx, ph, delta_sph)?;
    let density_filter = density_filter(ctx, ph)?;
    Ok(CheckedPhysics {
        rho0,
        gravity,
        sound,
        gamma,
        viscosity,
        delta_sph,
        delta_sph_form,
        density_filter,
        energy: ph.energy.unwrap_or(false),
    })
}

/// `physics.gravity_m_s2` (default 9.81 m/s² down).
fn gravity(ctx: &Ctx<'_>, ph: &RawPhysics, dim: usize) -> Result<[f64; 3], CaseError> {
    Ok(match &ph.gravity_m_s2 {
        Some(g) => {
            let v = vector(ctx, "physics.gravity_m_s2", g, dim, "gravity in m/s²")?;
            // Finite components can still have an infinite magnitude |g|.
            if !v.iter().map(|c| c * c).sum::<f64>().sqrt().is_finite() {
                return Err(ctx.err(
                    "physics.gravity_m_s2",
                    Some(format!("{g:?}")),
                    "has a magnitude too large to compute with (gravity in m/s²)",
                    "give the gravity in m/s², e.g. [0.0, -9.81] in 2D",
                ));
            }
            v
        }
        None => {
            let mut g = [0.0; 3];
            g[dim - 1] = -9.81;
            g
        }
    })
}

/// The speed of sound: `physics.sound_speed_m_s` or `physics.sound_speed_coef`, exactly one.
fn sound(ctx: &Ctx<'_>, raw: &RawCase) -> Result<Sound, CaseError> {
    let ph = &raw.physics;
    Ok(match (ph.sound_speed_m_s, ph.sound_speed_coef) {
        (Some(_), Some(_)) => {
            return Err(ctx.err(
                "physics.sound_speed_coef",
                None,
                "physics.sound_speed_m_s and physics.sound_speed_coef are both given",
                "keep only one of them",
            ))
        }
        (Some(c), None) => Sound::Speed(number(
            ctx,
            "physics.sound_speed_m_s",
            c,
            Bound::Positive,
            "the numerical speed of sound c0 in m/s",
            "give a positive speed, about 10 times the largest expected flow speed",
        )?),
        (None, Some(k)) => Sound::Coef(number(
            ctx,
            "physics.sound_speed_coef",
            k,
            Bound::Positive,
            "c0 = coef * sqrt(|g| * H)",
            "use e.g. 10.0",
        )?),
        // A solid-only case has no fluid to give a sound speed to (unused; see
        // build_solid_case in build.rs).
        (None, None)
            if raw.fluid_block.is_empty()
                && raw.fill.iter().all(|f| f.enabled == Some(false))
                && !raw.solid.is_empty() =>
        {
            Sound::Speed(1.0)
        }
        (None, None) => {
            return Err(ctx.err(
                "physics.sound_speed_coef",
                None,
                "the speed of sound is not given: [physics] needs exactly one of sound_speed_m_s \
             (c0 in m/s) or sound_speed_coef (c0 = coef * sqrt(|g| * H))",
                "add sound_speed_coef = 10.0 to [physics]",
            ))
        }
    })
}

/// `physics.viscosity` with its coefficient (`alpha` or `nu_m2_s`, not the other's).
fn viscosity(ctx: &Ctx<'_>, ph: &RawPhysics) -> Result<Viscosity, CaseError> {
    Ok(match ph.viscosity.unwrap_or(ViscosityName::Artificial) {
        ViscosityName::Artificial => {
            if let Some(nu) = ph.nu_m2_s {
                return Err(ctx.err(
                    "physics.nu_m2_s",
                    Some(num(nu)),
                    "is only used with viscosity = \"laminar\", but the viscosity is \
                 \"artificial\"",
                    "remove nu_m2_s, or set viscosity = \"laminar\"",
                ));
            }
            let alpha = number(
                ctx,
                "physics.alpha",
                ph.alpha.unwrap_or(0.01),
                Bound::Closed(0.0, 1.0),
                "the artificial viscosity coefficient",
                "use a small value such as 0.01 to 0.05",
            )?;
            Viscosity::Artificial { alpha }
        }
        ViscosityName::Laminar => {
            if let Some(a) = ph.alpha {
                return Err(ctx.err(
                    "physics.alpha",
                    Some(num(a)),
                    "is only used with viscosity = \"artificial\", but the viscosity is \
                 \"laminar\"",
                    "remove alpha, or set viscosity = \"artificial\"",
                ));
            }
            let Some(nu) = ph.nu_m2_s else {
                return Err(ctx.err(
                    "physics.nu_m2_s",
                    None,
                    "is required with viscosity = \"laminar\"",
                    "add nu_m2_s = 1.0e-6 (water) to [physics]",
                ));
            };
            let nu = number(
                ctx,
                "physics.nu_m2_s",
                nu,
                Bound::Positive,
                "the kinematic viscosity in m²/s",
                "use e.g. 1.0e-6 for water",
            )?;
            Viscosity::Laminar { nu }
        }
    })
}

/// `[time]`.
fn time(ctx: &Ctx<'_>, raw: &RawCase) -> Result<TimeControl, CaseError> {
    let t = &raw.time;
    let end_s = number(
        ctx,
        "time.end_s",
        t.end_s,
        Bound::Positive,
        "the end time in seconds",
        "give a positive duration such as 1.0",
    )?;
    let output_every_s = number(
        ctx,
        "time.output_every_s",
        t.output_every_s,
        Bound::Positive,
        "the interval between particle outputs in seconds",
        "give a positive interval such as 0.02",
    )?;
    let probe_every_s = number(
        ctx,
        "time.probe_every_s",
        t.probe_every_s.unwrap_or(output_every_s),
        Bound::OpenClosed(0.0, output_every_s),
        "the probe sampling interval in seconds, at most time.output_every_s",
        "give a positive interval no larger than output_every_s",
    )?;
    let cfl = number(
        ctx,
        "time.cfl",
        t.cfl.unwrap_or(0.2),
        Bound::OpenClosed(0.0, 1.0),
        "the Courant number",
        "use e.g. 0.2",
    )?;
    let density_variation_warn = number(
        ctx,
        "time.density_variation_warn",
        t.density_variation_warn
            .unwrap_or(TimeControl::DENSITY_VARIATION_WARN),
        Bound::OpenClosed(0.0, 1.0),
        "the fluid's density variation |ρ/ρ0 − 1| beyond which the run warns",
        "use e.g. 0.03 (3 %)",
    )?;
    let density_variation_stop = number(
        ctx,
        "time.density_variation_stop",
        t.density_variation_stop
            .unwrap_or(TimeControl::DENSITY_VARIATION_STOP.max(2.0 * density_variation_warn)),
        Bound::OpenClosed(density_variation_warn, 10.0),
        "the fluid's density variation |ρ/ρ0 − 1| beyond which the run stops, above \
         time.density_variation_warn",
        &format!(
            "give a value above density_variation_warn = {density_variation_warn}, e.g. {}",
            2.0 * density_variation_warn
        ),
    )?;
    Ok(TimeControl {
        end_s,
        output_every_s,
        probe_every_s,
        cfl,
        density_variation_warn,
        density_variation_stop,
        overlap_exchange: match t.overlap_exchange {
            None | Some(OverlapExchangeName::Auto) => OverlapExchange::Auto,
            Some(OverlapExchangeName::Always) => OverlapExchange::Always,
            Some(OverlapExchangeName::Never) => OverlapExchange::Never,
        },
        output_boundary: match t.output_boundary {
            None | Some(OutputBoundaryName::Every) => OutputBoundary::Every,
            Some(OutputBoundaryName::First) => OutputBoundary::First,
        },
    })
}

/// `[tank]` with its motion.
fn tank(
    ctx: &Ctx<'_>,
    raw: &RawCase,
    dim: usize,
    case_dir: &std::path::Path,
) -> Result<Option<Tank>, CaseError> {
    Ok(match &raw.tank {
        None => None,
        Some(tk) => {
            let inner = aabb(ctx, "tank", &tk.min_m, &tk.max_m, dim, "the tank")?;
            let layers = tk.layers.unwrap_or(3);
            if !(1..=8).contains(&layers) {
                return Err(ctx.err(
                    "tank.layers",
                    Some(layers.to_string()),
                    "must be between 1 and 8 (the number of wall-particle layers)",
                    "use 3, or enough layers to cover the kernel support 2h",
                ));
            }
            let wall = treatment(ctx, "tank", tk.wall, tk.slip)?;
            let motion = match &tk.motion {
                None => None,
                Some(m) => {
                    if let Treatment::Mirror { .. } = wall {
                        return Err(ctx.err(
                            "tank.motion",
                            None,
                            "a moving tank needs wall particles that move with it; mirror \
                         walls are fixed planes",
                            "set tank.wall = \"fixed_ghost\" (or \"dynamic\", \"repulsive\"), \
                         or remove [tank.motion]",
                        ));
                    }
                    Some(super::bodies::motion(
                        ctx,
                        "tank.motion",
                        m,
                        dim,
                        false,
                        case_dir,
                    )?)
                }
            };
            Some(Tank {
                inner,
                layers: layers as u32,
                open_top: tk.open_top.unwrap_or(true),
                wall,
                motion,
            })
        }
    })
}

/// `[[solid]]`, and what a case with solids cannot have.
fn solids(
    ctx: &Ctx<'_>,
    raw: &RawCase,
    dim: usize,
) -> Result<Vec<super::solids::SolidSpec>, CaseError> {
    let solids = raw
        .solid
        .iter()
        .enumerate()
        .map(|(i, s)| super::solids::validate_solid(ctx, i, s, dim))
        .collect::<Result<Vec<_>, _>>()?;
    if !solids.is_empty() {
        // Solids take the fluid's load and contact with walls, bodies and each other
        // (interaction.wgsl); what they cannot yet be combined with:
        let other = [
            (
                "tank.wall",
                raw.tank
                    .as_ref()
                    .is_some_and(|t| t.wall == Some(WallName::Mirror)),
                "= \"mirror\" (mirror planes have no particles for a solid to touch, and \
                 their images carry no solid)",
            ),
            (
                "tank.motion",
                raw.tank.as_ref().is_some_and(|t| t.motion.is_some()),
                "yet (clamped solid particles stay where they are)",
            ),
            (
                "physics.energy",
                raw.physics.energy == Some(true),
                "yet (the energy equation has no solid terms)",
            ),
        ];
        if let Some((what, _, why)) = other.iter().find(|(_, present, _)| *present) {
            return Err(ctx.err(
                what,
                None,
                format!("a case with [[solid]] cannot have {what} {why}"),
                format!("remove {what}, or the [[solid]] tables"),
            ));
        }
    }
    Ok(solids)
}

/// `[[fluid_block]]`.
fn blocks(ctx: &Ctx<'_>, raw: &RawCase, dim: usize) -> Result<Vec<Block>, CaseError> {
    let mut blocks = Vec::with_capacity(raw.fluid_block.len());
    for (i, b) in raw.fluid_block.iter().enumerate() {
        let path = format!("fluid_block[{i}]");
        let bx = aabb(ctx, &path, &b.min_m, &b.max_m, dim, "the fluid block")?;
        let vel = initial_velocity(ctx, &path, &b.velocity_m_s, dim)?;
        blocks.push(Block { bx, vel });
    }
    Ok(blocks)
}

/// The enabled obstacles' boxes, wall treatments and paths in the file.
type Obstacles = (Vec<Aabb>, Vec<Treatment>, Vec<String>);

/// `[[obstacle]]`: each enabled box, its wall treatment (not mirror) and its path.
fn obstacles(ctx: &Ctx<'_>, raw: &RawCase, dim: usize) -> Result<Obstacles, CaseError> {
    let mut obstacles = Vec::with_capacity(raw.obstacle.len());
    let mut obstacle_walls = Vec::with_capacity(raw.obstacle.len());
    let mut paths = Vec::with_capacity(raw.obstacle.len());
    for (i, o) in raw.obstacle.iter().enumerate() {
        if o.enabled == Some(false) {
            continue;
        }
        let path = format!("obstacle[{i}]");
        obstacles.push(aabb(ctx, &path, &o.min_m, &o.max_m, dim, "the obstacle")?);
        if o.wall == Some(WallName::Mirror) {
            return Err(ctx.err(
                &format!("{path}.wall"),
                Some("\"mirror\"".into()),
                "mirror ghosts are for the tank's straight faces; use fixed_ghost for obstacles",
                "use wall = \"fixed_ghost\" (or \"dynamic\" or \"repulsive\")",
            ));
        }
        obstacle_walls.push(treatment(ctx, &path, o.wall, o.slip)?);
        paths.push(path);
    }
    Ok((obstacles, obstacle_walls, paths))
}

/// `[walls]` (the friction pairs are added later, once the bodies are known).
fn wall_settings(ctx: &Ctx<'_>, raw: &RawCase) -> Result<WallSettings, CaseError> {
    Ok(match &raw.walls {
        None => WallSettings {
            ghost_correction: GhostCorrection::Mls,
            repulsive_d: None,
            repulsive_r0: None,
            repulsive_form: RepulsiveForm::LennardJones,
            repulsive_k: None,
            repulsive_beta: 1.0,
            friction: 0.0,
            friction_slip: DEFAULT_FRICTION_SLIP,
            friction_pairs: Vec::new(),
        },
        Some(w) => WallSettings {
            ghost_correction: match w.ghost_correction.unwrap_or(GhostCorrectionName::Mls) {
                GhostCorrectionName::Shepard => GhostCorrection::Shepard,
                GhostCorrectionName::Mls => GhostCorrection::Mls,
            },
            repulsive_d: w
                .repulsive_d_m2_s2
                .map(|d| {
                    number(
                        ctx,
                        "walls.repulsive_d_m2_s2",
                        d,
                        Bound::Positive,
                        "the Lennard-Jones strength D of repulsive walls in m²/s²",
                        "use about 5 |g| H, e.g. 24.5 for 0.5 m of water, or remove it for that \
                     default",
                    )
                })
                .transpose()?,
            repulsive_r0: w
                .repulsive_r0_m
                .map(|r| {
                    number(
                        ctx,
                        "walls.repulsive_r0_m",
                        r,
                        Bound::Positive,
                        "the Lennard-Jones cut-off r0 of repulsive walls in metres",
                        "use the particle spacing dx_m, or remove it for that default",
                    )
                })
                .transpose()?,
            repulsive_form: match w.repulsive_form.unwrap_or(RepulsiveFormName::LennardJones) {
                RepulsiveFormName::LennardJones => RepulsiveForm::LennardJones,
                RepulsiveFormName::MonaghanKajtar => RepulsiveForm::MonaghanKajtar,
            },
            repulsive_k: w
                .repulsive_k_m2_s2
                .map(|k| {
                    number(
                        ctx,
                        "walls.repulsive_k_m2_s2",
                        k,
                        Bound::Positive,
                        "the Monaghan & Kajtar strength K of repulsive walls in m²/s²",
                        "use about |g| H, e.g. 4.9 for 0.5 m of water, or remove it for that \
                     default",
                    )
                })
                .transpose()?,
            repulsive_beta: number(
                ctx,
                "walls.repulsive_beta",
                w.repulsive_beta.unwrap_or(1.0),
                Bound::Closed(0.1, 10.0),
                "the ratio of fluid to boundary-particle spacing",
                "use 1 for boundary particles on the fluid lattice (as wgsph builds them)",
            )?,
            friction: number(
                ctx,
                "walls.friction_coefficient",
                w.friction_coefficient.unwrap_or(0.0),
                Bound::Closed(0.0, 10.0),
                "the Coulomb friction coefficient μ of contact",
                "use 0 (frictionless) to about 1, e.g. 0.3",
            )?,
            friction_slip: number(
                ctx,
                "walls.friction_slip_m_s",
                w.friction_slip_m_s.unwrap_or(DEFAULT_FRICTION_SLIP),
                Bound::Positive,
                "the regularisation speed of contact friction in m/s",
                "use a speed well below the sliding speeds of interest, e.g. 0.001",
            )?,
            friction_pairs: Vec::new(),
        },
    })
}

/// Every probe's name differs from the others' (names become file names).
fn check_probe_names(ctx: &Ctx<'_>, raw: &RawCase) -> Result<(), CaseError> {
    if let Some((i, j)) = (0..raw.probe.len())
        .flat_map(|i| (0..i).map(move |j| (i, j)))
        .find(|&(i, j)| raw.probe[i].name == raw.probe[j].name)
    {
        return Err(ctx.err(
            &format!("probe[{i}].name"),
            Some(format!("{:?}", raw.probe[i].name)),
            format!("probe[{j}] already has this name (names become file names)"),
            "give every probe a different name",
        ));
    }
    Ok(())
}

/// The sampled probes and their face normals.
type SampledProbes = (Vec<Probe>, Vec<Option<[f64; 3]>>, Vec<String>);

/// `[[probe]]`: the enabled sampled probes (with the body each is attached to, the normal of
/// the face each given by `face_m` lies on, and each one's path in the file) and the points.
fn probes(
    ctx: &Ctx<'_>,
    raw: &RawCase,
    dim: usize,
    tank_moves: bool,
    bodies: &[super::bodies::BodySpec],
) -> Result<(SampledProbes, Vec<super::probes::PointSpec>), CaseError> {
    let (mut probes, mut normals, mut paths): SampledProbes = (Vec::new(), Vec::new(), Vec::new());
    let mut points = Vec::new();
    for (i, p) in raw.probe.iter().enumerate() {
        if p.enabled == Some(false) {
            continue;
        }
        match super::probes::probe(ctx, i, p, dim)? {
            Checked::Sampled(mut probe, normal) => {
                probe.body = match &p.body {
                    None => None,
                    Some(name) => Some(attached_body(ctx, i, name, tank_moves, bodies)?),
                };
                probes.push(probe);
                normals.push(normal);
                paths.push(format!("probe[{i}]"));
            }
            Checked::Point(spec) => points.push(spec),
        }
    }
    Ok(((probes, normals, paths), points))
}

/// The index in the scenario's bodies (a moving tank first, then `[[body]]` in order) of the
/// body `probe[i].body` names.
fn attached_body(
    ctx: &Ctx<'_>,
    i: usize,
    name: &str,
    tank_moves: bool,
    bodies: &[super::bodies::BodySpec],
) -> Result<usize, CaseError> {
    if name == "tank" && tank_moves {
        return Ok(0);
    }
    if let Some(k) = bodies.iter().position(|b| b.name == name) {
        return Ok(k + tank_moves as usize);
    }
    let mut names: Vec<String> = bodies.iter().map(|b| format!("\"{}\"", b.name)).collect();
    if tank_moves {
        names.insert(0, "\"tank\"".into());
    }
    Err(ctx.err(
        &format!("probe[{i}].body"),
        Some(format!("{name:?}")),
        if name == "tank" {
            "the tank does not move (no [tank.motion]), so nothing to attach to".to_string()
        } else {
            "no body has this name".to_string()
        },
        if names.is_empty() {
            "remove body: the case has no moving bodies".to_string()
        } else {
            format!("use one of {}, or remove body", names.join(", "))
        },
    ))
}

/// `physics.delta_sph_form` (default Fourtakas et al. 2019; only with δ-SPH on).
fn delta_sph_form(
    ctx: &Ctx<'_>,
    ph: &RawPhysics,
    delta_sph: f64,
) -> Result<DeltaSphForm, CaseError> {
    let Some(name) = ph.delta_sph_form else {
        return Ok(DeltaSphForm::default());
    };
    if delta_sph == 0.0 {
        return Err(ctx.err(
            "physics.delta_sph_form",
            Some(
                match name {
                    DeltaSphFormName::Fourtakas => "\"fourtakas\"",
                    DeltaSphFormName::MolteniColagrossi => "\"molteni_colagrossi\"",
                }
                .to_string(),
            ),
            "is only used with delta-SPH on, but delta_sph = 0",
            "remove delta_sph_form, or give delta_sph > 0 (e.g. 0.1)",
        ));
    }
    Ok(match name {
        DeltaSphFormName::Fourtakas => DeltaSphForm::Fourtakas,
        DeltaSphFormName::MolteniColagrossi => DeltaSphForm::MolteniColagrossi,
    })
}

/// `physics.density_filter` with `physics.density_filter_every` (default 30, only with a filter).
fn density_filter(ctx: &Ctx<'_>, ph: &RawPhysics) -> Result<DensityFilter, CaseError> {
    let name = ph.density_filter.unwrap_or(DensityFilterName::None);
    if name == DensityFilterName::None {
        if let Some(n) = ph.density_filter_every {
            return Err(ctx.err(
                "physics.density_filter_every",
                Some(n.to_string()),
                "is only used with density_filter = \"shepard\" or \"mls\", but the filter is \
                 \"none\"",
                "remove density_filter_every, or set density_filter = \"shepard\" or \"mls\"",
            ));
        }
        return Ok(DensityFilter::None);
    }
    let every = ph.density_filter_every.unwrap_or(30);
    if !(1..=10_000).contains(&every) {
        return Err(ctx.err(
            "physics.density_filter_every",
            Some(every.to_string()),
            "must be between 1 and 10000 (the number of time steps between two density filters)",
            "use e.g. 30 (a filter every few tens of steps is usual)",
        ));
    }
    let every = every as u32;
    Ok(match name {
        DensityFilterName::Shepard => DensityFilter::Shepard { every },
        _ => DensityFilter::Mls { every },
    })
}

//! From a validated [`Case`] to the [`Scenario`]: geometric checks (blocks inside the tank,
//! nothing too thin; the size limits are in `limits.rs`, the domain and what must lie in it in
//! `domain.rs`), the particle lattices and the hydrostatic initial density, in the stages that
//! [`build`] lists.

use std::collections::HashSet;

use crate::scenario::{
    Body, Domain, ElasticMaterial, Inlet, Kind, MirrorPlane, Motion, Particle, Physics, Probe,
    ProbeKind, RepulsiveForm, Scenario, Solids, WallParams,
};

use super::bodies::Shape;
use super::buildings::{Raised, Site};
use super::check::{fmt_box, inside, point_in, point_inside, Aabb, Treatment, AXES, TOL};
use super::domain::domain;
use super::error::{num, CaseError};
use super::limits::{self, ParticleBudget};
use super::locate::Ctx;
use super::terrain::Ground;
use super::validate::{Case, Sound, WallSettings};
use crate::generate::lattice::{block_points, cells, range_points, Lattice, TankWall};

/// An obstacle's range of lattice indices: the first and the last, as floats.
type IndexRange = ([f64; 3], [f64; 3]);

/// The elastic solids placed: their materials and the solid of each particle.
type Placed = (Vec<ElasticMaterial>, Vec<u32>);

/// The scenario of `case`, built in stages, each a function below in this order (so an error
/// is that of the first stage that finds one):
///
/// 1. the parts on the particle lattice, checked ([`Geometry::of`]: tank, fluid blocks,
///    lattice, obstacles, inlets, the terrain's ground, the fills' water);
/// 2. the particle budget ([`particle_budget`]), before anything is allocated;
/// 3. the elastic solids' particles ([`elastic_solids`]);
/// 4. the domain ([`domain`]);
/// 5. the speed of sound and the hydrostatic start ([`Start::of`]);
/// 6. the particles: fluid ([`fluid_particles`]), inlets, walls ([`wall_particles`], and
///    [`mirror_planes`]), elastic solids ([`place_solids`]), bodies ([`bodies`]), checked
///    together ([`check_particles`]);
/// 7. probes, warnings, physics and wall parameters ([`finish`]).
///
/// A case of elastic solids alone is built by [`build_solid_case`].
pub(super) fn build(
    ctx: &Ctx<'_>,
    case: Case,
    budget: &ParticleBudget,
) -> Result<Scenario, CaseError> {
    let solids_alone = case.tank.is_none()
        && case.obstacles.is_empty()
        && case.surfaces.is_empty()
        && case.bodies.is_empty();
    let no_fluid = case.blocks.is_empty() && case.fills.is_empty() && case.inlets.is_empty();
    if !case.solids.is_empty() && no_fluid && solids_alone {
        return build_solid_case(ctx, case, budget);
    }
    let mut geo = Geometry::of(ctx, &case, budget)?;
    let total = particle_budget(ctx, &case, &geo, budget)?;
    let wall = geo.tank_cells.map(|n| geo.tank_wall(&case, n));
    let elastic = elastic_solids(ctx, &case, &budget.less(total))?;
    let ground_box = geo.ground.map(|g| g.bounds);
    let water = geo.water(&case);
    let fills: Vec<Aabb> = geo.fills.iter().map(|f| f.water).collect();
    let placed: Vec<(String, Aabb)> = (ground_box.map(|b| ("terrain".to_string(), b)))
        .into_iter()
        .chain(geo.raised.bounds.map(|b| ("buildings".to_string(), b)))
        .chain(geo.surface_walls.iter().enumerate().map(|(i, w)| {
            let box_of = super::fill::water_box(w, case.dx, 3);
            (format!("surface[{i}]"), box_of)
        }))
        .collect();
    let domain = domain(ctx, &case, &geo.lat, wall.as_ref(), (&placed, &fills))?;
    let start = Start::of(ctx, &case, &water, elastic.as_ref())?;

    let mut particles = fluid_particles(ctx, &case, &geo, elastic.as_ref(), &start, total)?;
    // Inlets right after the fluid blocks (their particles become fluid).
    let inlets: Vec<_> = case
        .inlets
        .iter()
        .zip(std::mem::take(&mut geo.inlet_layouts))
        .map(|(s, l)| {
            let rho_at = |depth| start.rho_at(depth);
            super::open_boundaries::build(s, l, &geo.lat, case.gravity, &rho_at, &mut particles)
        })
        .collect();
    let rho = BoundaryRho {
        water: &water,
        start: &start,
        reach: geo.layers as f64 * case.dx + case.dx,
        v: case.dim - 1,
    };
    let tank_particles = wall_particles(
        &case,
        (&geo.lat, &geo.obstacle_ranges),
        wall.as_ref(),
        &rho,
        &mut particles,
    );
    if let (Some(t), Some(g)) = (&case.terrain, &geo.ground) {
        let under = (&geo.obstacle_ranges[..], &geo.raised);
        ground_particles(&case, t, g, (&geo.lat, under), &rho, &mut particles);
    }
    surface_particles(&case, &geo, &rho, &mut particles);
    particles.extend(
        geo.raised
            .points
            .iter()
            .map(|&(pos, t)| rho.particle(t, pos)),
    );
    let mirror_planes = mirror_planes(&case, &geo.lat, wall.as_ref());
    let solids = place_solids(ctx, case.dim, elastic, &domain, &mut particles)?;
    let bodies = bodies(ctx, &case, &rho, tank_particles, &mut particles)?;
    check_particles(ctx, &case, &start, &particles, solids.as_ref())?;

    let built = Built {
        domain,
        notes: (geo.raised.notes.iter())
            .chain(&geo.surface_notes)
            .chain(geo.fills.iter().flat_map(|f| &f.notes))
            .cloned()
            .collect(),
        particles,
        bodies,
        solids,
        inlets,
        mirror_planes,
    };
    finish(ctx, case, &geo.obstacle_ranges, geo.h, &start, built)
}

/// The parts of a case on the particle lattice, checked: what [`Geometry::of`] finds.
struct Geometry {
    /// Particle layers of the tank (3 without a tank).
    layers: i64,
    /// Particle layers of the tank wall: `layers` for dynamic and fixed-ghost walls, the one
    /// nearest the fluid for repulsive walls, none for mirror planes.
    wall_layers: i64,
    /// The tank's cells along each axis (`None`: no tank).
    tank_cells: Option<[f64; 3]>,
    /// Each fluid block's cells along each axis.
    block_cells: Vec<[f64; 3]>,
    /// The global lattice, continued by walls and obstacles.
    lat: Lattice,
    /// Each obstacle's range of lattice indices (first and last, as floats).
    obstacle_ranges: Vec<IndexRange>,
    /// The smoothing length.
    h: f64,
    /// Each inlet's layout on the lattice.
    inlet_layouts: Vec<super::open_boundaries::Layout>,
    /// The terrain's wall on the lattice.
    ground: Option<Ground>,
    /// The buildings' wall particles.
    raised: Raised,
    /// Each fill's water.
    fills: Vec<super::fill::Filled>,
    /// Each surface's wall particles, and what was noticed making them.
    surface_walls: Vec<Vec<[f64; 3]>>,
    surface_notes: Vec<String>,
}

impl Geometry {
    /// Checks the tank, the fluid blocks, the obstacles and the inlets against each other and
    /// the lattice, in this order.
    fn of(ctx: &Ctx<'_>, case: &Case, budget: &ParticleBudget) -> Result<Geometry, CaseError> {
        let layers = case.tank.as_ref().map_or(3, |t| t.layers as i64);
        let wall_layers = case.tank.as_ref().map_or(layers, |t| match t.wall {
            Treatment::Dynamic | Treatment::FixedGhost { .. } => layers,
            Treatment::Repulsive => 1,
            Treatment::Mirror { .. } => 0,
        });
        let tank_cells = tank_cells(ctx, case)?;
        let block_cells = block_cells(ctx, case)?;
        let lat = lattice(case);
        let obstacle_ranges = obstacle_ranges(ctx, case, &lat)?;
        let h = case.h_over_dx * case.dx;
        let inlet_layouts = inlet_layouts(ctx, case, &lat, h)?;
        let clip = holder(case);
        let ground = match &case.terrain {
            Some(t) => Some(Ground::of(ctx, t, &lat, clip.as_ref(), budget)?),
            None => None,
        };
        let raised = raise_buildings(ctx, case, &lat, ground.as_ref(), budget)?;
        let (surface_walls, surface_notes) =
            super::surface::walls(ctx, (&case.surfaces, h), &lat, clip.as_ref(), budget)?;
        let under = (&obstacle_ranges[..], &raised);
        let fills = fills(ctx, case, &lat, under, (ground.as_ref(), budget))?;
        Ok(Geometry {
            layers,
            wall_layers,
            tank_cells,
            block_cells,
            lat,
            obstacle_ranges,
            h,
            inlet_layouts,
            ground,
            raised,
            fills,
            surface_walls,
            surface_notes,
        })
    }

    /// The boxes of the water at the start: the fluid blocks' and the fills' (the tops of
    /// their highest particles' cells).
    fn water(&self, case: &Case) -> Vec<Aabb> {
        (case.blocks.iter().map(|b| b.bx))
            .chain(self.fills.iter().map(|f| f.water))
            .collect()
    }

    /// The particle layers of a tank of `n` cells along each axis.
    fn tank_wall(&self, case: &Case, n: [f64; 3]) -> TankWall {
        TankWall {
            n: n.map(|c| c.min(1e15) as i64),
            layers: self.wall_layers,
            open_top: case.tank.as_ref().is_none_or(|t| t.open_top),
            dim: case.dim,
        }
    }
}

/// The buildings raised on the lattice, inside the tank's inner box, the domain and the
/// terrain's columns, on the terrain or the tank's floor.
fn raise_buildings(
    ctx: &Ctx<'_>,
    case: &Case,
    lat: &Lattice,
    ground: Option<&Ground>,
    budget: &ParticleBudget,
) -> Result<Raised, CaseError> {
    if case.buildings.is_empty() {
        return Ok(Raised::default());
    }
    let mut clip = ([f64::NEG_INFINITY; 2], [f64::INFINITY; 2]);
    let held = holder(case).map(|b| ([b.min[0], b.min[1]], [b.max[0], b.max[1]]));
    for (min, max) in held.into_iter().chain(ground.map(|g| g.clip())) {
        for a in 0..2 {
            clip.0[a] = clip.0[a].max(min[a]);
            clip.1[a] = clip.1[a].min(max[a]);
        }
    }
    let site = Site {
        terrain: case.terrain.as_ref(),
        floor: case.tank.as_ref().map(|t| t.inner.min[2]),
        clip,
    };
    super::buildings::raise(ctx, &case.buildings, lat, &site, budget)
}

/// Each fill's water, spread from its seed within what holds it (the tank's inner box and the
/// domain, else the terrain's columns) around the ground, obstacles, bodies, elastic solids
/// (their boxes: their particles are made later) and the fluid blocks; its columns rest on
/// the ground.
fn fills(
    ctx: &Ctx<'_>,
    case: &Case,
    lat: &Lattice,
    (obstacle_ranges, raised): (&[IndexRange], &Raised),
    (ground, budget): (Option<&Ground>, &ParticleBudget),
) -> Result<Vec<super::fill::Filled>, CaseError> {
    if case.fills.is_empty() {
        return Ok(Vec::new());
    }
    let (dim, v) = (case.dim, case.dim - 1);
    let blockers = Blockers::new(case, (lat, obstacle_ranges), (ground, raised), None);
    // The fluid blocks' water is there already.
    let fixed = |p: [f64; 3]| {
        (case.solids.iter())
            .position(|s| point_inside(p, &s.bx, dim))
            .map(|j| format!("solid[{j}]"))
            .or_else(|| {
                (case.blocks.iter())
                    .position(|b| point_inside(p, &b.bx, dim))
                    .map(|j| format!("fluid_block[{j}]"))
            })
            .or_else(|| blockers.name_at(p))
    };
    let holder_name = match (&case.tank, &case.domain) {
        (Some(_), _) => "the tank's inner box (tank.min_m to tank.max_m)",
        (None, Some(_)) => "the domain (domain.min_m to domain.max_m)",
        (None, None) => "the terrain's columns (terrain.file)",
    };
    let bound =
        match (holder(case), ground) {
            (Some(b), _) => b,
            (None, Some(g)) => {
                let mut b = g.bounds;
                b.max[v] = f64::INFINITY;
                b
            }
            (None, None) => return Err(ctx.err(
                &format!("fill[{}]", case.fills[0].index),
                None,
                "nothing holds the fill's water: a fill spreads inside a [tank], a [domain] or \
                 over a [terrain]",
                "add a [tank] or a [domain] around the water, or use a [[fluid_block]]",
            )),
        };
    let mut fills = Vec::with_capacity(case.fills.len());
    // The lattice points of the fills before, which a later fill's water goes around.
    let mut earlier: std::collections::HashMap<[u64; 3], usize> = Default::default();
    for f in &case.fills {
        let blocked = |p: [f64; 3]| {
            fixed(p).or_else(|| (earlier.get(&p.map(f64::to_bits))).map(|j| format!("fill[{j}]")))
        };
        let holder = (&bound, holder_name);
        let mut filled = super::fill::filled(ctx, f, lat, holder, (&blocked, budget))?;
        let on_lattice = filled.points.clone();
        if let (Some(t), Some(g)) = (&case.terrain, ground) {
            let points = std::mem::take(&mut filled.points);
            // Moved up, a column stays in what holds it (its top may stand below the level).
            let open = |p: [f64; 3]| blocked(p).is_none() && point_inside(p, &bound, dim);
            filled.points = g.settle_all(t, points, case.dx, open);
            filled.water = super::fill::water_box(&filled.points, case.dx, dim);
        }
        earlier.extend(on_lattice.iter().map(|p| (p.map(f64::to_bits), f.index)));
        fills.push(filled);
    }
    Ok(fills)
}

/// What holds the fluid: the tank's inner box cut by the domain, or either alone.
fn holder(case: &Case) -> Option<Aabb> {
    match (case.tank.as_ref().map(|t| t.inner), case.domain) {
        (Some(mut b), Some(d)) => {
            for a in 0..case.dim {
                b.min[a] = b.min[a].max(d.min[a]);
                b.max[a] = b.max[a].min(d.max[a]);
            }
            Some(b)
        }
        (b, d) => b.or(d),
    }
}

/// Tank cells along each axis (`None` without a tank): at least one, and not too many.
fn tank_cells(ctx: &Ctx<'_>, case: &Case) -> Result<Option<[f64; 3]>, CaseError> {
    let Some(t) = &case.tank else {
        return Ok(None);
    };
    let (dim, dx) = (case.dim, case.dx);
    let mut n = [1.0; 3];
    for (a, na) in n.iter_mut().enumerate().take(dim) {
        *na = cells(t.inner.max[a] - t.inner.min[a], dx);
        limits::tank_length(ctx, t.inner.max[a] - t.inner.min[a], *na, AXES[a])?;
        if *na < 1.0 {
            return Err(ctx.err(
                "tank.max_m",
                None,
                format!(
                    "the tank is {} m along {}, less than one particle spacing dx = {} m",
                    num(t.inner.max[a] - t.inner.min[a]),
                    AXES[a],
                    num(dx)
                ),
                "make the tank larger or particles.dx_m smaller",
            ));
        }
    }
    Ok(Some(n))
}

/// Each fluid block's cells along each axis. Fluid blocks: inside the tank, at least one
/// particle thick, not overlapping.
fn block_cells(ctx: &Ctx<'_>, case: &Case) -> Result<Vec<[f64; 3]>, CaseError> {
    let (dim, dx) = (case.dim, case.dx);
    let mut block_cells = Vec::with_capacity(case.blocks.len());
    for (i, b) in case.blocks.iter().enumerate() {
        let path = format!("fluid_block[{i}]");
        if let Some(t) = &case.tank {
            if let Some(a) = inside(&b.bx, &t.inner, dim) {
                let field = if b.bx.min[a] < t.inner.min[a] - TOL {
                    "min_m"
                } else {
                    "max_m"
                };
                return Err(ctx.err(
                    &format!("{path}.{field}"),
                    Some(format!(
                        "{:?}",
                        &(if field == "min_m" { b.bx.min } else { b.bx.max })[..dim]
                    )),
                    format!(
                        "the block ({}) leaves the tank's inner box ({}) along {}",
                        fmt_box(&b.bx, dim),
                        fmt_box(&t.inner, dim),
                        AXES[a]
                    ),
                    "keep fluid blocks inside the tank: min_m >= tank.min_m and max_m <= \
                     tank.max_m",
                ));
            }
        }
        let mut n = [1.0; 3];
        for (a, na) in n.iter_mut().enumerate().take(dim) {
            let len = b.bx.max[a] - b.bx.min[a];
            *na = cells(len, dx);
            if *na < 1.0 {
                return Err(ctx.err(
                    &format!("{path}.max_m"),
                    None,
                    format!(
                        "the block is {} m thick along {}, too thin to hold one particle at \
                         dx = {} m",
                        num(len),
                        AXES[a],
                        num(dx)
                    ),
                    "make the block at least dx thick, or decrease particles.dx_m",
                ));
            }
        }
        for (j, other) in case.blocks[..i].iter().enumerate() {
            if (0..dim)
                .all(|a| b.bx.max[a].min(other.bx.max[a]) - b.bx.min[a].max(other.bx.min[a]) > TOL)
            {
                return Err(ctx.err(
                    &path,
                    None,
                    format!(
                        "overlaps fluid_block[{j}] ({}); particles would be created twice",
                        fmt_box(&other.bx, dim)
                    ),
                    "make the blocks touch without overlapping",
                ));
            }
        }
        block_cells.push(n);
    }
    Ok(block_cells)
}

/// The global lattice, continued by walls and obstacles.
fn lattice(case: &Case) -> Lattice {
    let v = case.dim - 1;
    Lattice {
        // The tank's inner corner, else the first fluid block's, else the first inlet's, else
        // for fills the terrain's corner (or the domain's, or the first fill's seed) with a row
        // of cells topped at the first fill's level, else (solids and walls without fluid)
        // the first solid's.
        origin: match (&case.tank, case.blocks.first(), case.inlets.first()) {
            (Some(t), _, _) => t.inner.min,
            (None, Some(b), _) => b.bx.min,
            (None, None, Some(i)) => i.bx.min,
            (None, None, None) => match case.fills.first() {
                Some(f) => {
                    let terrain = case.terrain.as_ref().map(|t| t.grid.extent().0);
                    let mut o = match (terrain, case.domain) {
                        (Some(sw), _) => [sw[0], sw[1], 0.0],
                        (None, Some(d)) => d.min,
                        (None, None) => f.anchor(),
                    };
                    o[v] = f.top();
                    o
                }
                None => case.solids[0].bx.min,
            },
        },
        dx: case.dx,
        dim: case.dim,
    }
}

/// Each obstacle's range of lattice indices: at least one point along every axis.
fn obstacle_ranges(
    ctx: &Ctx<'_>,
    case: &Case,
    lat: &Lattice,
) -> Result<Vec<IndexRange>, CaseError> {
    let mut obstacle_ranges = Vec::with_capacity(case.obstacles.len());
    for (i, o) in case.obstacles.iter().enumerate() {
        let Some(r) = lat.range_in(o) else {
            return Err(ctx.err(
                &format!("{}.max_m", case.obstacle_paths[i]),
                None,
                format!(
                    "the obstacle ({}) is too thin to hold one wall particle on the particle \
                     lattice (spacing dx = {} m)",
                    fmt_box(o, case.dim),
                    num(case.dx)
                ),
                "make it at least dx thick along every axis, or decrease particles.dx_m",
            ));
        };
        obstacle_ranges.push(r);
    }
    Ok(obstacle_ranges)
}

/// The water inlet `i` brings has somewhere to go: a spacing beyond its buffer along its
/// direction lies in the tank (and the given domain) and in no obstacle. An inlet pointing
/// at a wall ran until the water it pushed into the wall was compressed beyond the stop limit,
/// and the run blamed the sound speed (issue 64).
fn inflow_has_room(ctx: &Ctx<'_>, case: &Case, i: usize, dx: f64) -> Result<(), CaseError> {
    let (s, dim) = (&case.inlets[i], case.dim);
    let a = s.axis;
    let mut beyond = s.bx;
    if s.sense > 0.0 {
        beyond.min[a] = s.bx.max[a];
        beyond.max[a] = s.bx.max[a] + dx;
    } else {
        beyond.max[a] = s.bx.min[a];
        beyond.min[a] = s.bx.min[a] - dx;
    }
    let overlaps = |b: &Aabb| {
        (0..dim).all(|k| beyond.max[k].min(b.max[k]) - beyond.min[k].max(b.min[k]) > TOL)
    };
    let outside = |b: &Aabb| inside(&beyond, b, dim).is_some();
    let blocked = (case.tank.as_ref())
        .filter(|t| outside(&t.inner))
        .map(|_| "the tank's wall".to_string())
        .or_else(|| {
            case.domain
                .filter(outside)
                .map(|_| "the edge of [domain]".into())
        })
        .or_else(|| {
            (case.obstacles.iter().position(overlaps)).map(|j| case.obstacle_paths[j].clone())
        });
    let Some(blocked) = blocked else {
        return Ok(());
    };
    let sign = if s.sense > 0.0 { "+" } else { "-" };
    Err(ctx.err(
        &format!("inlet[{i}].direction"),
        None,
        format!(
            "points ({sign}{}) from the buffer box ({}) at {blocked}: the water it brings would \
             be pushed into it",
            AXES[a],
            fmt_box(&s.bx, dim)
        ),
        "point the direction from the buffer into the water (the buffer's face that the \
         tank's interior lies beyond)",
    ))
}

/// Each inlet's layout. Inlets: inside the tank, clear of fluid blocks and obstacles, on the
/// lattice.
fn inlet_layouts(
    ctx: &Ctx<'_>,
    case: &Case,
    lat: &Lattice,
    h: f64,
) -> Result<Vec<super::open_boundaries::Layout>, CaseError> {
    let dim = case.dim;
    let mut inlet_layouts = Vec::with_capacity(case.inlets.len());
    for (i, s) in case.inlets.iter().enumerate() {
        let path = format!("inlet[{i}]");
        if let Some(t) = &case.tank {
            if let Some(a) = inside(&s.bx, &t.inner, dim) {
                return Err(ctx.err(
                    &path,
                    None,
                    format!(
                        "the buffer box ({}) leaves the tank's inner box ({}) along {}",
                        fmt_box(&s.bx, dim),
                        fmt_box(&t.inner, dim),
                        AXES[a]
                    ),
                    "keep inlets inside the tank: a nozzle through a wall is a gap in an \
                     obstacle, with the buffer inside the tank",
                ));
            }
        }
        inflow_has_room(ctx, case, i, lat.dx)?;
        let overlaps = |b: &Aabb| {
            (0..dim).all(|a| s.bx.max[a].min(b.max[a]) - s.bx.min[a].max(b.min[a]) > TOL)
        };
        let other = case
            .blocks
            .iter()
            .position(|b| overlaps(&b.bx))
            .map(|j| format!("fluid_block[{j}]"))
            .or_else(|| {
                case.obstacles
                    .iter()
                    .position(overlaps)
                    .map(|j| case.obstacle_paths[j].clone())
            })
            .or_else(|| {
                case.inlets[..i]
                    .iter()
                    .position(|o| overlaps(&o.bx))
                    .map(|j| format!("inlet[{j}]"))
            });
        if let Some(other) = other {
            return Err(ctx.err(
                &path,
                None,
                format!(
                    "the buffer box ({}) overlaps {other}; particles would be created twice",
                    fmt_box(&s.bx, dim)
                ),
                "make the buffer box touch other parts without overlapping them",
            ));
        }
        inlet_layouts.push(super::open_boundaries::layout(
            ctx,
            i,
            s,
            lat,
            (h, case.gravity),
        )?);
    }
    Ok(inlet_layouts)
}

/// The particle count of the case, checked against the `budget` before anything is
/// allocated: every part's count (for a body, the lattice its particles are picked from, so
/// that a long thin box counts its true length).
fn particle_budget(
    ctx: &Ctx<'_>,
    case: &Case,
    geo: &Geometry,
    budget: &ParticleBudget,
) -> Result<f64, CaseError> {
    let (dim, dx) = (case.dim, case.dx);
    let mut parts: Vec<(String, f64)> = Vec::new();
    for (i, n) in geo.block_cells.iter().enumerate() {
        parts.push((format!("fluid_block[{i}]"), n.iter().product()));
    }
    for (i, f) in geo.fills.iter().enumerate() {
        parts.push((format!("fill[{i}]"), f.points.len() as f64));
    }
    for (i, l) in geo.inlet_layouts.iter().enumerate() {
        parts.push((format!("inlet[{i}]"), l.n_columns * l.layers as f64));
    }
    let n_fluid_parts = parts.len();
    if let Some(n) = geo.tank_cells {
        parts.push(("tank".into(), geo.tank_wall(case, n).count()));
    }
    for (i, ((lo, hi), t)) in geo
        .obstacle_ranges
        .iter()
        .zip(&case.obstacle_walls)
        .enumerate()
    {
        let n = (0..dim).map(|a| hi[a] - lo[a] + 1.0);
        let all: f64 = n.clone().product();
        let count = if *t == Treatment::Repulsive {
            all - n.map(|c| (c - 2.0).max(0.0)).product::<f64>()
        } else {
            all
        };
        parts.push((case.obstacle_paths[i].clone(), count));
    }
    if let Some(g) = &geo.ground {
        parts.push(("terrain".into(), g.count));
    }
    if !geo.raised.points.is_empty() {
        parts.push(("buildings".into(), geo.raised.points.len() as f64));
    }
    for (i, w) in geo.surface_walls.iter().enumerate() {
        parts.push((format!("surface[{i}]"), w.len() as f64));
    }
    let n_wall_parts = parts.len();
    for (i, b) in case.bodies.iter().enumerate() {
        parts.push((format!("body[{i}]"), b.shape.lattice_size(dx, dim)));
    }
    limits::budget(
        ctx,
        (dx, dim),
        &parts,
        [n_fluid_parts, n_wall_parts],
        budget,
    )
}

/// The elastic solids of a case with fluid, as [`elastic_solids`] makes them.
struct Elastic {
    materials: Vec<ElasticMaterial>,
    particles: Vec<Particle>,
    /// The solid (index) of each particle.
    body: Vec<u32>,
    /// The box of each solid's particles.
    extents: Vec<Aabb>,
}

/// Elastic solids in the fluid: their particles, bodies and materials, within what is left of
/// the budget (`budget`); and the box of each solid's particles.
fn elastic_solids(
    ctx: &Ctx<'_>,
    case: &Case,
    budget: &ParticleBudget,
) -> Result<Option<Elastic>, CaseError> {
    if case.solids.is_empty() {
        return Ok(None);
    }
    let (materials, particles, body) =
        super::solids::solid_particles(ctx, &case.solids, case.dim, case.dx, budget)?;
    let mut extents = vec![
        Aabb {
            min: [f64::MAX; 3],
            max: [f64::MIN; 3],
        };
        case.solids.len()
    ];
    for (p, &b) in particles.iter().zip(&body) {
        let e = &mut extents[b as usize];
        for a in 0..3 {
            e.min[a] = e.min[a].min(p.pos[a]);
            e.max[a] = e.max[a].max(p.pos[a]);
        }
    }
    Ok(Some(Elastic {
        materials,
        particles,
        body,
        extents,
    }))
}

/// The speed of sound and the hydrostatic start, checked: what [`Start::of`] finds.
struct Start {
    /// |g| [m/s²].
    g: f64,
    c0: f64,
    /// The field the speed of sound came from, and its value, for errors.
    sound_path: &'static str,
    sound_value: f64,
    /// The Tait stiffness B = c0² ρ0 / γ.
    tait_b: f64,
    rho0: f64,
    gamma: f64,
    /// The particle mass ρ0 dx^dim.
    mass: f64,
}

impl Start {
    /// Speed of sound and the hydrostatic start: c0, the Tait stiffness, inflow below c0, the
    /// particle mass.
    fn of(
        ctx: &Ctx<'_>,
        case: &Case,
        water: &[Aabb],
        elastic: Option<&Elastic>,
    ) -> Result<Start, CaseError> {
        let (dim, dx) = (case.dim, case.dx);
        let g = case.gravity.iter().map(|c| c * c).sum::<f64>().sqrt();
        let c0 = sound_speed(ctx, case, (g, water), elastic)?;
        // The field the speed of sound came from, for the errors below.
        let (sound_path, sound_value) = match case.sound {
            Sound::Speed(c) => ("physics.sound_speed_m_s", c),
            Sound::Coef(k) => ("physics.sound_speed_coef", k),
        };
        let tait_b = c0 * c0 * case.rho0 / case.gamma;
        if !(tait_b.is_finite() && tait_b > 0.0) {
            return Err(ctx.err(
                sound_path,
                Some(num(sound_value)),
                format!(
                    "gives a Tait stiffness B = c0² rho0 / gamma = {} Pa that cannot be computed \
                     with (c0 = {} m/s, physics.rho0_kg_m3 = {}, physics.gamma = {})",
                    num(tait_b),
                    num(c0),
                    num(case.rho0),
                    num(case.gamma)
                ),
                "use a realistic speed of sound, about 10 times the largest flow speed, and a \
                 realistic physics.rho0_kg_m3",
            ));
        }
        let too_fast = (case.inlets.iter().enumerate()).find(|(_, s)| s.max_speed() >= c0);
        if let Some((i, s)) = too_fast {
            return Err(ctx.err(
                &format!("inlet[{i}].{}", s.inflow_field),
                None,
                format!(
                    "makes an inflow speed of {} m/s, not below the speed of sound c0 = {} m/s: \
                     weakly compressible SPH needs flow speeds of about c0 / 10 or less",
                    num(s.max_speed()),
                    num(c0)
                ),
                format!(
                    "lower the inflow speed, or raise {sound_path} so that c0 is about 10 times it"
                ),
            ));
        }
        let mass = case.rho0 * dx.powi(dim as i32);
        if !(mass.is_finite() && mass > 0.0) {
            return Err(ctx.err(
                "particles.dx_m",
                Some(num(dx)),
                format!(
                    "gives a particle mass physics.rho0_kg_m3 * dx^{dim} = {} * {}^{dim} = {} kg \
                     that cannot be computed with",
                    num(case.rho0),
                    num(dx),
                    num(mass)
                ),
                "use a spacing and density of realistic size",
            ));
        }
        Ok(Start {
            g,
            c0,
            sound_path,
            sound_value,
            tait_b,
            rho0: case.rho0,
            gamma: case.gamma,
            mass,
        })
    }

    /// The hydrostatic start density `depth` below a free surface.
    fn rho_at(&self, depth: f64) -> f64 {
        self.rho0 * (1.0 + self.rho0 * self.g * depth.max(0.0) / self.tait_b).powf(1.0 / self.gamma)
    }
}

/// The speed of sound c0: given, or `coef` times the larger of sqrt(|g| H) (H: the deepest
/// fluid block) and the fastest inflow. `g`: |g|.
fn sound_speed(
    ctx: &Ctx<'_>,
    case: &Case,
    (g, water): (f64, &[Aabb]),
    elastic: Option<&Elastic>,
) -> Result<f64, CaseError> {
    let v = case.dim - 1;
    Ok(match case.sound {
        // Without fluid c0 is unused (the solids have their own sound speed); that one keeps
        // the checks below meaningful.
        _ if water.is_empty() && case.inlets.is_empty() => elastic.map_or(1.0, |e| {
            e.materials
                .iter()
                .map(ElasticMaterial::sound_speed)
                .fold(0.0, f64::max)
        }),
        Sound::Speed(c) => c,
        Sound::Coef(k) => {
            let floor = |b: &Aabb| case.tank.as_ref().map_or(b.min[v], |t| t.inner.min[v]);
            let depth = water
                .iter()
                .map(|b| b.max[v] - floor(b))
                .fold(0.0, f64::max);
            // Inflow faster than the fall speed sets the scale instead.
            let inflow = (case.inlets.iter())
                .map(|s| s.max_speed())
                .fold(0.0, f64::max);
            let c = k * (g * depth).sqrt().max(inflow);
            if !c.is_finite() || c <= 0.0 {
                return Err(ctx.err(
                    "physics.sound_speed_coef",
                    Some(num(k)),
                    format!(
                        "gives c0 = coef * max(sqrt(|g| * H), inlet speed) = {} m/s with |g| \
                         = {} m/s² (physics.gravity_m_s2) and H = {} m (the deepest fluid \
                         block or fill)",
                        num(c),
                        num(g),
                        num(depth)
                    ),
                    "give physics.sound_speed_m_s instead",
                ));
            }
            c
        }
    })
}

/// What takes the place of fluid: the obstacles (the user's box and that of its particles),
/// the elastic solids, the ground, the buildings, the surfaces and the bodies.
struct Blockers<'a> {
    case: &'a Case,
    /// Each obstacle's box and the box of its particles.
    obstacles: Vec<(Aabb, Aabb)>,
    /// The box of each elastic solid's particles.
    solids: Option<&'a [Aabb]>,
    /// The ground, with its clip.
    ground: Option<(&'a super::terrain::Terrain, &'a Ground)>,
    /// The buildings.
    raised: &'a Raised,
}

impl<'a> Blockers<'a> {
    fn new(
        case: &'a Case,
        (lat, obstacle_ranges): (&Lattice, &[IndexRange]),
        (ground, raised): (Option<&'a Ground>, &'a Raised),
        solids: Option<&'a [Aabb]>,
    ) -> Blockers<'a> {
        let obstacles = (case.obstacles.iter().zip(obstacle_ranges))
            .map(|(o, (lo, hi))| {
                let first = lat.pos(lo.map(|c| c as i64));
                let last = lat.pos(hi.map(|c| c as i64));
                (
                    *o,
                    Aabb {
                        min: first,
                        max: last,
                    },
                )
            })
            .collect();
        Blockers {
            case,
            obstacles,
            solids,
            ground: case.terrain.as_ref().zip(ground),
            raised,
        }
    }

    /// What takes the place of fluid at `p`, as a message names it.
    fn name_at(&self, p: [f64; 3]) -> Option<String> {
        self.at(p).map(name_of)
    }

    /// Whether `p` lies in the user's box or within a spacing of the particles' box.
    fn covered(&self, p: [f64; 3], user: &Aabb, parts: &Aabb) -> bool {
        let (dim, dx) = (self.case.dim, self.case.dx);
        let d2: f64 = (0..dim)
            .map(|a| {
                (parts.min[a] - p[a])
                    .max(p[a] - parts.max[a])
                    .max(0.0)
                    .powi(2)
            })
            .sum();
        point_inside(p, user, dim) || d2 < (dx * (1.0 - 1e-6)).powi(2)
    }

    /// The obstacle, elastic solid or body that takes the place of a fluid particle at `p`.
    fn at(&self, p: [f64; 3]) -> Option<(&'static str, usize)> {
        let case = self.case;
        let obstacle = self
            .obstacles
            .iter()
            .position(|(user, parts)| self.covered(p, user, parts));
        let elastic_solid = || {
            let extents = self.solids?;
            case.solids
                .iter()
                .zip(extents)
                .position(|(s, parts)| self.covered(p, &s.bx, parts))
        };
        let body = || {
            case.bodies
                .iter()
                .position(|b| b.shape.near(p, 0.5 * case.dx * (1.0 - 1e-6), case.dim))
        };
        // Fluid keeps half a spacing above the ground, as above a tank's floor.
        let ground = || {
            let (t, g) = self.ground?;
            g.below(t, p, 0.5 * case.dx).then_some(("terrain", 0))
        };
        let building = || {
            let (i, _) = self.raised.at(&case.buildings, p, case.dx)?;
            Some(("building", i))
        };
        let surface = || {
            // Fluid keeps half a spacing off the surface, as off the ground.
            let clearance = 0.5 * case.dx * (1.0 - 1e-6);
            (case.surfaces.iter())
                .position(|s| s.blocks(p, case.dx, clearance))
                .map(|i| ("surface", i))
        };
        match (obstacle, elastic_solid()) {
            (Some(i), _) => Some(("obstacle", i)),
            (None, Some(i)) => Some(("solid", i)),
            (None, None) => ground()
                .or_else(building)
                .or_else(surface)
                .or_else(|| body().map(|i| ("body", i))),
        }
    }
}

/// A blocker as [`Blockers::at`] gives it, as a message names it.
fn name_of((kind, j): (&str, usize)) -> String {
    match kind {
        "terrain" => "the terrain".into(),
        "building" => format!("a building of buildings[{j}]"),
        _ => format!("{kind}[{j}]"),
    }
}

/// The fluid blocks' particles (room for `total` particles), minus what lies in (or within
/// half a spacing of) an obstacle's particles, an elastic solid or a body, then the fills';
/// a block left without any is an error.
fn fluid_particles(
    ctx: &Ctx<'_>,
    case: &Case,
    geo: &Geometry,
    elastic: Option<&Elastic>,
    start: &Start,
    total: f64,
) -> Result<Vec<Particle>, CaseError> {
    let (dim, dx, v, lat) = (case.dim, case.dx, case.dim - 1, &geo.lat);
    let blockers = Blockers::new(
        case,
        (lat, &geo.obstacle_ranges),
        (geo.ground.as_ref(), &geo.raised),
        elastic.map(|e| e.extents.as_slice()),
    );
    // What the host cannot give is refused here rather than aborting the process (the budget
    // estimates what it can: `sph::run_budget`).
    let mut particles = Vec::new();
    if particles.try_reserve_exact(total as usize).is_err() {
        return Err(ctx.err(
            "particles.dx_m",
            Some(num(dx)),
            format!(
                "the host's memory cannot hold the case's {} particles ({:.1} GiB)",
                total,
                total * std::mem::size_of::<Particle>() as f64 / (1u64 << 30) as f64
            ),
            format!("increase particles.dx_m (the count scales as 1/dx^{dim})"),
        ));
    }
    for (i, (b, n)) in case.blocks.iter().zip(&geo.block_cells).enumerate() {
        let top = b.bx.max[v];
        let start_len = particles.len();
        let mut first_blocker = None;
        let mut points = Vec::new();
        for pos in block_points(b.bx.min, n.map(|c| c as i64), dx, dim) {
            match blockers.at(pos) {
                None => points.push(pos),
                Some(s) => {
                    first_blocker.get_or_insert(s);
                }
            }
        }
        if let (Some(t), Some(g)) = (&case.terrain, &geo.ground) {
            points = g.settle_all(t, points, dx, |p| blockers.at(p).is_none());
        }
        particles.extend(points.into_iter().map(|pos| Particle {
            pos,
            vel: b.vel,
            rho: start.rho_at(top - pos[v]),
            kind: Kind::Fluid,
        }));
        if particles.len() == start_len {
            // A block wholly inside solids is a mistake, and a case without fluid is empty.
            let solid = first_blocker.map_or(String::new(), name_of);
            return Err(ctx.err(
                &format!("fluid_block[{i}]"),
                None,
                format!(
                    "the block ({}) lies inside {solid}, or within half a spacing of it \
                     (particles.dx_m / 2 = {} m): none of its particles would be fluid",
                    fmt_box(&b.bx, dim),
                    num(0.5 * dx)
                ),
                format!(
                    "move {solid} out of the fluid, remove fluid_block[{i}], or decrease \
                     particles.dx_m"
                ),
            ));
        }
    }
    // The fills' water, less what the elastic solids' particles (made after the fills were
    // spread) take.
    for f in &geo.fills {
        let top = f.water.max[v];
        for &pos in &f.points {
            if blockers.at(pos).is_none() {
                particles.push(Particle {
                    pos,
                    vel: [0.0; 3],
                    rho: start.rho_at(top - pos[v]),
                    kind: Kind::Fluid,
                });
            }
        }
    }
    Ok(particles)
}

/// The start density of wall and body particles.
struct BoundaryRho<'a> {
    /// The boxes of the water at the start (`Geometry::water`).
    water: &'a [Aabb],
    start: &'a Start,
    /// How far beside a fluid block a wall particle takes its hydrostatic density.
    reach: f64,
    /// The vertical axis.
    v: usize,
}

impl BoundaryRho<'_> {
    /// Hydrostatic below the highest water over `p` (within `reach`), else ρ0.
    fn wall(&self, p: [f64; 3]) -> f64 {
        let (v, reach) = (self.v, self.reach);
        let over = self
            .water
            .iter()
            .filter(|b| (0..v).all(|a| b.min[a] - reach <= p[a] && p[a] <= b.max[a] + reach));
        match over.map(|b| b.max[v]).reduce(f64::max) {
            Some(top) => self.start.rho_at(top - p[v]),
            None => self.start.rho0,
        }
    }

    /// A wall particle of treatment `t` at rest at `pos`.
    fn particle(&self, t: Treatment, pos: [f64; 3]) -> Particle {
        Particle {
            pos,
            vel: [0.0; 3],
            rho: self.of(t, pos),
            kind: kind_of(t),
        }
    }

    /// The start density of a particle of treatment `t` at `pos`. Repulsive particles carry no
    /// pressure: ρ0.
    fn of(&self, t: Treatment, pos: [f64; 3]) -> f64 {
        match t {
            Treatment::Repulsive => self.start.rho0,
            _ => self.wall(pos),
        }
    }
}

/// Walls: tank, then obstacles (each lattice point once), pushed onto `particles`; of a moving
/// tank, returned instead (its walls and obstacles become the body "tank", after every fixed
/// particle). Mirror walls have no particles (their TankWall has no layers).
fn wall_particles(
    case: &Case,
    (lat, obstacle_ranges): (&Lattice, &[IndexRange]),
    wall: Option<&TankWall>,
    rho: &BoundaryRho<'_>,
    particles: &mut Vec<Particle>,
) -> Vec<Particle> {
    let dim = case.dim;
    let tank_moves = case.tank_moves();
    let mut tank_particles = Vec::new();
    let mut push_wall = |pos: [f64; 3], t: Treatment| {
        let p = rho.particle(t, pos);
        if tank_moves {
            tank_particles.push(p);
        } else {
            particles.push(p);
        }
    };
    if let (Some(w), Some(t)) = (wall, case.tank.as_ref()) {
        w.indices()
            .into_iter()
            .for_each(|i| push_wall(lat.pos(i), t.wall));
    }
    let mut seen = HashSet::new();
    for ((lo, hi), &t) in obstacle_ranges.iter().zip(&case.obstacle_walls) {
        let (first, last) = (lo.map(|c| c as i64), hi.map(|c| c as i64));
        for idx in range_points(lat, *lo, *hi) {
            // A repulsive obstacle is only its surface: points with a lattice neighbour outside.
            let surface = (0..dim).any(|a| idx[a] == first[a] || idx[a] == last[a]);
            if t == Treatment::Repulsive && !surface {
                continue;
            }
            if !wall.is_some_and(|w| w.contains(idx)) && seen.insert(idx) {
                push_wall(lat.pos(idx), t);
            }
        }
    }
    tank_particles
}

/// The terrain's wall particles, column by column under the surface, pushed onto
/// `particles`; those in an obstacle's particles' box are the obstacle's, those under a
/// tank's inner box the tank floor's, the columns in a building's footprint the building's.
fn ground_particles(
    case: &Case,
    terrain: &super::terrain::Terrain,
    ground: &Ground,
    (lat, (obstacle_ranges, raised)): (&Lattice, (&[IndexRange], &Raised)),
    rho: &BoundaryRho<'_>,
    particles: &mut Vec<Particle>,
) {
    let dx = case.dx;
    // Below the tank's inner box the tank's floor is the wall.
    let floor = case
        .tank
        .as_ref()
        .map_or(f64::NEG_INFINITY, |t| t.inner.min[2]);
    let obstacles: Vec<Aabb> = obstacle_ranges
        .iter()
        .map(|(lo, hi)| Aabb {
            min: lat.pos(lo.map(|c| c as i64)).map(|c| c - 0.5 * dx),
            max: lat.pos(hi.map(|c| c as i64)).map(|c| c + 0.5 * dx),
        })
        .collect();
    for (centre, column) in ground.columns(terrain, lat) {
        if raised.covers(&case.buildings, centre[0], centre[1]) {
            continue;
        }
        for k in 0..column.count {
            let pos = [centre[0], centre[1], column.particle_z(k, dx)];
            if pos[2] < floor || obstacles.iter().any(|b| point_inside(pos, b, 3)) {
                continue;
            }
            particles.push(rho.particle(terrain.wall, pos));
        }
    }
}

/// The surfaces' wall particles, pushed onto `particles`: those in an obstacle's particles'
/// box are the obstacle's, those under the terrain's surface the ground's, and a point
/// of two surfaces is the first's.
fn surface_particles(
    case: &Case,
    geo: &Geometry,
    rho: &BoundaryRho<'_>,
    particles: &mut Vec<Particle>,
) {
    let blockers = Blockers::new(
        case,
        (&geo.lat, &geo.obstacle_ranges),
        (geo.ground.as_ref(), &geo.raised),
        None,
    );
    let mut seen = HashSet::new();
    for (s, points) in case.surfaces.iter().zip(&geo.surface_walls) {
        for &pos in points {
            let first = blockers.at(pos);
            let taken = matches!(first, Some(("obstacle" | "terrain" | "building", _)));
            if taken || !seen.insert(pos.map(f64::to_bits)) {
                continue;
            }
            particles.push(rho.particle(s.wall, pos));
        }
    }
}

/// Mirror planes on every face of the tank's inner box on the lattice (origin + n dx), the lid
/// only when the top is closed; normals point into the fluid.
fn mirror_planes(case: &Case, lat: &Lattice, wall: Option<&TankWall>) -> Vec<MirrorPlane> {
    let (dim, dx, v) = (case.dim, case.dx, case.dim - 1);
    let mut mirror_planes = Vec::new();
    if let (Some(w), Some(t)) = (wall, case.tank.as_ref()) {
        if let Treatment::Mirror { no_slip } = t.wall {
            for a in 0..dim {
                let mut normal = [0.0; 3];
                normal[a] = 1.0;
                mirror_planes.push(MirrorPlane {
                    point: lat.origin,
                    normal,
                    no_slip,
                });
                if a == v && t.open_top {
                    continue;
                }
                let mut point = lat.origin;
                point[a] += w.n[a] as f64 * dx;
                normal[a] = -1.0;
                mirror_planes.push(MirrorPlane {
                    point,
                    normal,
                    no_slip,
                });
            }
        }
    }
    mirror_planes
}

/// Elastic solids after the fixed walls (bodies come last), each particle inside the domain:
/// their materials and the solid of each particle (0 before them).
fn place_solids(
    ctx: &Ctx<'_>,
    dim: usize,
    elastic: Option<Elastic>,
    domain: &Domain,
    particles: &mut Vec<Particle>,
) -> Result<Option<Placed>, CaseError> {
    let Some(Elastic {
        materials,
        particles: mut parts,
        body,
        ..
    }) = elastic
    else {
        return Ok(None);
    };
    if let Some((p, &b)) = parts
        .iter()
        .zip(&body)
        .find(|(p, _)| !(0..dim).all(|a| domain.min[a] <= p.pos[a] && p.pos[a] <= domain.max[a]))
    {
        return Err(ctx.err(
            &format!("solid[{b}]"),
            None,
            format!(
                "has a particle at {:?}, outside the domain ({:?} to {:?})",
                &p.pos[..dim],
                &domain.min[..dim],
                &domain.max[..dim]
            ),
            "keep the solid inside the tank, or enlarge [domain]",
        ));
    }
    let start = particles.len();
    let mut of_particle = vec![0; start];
    of_particle.extend(body);
    particles.append(&mut parts);
    Ok(Some((materials, of_particle)))
}

/// A free body's particles (`points`) lie in the tank and outside every obstacle: one placed
/// through a wall is thrown out by the wall's forces at the first step, and the run went
/// unstable blaming the sound speed (issue 64). Fixed and prescribed bodies may meet the walls
/// (a building on the ground).
fn free_body_clear_of_walls(
    ctx: &Ctx<'_>,
    case: &Case,
    i: usize,
    points: &[[f64; 3]],
) -> Result<(), CaseError> {
    let dim = case.dim;
    let within = |p: &[f64; 3], b: &Aabb, slack: f64| {
        (0..dim).all(|a| b.min[a] - slack <= p[a] && p[a] <= b.max[a] + slack)
    };
    let in_wall = points.iter().find_map(|p| {
        if case
            .tank
            .as_ref()
            .is_some_and(|t| !within(p, &t.inner, TOL))
        {
            return Some((*p, "the tank's wall".to_string()));
        }
        (case.obstacles.iter().position(|o| within(p, o, -TOL)))
            .map(|j| (*p, case.obstacle_paths[j].clone()))
    });
    let Some((p, wall)) = in_wall else {
        return Ok(());
    };
    Err(ctx.err(
        &format!("body[{i}]"),
        None,
        format!(
            "is a free body with a particle at {:?}, inside {wall}: a body placed through a \
             wall is thrown out of it at the first step",
            &p[..dim]
        ),
        "place the body inside the tank, clear of the walls and obstacles",
    ))
}

/// The bodies, their particles pushed onto `particles`: a moving tank's (`tank_particles`)
/// first, then each `[[body]]`'s.
fn bodies(
    ctx: &Ctx<'_>,
    case: &Case,
    rho: &BoundaryRho<'_>,
    mut tank_particles: Vec<Particle>,
    particles: &mut Vec<Particle>,
) -> Result<Vec<Body>, CaseError> {
    let (dim, dx) = (case.dim, case.dx);
    let mut bodies = Vec::with_capacity(case.bodies.len() + 1);
    if let (Some(t), Some(motion)) = (
        &case.tank,
        case.tank.as_ref().and_then(|t| t.motion.clone()),
    ) {
        let start = particles.len();
        particles.append(&mut tank_particles);
        bodies.push(Body {
            name: "tank".into(),
            particles: start..particles.len(),
            mass: 0.0,
            center: [0, 1, 2].map(|a| 0.5 * (t.inner.min[a] + t.inner.max[a])),
            inertia: [[0.0; 3]; 3],
            motion,
        });
    }
    for (i, spec) in case.bodies.iter().enumerate() {
        let start = particles.len();
        let center = spec.shape.center();
        // A repulsive body is its surface layer (as a repulsive wall).
        let layers = match spec.wall {
            Treatment::Repulsive => Some(1),
            _ => spec.layers,
        };
        let points = spec.shape.points(dx, dim, layers);
        if points.is_empty() {
            return Err(no_particles(ctx, i, &spec.shape, dx));
        }
        if matches!(spec.motion, Motion::Free { .. }) {
            free_body_clear_of_walls(ctx, case, i, &points)?;
        }
        for pos in points {
            particles.push(Particle {
                pos,
                vel: start_velocity(&spec.motion, center, pos),
                rho: rho.of(spec.wall, pos),
                kind: kind_of(spec.wall),
            });
        }
        let mass = spec.mass.unwrap_or(0.0);
        bodies.push(Body {
            name: spec.name.clone(),
            particles: start..particles.len(),
            mass,
            center,
            inertia: spec.shape.inertia(dim, mass),
            motion: spec.motion.clone(),
        });
    }
    Ok(bodies)
}

/// The error of body `i`, whose `shape` holds no particle. Particles sit inside the surface (a
/// ball's and a polygon's at least dx/2): a ball smaller than that, a polygon too thin or a
/// mesh around no lattice point has none, and a body without particles would feel no fluid.
fn no_particles(ctx: &Ctx<'_>, i: usize, shape: &Shape, dx: f64) -> CaseError {
    match shape {
        Shape::Ball { radius, .. } => ctx.err(
            &format!("body[{i}].radius_m"),
            Some(num(*radius)),
            format!(
                "is less than half a particle spacing (dx / 2 = {} m): the body would \
                 have no particles",
                num(0.5 * dx)
            ),
            "make the radius a few particle spacings, or decrease particles.dx_m",
        ),
        shape => ctx.err(
            &format!(
                "body[{i}].{}",
                if let Shape::Polygon(_) = shape {
                    "vertices_m"
                } else {
                    "file"
                }
            ),
            None,
            format!(
                "no particle fits in the shape (particles sit at least dx/2 inside \
                 its surface, dx = {} m): the body would have no particles",
                num(dx)
            ),
            "make the body a few particle spacings thick, or decrease particles.dx_m",
        ),
    }
}

/// The start velocity of a body's particle at `pos`: a free body's, rigid about `center`; zero
/// for a prescribed motion, which sets the velocity from the first step on.
fn start_velocity(motion: &Motion, center: [f64; 3], pos: [f64; 3]) -> [f64; 3] {
    match motion {
        Motion::Free {
            velocity, omega, ..
        } => {
            let r = [0, 1, 2].map(|a| pos[a] - center[a]);
            [
                velocity[0] + omega[1] * r[2] - omega[2] * r[1],
                velocity[1] + omega[2] * r[0] - omega[0] * r[2],
                velocity[2] + omega[0] * r[1] - omega[1] * r[0],
            ]
        }
        // The prescribed motion sets the velocity from the first step on.
        Motion::Prescribed(_) => [0.0; 3],
    }
}

/// Checks of all particles together: free solid particles clear of the boundary particles
/// (`solids`: the solid of each particle), and every start density finite.
fn check_particles(
    ctx: &Ctx<'_>,
    case: &Case,
    start: &Start,
    particles: &[Particle],
    solids: Option<&Placed>,
) -> Result<(), CaseError> {
    let (dim, dx) = (case.dim, case.dx);
    if let Some((_, solid_of)) = solids {
        super::solids::check_clearance(ctx, particles, solid_of, dim, dx)?;
    }
    if let Some(p) = particles.iter().find(|p| !p.rho.is_finite()) {
        return Err(ctx.err(
            start.sound_path,
            Some(num(start.sound_value)),
            format!(
                "is so small that the hydrostatic start density at {:?} is {}",
                &p.pos[..dim],
                p.rho
            ),
            "use a speed of sound about 10 times sqrt(|g| * H) or more",
        ));
    }
    Ok(())
}

/// What the stages of [`build`] made, for [`finish`].
struct Built {
    domain: Domain,
    /// Warnings of the build's stages (footprints left out).
    notes: Vec<String>,
    particles: Vec<Particle>,
    bodies: Vec<Body>,
    /// The elastic materials and the solid of each particle (for the particles before the
    /// solids', 0).
    solids: Option<Placed>,
    inlets: Vec<Inlet>,
    mirror_planes: Vec<MirrorPlane>,
}

/// The scenario: the particles and parts `built`, with the probes and points resolved on them,
/// the warnings, the physics and the wall parameters. `obstacle_ranges`: each obstacle's
/// lattice indices; `h`: the smoothing length.
fn finish(
    ctx: &Ctx<'_>,
    case: Case,
    obstacle_ranges: &[IndexRange],
    h: f64,
    start: &Start,
    built: Built,
) -> Result<Scenario, CaseError> {
    let (dim, dx) = (case.dim, case.dx);
    let tank_moves = case.tank_moves();
    let Built {
        domain,
        notes,
        particles,
        bodies,
        solids,
        inlets,
        mirror_planes,
    } = built;
    let points = super::probes::resolve_points(ctx, &case.points, &particles, &bodies, dim, dx)?;
    // Lattice points of each obstacle along each axis.
    let obstacle_points: Vec<[f64; 3]> = obstacle_ranges
        .iter()
        .map(|(lo, hi)| [0, 1, 2].map(|a| hi[a] - lo[a] + 1.0))
        .collect();
    let mut warnings = super::warnings::of(&case, dx, h, &obstacle_points);
    warnings.extend(notes);
    let physics = physics(&case, start, h);
    let mut probes = case.probes;
    super::probes::place_on_faces(
        ctx,
        &mut probes,
        &case.probe_paths,
        &case.face_normals,
        &particles,
        (dim, dx, h),
    )?;
    super::probes::resolve_wall_patches(
        ctx,
        &mut probes,
        &case.probe_paths,
        &particles,
        dim,
        dx,
        h,
    )?;
    let mut walls = walls(
        ctx,
        &case.walls,
        (dim, dx, start.g),
        &probes,
        &particles,
        &bodies,
    )?;
    walls.mirror_planes = mirror_planes;
    warnings.extend(super::probes::sensors_meeting_at_edges(
        &probes,
        &case.probe_paths,
        &walls,
        &particles,
        h,
    ));
    let maps = (case.maps.as_ref())
        .map(|m| super::maps::resolve(ctx, m, &domain, (&particles, &bodies), dx))
        .transpose()?;
    let n_particles = particles.len();
    let mut sc = Scenario {
        name: case.name,
        physics,
        time: case.time,
        domain,
        particles,
        probes,
        points,
        walls,
        periodic: [false; 3],
        bodies,
        solids: solids.map(|(materials, mut body)| {
            body.resize(n_particles, 0);
            Solids {
                materials,
                tau0: vec![[0.0; 6]; n_particles],
                body,
            }
        }),
        inlets,
        outlets: case.outlets,
        warnings,
        world_origin_m: case.terrain.as_ref().map_or([0.0; 3], |t| t.origin),
        maps,
    };
    let fast = super::runnable::check(
        ctx,
        &sc,
        Some(start.sound_path),
        &case.blocks,
        (tank_moves, &case.obstacle_paths),
    )?;
    sc.warnings.extend(fast);
    // Probes that can never measure: said here, and NaN in their CSV (probe_reach.rs); those
    // that can but start inside a wall or body, said too.
    let blind = crate::probe_reach::unmeasurable(&sc);
    let is_blind: Vec<bool> = blind.iter().map(Option::is_some).collect();
    let inside = super::probes::inside_walls(&sc.probes, &is_blind, &sc.particles, dim, dx);
    sc.warnings.extend(inside);
    for (i, why) in blind.into_iter().enumerate() {
        if let Some(why) = why {
            let p = &sc.probes[i];
            sc.warnings.push(format!(
                "probe '{}' ({}) cannot measure: {why}; it reads nan for the whole run; fix: \
                 move it into the fluid's reach (a pressure point in the water or the air above \
                 it, a gauge's base_m under the water's surface)",
                p.name,
                match p.kind {
                    ProbeKind::Pressure { .. } => "point_m",
                    _ => "base_m",
                },
            ));
        }
    }
    Ok(sc)
}

/// The physics of the scenario.
fn physics(case: &Case, start: &Start, h: f64) -> Physics {
    Physics {
        dim: case.dim as u32,
        dx: case.dx,
        h,
        kernel: case.kernel,
        cell: case.cell,
        id_low_bits: case.id_low_bits,
        rho0: case.rho0,
        c0: start.c0,
        gamma: case.gamma,
        gravity: case.gravity,
        viscosity: case.viscosity,
        delta_sph: case.delta_sph,
        delta_sph_form: case.delta_sph_form,
        particle_mass: start.mass,
        density_filter: case.density_filter,
        energy: case.energy,
    }
}

/// The wall parameters ([`wall_params`], with H the fluid's height and the repulsive law's
/// strength checked where it acts) and the wall-pressure sensors of `probes`. `g`: |g|.
fn walls(
    ctx: &Ctx<'_>,
    set: &WallSettings,
    (dim, dx, g): (usize, f64, f64),
    probes: &[Probe],
    particles: &[Particle],
    bodies: &[Body],
) -> Result<WallParams, CaseError> {
    // The repulsive law acts on repulsive walls, on bodies and on solids (contact).
    let contact = !bodies.is_empty()
        || particles
            .iter()
            .any(|p| matches!(p.kind, Kind::Repulsive | Kind::Solid));
    let height = highest_column(particles, dim, dx);
    let mut walls = wall_params(ctx, set, dx, height, g, contact)?;
    walls.reactions = probes
        .iter()
        .any(|p| matches!(p.kind, ProbeKind::WallPressure(_)));
    walls.sensors = probes
        .iter()
        .filter(|p| p.body.is_none())
        .filter_map(|p| match p.kind {
            ProbeKind::WallPressure(patch) => Some(patch),
            _ => None,
        })
        .collect();
    Ok(walls)
}

/// The scenario of a case whose only particles are solids.
pub(super) fn build_solid_case(
    ctx: &Ctx<'_>,
    case: Case,
    budget: &ParticleBudget,
) -> Result<Scenario, CaseError> {
    let (dim, dx) = (case.dim, case.dx);
    let (materials, particles, body) =
        super::solids::solid_particles(ctx, &case.solids, dim, dx, budget)?;
    let d = solid_case_domain(ctx, &case)?;
    let n = particles.len();
    let points = super::probes::resolve_points(ctx, &case.points, &particles, &[], dim, dx)?;
    let mut probes = case.probes;
    let h = case.h_over_dx * dx;
    super::probes::place_on_faces(
        ctx,
        &mut probes,
        &case.probe_paths,
        &case.face_normals,
        &particles,
        (dim, dx, h),
    )?;
    let physics = Physics {
        dim: dim as u32,
        dx,
        h: case.h_over_dx * dx,
        kernel: case.kernel,
        cell: case.cell,
        id_low_bits: case.id_low_bits,
        rho0: case.rho0,
        // Unused without fluid; the solids' sound speeds enter through their materials.
        c0: materials
            .iter()
            .map(ElasticMaterial::sound_speed)
            .fold(0.0, f64::max),
        gamma: case.gamma,
        gravity: case.gravity,
        viscosity: case.viscosity,
        delta_sph: case.delta_sph,
        delta_sph_form: case.delta_sph_form,
        particle_mass: case.rho0 * dx.powi(dim as i32),
        density_filter: case.density_filter,
        energy: false,
    };
    let g = case.gravity.iter().map(|g| g * g).sum::<f64>().sqrt();
    // Solids alone touch only one another. H: from the lowest particle to the highest.
    let (lo, hi) = particles.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
        (lo.min(p.pos[dim - 1]), hi.max(p.pos[dim - 1]))
    });
    let walls = wall_params(ctx, &case.walls, dx, hi - lo + dx, g, case.solids.len() > 1)?;
    let sc = Scenario {
        name: case.name,
        physics,
        time: case.time,
        domain: Domain {
            min: d.min,
            max: d.max,
        },
        particles,
        probes,
        points,
        walls,
        periodic: [false; 3],
        bodies: Vec::new(),
        solids: Some(Solids {
            materials,
            body,
            tau0: vec![[0.0; 6]; n],
        }),
        inlets: Vec::new(),
        outlets: Vec::new(),
        warnings: Vec::new(),
        world_origin_m: [0.0; 3],
        maps: None,
    };
    // Without fluid no speed of sound to warn against.
    super::runnable::check(ctx, &sc, None, &[], (false, &[]))?;
    Ok(sc)
}

/// The domain of a case of solids alone: the given one, or the solids' box with half its
/// largest extent of room on every side; every solid inside it.
fn solid_case_domain(ctx: &Ctx<'_>, case: &Case) -> Result<Aabb, CaseError> {
    let (dim, dx) = (case.dim, case.dx);
    let first = &case.solids[0];
    // Default domain: the solids' box, with half its largest extent of room on every side.
    let mut bb = first.bx;
    for s in &case.solids {
        for a in 0..dim {
            bb.min[a] = bb.min[a].min(s.bx.min[a]);
            bb.max[a] = bb.max[a].max(s.bx.max[a]);
        }
    }
    let d = match case.domain {
        Some(d) => d,
        None => {
            let room = (0..dim).map(|a| bb.max[a] - bb.min[a]).fold(0.0, f64::max) * 0.5;
            let mut d = bb;
            for a in 0..dim {
                d.min[a] -= room + 2.0 * dx;
                d.max[a] += room + 2.0 * dx;
            }
            d
        }
    };
    for (i, s) in case.solids.iter().enumerate() {
        if !(point_in(s.bx.min, &d, dim) && point_in(s.bx.max, &d, dim)) {
            return Err(ctx.err(
                &format!("solid[{i}]"),
                None,
                "leaves the domain; its particles would be dropped",
                "enlarge [domain] (or remove it to get the default)",
            ));
        }
    }
    Ok(d)
}

/// The wall parameters: `[walls]` over the defaults for spacing `dx`, height H = `height` and
/// gravity |g| = `g`. Where the repulsive law acts (`contact`), its strength must not be zero,
/// which the default 5|g|H (|g|H for Monaghan & Kajtar) is without gravity.
pub(super) fn wall_params(
    ctx: &Ctx<'_>,
    set: &WallSettings,
    dx: f64,
    height: f64,
    g: f64,
    contact: bool,
) -> Result<WallParams, CaseError> {
    let mut walls = WallParams::defaults(dx, height, g);
    walls.ghost_correction = set.ghost_correction;
    if let Some(d) = set.repulsive_d {
        walls.repulsive_d = d;
    }
    if let Some(r0) = set.repulsive_r0 {
        walls.repulsive_r0 = r0;
    }
    walls.repulsive_form = set.repulsive_form;
    if let Some(k) = set.repulsive_k {
        walls.repulsive_k = k;
    }
    walls.repulsive_beta = set.repulsive_beta;
    walls.friction = set.friction;
    walls.friction_slip = set.friction_slip;
    walls.friction_pairs = set.friction_pairs.clone();
    let (field, strength) = match walls.repulsive_form {
        RepulsiveForm::LennardJones => ("walls.repulsive_d_m2_s2", walls.repulsive_d),
        RepulsiveForm::MonaghanKajtar => ("walls.repulsive_k_m2_s2", walls.repulsive_k),
    };
    if contact && strength <= 0.0 {
        return Err(ctx.err(
            field,
            None,
            "defaults to a multiple of |g|·H, which is 0 since physics.gravity_m_s2 is zero: the \
             repulsive law that keeps fluid off repulsive walls and bodies, solids and walls apart \
             would have no strength",
            format!(
                "give {field}, of the order of the square of the fastest velocity expected \
                 (Monaghan 1994), e.g. {} = 1.0, or a non-zero physics.gravity_m_s2",
                field.trim_start_matches("walls.")
            ),
        ));
    }
    Ok(walls)
}

/// Height of the fluid from its lowest to its highest particle (+ dx), the H of the default
/// repulsive-wall strength D = 5 g H (Monaghan 1994: D of the order of the largest v², 2 g H
/// for water falling H). Without fluid, the height of the highest elastic-solid particle above
/// the lowest particle of any kind (the floor): what a solid falls at most.
fn highest_column(particles: &[Particle], dim: usize, dx: f64) -> f64 {
    let up = dim - 1;
    let span = |of: &dyn Fn(Kind) -> bool| {
        particles
            .iter()
            .filter(|p| of(p.kind))
            .fold((f64::MAX, f64::MIN), |(lo, hi), p| {
                (lo.min(p.pos[up]), hi.max(p.pos[up]))
            })
    };
    let (lo, hi) = span(&|k| k == Kind::Fluid);
    if lo <= hi {
        return hi - lo + dx;
    }
    let (_, top) = span(&|k| matches!(k, Kind::Solid | Kind::SolidClamped));
    let (floor, _) = span(&|_| true);
    if floor <= top {
        top - floor + dx
    } else {
        dx
    }
}

/// The particle kind of a wall treatment (mirror walls have no particles of their own; their
/// kind is never used).
fn kind_of(t: Treatment) -> Kind {
    match t {
        Treatment::Dynamic => Kind::Wall,
        Treatment::Repulsive => Kind::Repulsive,
        Treatment::FixedGhost { no_slip: true } | Treatment::Mirror { no_slip: true } => {
            Kind::GhostNoSlip
        }
        Treatment::FixedGhost { no_slip: false } | Treatment::Mirror { no_slip: false } => {
            Kind::GhostFreeSlip
        }
    }
}

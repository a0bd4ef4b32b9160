//! `[[fill]]`: water poured at a seed until it stands at a level (docs/cases.md, "Fills"),
//! checked, and its lattice points found by `crate::generate::fill::flood` within what holds
//! the water (the tank, the domain, the terrain), around what takes its place (the ground,
//! obstacles, bodies, solids: the caller's `blocked`).

use std::path::Path;

use crate::generate::fill::{flood, IndexBox};
use crate::generate::footprint::Footprint;
use crate::generate::surface::Surface;

use super::check::{number, vector, Aabb, Bound};
use super::error::{num, CaseError};
use super::limits::{self, ParticleBudget};
use super::locate::Ctx;
use super::schema::RawFill;
use super::surface::{placed, MeshFields};
use crate::generate::lattice::Lattice;

/// Most lattice points a fill's box may hold (one bit each while the water spreads: 512 MiB).
const MAX_BOX_POINTS: u64 = 1 << 32;

/// A fill, checked: where its water is and the level it stands at.
#[derive(Debug, Clone)]
pub(super) struct Fill {
    /// Its place among the file's `[[fill]]` tables, as messages name it.
    pub index: usize,
    pub region: Region,
    /// The water's top; a mesh's water may be left without one (all of the inside).
    pub level: Option<f64>,
}

/// Where a fill's water goes.
#[derive(Debug, Clone)]
pub(super) enum Region {
    /// Spread from this point through what is open, below the level.
    Seed([f64; 3]),
    /// Inside a closed mesh (by its winding number); how many of its edges are open.
    Mesh(Box<Surface>, usize),
    /// Over a polygon in x–y, below the level.
    Prism(Footprint),
}

impl Fill {
    /// A point of the water's region, for a lattice that needs one.
    pub(super) fn anchor(&self) -> [f64; 3] {
        match &self.region {
            Region::Seed(s) => *s,
            Region::Mesh(m, _) => m.bounds().0,
            Region::Prism(f) => {
                let ([x, y], _) = f.bounds();
                [x, y, 0.0]
            }
        }
    }

    /// The height the water's lattice is topped at: the level, else the mesh's top.
    pub(super) fn top(&self) -> f64 {
        match (&self.region, self.level) {
            (_, Some(l)) => l,
            (Region::Mesh(m, _), None) => m.bounds().1[2],
            (_, None) => 0.0,
        }
    }
}

/// `[[fill]]`: each a seed, a mesh or a polygon, with a finite level (a mesh's is optional).
pub(super) fn validate(
    ctx: &Ctx<'_>,
    raw: &[RawFill],
    (dim, dx): (usize, f64),
    case_dir: &Path,
) -> Result<Vec<Fill>, CaseError> {
    let checked: Vec<(Fill, bool)> =
        raw.iter()
            .enumerate()
            .map(|(i, f)| {
                let path = format!("fill[{i}]");
                let level = match f.level_m {
                    None => None,
                    Some(l) => Some(number(
                        ctx,
                        &format!("{path}.level_m"),
                        l,
                        Bound::Closed(-1e7, 1e7),
                        "the water's level, an elevation in m",
                        "give the level the water stands at",
                    )?),
                };
                let moved = f.scale.is_some() || f.rotate_deg.is_some() || f.translate_m.is_some();
                if moved && f.mesh.is_none() {
                    return Err(ctx.err(
                        &path,
                        None,
                        "scale, rotate_deg and translate_m place a fill's mesh, and it has none",
                        "remove them, or give the mesh they place",
                    ));
                }
                let region = match (&f.seed_m, &f.mesh, &f.polygon_m) {
                    (Some(seed), None, None) => Region::Seed(vector(
                        ctx,
                        &format!("{path}.seed_m"),
                        seed,
                        dim,
                        "the seed",
                    )?),
                    (None, Some(file), None) => {
                        three_d(ctx, &path, dim, "mesh")?;
                        let fields = MeshFields {
                            file,
                            scale: f.scale,
                            rotate_deg: f.rotate_deg.as_deref(),
                            translate_m: f.translate_m.as_deref(),
                        };
                        let (surface, edges) = placed(ctx, &path, &fields, (case_dir, dx, false))?;
                        Region::Mesh(Box::new(surface), edges.open)
                    }
                    (None, None, Some(polygon)) => {
                        three_d(ctx, &path, dim, "polygon_m")?;
                        Region::Prism(prism(ctx, &path, polygon)?)
                    }
                    (None, None, None) => {
                        return Err(ctx.err(
                            &format!("{path}.seed_m"),
                            None,
                            "is missing: a fill needs one place for its water, seed_m, mesh or \
                         polygon_m",
                            "give seed_m (water spread from a point), mesh (inside a closed mesh) \
                         or polygon_m (over a polygon), with level_m",
                        ))
                    }
                    _ => return Err(ctx.err(
                        &path,
                        None,
                        "has more than one place for its water: seed_m, mesh or polygon_m",
                        "give exactly one of seed_m (water spread from a point), mesh (inside a \
                         closed mesh) or polygon_m (over a polygon), with level_m",
                    )),
                };
                if level.is_none() && !matches!(region, Region::Mesh(..)) {
                    return Err(ctx.err(
                        &format!("{path}.level_m"),
                        None,
                        "is missing: the water stands at a level",
                        "add level_m = <elevation in m>",
                    ));
                }
                let fill = Fill {
                    index: i,
                    region,
                    level,
                };
                Ok((fill, f.enabled != Some(false)))
            })
            .collect::<Result<_, CaseError>>()?;
    // A fill left out is checked all the same, as a case with it would be.
    Ok((checked.into_iter())
        .filter_map(|(fill, enabled)| enabled.then_some(fill))
        .collect())
}

fn three_d(ctx: &Ctx<'_>, path: &str, dim: usize, field: &str) -> Result<(), CaseError> {
    if dim == 3 {
        return Ok(());
    }
    Err(ctx.err(
        &format!("{path}.{field}"),
        None,
        "outlines water in a 3D case; this case is 2D",
        "use seed_m, or a [[fluid_block]]",
    ))
}

/// `polygon_m`: three or more [x, y] corners of a polygon of non-zero area.
fn prism(ctx: &Ctx<'_>, path: &str, polygon: &[Vec<f64>]) -> Result<Footprint, CaseError> {
    let field = format!("{path}.polygon_m");
    let mut ring = Vec::with_capacity(polygon.len());
    for (k, corner) in polygon.iter().enumerate() {
        let c = vector(ctx, &format!("{field}[{k}]"), corner, 2, "a corner [x, y]")?;
        ring.push([c[0], c[1]]);
    }
    let corners = ring.len();
    let outline = Footprint {
        rings: vec![ring],
        height: None,
        feature: 0,
    };
    let area = outline.outline_area();
    if corners < 3 || area == 0.0 || !area.is_finite() {
        return Err(ctx.err(
            &field,
            None,
            format!("has {corners} corners and encloses no area"),
            "give three or more [x, y] corners of the water's outline",
        ));
    }
    Ok(outline)
}

/// A fill's water: its points, the box of their cells and what was noticed on the way.
#[derive(Debug, Clone)]
pub(super) struct Filled {
    pub points: Vec<[f64; 3]>,
    pub water: Aabb,
    pub notes: Vec<String>,
}

/// The lattice points of `fill` within `bound` whose cells lie below the level and where
/// no `blocked` names something: connected to the seed's point, inside the mesh, or over the
/// polygon. An error when that leaves no water (or a seed outside, above the level or
/// blocked), or when the water would hold more particles than `budget` (found as it
/// spreads).
pub(super) fn filled(
    ctx: &Ctx<'_>,
    fill: &Fill,
    lat: &Lattice,
    (bound, holder): (&Aabb, &str),
    (blocked, budget): (impl Fn([f64; 3]) -> Option<String>, &ParticleBudget),
) -> Result<Filled, CaseError> {
    let (dim, dx, v) = (lat.dim, lat.dx, lat.dim - 1);
    let path = format!("fill[{}]", fill.index);
    let mut below = *bound;
    below.max[v] = below.max[v].min(fill.top() - 0.5 * dx);
    let Some((lo, hi)) = lat.range_in(&below) else {
        return Err(ctx.err(
            &format!("{path}.level_m"),
            Some(num(fill.top())),
            format!(
                "leaves no water: no particle of spacing particles.dx_m = {} m fits below it \
                 inside {holder}",
                num(dx)
            ),
            "raise the level above the ground",
        ));
    };
    let index = IndexBox {
        lo: lo.map(|c| c as i64),
        hi: hi.map(|c| c as i64),
    };
    if index.points() > MAX_BOX_POINTS {
        return Err(ctx.err(
            &path,
            None,
            format!(
                "the water may spread over {} lattice points below the level inside {holder}, \
                 more than the {MAX_BOX_POINTS} a fill searches",
                index.points()
            ),
            "increase particles.dx_m, or bound the water with a smaller [domain] or tank",
        ));
    }
    let limit = budget.particles.min(1e15) as usize;
    let open = |p: [i64; 3]| blocked(lat.pos(p)).is_none();
    let (points, notes) = match &fill.region {
        Region::Seed(seed) => {
            let start = seed_point(
                ctx,
                (&path, *seed, fill.top()),
                lat,
                (&index, holder),
                &blocked,
            )?;
            (flood(&index, start, limit, open), Vec::new())
        }
        Region::Mesh(mesh, open_edges) => {
            // Refused before any point is visited: the water's volume in cells.
            let cells = mesh.signed_volume().abs() / dx.powi(3);
            limits::part_fits(ctx, (dx, dim), (path.as_str(), cells), budget)?;
            let (min, max) = mesh.bounds();
            let inside = lat
                .range_in(&Aabb { min, max })
                .map_or(Vec::new(), |(l, h)| {
                    let clip = IndexBox {
                        lo: [0, 1, 2].map(|a| (l[a] as i64).max(index.lo[a])),
                        hi: [0, 1, 2].map(|a| (h[a] as i64).min(index.hi[a])),
                    };
                    mesh.inside_points(lat.origin, dx, (clip.lo, clip.hi))
                });
            let notes = (*open_edges > 0)
                .then(|| {
                    format!(
                        "{path}.mesh is not closed ({open_edges} edges belong to one triangle \
                         only): its inside is taken where its winding number is ½ or more"
                    )
                })
                .into_iter()
                .collect();
            let water: Vec<[i64; 3]> = inside.into_iter().filter(|&p| open(p)).collect();
            if water.is_empty() {
                return Err(ctx.err(
                    &format!("{path}.mesh"),
                    None,
                    format!(
                        "holds no water of spacing particles.dx_m = {} m below the level, \
                         inside {holder} and clear of walls and bodies{}",
                        num(dx),
                        if *open_edges > 0 {
                            format!("; it is not closed ({open_edges} edges of one triangle)")
                        } else {
                            String::new()
                        }
                    ),
                    "give a closed mesh around the water (repair holes: MeshLab's 'close \
                     holes'), check its scale and place, or decrease particles.dx_m",
                ));
            }
            ((water.len() <= limit).then_some(water), notes)
        }
        Region::Prism(outline) => {
            // Refused before any point is visited: the prism's volume in cells.
            let height = fill.top() - bound.min[v];
            let cells = outline.outline_area() * height.max(0.0) / dx.powi(3);
            limits::part_fits(ctx, (dx, dim), (path.as_str(), cells), budget)?;
            let mut water = Vec::new();
            for p in index.iter() {
                let x = lat.pos(p);
                if outline.contains(x[0], x[1]) && open(p) {
                    water.push(p);
                    if water.len() > limit {
                        break;
                    }
                }
            }
            if water.is_empty() {
                return Err(ctx.err(
                    &format!("{path}.polygon_m"),
                    None,
                    format!("holds no water below the level inside {holder}, clear of the ground, walls and bodies"),
                    "draw the polygon over open ground, and the level above it",
                ));
            }
            ((water.len() <= limit).then_some(water), Vec::new())
        }
    };
    let Some(points) = points else {
        let water = format!("{path}'s water inside {holder}");
        let count = (water.as_str(), limit as f64);
        return Err(limits::too_many(ctx, (dx, dim), count, budget));
    };
    let points: Vec<[f64; 3]> = points.into_iter().map(|p| lat.pos(p)).collect();
    Ok(Filled {
        water: water_box(&points, dx, dim),
        points,
        notes,
    })
}

/// The lattice point of a seed fill's `seed`: inside the box `index`, under the level, and
/// open.
fn seed_point(
    ctx: &Ctx<'_>,
    (path, seed, level): (&str, [f64; 3], f64),
    lat: &Lattice,
    (index, holder): (&IndexBox, &str),
    blocked: &impl Fn([f64; 3]) -> Option<String>,
) -> Result<[i64; 3], CaseError> {
    let (dim, dx, v) = (lat.dim, lat.dx, lat.dim - 1);
    let seed_path = format!("{path}.seed_m");
    let seed_value = Some(format!("{:?}", &seed[..dim]));
    let mut at = [0i64; 3];
    for (a, s) in at.iter_mut().enumerate().take(dim) {
        *s = ((seed[a] - lat.origin[a]) / dx - 0.5).round() as i64;
    }
    if seed[v] > level {
        return Err(ctx.err(
            &seed_path,
            seed_value,
            format!("lies above the fill's level_m = {}", num(level)),
            "put the seed in the water: below level_m, above the ground",
        ));
    }
    if !index.contains(at) {
        return Err(ctx.err(
            &seed_path,
            seed_value,
            format!(
                "lies outside {holder}, or within half a spacing (particles.dx_m / 2 = {} m) of \
                 the level: the water has nowhere to start",
                num(0.5 * dx)
            ),
            "put the seed in the water: inside the tank (or domain), below level_m",
        ));
    }
    if let Some(what) = blocked(lat.pos(at)) {
        return Err(ctx.err(
            &seed_path,
            seed_value,
            format!(
                "lies in {what} (its nearest particle at particles.dx_m = {} m, at {:?}, is no \
                 place for water): the water has nowhere to start",
                num(dx),
                &lat.pos(at)[..dim]
            ),
            "put the seed in the open water, a few spacings above the ground and clear of \
             walls and bodies",
        ));
    }
    Ok(at)
}

/// The box of the cells of `points` (spacing `dx`).
pub(super) fn water_box(points: &[[f64; 3]], dx: f64, dim: usize) -> Aabb {
    let mut water = Aabb {
        min: [0.0; 3],
        max: [0.0; 3],
    };
    for a in 0..dim {
        water.min[a] = points.iter().map(|p| p[a]).fold(f64::INFINITY, f64::min) - 0.5 * dx;
        water.max[a] = points
            .iter()
            .map(|p| p[a])
            .fold(f64::NEG_INFINITY, f64::max)
            + 0.5 * dx;
    }
    water
}

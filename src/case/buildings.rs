//! `[[buildings]]`: buildings extruded from their footprints in a GeoJSON file (docs/cases.md,
//! "Buildings"), read and checked, and their wall particles on the case's lattice. The
//! footprints' reader and geometry are `crate::generate::footprint`'s.

use std::path::Path;

use crate::generate::footprint::{parse_geojson, Footprint, FootprintError};

use super::check::{number, particle_wall, read_bounded, support_layers, Aabb, Bound, Treatment};
use super::error::{num, CaseError};
use super::limits::{self, ParticleBudget};
use super::locate::Ctx;
use super::schema::RawBuildings;
use super::terrain::Terrain;
use crate::generate::lattice::{range_points, Lattice};

/// The largest footprint file: 1 GiB of GeoJSON.
const MAX_FILE_BYTES: u64 = 1 << 30;

/// A `[[buildings]]` table, checked: its footprints in the case's coordinates, each with its
/// height.
#[derive(Debug, Clone)]
pub(super) struct Buildings {
    pub footprints: Vec<Footprint>,
    pub wall: Treatment,
    pub layers: u32,
    /// The file as the case gives it, for messages.
    pub file: String,
}

/// `[[buildings]]` of a 3D case, each file read relative to `case_dir`, its footprints moved
/// by −`origin` (the terrain's).
pub(super) fn validate(
    ctx: &Ctx<'_>,
    raw: &[RawBuildings],
    (dim, h_over_dx): (usize, f64),
    case_dir: &Path,
    origin: [f64; 3],
) -> Result<Vec<Buildings>, CaseError> {
    let mut out = Vec::with_capacity(raw.len());
    for (i, b) in raw.iter().enumerate() {
        let path = format!("buildings[{i}]");
        if dim != 3 {
            return Err(ctx.err(
                &path,
                None,
                "buildings stand in a 3D case; this case is 2D",
                "set dimension = 3, or draw a 2D building as an [[obstacle]]",
            ));
        }
        let wall = particle_wall(ctx, &path, (b.wall, b.slip), "buildings")?;
        let layers = support_layers(ctx, &path, b.layers, h_over_dx)?;
        let default = match b.default_height_m {
            None => None,
            Some(h) => Some(number(
                ctx,
                &format!("{path}.default_height_m"),
                h,
                Bound::Positive,
                "the height of a building whose feature gives none, in m",
                "give a positive height in metres",
            )?),
        };
        let key = b.height_property.as_deref().unwrap_or("height");
        let footprints = read(ctx, &path, &b.file, case_dir, key)?;
        let mut resolved = Vec::with_capacity(footprints.len());
        for f in footprints {
            let height = f.height.or(default);
            if height.is_none() {
                return Err(ctx.err(
                    &format!("{path}.file"),
                    Some(format!("{:?}", b.file)),
                    format!(
                        "feature {} has no height: no property {key:?}, and no \
                         default_height_m",
                        f.feature
                    ),
                    format!(
                        "add default_height_m = <m> to {path}, or name the height's property \
                         with height_property"
                    ),
                ));
            }
            resolved.push(Footprint { height, ..f }.shifted(origin));
        }
        out.push(Buildings {
            footprints: resolved,
            wall,
            layers,
            file: b.file.clone(),
        });
    }
    Ok(out)
}

/// The footprints in `file`.
fn read(
    ctx: &Ctx<'_>,
    path: &str,
    file: &str,
    case_dir: &Path,
    key: &str,
) -> Result<Vec<Footprint>, CaseError> {
    let full = case_dir.join(file);
    let refuse = |problem: String, fix: String| {
        ctx.err(
            &format!("{path}.file"),
            Some(format!("{file:?}")),
            format!("{}: {problem}", full.display()),
            fix,
        )
    };
    match std::fs::metadata(&full) {
        Ok(m) if m.is_file() => {}
        Ok(_) => {
            return Err(refuse(
                "is not a regular file".into(),
                "give the GeoJSON file".into(),
            ))
        }
        Err(e) => {
            return Err(refuse(
                e.to_string(),
                "give the path of the GeoJSON file relative to the case file".into(),
            ))
        }
    }
    let text = read_bounded(&full, MAX_FILE_BYTES)
        .map_err(|e| refuse(e.to_string(), "give a GeoJSON file (text)".into()))?;
    parse_geojson(&text, key).map_err(
        |FootprintError {
             feature,
             problem,
             fix,
         }| {
            let problem = match feature {
                Some(f) => format!("feature {f} {problem}"),
                None => problem,
            };
            refuse(problem, fix)
        },
    )
}

/// The buildings' wall particles on the lattice, and what keeps water out of them.
#[derive(Debug, Clone, Default)]
pub(super) struct Raised {
    /// Each particle's place and treatment.
    pub points: Vec<([f64; 3], Treatment)>,
    /// Each building standing in the model: its table, footprint and the top of its roof's
    /// particles' cells.
    pub standing: Vec<(usize, usize, f64)>,
    /// The box of the particles.
    pub bounds: Option<Aabb>,
    /// What a warning should say: footprints left out.
    pub notes: Vec<String>,
}

/// Where the buildings stand: the ground (`terrain`, else a flat floor at `floor`) and the
/// columns of the model (`clip`, x and y).
pub(super) struct Site<'a> {
    pub terrain: Option<&'a Terrain>,
    pub floor: Option<f64>,
    pub clip: ([f64; 2], [f64; 2]),
}

/// Each building of `tables` raised on the lattice: a footprint's columns (centres inside it
/// and the clip) hold its walls (within `layers` spacings of the outline) from `layers`
/// spacings under the lowest ground beneath it up to its roof, the ground's mean elevation
/// beneath it plus its height; the columns further in hold the roof's `layers` layers. An
/// error as soon as they hold more particles than `budget`.
pub(super) fn raise(
    ctx: &Ctx<'_>,
    tables: &[Buildings],
    lat: &Lattice,
    site: &Site<'_>,
    budget: &ParticleBudget,
) -> Result<Raised, CaseError> {
    let dx = lat.dx;
    let mut raised = Raised::default();
    for (i, b) in tables.iter().enumerate() {
        let mut left_out = 0;
        for (j, f) in b.footprints.iter().enumerate() {
            let columns = columns(f, lat, site.clip, |n| {
                let count = ("the buildings", raised.points.len() as f64 + n);
                limits::part_fits(ctx, (dx, 3), count, budget)
            })?;
            let ground: Vec<f64> = columns
                .iter()
                .map(|c| match site.terrain {
                    Some(t) => t.grid.elevation(c[0], c[1]),
                    None => site.floor.unwrap_or(0.0),
                })
                .collect();
            if columns.is_empty() {
                left_out += 1;
                continue;
            }
            let lowest = ground.iter().copied().fold(f64::INFINITY, f64::min);
            let mean = ground.iter().sum::<f64>() / ground.len() as f64;
            let roof = mean + f.height.unwrap_or(0.0);
            let depth = f64::from(b.layers) * dx;
            let bottom = match (site.terrain, site.floor) {
                (Some(_), Some(floor)) => (lowest - depth).max(floor),
                (Some(_), None) => lowest - depth,
                (None, _) => lowest,
            };
            let z = |height: f64| lat.origin[2] + height;
            // The layers' indices, the wall's full height counted against the budget before any
            // is made (and kept within the lattice's index range: a building that far away is
            // refused by the domain's check).
            let lo = ((bottom - lat.origin[2]) / dx - 0.5).ceil();
            let hi = ((roof - lat.origin[2]) / dx - 1.0 + 1e-9).floor();
            // (NaN: no layer either.)
            if hi.partial_cmp(&lo).is_none_or(|o| o.is_lt()) {
                left_out += 1;
                continue;
            }
            let at_most = raised.points.len() as f64 + columns.len() as f64 * (hi - lo + 1.0);
            let part = match site.terrain {
                // Their heights count from the ground's elevations, less terrain.origin_m's.
                Some(_) => "the buildings (on the terrain's elevations less terrain.origin_m)",
                None => "the buildings",
            };
            limits::part_fits(ctx, (dx, 3), (part, at_most), budget)?;
            let (k_lo, k_hi) = (lo.clamp(-1e15, 1e15) as i64, hi.clamp(-1e15, 1e15) as i64);
            let roof_layers = (k_hi - b.layers as i64 + 1).max(k_lo);
            for c in &columns {
                let wall = f.distance_to_outline(c[0], c[1]) < depth;
                let from = if wall { k_lo } else { roof_layers };
                for k in from..=k_hi {
                    let p = [c[0], c[1], z((k as f64 + 0.5) * dx)];
                    raised.points.push((p, b.wall));
                }
            }
            let top = z((k_hi as f64 + 1.0) * dx);
            raised.standing.push((i, j, top));
            let (min, max) = f.bounds();
            let bx = Aabb {
                min: [min[0], min[1], z((k_lo as f64) * dx)],
                max: [max[0], max[1], top],
            };
            raised.bounds = Some(match raised.bounds {
                None => bx,
                Some(b) => Aabb {
                    min: [0, 1, 2].map(|a| b.min[a].min(bx.min[a])),
                    max: [0, 1, 2].map(|a| b.max[a].max(bx.max[a])),
                },
            });
        }
        let n = b.footprints.len();
        if left_out == n {
            let (min, max) = extent(&b.footprints);
            return Err(ctx.err(
                &format!("buildings[{i}].file"),
                Some(format!("{:?}", b.file)),
                format!(
                    "none of its {n} footprints covers a particle column of the model: they \
                     span x {} to {} m, y {} to {} m in the case's coordinates, the model (the \
                     tank's inner box tank.min_m to tank.max_m, the domain and the terrain) x {} \
                     to {} m, y {} to {} m",
                    num(min[0]),
                    num(max[0]),
                    num(min[1]),
                    num(max[1]),
                    num(site.clip.0[0]),
                    num(site.clip.1[0]),
                    num(site.clip.0[1]),
                    num(site.clip.1[1]),
                ),
                "give the footprints in the terrain's coordinates (GeoJSON in longitude and \
                 latitude must be projected to them first: ogr2ogr -t_srs EPSG:<the grid's>), \
                 or footprints wider than particles.dx_m",
            ));
        }
        if left_out > 0 {
            raised.notes.push(format!(
                "buildings[{i}]: {left_out} of the {n} footprints of {} cover no particle column \
                 of the model (outside the tank, the domain or the terrain, or narrower than \
                 particles.dx_m) and are left out",
                b.file
            ));
        }
    }
    Ok(raised)
}

/// The lattice's columns (centres, z unused) inside the footprint and the clip; `fits` judges
/// the number of columns of its box first (each column holds a particle at least).
fn columns(
    f: &Footprint,
    lat: &Lattice,
    clip: ([f64; 2], [f64; 2]),
    fits: impl Fn(f64) -> Result<(), CaseError>,
) -> Result<Vec<[f64; 3]>, CaseError> {
    let (min, max) = f.bounds();
    let z0 = lat.origin[2];
    let b = Aabb {
        min: [min[0].max(clip.0[0]), min[1].max(clip.0[1]), z0],
        max: [max[0].min(clip.1[0]), max[1].min(clip.1[1]), z0 + lat.dx],
    };
    let Some((lo, hi)) = lat.range_in(&b) else {
        return Ok(Vec::new());
    };
    fits((hi[0] - lo[0] + 1.0) * (hi[1] - lo[1] + 1.0))?;
    Ok(range_points(lat, lo, hi)
        .map(|idx| lat.pos(idx))
        .filter(|p| f.contains(p[0], p[1]))
        .collect())
}

/// The box of all the footprints, (min, max).
fn extent(footprints: &[Footprint]) -> ([f64; 2], [f64; 2]) {
    footprints.iter().map(Footprint::bounds).fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(lo, hi), (a, b)| {
            (
                [lo[0].min(a[0]), lo[1].min(a[1])],
                [hi[0].max(b[0]), hi[1].max(b[1])],
            )
        },
    )
}

impl Raised {
    /// The building whose footprint holds (x, y) and whose particles' cells reach above `z`
    /// less half a spacing: no place for water. (table, footprint).
    pub(super) fn at(&self, tables: &[Buildings], p: [f64; 3], dx: f64) -> Option<(usize, usize)> {
        self.standing
            .iter()
            .find(|(i, j, top)| {
                p[2] < top + 0.5 * dx * (1.0 - 1e-9)
                    && tables[*i].footprints[*j].contains(p[0], p[1])
            })
            .map(|(i, j, _)| (*i, *j))
    }

    /// Whether (x, y) lies in a standing building's footprint.
    pub(super) fn covers(&self, tables: &[Buildings], x: f64, y: f64) -> bool {
        self.standing
            .iter()
            .any(|(i, j, _)| tables[*i].footprints[*j].contains(x, y))
    }
}

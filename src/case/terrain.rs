//! `[terrain]`: the ground from an elevation grid file (docs/cases.md, "Terrain"), read and
//! checked field by field. The grid's geometry (the readers of the files' formats, the surface,
//! the wall's columns) is `crate::generate::terrain`'s and `crate::generate::geotiff`'s; this
//! file names the field and the fix.

use std::path::Path;

use crate::generate::geotiff::parse_geotiff;
use crate::generate::terrain::{parse_asc, Column, ElevationGrid, GridError, NodataRule};

use super::check::{
    number, particle_wall, read_bounded, read_bytes_bounded, support_layers, vector, Aabb, Bound,
    Treatment,
};
use super::error::{num, CaseError};
use super::limits::{self, ParticleBudget};
use super::locate::Ctx;
use super::schema::{NodataName, RawTerrain};
use crate::generate::lattice::{range_points, Lattice};

/// The largest grid file: 2 GiB (a 10 000 × 10 000 ESRI ASCII grid at up to 20 characters a
/// value; a GeoTIFF of the most cells a grid may have, as f64, is 1.2 GB).
const MAX_FILE_BYTES: u64 = 2 << 30;

/// The ground, checked: its grid in the case's coordinates and its wall.
#[derive(Debug, Clone)]
pub(super) struct Terrain {
    /// The grid, moved by −`origin`: every elevation given.
    pub grid: ElevationGrid,
    /// The world coordinates of the case's (0, 0, 0).
    pub origin: [f64; 3],
    pub wall: Treatment,
    /// Wall-particle layers across the surface.
    pub layers: u32,
}

/// `[terrain]` of a 3D case: the grid read relative to `case_dir`, with its cells without
/// data filled as `nodata` says; the wall's treatment and layers (by default enough to cover
/// the kernel support 2h).
pub(super) fn terrain(
    ctx: &Ctx<'_>,
    raw: Option<&RawTerrain>,
    dim: usize,
    h_over_dx: f64,
    case_dir: &Path,
) -> Result<Option<Terrain>, CaseError> {
    let Some(t) = raw else {
        return Ok(None);
    };
    if dim != 3 {
        return Err(ctx.err(
            "terrain",
            None,
            "a terrain is the ground under a 3D case; this case is 2D",
            "set dimension = 3, or draw a 2D ground as [[obstacle]] boxes or a polygon body",
        ));
    }
    let wall = particle_wall(ctx, "terrain", (t.wall, t.slip), "a ground")?;
    let layers = support_layers(ctx, "terrain", t.layers, h_over_dx)?;
    let rule = nodata(ctx, t)?;
    let grid = read_grid(ctx, &t.file, case_dir)?
        .filled(rule)
        .map_err(|e| grid_error(ctx, &t.file, case_dir, e))?;
    let (sw, _) = grid.extent();
    let origin = match &t.origin_m {
        None => [sw[0], sw[1], 0.0],
        Some(o) => vector(
            ctx,
            "terrain.origin_m",
            o,
            3,
            "the world point at the case's origin",
        )?,
    };
    let grid = grid.shifted(origin);
    check_near_origin(ctx, &grid, origin)?;
    Ok(Some(Terrain {
        grid,
        origin,
        wall,
        layers,
    }))
}

/// `terrain.nodata` and `terrain.nodata_elevation_m`, together.
fn nodata(ctx: &Ctx<'_>, t: &RawTerrain) -> Result<NodataRule, CaseError> {
    match (t.nodata.unwrap_or(NodataName::Refuse), t.nodata_elevation_m) {
        (NodataName::Elevation, Some(e)) => Ok(NodataRule::Elevation(number(
            ctx,
            "terrain.nodata_elevation_m",
            e,
            Bound::Closed(-1e7, 1e7),
            "the elevation given to cells without data, in m",
            "give an elevation in metres",
        )?)),
        (NodataName::Elevation, None) => Err(ctx.err(
            "terrain.nodata",
            Some("\"elevation\"".into()),
            "needs the elevation to give: terrain.nodata_elevation_m is missing",
            "add nodata_elevation_m = <m>, or set nodata = \"nearest\"",
        )),
        (_, Some(e)) => Err(ctx.err(
            "terrain.nodata_elevation_m",
            Some(num(e)),
            "is only used with nodata = \"elevation\"",
            "set nodata = \"elevation\", or remove nodata_elevation_m",
        )),
        (NodataName::Refuse, None) => Ok(NodataRule::Refuse),
        (NodataName::Nearest, None) => Ok(NodataRule::Nearest),
    }
}

/// The formats a terrain is read from.
enum GridFormat {
    /// ESRI ASCII grid (`.asc`).
    Asc,
    /// Single-band GeoTIFF (`.tif`, `.tiff`).
    GeoTiff,
}

/// The grid in `file` (relative to `case_dir`), by its extension.
/// How far from the case's origin a terrain may lie, m: f32 positions there are still good to
/// 0.06 m (a finer case wants a nearer origin; one further off is a wrong `origin_m`).
const MAX_FROM_ORIGIN_M: f64 = 1e6;

/// The grid moved by −`origin` must lie within [`MAX_FROM_ORIGIN_M`] of the case's origin in
/// plan and elevation: `terrain.origin_m` far from the grid (another datum, a typo, a value of
/// 10¹⁸) puts the ground where no water, wall or domain of the case is, and the errors it would
/// cause later would name another field.
fn check_near_origin(
    ctx: &Ctx<'_>,
    grid: &ElevationGrid,
    origin: [f64; 3],
) -> Result<(), CaseError> {
    let (sw, ne) = grid.extent();
    let (lo, hi) = (grid.z.iter()).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &z| {
        (lo.min(z), hi.max(z))
    });
    let far = [sw[0], sw[1], ne[0], ne[1], lo, hi]
        .iter()
        .map(|v| v.abs())
        .fold(0.0, f64::max);
    if far <= MAX_FROM_ORIGIN_M {
        return Ok(());
    }
    Err(ctx.err(
        "terrain.origin_m",
        Some(format!(
            "[{}, {}, {}]",
            num(origin[0]),
            num(origin[1]),
            num(origin[2])
        )),
        format!(
            "puts the grid {} m from the case's origin (the case's coordinates are the world's \
             minus origin_m), more than {} m",
            num(far),
            num(MAX_FROM_ORIGIN_M)
        ),
        "give a world point near the grid, in its units and datum (by default its south-west \
         corner at elevation 0)",
    ))
}

fn read_grid(ctx: &Ctx<'_>, file: &str, case_dir: &Path) -> Result<ElevationGrid, CaseError> {
    let full = case_dir.join(file);
    let refuse = |problem: String, fix: &str| {
        ctx.err(
            "terrain.file",
            Some(format!("{file:?}")),
            format!("{}: {problem}", full.display()),
            fix,
        )
    };
    let extension = full
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let format =
        match extension.as_deref() {
            Some("asc") => GridFormat::Asc,
            Some("tif" | "tiff") => GridFormat::GeoTiff,
            _ => return Err(refuse(
                "is neither an ESRI ASCII grid (.asc) nor a GeoTIFF (.tif, .tiff), the formats \
                 a terrain is read from"
                    .into(),
                "export the elevation grid as a GeoTIFF or an ESRI ASCII grid (gdal_translate \
                 -of GTiff in out.tif, or gdal_translate -of AAIGrid in out.asc)",
            )),
        };
    match std::fs::metadata(&full) {
        Ok(m) if m.is_file() => {}
        Ok(_) => {
            return Err(refuse(
                "is not a regular file".into(),
                "give the grid's file",
            ))
        }
        Err(e) => {
            return Err(refuse(
                e.to_string(),
                "give the path of the grid relative to the case file",
            ))
        }
    }
    let grid = match format {
        GridFormat::Asc => {
            let text = read_bounded(&full, MAX_FILE_BYTES).map_err(|e| {
                refuse(
                    e.to_string(),
                    "give an ESRI ASCII grid (text); resample a larger one coarser",
                )
            })?;
            parse_asc(&text)
        }
        GridFormat::GeoTiff => {
            let bytes = read_bytes_bounded(&full, MAX_FILE_BYTES).map_err(|e| {
                refuse(
                    e.to_string(),
                    "give a GeoTIFF elevation grid; resample a larger one coarser (gdalwarp -tr)",
                )
            })?;
            parse_geotiff(&bytes)
        }
    };
    grid.map_err(|e| grid_error(ctx, file, case_dir, e))
}

/// The grid's error, at `terrain.file` with the file and line.
fn grid_error(ctx: &Ctx<'_>, file: &str, case_dir: &Path, e: GridError) -> CaseError {
    let place = match e.line {
        Some(l) => format!("{}, line {l}", case_dir.join(file).display()),
        None => case_dir.join(file).display().to_string(),
    };
    ctx.err(
        "terrain.file",
        Some(format!("{file:?}")),
        format!("{place}: {}", e.problem),
        e.fix,
    )
}

/// The terrain's wall on the case's lattice: the columns whose centres lie over the grid,
/// inside the tank and the given domain (the clip), and what they hold.
#[derive(Debug, Clone, Copy)]
pub(super) struct Ground {
    /// The first and last lattice index of the columns along x and y (z: 0).
    lo: [f64; 3],
    hi: [f64; 3],
    /// Where the ground keeps fluid out, along x and y: the clip.
    clip: ([f64; 2], [f64; 2]),
    /// The wall particles (an upper bound: the points in obstacles are left out).
    pub count: f64,
    /// The box of the wall particles, the surface on top.
    pub bounds: Aabb,
}

impl Ground {
    /// The ground of `terrain` on `lat`, clipped in plan to `holder` (what holds the water:
    /// the tank's inner box cut by the domain) when given; an error when no column is left, or
    /// when its columns alone hold more particles than `budget` (checked before they are
    /// counted).
    pub(super) fn of(
        ctx: &Ctx<'_>,
        terrain: &Terrain,
        lat: &Lattice,
        holder: Option<&Aabb>,
        budget: &ParticleBudget,
    ) -> Result<Ground, CaseError> {
        let (mut min, mut max) = terrain.grid.extent();
        if let Some(b) = holder {
            for a in 0..2 {
                min[a] = min[a].max(b.min[a]);
                max[a] = max[a].min(b.max[a]);
            }
        }
        // Columns beyond the budget are refused before any is counted (at a tiny dx the index
        // range itself overflows).
        let across = (0..2).map(|a| ((max[a] - min[a]) / lat.dx).max(0.0) + 1.0);
        let layers = f64::from(terrain.layers);
        let at_least = ("the terrain", across.product::<f64>() * layers);
        limits::part_fits(ctx, (lat.dx, 3), at_least, budget)?;
        // The lattice's columns within the clip: the range of points of a box one spacing
        // high at the lattice's origin (z index 0).
        let z0 = lat.origin[2];
        let columns = Aabb {
            min: [min[0], min[1], z0],
            max: [max[0], max[1], z0 + lat.dx],
        };
        let Some((lo, hi)) = lat.range_in(&columns) else {
            let (gmin, gmax) = terrain.grid.extent();
            return Err(ctx.err(
                "terrain.file",
                None,
                format!(
                    "the grid covers x {} to {} m, y {} to {} m in the case's coordinates \
                     (world minus terrain.origin_m), and no particle column of spacing \
                     particles.dx_m = {} m lies over it{}",
                    num(gmin[0]),
                    num(gmax[0]),
                    num(gmin[1]),
                    num(gmax[1]),
                    num(lat.dx),
                    if holder.is_some() {
                        " inside the tank and the domain"
                    } else {
                        ""
                    }
                ),
                "give the tank, the fluid and the domain in the case's coordinates (world \
                 minus terrain.origin_m, by default the grid's south-west corner)",
            ));
        };
        let mut ground = Ground {
            lo,
            hi,
            clip: (min, max),
            count: 0.0,
            bounds: Aabb {
                min: [min[0], min[1], f64::INFINITY],
                max: [max[0], max[1], f64::NEG_INFINITY],
            },
        };
        for (_, c) in ground.columns(terrain, lat) {
            ground.count += c.count as f64;
            ground.bounds.min[2] = ground.bounds.min[2].min(c.bottom(lat.dx) - 0.5 * lat.dx);
            ground.bounds.max[2] = ground.bounds.max[2].max(c.surface);
        }
        Ok(ground)
    }

    /// Each column's centre (x, y; z is the lattice origin's) and its wall particles.
    pub(super) fn columns<'a>(
        &self,
        terrain: &'a Terrain,
        lat: &'a Lattice,
    ) -> impl Iterator<Item = ([f64; 3], Column)> + 'a {
        range_points(lat, self.lo, self.hi).map(move |idx| {
            let p = lat.pos(idx);
            let column = terrain.grid.column(p[0], p[1], lat.dx, terrain.layers);
            (p, column)
        })
    }

    /// The columns' extent along x and y, (min, max).
    pub(super) fn clip(&self) -> ([f64; 2], [f64; 2]) {
        self.clip
    }

    /// Whether `p` lies over the ground's clip.
    fn over(&self, p: [f64; 3]) -> bool {
        let (min, max) = self.clip;
        (0..2).all(|a| min[a] <= p[a] && p[a] <= max[a])
    }

    /// Whether `p` lies over the ground's clip and less than `clearance` above the surface
    /// (to rounding): no place for fluid.
    pub(super) fn below(&self, terrain: &Terrain, p: [f64; 3], clearance: f64) -> bool {
        self.over(p) && p[2] < terrain.grid.elevation(p[0], p[1]) + clearance * (1.0 - 1e-9)
    }

    /// Rests a lattice column of fluid on the ground: `column`, one column's fluid points from
    /// the bottom up, moves as a whole so that its lowest point lies half a spacing above the
    /// surface, as above a tank's floor (the lattice leaves a gap of up to a spacing more,
    /// which the water would fall across and bounce on for seconds). It moves down when
    /// the gap is half a spacing or less, else up, with a point added below where `open`
    /// allows, so the column's water stays within half a spacing of its height. A column not
    /// over the ground, or not resting on it (its lowest point a spacing or more above the
    /// surface: on an obstacle, say), stays.
    pub(super) fn settle(
        &self,
        terrain: &Terrain,
        column: &mut Vec<[f64; 3]>,
        dx: f64,
        open: impl Fn([f64; 3]) -> bool,
    ) {
        let Some(&lowest) = column.first().filter(|p| self.over(**p)) else {
            return;
        };
        let rest = terrain.grid.elevation(lowest[0], lowest[1]) + 0.5 * dx;
        let gap = lowest[2] - rest;
        if !(1e-9 * dx..dx * (1.0 - 1e-9)).contains(&gap) {
            return;
        }
        if gap <= 0.5 * dx {
            column.iter_mut().for_each(|p| p[2] -= gap);
        } else {
            column.iter_mut().for_each(|p| p[2] += dx - gap);
            let below = [lowest[0], lowest[1], rest];
            if open(below) {
                column.insert(0, below);
            }
        }
        column.retain(|p| open(*p));
    }

    /// [`Self::settle`] on each column of `points` (lattice points in the lattice's order:
    /// a column's points follow each other, bottom up).
    pub(super) fn settle_all(
        &self,
        terrain: &Terrain,
        points: Vec<[f64; 3]>,
        dx: f64,
        open: impl Fn([f64; 3]) -> bool,
    ) -> Vec<[f64; 3]> {
        let mut settled = Vec::with_capacity(points.len());
        for column in points.chunk_by(|a, b| a[0] == b[0] && a[1] == b[1]) {
            let mut column = column.to_vec();
            self.settle(terrain, &mut column, dx, &open);
            settled.extend(column);
        }
        settled
    }
}

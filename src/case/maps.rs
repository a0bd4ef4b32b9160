//! `[maps]`: flood maps over a plan grid (docs/cases.md "Flood maps"), checked against the case
//! (3D, cells of at least dx, an area inside the domain, a grid the GPU can hold), and the
//! ground under each cell found from the fixed walls' particles once they are built.

use crate::scenario::{Body, Domain, FloodMaps, Particle};

use super::check::{number, vector, Bound};
use super::error::{num, CaseError};
use super::locate::Ctx;
use super::schema::RawMaps;

/// The most cells a map grid may have: its records (32 bytes a cell) then fit the 128 MiB
/// storage binding every adapter offers (lavapipe's default).
pub const MAX_MAP_CELLS: usize = (128 << 20) / 32;

/// A checked `[maps]` table, its defaults (the domain's plan, cells of 2 dx, a wet depth of dx)
/// taken when the domain is known (`resolve`).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct MapsSpec {
    pub cell: Option<f64>,
    pub min: Option<[f64; 2]>,
    pub max: Option<[f64; 2]>,
    pub wet_depth: Option<f64>,
}

pub(super) fn validate(
    ctx: &Ctx<'_>,
    raw: Option<&RawMaps>,
    dim: usize,
    dx: f64,
) -> Result<Option<MapsSpec>, CaseError> {
    let Some(raw) = raw else {
        return Ok(None);
    };
    if dim != 3 {
        return Err(ctx.err(
            "maps",
            None,
            "flood maps are plan grids of a 3D case",
            "remove [maps]; in 2D a wave gauge ([[probe]] kind = \"height\") gives the depth",
        ));
    }
    let cell = match raw.cell_m {
        Some(c) => Some(number(
            ctx,
            "maps.cell_m",
            c,
            Bound::Positive,
            "the cells' size in metres",
            "give a size of a few particles.dx_m, e.g. 2 dx",
        )?),
        None => None,
    };
    if let Some(c) = cell.filter(|&c| c < dx) {
        return Err(ctx.err(
            "maps.cell_m",
            Some(num(c)),
            format!("is smaller than particles.dx_m = {} (a cell finer than the particles maps nothing they resolve)", num(dx)),
            format!("use cell_m = {} or more", num(dx)),
        ));
    }
    let corner = |field: &str, v: &Option<Vec<f64>>| -> Result<Option<[f64; 2]>, CaseError> {
        v.as_ref()
            .map(|v| {
                let what = "a point in plan in metres";
                let p = vector(ctx, &format!("maps.{field}"), v, 2, what)?;
                Ok([p[0], p[1]])
            })
            .transpose()
    };
    let wet_depth = match raw.wet_depth_m {
        Some(d) => Some(number(
            ctx,
            "maps.wet_depth_m",
            d,
            Bound::Positive,
            "the depth of arrival in metres",
            "give a depth such as 0.01",
        )?),
        None => None,
    };
    Ok(Some(MapsSpec {
        cell,
        min: corner("min_m", &raw.min_m)?,
        max: corner("max_m", &raw.max_m)?,
        wet_depth,
    }))
}

/// The maps of `spec` over `domain`: the grid, and the ground under each cell's centre from
/// `particles` (`ground_under`).
pub(super) fn resolve(
    ctx: &Ctx<'_>,
    spec: &MapsSpec,
    domain: &Domain,
    (particles, bodies): (&[Particle], &[Body]),
    dx: f64,
) -> Result<FloodMaps, CaseError> {
    let min = spec.min.unwrap_or([domain.min[0], domain.min[1]]);
    let max = spec.max.unwrap_or([domain.max[0], domain.max[1]]);
    let extent = format!(
        "[{}, {}] × [{}, {}]",
        num(domain.min[0]),
        num(domain.max[0]),
        num(domain.min[1]),
        num(domain.max[1])
    );
    for (field, p) in [("min_m", min), ("max_m", max)] {
        let inside = (0..2).all(|a| domain.min[a] <= p[a] && p[a] <= domain.max[a]);
        if !inside {
            return Err(ctx.err(
                &format!("maps.{field}"),
                Some(format!("[{}, {}]", num(p[0]), num(p[1]))),
                format!("lies outside the domain's plan {extent}"),
                "give a corner inside the domain, or leave it out to map the whole domain",
            ));
        }
    }
    if (0..2).any(|a| min[a] >= max[a]) {
        return Err(ctx.err(
            "maps.max_m",
            Some(format!("[{}, {}]", num(max[0]), num(max[1]))),
            format!(
                "must lie north-east of maps.min_m = [{}, {}]",
                num(min[0]),
                num(min[1])
            ),
            "give max_m greater than min_m along x and y",
        ));
    }
    let cell = spec.cell.unwrap_or(2.0 * dx);
    let [nx, ny] = [0, 1].map(|a| (((max[a] - min[a]) / cell) - 1e-9).ceil().max(1.0) as usize);
    if nx.saturating_mul(ny) > MAX_MAP_CELLS {
        let area = (max[0] - min[0]) * (max[1] - min[1]);
        return Err(ctx.err(
            "maps.cell_m",
            Some(num(cell)),
            format!(
                "makes {nx} × {ny} cells, more than the {MAX_MAP_CELLS} a map may have (its \
                 records must fit one GPU storage binding of 128 MiB)"
            ),
            format!(
                "use cell_m = {} or more, or map a smaller area (maps.min_m, maps.max_m)",
                num(two_digits_up((area / MAX_MAP_CELLS as f64).sqrt()))
            ),
        ));
    }
    let mut maps = FloodMaps {
        first_centre: [0, 1].map(|a| min[a] + 0.5 * cell),
        cell,
        nx,
        ny,
        wet_depth: spec.wet_depth.unwrap_or(dx),
        ground: Vec::new(),
    };
    maps.ground = ground_under(&maps, particles, bodies, dx, domain.min[2]);
    Ok(maps)
}

/// `x` rounded up to two significant digits (a size to suggest).
fn two_digits_up(x: f64) -> f64 {
    let unit = 10f64.powf(x.log10().floor() - 1.0);
    (x / unit).ceil() * unit
}

/// The ground under each cell's centre: the highest top face (z + dx/2) of the fixed walls'
/// particles within dx/2 of it in plan (terrain, buildings' roofs, a tank's floor, obstacles;
/// not a moving body's), `floor` where there is none. Cells are at least dx, so a particle is
/// within dx/2 of at most the centre nearest it.
fn ground_under(
    maps: &FloodMaps,
    particles: &[Particle],
    bodies: &[Body],
    dx: f64,
    floor: f64,
) -> Vec<f64> {
    let moving = bodies.iter().map(|b| b.particles.start).min();
    let fixed = (particles.iter().enumerate())
        .filter(|(i, _)| moving.is_none_or(|m| *i < m))
        .map(|(_, p)| p)
        .filter(|p| p.kind.is_boundary());
    let mut top = vec![f64::NEG_INFINITY; maps.cells()];
    let reach = 0.5 * dx * (1.0 + 1e-9);
    for p in fixed {
        let index = |a: usize, n: usize| {
            let i = ((p.pos[a] - maps.first_centre[a]) / maps.cell).round();
            (0.0..n as f64).contains(&i).then_some(i as usize)
        };
        let (Some(ix), Some(iy)) = (index(0, maps.nx), index(1, maps.ny)) else {
            continue;
        };
        let c = iy * maps.nx + ix;
        let centre = maps.centre(c);
        if (0..2).all(|a| (p.pos[a] - centre[a]).abs() <= reach) {
            top[c] = top[c].max(p.pos[2] + 0.5 * dx);
        }
    }
    top.into_iter()
        .map(|z| if z.is_finite() { z } else { floor })
        .collect()
}

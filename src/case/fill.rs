//! `[[fill]]`: water poured at a seed until it stands at a level (docs/cases.md, "Fills"),
//! checked, and its lattice points found by `crate::generate::fill::flood` within what holds
//! the water (the tank, the domain, the terrain), around what takes its place (the ground,
//! obstacles, bodies, solids: the caller's `blocked`).

use crate::generate::fill::{flood, IndexBox};

use super::check::{number, vector, Aabb, Bound};
use super::error::{num, CaseError};
use super::lattice::Lattice;
use super::limits::{self, ParticleBudget};
use super::locate::Ctx;
use super::schema::RawFill;

/// Most lattice points a fill's box may hold (one bit each while the water spreads: 512 MiB).
const MAX_BOX_POINTS: u64 = 1 << 32;

/// A fill, checked.
#[derive(Debug, Clone, Copy)]
pub(super) struct Fill {
    pub seed: [f64; 3],
    pub level: f64,
}

/// `[[fill]]`: each seed a point and each level a finite elevation.
pub(super) fn validate(ctx: &Ctx<'_>, raw: &[RawFill], dim: usize) -> Result<Vec<Fill>, CaseError> {
    raw.iter()
        .enumerate()
        .map(|(i, f)| {
            let seed = vector(
                ctx,
                &format!("fill[{i}].seed_m"),
                &f.seed_m,
                dim,
                "the seed",
            )?;
            let level = number(
                ctx,
                &format!("fill[{i}].level_m"),
                f.level_m,
                Bound::Closed(-1e7, 1e7),
                "the water's level, an elevation in m",
                "give the level the water stands at",
            )?;
            Ok(Fill { seed, level })
        })
        .collect()
}

/// A fill's water: its points and the box of their cells.
#[derive(Debug, Clone)]
pub(super) struct Filled {
    pub points: Vec<[f64; 3]>,
    pub water: Aabb,
}

/// The lattice points of fill `i`: those within `bound` whose cells lie below the level,
/// connected to the seed's point through points no `blocked` names. An error when the seed's
/// point is outside, above the level or blocked, or when the water would hold more particles
/// than `budget` (found as it spreads).
pub(super) fn filled(
    ctx: &Ctx<'_>,
    (i, fill): (usize, &Fill),
    lat: &Lattice,
    (bound, holder): (&Aabb, &str),
    (blocked, budget): (impl Fn([f64; 3]) -> Option<String>, &ParticleBudget),
) -> Result<Filled, CaseError> {
    let (dim, dx, v) = (lat.dim, lat.dx, lat.dim - 1);
    let path = format!("fill[{i}]");
    let mut below = *bound;
    below.max[v] = below.max[v].min(fill.level - 0.5 * dx);
    let seed_path = format!("{path}.seed_m");
    let seed_value = Some(format!("{:?}", &fill.seed[..dim]));
    let Some((lo, hi)) = lat.range_in(&below) else {
        return Err(ctx.err(
            &format!("{path}.level_m"),
            Some(num(fill.level)),
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
    let mut seed = [0i64; 3];
    for (a, s) in seed.iter_mut().enumerate().take(dim) {
        *s = ((fill.seed[a] - lat.origin[a]) / dx - 0.5).round() as i64;
    }
    if fill.seed[v] > fill.level {
        return Err(ctx.err(
            &seed_path,
            seed_value,
            format!("lies above the fill's level_m = {}", num(fill.level)),
            "put the seed in the water: below level_m, above the ground",
        ));
    }
    if !index.contains(seed) {
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
    if let Some(what) = blocked(lat.pos(seed)) {
        return Err(ctx.err(
            &seed_path,
            seed_value,
            format!(
                "lies in {what} (its nearest particle at particles.dx_m = {} m, at {:?}, is no \
                 place for water): the water has nowhere to start",
                num(dx),
                &lat.pos(seed)[..dim]
            ),
            "put the seed in the open water, a few spacings above the ground and clear of \
             walls and bodies",
        ));
    }
    let limit = budget.particles.min(1e15) as usize;
    let Some(points) = flood(&index, seed, limit, |p| blocked(lat.pos(p)).is_none()) else {
        let water = format!("{path}'s water inside {holder}");
        let count = (water.as_str(), limit as f64);
        return Err(limits::too_many(ctx, (dx, dim), count, budget));
    };
    let points: Vec<[f64; 3]> = points.into_iter().map(|p| lat.pos(p)).collect();
    Ok(Filled {
        water: water_box(&points, dx, dim),
        points,
    })
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

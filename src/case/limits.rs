//! The size limits of a case, checked before any particle is made: the particle budget (the
//! message names the part with the most), the tank's length in spacings, and the extent of
//! the solver's neighbour grid. Each refusal names the field that makes the case too large.

use crate::grid::Grid;
use crate::scenario::Domain;

use super::check::Aabb;
use super::error::{num, CaseError};
use super::locate::Ctx;

/// Refuse cases with more particles than this.
pub const MAX_PARTICLES: f64 = 200e6;

/// The most particles a case may make, and why (what a refusal says): the engine's limit, or
/// what the adapter and the host's memory hold, checked before any particle is made (issue 64:
/// a case of 150 million particles, within the engine's limit, exhausted the host's memory
/// building them before the adapter's limit was looked at).
#[derive(Clone, Debug, PartialEq)]
pub struct ParticleBudget {
    pub particles: f64,
    pub why: String,
}

impl Default for ParticleBudget {
    fn default() -> Self {
        ParticleBudget {
            particles: MAX_PARTICLES,
            why: "the engine's".into(),
        }
    }
}

impl ParticleBudget {
    /// At most `particles`, because of `why`, within the engine's own limit.
    pub fn at_most(particles: f64, why: impl Into<String>) -> Self {
        let engine = Self::default();
        if particles < engine.particles {
            ParticleBudget {
                particles,
                why: why.into(),
            }
        } else {
            engine
        }
    }

    /// What is left of it after `used` particles.
    pub(super) fn less(&self, used: f64) -> Self {
        ParticleBudget {
            particles: self.particles - used,
            why: self.why.clone(),
        }
    }
}
/// Longest tank, in particle spacings along one axis: the neighbour grid takes 2^30 cells of
/// 2h <= 6 dx along an axis, so a longer tank could never run; its lattice count would also
/// lose precision (and mirror walls, having no particles, escape the particle budget).
const MAX_TANK_SPACINGS: f64 = 1e10;

fn fmt_count(n: f64) -> String {
    // + 0.0 turns the -0 of an empty sum into 0.
    let n = n + 0.0;
    if n < 1e12 {
        format!("{n:.0}")
    } else {
        format!("{n:.2e}")
    }
}

/// A particle budget for messages: "200 million", or the count itself when smaller.
fn fmt_limit(n: f64) -> String {
    if n >= 1e6 && (n / 1e6).fract() == 0.0 {
        format!("{} million", n / 1e6)
    } else {
        fmt_count(n)
    }
}

/// `count` particles of one part of the case (`part`, as a message names it) within the
/// budget, checked before they are made: a terrain, buildings or a fill of a case whose dx is
/// far too small would otherwise take minutes to find out how many they are.
pub(super) fn part_fits(
    ctx: &Ctx<'_>,
    (dx, dim): (f64, usize),
    (part, count): (&str, f64),
    budget: &ParticleBudget,
) -> Result<(), CaseError> {
    if count <= budget.particles {
        return Ok(());
    }
    Err(too_many(ctx, (dx, dim), (part, count), budget))
}

/// The error of a part of the case (`part`) that would create more than `count` particles,
/// beyond `budget`.
pub(super) fn too_many(
    ctx: &Ctx<'_>,
    (dx, dim): (f64, usize),
    (part, count): (&str, f64),
    budget: &ParticleBudget,
) -> CaseError {
    ctx.err(
        "particles.dx_m",
        Some(num(dx)),
        format!(
            "{part} alone would create more than {} particles, more than {} ({} limit)",
            fmt_count(count),
            fmt_limit(budget.particles),
            budget.why
        ),
        format!("increase particles.dx_m (the count scales as 1/dx^{dim}) or shrink {part}"),
    )
}

/// The tank's inner box is `len` m, `spacings` dx, along `axis`.
pub(super) fn tank_length(
    ctx: &Ctx<'_>,
    len: f64,
    spacings: f64,
    axis: &str,
) -> Result<(), CaseError> {
    if spacings <= MAX_TANK_SPACINGS {
        return Ok(());
    }
    Err(ctx.err(
        "tank.max_m",
        None,
        format!(
            "the tank is {} m along {axis}, {} particle spacings, more than the {} the \
             solver's neighbour grid can hold",
            num(len),
            num(spacings),
            num(MAX_TANK_SPACINGS)
        ),
        "make the tank smaller or particles.dx_m larger",
    ))
}

/// The total particle count of `parts` (name, count), which are fluid blocks up to
/// `ends[0]`, walls up to `ends[1]`, then bodies; refused above the `budget`.
pub(super) fn budget(
    ctx: &Ctx<'_>,
    (dx, dim): (f64, usize),
    parts: &[(String, f64)],
    ends: [usize; 2],
    budget: &ParticleBudget,
) -> Result<f64, CaseError> {
    let max_particles = budget.particles;
    let sum = |r: std::ops::Range<usize>| parts[r].iter().map(|(_, n)| n).sum::<f64>();
    let (fluid_n, wall_n) = (sum(0..ends[0]), sum(ends[0]..ends[1]));
    let body_n = sum(ends[1]..parts.len());
    let total = fluid_n + wall_n + body_n;
    if !(total.is_nan() || total > max_particles) {
        return Ok(total);
    }
    let (largest, most) = parts
        .iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(("the geometry", 0.0), |(p, n)| (p.as_str(), *n));
    Err(ctx.err(
        "particles.dx_m",
        Some(num(dx)),
        format!(
            "the case would create about {} particles ({} fluid, {} wall, {} body; the most, \
             about {}, in {largest}), more than {} ({} limit)",
            fmt_count(total),
            fmt_count(fluid_n),
            fmt_count(wall_n),
            fmt_count(body_n),
            fmt_count(most),
            fmt_limit(max_particles),
            budget.why
        ),
        if largest.starts_with("inlet") {
            // An inlet makes the particles of its whole inflow: its length in time counts.
            format!(
                "increase particles.dx_m (the count scales as 1/dx^{dim}), shrink {largest}, or \
                 stop it sooner ({largest}.stop_s, else time.end_s)"
            )
        } else {
            format!("increase particles.dx_m (the count scales as 1/dx^{dim}) or shrink {largest}")
        },
    ))
}

/// The solver's neighbour grid (cells 2h wide) must cover the domain; an error names the
/// given domain, or the part that stretches the default one farthest from the fluid.
///
/// `given`: whether the case gives `[domain]`; `fluid_parts`: the fluid's parts (blocks and
/// inlets' buffers, a case has one of them at least; the solids-only cases do not come here)
/// and `solid` the walls', obstacles' and bodies' boxes, each with the field that places it.
pub(super) fn grid_fits(
    ctx: &Ctx<'_>,
    (dim, h): (usize, f64),
    domain: &Domain,
    given: bool,
    fluid_parts: &[(String, Aabb)],
    solid: &[(String, Aabb)],
) -> Result<(), CaseError> {
    let Err(e) = Grid::new(domain, h, dim as u32, 0, [false; 3], None) else {
        return Ok(());
    };
    let extent = |a: usize| domain.max[a] - domain.min[a];
    let a = (0..dim)
        .max_by(|&a, &b| extent(a).total_cmp(&extent(b)))
        .unwrap_or(0);
    let Some((first_path, first)) = fluid_parts.first().cloned() else {
        return Err(ctx.err(
            "domain",
            None,
            format!("is too large for the neighbour grid: {e}"),
            "shrink [domain] or increase particles.dx_m",
        ));
    };
    let fluid = 0.5 * (first.min[a] + first.max[a]);
    let reach = |b: &Aabb| (b.min[a] - fluid).abs().max((b.max[a] - fluid).abs());
    let (path, fix) = if given {
        let field = if (domain.min[a] - fluid).abs() > (domain.max[a] - fluid).abs() {
            "domain.min_m"
        } else {
            "domain.max_m"
        };
        (
            field.to_string(),
            "shrink [domain] to where the fluid can go, or increase particles.dx_m".to_string(),
        )
    } else {
        let (path, _) = solid
            .iter()
            .cloned()
            .chain(fluid_parts.iter().cloned())
            .max_by(|x, y| reach(&x.1).total_cmp(&reach(&y.1)))
            .unwrap_or((first_path, first));
        let fix = format!(
            "bring {path} closer to the fluid or make it smaller (the default domain encloses \
             everything), or increase particles.dx_m"
        );
        (path, fix)
    };
    Err(ctx.err(
        &path,
        None,
        format!(
            "makes the domain ({:?} to {:?}) too large for the neighbour grid, whose cells are \
             2h = {} m wide: {e}",
            &domain.min[..dim],
            &domain.max[..dim],
            num(2.0 * h)
        ),
        fix,
    ))
}

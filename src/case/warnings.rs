//! Doubts about a case the loader accepts (`Scenario::warnings`): set-ups that run but that a
//! practised user would not want by mistake. Each names the part, says what goes wrong and
//! gives a fix; `wgsph run` logs them and run.json lists them.

use super::bodies::Shape;
use super::build::fmt_box;
use super::error::num;
use super::validate::{Case, Treatment};

/// Every warning about `case` at spacing `dx` and smoothing length `h`.
pub(super) fn of(case: &Case, dx: f64, h: f64) -> Vec<String> {
    let mut out = shallow_walls(case, dx, h);
    out.extend(thin_ghosts(case, dx, h));
    out
}

/// Tank walls and shell bodies (`layers`) of dynamic particles or fixed ghosts whose layers
/// are thinner than the kernel support 2h: a fluid particle beside them (dx/2 off the face)
/// finds no wall particle in the rest of its support, so its density sum and the wall's
/// pressure there fall short and it can come too close to the wall.
fn shallow_walls(case: &Case, dx: f64, h: f64) -> Vec<String> {
    let support = 2.0 * h;
    let needed = (support / dx - 1e-9).ceil();
    let filled = |t: Treatment| matches!(t, Treatment::Dynamic | Treatment::FixedGhost { .. });
    let warning = |field: String, part: &str, layers: u32| {
        format!(
            "{field} = {layers}: {layers} particle layers ({} m) are less than the kernel \
             support 2h = {} m deep, so fluid beside the {part} misses part of its kernel (its \
             density and the wall's push fall short and it comes too close); fix: set {field} \
             to {needed} or more",
            num(layers as f64 * dx),
            num(support)
        )
    };
    let tank = case
        .tank
        .iter()
        .filter(|t| filled(t.wall) && (t.layers as f64) < needed)
        .map(|t| warning("tank.layers".into(), "tank wall", t.layers));
    let bodies = case.bodies.iter().enumerate().filter_map(|(i, b)| {
        let layers = b
            .layers
            .filter(|&l| filled(b.wall) && (l as f64) < needed)?;
        Some(warning(
            format!("body[{i}].layers"),
            &format!("body '{}'", b.name),
            layers,
        ))
    });
    tank.chain(bodies).collect()
}

/// Fixed-ghost obstacles and bodies thinner than 4h − dx (docs/cases.md, "fixed_ghost"): the
/// water stays about dx/2 off a face, so a ghost within 2h of the water on one side is then
/// also within 2h of the water beyond the opposite face, and where water is on both sides the
/// ghost's interpolated pressure and velocity mix the two sides'. A warning, not a refusal: a
/// thin wall with water on one side only is fine.
fn thin_ghosts(case: &Case, dx: f64, h: f64) -> Vec<String> {
    let limit = 4.0 * h - dx;
    let dim = case.dim;
    let ghosts = |t: Treatment| matches!(t, Treatment::FixedGhost { .. });
    // `measured`: on the lattice (polygons and meshes), to within dx.
    let warning = |part: String, thickness: f64, measured: bool| {
        format!(
            "{part} has fixed ghosts and is {}{} m thick, less than 4h - dx = {} m: where water \
             is on both sides, a ghost near one face also interpolates the water beyond the \
             other, mixing the two sides' pressures; fix: make it at least {} m thick, or \
             decrease particles.dx_m (the limit is (4 h_over_dx - 1) dx)",
            if measured { "about " } else { "" },
            // Three digits of a measured thickness are all it has.
            num(if measured {
                format!("{thickness:.2e}").parse().unwrap_or(thickness)
            } else {
                thickness
            }),
            num(limit),
            num(limit)
        )
    };
    let obstacles = case
        .obstacles
        .iter()
        .zip(&case.obstacle_walls)
        .enumerate()
        .filter(|(_, (_, &t))| ghosts(t))
        .filter_map(|(i, (b, _))| {
            let thickness = (0..dim)
                .map(|a| b.max[a] - b.min[a])
                .fold(f64::MAX, f64::min);
            (thickness < limit).then(|| {
                warning(
                    format!("obstacle[{i}] ({})", fmt_box(b, dim)),
                    thickness,
                    false,
                )
            })
        });
    let bodies = case
        .bodies
        .iter()
        .enumerate()
        .filter(|(_, b)| ghosts(b.wall))
        .filter_map(|(i, b)| {
            let thickness = b.shape.thinner_than(limit, dx, dim)?;
            let measured = matches!(b.shape, Shape::Polygon(_) | Shape::Mesh(_));
            Some(warning(
                format!("body[{i}] ('{}')", b.name),
                thickness,
                measured,
            ))
        });
    obstacles.chain(bodies).collect()
}

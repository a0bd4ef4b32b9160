//! Doubts about a case the loader accepts (`Scenario::warnings`): set-ups that run but that a
//! practised user would not want by mistake. Each names the part, says what goes wrong and
//! gives a fix; `wgsph run` logs them and run.json lists them.

use super::bodies::Shape;
use super::check::{fmt_box, Treatment, AXES};
use super::error::num;
use super::validate::Case;
use crate::scenario::ContactGroup;

/// Every warning about `case` at spacing `dx` and smoothing length `h`; `obstacle_points`:
/// the lattice points each obstacle holds along each axis. (A speed beyond c0/10 is warned
/// of where the built case's motions are known: `runnable::check`.)
pub(super) fn of(case: &Case, dx: f64, h: f64, obstacle_points: &[[f64; 3]]) -> Vec<String> {
    let mut out = rounded_blocks(case, dx);
    out.extend(rounded_obstacles(case, dx, obstacle_points));
    out.extend(shallow_walls(case, dx, h));
    out.extend(thin_ghosts(case, dx, h));
    out.extend(idle_friction(case));
    out.extend(left_behind(case));
    out
}

/// Fixed bodies in a moving tank: they stay where they are in the world while the tank's walls
/// and obstacles move (a fixed body is not carried with the tank), and their contact with the
/// walls is left out, so the walls pass through them.
fn left_behind(case: &Case) -> Vec<String> {
    if !case.tank_moves() {
        return Vec::new();
    }
    (case.bodies.iter().enumerate())
        .filter(|(_, b)| b.motion.is_fixed())
        .map(|(i, b)| {
            format!(
                "body[{i}] ('{}') is fixed in the world while the tank moves: it is not carried \
                 with the tank, whose walls and obstacles move past and through it (their \
                 contact with a fixed body is left out); fix: give it the tank's motion \
                 (body.motion as tank.motion, with the same pivot), or make a box of it an \
                 [[obstacle]], which moves with the tank",
                b.name
            )
        })
        .collect()
}

/// `[[friction]]` pairs between two things that both move as the case prescribes (the walls, a
/// moving tank, fixed and prescribed bodies): their contact is left out of the step
/// (interaction.wgsl, `contact_counts`), so the coefficient never acts.
fn idle_friction(case: &Case) -> Vec<String> {
    let tank_moves = case.tank_moves();
    // The name `between` gives a kinematic group, or None for one that moves under its load.
    let kinematic = |g: ContactGroup| -> Option<String> {
        match g {
            ContactGroup::Walls => Some("walls".into()),
            ContactGroup::Body(0) if tank_moves => Some("walls".into()),
            ContactGroup::Body(k) => {
                let b = &case.bodies[k - tank_moves as usize];
                b.motion.is_kinematic().then(|| b.name.clone())
            }
            ContactGroup::Solid(_) => None,
        }
    };
    let mut out: Vec<String> = Vec::new();
    for pair in &case.walls.friction_pairs {
        let [Some(a), Some(b)] = pair.between.map(kinematic) else {
            continue;
        };
        let body = if a == "walls" { &b } else { &a };
        let w = format!(
            "[[friction]] between \"{a}\" and \"{b}\": neither moves under its load (fixed \
             walls, a moving tank, fixed or prescribed bodies), so their contact is left out of \
             the step and this coefficient never acts; fix: remove the table, or make \"{body}\" \
             a free body"
        );
        if !out.contains(&w) {
            out.push(w);
        }
    }
    out
}

/// `x` to three significant digits, for messages.
pub(super) fn round3(x: f64) -> f64 {
    significant(x, 3)
}

/// `x` to `digits` significant digits.
fn significant(x: f64, digits: usize) -> f64 {
    format!("{x:.*e}", digits - 1).parse().unwrap_or(x)
}

/// How far a fluid block's extent may change by its filling with whole spacings before a
/// warning. A water depth off by this share moves the hydrostatic pressure as much and the
/// long-wave speed by half of it; below 1.5 % that is within what the SPH discretisation itself
/// gives at the shipped resolutions (hydrostatic probes 0.3–3 % off, docs/validation.md), above
/// it the set-up's error dominates (the sloshing cases' 0.465 m at dx = 0.01 or 0.02 is 1.1 %
/// off and loads without; the SPHERIC column at dx = 0.02, 1.8 %, with).
const BLOCK_ROUNDING: f64 = 0.015;

/// Fluid blocks whose extent along an axis is not close to a whole number of spacings: a block
/// is filled with round(L/dx) cells (build.rs), so its water is that many spacings long, not L
/// (a 0.55 m column at dx = 0.02 m holds 28 layers, 0.56 m of water).
fn rounded_blocks(case: &Case, dx: f64) -> Vec<String> {
    let mut out = Vec::new();
    for (i, b) in case.blocks.iter().enumerate() {
        for (a, axis) in AXES.iter().enumerate().take(case.dim) {
            let len = b.bx.max[a] - b.bx.min[a];
            let n = crate::generate::lattice::cells(len, dx);
            let filled = n * dx;
            if (filled - len).abs() <= BLOCK_ROUNDING * len {
                continue;
            }
            // The two spacings nearest dx that divide the extent.
            let (fewer, more) = ((len / dx).floor().max(1.0), (len / dx).ceil().max(1.0));
            out.push(format!(
                "fluid_block[{i}] is {} m along {} but is filled with {n} spacings of dx = {} m: \
                 {} m of water ({:+.1} %), which moves its hydrostatic pressure and wave speed \
                 as much; fix: a particles.dx_m that divides {} m (such as {} or {}), or a \
                 block of a whole number of spacings",
                num(len),
                axis,
                num(dx),
                num(round3(filled)),
                100.0 * (filled / len - 1.0),
                num(len),
                num(significant(len / more, 6)),
                num(significant(len / fewer, 6)),
            ));
        }
    }
    out
}

/// Obstacles whose particles span more than [`BLOCK_ROUNDING`] more or less than their box
/// along an axis: an obstacle is the lattice points inside its box, so its faces move to the
/// lattice's, by up to a spacing in all (the SPHERIC box, 0.161 m, is 0.165 m at dx = 0.55/30).
fn rounded_obstacles(case: &Case, dx: f64, points: &[[f64; 3]]) -> Vec<String> {
    let mut out = Vec::new();
    for (i, (b, n)) in case.obstacles.iter().zip(points).enumerate() {
        for (a, axis) in AXES.iter().enumerate().take(case.dim) {
            let len = b.max[a] - b.min[a];
            let filled = n[a] * dx;
            if (filled - len).abs() > BLOCK_ROUNDING * len {
                out.push(format!(
                    "{} is {} m along {axis} but holds {} lattice points of dx = {} \
                     m: its particles span {} m ({:+.1} %), and its faces stand where the \
                     lattice puts them; fix: a particles.dx_m at which the box spans a whole \
                     number of spacings on the lattice (it starts at the tank's inner corner), \
                     or a box that does",
                    case.obstacle_paths[i],
                    num(len),
                    n[a],
                    num(dx),
                    num(round3(filled)),
                    100.0 * (filled / len - 1.0),
                ));
            }
        }
    }
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
    let warning =
        |part: String, thickness: f64, measured: bool| {
            format!(
            "{part} has fixed ghosts and is {}{} m thick, less than 4h - dx = {} m: where water \
             is on both sides, a ghost near one face also interpolates the water beyond the \
             other, mixing the two sides' pressures; fix: make it at least {} m thick, or \
             decrease particles.dx_m (the limit is (4 h_over_dx - 1) dx)",
            if measured { "about " } else { "" },
            // Three digits of a measured thickness are all it has.
            num(if measured { round3(thickness) } else { thickness }),
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
                    format!("{} ({})", case.obstacle_paths[i], fmt_box(b, dim)),
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

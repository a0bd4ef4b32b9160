//! The domain of a case with fluid: the given one or the default, and the checks that the
//! fluid, the inlets, the outlets, the walls, the bodies and the probes lie in it (`build.rs`
//! calls [`domain`] after the particle budget, before any particle is made).

use crate::scenario::{Domain, Motion, ProbeKind};

use super::check::{fmt_box, inside, point_inside, Aabb, AXES, TOL};
use super::error::{num, CaseError};
use super::limits;
use super::locate::Ctx;
use super::validate::Case;
use crate::generate::lattice::{Lattice, TankWall};

/// The given domain, or the default one; checks that fluid, walls and probes lie inside it.
pub(super) fn domain(
    ctx: &Ctx<'_>,
    case: &Case,
    lat: &Lattice,
    wall: Option<&TankWall>,
    (placed, fills): (&[(String, Aabb)], &[Aabb]),
) -> Result<Domain, CaseError> {
    let dim = case.dim;
    let mut solid = solid_boxes(case, lat, wall);
    solid.extend_from_slice(placed);
    let d = match case.domain {
        Some(d) => d,
        None => default_domain(case, wall, &solid, fills),
    };
    check_fluid_inside(ctx, case, &d)?;
    check_outlets(ctx, case, &d)?;
    check_solids_inside(ctx, case, &d, &solid)?;
    check_probes_inside(ctx, case, &d)?;
    let domain = Domain {
        min: d.min,
        max: d.max,
    };
    // The fluid's parts: blocks and inlets' buffers.
    let fluid_parts: Vec<(String, Aabb)> = case
        .blocks
        .iter()
        .enumerate()
        .map(|(i, b)| (format!("fluid_block[{i}]"), b.bx))
        .chain(
            case.inlets
                .iter()
                .enumerate()
                .map(|(i, s)| (format!("inlet[{i}]"), s.bx)),
        )
        .chain((fills.iter().enumerate()).map(|(i, f)| (format!("fill[{i}]"), *f)))
        .collect();
    limits::grid_fits(
        ctx,
        (dim, case.h_over_dx * case.dx),
        &domain,
        case.domain.is_some(),
        &fluid_parts,
        &solid,
    )?;
    Ok(domain)
}

/// The solids with the field that places each: obstacles, the tank's walls, the bodies (a
/// prescribed motion's whole path).
fn solid_boxes(case: &Case, lat: &Lattice, wall: Option<&TankWall>) -> Vec<(String, Aabb)> {
    let (dim, dx) = (case.dim, case.dx);
    let mut solid: Vec<(String, Aabb)> = case
        .obstacles
        .iter()
        .zip(&case.obstacle_paths)
        .map(|(o, path)| (path.clone(), *o))
        .collect();
    if let Some(w) = wall {
        let (mut min, mut max) = ([0.0; 3], [0.0; 3]);
        for a in 0..dim {
            let (lo, hi) = w.outer(a);
            min[a] = lat.origin[a] + lo as f64 * dx;
            max[a] = lat.origin[a] + hi as f64 * dx;
        }
        let mut b = Aabb { min, max };
        let mut path = "tank";
        if let Some(m) = case.tank.as_ref().and_then(|t| t.motion.as_ref()) {
            b = swept(&b, m, case.time.end_s, dim);
            path = "tank.motion";
        }
        solid.push((path.into(), b));
    }
    // Bodies, each at its start position (a free body's later path is the user's business).
    for (i, body) in case.bodies.iter().enumerate() {
        let mut b = body.shape.bounds(dim);
        let mut path = format!("body[{i}]");
        if let Motion::Prescribed(_) = body.motion {
            b = swept(&b, &body.motion, case.time.end_s, dim);
            path.push_str(".motion");
        }
        solid.push((path, b));
    }
    solid
}

/// The default domain: the box around the solids (`solid`; without a tank also around the
/// fluid blocks, the fills' water (`fills`), the elastic solids and the inlets), with room above an open top, and two spacings
/// on every side.
fn default_domain(
    case: &Case,
    wall: Option<&TankWall>,
    solid: &[(String, Aabb)],
    fills: &[Aabb],
) -> Aabb {
    let (dim, dx) = (case.dim, case.dx);
    let v = dim - 1;
    let mut all: Vec<Aabb> = solid.iter().map(|(_, b)| *b).collect();
    if wall.is_none() {
        all.extend(case.blocks.iter().map(|b| b.bx));
        all.extend(case.solids.iter().map(|s| s.bx));
        all.extend(case.inlets.iter().map(|s| s.bx));
        all.extend(fills);
    }
    let mut d = all[0];
    for b in &all[1..] {
        for a in 0..dim {
            d.min[a] = d.min[a].min(b.min[a]);
            d.max[a] = d.max[a].max(b.max[a]);
        }
    }
    let open = case.tank.as_ref().is_none_or(|t| t.open_top);
    if open {
        // Room above for splashes: the tank's (or the fluid's) height.
        d.max[v] += match wall {
            Some(w) => w.n[v] as f64 * dx,
            None => d.max[v] - d.min[v],
        };
    }
    for a in 0..dim {
        d.min[a] -= 2.0 * dx;
        d.max[a] += 2.0 * dx;
    }
    d
}

/// Which bound of `[domain]` (`d`) to move, and to where, for a box `b` that leaves it along
/// `a`.
fn domain_fix(case: &Case, d: &Aabb, b: &Aabb, a: usize) -> String {
    if case.domain.is_none() {
        return "enlarge [domain] (or remove it to get the default, which encloses the tank)"
            .to_string();
    }
    let (field, side, to) = if b.min[a] < d.min[a] - TOL {
        ("min_m", "lower", b.min[a])
    } else {
        ("max_m", "raise", b.max[a])
    };
    format!(
        "{side} domain.{field}[{a}] to {} or beyond, or remove [domain] to get the \
         default, which encloses everything",
        num(to)
    )
}

/// The fluid blocks and the inlets' buffers inside the domain `d`.
fn check_fluid_inside(ctx: &Ctx<'_>, case: &Case, d: &Aabb) -> Result<(), CaseError> {
    let dim = case.dim;
    let fix = |b: &Aabb, a: usize| domain_fix(case, d, b, a);
    for (i, b) in case.blocks.iter().enumerate() {
        if let Some(a) = inside(&b.bx, d, dim) {
            return Err(ctx.err(
                &format!("fluid_block[{i}]"),
                None,
                format!(
                    "the block ({}) leaves the domain ({}) along {}",
                    fmt_box(&b.bx, dim),
                    fmt_box(d, dim),
                    AXES[a]
                ),
                fix(&b.bx, a),
            ));
        }
    }
    for (i, s) in case.inlets.iter().enumerate() {
        if let Some(a) = inside(&s.bx, d, dim) {
            return Err(ctx.err(
                &format!("inlet[{i}]"),
                None,
                format!(
                    "the buffer box ({}) leaves the domain ({}) along {}",
                    fmt_box(&s.bx, dim),
                    fmt_box(d, dim),
                    AXES[a]
                ),
                fix(&s.bx, a),
            ));
        }
    }
    Ok(())
}

/// Outlets: reaching into the domain `d`, clear of the fluid blocks and the inlets' buffers.
fn check_outlets(ctx: &Ctx<'_>, case: &Case, d: &Aabb) -> Result<(), CaseError> {
    let dim = case.dim;
    let overlap = |a: &Aabb, b: &Aabb| {
        (0..dim).all(|k| a.max[k].min(b.max[k]) - a.min[k].max(b.min[k]) > TOL)
    };
    for (i, o) in case.outlets.iter().enumerate() {
        let bx = Aabb {
            min: o.min,
            max: o.max,
        };
        if !overlap(&bx, d) {
            return Err(ctx.err(
                &format!("outlet[{i}]"),
                None,
                format!(
                    "the box ({}) lies outside the domain ({}): no fluid could reach it",
                    fmt_box(&bx, dim),
                    fmt_box(d, dim)
                ),
                "place the outlet where the fluid leaves, inside the domain",
            ));
        }
        let other = case
            .blocks
            .iter()
            .position(|b| overlap(&bx, &b.bx))
            .map(|j| format!("fluid_block[{j}]"))
            .or_else(|| {
                case.inlets
                    .iter()
                    .position(|s| overlap(&bx, &s.bx))
                    .map(|j| format!("inlet[{j}]"))
            });
        if let Some(other) = other {
            return Err(ctx.err(
                &format!("outlet[{i}]"),
                None,
                format!(
                    "the box ({}) overlaps {other}, whose fluid it would remove at once",
                    fmt_box(&bx, dim)
                ),
                "move the outlet downstream, clear of fluid blocks and inlets",
            ));
        }
    }
    Ok(())
}

/// The solids' particles (`solid`: each box with the field that places it) inside the domain
/// `d`.
fn check_solids_inside(
    ctx: &Ctx<'_>,
    case: &Case,
    d: &Aabb,
    solid: &[(String, Aabb)],
) -> Result<(), CaseError> {
    let dim = case.dim;
    let fix = |b: &Aabb, a: usize| domain_fix(case, d, b, a);
    for (path, b) in solid {
        if let Some(a) = inside(b, d, dim) {
            return Err(ctx.err(
                path,
                None,
                format!(
                    "its particles ({}) leave the domain ({}) along {} and would be dropped",
                    fmt_box(b, dim),
                    fmt_box(d, dim),
                    AXES[a]
                ),
                fix(b, a),
            ));
        }
    }
    Ok(())
}

/// Every probe's point inside the domain `d`.
fn check_probes_inside(ctx: &Ctx<'_>, case: &Case, d: &Aabb) -> Result<(), CaseError> {
    let dim = case.dim;
    for (i, p) in case.probes.iter().enumerate() {
        let (field, point) = match &p.kind {
            ProbeKind::Pressure { point } if case.face_normals[i].is_some() => ("face_m", *point),
            ProbeKind::Pressure { point } => ("point_m", *point),
            ProbeKind::Height { base, .. } => ("base_m", *base),
            ProbeKind::Front { origin, .. } => ("origin_m", *origin),
            ProbeKind::WallPressure(patch) => ("point_m", patch.point),
            // Either end outside.
            ProbeKind::Discharge { from, to } if point_inside(*from, d, dim) => ("to_m", *to),
            ProbeKind::Discharge { from, .. } => ("from_m", *from),
        };
        if !point_inside(point, d, dim) {
            // Say what the default domain encloses: removing the tank shrinks it to the fluid.
            let (which, fix) = match (case.domain, &case.tank) {
                (Some(_), _) => (
                    "the domain",
                    "move the probe inside [domain], or enlarge it",
                ),
                (None, Some(_)) => (
                    "the default domain (around the tank, obstacles and bodies)",
                    "move the probe inside it, or give a [domain] that encloses it",
                ),
                (None, None) => (
                    "the default domain (around the fluid, obstacles and bodies: there is no tank)",
                    "move the probe inside it, or give a [domain] that encloses it",
                ),
            };
            return Err(ctx.err(
                &format!("{}.{field}", case.probe_paths[i]),
                Some(format!("{:?}", &point[..dim])),
                format!("lies outside {which} ({})", fmt_box(d, dim)),
                fix,
            ));
        }
    }
    Ok(())
}

/// The bounding box of `b` moved by a prescribed `motion` over [0, end_s] (sampled finely; a
/// free motion leaves it as it is).
fn swept(b: &Aabb, motion: &Motion, end_s: f64, dim: usize) -> Aabb {
    let Motion::Prescribed(law) = motion else {
        return *b;
    };
    let mut out = *b;
    let corners: Vec<glam::DVec3> = (0..1 << dim)
        .map(|k: usize| {
            glam::DVec3::from_array([0, 1, 2].map(|a| {
                if a >= dim {
                    0.0
                } else if k >> a & 1 == 1 {
                    b.max[a]
                } else {
                    b.min[a]
                }
            }))
        })
        .collect();
    const SAMPLES: usize = 2000;
    for s in 0..=SAMPLES {
        let t = end_s * s as f64 / SAMPLES as f64;
        for &c in &corners {
            // A corner moves as a body whose centre it is.
            let x = law.pose(c, t).center;
            for a in 0..dim {
                out.min[a] = out.min[a].min(x[a]);
                out.max[a] = out.max[a].max(x[a]);
            }
        }
    }
    out
}

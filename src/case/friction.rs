//! `[[friction]]`: Coulomb coefficients of their own for pairs of things in contact (bodies,
//! solids, the walls), over `[walls] friction_coefficient` for every other pair.

use super::bodies::BodySpec;
use super::check::{number, Bound};
use super::error::CaseError;
use super::locate::Ctx;
use super::schema::RawFriction;
use super::solids::SolidSpec;
use crate::layout::MAX_FRICTION_GROUPS;
use crate::scenario::{ContactGroup, FrictionPair};

/// The name `between` gives the fixed walls (the tank, moving or not, and the obstacles).
const WALLS: &str = "walls";

/// The pairs of `raw`, each name resolved to its contact groups: a `[[body]]` (after a moving
/// tank, which is body 0), a `[[solid]]`, or "walls" (the fixed walls and a moving tank).
pub(super) fn pairs(
    ctx: &Ctx<'_>,
    raw: &[RawFriction],
    bodies: &[BodySpec],
    solids: &[SolidSpec],
    tank_moves: bool,
) -> Result<Vec<FrictionPair>, CaseError> {
    if raw.is_empty() {
        return Ok(Vec::new());
    }
    let groups = 1 + tank_moves as usize + bodies.len() + solids.len();
    if groups > MAX_FRICTION_GROUPS {
        return Err(ctx.err(
            "friction",
            None,
            format!(
                "friction by pair handles at most {MAX_FRICTION_GROUPS} walls, bodies and solids \
                 together; the case has {groups}"
            ),
            "remove the [[friction]] tables and give one walls.friction_coefficient for all \
             contact",
        ));
    }
    let names: Vec<String> = std::iter::once(format!("\"{WALLS}\""))
        .chain(bodies.iter().map(|b| format!("\"{}\"", b.name)))
        .chain(solids.iter().map(|s| format!("\"{}\"", s.name)))
        .collect();
    let mut out: Vec<FrictionPair> = Vec::new();
    let mut seen: Vec<[Vec<ContactGroup>; 2]> = Vec::new();
    for (i, f) in raw.iter().enumerate() {
        let path = format!("friction[{i}].between");
        if f.between.len() != 2 {
            return Err(ctx.err(
                &path,
                None,
                format!("names {} things; a pair is two", f.between.len()),
                format!("write two names, e.g. between = [\"box\", \"{WALLS}\"]"),
            ));
        }
        let resolve = |k: usize| -> Result<Vec<ContactGroup>, CaseError> {
            let name = f.between[k].as_str();
            let body = bodies.iter().position(|b| b.name == name);
            let solid = solids.iter().position(|s| s.name == name);
            let found: Vec<ContactGroup> = [
                (name == WALLS).then_some(ContactGroup::Walls),
                body.map(|b| ContactGroup::Body(b + tank_moves as usize)),
                solid.map(ContactGroup::Solid),
            ]
            .into_iter()
            .flatten()
            .collect();
            match found.len() {
                0 => Err(ctx.err(
                    &format!("{path}[{k}]"),
                    Some(format!("{name:?}")),
                    "is not the name of a [[body]] or [[solid]], nor \"walls\"",
                    format!("use one of {}", names.join(", ")),
                )),
                1 if found[0] == ContactGroup::Walls && tank_moves => {
                    Ok(vec![ContactGroup::Walls, ContactGroup::Body(0)])
                }
                1 => Ok(found),
                _ => Err(ctx.err(
                    &format!("{path}[{k}]"),
                    Some(format!("{name:?}")),
                    "names more than one thing (\"walls\", a body and a solid share names here)",
                    "rename the body or solid so that each name is one thing",
                )),
            }
        };
        let (a, b) = (resolve(0)?, resolve(1)?);
        if a == b {
            return Err(ctx.err(
                &path,
                None,
                "names the same thing twice: a body or solid has no contact with itself",
                "name two different things",
            ));
        }
        if let Some(j) = seen
            .iter()
            .position(|[x, y]| (*x == a && *y == b) || (*x == b && *y == a))
        {
            return Err(ctx.err(
                &path,
                None,
                format!("friction[{j}] already gives this pair a coefficient"),
                "keep one [[friction]] table per pair",
            ));
        }
        let coefficient = number(
            ctx,
            &format!("friction[{i}].coefficient"),
            f.coefficient,
            Bound::Closed(0.0, 10.0),
            "the pair's Coulomb friction coefficient μ",
            "use 0 (frictionless) to about 1, e.g. 0.3",
        )?;
        for ga in &a {
            for gb in &b {
                out.push(FrictionPair {
                    between: [*ga, *gb],
                    coefficient,
                });
            }
        }
        seen.push([a, b]);
    }
    Ok(out)
}

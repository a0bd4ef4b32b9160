//! Checks of one `[[probe]]`: a file-safe name, exactly the fields of its kind, vectors of the
//! case's dimension (padded to 3 components), a non-zero front axis (normalised).

use crate::scenario::{Probe, ProbeKind};

use super::error::CaseError;
use super::locate::Ctx;
use super::schema::{ProbeName, RawProbe};
use super::validate::vector;

pub(super) fn probe(ctx: &Ctx<'_>, i: usize, p: &RawProbe, dim: usize) -> Result<Probe, CaseError> {
    let path = format!("probe[{i}]");
    if p.name.is_empty()
        || !p
            .name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    {
        return Err(ctx.err(
            &format!("{path}.name"),
            Some(format!("{:?}", p.name)),
            "must be made of letters, digits, `_` and `-` only (it becomes a file name)",
            "use a name like \"P1\" or \"front\"",
        ));
    }
    let (kind_name, needs): (&str, &[&str]) = match p.kind {
        ProbeName::Pressure => ("pressure", &["point_m"]),
        ProbeName::Height => ("height", &["base_m"]),
        ProbeName::Front => ("front", &["origin_m", "axis"]),
    };
    let fields = [
        ("point_m", &p.point_m),
        ("base_m", &p.base_m),
        ("origin_m", &p.origin_m),
        ("axis", &p.axis),
    ];
    for (field, value) in fields {
        let f = format!("{path}.{field}");
        match (needs.contains(&field), value) {
            (true, None) => {
                return Err(ctx.err(
                    &f,
                    None,
                    format!("is required for a \"{kind_name}\" probe"),
                    format!("add {field} = [...] ({} numbers)", dim),
                ));
            }
            (false, Some(_)) => {
                return Err(ctx.err(
                    &f,
                    None,
                    format!(
                        "is not used by a \"{kind_name}\" probe, which takes {}",
                        needs.join(" and ")
                    ),
                    format!("remove {field}, or change the probe's kind"),
                ));
            }
            _ => {}
        }
    }
    let get = |field: &str, v: &Option<Vec<f64>>, what: &str| {
        vector(
            ctx,
            &format!("{path}.{field}"),
            v.as_deref().unwrap_or(&[]),
            dim,
            what,
        )
    };
    let kind = match p.kind {
        ProbeName::Pressure => ProbeKind::Pressure {
            point: get("point_m", &p.point_m, "the sampling point in metres")?,
        },
        ProbeName::Height => ProbeKind::Height {
            base: get("base_m", &p.base_m, "the foot of the gauge line in metres")?,
        },
        ProbeName::Front => {
            let origin = get(
                "origin_m",
                &p.origin_m,
                "the front probe's origin in metres",
            )?;
            let axis = get(
                "axis",
                &p.axis,
                "the direction along which the front is measured",
            )?;
            // Scale first so that huge components do not overflow the norm.
            let big = axis.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
            let scaled = axis.map(|a| if big > 0.0 { a / big } else { 0.0 });
            let len = scaled.iter().map(|a| a * a).sum::<f64>().sqrt();
            if !(len.is_finite() && len > 0.0) {
                return Err(ctx.err(
                    &format!("{path}.axis"),
                    Some(format!("{:?}", p.axis.as_deref().unwrap_or(&[]))),
                    "must be a non-zero direction (it is normalised)",
                    "give the direction of the surge, e.g. [1.0, 0.0]",
                ));
            }
            ProbeKind::Front {
                origin,
                axis: scaled.map(|a| a / len),
            }
        }
    };
    Ok(Probe {
        name: p.name.clone(),
        kind,
        // Resolved against the bodies once they are known (validate.rs).
        body: None,
    })
}

//! Checks of one `[[probe]]`: a file-safe name, exactly the fields of its kind, vectors of the
//! case's dimension (padded to 3 components), a non-zero front axis (normalised); the choice
//! of the particle a `"point"` probe follows; a pressure probe given on a face placed in front
//! of it at the case's dx, and one that starts inside a wall or body told.

use crate::probe_reach::fmt_point;
use crate::scenario::{
    Body, GaugeSurface, Particle, Probe, ProbeKind, TrackedPoint, WallParams, WallPatch,
    FACE_UNBOUNDED,
};

use super::check::{file_safe, vector, MAX_NAME_BYTES};
use super::error::CaseError;
use super::locate::Ctx;
use super::schema::{ProbeName, RawProbe};

/// A checked `[[probe]]`: a sampled quantity (with the unit normal of the face its point lies
/// on, for a pressure probe given by `face_m`: [`place_on_faces`]), or a point of a body to
/// follow.
pub(super) enum Checked {
    Sampled(Probe, Option<[f64; 3]>),
    Point(PointSpec),
}

/// A `kind = "point"` probe before its particle is chosen (`resolve_points`, once the
/// particles are built).
#[derive(Clone, Debug)]
pub(super) struct PointSpec {
    /// Its index among the file's `[[probe]]` tables.
    pub index: usize,
    pub name: String,
    pub point: [f64; 3],
}

/// `probe[i]`, `p`: its name, its fields, and the probe or point it describes.
pub(super) fn probe(
    ctx: &Ctx<'_>,
    i: usize,
    p: &RawProbe,
    dim: usize,
) -> Result<Checked, CaseError> {
    let path = format!("probe[{i}]");
    if !file_safe(&p.name) {
        return Err(ctx.err(
            &format!("{path}.name"),
            Some(format!("{:?}", p.name)),
            format!(
                "must be 1 to {MAX_NAME_BYTES} letters, digits, `_` and `-` (it becomes a file \
                 name)"
            ),
            "use a name like \"P1\" or \"front\"",
        ));
    }
    check_probe_fields(ctx, &path, p, dim)?;
    let get = |field: &str, v: &Option<Vec<f64>>, what: &str| {
        field_vector(ctx, &path, field, v, dim, what)
    };
    let mut on_face = None;
    let kind = match p.kind {
        ProbeName::Point => {
            return Ok(Checked::Point(PointSpec {
                index: i,
                name: p.name.clone(),
                point: get("point_m", &p.point_m, "the point to follow in metres")?,
            }))
        }
        ProbeName::Pressure if p.face_m.is_some() => {
            let normal = get("normal", &p.normal, "the face's normal, into the fluid")?;
            on_face = Some(unit(
                ctx,
                &format!("{path}.normal"),
                normal,
                &p.normal,
                "the normal of a box's face towards the water, e.g. [1.0, 0.0, 0.0]",
            )?);
            ProbeKind::Pressure {
                point: get("face_m", &p.face_m, "a point on a wall's face in metres")?,
            }
        }
        ProbeName::Pressure => ProbeKind::Pressure {
            point: get("point_m", &p.point_m, "the sampling point in metres")?,
        },
        ProbeName::Height | ProbeName::Depth => ProbeKind::Height {
            base: get("base_m", &p.base_m, "the foot of the gauge line in metres")?,
            surface: match p.kind {
                ProbeName::Depth => GaugeSurface::WaterFraction,
                _ => GaugeSurface::FluidHalf,
            },
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
            ProbeKind::Front {
                origin,
                axis: unit(
                    ctx,
                    &format!("{path}.axis"),
                    axis,
                    &p.axis,
                    "the direction of the surge, e.g. [1.0, 0.0]",
                )?,
                continuous: p.continuous.unwrap_or(false),
            }
        }
        ProbeName::WallPressure => wall_pressure(ctx, &path, p, dim)?,
        ProbeName::Discharge => discharge(ctx, &path, p, dim)?,
    };
    Ok(Checked::Sampled(
        Probe {
            name: p.name.clone(),
            kind,
            // Resolved against the bodies once they are known (validate.rs).
            body: None,
        },
        on_face,
    ))
}

/// The fields of `p` at `path`: those its kind needs, and beside them only those it may take
/// (a point probe attached to no body).
fn check_probe_fields(
    ctx: &Ctx<'_>,
    path: &str,
    p: &RawProbe,
    dim: usize,
) -> Result<(), CaseError> {
    let (kind_name, needs, optional): (&str, &[&str], &[&str]) = match p.kind {
        ProbeName::Pressure if p.face_m.is_some() => ("pressure", &["face_m", "normal"], &[]),
        ProbeName::Pressure => ("pressure", &["point_m"], &[]),
        ProbeName::Height => ("height", &["base_m"], &[]),
        ProbeName::Depth => ("depth", &["base_m"], &[]),
        // The furthest particle unless `continuous`.
        ProbeName::Front => ("front", &["origin_m", "axis"], &["continuous"]),
        ProbeName::Point => ("point", &["point_m"], &[]),
        ProbeName::WallPressure => ("wall_pressure", &["point_m", "normal", "radius_m"], &[]),
        ProbeName::Discharge => ("discharge", &["from_m", "to_m"], &[]),
    };
    let unattached = match p.kind {
        ProbeName::Point => Some(
            "is not used by a \"point\" probe: it follows the particle nearest to point_m, \
             whatever body that particle belongs to",
        ),
        ProbeName::Discharge => {
            Some("is not used by a \"discharge\" probe: its section stays where it is drawn")
        }
        _ => None,
    };
    if let (Some(problem), Some(_)) = (unattached, &p.body) {
        return Err(ctx.err(&format!("{path}.body"), None, problem, "remove body"));
    }
    let fields = [
        ("point_m", &p.point_m),
        ("face_m", &p.face_m),
        ("base_m", &p.base_m),
        ("origin_m", &p.origin_m),
        ("axis", &p.axis),
        ("normal", &p.normal),
        ("from_m", &p.from_m),
        ("to_m", &p.to_m),
    ];
    let present = fields
        .iter()
        .map(|(field, value)| (*field, value.is_some()))
        .chain([
            ("radius_m", p.radius_m.is_some()),
            ("continuous", p.continuous.is_some()),
        ]);
    for (field, value) in present {
        if optional.contains(&field) {
            continue;
        }
        let f = format!("{path}.{field}");
        match (needs.contains(&field), value) {
            (true, false) => {
                let add = if field == "radius_m" {
                    format!("add {field} = ... (metres, e.g. half the sensor's diameter)")
                } else {
                    format!("add {field} = [...] ({dim} numbers)")
                };
                return Err(ctx.err(
                    &f,
                    None,
                    format!("is required for a \"{kind_name}\" probe"),
                    add,
                ));
            }
            (false, true) => {
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
    Ok(())
}

/// A discharge probe's section: from `from_m` to `to_m`, in 3D their line in plan (the
/// section is the vertical plane through it), at least some length apart.
fn discharge(ctx: &Ctx<'_>, path: &str, p: &RawProbe, dim: usize) -> Result<ProbeKind, CaseError> {
    let get = |field: &str, v: &Option<Vec<f64>>, what: &str| {
        field_vector(ctx, path, field, v, dim, what)
    };
    let from = get("from_m", &p.from_m, "one end of the section in metres")?;
    let to = get("to_m", &p.to_m, "the other end of the section in metres")?;
    let (_, length) = ProbeKind::section_normal(from, to);
    if !(length.is_finite() && length > 1e-9) {
        let plan = if dim == 3 { " in plan (x and y)" } else { "" };
        return Err(ctx.err(
            &format!("{path}.to_m"),
            p.to_m.as_ref().map(|v| format!("{v:?}")),
            format!("is where from_m is{plan}: the section has no length"),
            "give the two ends of a line across the flow, e.g. from one side of a street to \
             the other",
        ));
    }
    Ok(ProbeKind::Discharge { from, to })
}

/// `{path}.{field}`, `v`: a vector of `dim` finite numbers (`what` it is); a missing one is
/// read as empty.
fn field_vector(
    ctx: &Ctx<'_>,
    path: &str,
    field: &str,
    v: &Option<Vec<f64>>,
    dim: usize,
    what: &str,
) -> Result<[f64; 3], CaseError> {
    vector(
        ctx,
        &format!("{path}.{field}"),
        v.as_deref().unwrap_or(&[]),
        dim,
        what,
    )
}

/// A `"wall_pressure"` probe: the sensor's face (point, unit normal into the fluid, radius).
fn wall_pressure(
    ctx: &Ctx<'_>,
    path: &str,
    p: &RawProbe,
    dim: usize,
) -> Result<ProbeKind, CaseError> {
    let get = |field: &str, v: &Option<Vec<f64>>, what: &str| {
        field_vector(ctx, path, field, v, dim, what)
    };
    let point = get(
        "point_m",
        &p.point_m,
        "the centre of the sensor's face in metres",
    )?;
    let normal = get("normal", &p.normal, "the face's normal, into the fluid")?;
    let radius = p.radius_m.unwrap_or(f64::NAN);
    if !(radius.is_finite() && radius > 0.0) {
        return Err(ctx.err(
            &format!("{path}.radius_m"),
            Some(format!("{radius}")),
            "must be a positive number of metres",
            "give the sensor's radius, e.g. radius_m = 0.005",
        ));
    }
    Ok(ProbeKind::WallPressure(WallPatch {
        point,
        normal: unit(
            ctx,
            &format!("{path}.normal"),
            normal,
            &p.normal,
            "the normal of a right-hand wall, e.g. [-1.0, 0.0]",
        )?,
        radius,
        // Resolved against the particles (`resolve_wall_patches`).
        area: 0.0,
        face: 0.0,
        over_lo: [-FACE_UNBOUNDED; 3],
        over_hi: [FACE_UNBOUNDED; 3],
    }))
}

/// `v` normalised; an error at `path` (a direction) when it is zero or not finite.
fn unit(
    ctx: &Ctx<'_>,
    path: &str,
    v: [f64; 3],
    given: &Option<Vec<f64>>,
    example: &str,
) -> Result<[f64; 3], CaseError> {
    // Scale first so that huge components do not overflow the norm.
    let big = v.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
    let scaled = v.map(|a| if big > 0.0 { a / big } else { 0.0 });
    let len = scaled.iter().map(|a| a * a).sum::<f64>().sqrt();
    if !(len.is_finite() && len > 0.0) {
        return Err(ctx.err(
            path,
            Some(format!("{:?}", given.as_deref().unwrap_or(&[]))),
            "must be a non-zero direction (it is normalised)",
            format!("give {example}"),
        ));
    }
    Ok(scaled.map(|a| a / len))
}

/// The largest wall-pressure patch radius, in smoothing lengths: its box then holds about 50³
/// cells in 3D.
const MAX_PATCH_RADIUS_H: f64 = 20.0;

/// Each wall-pressure probe's patch among the built particles ([`WallPatch::resolve`]): an
/// error when the case has no wall particles (no tank, or mirror walls only) or none lies
/// within its radius (or dx) of its point (a point off the wall).
pub(super) fn resolve_wall_patches(
    ctx: &Ctx<'_>,
    probes: &mut [Probe],
    paths: &[String],
    particles: &[Particle],
    dim: usize,
    dx: f64,
    h: f64,
) -> Result<(), CaseError> {
    let has_walls = particles.iter().any(|p| p.kind.is_boundary());
    for (probe, path) in probes.iter_mut().zip(paths) {
        let ProbeKind::WallPressure(patch) = &mut probe.kind else {
            continue;
        };
        if patch.radius > MAX_PATCH_RADIUS_H * h {
            return Err(ctx.err(
                &format!("{path}.radius_m"),
                Some(format!("{}", patch.radius)),
                format!(
                    "is more than {MAX_PATCH_RADIUS_H} h = {:.4} m: one GPU thread visits every \
                     cell of a wall-pressure probe's box at every sample",
                    MAX_PATCH_RADIUS_H * h
                ),
                "give the sensor's own radius (millimetres to centimetres), or several probes",
            ));
        }
        if !has_walls {
            return Err(ctx.err(
                &format!("{path}.kind"),
                Some("\"wall_pressure\"".into()),
                "sums the fluid's force on wall particles, and the case has none (no [tank] or \
                 [[obstacle]] of particles, or mirror walls only)",
                "add a [tank] with wall = \"dynamic\", \"fixed_ghost\" or \"repulsive\", or use \
                 a \"pressure\" probe",
            ));
        }
        match WallPatch::resolve(
            particles,
            patch.point,
            patch.normal,
            patch.radius,
            dim,
            dx,
            h,
        ) {
            Some(resolved) => *patch = resolved,
            None => {
                return Err(ctx.err(
                    &format!("{path}.point_m"),
                    Some(format!("{:?}", &patch.point[..dim])),
                    format!(
                        "has no wall particle within radius_m = {} (or particles.dx_m = {dx}, \
                         if larger) across the normal and within dx behind it: a wall-pressure \
                         probe sums the fluid's force on the wall particles behind a face \
                         (mirror walls have none)",
                        patch.radius
                    ),
                    "put point_m on the face of a particle wall (of the [tank], an \
                     [[obstacle]] or a [[body]], dynamic, fixed_ghost or repulsive) with normal \
                     pointing into the fluid; a wall that particles.dx_m leaves without \
                     particles there needs a smaller particles.dx_m",
                ));
            }
        }
    }
    Ok(())
}

/// A warning for each pair of wall-pressure probes on fixed walls that meet at an edge: a wall
/// particle in both columns, within 2h of the face of the one it does not belong to
/// (`WallParams::sensor_of`: it belongs to the face it lies less deep behind), carries water
/// of that face which that sensor then misses.
pub(super) fn sensors_meeting_at_edges(
    probes: &[Probe],
    paths: &[String],
    walls: &WallParams,
    particles: &[Particle],
    h: f64,
) -> Vec<String> {
    // Path and name of each sensor, in the order of `walls.sensors`.
    let names: Vec<(&str, &str)> = (probes.iter().zip(paths))
        .filter(|(p, _)| p.body.is_none() && matches!(p.kind, ProbeKind::WallPressure(_)))
        .map(|(p, path)| (path.as_str(), p.name.as_str()))
        .collect();
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    for p in particles.iter().filter(|p| p.kind.is_boundary()) {
        let Some(owner) = walls.sensor_of(p.pos, h) else {
            continue;
        };
        for (k, s) in walls.sensors.iter().enumerate() {
            if k != owner
                && s.holds(p.pos, h)
                && !s.same_face(&walls.sensors[owner])
                && s.depth_behind_face(p.pos) < 2.0 * h
                && !pairs.contains(&(owner, k))
            {
                pairs.push((owner, k));
            }
        }
    }
    pairs.sort_unstable();
    pairs
        .into_iter()
        .map(|(owner, k)| {
            let ((i, a), (j, b)) = (names[owner], names[k]);
            format!(
                "{j} ('{b}') and {i} ('{a}') meet at an edge: wall particles \
                 within 2h = {:.4} m of {j}'s face lie in both columns and count for \
                 {i}'s face, which they are nearer, so {j} misses the water \
                 they carry; fix: move the sensors apart, each more than 2h behind the other's \
                 face, or give them smaller radius_m",
                2.0 * h
            )
        })
        .collect()
}

/// The particle each point probe follows: the nearest particle of an elastic solid or a rigid
/// body (moving tank included) at t = 0, which must lie within 2 dx of `point_m`.
pub(super) fn resolve_points(
    ctx: &Ctx<'_>,
    specs: &[PointSpec],
    particles: &[Particle],
    bodies: &[Body],
    dim: usize,
    dx: f64,
) -> Result<Vec<TrackedPoint>, CaseError> {
    let show = |x: &[f64; 3]| {
        let parts: Vec<String> = x[..dim].iter().map(|v| format!("{v:.4}")).collect();
        format!("[{}]", parts.join(", "))
    };
    let followable =
        |k: usize| particles[k].kind.is_solid() || bodies.iter().any(|b| b.particles.contains(&k));
    specs
        .iter()
        .map(|s| {
            let path = format!("probe[{}].point_m", s.index);
            let d2 = |k: usize| {
                (0..3)
                    .map(|a| (particles[k].pos[a] - s.point[a]).powi(2))
                    .sum::<f64>()
            };
            let nearest = (0..particles.len())
                .filter(|&k| followable(k))
                .min_by(|&a, &b| d2(a).total_cmp(&d2(b)));
            let Some(k) = nearest else {
                return Err(ctx.err(
                    &format!("probe[{}].kind", s.index),
                    Some("\"point\"".into()),
                    "follows a particle of an elastic solid or a rigid body, and the case has \
                     neither",
                    "add a [[solid]] or [[body]], or use a pressure or height probe",
                ));
            };
            let d = d2(k).sqrt();
            if d > 2.0 * dx {
                return Err(ctx.err(
                    &path,
                    Some(show(&s.point)),
                    format!(
                        "is {d:.4} m from the nearest particle of a solid or body (at {}), more \
                         than 2 dx = {:.4} m",
                        show(&particles[k].pos),
                        2.0 * dx
                    ),
                    "put point_m on (or inside) the body whose point you want to follow",
                ));
            }
            Ok(TrackedPoint {
                name: s.name.clone(),
                particle: k as u32,
            })
        })
        .collect()
}

/// Each pressure probe given on a face (`face_m`, its `normals` entry) moved out along its
/// normal to half a spacing in front of the face that the wall's particles have at this dx
/// ([`WallPatch::resolve`]: half a spacing in front of their first layer), the centre of the
/// first fluid layer. A shipped probe sits there at the shipped dx; given by its face, it stays
/// there at any dx, however the lattice rounds the wall.
pub(super) fn place_on_faces(
    ctx: &Ctx<'_>,
    probes: &mut [Probe],
    paths: &[String],
    normals: &[Option<[f64; 3]>],
    particles: &[Particle],
    (dim, dx, h): (usize, f64, f64),
) -> Result<(), CaseError> {
    for ((probe, normal), path) in probes.iter_mut().zip(normals).zip(paths) {
        let (ProbeKind::Pressure { point }, Some(normal)) = (&mut probe.kind, normal) else {
            continue;
        };
        let Some(patch) = WallPatch::resolve(particles, *point, *normal, 0.5 * dx, dim, dx, h)
        else {
            return Err(ctx.err(
                &format!("{path}.face_m"),
                Some(format!("{:?}", &point[..dim])),
                format!(
                    "has no wall particle within particles.dx_m = {dx} of it across its normal \
                     and within dx behind it: a pressure probe given by face_m samples in front \
                     of the face of a particle wall"
                ),
                "put face_m on a face of the [tank], an [[obstacle]] or a [[body]] of particles \
                 (dynamic, fixed_ghost or repulsive), with normal pointing into the fluid; or \
                 give point_m, a point in the water, instead",
            ));
        };
        let out = patch.face + 0.5 * dx;
        *point = [0, 1, 2].map(|a| point[a] + out * normal[a]);
    }
    Ok(())
}

/// The warnings of the pressure probes (those not in `blind`) whose point starts inside a
/// wall, an obstacle, a body or a solid: within the lattice cell (half a spacing along every
/// axis) of one of its particles. Such a probe reads, through the kernel, the water in front of
/// the face rather than the pressure at its point.
pub(super) fn inside_walls(
    probes: &[Probe],
    blind: &[bool],
    particles: &[Particle],
    dim: usize,
    dx: f64,
) -> Vec<String> {
    let half = 0.5 * dx * (1.0 - 1e-6);
    let solid = |p: &&Particle| p.kind.is_boundary() || p.kind.is_solid();
    (probes.iter().zip(blind))
        .filter(|(_, &blind)| !blind)
        .filter_map(|(probe, _)| {
            let ProbeKind::Pressure { point } = probe.kind else {
                return None;
            };
            let inside = (particles.iter().filter(solid))
                .find(|p| (0..dim).all(|a| (p.pos[a] - point[a]).abs() < half))?;
            Some(format!(
                "probe '{}' (point_m) starts inside a wall, an obstacle or a body: {} lies \
                     within half a spacing (dx = {dx} m) of its particle at {}, so it reads the \
                     water in front of the face through the kernel, not the pressure at its \
                     point; fix: give the face instead (face_m and normal: the probe then \
                     samples half a spacing in front of it at any dx), or move point_m into the \
                     water",
                probe.name,
                fmt_point(&point, dim as u32),
                fmt_point(&inside.pos, dim as u32),
            ))
        })
        .collect()
}

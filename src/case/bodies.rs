//! Moving solids in case files: `[[body]]` tables and `[tank.motion]`. Field checks, the
//! motion laws (sine, or a CSV time series read relative to the case file), the bodies'
//! particles and their mass properties (from the shape, not from the particles, so a body can
//! be a shell of a few particle layers).

use std::f64::consts::PI;
use std::path::Path;
use std::sync::Arc;

use crate::scenario::{Motion, MotionLaw, Prescribed};

use super::check::{
    aabb, file_safe, initial_velocity, number, read_mesh, treatment, vector, Aabb, Bound,
    Treatment, MAX_NAME_BYTES,
};
use super::error::{num, CaseError};
use super::locate::Ctx;
use super::schema::{MotionName, RawBody, RawMotion, ShapeName};
use super::time_series;
use crate::generate::mesh::Mesh;
use crate::generate::polygon::Polygon;

#[derive(Debug, Clone, PartialEq)]
pub(super) enum Shape {
    Box(Aabb),
    /// A circle (2D) or a sphere (3D).
    Ball {
        center: [f64; 3],
        radius: f64,
    },
    /// A simple polygon (2D).
    Polygon(Arc<Polygon>),
    /// A closed triangle surface read from an STL file (3D).
    Mesh(Arc<Mesh>),
}

#[derive(Debug, Clone)]
pub(super) struct BodySpec {
    pub name: String,
    pub shape: Shape,
    /// Mass [kg] (per metre in 2D); `None` for prescribed bodies given neither mass nor density.
    pub mass: Option<f64>,
    /// Particle layers under the surface; `None`: the whole body.
    pub layers: Option<u32>,
    /// The kind of its particles (never `Mirror`).
    pub wall: Treatment,
    pub motion: Motion,
}

/// `[[body]]`: every body checked, in order.
pub(super) fn validate(
    ctx: &Ctx<'_>,
    raw: &[RawBody],
    dim: usize,
    case_dir: &Path,
) -> Result<Vec<BodySpec>, CaseError> {
    let mut out: Vec<BodySpec> = Vec::with_capacity(raw.len());
    for (i, b) in raw.iter().enumerate() {
        let spec = body(ctx, (i, b), &out, dim, case_dir)?;
        out.push(spec);
    }
    Ok(out)
}

/// `body[i]`, `b`; `earlier`: the bodies before it, whose names it must not repeat.
fn body(
    ctx: &Ctx<'_>,
    (i, b): (usize, &RawBody),
    earlier: &[BodySpec],
    dim: usize,
    case_dir: &Path,
) -> Result<BodySpec, CaseError> {
    let path = format!("body[{i}]");
    if !file_safe(&b.name) || b.name == "tank" {
        return Err(ctx.err(
            &format!("{path}.name"),
            Some(format!("{:?}", b.name)),
            format!(
                "must be 1 to {MAX_NAME_BYTES} letters, digits, `_` and `-` (it becomes the \
                 file name probes/body_<name>.csv) and must not be \"tank\" (the moving \
                 tank's name)"
            ),
            "use a name like \"box\" or \"cylinder\"",
        ));
    }
    if let Some(j) = earlier.iter().position(|o| o.name == b.name) {
        return Err(ctx.err(
            &format!("{path}.name"),
            Some(format!("{:?}", b.name)),
            format!("body[{j}] already has this name"),
            "give every body a different name",
        ));
    }
    let wall = treatment(ctx, &path, b.wall, b.slip)?;
    if let Treatment::Mirror { .. } = wall {
        return Err(ctx.err(
            &format!("{path}.wall"),
            Some("\"mirror\"".into()),
            "mirror ghosts are for the tank's straight faces",
            "use wall = \"fixed_ghost\" (or \"dynamic\", \"repulsive\")",
        ));
    }
    let shape = shape(ctx, &path, b, dim, case_dir)?;
    let mass = mass(ctx, &path, b, &shape, dim)?;
    let layers = match b.layers {
        None => None,
        Some(l) if (1..=64).contains(&l) => Some(l as u32),
        Some(l) => {
            return Err(ctx.err(
                &format!("{path}.layers"),
                Some(l.to_string()),
                "must be between 1 and 64 (particle layers under the surface)",
                "use 3 or more (the kernel support is 2h), or remove it to fill the body",
            ))
        }
    };
    let motion_path = format!("{path}.motion");
    let motion = match &b.motion {
        None => Motion::Free {
            velocity: [0.0; 3],
            omega: [0.0; 3],
            release_s: 0.0,
        },
        Some(m) => motion(ctx, &motion_path, m, dim, true, case_dir)?,
    };
    if matches!(motion, Motion::Free { .. }) && mass.is_none() {
        return Err(ctx.err(
            &path,
            None,
            "a free body (one without [body.motion], or with kind = \"free\") needs its \
             mass: give density_kg_m3 or mass_kg",
            "add density_kg_m3 = 500.0 (or mass_kg)",
        ));
    }
    Ok(BodySpec {
        name: b.name.clone(),
        shape,
        mass,
        layers,
        wall,
        motion,
    })
}

/// The largest body a case may hold, in metres across: a thousand kilometres.
const MAX_BODY_SIZE_M: f64 = 1e6;

/// The mass of body `b` at `path` (of `shape`): from `density_kg_m3` or `mass_kg` (not both;
/// neither: `None`), with a mass and moments of inertia that can be computed with.
fn mass(
    ctx: &Ctx<'_>,
    path: &str,
    b: &RawBody,
    shape: &Shape,
    dim: usize,
) -> Result<Option<f64>, CaseError> {
    let mass = match (b.density_kg_m3, b.mass_kg) {
        (Some(_), Some(_)) => {
            return Err(ctx.err(
                &format!("{path}.mass_kg"),
                None,
                "density_kg_m3 and mass_kg are both given",
                "keep only one of them",
            ))
        }
        (Some(d), None) => Some(
            number(
                ctx,
                &format!("{path}.density_kg_m3"),
                d,
                Bound::Positive,
                "the body density in kg/m³",
                "give a positive density, e.g. 500.0",
            )? * shape.measure(dim),
        ),
        (None, Some(m)) => Some(number(
            ctx,
            &format!("{path}.mass_kg"),
            m,
            Bound::Positive,
            "the body mass in kg (per metre of depth in 2D)",
            "give a positive mass",
        )?),
        (None, None) => None,
    };
    if let Some(m) = mass {
        // Density times a large area, or a large mass times a large size, can overflow (or
        // a tiny density underflow to 0); the rigid-body equations divide by both.
        let inertia = shape.inertia(dim, m);
        let used: &[usize] = if dim == 2 { &[2] } else { &[0, 1, 2] };
        let fine = |x: f64| x.is_finite() && x > 0.0;
        if !(fine(m) && used.iter().all(|&a| fine(inertia[a][a]))) {
            // A shape of no realistic size is the cause, not the density (issue 64: a vertex
            // at 1e30 m was blamed on the density).
            let bounds = shape.bounds(dim);
            let size = (0..dim)
                .map(|a| bounds.max[a] - bounds.min[a])
                .fold(0.0, f64::max);
            if !(size.is_finite() && size <= MAX_BODY_SIZE_M) {
                return Err(ctx.err(
                    path,
                    None,
                    format!(
                        "has a shape {} m across, which no mass or inertia can be computed \
                         for (from {:?} to {:?})",
                        num(size),
                        &bounds.min[..dim],
                        &bounds.max[..dim]
                    ),
                    "check the shape's coordinates and the mesh's units (scale it to metres)",
                ));
            }
            let (field, value) = match (b.density_kg_m3, b.mass_kg) {
                (Some(d), _) => ("density_kg_m3", d),
                (_, m) => ("mass_kg", m.unwrap_or(0.0)),
            };
            return Err(ctx.err(
                &format!("{path}.{field}"),
                Some(num(value)),
                format!(
                    "gives the body a mass of {} kg and moments of inertia {:?} kg m² that \
                     cannot be computed with",
                    num(m),
                    used.iter().map(|&a| num(inertia[a][a])).collect::<Vec<_>>()
                ),
                "give a realistic density or mass",
            ));
        }
    }
    Ok(mass)
}

fn shape(
    ctx: &Ctx<'_>,
    path: &str,
    b: &RawBody,
    dim: usize,
    case_dir: &Path,
) -> Result<Shape, CaseError> {
    let (name, needs): (&str, &[&str]) = match b.shape {
        ShapeName::Box => ("box", &["min_m", "max_m"]),
        ShapeName::Circle => ("circle", &["center_m", "radius_m"]),
        ShapeName::Sphere => ("sphere", &["center_m", "radius_m"]),
        ShapeName::Polygon => ("polygon", &["vertices_m"]),
        ShapeName::Mesh => ("mesh", &["file"]),
    };
    let given = [
        ("min_m", b.min_m.is_some()),
        ("max_m", b.max_m.is_some()),
        ("center_m", b.center_m.is_some()),
        ("radius_m", b.radius_m.is_some()),
        ("vertices_m", b.vertices_m.is_some()),
        ("file", b.file.is_some()),
    ];
    for (field, present) in given {
        if present != needs.contains(&field) {
            return Err(ctx.err(
                &format!("{path}.{field}"),
                None,
                if present {
                    format!("is not used by a {name} body")
                } else {
                    format!("is required for a {name} body")
                },
                format!("a {name} body takes {}", needs.join(" and ")),
            ));
        }
    }
    match (b.shape, dim) {
        (ShapeName::Circle | ShapeName::Polygon, 3) | (ShapeName::Sphere | ShapeName::Mesh, 2) => {
            return Err(ctx.err(
                &format!("{path}.shape"),
                Some(format!("\"{name}\"")),
                format!("is not a {dim}D shape"),
                if dim == 2 {
                    "use shape = \"circle\" (or \"box\", \"polygon\") in 2D"
                } else {
                    "use shape = \"sphere\" (or \"box\", \"mesh\") in 3D"
                },
            ))
        }
        _ => {}
    }
    if let Some(file) = &b.file {
        let field = format!("{path}.file");
        let triangles = read_mesh(ctx, &field, case_dir, file)?;
        let full = case_dir.join(file).display().to_string();
        let mesh = Mesh::new(&full, &triangles.vertices, &triangles.faces)
            .map_err(|e| ctx.err(&field, Some(format!("{file:?}")), e.to_string(), e.fix()))?;
        return Ok(Shape::Mesh(Arc::new(mesh)));
    }
    if let Some(corners) = &b.vertices_m {
        let field = format!("{path}.vertices_m");
        let mut v = Vec::with_capacity(corners.len());
        for (k, c) in corners.iter().enumerate() {
            let p = vector(ctx, &format!("{field}[{k}]"), c, 2, "a corner in metres")?;
            v.push([p[0], p[1]]);
        }
        let polygon = Polygon::new(&v).map_err(|e| {
            ctx.err(
                &field,
                None,
                e.to_string(),
                "list the corners in order around the outline (either sense), each once, \
                 with no two edges crossing",
            )
        })?;
        return Ok(Shape::Polygon(Arc::new(polygon)));
    }
    Ok(match (&b.min_m, &b.max_m, &b.center_m, b.radius_m) {
        (Some(lo), Some(hi), _, _) => Shape::Box(aabb(ctx, path, lo, hi, dim, "the body")?),
        (_, _, Some(c), Some(r)) => Shape::Ball {
            center: vector(
                ctx,
                &format!("{path}.center_m"),
                c,
                dim,
                "the centre in metres",
            )?,
            radius: number(
                ctx,
                &format!("{path}.radius_m"),
                r,
                Bound::Positive,
                "the radius in metres",
                "give a positive radius",
            )?,
        },
        _ => unreachable!("fields checked above"),
    })
}

/// A `[... .motion]` table; `for_body`: a body's, which may also be free or fixed (the tank is
/// only prescribed).
pub(super) fn motion(
    ctx: &Ctx<'_>,
    path: &str,
    m: &RawMotion,
    dim: usize,
    for_body: bool,
    case_dir: &Path,
) -> Result<Motion, CaseError> {
    let kind = check_motion_fields(ctx, path, m)?;
    if !for_body && matches!(m.kind, MotionName::Free | MotionName::Fixed) {
        return Err(ctx.err(
            &format!("{path}.kind"),
            Some(format!("\"{kind}\"")),
            if m.kind == MotionName::Free {
                "the tank cannot move freely"
            } else {
                "a tank without [tank.motion] is fixed"
            },
            "use kind = \"sine\" or \"series\" (or remove [tank.motion])",
        ));
    }
    if m.kind == MotionName::Fixed {
        return Ok(Motion::Prescribed(Prescribed {
            pivot: [0.0; 3],
            axis: [0.0, 0.0, 1.0],
            law: MotionLaw::Fixed,
        }));
    }
    if m.kind == MotionName::Free {
        return free_motion(ctx, path, m, dim);
    }
    let pivot = match &m.pivot_m {
        Some(p) => vector(
            ctx,
            &format!("{path}.pivot_m"),
            p,
            dim,
            "the rotation pivot in metres",
        )?,
        None => [0.0; 3],
    };
    let axis = match &m.axis {
        Some(_) if dim == 2 => {
            return Err(ctx.err(
                &format!("{path}.axis"),
                None,
                "is only used in 3D (2D motions turn about z)",
                "remove axis",
            ))
        }
        None => [0.0, 0.0, 1.0],
        Some(a) => {
            let a = vector(ctx, &format!("{path}.axis"), a, 3, "the rotation axis")?;
            let len = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            if len == 0.0 {
                return Err(ctx.err(
                    &format!("{path}.axis"),
                    None,
                    "is the zero vector",
                    "give the rotation axis, e.g. [0.0, 1.0, 0.0]",
                ));
            }
            a.map(|c| c / len)
        }
    };
    let law = if m.kind == MotionName::Sine {
        sine_law(ctx, path, m, dim)?
    } else {
        let Some(file) = &m.file else {
            return Err(ctx.err(
                &format!("{path}.file"),
                None,
                "is required for a series motion",
                "add file = \"excitation.csv\" (t_s, dx_m, dy_m[, dz_m], angle_deg)",
            ));
        };
        series(ctx, &format!("{path}.file"), file, dim, case_dir)?
    };
    Ok(Motion::Prescribed(Prescribed { pivot, axis, law }))
}

/// The motion's kind as the file writes it; an error names the first field given that the
/// kind does not use.
fn check_motion_fields(
    ctx: &Ctx<'_>,
    path: &str,
    m: &RawMotion,
) -> Result<&'static str, CaseError> {
    let needs: &[&str] = match m.kind {
        MotionName::Free => &["velocity_m_s", "angular_velocity_rad_s", "release_s"],
        MotionName::Fixed => &[],
        MotionName::Sine => &[
            "pivot_m",
            "axis",
            "translation_m",
            "rotation_deg",
            "period_s",
            "phase_deg",
        ],
        MotionName::Series => &["pivot_m", "axis", "file"],
    };
    let kind = match m.kind {
        MotionName::Free => "free",
        MotionName::Fixed => "fixed",
        MotionName::Sine => "sine",
        MotionName::Series => "series",
    };
    let given = [
        ("velocity_m_s", m.velocity_m_s.is_some()),
        ("angular_velocity_rad_s", m.angular_velocity_rad_s.is_some()),
        ("release_s", m.release_s.is_some()),
        ("pivot_m", m.pivot_m.is_some()),
        ("axis", m.axis.is_some()),
        ("translation_m", m.translation_m.is_some()),
        ("rotation_deg", m.rotation_deg.is_some()),
        ("period_s", m.period_s.is_some()),
        ("phase_deg", m.phase_deg.is_some()),
        ("file", m.file.is_some()),
    ];
    for (field, present) in given {
        if present && !needs.contains(&field) {
            return Err(ctx.err(
                &format!("{path}.{field}"),
                None,
                format!("is not used by a {kind} motion"),
                if needs.is_empty() {
                    format!("a {kind} motion takes no other field: remove it")
                } else {
                    format!("a {kind} motion takes {}", needs.join(", "))
                },
            ));
        }
    }
    Ok(kind)
}

/// A free motion: the initial velocity and angular velocity, or a release time.
fn free_motion(ctx: &Ctx<'_>, path: &str, m: &RawMotion, dim: usize) -> Result<Motion, CaseError> {
    let velocity = initial_velocity(ctx, path, &m.velocity_m_s, dim)?;
    let omega = match &m.angular_velocity_rad_s {
        None => [0.0; 3],
        // One component (the length is right): `vector` only checks that it is finite,
        // naming `angular_velocity_rad_s[0]`.
        Some(w) if dim == 2 && w.len() == 1 => {
            let w = vector(
                ctx,
                &format!("{path}.angular_velocity_rad_s"),
                w,
                1,
                "the initial rate of turn about z in rad/s",
            )?;
            [0.0, 0.0, w[0]]
        }
        Some(w) if dim == 3 => vector(
            ctx,
            &format!("{path}.angular_velocity_rad_s"),
            w,
            3,
            "the initial angular velocity in rad/s",
        )?,
        Some(w) => {
            return Err(ctx.err(
                &format!("{path}.angular_velocity_rad_s"),
                Some(format!("{w:?}")),
                "in 2D (dimension = 2) is one number in a list, the rate about z",
                "write angular_velocity_rad_s = [0.0]",
            ))
        }
    };
    let release_s = match m.release_s {
        None => 0.0,
        Some(r) if r.is_finite() && r >= 0.0 => r,
        Some(r) => {
            return Err(ctx.err(
                &format!("{path}.release_s"),
                Some(r.to_string()),
                "must be a time of at least 0 s (how long the body is held at rest before \
                 it is released)",
                "write e.g. release_s = 1.0, or remove it to release the body at once",
            ))
        }
    };
    if release_s > 0.0 && (velocity != [0.0; 3] || omega != [0.0; 3]) {
        return Err(ctx.err(
            &format!("{path}.release_s"),
            Some(release_s.to_string()),
            "holds the body at rest until it is released, so it cannot also have an \
             initial velocity_m_s or angular_velocity_rad_s",
            "remove velocity_m_s and angular_velocity_rad_s (a held body is released from \
             rest), or remove release_s",
        ));
    }
    Ok(Motion::Free {
        velocity,
        omega,
        release_s,
    })
}

/// The law of a sine motion: its period, amplitudes and phase.
fn sine_law(ctx: &Ctx<'_>, path: &str, m: &RawMotion, dim: usize) -> Result<MotionLaw, CaseError> {
    let Some(period) = m.period_s else {
        return Err(ctx.err(
            &format!("{path}.period_s"),
            None,
            "is required for a sine motion",
            "add period_s = 3.14159 (for example)",
        ));
    };
    let period = number(
        ctx,
        &format!("{path}.period_s"),
        period,
        Bound::Positive,
        "the period in seconds",
        "give a positive period",
    )?;
    let translation = match &m.translation_m {
        Some(t) => vector(
            ctx,
            &format!("{path}.translation_m"),
            t,
            dim,
            "the displacement amplitude in metres",
        )?,
        None => [0.0; 3],
    };
    let angle = number(
        ctx,
        &format!("{path}.rotation_deg"),
        m.rotation_deg.unwrap_or(0.0),
        Bound::Closed(-180.0, 180.0),
        "the rotation amplitude in degrees",
        "give an amplitude between -180 and 180 degrees",
    )?;
    let phase = number(
        ctx,
        &format!("{path}.phase_deg"),
        m.phase_deg.unwrap_or(0.0),
        Bound::Closed(-360.0, 360.0),
        "the phase in degrees",
        "give a phase between -360 and 360 degrees",
    )?;
    Ok(MotionLaw::Sine {
        translation,
        angle: angle.to_radians(),
        omega: 2.0 * PI / period,
        phase: phase.to_radians(),
    })
}

/// A motion time series: rows `t_s, dx_m, dy_m[, dz_m], angle_deg` (t strictly increasing).
fn series(
    ctx: &Ctx<'_>,
    path: &str,
    file: &str,
    dim: usize,
    case_dir: &Path,
) -> Result<MotionLaw, CaseError> {
    let columns: &[&str] = if dim == 3 {
        &["t_s", "dx_m", "dy_m", "dz_m", "angle_deg"]
    } else {
        &["t_s", "dx_m", "dy_m", "angle_deg"]
    };
    let rows = time_series::read(ctx, path, file, case_dir, columns)?;
    let t = rows.iter().map(|r| r.values[0]).collect();
    let translation = (rows.iter())
        .map(|r| {
            let mut d = [0.0; 3];
            d[..dim].copy_from_slice(&r.values[1..=dim]);
            d
        })
        .collect();
    let angle = rows
        .iter()
        .map(|r| r.values[dim + 1].to_radians())
        .collect();
    Ok(MotionLaw::Series {
        t,
        translation,
        angle,
    })
}

impl Shape {
    /// Area (2D) or volume (3D).
    pub(super) fn measure(&self, dim: usize) -> f64 {
        match self {
            Shape::Box(b) => (0..dim).map(|a| b.max[a] - b.min[a]).product(),
            Shape::Ball { radius, .. } if dim == 2 => PI * radius * radius,
            Shape::Ball { radius, .. } => 4.0 / 3.0 * PI * radius.powi(3),
            Shape::Polygon(p) => p.area(),
            Shape::Mesh(m) => m.volume(),
        }
    }

    /// How many points [`Shape::points`] considers at spacing `dx` (at least as many as it
    /// returns), for the particle budget.
    pub(super) fn lattice_size(&self, dx: f64, dim: usize) -> f64 {
        match self {
            Shape::Box(b) => (0..dim)
                .map(|a| ((b.max[a] - b.min[a]) / dx).round().max(1.0))
                .product(),
            // Rings a spacing apart, each with about 2 pi r / dx points.
            Shape::Ball { radius, .. } if dim == 2 => PI * (radius / dx + 1.0).powi(2),
            Shape::Ball { radius, .. } => (2.0 * (radius / dx).ceil() + 1.0).powi(3),
            Shape::Polygon(p) => p.particle_bound(dx, None, super::limits::MAX_PARTICLES),
            Shape::Mesh(m) => m.lattice(dx).0.iter().map(|&n| n as f64).product(),
        }
    }

    /// The centre of mass at uniform density.
    pub(super) fn center(&self) -> [f64; 3] {
        match self {
            Shape::Box(b) => [0, 1, 2].map(|a| 0.5 * (b.min[a] + b.max[a])),
            Shape::Ball { center, .. } => *center,
            Shape::Polygon(p) => p.centroid(),
            Shape::Mesh(m) => m.centroid(),
        }
    }

    /// The smallest box around the shape (third axis 0 in 2D).
    pub(super) fn bounds(&self, dim: usize) -> Aabb {
        match self {
            Shape::Box(b) => *b,
            Shape::Ball { center, radius } => Aabb {
                min: [0, 1, 2].map(|a| if a < dim { center[a] - radius } else { 0.0 }),
                max: [0, 1, 2].map(|a| if a < dim { center[a] + radius } else { 0.0 }),
            },
            Shape::Polygon(p) => p.bounds(),
            Shape::Mesh(m) => m.bounds(),
        }
    }

    /// Inertia tensor about the centre of a uniform body of `mass`.
    pub(super) fn inertia(&self, dim: usize, mass: f64) -> [[f64; 3]; 3] {
        let diag = match self {
            Shape::Box(b) => {
                let s = [0, 1, 2].map(|a| if a < dim { b.max[a] - b.min[a] } else { 0.0 });
                let sq = s.map(|x| x * x);
                [
                    mass * (sq[1] + sq[2]) / 12.0,
                    mass * (sq[0] + sq[2]) / 12.0,
                    mass * (sq[0] + sq[1]) / 12.0,
                ]
            }
            Shape::Ball { radius, .. } if dim == 2 => {
                let r2 = radius * radius;
                [mass * r2 / 4.0, mass * r2 / 4.0, mass * r2 / 2.0]
            }
            Shape::Ball { radius, .. } => [0.4 * mass * radius * radius; 3],
            Shape::Polygon(p) => return p.inertia(mass),
            Shape::Mesh(m) => return m.inertia(mass),
        };
        [
            [diag[0], 0.0, 0.0],
            [0.0, diag[1], 0.0],
            [0.0, 0.0, diag[2]],
        ]
    }

    /// The shape's thickness, twice the depth of its deepest point, when that is less than
    /// `limit` (`None`: at least `limit` thick). Exact for a box (its smallest side) and a
    /// ball; for a polygon or mesh estimated from its particles at spacing `dx` (their layers
    /// are dx apart and the deepest lies less than dx under the middle): twice the deepest
    /// particle's depth plus dx, to within dx.
    pub(super) fn thinner_than(&self, limit: f64, dx: f64, dim: usize) -> Option<f64> {
        // A particle (limit − dx)/2 deep makes the estimate reach the limit: stop there.
        let reach = 0.5 * (limit - dx);
        let deepest = |depth: &dyn Fn([f64; 3]) -> Option<f64>| {
            self.points(dx, dim, None)
                .into_iter()
                .try_fold(0.0f64, |deepest, p| Some(deepest.max(depth(p)?)))
        };
        let thickness = match self {
            Shape::Box(b) => (0..dim)
                .map(|a| b.max[a] - b.min[a])
                .fold(f64::MAX, f64::min),
            Shape::Ball { radius, .. } => 2.0 * radius,
            Shape::Polygon(q) => {
                2.0 * deepest(&|p| Some(q.distance(p)).filter(|&d| d < reach))? + dx
            }
            Shape::Mesh(m) => 2.0 * deepest(&|p| m.distance_within(p, reach))? + dx,
        };
        (thickness < limit).then_some(thickness)
    }

    /// Whether `p` is inside the shape or less than `margin` from its surface.
    pub(super) fn near(&self, p: [f64; 3], margin: f64, dim: usize) -> bool {
        match self {
            Shape::Box(b) => box_distance(b, p, dim) < margin,
            Shape::Ball { center, radius } => ball_distance(*center, *radius, p, dim) < margin,
            Shape::Polygon(q) => q.contains(p) || q.distance(p) < margin,
            Shape::Mesh(m) => m.contains(p) || m.distance_within(p, margin).is_some(),
        }
    }

    /// The body's particles at spacing `dx`: a box on its own cell-centred lattice, a circle
    /// as concentric rings (a smooth surface), a polygon in layers along its outline, a sphere
    /// on a lattice through its centre, a mesh on a cell-centred lattice over its bounding box;
    /// only the outer `layers` when given.
    pub(super) fn points(&self, dx: f64, dim: usize, layers: Option<u32>) -> Vec<[f64; 3]> {
        let depth = layers.map_or(f64::MAX, |l| l as f64 * dx);
        let mut out = Vec::new();
        match *self {
            Shape::Polygon(ref p) => return p.points(dx, layers.map(|_| depth)),
            Shape::Mesh(ref m) => return m.points(dx, layers.map(|_| depth)),
            Shape::Box(b) => {
                let n = [0, 1, 2].map(|a| {
                    if a < dim {
                        ((b.max[a] - b.min[a]) / dx).round().max(1.0) as i64
                    } else {
                        1
                    }
                });
                let step = [0, 1, 2].map(|a| {
                    if a < dim {
                        (b.max[a] - b.min[a]) / n[a] as f64
                    } else {
                        0.0
                    }
                });
                for i in 0..n[0] {
                    for j in 0..n[1] {
                        for k in 0..n[2] {
                            let idx = [i, j, k];
                            let p = [0, 1, 2].map(|a| {
                                if a < dim {
                                    b.min[a] + (idx[a] as f64 + 0.5) * step[a]
                                } else {
                                    0.0
                                }
                            });
                            if -box_distance(&b, p, dim) < depth {
                                out.push(p);
                            }
                        }
                    }
                }
            }
            Shape::Ball { center, radius } if dim == 2 => {
                let mut r = radius - 0.5 * dx;
                let mut ring = 0;
                while r > 0.0 && radius - r < depth {
                    if r * 3f64.sqrt() < dx {
                        // No room for a ring of three: one particle at the centre.
                        out.push(center);
                        break;
                    }
                    // As many as fit with a chord of at least dx.
                    let n = ((PI / (0.5 * dx / r).asin()).floor() as usize).max(3);
                    let shift = if ring % 2 == 0 { 0.0 } else { 0.5 };
                    for j in 0..n {
                        // From the bottom: every ring is mirror-symmetric about the vertical
                        // through the centre, as a vertical entry or a floating body is.
                        let a = -0.5 * PI + 2.0 * PI * (j as f64 + shift) / n as f64;
                        out.push([center[0] + r * a.cos(), center[1] + r * a.sin(), 0.0]);
                    }
                    r -= dx;
                    ring += 1;
                }
            }
            Shape::Ball { center, radius } => {
                let n = (radius / dx).ceil() as i64;
                for i in -n..=n {
                    for j in -n..=n {
                        for k in -n..=n {
                            let p = [
                                center[0] + i as f64 * dx,
                                center[1] + j as f64 * dx,
                                center[2] + k as f64 * dx,
                            ];
                            let d = -ball_distance(center, radius, p, dim);
                            if d >= 0.5 * dx - 1e-9 * dx && d < depth + 0.5 * dx {
                                out.push(p);
                            }
                        }
                    }
                }
            }
        }
        out
    }
}

/// Distance from `p` to the surface of the box `b`, negative inside.
fn box_distance(b: &Aabb, p: [f64; 3], dim: usize) -> f64 {
    let d: Vec<f64> = (0..dim)
        .map(|a| (b.min[a] - p[a]).max(p[a] - b.max[a]))
        .collect();
    let outside = d.iter().map(|x| x.max(0.0).powi(2)).sum::<f64>().sqrt();
    let inside = d.iter().cloned().fold(f64::MIN, f64::max).min(0.0);
    outside + inside
}

/// Distance from `p` to the surface of the ball, negative inside.
fn ball_distance(center: [f64; 3], radius: f64, p: [f64; 3], dim: usize) -> f64 {
    (0..dim)
        .map(|a| (p[a] - center[a]).powi(2))
        .sum::<f64>()
        .sqrt()
        - radius
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A circle's rings are mirror images of themselves across the vertical through the
    /// centre (rings of odd counts started at angle 0 were not, and a vertical entry turned).
    #[test]
    fn circles_are_symmetric_about_their_vertical() {
        let c = [0.45, 0.355, 0.0];
        for (radius, dx) in [(0.055, 0.01), (0.055, 0.005), (0.1, 0.013)] {
            let pts = Shape::Ball { center: c, radius }.points(dx, 2, None);
            for p in &pts {
                let mirrored = [2.0 * c[0] - p[0], p[1]];
                assert!(
                    pts.iter()
                        .any(|q| (q[0] - mirrored[0]).hypot(q[1] - mirrored[1]) < 1e-12),
                    "no mirror image of {p:?} (r = {radius}, dx = {dx})"
                );
            }
        }
    }

    #[test]
    fn shell_and_filled_boxes() {
        let b = Shape::Box(Aabb {
            min: [0.0, 0.0, 0.0],
            max: [0.1, 0.06, 0.0],
        });
        assert_eq!(b.points(0.01, 2, None).len(), 60);
        // Two layers: everything but the inner 6 x 2.
        assert_eq!(b.points(0.01, 2, Some(2)).len(), 60 - 12);
        assert!((b.measure(2) - 0.006).abs() < 1e-15);
        let Shape::Box(bx) = b else { unreachable!() };
        assert!((box_distance(&bx, [0.05, 0.03, 0.0], 2) + 0.03).abs() < 1e-15);
        assert!((box_distance(&bx, [0.13, 0.1, 0.0], 2) - 0.05).abs() < 1e-15);
    }

    #[test]
    fn a_circle_of_rings_fills_its_area() {
        let c = Shape::Ball {
            center: [0.3, 0.4, 0.0],
            radius: 0.055,
        };
        let dx = 0.005;
        let pts = c.points(dx, 2, None);
        let area = pts.len() as f64 * dx * dx;
        assert!(
            (area / c.measure(2) - 1.0).abs() < 0.05,
            "{} particles",
            pts.len()
        );
        // Outer ring half a spacing inside the surface.
        let outer = pts
            .iter()
            .map(|p| ball_distance([0.3, 0.4, 0.0], 0.055, *p, 2))
            .fold(f64::MIN, f64::max);
        assert!((outer + 0.5 * dx).abs() < 1e-12);
        // Mean is the centre.
        let mean = [0, 1].map(|a| pts.iter().map(|p| p[a]).sum::<f64>() / pts.len() as f64);
        assert!((mean[0] - 0.3).abs() < 1e-3 * dx && (mean[1] - 0.4).abs() < 1e-3 * dx);
    }

    #[test]
    fn a_sphere_fills_its_volume() {
        let s = Shape::Ball {
            center: [0.0; 3],
            radius: 0.1,
        };
        let dx = 0.01;
        let n = s.points(dx, 3, None).len() as f64;
        // Centres fill the ball of radius R − dx/2 (the surface stays dx/2 beyond them).
        let inner = Shape::Ball {
            center: [0.0; 3],
            radius: 0.1 - 0.5 * dx,
        };
        assert!(
            (n * dx.powi(3) / inner.measure(3) - 1.0).abs() < 0.05,
            "{n}"
        );
        assert!(s.points(dx, 3, Some(2)).len() < n as usize);
    }

    #[test]
    fn inertia_of_a_square_and_a_disc() {
        let b = Shape::Box(Aabb {
            min: [0.0; 3],
            max: [0.2, 0.1, 0.0],
        });
        let i = b.inertia(2, 3.0);
        assert!((i[2][2] - 3.0 * (0.04 + 0.01) / 12.0).abs() < 1e-15);
        let d = Shape::Ball {
            center: [0.0; 3],
            radius: 0.5,
        };
        assert!((d.inertia(2, 2.0)[2][2] - 0.25).abs() < 1e-15);
    }
}

//! `[[inlet]]` and `[[outlet]]`: velocity inlets and outlets (docs/cases.md, "Inlets",
//! "Outlets"). An inlet's box on the fluid's lattice is its buffer; the face its `direction`
//! points at is the inlet plane. Its particles are built layer after layer from the plane
//! backwards, as many layers as the inflow takes until `stop_s` (at least the buffer's), so the
//! GPU finds a particle's layer and column from its id (shaders/open_boundaries.wgsl). An
//! outlet is a box that removes the fluid entering it.

use super::check::{aabb, number, vector, Aabb, Bound, AXES};
use super::error::{num, CaseError};
use super::locate::Ctx;
use std::path::Path;

use super::schema::{InletPressureName, InterpolationName, RawInlet, RawOutlet};
use super::time_series;
use crate::generate::lattice::{range_points, Lattice};
use crate::generate::triangle::{dot, sub};
use crate::hydrograph::{Hydrograph, Interpolation};
use crate::scenario::{FlowWindow, Inlet, InletLevel, InletPressure, Kind, Outlet, Particle};

/// An `[[inlet]]` as checked against the case, before the lattice is known.
#[derive(Clone, Debug)]
pub(super) struct InletSpec {
    pub name: String,
    pub bx: Aabb,
    /// The flow axis and its sense (±1).
    pub axis: usize,
    pub sense: f64,
    /// The inflow in time: a speed [m/s], or a discharge [m³/s; 2D m²/s] where it is given as
    /// one ([`InletSpec::is_discharge`]).
    pub inflow: Hydrograph,
    /// The field that gives it (`velocity_m_s`, `discharge_file`, …).
    pub inflow_field: &'static str,
    /// The box's section across the flow [m², 2D m], for the speed a discharge makes before
    /// the lattice is known.
    pub box_section: f64,
    pub stop_s: f64,
    /// `pressure`.
    pub pressure: InletPressureName,
    /// `level_file`'s level in time [m], joined linearly.
    pub level: Option<Hydrograph>,
}

impl InletSpec {
    /// Whether `inflow` is a discharge (`discharge_m3_s`, `discharge_file`), not a speed.
    pub fn is_discharge(&self) -> bool {
        self.inflow_field.starts_with("discharge")
    }

    /// The fastest inflow [m/s] (a discharge over the box's section), for the speed of sound.
    pub fn max_speed(&self) -> f64 {
        let speed = self.inflow.max_speed();
        if self.is_discharge() {
            speed / self.box_section
        } else {
            speed
        }
    }
}

pub(super) fn validate(
    ctx: &Ctx<'_>,
    raw: &[RawInlet],
    (dim, end_s): (usize, f64),
    case_dir: &Path,
) -> Result<Vec<InletSpec>, CaseError> {
    let mut out: Vec<InletSpec> = Vec::with_capacity(raw.len());
    for (i, r) in raw.iter().enumerate() {
        let path = format!("inlet[{i}]");
        if let Some(j) = out.iter().position(|o| o.name == r.name) {
            return Err(ctx.err(
                &format!("{path}.name"),
                Some(format!("{:?}", r.name)),
                format!("is also the name of inlet[{j}]"),
                "give every inlet its own name",
            ));
        }
        let bx = aabb(ctx, &path, &r.min_m, &r.max_m, dim, "the inlet's buffer")?;
        let d = vector(
            ctx,
            &format!("{path}.direction"),
            &r.direction,
            dim,
            "the inflow direction",
        )?;
        let nonzero: Vec<usize> = (0..dim).filter(|&a| d[a] != 0.0).collect();
        let axis = match nonzero[..] {
            [a] if d[a].abs() == 1.0 => a,
            _ => {
                let example = if dim == 2 {
                    "[1.0, 0.0]"
                } else {
                    "[1.0, 0.0, 0.0]"
                };
                return Err(ctx.err(
                    &format!("{path}.direction"),
                    Some(format!("{:?}", r.direction)),
                    "must be a unit vector along an axis (inlets are faces of boxes on the \
                     particle lattice)",
                    format!(
                        "use one of ±x, ±y{}, e.g. direction = {example}",
                        if dim == 3 { ", ±z" } else { "" }
                    ),
                ));
            }
        };
        let (inflow, inflow_field) = inflow(ctx, &path, r, case_dir)?;
        let level = level(ctx, &path, r, inflow_field, case_dir)?;
        // Particles are made for the inflow within the run only (a later stop is the end).
        let stop_s = match r.stop_s {
            None => end_s,
            Some(s) => number(
                ctx,
                &format!("{path}.stop_s"),
                s,
                Bound::Positive,
                "when the inflow stops, in seconds",
                "give a positive time, or remove it to inject until time.end_s",
            )?
            .min(end_s),
        };
        out.push(InletSpec {
            name: r.name.clone(),
            bx,
            axis,
            sense: d[axis],
            inflow,
            inflow_field,
            box_section: (0..dim)
                .filter(|&b| b != axis)
                .map(|b| bx.max[b] - bx.min[b])
                .product(),
            stop_s,
            pressure: r.pressure.unwrap_or(InletPressureName::Zero),
            level,
        });
    }
    Ok(out)
}

/// A level-driven inlet's level (`level_file`): rows `t_s, level_m`, times from 0 on, joined
/// linearly. Given with a speed only: the level sets which columns flow, so with a discharge
/// the speed would have to follow the wetted section, which this inlet does not do.
fn level(
    ctx: &Ctx<'_>,
    path: &str,
    r: &RawInlet,
    inflow_field: &str,
    case_dir: &Path,
) -> Result<Option<Hydrograph>, CaseError> {
    let Some(file) = &r.level_file else {
        return Ok(None);
    };
    let field_path = format!("{path}.level_file");
    if !inflow_field.starts_with("velocity") {
        return Err(ctx.err(
            &field_path,
            Some(format!("{file:?}")),
            format!(
                "is given with {inflow_field}: a level inlet takes the speed the water enters \
                 with, and the level sets its wetted section"
            ),
            "give the inflow as velocity_m_s or velocity_file (the discharge is then the speed \
             times the wetted section), or remove level_file",
        ));
    }
    let rows = time_series::read(ctx, &field_path, file, case_dir, &["t_s", "level_m"])?;
    if let Some(row) = rows.iter().find(|row| row.values[0] < 0.0) {
        return Err(ctx.err(
            &field_path,
            Some(format!("{file:?}")),
            format!(
                "{} line {}: t = {} s is before the run starts at 0",
                case_dir.join(file).display(),
                row.line,
                row.values[0]
            ),
            "give times from 0 s on (a run starts at t = 0)",
        ));
    }
    let t: Vec<f64> = rows.iter().map(|r| r.values[0]).collect();
    let h: Vec<f64> = rows.iter().map(|r| r.values[1]).collect();
    Ok(Some(Hydrograph::from_samples(
        &t,
        &h,
        Interpolation::Linear,
    )))
}

/// An inlet's inflow: exactly one of a constant speed or discharge and a CSV of either in
/// time; the hydrograph and the field that gave it.
fn inflow(
    ctx: &Ctx<'_>,
    path: &str,
    r: &RawInlet,
    case_dir: &Path,
) -> Result<(Hydrograph, &'static str), CaseError> {
    let given: Vec<&'static str> = [
        ("velocity_m_s", r.velocity_m_s.is_some()),
        ("discharge_m3_s", r.discharge_m3_s.is_some()),
        ("velocity_file", r.velocity_file.is_some()),
        ("discharge_file", r.discharge_file.is_some()),
    ]
    .into_iter()
    .filter_map(|(name, on)| on.then_some(name))
    .collect();
    let field = match given[..] {
        [one] => one,
        [] => {
            return Err(ctx.err(
                &format!("{path}.velocity_m_s"),
                None,
                "is missing: an inlet needs its inflow",
                "give velocity_m_s or discharge_m3_s, or a CSV of either in time as \
                 velocity_file or discharge_file",
            ))
        }
        [first, second, ..] => {
            return Err(ctx.err(
                &format!("{path}.{second}"),
                None,
                format!("is given together with {first}: an inlet has one inflow"),
                format!("keep one of {}", given.join(", ")),
            ))
        }
    };
    let interpolation = r.interpolation.map(|i| match i {
        InterpolationName::Linear => Interpolation::Linear,
        InterpolationName::Cubic => Interpolation::MonotoneCubic,
    });
    let file = r.velocity_file.as_ref().or(r.discharge_file.as_ref());
    if let (Some(_), None) = (interpolation, file) {
        return Err(ctx.err(
            &format!("{path}.interpolation"),
            None,
            "joins the samples of a velocity_file or discharge_file, and the inlet has neither",
            "remove it, or give the inflow as a CSV file",
        ));
    }
    let what = if field.starts_with("velocity") {
        "speed in m/s along direction"
    } else {
        "discharge in m³/s (2D: m²/s)"
    };
    let Some(file) = file else {
        let value = r.velocity_m_s.or(r.discharge_m3_s).unwrap_or(f64::NAN);
        let value = number(
            ctx,
            &format!("{path}.{field}"),
            value,
            Bound::Positive,
            &format!("the inflow {what}"),
            "give a positive value (fluid leaves through [[outlet]] boxes, not inlets)",
        )?;
        return Ok((Hydrograph::constant(value), field));
    };
    let column = if field == "velocity_file" {
        "u_m_s"
    } else {
        "q_m3_s"
    };
    let field_path = format!("{path}.{field}");
    let rows = time_series::read(ctx, &field_path, file, case_dir, &["t_s", column])?;
    let bad = |line: usize, problem: String, fix: &str| {
        ctx.err(
            &field_path,
            Some(format!("{file:?}")),
            format!("{} line {line}: {problem}", case_dir.join(file).display()),
            fix,
        )
    };
    for row in &rows {
        let [t, q] = row.values[..] else {
            unreachable!("two columns")
        };
        if t < 0.0 {
            return Err(bad(
                row.line,
                format!("t = {t} s is before the run starts at 0"),
                "give times from 0 s on (a run starts at t = 0)",
            ));
        }
        if q < 0.0 {
            return Err(bad(
                row.line,
                format!("{column} = {q} is negative"),
                "give an inflow of 0 or more: an inlet only brings water in (drain it through \
                 an [[outlet]])",
            ));
        }
    }
    if rows.iter().all(|r| r.values[1] == 0.0) {
        return Err(bad(
            rows[0].line,
            format!("the {what} is 0 at every time: the inlet brings no water"),
            "give the inflow's values, or remove the inlet",
        ));
    }
    let t: Vec<f64> = rows.iter().map(|r| r.values[0]).collect();
    let u: Vec<f64> = rows.iter().map(|r| r.values[1]).collect();
    let how = interpolation.unwrap_or(Interpolation::Linear);
    Ok((Hydrograph::from_samples(&t, &u, how), field))
}

/// The inlet's geometry on the lattice, checked (errors name the field to fix): the lattice
/// range of its front layer, where its plane lies, its buffer layers and all its layers.
pub(super) struct Layout {
    front_lo: [f64; 3],
    front_hi: [f64; 3],
    axis: usize,
    plane: f64,
    pub buffer_layers: usize,
    pub layers: usize,
    /// Columns (the front layer's points); counted before any is made.
    pub n_columns: f64,
    /// The inflow speed in time.
    inflow: Hydrograph,
}

impl Layout {
    /// Each column's point on the plane (for a layout within the particle budget).
    fn columns(&self, lat: &Lattice) -> Vec<[f64; 3]> {
        range_points(lat, self.front_lo, self.front_hi)
            .map(|idx| {
                let mut p = lat.pos(idx);
                p[self.axis] = self.plane;
                p
            })
            .collect()
    }
}

pub(super) fn layout(
    ctx: &Ctx<'_>,
    i: usize,
    spec: &InletSpec,
    lat: &Lattice,
    (h, gravity): (f64, [f64; 3]),
) -> Result<Layout, CaseError> {
    let path = format!("inlet[{i}]");
    let (dx, a) = (lat.dx, spec.axis);
    let Some((lo, hi)) = lat.range_in(&spec.bx) else {
        return Err(ctx.err(
            &format!("{path}.max_m"),
            None,
            format!(
                "the buffer box is too thin to hold one particle on the lattice (dx = {} m)",
                num(dx)
            ),
            "make it at least dx wide across the flow and 2h deep along it, or make \
             particles.dx_m finer",
        ));
    };
    let depth = hi[a] - lo[a] + 1.0;
    if depth * dx < 2.0 * h * (1.0 - 1e-9) {
        return Err(ctx.err(
            &format!("{path}.max_m"),
            None,
            format!(
                "the buffer holds {depth} layer(s) along {} ({} m), less than the kernel \
                 support 2h = {} m: fluid at the plane would miss neighbours",
                AXES[a],
                num(depth * dx),
                num(2.0 * h)
            ),
            format!(
                "make the box at least {} m deep along {}, or make particles.dx_m finer or \
                 particles.h_over_dx smaller, so that 2h fits within it",
                num((2.0 * h / dx).ceil() * dx),
                AXES[a]
            ),
        ));
    }
    // The layer next to the plane is the row at the box's downstream end; the plane lies half a
    // spacing beyond it.
    let front = if spec.sense > 0.0 { hi[a] } else { lo[a] };
    let mut idx = [0i64; 3];
    idx[a] = front as i64;
    let plane = lat.pos(idx)[a] + 0.5 * dx * spec.sense;
    let (mut front_lo, mut front_hi) = (lo, hi);
    front_lo[a] = front;
    front_hi[a] = front;
    let n_columns = (0..lat.dim)
        .filter(|&b| b != a)
        .map(|b| hi[b] - lo[b] + 1.0)
        .product();
    // A discharge is a speed over the section of the buffer's columns.
    let inflow = if spec.is_discharge() {
        spec.inflow
            .scaled(1.0 / (n_columns * dx.powi(lat.dim as i32 - 1)))
    } else {
        spec.inflow.clone()
    };
    // Layers crossing the plane by the stop: those with (layer + ½) dx ≤ D(stop), for the
    // column that flows longest (under a level, the lowest: it is wet whenever one above is).
    let carried = match &spec.level {
        None => inflow.distance(spec.stop_s),
        Some(level) => {
            let up = up(ctx, &path, gravity)?;
            let mut lowest = f64::INFINITY;
            for corner in 0..1usize << lat.dim {
                let idx = [0, 1, 2].map(|b| {
                    let hi_end = b < lat.dim && corner >> b & 1 == 1;
                    (if hi_end { front_hi[b] } else { front_lo[b] }) as i64
                });
                let mut p = lat.pos(idx);
                p[a] = plane;
                lowest = lowest.min(dot(up, p));
            }
            let windows = FlowWindow::of_column(0, lowest, level, &inflow);
            if windows.first().is_none_or(|w| w.start >= spec.stop_s) {
                return Err(ctx.err(
                    &format!("{path}.level_file"),
                    None,
                    format!(
                        "never rises above the inlet's lowest column, {} m high, before the \
                         inflow stops at {} s: the inlet brings no water",
                        num(lowest),
                        num(spec.stop_s)
                    ),
                    "give levels in the case's coordinates (the height against gravity), above \
                     the inlet box's bottom",
                ));
            }
            FlowWindow::travel(&windows, &inflow, spec.stop_s).distance
        }
    };
    let delivered = (carried / dx + 0.5).floor();
    let buffer_layers = depth.min(1e15) as usize;
    Ok(Layout {
        front_lo,
        front_hi,
        axis: a,
        plane,
        buffer_layers,
        layers: buffer_layers.max(delivered.min(1e15) as usize),
        n_columns,
        inflow,
    })
}

/// The unit vector against `gravity`, the direction a level's heights are measured along;
/// `None` without gravity.
fn up_of(gravity: [f64; 3]) -> Option<[f64; 3]> {
    let g = dot(gravity, gravity).sqrt();
    (g > 0.0).then(|| gravity.map(|c| -c / g))
}

/// [`up_of`], or the error a level inlet without gravity gets.
fn up(ctx: &Ctx<'_>, path: &str, gravity: [f64; 3]) -> Result<[f64; 3], CaseError> {
    up_of(gravity).ok_or_else(|| {
        ctx.err(
            &format!("{path}.level_file"),
            None,
            "needs gravity to tell which way is up, and physics.gravity_m_s2 is zero",
            "give physics.gravity_m_s2, or remove level_file",
        )
    })
}

/// The inlet's particles (buffer layers at their places, the waiting ones stacked at the
/// buffer's back, where the GPU keeps them excluded), appended to `particles`, and the
/// scenario's inlet.
/// `rho_at(depth)` is the hydrostatic start density `depth` below a free surface.
pub(super) fn build(
    spec: &InletSpec,
    layout: Layout,
    lat: &Lattice,
    gravity: [f64; 3],
    rho_at: &dyn Fn(f64) -> f64,
    particles: &mut Vec<Particle>,
) -> Inlet {
    let dx = lat.dx;
    let columns = layout.columns(lat);
    let start = particles.len();
    let mut normal = [0.0; 3];
    normal[spec.axis] = spec.sense;
    let n = columns.len() * layout.layers;
    // `layout` refused a level without gravity.
    let level = (spec.level.as_ref().zip(up_of(gravity))).map(|(level, up)| {
        let windows = (columns.iter().enumerate())
            .flat_map(|(c, &p)| FlowWindow::of_column(c, dot(up, p), level, &layout.inflow))
            .collect();
        InletLevel {
            level: level.clone(),
            up,
            windows,
        }
    });
    let inlet = Inlet {
        name: spec.name.clone(),
        normal,
        inflow: layout.inflow,
        thickness: layout.buffer_layers as f64 * dx,
        spacing: dx,
        columns,
        particles: start..start + n,
        level,
        pressure: match spec.pressure {
            InletPressureName::Zero => InletPressure::Zero,
            InletPressureName::Extrapolated => InletPressure::Extrapolated,
            // The box's corner farthest up against gravity.
            InletPressureName::Hydrostatic => InletPressure::Hydrostatic {
                surface: [0, 1, 2].map(|a| {
                    if gravity[a] < 0.0 {
                        spec.bx.max[a]
                    } else {
                        spec.bx.min[a]
                    }
                }),
            },
        },
    };
    // Below the surface at the start: the box's top, or the level.
    let depth = |x: [f64; 3]| match (inlet.pressure, up_of(gravity)) {
        (InletPressure::Hydrostatic { surface }, Some(up)) => {
            dot(up, sub(inlet.surface(surface, 0.0), x)).max(0.0)
        }
        _ => 0.0,
    };
    let speed = inlet.inflow.speed(0.0);
    for k in 0..n {
        // A dormant particle waits at the buffer's back, the place it joins from.
        let s = inlet.distance(k, 0.0).max(-inlet.thickness);
        let pos = inlet.position_at(k, s);
        particles.push(Particle {
            pos,
            vel: normal.map(|c| c * speed),
            rho: rho_at(depth(pos)),
            kind: Kind::Inlet,
        });
    }
    inlet
}

/// `[[outlet]]` tables: unique names, boxes with min < max.
pub(super) fn validate_outlets(
    ctx: &Ctx<'_>,
    raw: &[RawOutlet],
    dim: usize,
) -> Result<Vec<Outlet>, CaseError> {
    let mut out: Vec<Outlet> = Vec::with_capacity(raw.len());
    for (i, r) in raw.iter().enumerate() {
        let path = format!("outlet[{i}]");
        if let Some(j) = out.iter().position(|o| o.name == r.name) {
            return Err(ctx.err(
                &format!("{path}.name"),
                Some(format!("{:?}", r.name)),
                format!("is also the name of outlet[{j}]"),
                "give every outlet its own name",
            ));
        }
        let bx = aabb(ctx, &path, &r.min_m, &r.max_m, dim, "the outlet's box")?;
        out.push(Outlet {
            name: r.name.clone(),
            min: bx.min,
            max: bx.max,
        });
    }
    Ok(out)
}

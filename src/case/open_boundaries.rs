//! `[[inlet]]` and `[[outlet]]`: velocity inlets and outlets (docs/cases.md, "Inlets",
//! "Outlets"). An inlet's box on the fluid's lattice is its buffer; the face its `direction`
//! points at is the inlet plane. Its particles are built layer after layer from the plane
//! backwards, as many layers as the inflow takes until `stop_s` (at least the buffer's), so the
//! GPU finds a particle's layer and column from its id (shaders/open_boundaries.wgsl). An
//! outlet is a box that removes the fluid entering it.

use super::check::{aabb, number, vector, Aabb, Bound, AXES};
use super::error::{num, CaseError};
use super::locate::Ctx;
use super::schema::{InletPressureName, RawInlet, RawOutlet};
use crate::generate::lattice::{range_points, Lattice};
use crate::scenario::{Inlet, InletPressure, Kind, Outlet, Particle};

/// An `[[inlet]]` as checked against the case, before the lattice is known.
#[derive(Clone, Debug)]
pub(super) struct InletSpec {
    pub name: String,
    pub bx: Aabb,
    /// The flow axis and its sense (±1).
    pub axis: usize,
    pub sense: f64,
    pub speed: f64,
    pub stop_s: f64,
    /// `pressure`.
    pub pressure: InletPressureName,
}

pub(super) fn validate(
    ctx: &Ctx<'_>,
    raw: &[RawInlet],
    dim: usize,
    end_s: f64,
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
        let speed = number(
            ctx,
            &format!("{path}.velocity_m_s"),
            r.velocity_m_s,
            Bound::Positive,
            "the inflow speed in m/s along direction",
            "give a positive speed (fluid leaves through [[outlet]] boxes, not inlets)",
        )?;
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
            speed,
            stop_s,
            pressure: r.pressure.unwrap_or(InletPressureName::Zero),
        });
    }
    Ok(out)
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
    h: f64,
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
    // Layers crossing the plane by the stop: those with (layer + ½) dx ≤ speed × stop.
    let delivered = (spec.speed * spec.stop_s / dx + 0.5).floor();
    let buffer_layers = depth.min(1e15) as usize;
    Ok(Layout {
        front_lo,
        front_hi,
        axis: a,
        plane,
        buffer_layers,
        layers: buffer_layers.max(delivered.min(1e15) as usize),
        n_columns,
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
    let inlet = Inlet {
        name: spec.name.clone(),
        normal,
        speed: spec.speed,
        thickness: layout.buffer_layers as f64 * dx,
        spacing: dx,
        columns,
        particles: start..start + n,
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
    let g = gravity.iter().map(|c| c * c).sum::<f64>().sqrt();
    let depth = |x: [f64; 3]| match inlet.pressure {
        InletPressure::Hydrostatic { surface: s } if g > 0.0 => {
            (0..3).map(|a| gravity[a] * (x[a] - s[a])).sum::<f64>() / g
        }
        _ => 0.0,
    };
    for k in 0..n {
        let t0 = if inlet.dormant(k) {
            // At the buffer's back: the place it joins from.
            (-inlet.thickness - inlet.distance(k, 0.0)) / inlet.speed
        } else {
            0.0
        };
        let pos = inlet.position(k, t0);
        particles.push(Particle {
            pos,
            vel: normal.map(|c| c * spec.speed),
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

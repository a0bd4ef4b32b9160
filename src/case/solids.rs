//! `[[solid]]`: elastic bodies of hypoelastic solid particles (Gray, Monaghan & Swift 2001):
//! their checks and their particles (`build.rs` adds them to a case, or builds a case of solids
//! alone from them).

use crate::scenario::{distinct_materials, ElasticMaterial, Kind, Particle, SolidFormulation};

use super::check::{aabb, number, point_in, vector, Aabb, Bound};
use super::error::{num, CaseError};
use super::limits::ParticleBudget;
use super::locate::Ctx;
use super::schema::{RawSolid, SolidFormulationName, SolidVelocityName};
use crate::generate::lattice::Lattice;
use crate::layout::MAX_SOLID_MATERIALS;

/// Initial velocity of a cantilever in its first bending mode (Gray, Monaghan & Swift 2001,
/// section 6): v(x) = V f(s)/f(L) along `direction`, s = (x − root)·axis, zero for s < 0.
#[derive(Debug, Clone, Copy)]
pub(super) struct CantileverMode {
    pub root: [f64; 3],
    pub axis: [f64; 3],
    pub direction: [f64; 3],
    pub length: f64,
    pub tip_velocity: f64,
}

/// kL of the first cantilever mode.
pub const KL_FIRST: f64 = 1.875;

impl CantileverMode {
    /// f(s) = (sin kL + sinh kL)(cos ks − cosh ks) − (cos kL + cosh kL)(sin ks − sinh ks).
    fn shape(&self, s: f64) -> f64 {
        let kl = KL_FIRST;
        let k = kl / self.length;
        (kl.sin() + kl.sinh()) * ((k * s).cos() - (k * s).cosh())
            - (kl.cos() + kl.cosh()) * ((k * s).sin() - (k * s).sinh())
    }

    pub(super) fn velocity(&self, x: [f64; 3]) -> [f64; 3] {
        let s: f64 = (0..3).map(|a| (x[a] - self.root[a]) * self.axis[a]).sum();
        if s <= 0.0 {
            return [0.0; 3];
        }
        let v = self.tip_velocity * self.shape(s) / self.shape(self.length);
        self.direction.map(|d| v * d)
    }
}

#[derive(Debug, Clone)]
pub(super) struct SolidSpec {
    pub name: String,
    pub bx: Aabb,
    pub material: ElasticMaterial,
    pub clamped: Option<Aabb>,
    pub velocity: Option<CantileverMode>,
}

fn unit(
    ctx: &Ctx<'_>,
    path: &str,
    v: &[f64],
    dim: usize,
    what: &str,
) -> Result<[f64; 3], CaseError> {
    let u = vector(ctx, path, v, dim, what)?;
    let n = u.iter().map(|c| c * c).sum::<f64>().sqrt();
    if n == 0.0 {
        return Err(ctx.err(
            path,
            Some(format!("{v:?}")),
            format!("is the zero vector ({what})"),
            "give a non-zero direction",
        ));
    }
    Ok(u.map(|c| c / n))
}

pub(super) fn validate_solid(
    ctx: &Ctx<'_>,
    i: usize,
    s: &RawSolid,
    dim: usize,
) -> Result<SolidSpec, CaseError> {
    let path = format!("solid[{i}]");
    if s.name.is_empty()
        || !s
            .name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    {
        return Err(ctx.err(
            &format!("{path}.name"),
            Some(format!("{:?}", s.name)),
            "must be a non-empty name of letters, digits, _ and -",
            "e.g. name = \"plate\"",
        ));
    }
    let bx = aabb(ctx, &path, &s.min_m, &s.max_m, dim, "the solid")?;
    let material = material(ctx, &path, s)?;
    let clamped = clamped(ctx, &path, s, dim)?;
    let velocity = cantilever_mode(ctx, &path, s, dim)?;
    Ok(SolidSpec {
        name: s.name.clone(),
        bx,
        material,
        clamped,
        velocity,
    })
}

/// The material of `solid[i]` (`path`): density, Young's modulus and Poisson ratio giving a
/// sound speed the solver computes with, the formulation and its stabilisers.
fn material(ctx: &Ctx<'_>, path: &str, s: &RawSolid) -> Result<ElasticMaterial, CaseError> {
    let density = number(
        ctx,
        &format!("{path}.density_kg_m3"),
        s.density_kg_m3,
        Bound::Positive,
        "the solid's density in kg/m³",
        "e.g. density_kg_m3 = 1000.0",
    )?;
    let youngs_modulus = number(
        ctx,
        &format!("{path}.youngs_modulus_pa"),
        s.youngs_modulus_pa,
        Bound::Positive,
        "Young's modulus in Pa",
        "e.g. youngs_modulus_pa = 2.0e6",
    )?;
    let poisson_ratio = number(
        ctx,
        &format!("{path}.poisson_ratio"),
        s.poisson_ratio,
        Bound::Closed(0.0, 0.49),
        "the Poisson ratio; 0.5 (incompressible) has no finite sound speed",
        "use a value between 0 and 0.49, e.g. 0.3975",
    )?;
    // The GPU works with c_s² = K/ρ and μ in f32: a modulus or density at the ends of the f64
    // range (5e-324 Pa passes "positive") would give a zero or infinite sound speed.
    let c2 = youngs_modulus / (3.0 * (1.0 - 2.0 * poisson_ratio)) / density;
    if !(1e-12..=1e20).contains(&c2) {
        return Err(ctx.err(
            &format!("{path}.youngs_modulus_pa"),
            Some(num(youngs_modulus)),
            format!(
                "with density_kg_m3 = {} and poisson_ratio = {} gives the solid a sound speed \
                 c_s = sqrt(K/ρ) of {} m/s, outside what the solver computes with \
                 (1e-6 to 1e10 m/s)",
                num(density),
                num(poisson_ratio),
                num(c2.sqrt())
            ),
            "give a realistic Young's modulus and density, e.g. youngs_modulus_pa = 2.0e6 with \
             density_kg_m3 = 1000.0",
        ));
    }
    let formulation = formulation(ctx, path, s)?;
    let tl = formulation == SolidFormulation::TotalLagrangian;
    let alpha = number(
        ctx,
        &format!("{path}.alpha"),
        s.alpha.unwrap_or(if tl { 0.0 } else { 0.1 }),
        Bound::Closed(0.0, 2.0),
        "the Monaghan artificial viscosity between solid particles",
        "use 0.1 (the default) or up to 1",
    )?;
    let artificial_stress = number(
        ctx,
        &format!("{path}.artificial_stress"),
        s.artificial_stress.unwrap_or(if tl { 0.0 } else { 0.3 }),
        Bound::Closed(0.0, 1.0),
        "the artificial stress coefficient ε (Monaghan 2000); 0 disables it",
        "use 0.3 (Gray, Monaghan & Swift 2001), or 0",
    )?;
    Ok(ElasticMaterial {
        density,
        youngs_modulus,
        poisson_ratio,
        alpha,
        artificial_stress,
        formulation,
    })
}

/// `{path}.formulation`; a total-Lagrangian solid takes no artificial viscosity or stress.
fn formulation(ctx: &Ctx<'_>, path: &str, s: &RawSolid) -> Result<SolidFormulation, CaseError> {
    let formulation = match s.formulation {
        // Total Lagrangian by default: on the cantilever plates it keeps the Euler–Bernoulli
        // period within 2–5 % at constant amplitude, where the seed's updated-Lagrangian scheme
        // is 12–25 % off and drifts (docs/validation.md, "Oscillating plate").
        None | Some(SolidFormulationName::TotalLagrangian) => SolidFormulation::TotalLagrangian,
        Some(SolidFormulationName::UpdatedLagrangian) => SolidFormulation::UpdatedLagrangian,
    };
    if formulation == SolidFormulation::TotalLagrangian {
        // The total-Lagrangian solid is stable without either stabiliser: a nonzero value
        // given for one would be silently ignored, so it is refused (0, which is what the
        // formulation uses, is accepted, so a case of the other formulation can be switched
        // with --set).
        for (field, given) in [
            ("alpha", s.alpha),
            ("artificial_stress", s.artificial_stress),
        ] {
            if let Some(v) = given.filter(|&v| v != 0.0) {
                return Err(ctx.err(
                    &format!("{path}.{field}"),
                    Some(v.to_string()),
                    format!(
                        "is not used with formulation = \"total_lagrangian\"{} (no artificial \
                         viscosity or stress: the formulation is stable without them)",
                        if s.formulation.is_none() {
                            ", the default"
                        } else {
                            ""
                        }
                    ),
                    format!(
                        "remove {field} (or set it to 0), or use formulation = \
                         \"updated_lagrangian\""
                    ),
                ));
            }
        }
    }
    Ok(formulation)
}

/// The clamped region `{path}.clamped_min_m` to `{path}.clamped_max_m` (both or neither).
fn clamped(ctx: &Ctx<'_>, path: &str, s: &RawSolid, dim: usize) -> Result<Option<Aabb>, CaseError> {
    Ok(match (&s.clamped_min_m, &s.clamped_max_m) {
        (None, None) => None,
        (Some(lo), Some(hi)) => {
            let min = vector(
                ctx,
                &format!("{path}.clamped_min_m"),
                lo,
                dim,
                "the lower corner of the clamped region",
            )?;
            let max = vector(
                ctx,
                &format!("{path}.clamped_max_m"),
                hi,
                dim,
                "the upper corner of the clamped region",
            )?;
            if let Some(a) = (0..dim).find(|&a| max[a] <= min[a]) {
                return Err(ctx.err(
                    &format!("{path}.clamped_max_m"),
                    Some(format!("{hi:?}")),
                    format!(
                        "clamped_max_m[{a}] = {} is not above clamped_min_m[{a}] = {} (the \
                     clamped region would be empty)",
                        max[a], min[a]
                    ),
                    "make every component of clamped_max_m larger than that of clamped_min_m",
                ));
            }
            Some(Aabb { min, max })
        }
        (Some(_), None) | (None, Some(_)) => {
            let missing = if s.clamped_min_m.is_none() {
                "clamped_min_m"
            } else {
                "clamped_max_m"
            };
            return Err(ctx.err(
                &format!("{path}.{missing}"),
                None,
                "the clamped region needs both clamped_min_m and clamped_max_m",
                format!("add {missing}, or remove the other"),
            ));
        }
    })
}

/// `{path}.initial_velocity`: a cantilever's first bending mode, with every field it needs.
fn cantilever_mode(
    ctx: &Ctx<'_>,
    path: &str,
    s: &RawSolid,
    dim: usize,
) -> Result<Option<CantileverMode>, CaseError> {
    Ok(match &s.initial_velocity {
        None => None,
        Some(v) => {
            let vp = format!("{path}.initial_velocity");
            match v.kind {
                SolidVelocityName::CantileverMode => {}
            }
            let need = |f: &Option<Vec<f64>>, name: &str| -> Result<Vec<f64>, CaseError> {
                f.clone().ok_or_else(|| {
                    ctx.err(
                        &format!("{vp}.{name}"),
                        None,
                        "is required with kind = \"cantilever_mode\"",
                        format!("add {name}"),
                    )
                })
            };
            let root = vector(
                ctx,
                &format!("{vp}.root_m"),
                &need(&v.root_m, "root_m")?,
                dim,
                "the clamped end of the cantilever",
            )?;
            let axis = unit(
                ctx,
                &format!("{vp}.axis"),
                &need(&v.axis, "axis")?,
                dim,
                "the cantilever's axis, root to tip",
            )?;
            let direction = unit(
                ctx,
                &format!("{vp}.direction"),
                &need(&v.direction, "direction")?,
                dim,
                "the direction of the initial velocity",
            )?;
            let Some(length) = v.length_m else {
                return Err(ctx.err(
                    &format!("{vp}.length_m"),
                    None,
                    "is required with kind = \"cantilever_mode\"",
                    "add length_m, the free length of the cantilever",
                ));
            };
            let length = number(
                ctx,
                &format!("{vp}.length_m"),
                length,
                Bound::Positive,
                "the free length of the cantilever in metres",
                "e.g. length_m = 0.2",
            )?;
            let Some(tip) = v.tip_velocity_m_s else {
                return Err(ctx.err(
                    &format!("{vp}.tip_velocity_m_s"),
                    None,
                    "is required with kind = \"cantilever_mode\"",
                    "add tip_velocity_m_s",
                ));
            };
            if !tip.is_finite() {
                return Err(ctx.err(
                    &format!("{vp}.tip_velocity_m_s"),
                    Some(format!("{tip}")),
                    "must be a finite number (the tip velocity in m/s)",
                    "e.g. tip_velocity_m_s = 0.57",
                ));
            }
            Some(CantileverMode {
                root,
                axis,
                direction,
                length,
                tip_velocity: tip,
            })
        }
    })
}

/// How many particles at the end of `body` belong to solid `i` (they are built solid by solid).
fn body_len(body: &[u32], i: usize) -> usize {
    body.iter().rev().take_while(|&&b| b == i as u32).count()
}

/// The material of each solid, the solids' particles and the body (solid index) of each.
pub(super) type SolidParticles = (Vec<ElasticMaterial>, Vec<Particle>, Vec<u32>);

/// The particles of the solids (on one lattice from the first solid's corner), their bodies
/// (the solid's index) and the material of each solid; at most `budget` of them.
pub(super) fn solid_particles(
    ctx: &Ctx<'_>,
    solids: &[SolidSpec],
    dim: usize,
    dx: f64,
    budget: &ParticleBudget,
) -> Result<SolidParticles, CaseError> {
    let max_particles = budget.particles;
    let first = &solids[0];
    let materials = materials(ctx, solids)?;
    let lat = Lattice {
        origin: first.bx.min,
        dx,
        dim,
    };
    let mut particles = Vec::new();
    let mut body = Vec::new();
    // Counted over all solids, before any is built (the budget of the other cases).
    let mut total = 0.0;
    // The total-Lagrangian solids first: the solver indexes their particles as one run of ids.
    let mut order: Vec<usize> = (0..solids.len()).collect();
    order.sort_by_key(|&i| solids[i].material.formulation != SolidFormulation::TotalLagrangian);
    for (i, s) in order.into_iter().map(|i| (i, &solids[i])) {
        let Some((lo, hi)) = lat.range_in(&s.bx) else {
            return Err(ctx.err(
                &format!("solid[{i}].max_m"),
                None,
                format!("the solid is too thin to hold one particle at dx = {dx} m"),
                "make it at least dx thick along every axis, or decrease particles.dx_m",
            ));
        };
        if s.material.formulation == SolidFormulation::TotalLagrangian {
            tl_thickness(ctx, i, (lo, hi), dim, dx)?;
        }
        let count: f64 = (0..dim).map(|a| hi[a] - lo[a] + 1.0).product();
        total += count;
        if total > max_particles {
            return Err(ctx.err(
                "particles.dx_m",
                Some(format!("{dx}")),
                format!(
                    "with solid[{i}] the solids would have {total:.3e} particles, more than \
                     {max_particles:.3e} ({} limit)",
                    budget.why
                ),
                "increase particles.dx_m",
            ));
        }
        push_solid(ctx, (i, s), &lat, (lo, hi), &mut particles, &mut body)?;
        // A solid clamped everywhere has nothing to simulate.
        if !particles[particles.len() - body_len(&body, i)..]
            .iter()
            .any(|p| p.kind == Kind::Solid)
        {
            return Err(ctx.err(
                &format!("solid[{i}].clamped_max_m"),
                None,
                "the clamped box holds every particle of the solid: nothing is left to move",
                "clamp only a part of the solid (its root), or remove clamped_min_m/clamped_max_m",
            ));
        }
    }
    Ok((materials, particles, body))
}

/// The total-Lagrangian gradients are least-squares fits exact for quadratic fields, which need
/// three distinct particle rows along every axis: a thinner solid's fit is singular (the solver
/// would refuse it later, src/lagrangian.rs), so it is refused here, naming the solid.
fn tl_thickness(
    ctx: &Ctx<'_>,
    i: usize,
    (lo, hi): ([f64; 3], [f64; 3]),
    dim: usize,
    dx: f64,
) -> Result<(), CaseError> {
    const MIN_ROWS: f64 = 3.0;
    match (0..dim).find(|&a| hi[a] - lo[a] + 1.0 < MIN_ROWS) {
        None => Ok(()),
        Some(a) => Err(ctx.err(
            &format!("solid[{i}].max_m"),
            None,
            format!(
                "the solid is {} particle(s) thick along {} at dx = {dx} m; the \
                 total-Lagrangian formulation (the default) needs at least {MIN_ROWS}",
                hi[a] - lo[a] + 1.0,
                ["x", "y", "z"][a]
            ),
            "make the solid at least 3 dx thick, decrease particles.dx_m, or set \
             formulation = \"updated_lagrangian\"",
        )),
    }
}

/// The material of each solid; names unique, and at most [`MAX_SOLID_MATERIALS`] materials.
fn materials(ctx: &Ctx<'_>, solids: &[SolidSpec]) -> Result<Vec<ElasticMaterial>, CaseError> {
    for (i, s) in solids.iter().enumerate().skip(1) {
        if let Some(j) = solids[..i].iter().position(|o| o.name == s.name) {
            return Err(ctx.err(
                &format!("solid[{i}].name"),
                Some(format!("{:?}", s.name)),
                format!("is also the name of solid[{j}]"),
                "give every solid its own name",
            ));
        }
    }
    let materials: Vec<ElasticMaterial> = solids.iter().map(|s| s.material).collect();
    let (_, index) = distinct_materials(&materials);
    if let Some(i) = index
        .iter()
        .position(|&k| k as usize >= MAX_SOLID_MATERIALS)
    {
        return Err(ctx.err(
            &format!("solid[{i}]"),
            None,
            format!(
                "is of a {}th material: a case holds at most {MAX_SOLID_MATERIALS} different \
                 solid materials (density, Young's modulus, Poisson ratio, alpha and \
                 artificial_stress)",
                index[i] + 1
            ),
            "give solids of nearly equal materials the same values",
        ));
    }
    Ok(materials)
}

/// The particles of solid `i`, `s` (lattice indices `lo` to `hi` of `lat`), pushed onto
/// `particles` with their `body` (`i`); clamped where inside the clamped region, else moving
/// with the initial velocity, which must be finite.
fn push_solid(
    ctx: &Ctx<'_>,
    (i, s): (usize, &SolidSpec),
    lat: &Lattice,
    (lo, hi): ([f64; 3], [f64; 3]),
    particles: &mut Vec<Particle>,
    body: &mut Vec<u32>,
) -> Result<(), CaseError> {
    let dim = lat.dim;
    let n = [0, 1, 2].map(|a| {
        if a < dim {
            (hi[a] - lo[a]) as i64 + 1
        } else {
            1
        }
    });
    for k in 0..n[2] {
        for j in 0..n[1] {
            for l in 0..n[0] {
                let idx = [lo[0] as i64 + l, lo[1] as i64 + j, lo[2] as i64 + k];
                let pos = lat.pos(idx);
                let clamped = s.clamped.as_ref().is_some_and(|c| point_in(pos, c, dim));
                let vel = match (&s.velocity, clamped) {
                    (Some(m), false) => m.velocity(pos),
                    _ => [0.0; 3],
                };
                if !vel.iter().all(|v| v.is_finite()) {
                    return Err(ctx.err(
                        &format!("solid[{i}].initial_velocity"),
                        None,
                        format!("gives a non-finite velocity at {pos:?}"),
                        "give a length_m of the order of the solid's length and a finite \
                         tip_velocity_m_s",
                    ));
                }
                particles.push(Particle {
                    pos,
                    vel,
                    rho: s.material.density,
                    kind: if clamped {
                        Kind::SolidClamped
                    } else {
                        Kind::Solid
                    },
                });
                body.push(i as u32);
            }
        }
    }
    Ok(())
}

/// Refuses a free solid particle that starts closer than a particle spacing to a wall, obstacle
/// or body particle (the parts overlap): the contact law (interaction.wgsl, `solid_loads`)
/// would throw it off at the first step. `solid_of` gives each particle's `[[solid]]` index
/// (read for solid kinds). Touching parts, a spacing apart, are fine; clamped particles do not
/// move and may sit anywhere.
pub(super) fn check_clearance(
    ctx: &Ctx<'_>,
    particles: &[Particle],
    solid_of: &[u32],
    dim: usize,
    dx: f64,
) -> Result<(), CaseError> {
    use std::collections::HashMap;
    let cell = |p: &[f64; 3]| {
        [0, 1, 2].map(|a| {
            if a < dim {
                (p[a] / dx).floor() as i64
            } else {
                0
            }
        })
    };
    let boundary = |k: Kind| !matches!(k, Kind::Fluid | Kind::Solid | Kind::SolidClamped);
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (i, p) in particles.iter().enumerate() {
        if boundary(p.kind) {
            grid.entry(cell(&p.pos)).or_default().push(i);
        }
    }
    let reach = dx * (1.0 - 1e-6);
    let z = if dim == 3 { 1 } else { 0 };
    for (i, p) in particles.iter().enumerate() {
        if p.kind != Kind::Solid {
            continue;
        }
        let c = cell(&p.pos);
        for (ox, oy, oz) in
            (-1..=1).flat_map(|x| (-1..=1).flat_map(move |y| (-z..=z).map(move |w| (x, y, w))))
        {
            let Some(near) = grid.get(&[c[0] + ox, c[1] + oy, c[2] + oz]) else {
                continue;
            };
            for &j in near {
                let q = particles[j].pos;
                let d = (0..dim)
                    .map(|a| (p.pos[a] - q[a]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                if d < reach {
                    let s = solid_of[i];
                    return Err(ctx.err(
                        &format!("solid[{s}]"),
                        None,
                        format!(
                            "overlaps a wall, obstacle or body: its particle at {:?} is {} m \
                             from the boundary particle at {:?}, closer than the particle \
                             spacing dx = {} m, and the contact law would throw it off at the \
                             start",
                            &p.pos[..dim],
                            num(d),
                            &q[..dim],
                            num(dx)
                        ),
                        format!(
                            "move solid[{s}] or the wall so that they touch without \
                             overlapping, or clamp that part (clamped_min_m, clamped_max_m)"
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

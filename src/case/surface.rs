//! `[[surface]]`: walls from triangle mesh files, open or closed (docs/cases.md, "Surfaces"),
//! and the meshes of fills, read, placed and checked field by field. The geometry (the
//! readers, what lies behind or inside a surface) is `crate::generate`'s; this file names the
//! field, the file and the fix.

use std::path::Path;

use crate::generate::surface::{Edges, Placement, Surface};

use super::check::{
    number, particle_wall, read_mesh, support_layers, vector, Aabb, Bound, Treatment,
};
use super::error::{num, CaseError};
use super::limits::{self, ParticleBudget};
use super::locate::Ctx;
use super::schema::RawSurface;
use crate::generate::lattice::Lattice;

/// A surface wall, checked: the placed mesh, how its edges are shared and its treatment.
#[derive(Debug, Clone)]
pub(super) struct SurfaceWall {
    pub surface: Surface,
    /// Every edge on two triangles running along it the opposite way: then the surface
    /// encloses what lies behind it, and fluid is kept out of all of it.
    pub closed: bool,
    pub wall: Treatment,
    /// Wall-particle layers behind the surface.
    pub layers: u32,
}

/// A mesh file's fields: the file (relative to the case file) and its placement.
pub(super) struct MeshFields<'a> {
    pub file: &'a str,
    pub scale: Option<f64>,
    pub rotate_deg: Option<&'a [f64]>,
    pub translate_m: Option<&'a [f64]>,
}

/// `[[surface]]` of a 3D case, each mesh read relative to `case_dir` and placed; the
/// orientation of its triangles checked (they decide which side is the wall).
pub(super) fn validate(
    ctx: &Ctx<'_>,
    raw: &[RawSurface],
    (dim, dx, h_over_dx): (usize, f64, f64),
    case_dir: &Path,
) -> Result<Vec<SurfaceWall>, CaseError> {
    let mut out = Vec::with_capacity(raw.len());
    for (i, s) in raw.iter().enumerate() {
        let path = format!("surface[{i}]");
        if dim != 3 {
            return Err(ctx.err(
                &path,
                None,
                "a surface is a wall of a 3D case; this case is 2D",
                "set dimension = 3, or draw a 2D wall as [[obstacle]] boxes or a polygon body",
            ));
        }
        let wall = particle_wall(ctx, &path, (s.wall, s.slip), "a surface")?;
        let layers = support_layers(ctx, &path, s.layers, h_over_dx)?;
        let fields = MeshFields {
            file: &s.file,
            scale: s.scale,
            rotate_deg: s.rotate_deg.as_deref(),
            translate_m: s.translate_m.as_deref(),
        };
        let (surface, edges) =
            placed(ctx, &path, &fields, (case_dir, dx, s.flip.unwrap_or(false)))?;
        if let Some((from, to)) = edges.same_way_example {
            return Err(ctx.err(
                &format!("{path}.file"),
                Some(format!("{:?}", s.file)),
                format!(
                    "{}: its triangles are not oriented alike ({} edges run the same way in \
                     their two triangles, one from {from:?} to {to:?}): a triangle's corners run \
                     counter-clockwise seen from the fluid, so a flipped one puts the wall on \
                     the wrong side",
                    case_dir.join(s.file.as_str()).display(),
                    edges.same_way
                ),
                "re-orient the faces coherently (MeshLab: 'Re-Orient all faces coherently'), \
                 facing the water; set flip = true if they all face away from it",
            ));
        }
        out.push(SurfaceWall {
            surface,
            closed: edges.closed(),
            wall,
            layers,
        });
    }
    Ok(out)
}

/// The mesh of `fields` read, placed (and with `flip` turned over), with how its edges are
/// shared; an error naming `{path}.file` when it cannot be read, or when it is smaller than
/// two particle spacings `dx` (a drawing in another unit).
pub(super) fn placed(
    ctx: &Ctx<'_>,
    path: &str,
    fields: &MeshFields<'_>,
    (case_dir, dx, flip): (&Path, f64, bool),
) -> Result<(Surface, Edges), CaseError> {
    let placement = placement(ctx, path, fields)?;
    let file_path = format!("{path}.file");
    let mesh = read_mesh(ctx, &file_path, case_dir, fields.file)?;
    let full = case_dir.join(fields.file);
    let refuse = |problem: String, fix: &str| {
        ctx.err(
            &file_path,
            Some(format!("{:?}", fields.file)),
            format!("{}{problem}", full.display()),
            fix,
        )
    };
    let mut faces = mesh.faces;
    if flip {
        faces.iter_mut().for_each(|f| f.swap(1, 2));
    }
    let vertices: Vec<[f64; 3]> = mesh.vertices.iter().map(|&p| placement.apply(p)).collect();
    let edges = Edges::of(&vertices, &faces);
    let Some(surface) = Surface::new(&vertices, &faces) else {
        return Err(refuse(
            ": every triangle has zero area".into(),
            "export the surface's faces, in metres",
        ));
    };
    let (min, max) = surface.bounds();
    let size = (0..3).map(|a| max[a] - min[a]).fold(0.0, f64::max);
    if size < 2.0 * dx {
        return Err(refuse(
            format!(
                ": placed, it is {} m across, less than two particle spacings (particles.dx_m \
                 = {} m): too small to hold wall particles",
                num(size),
                num(dx)
            ),
            "give the mesh's scale to metres (scale = 1000 for a drawing in kilometres, 1 for \
             metres), or decrease particles.dx_m",
        ));
    }
    Ok((surface, edges))
}

/// `scale`, `rotate_deg` and `translate_m` of a mesh.
fn placement(ctx: &Ctx<'_>, path: &str, f: &MeshFields<'_>) -> Result<Placement, CaseError> {
    let scale = match f.scale {
        None => 1.0,
        Some(s) => number(
            ctx,
            &format!("{path}.scale"),
            s,
            Bound::Positive,
            "the factor from the file's units to metres",
            "give a positive factor: 0.001 for a drawing in millimetres, 1 for metres",
        )?,
    };
    let three = |name: &str, v: Option<&[f64]>, what: &str| match v {
        None => Ok([0.0; 3]),
        Some(v) => vector(ctx, &format!("{path}.{name}"), v, 3, what),
    };
    Ok(Placement {
        scale,
        rotate_deg: three(
            "rotate_deg",
            f.rotate_deg,
            "the turns about the x, y and z axes in degrees",
        )?,
        translate: three(
            "translate_m",
            f.translate_m,
            "the move after the turns, in m",
        )?,
    })
}

/// The positions of a surface's wall particles.
pub(super) type WallPoints = Vec<[f64; 3]>;

/// Each surface's wall particles on the lattice, inside `clip` (the tank's inner box and the
/// domain): their positions, and what was noticed on the way. An error when a surface lies
/// outside, leaves no particle, or would hold more than `budget` (checked while they are
/// found).
pub(super) fn walls(
    ctx: &Ctx<'_>,
    (surfaces, h): (&[SurfaceWall], f64),
    lat: &Lattice,
    clip: Option<&Aabb>,
    budget: &ParticleBudget,
) -> Result<(Vec<WallPoints>, Vec<String>), CaseError> {
    let dx = lat.dx;
    let mut out = Vec::with_capacity(surfaces.len());
    let mut notes = Vec::new();
    for (i, s) in surfaces.iter().enumerate() {
        let path = format!("surface[{i}]");
        let (min, max) = s.surface.bounds();
        if let Some(c) = clip {
            if (0..3).any(|a| max[a] < c.min[a] || min[a] > c.max[a]) {
                return Err(ctx.err(
                    &format!("{path}.file"),
                    None,
                    format!(
                        "placed, the mesh ({min:?} to {max:?}) lies outside the tank's inner \
                         box and the domain ({:?} to {:?})",
                        c.min, c.max
                    ),
                    "move it with translate_m, or check scale (0.001 for a drawing in \
                     millimetres) and rotate_deg",
                ));
            }
        }
        let depth = s.layers as f64 * dx;
        // Refused before any point is visited: the wall's volume, area × depth, in cells.
        let estimate = s.surface.area() * depth / dx.powi(3);
        limits::part_fits(ctx, (dx, 3), (path.as_str(), estimate), budget)?;
        let limit = budget.particles.min(1e15) as usize;
        let Some(indices) = s.surface.wall(lat.origin, dx, depth, limit) else {
            let count = (path.as_str(), budget.particles + 1.0);
            return Err(limits::too_many(ctx, (dx, 3), count, budget));
        };
        let points: Vec<[f64; 3]> = (indices.into_iter())
            .map(|i| lat.pos(i))
            .filter(|p| clip.is_none_or(|c| (0..3).all(|a| (c.min[a]..=c.max[a]).contains(&p[a]))))
            .collect();
        if points.is_empty() {
            return Err(ctx.err(
                &format!("{path}.file"),
                None,
                format!(
                    "leaves no wall particle of spacing particles.dx_m = {} m inside the tank \
                     and the domain",
                    num(dx)
                ),
                "move the surface into the domain, or decrease particles.dx_m",
            ));
        }
        if s.closed && s.surface.signed_volume() < 0.0 {
            notes.push(format!(
                "{path} is closed and its faces look in: its wall surrounds it and water may \
                 stand inside (set flip = true for a solid)"
            ));
        }
        if let Some((t, at)) = s.surface.thinnest(2.0 * h) {
            notes.push(format!(
                "{path} is {} m thick at {at:?}, thinner than the kernel support 2h = {} m: \
                 water on one side feels the water on the other through it{}",
                num(t),
                num(2.0 * h),
                if t < dx {
                    "; thinner than a spacing, it may hold no particle across and leak"
                } else {
                    ""
                }
            ));
        }
        out.push(points);
    }
    Ok((out, notes))
}

impl SurfaceWall {
    /// Whether fluid at `p` would stand in the wall (on the lattice of spacing `dx`): within
    /// `clearance` of the surface, in the wall behind it, or deeper inside it when it is
    /// closed.
    pub(super) fn blocks(&self, p: [f64; 3], dx: f64, clearance: f64) -> bool {
        let depth = self.layers as f64 * dx;
        match self.surface.side(p, depth) {
            Some((d, s)) => d < clearance || s < 0.0,
            None => self.closed && self.encloses(p),
        }
    }

    /// Whether a closed surface's inside holds `p` (its faces looking out).
    fn encloses(&self, p: [f64; 3]) -> bool {
        let (min, max) = self.surface.bounds();
        (0..3).all(|a| (min[a]..=max[a]).contains(&p[a])) && self.surface.winding_number(p) >= 0.5
    }
}

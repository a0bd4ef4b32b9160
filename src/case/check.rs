//! The checking primitives the rest of the case loader is built on: boxes ([`Aabb`]), the
//! checks of a single number, vector or box against its field ([`number`], [`vector`],
//! [`aabb`]), wall treatments ([`Treatment`], [`treatment`]), inside tests and how a box is
//! written in a message ([`fmt_box`], [`AXES`]), and bounded reads of the files a case names.
//!
//! The bottom layer of `src/case/` (see `mod.rs`): it imports only the foundation (`error.rs`,
//! `locate.rs`, `schema.rs`, which import nothing else from the case module), and every other
//! case file may import it.

use std::path::Path;

use crate::generate::mesh_file::{parse, IndexedTriangles, MeshFormat};

use super::error::{num, CaseError};
use super::locate::Ctx;
use super::schema::{SlipName, WallName};

/// The longest name (in bytes) of a case, probe or body: names become file and folder names
/// (`out/<case>`, `probes/body_<name>.csv`), which file systems cap at 255 bytes; a longer one
/// failed only after the run had made its folders (issue 64).
pub(super) const MAX_NAME_BYTES: usize = 100;

/// Whether `name` can be a probe's or body's file name: 1 to [`MAX_NAME_BYTES`] letters,
/// digits, `_` and `-`.
pub(super) fn file_safe(name: &str) -> bool {
    (1..=MAX_NAME_BYTES).contains(&name.len())
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

/// The wall treatment of the particle wall at `path` (`what` it is, for the message): any but
/// mirror ghosts, which are the tank's straight faces.
pub(super) fn particle_wall(
    ctx: &Ctx<'_>,
    path: &str,
    (wall, slip): (Option<WallName>, Option<SlipName>),
    what: &str,
) -> Result<Treatment, CaseError> {
    if wall == Some(WallName::Mirror) {
        return Err(ctx.err(
            &format!("{path}.wall"),
            Some("\"mirror\"".into()),
            format!("mirror ghosts are for the tank's straight faces, not {what}"),
            "use wall = \"dynamic\" (or \"fixed_ghost\" or \"repulsive\")",
        ));
    }
    treatment(ctx, path, wall, slip)
}

/// `path.layers` of a particle wall, 1 to 8: by default enough to cover the kernel support 2h
/// (⌈2 h/dx⌉).
pub(super) fn support_layers(
    ctx: &Ctx<'_>,
    path: &str,
    given: Option<i64>,
    h_over_dx: f64,
) -> Result<u32, CaseError> {
    let support = (2.0 * h_over_dx).ceil().clamp(1.0, 8.0) as i64;
    let layers = given.unwrap_or(support);
    if !(1..=8).contains(&layers) {
        return Err(ctx.err(
            &format!("{path}.layers"),
            Some(layers.to_string()),
            "must be between 1 and 8 (wall-particle layers)",
            format!("leave it out: the default, {support}, covers the kernel support 2h"),
        ));
    }
    Ok(layers as u32)
}

pub(super) use crate::generate::aabb::Aabb;

/// Allowed range of a number.
#[derive(Clone, Copy)]
pub(super) enum Bound {
    /// > 0
    Positive,
    /// [lo, hi]
    Closed(f64, f64),
    /// (lo, hi]
    OpenClosed(f64, f64),
}

/// `v` when it is finite and within `bound`, else an error at `path` saying `what` it is and
/// how to `fix` it.
pub(super) fn number(
    ctx: &Ctx<'_>,
    path: &str,
    v: f64,
    bound: Bound,
    what: &str,
    fix: &str,
) -> Result<f64, CaseError> {
    if !v.is_finite() {
        return Err(ctx.err(
            path,
            Some(num(v)),
            format!("must be a finite number ({what})"),
            fix,
        ));
    }
    let (ok, rule) = match bound {
        Bound::Positive => (v > 0.0, "must be > 0".to_string()),
        Bound::Closed(lo, hi) => (
            lo <= v && v <= hi,
            format!("must be in [{}, {}]", num(lo), num(hi)),
        ),
        Bound::OpenClosed(lo, hi) => (
            lo < v && v <= hi,
            format!("must be in ({}, {}]", num(lo), num(hi)),
        ),
    };
    if ok {
        Ok(v)
    } else {
        Err(ctx.err(path, Some(num(v)), format!("{rule} ({what})"), fix))
    }
}

/// `path.velocity_m_s`, an optional initial velocity (zero when absent).
pub(super) fn initial_velocity(
    ctx: &Ctx<'_>,
    path: &str,
    v: &Option<Vec<f64>>,
    dim: usize,
) -> Result<[f64; 3], CaseError> {
    match v {
        Some(v) => vector(
            ctx,
            &format!("{path}.velocity_m_s"),
            v,
            dim,
            "the initial velocity in m/s",
        ),
        None => Ok([0.0; 3]),
    }
}

/// A `dim`-component vector of finite numbers, padded to 3 components.
pub(super) fn vector(
    ctx: &Ctx<'_>,
    path: &str,
    v: &[f64],
    dim: usize,
    what: &str,
) -> Result<[f64; 3], CaseError> {
    let axes = if dim == 2 {
        "[x, y] with y up"
    } else {
        "[x, y, z] with z up"
    };
    if v.len() != dim {
        return Err(ctx.err(
            path,
            Some(format!("{v:?}")),
            format!(
                "has {} components but this {dim}D case (dimension = {dim}) needs {dim}: {axes} \
                 ({what})",
                v.len()
            ),
            format!("give {dim} numbers, {axes}"),
        ));
    }
    let mut out = [0.0; 3];
    for (i, &c) in v.iter().enumerate() {
        if !c.is_finite() {
            return Err(ctx.err(
                &format!("{path}[{i}]"),
                Some(num(c)),
                format!("must be a finite number ({what})"),
                "give a finite number",
            ));
        }
        out[i] = c;
    }
    Ok(out)
}

/// A box from `{path}.min_m` / `{path}.max_m` with min < max on every axis.
pub(super) fn aabb(
    ctx: &Ctx<'_>,
    path: &str,
    min: &[f64],
    max: &[f64],
    dim: usize,
    what: &str,
) -> Result<Aabb, CaseError> {
    let lo = vector(
        ctx,
        &format!("{path}.min_m"),
        min,
        dim,
        &format!("the lower corner of {what}"),
    )?;
    let hi = vector(
        ctx,
        &format!("{path}.max_m"),
        max,
        dim,
        &format!("the upper corner of {what}"),
    )?;
    for a in 0..dim {
        if hi[a] <= lo[a] {
            return Err(ctx.err(
                &format!("{path}.max_m"),
                Some(format!("{max:?}")),
                format!(
                    "max_m[{a}] = {} is not above min_m[{a}] = {} ({what} would be empty)",
                    num(hi[a]),
                    num(lo[a])
                ),
                "make every component of max_m larger than that of min_m",
            ));
        }
    }
    Ok(Aabb { min: lo, max: hi })
}

/// The wall treatment of the tank or of an obstacle (`docs/cases.md`, "Wall treatments").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Treatment {
    /// Dynamic boundary particles (Crespo et al. 2007), `Kind::Wall`.
    Dynamic,
    /// One layer of Lennard-Jones boundary particles (Monaghan 1994), `Kind::Repulsive`.
    Repulsive,
    /// Mirror planes on the tank's faces, no particles (tank only).
    Mirror { no_slip: bool },
    /// Fixed ghost particles, `Kind::GhostNoSlip` / `Kind::GhostFreeSlip`.
    FixedGhost { no_slip: bool },
}

/// The treatment of `{path}.wall` with `{path}.slip` (only for mirror and fixed_ghost walls).
pub(super) fn treatment(
    ctx: &Ctx<'_>,
    path: &str,
    wall: Option<WallName>,
    slip: Option<SlipName>,
) -> Result<Treatment, CaseError> {
    let wall = wall.unwrap_or(WallName::Dynamic);
    let no_slip = slip.unwrap_or(SlipName::NoSlip) == SlipName::NoSlip;
    Ok(match wall {
        WallName::Dynamic | WallName::Repulsive => {
            if let Some(s) = slip {
                let written = if s == SlipName::NoSlip {
                    "\"no_slip\""
                } else {
                    "\"free_slip\""
                };
                return Err(ctx.err(
                    &format!("{path}.slip"),
                    Some(written.into()),
                    format!(
                        "is only used with wall = \"mirror\" or \"fixed_ghost\", but the wall is \
                         \"{}\"",
                        wall.as_str()
                    ),
                    "remove slip, or set wall = \"fixed_ghost\"",
                ));
            }
            if wall == WallName::Dynamic {
                Treatment::Dynamic
            } else {
                Treatment::Repulsive
            }
        }
        WallName::Mirror => Treatment::Mirror { no_slip },
        WallName::FixedGhost => Treatment::FixedGhost { no_slip },
    })
}

/// Tolerance for "inside" tests of user boxes [m].
pub(super) const TOL: f64 = 1e-9;
/// The axes' names, as messages write them.
pub(super) const AXES: [&str; 3] = ["x", "y", "z"];

/// The first axis along which `b` leaves `outer` (by more than [`TOL`]), if any.
pub(super) fn inside(b: &Aabb, outer: &Aabb, dim: usize) -> Option<usize> {
    (0..dim).find(|&a| b.min[a] < outer.min[a] - TOL || b.max[a] > outer.max[a] + TOL)
}

/// Whether `p` lies in `b` (within [`TOL`]).
pub(super) fn point_inside(p: [f64; 3], b: &Aabb, dim: usize) -> bool {
    (0..dim).all(|a| b.min[a] - TOL <= p[a] && p[a] <= b.max[a] + TOL)
}

/// Whether `p` lies in `b`, bounds included (no tolerance).
pub(super) fn point_in(p: [f64; 3], b: &Aabb, dim: usize) -> bool {
    (0..dim).all(|a| p[a] >= b.min[a] && p[a] <= b.max[a])
}

/// `b` as messages write it: `[x0, y0] to [x1, y1]`.
pub(super) fn fmt_box(b: &Aabb, dim: usize) -> String {
    format!("{:?} to {:?}", &b.min[..dim], &b.max[..dim])
}

/// The text of the file at `path`, or an error if it is longer than `limit` bytes.
pub(crate) fn read_bounded(path: &Path, limit: u64) -> std::io::Result<String> {
    String::from_utf8(read_bytes_bounded(path, limit)?)
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))
}

/// The largest mesh file (about five million triangles in binary STL).
const MAX_MESH_BYTES: u64 = 256 << 20;

/// The triangles of the mesh file `file` (relative to `case_dir`) that the field `field`
/// names: STL or Wavefront OBJ by its extension. An error names the field, the file's path, the
/// line (OBJ) and a fix.
pub(super) fn read_mesh(
    ctx: &Ctx<'_>,
    field: &str,
    case_dir: &Path,
    file: &str,
) -> Result<IndexedTriangles, CaseError> {
    let full = case_dir.join(file);
    let refuse = |problem: String, fix: &str| {
        ctx.err(
            field,
            Some(format!("{file:?}")),
            format!("{}{problem}", full.display()),
            fix,
        )
    };
    let extension = full.extension().map(|e| e.to_string_lossy().to_string());
    let Some(format) = extension.as_deref().and_then(MeshFormat::of_extension) else {
        return Err(refuse(
            ": is not an STL (.stl) or Wavefront OBJ (.obj) file, the formats a mesh is read \
             from"
                .into(),
            "export the surface as STL or OBJ",
        ));
    };
    let bytes = read_bytes_bounded(&full, MAX_MESH_BYTES).map_err(|e| {
        refuse(
            format!(": cannot read it: {e}"),
            "give the path of the mesh relative to the case file",
        )
    })?;
    parse(&bytes, format).map_err(|e| {
        let line = e.line.map_or(String::new(), |l| format!(", line {l}"));
        refuse(format!("{line}: {}", e.problem), &e.fix)
    })
}

/// The bytes of the file at `path`, or an error if it has more than `limit`.
pub(crate) fn read_bytes_bounded(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let mut bytes = Vec::new();
    std::fs::File::open(path)?
        .take(limit + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(limit));
    }
    Ok(bytes)
}

fn too_large(limit: u64) -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::FileTooLarge,
        format!("longer than {} MiB; is it the right file?", limit >> 20),
    )
}

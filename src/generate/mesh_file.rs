//! Triangle surfaces from the files CAD and GIS programs write: STL (ASCII or binary, read by
//! the `stl_io` crate) and Wavefront OBJ (read here: `v` vertices and `f` faces, whose polygons
//! are split into fans of triangles; texture, normal, group and material lines are passed
//! over). Vertices shared by faces are shared in the result, so edges can be matched.

use std::io::Cursor;

/// Indexed triangles as a file gives them: vertex positions and, for each face, three indices.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct IndexedTriangles {
    pub vertices: Vec<[f64; 3]>,
    pub faces: Vec<[usize; 3]>,
}

/// What is wrong with a mesh file: where (the line, for OBJ), what, and how to fix it. The
/// case's reader adds the file and the field.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshFileError {
    pub line: Option<usize>,
    pub problem: String,
    pub fix: String,
}

fn error(line: Option<usize>, problem: impl Into<String>, fix: &str) -> MeshFileError {
    MeshFileError {
        line,
        problem: problem.into(),
        fix: fix.into(),
    }
}

/// The formats read, by the file name's extension.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MeshFormat {
    Stl,
    Obj,
}

impl MeshFormat {
    /// The format of a file ending in `extension` (any case), if it is one read here.
    pub fn of_extension(extension: &str) -> Option<MeshFormat> {
        match extension.to_ascii_lowercase().as_str() {
            "stl" => Some(MeshFormat::Stl),
            "obj" => Some(MeshFormat::Obj),
            _ => None,
        }
    }
}

/// The triangles of a file's `bytes` in `format`; every coordinate finite, every index in
/// range, at least one face.
pub fn parse(bytes: &[u8], format: MeshFormat) -> Result<IndexedTriangles, MeshFileError> {
    let mesh = match format {
        MeshFormat::Stl => parse_stl(bytes)?,
        MeshFormat::Obj => {
            let text = std::str::from_utf8(bytes).map_err(|e| {
                error(
                    None,
                    format!("is not text ({e}), as an OBJ file is"),
                    "export the surface as a Wavefront OBJ (text) or an STL file",
                )
            })?;
            parse_obj(text)?
        }
    };
    if mesh.faces.is_empty() {
        return Err(error(
            None,
            "has no triangles",
            "export the surface's faces (not only its points or lines)",
        ));
    }
    if mesh.vertices.iter().flatten().any(|c| !c.is_finite()) {
        return Err(error(
            None,
            "has a vertex with a coordinate that is not a finite number",
            "repair or re-export the mesh",
        ));
    }
    Ok(mesh)
}

fn parse_stl(bytes: &[u8]) -> Result<IndexedTriangles, MeshFileError> {
    let stl = stl_io::read_stl(&mut Cursor::new(bytes)).map_err(|e| {
        error(
            None,
            format!("is not an STL file stl_io can read: {e}"),
            "export the surface as an ASCII or binary STL",
        )
    })?;
    Ok(IndexedTriangles {
        vertices: stl.vertices.iter().map(|v| v.0.map(f64::from)).collect(),
        faces: stl.faces.iter().map(|f| f.vertices).collect(),
    })
}

/// An OBJ file's vertices and faces; a face of n > 3 corners becomes the n − 2 triangles of
/// the fan from its first corner (exact for the convex polygons exporters write).
pub fn parse_obj(text: &str) -> Result<IndexedTriangles, MeshFileError> {
    let mut mesh = IndexedTriangles::default();
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        let mut tokens = line.split_whitespace();
        match tokens.next() {
            Some("v") => mesh.vertices.push(vertex(line_no, tokens)?),
            Some("f") => {
                let corners = tokens
                    .map(|t| corner(line_no, t, mesh.vertices.len()))
                    .collect::<Result<Vec<_>, _>>()?;
                if corners.len() < 3 {
                    return Err(error(
                        Some(line_no),
                        format!("a face has {} corners, fewer than three", corners.len()),
                        "give each face (f) three or more vertex indices",
                    ));
                }
                for k in 1..corners.len() - 1 {
                    mesh.faces.push([corners[0], corners[k], corners[k + 1]]);
                }
            }
            _ => {}
        }
    }
    Ok(mesh)
}

/// `v x y z [w]`: the position (a weight w is a rational curve's, not used here).
fn vertex<'a>(
    line: usize,
    mut tokens: impl Iterator<Item = &'a str>,
) -> Result<[f64; 3], MeshFileError> {
    let mut p = [0.0; 3];
    for (a, x) in p.iter_mut().enumerate() {
        let token = tokens.next().ok_or_else(|| {
            error(
                Some(line),
                format!("a vertex (v) has {a} coordinates, not three"),
                "give each vertex x, y and z",
            )
        })?;
        *x = token.parse().map_err(|_| {
            error(
                Some(line),
                format!("a vertex's coordinate {token:?} is not a number"),
                "write coordinates as numbers (a decimal point, not a comma)",
            )
        })?;
    }
    Ok(p)
}

/// One corner of a face, `v`, `v/vt`, `v//vn` or `v/vt/vn`: its vertex, counted from 1, or
/// back from the last vertex read when negative.
fn corner(line: usize, token: &str, read: usize) -> Result<usize, MeshFileError> {
    let index = token.split('/').next().unwrap_or("");
    let n: i64 = index.parse().map_err(|_| {
        error(
            Some(line),
            format!("a face's corner {token:?} does not start with a vertex index"),
            "write face corners as vertex indices (f 1 2 3, or f 1/1/1 2/2/2 3/3/3)",
        )
    })?;
    let resolved = match n {
        1.. => n - 1,
        ..=-1 => read as i64 + n,
        0 => -1,
    };
    if resolved < 0 || resolved >= read as i64 {
        return Err(error(
            Some(line),
            format!(
                "a face's corner {token:?} names vertex {n}, but {read} vertices come before it"
            ),
            "give faces after their vertices, indices from 1 (or negative, back from the last)",
        ));
    }
    Ok(resolved as usize)
}

#[cfg(test)]
mod tests;

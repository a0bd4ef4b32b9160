//! ParaView `.vtu` (VTK XML UnstructuredGrid) writer with raw appended binary data.
//!
//! Layout: the XML header declares every array with `format="appended"` and its byte `offset`
//! into the appended section; `<AppendedData encoding="raw">_` is followed by one block per array,
//! each a little-endian UInt64 byte count then the raw little-endian values
//! (`header_type="UInt64"`, `byte_order="LittleEndian"`). Each particle is one VTK_VERTEX cell.

use std::io::{self, Write};

use super::Snapshot;

/// VTK cell type of a single point.
const VTK_VERTEX: u8 = 1;

/// Scalar types that can be stored in the appended section.
trait LeBytes: Copy {
    const SIZE: usize;
    const VTK_NAME: &'static str;
    fn put(self, out: &mut Vec<u8>);
}

macro_rules! le_bytes {
    ($t:ty, $name:literal) => {
        impl LeBytes for $t {
            const SIZE: usize = std::mem::size_of::<$t>();
            const VTK_NAME: &'static str = $name;
            #[inline(always)]
            fn put(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
        }
    };
}
le_bytes!(f64, "Float64");
le_bytes!(f32, "Float32");
le_bytes!(u32, "UInt32");
le_bytes!(i32, "Int32");
le_bytes!(i64, "Int64");
le_bytes!(u8, "UInt8");

/// Description of one appended array: XML element and byte offset of its block.
struct ArrayDecl<'a> {
    name: &'a str,
    vtk_type: &'static str,
    components: usize,
    tuples: usize,
    elem_size: usize,
}

impl<'a> ArrayDecl<'a> {
    fn new<T: LeBytes>(name: &'a str, components: usize, tuples: usize) -> Self {
        ArrayDecl {
            name,
            vtk_type: T::VTK_NAME,
            components,
            tuples,
            elem_size: T::SIZE,
        }
    }

    /// The declaration in a `.pvtu` (`PDataArray`: the type and components, no data).
    fn pxml(&self, indent: &str) -> String {
        format!(
            "{indent}<PDataArray type=\"{}\" Name=\"{}\"{}/>\n",
            self.vtk_type,
            self.name,
            self.components_attr()
        )
    }

    /// ` NumberOfComponents="k"` for k > 1 (VTK's default is 1).
    fn components_attr(&self) -> String {
        match self.components {
            1 => String::new(),
            k => format!(" NumberOfComponents=\"{k}\""),
        }
    }

    fn data_bytes(&self) -> u64 {
        (self.tuples * self.components * self.elem_size) as u64
    }

    /// Block size in the appended section: UInt64 header + data.
    fn block_bytes(&self) -> u64 {
        8 + self.data_bytes()
    }

    fn xml(&self, indent: &str, offset: u64, extra: &str) -> String {
        let comps = self.components_attr();
        format!(
            "{indent}<DataArray type=\"{}\" Name=\"{}\"{comps}{extra} format=\"appended\" offset=\"{offset}\"/>\n",
            self.vtk_type, self.name
        )
    }
}

/// Writes one appended block: byte count as UInt64, then the values, encoded in chunks.
fn write_block<T: LeBytes>(
    w: &mut dyn Write,
    decl: &ArrayDecl,
    values: impl Iterator<Item = T>,
    chunk: &mut Vec<u8>,
) -> io::Result<()> {
    const CHUNK_BYTES: usize = 1 << 16;
    w.write_all(&decl.data_bytes().to_le_bytes())?;
    let mut written = 0u64;
    chunk.clear();
    for v in values {
        v.put(chunk);
        if chunk.len() >= CHUNK_BYTES {
            w.write_all(chunk)?;
            written += chunk.len() as u64;
            chunk.clear();
        }
    }
    w.write_all(chunk)?;
    written += chunk.len() as u64;
    chunk.clear();
    if written != decl.data_bytes() {
        // Cannot happen for a validated snapshot; refuse to produce an inconsistent file.
        return Err(io::Error::other(format!(
            "array {} has {written} bytes, declared {}",
            decl.name,
            decl.data_bytes()
        )));
    }
    Ok(())
}

/// The per-particle arrays of a particle file (after its points), for `n` particles.
fn particle_arrays(n: usize) -> [ArrayDecl<'static>; 5] {
    [
        ArrayDecl::new::<f32>("velocity", 3, n),
        ArrayDecl::new::<f32>("density", 1, n),
        ArrayDecl::new::<f32>("pressure", 1, n),
        ArrayDecl::new::<u32>("kind", 1, n),
        ArrayDecl::new::<u32>("id", 1, n),
    ]
}

/// Writes the `.pvtu` of one output of a run over several ranks: the arrays every piece holds
/// (as [`write_vtu`] writes them, with the further scalars `extra`) and the pieces' files
/// (relative to the `.pvtu`), so that ParaView opens the pieces as one data set.
pub(crate) fn write_pvtu(w: &mut dyn Write, extra: &[&str], pieces: &[String]) -> io::Result<()> {
    let mut xml = String::with_capacity(1024);
    xml.push_str("<?xml version=\"1.0\"?>\n");
    xml.push_str(
        "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
    );
    xml.push_str("  <PUnstructuredGrid GhostLevel=\"0\">\n");
    xml.push_str("    <PPointData Scalars=\"density\" Vectors=\"velocity\">\n");
    let mut decls: Vec<ArrayDecl> = particle_arrays(0).into();
    decls.extend(extra.iter().map(|name| ArrayDecl::new::<f32>(name, 1, 0)));
    for d in decls {
        xml.push_str(&d.pxml("      "));
    }
    xml.push_str("    </PPointData>\n    <PPoints>\n");
    xml.push_str(&ArrayDecl::new::<f64>("Points", 3, 0).pxml("      "));
    xml.push_str("    </PPoints>\n");
    for piece in pieces {
        xml.push_str(&format!(
            "    <Piece Source=\"{}\"/>\n",
            super::pvd::xml_escape(piece)
        ));
    }
    xml.push_str("  </PUnstructuredGrid>\n</VTKFile>\n");
    w.write_all(xml.as_bytes())
}

/// The `Source` of every piece a `.pvtu` written by [`write_pvtu`] names, in order.
pub(crate) fn pvtu_pieces(text: &str) -> Result<Vec<String>, String> {
    if !text.contains("type=\"PUnstructuredGrid\"") {
        return Err("not a PUnstructuredGrid file".into());
    }
    let pieces: Vec<String> = text
        .lines()
        .filter_map(|l| {
            let rest = l.trim_start().strip_prefix("<Piece Source=\"")?;
            Some(rest[..rest.find('"')?].to_string())
        })
        .collect();
    if pieces.is_empty() {
        return Err("it names no pieces".into());
    }
    // `write_pvtu` names `.vtu` files beside the `.pvtu`: anything else (another `.pvtu`, which
    // could name this one, or a path elsewhere) is not a file wgsph wrote.
    if let Some(odd) = pieces
        .iter()
        .find(|p| !p.ends_with(".vtu") || p.contains(['/', '\\']) || p.starts_with('.'))
    {
        return Err(format!(
            "it names the piece \"{odd}\", not a .vtu file beside it"
        ));
    }
    Ok(pieces)
}

/// Writes a complete `.vtu` for `snap` (arrays must all have `snap.len()` entries).
pub(crate) fn write_vtu(w: &mut dyn Write, snap: &Snapshot) -> io::Result<()> {
    let n = snap.len();
    // Int32 cell indices while they fit (half the size), Int64 beyond.
    let wide = n > i32::MAX as usize;
    let index_decl = |name| {
        if wide {
            ArrayDecl::new::<i64>(name, 1, n)
        } else {
            ArrayDecl::new::<i32>(name, 1, n)
        }
    };

    let time = ArrayDecl::new::<f64>("TimeValue", 1, 1);
    let [velocity, density, pressure, kind, id] = particle_arrays(n);
    let points = ArrayDecl::new::<f64>("Points", 3, n);
    let connectivity = index_decl("connectivity");
    let offsets = index_decl("offsets");
    let types = ArrayDecl::new::<u8>("types", 1, n);

    // Byte offsets of the blocks, in the order they are appended.
    let order = [
        &time,
        &velocity,
        &density,
        &pressure,
        &kind,
        &id,
        &points,
        &connectivity,
        &offsets,
        &types,
    ];
    let mut off = [0u64; 10];
    let mut acc = 0u64;
    for (o, d) in off.iter_mut().zip(order) {
        *o = acc;
        acc += d.block_bytes();
    }
    // Extra scalars are appended after the fixed blocks.
    let extra: Vec<(ArrayDecl, u64)> = snap
        .extra
        .iter()
        .map(|(name, _)| {
            let d = ArrayDecl::new::<f32>(name, 1, n);
            let o = acc;
            acc += d.block_bytes();
            (d, o)
        })
        .collect();

    let mut xml = String::with_capacity(2048);
    xml.push_str("<?xml version=\"1.0\"?>\n");
    xml.push_str(
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
    );
    xml.push_str("  <UnstructuredGrid>\n");
    xml.push_str("    <FieldData>\n");
    xml.push_str(&time.xml("      ", off[0], " NumberOfTuples=\"1\""));
    xml.push_str("    </FieldData>\n");
    xml.push_str(&format!(
        "    <Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{n}\">\n"
    ));
    xml.push_str("      <PointData Scalars=\"density\" Vectors=\"velocity\">\n");
    for (d, o) in order[1..6].iter().zip(&off[1..6]) {
        xml.push_str(&d.xml("        ", *o, ""));
    }
    for (d, o) in &extra {
        xml.push_str(&d.xml("        ", *o, ""));
    }
    xml.push_str("      </PointData>\n");
    xml.push_str("      <Points>\n");
    xml.push_str(&points.xml("        ", off[6], ""));
    xml.push_str("      </Points>\n");
    xml.push_str("      <Cells>\n");
    for (d, o) in order[7..].iter().zip(&off[7..]) {
        xml.push_str(&d.xml("        ", *o, ""));
    }
    xml.push_str("      </Cells>\n");
    xml.push_str("    </Piece>\n");
    xml.push_str("  </UnstructuredGrid>\n");
    xml.push_str("  <AppendedData encoding=\"raw\">\n   _");
    w.write_all(xml.as_bytes())?;

    let mut chunk = Vec::with_capacity((1 << 16) + 64);
    let c = &mut chunk;
    write_block(w, &time, std::iter::once(snap.time_s), c)?;
    write_block(w, &velocity, snap.vel.iter().flatten().copied(), c)?;
    write_block(w, &density, snap.rho.iter().copied(), c)?;
    write_block(w, &pressure, snap.pressure.iter().copied(), c)?;
    write_block(w, &kind, snap.kind.iter().copied(), c)?;
    write_block(w, &id, snap.id.iter().copied(), c)?;
    write_block(w, &points, snap.pos.iter().flatten().copied(), c)?;
    if wide {
        write_block(w, &connectivity, 0..n as i64, c)?;
        write_block(w, &offsets, 1..=n as i64, c)?;
    } else {
        write_block(w, &connectivity, 0..n as i32, c)?;
        write_block(w, &offsets, 1..=n as i32, c)?;
    }
    write_block(w, &types, std::iter::repeat_n(VTK_VERTEX, n), c)?;
    for ((d, _), (_, values)) in extra.iter().zip(snap.extra) {
        write_block(w, d, values.iter().copied(), c)?;
    }

    w.write_all(b"\n  </AppendedData>\n</VTKFile>\n")?;
    Ok(())
}

/// VTK cell type of a triangle.
const VTK_TRIANGLE: u8 = 5;

/// Writes a complete `.vtu` of the triangle mesh `mesh` (`wgsph surface`): its vertices as
/// points, one VTK_TRIANGLE cell per triangle, the time as field data.
pub(crate) fn write_triangles_vtu(w: &mut dyn Write, mesh: &super::SurfaceMesh) -> io::Result<()> {
    let (n, cells) = (mesh.vertices.len(), mesh.triangles.len());
    let wide = n > i32::MAX as usize || 3 * cells > i32::MAX as usize;
    let index_decl = |name, tuples| {
        if wide {
            ArrayDecl::new::<i64>(name, 1, tuples)
        } else {
            ArrayDecl::new::<i32>(name, 1, tuples)
        }
    };
    let time = ArrayDecl::new::<f64>("TimeValue", 1, 1);
    let points = ArrayDecl::new::<f64>("Points", 3, n);
    let connectivity = index_decl("connectivity", 3 * cells);
    let offsets = index_decl("offsets", cells);
    let types = ArrayDecl::new::<u8>("types", 1, cells);
    let order = [&time, &points, &connectivity, &offsets, &types];
    let mut off = [0u64; 5];
    let mut acc = 0u64;
    for (o, d) in off.iter_mut().zip(order) {
        *o = acc;
        acc += d.block_bytes();
    }
    let mut xml = String::with_capacity(1024);
    xml.push_str("<?xml version=\"1.0\"?>\n");
    xml.push_str(
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
    );
    xml.push_str("  <UnstructuredGrid>\n    <FieldData>\n");
    xml.push_str(&time.xml("      ", off[0], " NumberOfTuples=\"1\""));
    xml.push_str("    </FieldData>\n");
    xml.push_str(&format!(
        "    <Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{cells}\">\n      <Points>\n"
    ));
    xml.push_str(&points.xml("        ", off[1], ""));
    xml.push_str("      </Points>\n      <Cells>\n");
    for (d, o) in order[2..].iter().zip(&off[2..]) {
        xml.push_str(&d.xml("        ", *o, ""));
    }
    xml.push_str("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n");
    xml.push_str("  <AppendedData encoding=\"raw\">\n   _");
    w.write_all(xml.as_bytes())?;

    let mut chunk = Vec::with_capacity((1 << 16) + 64);
    let c = &mut chunk;
    write_block(w, &time, std::iter::once(mesh.time_s), c)?;
    write_block(w, &points, mesh.vertices.iter().flatten().copied(), c)?;
    let corners = mesh.triangles.iter().flatten().copied();
    if wide {
        write_block(w, &connectivity, corners.map(|v| v as i64), c)?;
        write_block(w, &offsets, (1..=cells as i64).map(|k| 3 * k), c)?;
    } else {
        write_block(w, &connectivity, corners.map(|v| v as i32), c)?;
        write_block(w, &offsets, (1..=cells as i32).map(|k| 3 * k), c)?;
    }
    write_block(w, &types, std::iter::repeat_n(VTK_TRIANGLE, cells), c)?;
    w.write_all(b"\n  </AppendedData>\n</VTKFile>\n")?;
    Ok(())
}

/// Reads the files written above back (`wgsph plot --snapshots`, the tests). Only this writer's
/// layout is understood: raw appended arrays with UInt64 byte counts, little-endian. Errors say
/// what is wrong in words; the caller names the file.
pub(crate) mod reader {
    use std::collections::HashMap;

    pub struct Array {
        pub vtk_type: String,
        pub components: usize,
        pub data: Vec<u8>,
    }

    pub struct Vtu {
        /// The XML before the appended data (what the tests check the structure of).
        #[cfg_attr(not(test), allow(dead_code))]
        pub header: String,
        pub number_of_points: usize,
        pub number_of_cells: usize,
        pub arrays: HashMap<String, Array>,
    }

    fn attr(elem: &str, name: &str) -> Option<String> {
        let key = format!(" {name}=\"");
        let start = elem.find(&key)? + key.len();
        let len = elem[start..].find('"')?;
        Some(elem[start..start + len].to_string())
    }

    fn number(elem: &str, name: &str) -> Result<usize, String> {
        attr(elem, name)
            .and_then(|v| v.parse().ok())
            .ok_or_else(|| format!("no whole-number {name} in `{}`", elem.trim()))
    }

    const CLOSING: &[u8] = b"\n  </AppendedData>\n</VTKFile>\n";

    impl Vtu {
        pub fn parse(bytes: &[u8]) -> Result<Vtu, String> {
            let marker = b"<AppendedData encoding=\"raw\">";
            let m = bytes
                .windows(marker.len())
                .position(|w| w == marker)
                .ok_or("no raw <AppendedData> element (not a file wgsph wrote, or cut short)")?;
            let header = std::str::from_utf8(&bytes[..m])
                .map_err(|_| "the XML header is not UTF-8")?
                .to_string();
            let us = m + bytes[m..]
                .iter()
                .position(|&b| b == b'_')
                .ok_or("no '_' opening the appended data")?;
            if !bytes[m + marker.len()..us]
                .iter()
                .all(|b| b.is_ascii_whitespace())
            {
                return Err("text between <AppendedData> and its '_'".into());
            }
            let base = us + 1;
            for (needle, what) in [
                (
                    "<VTKFile type=\"UnstructuredGrid\"",
                    "an UnstructuredGrid file",
                ),
                ("byte_order=\"LittleEndian\"", "little-endian"),
                ("header_type=\"UInt64\"", "UInt64 block headers"),
            ] {
                if !header.contains(needle) {
                    return Err(format!("the header does not declare {what}"));
                }
            }
            let piece = header
                .lines()
                .find(|l| l.contains("<Piece "))
                .ok_or("no <Piece> element")?;
            let number_of_points = number(piece, "NumberOfPoints")?;
            let number_of_cells = number(piece, "NumberOfCells")?;

            let mut arrays = HashMap::new();
            let mut last_end = 0usize;
            for line in header.lines().filter(|l| l.contains("<DataArray ")) {
                let name =
                    attr(line, "Name").ok_or_else(|| format!("no Name in `{}`", line.trim()))?;
                if attr(line, "format").as_deref() != Some("appended") {
                    return Err(format!("array {name} is not in the appended section"));
                }
                let vtk_type =
                    attr(line, "type").ok_or_else(|| format!("array {name} has no type"))?;
                let components = match attr(line, "NumberOfComponents") {
                    Some(_) => number(line, "NumberOfComponents")?,
                    None => 1,
                };
                let cut = || format!("array {name} runs past the end of the file (cut short?)");
                // Offsets and lengths are the file's word: checked, as a corrupt one may be
                // anything up to 2^64 - 1.
                let at = base.checked_add(number(line, "offset")?).ok_or_else(cut)?;
                let count = bytes.get(at..at.saturating_add(8)).ok_or_else(cut)?;
                let len = u64::from_le_bytes(count.try_into().expect("8 bytes"));
                let end = usize::try_from(len)
                    .ok()
                    .and_then(|len| (at + 8).checked_add(len))
                    .ok_or_else(cut)?;
                let data = bytes.get(at + 8..end).ok_or_else(cut)?.to_vec();
                last_end = last_end.max(end);
                let prev = arrays.insert(
                    name.clone(),
                    Array {
                        vtk_type,
                        components,
                        data,
                    },
                );
                if prev.is_some() {
                    return Err(format!("array {name} appears twice"));
                }
            }
            if bytes.get(last_end..) != Some(CLOSING) {
                return Err(
                    "the file does not end with its closing tags after the last array \
                            (cut short, or written by something else)"
                        .into(),
                );
            }
            Ok(Vtu {
                header,
                number_of_points,
                number_of_cells,
                arrays,
            })
        }

        /// The bytes of array `name`, which must have this type and number of components.
        pub fn array(
            &self,
            name: &str,
            vtk_type: &str,
            components: usize,
        ) -> Result<&[u8], String> {
            let a = self
                .arrays
                .get(name)
                .ok_or_else(|| format!("no array {name}"))?;
            if (a.vtk_type.as_str(), a.components) != (vtk_type, components) {
                return Err(format!(
                    "array {name} is {} × {}, not {vtk_type} × {components}",
                    a.vtk_type, a.components
                ));
            }
            Ok(&a.data)
        }

        /// Array `name` as `T` values, `components` per point (per tuple for field data).
        fn values<const N: usize, T>(
            &self,
            name: &str,
            vtk_type: &str,
            components: usize,
            from: fn([u8; N]) -> T,
        ) -> Result<Vec<T>, String> {
            let data = self.array(name, vtk_type, components)?;
            if data.len() % N != 0 {
                return Err(format!(
                    "array {name}'s {} bytes are not whole values",
                    data.len()
                ));
            }
            Ok(data
                .chunks_exact(N)
                .map(|c| from(c.try_into().expect("N bytes")))
                .collect())
        }

        pub fn f64s(&self, name: &str, comps: usize) -> Result<Vec<f64>, String> {
            self.values(name, "Float64", comps, f64::from_le_bytes)
        }

        pub fn f32s(&self, name: &str, comps: usize) -> Result<Vec<f32>, String> {
            self.values(name, "Float32", comps, f32::from_le_bytes)
        }

        pub fn u32s(&self, name: &str) -> Result<Vec<u32>, String> {
            self.values(name, "UInt32", 1, u32::from_le_bytes)
        }

        pub fn i32s(&self, name: &str) -> Result<Vec<i32>, String> {
            self.values(name, "Int32", 1, i32::from_le_bytes)
        }

        pub fn i64s(&self, name: &str) -> Result<Vec<i64>, String> {
            self.values(name, "Int64", 1, i64::from_le_bytes)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::reader::Vtu;
    use super::*;

    struct Owned {
        pos: Vec<[f64; 3]>,
        vel: Vec<[f32; 3]>,
        rho: Vec<f32>,
        p: Vec<f32>,
        kind: Vec<u32>,
        id: Vec<u32>,
    }

    impl Owned {
        fn new(n: usize) -> Self {
            let pos = (0..n)
                .map(|i| {
                    let x = i as f64;
                    [1e6 + x / 3.0, -x * 0.1 - 1e-9, (x + 0.5).sqrt()]
                })
                .collect();
            Owned {
                pos,
                vel: (0..n)
                    .map(|i| [i as f32, -(i as f32) / 7.0, 0.25])
                    .collect(),
                rho: (0..n).map(|i| 1000.0 + i as f32 * 0.01).collect(),
                p: (0..n).map(|i| i as f32 * 3.5 - 10.0).collect(),
                kind: (0..n).map(|i| (i % 3 == 0) as u32).collect(),
                id: (0..n).map(|i| (n - i) as u32 * 7 + 3).collect(),
            }
        }

        fn snap(&self, t: f64) -> Snapshot<'_> {
            Snapshot {
                extra: &[],
                time_s: t,
                pos: &self.pos,
                vel: &self.vel,
                rho: &self.rho,
                pressure: &self.p,
                kind: &self.kind,
                id: &self.id,
            }
        }
    }

    fn to_bytes(snap: &Snapshot) -> Vec<u8> {
        let mut buf = Vec::new();
        write_vtu(&mut buf, snap).unwrap();
        buf
    }

    #[test]
    fn round_trip_all_arrays() {
        let n = 20_000; // several encoding chunks per array
        let o = Owned::new(n);
        let bytes = to_bytes(&o.snap(0.125));
        let v = Vtu::parse(&bytes).unwrap();
        assert_eq!(v.number_of_points, n);
        assert_eq!(v.number_of_cells, n);
        assert_eq!(v.arrays.len(), 10);

        let pts = v.f64s("Points", 3).unwrap();
        let ids = v.u32s("id").unwrap();
        assert_eq!(pts.len(), 3 * n);
        assert_eq!(ids, o.id);
        for i in [0, 1, 2, n / 2, n - 1] {
            for c in 0..3 {
                assert_eq!(pts[3 * i + c].to_bits(), o.pos[i][c].to_bits());
            }
            assert_eq!(ids[i], o.id[i]);
        }
        let all_pos: Vec<f64> = o.pos.iter().flatten().copied().collect();
        assert_eq!(pts, all_pos);
        let all_vel: Vec<f32> = o.vel.iter().flatten().copied().collect();
        assert_eq!(v.f32s("velocity", 3).unwrap(), all_vel);
        assert_eq!(v.f32s("density", 1).unwrap(), o.rho);
        assert_eq!(v.f32s("pressure", 1).unwrap(), o.p);
        assert_eq!(v.u32s("kind").unwrap(), o.kind);
        assert_eq!(
            v.i32s("connectivity").unwrap(),
            (0..n as i32).collect::<Vec<_>>()
        );
        assert_eq!(
            v.i32s("offsets").unwrap(),
            (1..=n as i32).collect::<Vec<_>>()
        );
        assert!(v
            .array("types", "UInt8", 1)
            .unwrap()
            .iter()
            .all(|&t| t == 1));
        assert_eq!(v.array("types", "UInt8", 1).unwrap().len(), n);
        assert_eq!(v.f64s("TimeValue", 1).unwrap(), vec![0.125]);
        assert!(v
            .header
            .contains("<PointData Scalars=\"density\" Vectors=\"velocity\">"));
        // Well-formed XML for this fixed structure: each element opened and closed once.
        assert!(v
            .header
            .starts_with("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\""));
        for tag in [
            "UnstructuredGrid",
            "Piece",
            "PointData",
            "Points",
            "Cells",
            "FieldData",
        ] {
            let open = v.header.matches(&format!("<{tag}>")).count()
                + v.header.matches(&format!("<{tag} ")).count();
            let close = v.header.matches(&format!("</{tag}>")).count();
            assert_eq!((open, close), (1, 1), "tag {tag}");
        }
        assert!(v
            .header
            .lines()
            .filter(|l| l.contains("<DataArray "))
            .all(|l| l.trim_end().ends_with("/>")));
    }

    /// A surface mesh reads back as written: points, one triangle cell per triangle, its time.
    #[test]
    fn triangle_meshes_round_trip() {
        let mesh = crate::output::SurfaceMesh {
            time_s: 0.25,
            vertices: vec![
                [0.0, 0.0, 1.0],
                [1.0, 0.0, 1.0],
                [0.0, 1.0, 1.0],
                [1.0, 1.0, 1.5],
            ],
            triangles: vec![[0, 1, 2], [1, 3, 2]],
        };
        let mut buf = Vec::new();
        write_triangles_vtu(&mut buf, &mesh).unwrap();
        let v = Vtu::parse(&buf).unwrap();
        assert_eq!((v.number_of_points, v.number_of_cells), (4, 2));
        assert_eq!(v.f64s("TimeValue", 1).unwrap(), [0.25]);
        let points = v.f64s("Points", 3).unwrap();
        assert_eq!(points, mesh.vertices.concat());
        assert_eq!(v.i32s("connectivity").unwrap(), [0, 1, 2, 1, 3, 2]);
        assert_eq!(v.i32s("offsets").unwrap(), [3, 6]);
        let types = &v.arrays["types"];
        assert_eq!(
            (types.vtk_type.as_str(), types.data.as_slice()),
            ("UInt8", &[5u8, 5][..])
        );
    }

    #[test]
    fn a_cut_or_foreign_file_is_an_error_not_a_panic() {
        let bytes = to_bytes(&Owned::new(100).snap(0.5));
        for cut in [0, 10, 200, bytes.len() / 2, bytes.len() - 1] {
            assert!(Vtu::parse(&bytes[..cut]).is_err(), "cut at {cut}");
        }
        let v = Vtu::parse(&bytes).unwrap();
        let err = v.f32s("Points", 3).unwrap_err();
        assert!(err.contains("Float64"), "{err}");
        assert!(v.u32s("no such array").is_err());
        let mut big_offset = bytes.clone();
        let at = String::from_utf8_lossy(&bytes).find("offset=\"").unwrap() + 8;
        big_offset[at] = b'9';
        big_offset.splice(at..at, *b"99999999");
        assert!(Vtu::parse(&big_offset).is_err());
    }

    #[test]
    fn zero_particles() {
        let o = Owned::new(0);
        let bytes = to_bytes(&o.snap(0.0));
        let v = Vtu::parse(&bytes).unwrap();
        assert_eq!(v.number_of_points, 0);
        assert_eq!(v.number_of_cells, 0);
        assert_eq!(v.arrays.len(), 10);
        assert!(v.f64s("Points", 3).unwrap().is_empty());
        assert!(v.u32s("id").unwrap().is_empty());
        assert!(v.i32s("offsets").unwrap().is_empty());
    }

    #[test]
    fn nan_values_are_kept_bitwise() {
        let mut o = Owned::new(3);
        o.pos[1] = [f64::NAN, f64::INFINITY, -0.0];
        o.p[2] = f32::NAN;
        let bytes = to_bytes(&o.snap(f64::NAN));
        let v = Vtu::parse(&bytes).unwrap();
        let pts = v.f64s("Points", 3).unwrap();
        assert!(
            pts[3].is_nan() && pts[4] == f64::INFINITY && pts[5].to_bits() == (-0.0f64).to_bits()
        );
        assert!(v.f32s("pressure", 1).unwrap()[2].is_nan());
        assert!(v.f64s("TimeValue", 1).unwrap()[0].is_nan());
    }

    #[test]
    fn file_size_matches_layout() {
        let n = 1000;
        let o = Owned::new(n);
        let bytes = to_bytes(&o.snap(1.0));
        let v = Vtu::parse(&bytes).unwrap();
        let data: usize = v.arrays.values().map(|a| a.data.len() + 8).sum();
        // 24 + 12 + 4 + 4 + 4 + 4 + 4 + 4 + 1 bytes per particle, plus the time value.
        assert_eq!(data, n * 61 + 16 + 9 * 8);
        let header_end = v.header.len() + "<AppendedData encoding=\"raw\">\n   _".len();
        assert_eq!(
            bytes.len(),
            header_end + data + "\n  </AppendedData>\n</VTKFile>\n".len()
        );
    }
}

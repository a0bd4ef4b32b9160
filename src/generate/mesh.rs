//! Closed triangle meshes as the shape of a 3D body: checking that the triangles bound a solid,
//! the solid's mass properties at uniform density, which points lie inside it and how far a
//! point is from its surface.
//!
//! Inside means an odd number of surface crossings on the vertical line above the point (the
//! even–odd rule, exact for a closed surface). The lines are cast through points shifted by a
//! fixed tiny offset, so a line through a lattice point does not run exactly along an edge of a
//! mesh drawn on round numbers. Triangles are bucketed by the columns of a grid in x–y, so a
//! line or a small ball meets only the triangles of the columns it touches.

use crate::generate::surface::Edges;
use crate::generate::triangle::{cross, distance, dot, sub};

use super::aabb::Aabb;

/// How far, relative to the shape's size, the lines that count crossings are moved off the
/// points they go through (x, y): far below a spacing, off any round number (also a
/// polygon's).
pub(crate) const LINE_SHIFT: [f64; 2] = [2.718_281_8e-9, 1.414_213_5e-9];

/// What is wrong with a mesh as a body's shape; the messages name the file and say where.
#[derive(Debug, thiserror::Error)]
pub(crate) enum MeshError {
    #[error("{file} has no triangles")]
    Empty { file: String },
    #[error("{file} has a vertex with a coordinate that is not a finite number")]
    NotFinite { file: String },
    #[error(
        "{file} is not closed: {count} edges belong to one triangle only, one from {from:?} to \
         {to:?}; inside and outside are then undefined"
    )]
    Open {
        file: String,
        count: usize,
        from: [f64; 3],
        to: [f64; 3],
    },
    #[error(
        "{file} is not a surface: {count} edges are shared by more than two triangles, one from \
         {from:?} to {to:?}"
    )]
    NonManifold {
        file: String,
        count: usize,
        from: [f64; 3],
        to: [f64; 3],
    },
    #[error(
        "{file}'s triangles are not oriented alike: the two triangles on the edge from {from:?} \
         to {to:?} run along it in the same direction"
    )]
    Inconsistent {
        file: String,
        from: [f64; 3],
        to: [f64; 3],
    },
    #[error("{file} encloses no volume ({volume:e} m³)")]
    NoVolume { file: String, volume: f64 },
}

impl MeshError {
    /// What the user can do about it.
    pub(crate) fn fix(&self) -> &'static str {
        match self {
            MeshError::Empty { .. } | MeshError::NotFinite { .. } => {
                "export the body's closed surface as an STL or OBJ file, in metres"
            }
            MeshError::Open { .. } | MeshError::NonManifold { .. } => {
                "export one closed, watertight surface (repair it in the CAD tool or with a mesh \
                 fixer such as MeshLab's 'close holes')"
            }
            MeshError::Inconsistent { .. } => {
                "re-orient the faces consistently (MeshLab: 'Re-Orient all faces coherently')"
            }
            MeshError::NoVolume { .. } => "export the solid's surface, in metres",
        }
    }
}

/// A closed, consistently oriented triangle surface and the solid it bounds.
#[derive(Clone, PartialEq)]
pub(crate) struct Mesh {
    /// The triangles, counter-clockwise seen from outside.
    tris: Vec<[[f64; 3]; 3]>,
    bounds: Aabb,
    volume: f64,
    centroid: [f64; 3],
    /// ∫ (r − c)(r − c)ᵀ dV over the solid, about its centroid c [m⁵].
    second_moment: [[f64; 3]; 3],
    columns: Columns,
}

impl std::fmt::Debug for Mesh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Mesh {{ {} triangles, {:?} .. {:?} }}",
            self.tris.len(),
            self.bounds.min,
            self.bounds.max
        )
    }
}

/// Triangles by the grid columns (in x–y) their bounding boxes overlap.
#[derive(Clone, PartialEq)]
struct Columns {
    origin: [f64; 2],
    cell: f64,
    n: [usize; 2],
    /// Column k holds `tris[start[k]..start[k + 1]]`.
    start: Vec<u32>,
    tris: Vec<u32>,
}

impl Mesh {
    /// The mesh of indexed triangles; `file` names it in errors.
    pub(crate) fn new(
        file: &str,
        vertices: &[[f64; 3]],
        faces: &[[usize; 3]],
    ) -> Result<Mesh, MeshError> {
        if faces.is_empty() {
            return Err(MeshError::Empty { file: file.into() });
        }
        if vertices.iter().flatten().any(|c| !c.is_finite()) {
            return Err(MeshError::NotFinite { file: file.into() });
        }
        check_closed(file, vertices, faces)?;
        // Zero-area triangles bound nothing (their edges are their neighbours' too).
        let mut tris: Vec<[[f64; 3]; 3]> = faces
            .iter()
            .map(|f| f.map(|v| vertices[v]))
            .filter(|[a, b, c]| cross(sub(*b, *a), sub(*c, *a)) != [0.0; 3])
            .collect();
        let mut bounds = Aabb {
            min: [f64::MAX; 3],
            max: [f64::MIN; 3],
        };
        for p in vertices {
            for (a, &x) in p.iter().enumerate() {
                bounds.min[a] = bounds.min[a].min(x);
                bounds.max[a] = bounds.max[a].max(x);
            }
        }
        let (mut volume, centroid, mut second_moment) = mass_properties(&tris, &bounds);
        if !(volume.abs() > 0.0 && volume.is_finite()) {
            return Err(MeshError::NoVolume {
                file: file.into(),
                volume,
            });
        }
        if volume < 0.0 {
            // Inward normals: the same solid, read the other way round.
            for t in &mut tris {
                t.swap(1, 2);
            }
            volume = -volume;
            for row in &mut second_moment {
                for x in row {
                    *x = -*x;
                }
            }
        }
        let columns = Columns::new(&tris, &bounds);
        Ok(Mesh {
            tris,
            bounds,
            volume,
            centroid,
            second_moment,
            columns,
        })
    }

    pub(crate) fn bounds(&self) -> Aabb {
        self.bounds
    }

    pub(crate) fn volume(&self) -> f64 {
        self.volume
    }

    pub(crate) fn centroid(&self) -> [f64; 3] {
        self.centroid
    }

    /// Inertia tensor about the centroid of the solid of uniform density and `mass`:
    /// I = (mass / V) (tr S 1 − S) with S the second moment.
    pub(crate) fn inertia(&self, mass: f64) -> [[f64; 3]; 3] {
        let s = &self.second_moment;
        let trace = s[0][0] + s[1][1] + s[2][2];
        let k = mass / self.volume;
        let mut i = [[0.0; 3]; 3];
        for (a, row) in i.iter_mut().enumerate() {
            for (b, x) in row.iter_mut().enumerate() {
                *x = k * (if a == b { trace } else { 0.0 } - s[a][b]);
            }
        }
        i
    }

    /// The heights at which the vertical line through (x, y) crosses the surface, ascending.
    fn crossings(&self, x: f64, y: f64) -> Vec<f64> {
        let (x, y) = self.shifted(x, y);
        let mut z = Vec::new();
        let Some(k) = self.columns.column(x, y) else {
            return z;
        };
        for &t in self.columns.of(k) {
            let [a, b, c] = self.tris[t as usize];
            // Twice the signed areas of the sub-triangles opposite each vertex, in x–y.
            let w = [orient(b, c, x, y), orient(c, a, x, y), orient(a, b, x, y)];
            let area = w[0] + w[1] + w[2];
            let inside = if area > 0.0 {
                w.iter().all(|&v| v > 0.0)
            } else if area < 0.0 {
                w.iter().all(|&v| v < 0.0)
            } else {
                // Seen edge-on from above: the line does not cross it.
                false
            };
            if inside {
                z.push((w[0] * a[2] + w[1] * b[2] + w[2] * c[2]) / area);
            }
        }
        z.sort_by(f64::total_cmp);
        z
    }

    /// Whether `p` is inside the solid.
    pub(crate) fn contains(&self, p: [f64; 3]) -> bool {
        odd_above(p[2], &self.crossings(p[0], p[1]))
    }

    /// The line casts go through (x, y) moved by a fixed offset far below a lattice spacing
    /// (a few 1e-9 of the mesh's size), off the mesh's own round numbers.
    fn shifted(&self, x: f64, y: f64) -> (f64, f64) {
        let size = (0..3)
            .map(|a| self.bounds.max[a] - self.bounds.min[a])
            .fold(0.0, f64::max);
        (x + LINE_SHIFT[0] * size, y + LINE_SHIFT[1] * size)
    }

    /// The distance from `p` to the surface if it is less than `reach`.
    pub(crate) fn distance_within(&self, p: [f64; 3], reach: f64) -> Option<f64> {
        let mut best = reach;
        let mut found = false;
        for k in self.columns.around(p[0], p[1], reach) {
            for &t in self.columns.of(k) {
                let tri = &self.tris[t as usize];
                // A column holds its triangles at every height: those farther than the best
                // so far along any axis are passed over without the full test.
                let apart = (0..3).any(|a| {
                    let (lo, hi) = (
                        tri.iter().map(|q| q[a]).fold(f64::MAX, f64::min),
                        tri.iter().map(|q| q[a]).fold(f64::MIN, f64::max),
                    );
                    p[a] < lo - best || p[a] > hi + best
                });
                if apart {
                    continue;
                }
                let d = distance(p, tri);
                if d < best {
                    best = d;
                    found = true;
                }
            }
        }
        found.then_some(best)
    }

    /// The lattice points of the solid: a cell-centred lattice of spacing `dx` centred on the
    /// bounding box (whose cells cover it), keeping the points inside the surface and, with
    /// `depth`, less than `depth` from it. A cuboid whose sides are whole multiples of `dx`
    /// gets a box body's lattice.
    pub(crate) fn points(&self, dx: f64, depth: Option<f64>) -> Vec<[f64; 3]> {
        let (n, origin) = self.lattice(dx);
        let at = |a: usize, i: usize| origin[a] + (i as f64 + 0.5) * dx;
        let near = depth.map(|d| self.near_lattice(n, origin, dx, d));
        let mut out = Vec::new();
        for i in 0..n[0] {
            for j in 0..n[1] {
                let (x, y) = (at(0, i), at(1, j));
                let crossings = self.crossings(x, y);
                if crossings.is_empty() {
                    continue;
                }
                for k in 0..n[2] {
                    let p = [x, y, at(2, k)];
                    let close = near
                        .as_ref()
                        .is_none_or(|near| near[i + n[0] * (j + n[1] * k)]);
                    if close && odd_above(p[2], &crossings) {
                        out.push(p);
                    }
                }
            }
        }
        out
    }

    /// Cells of size `dx` along each axis that cover the bounding box (a whole multiple of
    /// `dx`, to rounding, is covered exactly), centred on it, and the corner of the first.
    pub(crate) fn lattice(&self, dx: f64) -> ([usize; 3], [f64; 3]) {
        let b = &self.bounds;
        let n = [0, 1, 2].map(|a| ((b.max[a] - b.min[a]) / dx - 1e-9).ceil().max(1.0) as usize);
        let origin = [0, 1, 2].map(|a| 0.5 * (b.min[a] + b.max[a]) - 0.5 * n[a] as f64 * dx);
        (n, origin)
    }

    /// Which points of the lattice (`n` cells from `origin`, spacing `dx`) are less than
    /// `reach` from the surface: each triangle marks the points of its bounding box grown by
    /// `reach`, so the work goes with the surface, not with the solid's volume.
    fn near_lattice(&self, n: [usize; 3], origin: [f64; 3], dx: f64, reach: f64) -> Vec<bool> {
        let mut near = vec![false; n[0] * n[1] * n[2]];
        let at = |a: usize, i: usize| origin[a] + (i as f64 + 0.5) * dx;
        for tri in &self.tris {
            let range = [0, 1, 2].map(|a| {
                let lo = tri.iter().map(|q| q[a]).fold(f64::MAX, f64::min) - reach;
                let hi = tri.iter().map(|q| q[a]).fold(f64::MIN, f64::max) + reach;
                let first = ((lo - origin[a]) / dx - 0.5).ceil().max(0.0) as usize;
                let last = ((hi - origin[a]) / dx - 0.5).floor().min(n[a] as f64 - 1.0);
                (first, last)
            });
            if range.iter().any(|&(first, last)| last < first as f64) {
                continue;
            }
            for k in range[2].0..=range[2].1 as usize {
                for j in range[1].0..=range[1].1 as usize {
                    for i in range[0].0..=range[0].1 as usize {
                        let idx = i + n[0] * (j + n[1] * k);
                        if !near[idx] && distance([at(0, i), at(1, j), at(2, k)], tri) < reach {
                            near[idx] = true;
                        }
                    }
                }
            }
        }
        near
    }
}

/// Whether an odd number of the ascending `crossings` lie above `z`: inside, by the even–odd
/// rule (also a polygon's, `polygon.rs`).
pub(crate) fn odd_above(z: f64, crossings: &[f64]) -> bool {
    (crossings.len() - crossings.partition_point(|&c| c <= z)) % 2 == 1
}

/// Every edge must be shared by exactly two triangles that run along it in opposite
/// directions: then the surface is closed and its orientation is consistent.
fn check_closed(file: &str, v: &[[f64; 3]], faces: &[[usize; 3]]) -> Result<(), MeshError> {
    let edges = Edges::of(v, faces);
    if let Some((from, to)) = edges.open_example {
        return Err(MeshError::Open {
            file: file.into(),
            count: edges.open,
            from,
            to,
        });
    }
    if let Some((from, to)) = edges.crowded_example {
        return Err(MeshError::NonManifold {
            file: file.into(),
            count: edges.crowded,
            from,
            to,
        });
    }
    if let Some((from, to)) = edges.same_way_example {
        return Err(MeshError::Inconsistent {
            file: file.into(),
            from,
            to,
        });
    }
    Ok(())
}

/// Signed volume, centroid and second moment about the centroid of the solid bounded by
/// `tris`, summed over the tetrahedra each triangle spans with a reference point (the centre of
/// the bounds, which keeps the terms small). For the tetrahedron (0, a, b, c) with
/// D = a·(b × c): V = D/6, ∫r dV = D/24 (a + b + c), and
/// ∫r rᵀ dV = D/120 (a aᵀ + b bᵀ + c cᵀ + s sᵀ), s = a + b + c.
fn mass_properties(tris: &[[[f64; 3]; 3]], bounds: &Aabb) -> (f64, [f64; 3], [[f64; 3]; 3]) {
    let o = [0, 1, 2].map(|a| 0.5 * (bounds.min[a] + bounds.max[a]));
    let (mut vol, mut first, mut second) = (0.0, [0.0; 3], [[0.0; 3]; 3]);
    for t in tris {
        let [a, b, c] = t.map(|p| [0, 1, 2].map(|k| p[k] - o[k]));
        let d = dot(a, cross(b, c));
        let s = [0, 1, 2].map(|k| a[k] + b[k] + c[k]);
        vol += d / 6.0;
        for k in 0..3 {
            first[k] += d / 24.0 * s[k];
        }
        for (i, row) in second.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x += d / 120.0 * (a[i] * a[j] + b[i] * b[j] + c[i] * c[j] + s[i] * s[j]);
            }
        }
    }
    // Centroid relative to o, then the parallel-axis shift of the second moment to it.
    let rel = first.map(|x| x / vol);
    let centroid = [0, 1, 2].map(|k| o[k] + rel[k]);
    for (i, row) in second.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x -= vol * rel[i] * rel[j];
        }
    }
    (vol, centroid, second)
}

impl Columns {
    /// A grid of about as many columns as triangles (at most 512 a side) over the bounds.
    fn new(tris: &[[[f64; 3]; 3]], bounds: &Aabb) -> Columns {
        let extent = [0, 1].map(|a| (bounds.max[a] - bounds.min[a]).max(f64::MIN_POSITIVE));
        let side = (tris.len() as f64).sqrt().ceil().clamp(1.0, 512.0);
        let cell = extent[0].max(extent[1]) / side;
        let n = extent.map(|e| ((e / cell).ceil() as usize).clamp(1, 512));
        let mut columns = Columns {
            origin: [bounds.min[0], bounds.min[1]],
            cell,
            n,
            start: Vec::new(),
            tris: Vec::new(),
        };
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); n[0] * n[1]];
        for (t, tri) in tris.iter().enumerate() {
            let lo = [0, 1].map(|a| tri.iter().map(|p| p[a]).fold(f64::MAX, f64::min));
            let hi = [0, 1].map(|a| tri.iter().map(|p| p[a]).fold(f64::MIN, f64::max));
            let (i0, j0) = columns.index(lo[0], lo[1]);
            let (i1, j1) = columns.index(hi[0], hi[1]);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    lists[i + n[0] * j].push(t as u32);
                }
            }
        }
        columns.start.push(0);
        for l in lists {
            columns.tris.extend(l);
            columns.start.push(columns.tris.len() as u32);
        }
        columns
    }

    /// The column holding (x, y), clamped to the grid.
    fn index(&self, x: f64, y: f64) -> (usize, usize) {
        let at = |v: f64, a: usize| {
            (((v - self.origin[a]) / self.cell).floor().max(0.0) as usize).min(self.n[a] - 1)
        };
        (at(x, 0), at(y, 1))
    }

    /// The column of (x, y) if it lies over the grid (a line elsewhere meets no triangle).
    fn column(&self, x: f64, y: f64) -> Option<usize> {
        let (fx, fy) = (
            (x - self.origin[0]) / self.cell,
            (y - self.origin[1]) / self.cell,
        );
        let over = |f: f64, a: usize| (0.0..=self.n[a] as f64).contains(&f);
        if !(over(fx, 0) && over(fy, 1)) {
            return None;
        }
        let (i, j) = self.index(x, y);
        Some(i + self.n[0] * j)
    }

    /// The columns that the disc of radius `r` about (x, y) touches.
    fn around(&self, x: f64, y: f64, r: f64) -> impl Iterator<Item = usize> + '_ {
        let (i0, j0) = self.index(x - r, y - r);
        let (i1, j1) = self.index(x + r, y + r);
        (j0..=j1).flat_map(move |j| (i0..=i1).map(move |i| i + self.n[0] * j))
    }

    fn of(&self, k: usize) -> &[u32] {
        &self.tris[self.start[k] as usize..self.start[k + 1] as usize]
    }
}

/// Twice the signed area of the triangle (a, b, (x, y)) in x–y: positive when counter-clockwise.
fn orient(a: [f64; 3], b: [f64; 3], x: f64, y: f64) -> f64 {
    (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::generate::mesh_file::{parse, MeshFormat};
    use crate::generate::surface::tests::{cuboid, globe};

    fn mesh(vf: (Vec<[f64; 3]>, Vec<[usize; 3]>)) -> Mesh {
        Mesh::new("test.stl", &vf.0, &vf.1).unwrap()
    }

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * b.abs().max(1e-300)
    }

    #[test]
    fn a_cuboid_has_the_mass_properties_of_a_box() {
        let (lo, hi) = ([0.1, -0.2, 0.3], [0.5, 0.1, 0.45]);
        let m = mesh(cuboid(lo, hi));
        let s = [0, 1, 2].map(|a| hi[a] - lo[a]);
        assert!(close(m.volume(), s[0] * s[1] * s[2], 1e-12));
        for a in 0..3 {
            assert!(close(m.centroid()[a], 0.5 * (lo[a] + hi[a]), 1e-12));
        }
        let i = m.inertia(3.0);
        let sq = s.map(|x| x * x);
        let expect = [sq[1] + sq[2], sq[0] + sq[2], sq[0] + sq[1]].map(|x| 3.0 * x / 12.0);
        for a in 0..3 {
            assert!(close(i[a][a], expect[a], 1e-12), "{i:?}");
            for b in 0..3 {
                assert!(a == b || i[a][b].abs() < 1e-14, "{i:?}");
            }
        }
    }

    /// The corner tetrahedron of the unit cube, scaled by L and moved: V = L³/6, centroid at
    /// L/4 from the corner, and by direct integration ∫x'² dV = L⁵/160, ∫x'y' dV = −L⁵/480
    /// about the centroid, so I_xx = (m/V)(2 L⁵/160) and I_xy = (m/V) L⁵/480. Its centroid is
    /// not the centre of its bounds, which the mass properties are summed about.
    #[test]
    fn a_tetrahedron_has_its_textbook_mass_properties() {
        let (l, o) = (0.3, [1.0, -2.0, 0.5]);
        let v: Vec<[f64; 3]> = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
            .iter()
            .map(|p| [0, 1, 2].map(|a| o[a] + l * p[a]))
            .collect();
        let m = mesh((v, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]));
        let vol = l * l * l / 6.0;
        assert!(close(m.volume(), vol, 1e-13));
        for (got, o) in m.centroid().iter().zip(o) {
            assert!(close(*got, o + 0.25 * l, 1e-13));
        }
        let (mass, l5) = (2.0, l.powi(5));
        for (a, row) in m.inertia(mass).iter().enumerate() {
            for (b, got) in row.iter().enumerate() {
                let want = mass / vol * if a == b { 2.0 * l5 / 160.0 } else { l5 / 480.0 };
                assert!(close(*got, want, 1e-12), "{a}{b}: {got} vs {want}");
            }
        }
    }

    /// Turned by R, the inertia tensor is R I Rᵀ, off-diagonal terms included.
    #[test]
    fn a_turned_cuboid_has_the_turned_inertia() {
        let (v, f) = cuboid([-0.2, -0.1, -0.05], [0.2, 0.1, 0.05]);
        let (a, b) = (0.4f64, -0.7f64);
        // R = Rz(a) Rx(b).
        let r = [
            [a.cos(), -a.sin() * b.cos(), a.sin() * b.sin()],
            [a.sin(), a.cos() * b.cos(), -a.cos() * b.sin()],
            [0.0, b.sin(), b.cos()],
        ];
        let turn =
            |p: [f64; 3]| [0, 1, 2].map(|i| (0..3).map(|k| r[i][k] * p[k]).sum::<f64>() + 1.0);
        let m = mesh((v.iter().map(|&p| turn(p)).collect(), f));
        let i0 = [0.04 + 0.01, 0.16 + 0.01, 0.16 + 0.04].map(|x| 2.0 * x / 12.0);
        for p in 0..3 {
            assert!(close(m.centroid()[p], 1.0, 1e-12));
            for q in 0..3 {
                let want: f64 = (0..3).map(|k| r[p][k] * i0[k] * r[q][k]).sum();
                assert!((m.inertia(2.0)[p][q] - want).abs() < 1e-14, "{p}{q}");
            }
        }
        assert!(
            m.inertia(2.0)[0][1].abs() > 1e-4,
            "the test turns the box off the axes"
        );
    }

    /// Faces listed inward give the same solid.
    #[test]
    fn inward_faces_give_the_same_solid() {
        let (v, f) = cuboid([0.0; 3], [0.3, 0.2, 0.1]);
        let flipped: Vec<[usize; 3]> = f.iter().map(|t| [t[0], t[2], t[1]]).collect();
        let (out, inw) = (mesh((v.clone(), f)), mesh((v, flipped)));
        assert!(close(inw.volume(), out.volume(), 1e-14));
        assert_eq!(inw.inertia(1.0), out.inertia(1.0));
        assert_eq!(inw.points(0.05, Some(0.05)), out.points(0.05, Some(0.05)));
    }

    /// The cuboid's lattice is a box body's: cell-centred, as many cells as fit.
    #[test]
    fn a_cuboid_is_filled_like_a_box() {
        let m = mesh(cuboid([0.0, 0.0, 0.0], [0.1, 0.06, 0.04]));
        let all = m.points(0.01, None);
        assert_eq!(all.len(), 10 * 6 * 4);
        assert_eq!(all[0], [0.005, 0.005, 0.005]);
        // Two layers: everything but the inner 6 x 2 x 0.
        assert_eq!(m.points(0.01, Some(0.02)).len(), 240);
        // One layer: everything but the inner 8 x 4 x 2.
        assert_eq!(m.points(0.01, Some(0.01)).len(), 240 - 64);
    }

    /// A faceted sphere: its volume is the polyhedron's (computed here from its facets
    /// independently: the sum of the pyramids from the centre), points well inside and well
    /// outside are classified as the sphere's, and its lattice fills the volume.
    #[test]
    fn a_faceted_sphere() {
        let (c, r) = ([0.3, -0.1, 0.2], 0.1);
        let (v, f) = globe(c, r, 24, 48);
        let m = mesh((v.clone(), f.clone()));
        let pyramids: f64 = f
            .iter()
            .map(|t| {
                let [a, b, d] = t.map(|k| sub(v[k], c));
                dot(a, cross(b, d)) / 6.0
            })
            .sum();
        assert!(close(m.volume(), pyramids.abs(), 1e-12));
        assert!(close(
            m.volume(),
            4.0 / 3.0 * std::f64::consts::PI * r * r * r,
            0.01
        ));
        for (got, c) in m.centroid().iter().zip(c) {
            assert!((got - c).abs() < 1e-12);
        }
        let mut rng = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..2000 {
            let p = [0, 1, 2].map(|a| c[a] + 0.25 * (2.0 * next() - 1.0));
            let d = (0..3).map(|a| (p[a] - c[a]).powi(2)).sum::<f64>().sqrt();
            // The facets lie within r (1 − cos(π/24)) < 0.01 r of the sphere.
            if (d - r).abs() > 0.01 * r {
                assert_eq!(m.contains(p), d < r, "{p:?} at {d} from the centre");
            }
        }
        let dx = 0.01;
        let n = m.points(dx, None).len() as f64;
        assert!(close(n * dx * dx * dx, m.volume(), 0.05), "{n}");
        let shell = m.points(dx, Some(2.0 * dx));
        assert!(shell.len() < n as usize && !shell.is_empty());
        for p in shell {
            let d = (0..3).map(|a| (p[a] - c[a]).powi(2)).sum::<f64>().sqrt();
            assert!(d > r - 2.0 * dx - 0.01 * r && d < r, "{p:?}");
        }
    }

    /// The distance to a triangle against an independent form: the distance to the plane
    /// where the foot of the perpendicular lies inside, else to the nearest edge.
    #[test]
    fn distance_to_triangles() {
        let mut rng = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            2.0 * ((rng >> 11) as f64 / (1u64 << 53) as f64) - 1.0
        };
        for _ in 0..20000 {
            let t = [
                [next(), next(), next()],
                [next(), next(), next()],
                [next(), next(), next()],
            ];
            let p = [next(), next(), next()].map(|x| 2.0 * x);
            let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
            let nn = dot(n, n);
            let h = dot(sub(p, t[0]), n) / nn;
            let foot = [0, 1, 2].map(|k| p[k] - h * n[k]);
            let inside = (0..3).all(|e| {
                let (u, v) = (t[e], t[(e + 1) % 3]);
                dot(cross(sub(v, u), sub(foot, u)), n) >= 0.0
            });
            let want = if inside {
                h.abs() * nn.sqrt()
            } else {
                (0..3)
                    .map(|e| {
                        let (u, v) = (t[e], t[(e + 1) % 3]);
                        let (uv, up) = (sub(v, u), sub(p, u));
                        let s = (dot(up, uv) / dot(uv, uv)).clamp(0.0, 1.0);
                        let d = sub(up, uv.map(|x| s * x));
                        dot(d, d).sqrt()
                    })
                    .fold(f64::MAX, f64::min)
            };
            let got = distance(p, &t);
            assert!((got - want).abs() < 1e-9 * (1.0 + want), "{got} vs {want}");
        }
    }

    #[test]
    fn broken_meshes_are_refused_with_the_reason() {
        let (v, f) = cuboid([0.0; 3], [1.0; 3]);
        let err = |v: &[[f64; 3]], f: &[[usize; 3]]| Mesh::new("hull.stl", v, f).unwrap_err();
        let e = err(&v, &f[1..]);
        assert!(matches!(e, MeshError::Open { count: 3, .. }), "{e}");
        assert!(
            e.to_string().contains("hull.stl is not closed: 3 edges"),
            "{e}"
        );
        let mut flipped = f.clone();
        flipped[4] = [f[4][0], f[4][2], f[4][1]];
        assert!(matches!(err(&v, &flipped), MeshError::Inconsistent { .. }));
        let mut doubled = f.clone();
        doubled.push(f[0]);
        doubled.push([f[0][0], f[0][2], f[0][1]]);
        assert!(matches!(
            err(&v, &doubled),
            MeshError::NonManifold { count: 3, .. }
        ));
        assert!(matches!(err(&v, &[]), MeshError::Empty { .. }));
        let mut nan = v.clone();
        nan[3][1] = f64::NAN;
        assert!(matches!(err(&nan, &f), MeshError::NotFinite { .. }));
        // Two faces back to back: closed, oriented, and flat.
        let flat = [[0, 1, 3], [0, 3, 1]];
        assert!(matches!(err(&v, &flat), MeshError::NoVolume { .. }));
        for e in [err(&v, &f[1..]), err(&v, &flat)] {
            assert!(!e.fix().is_empty());
        }
    }

    /// Binary and ASCII STL files read back as the mesh written.
    #[test]
    fn stl_files_of_both_encodings_read_back() {
        let (v, f) = globe([0.0; 3], 0.5, 6, 8);
        let tris: Vec<stl_io::Triangle> = f
            .iter()
            .map(|t| {
                let p = t.map(|k| v[k]);
                let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
                stl_io::Triangle {
                    normal: stl_io::Vector::new(n.map(|x| x as f32)),
                    vertices: p.map(|q| stl_io::Vector::new(q.map(|x| x as f32))),
                }
            })
            .collect();
        let mut binary = Vec::new();
        stl_io::write_stl(&mut binary, tris.iter()).unwrap();
        let mut ascii = String::from("solid globe\n");
        for t in &tris {
            ascii += "facet normal 0 0 0\nouter loop\n";
            for q in &t.vertices {
                ascii += &format!("vertex {:e} {:e} {:e}\n", q[0], q[1], q[2]);
            }
            ascii += "endloop\nendfacet\n";
        }
        ascii += "endsolid globe\n";
        let read = |bytes: &[u8]| {
            let file = parse(bytes, MeshFormat::Stl).unwrap();
            Mesh::new("globe.stl", &file.vertices, &file.faces).unwrap()
        };
        let (a, b) = (read(&binary), read(ascii.as_bytes()));
        // The f32 coordinates of the file against the f64 mesh.
        let exact = mesh((v, f));
        assert!(close(a.volume(), exact.volume(), 1e-6));
        assert_eq!(a, b);
    }
}

//! Triangle surfaces as walls and as the outline of water (`[[surface]]` and a fill's `mesh`,
//! docs/cases.md "Surfaces"): placing a file's mesh in the case, checking how its edges are
//! shared, the wall particles behind it, the points it encloses and how thin it is.
//!
//! - **Behind.** A surface's faces look at the fluid: the side from which a triangle's corners
//!   run counter-clockwise is in front. A point is behind the surface when it lies against the
//!   angle-weighted pseudonormal at its closest point (Bærentzen & Aanæs 2005), which decides
//!   the side on edges and corners too, and works for an open surface (a channel's lining, a
//!   hillside) as for a closed one (a building). The wall is every lattice point less than
//!   `depth` behind the surface, or on it.
//! - **Inside.** A point is inside when the generalised winding number, the solid angle the
//!   surface subtends over 4π (Jacobson, Kavan & Sorkine-Hornung 2013), is at least ½: 1
//!   inside a closed surface, 0 outside, and still a fair answer for the small holes,
//!   duplicated and overlapping triangles of real-world meshes, where counting crossings fails.
//!   Far groups of triangles count by their dipole (Barill et al. 2018, first order).

use super::triangle::{
    area_vector, closest_point, cross, dot, norm, ray_hit, solid_angle, sub, Point, Triangle,
};
use std::collections::HashMap;

/// A group of triangles counts by its dipole in the winding number beyond this many times
/// its radius.
const DIPOLE_BEYOND: f64 = 3.0;

/// How a file's mesh is placed in the case: scaled about the file's origin, rotated about
/// the x, then the y, then the z axis (fixed axes, right-handed, degrees), then moved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    pub scale: f64,
    pub rotate_deg: [f64; 3],
    pub translate: [f64; 3],
}

impl Default for Placement {
    fn default() -> Placement {
        Placement {
            scale: 1.0,
            rotate_deg: [0.0; 3],
            translate: [0.0; 3],
        }
    }
}

impl Placement {
    pub fn apply(&self, p: Point) -> Point {
        let mut q = p.map(|x| x * self.scale);
        for (axis, deg) in self.rotate_deg.iter().enumerate() {
            if *deg != 0.0 {
                let (s, c) = deg.to_radians().sin_cos();
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                (q[u], q[v]) = (c * q[u] - s * q[v], s * q[u] + c * q[v]);
            }
        }
        [0, 1, 2].map(|a| q[a] + self.translate[a])
    }
}

/// How a mesh's edges are shared. A closed surface has every edge on two triangles that run
/// along it in opposite directions; an open one has edges on one triangle (its rim).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Edges {
    /// Edges of one triangle only, and one of them.
    pub open: usize,
    pub open_example: Option<(Point, Point)>,
    /// Edges of more than two triangles.
    pub crowded: usize,
    pub crowded_example: Option<(Point, Point)>,
    /// Edges whose two triangles run along them the same way: one of the two is flipped.
    pub same_way: usize,
    pub same_way_example: Option<(Point, Point)>,
}

impl Edges {
    /// How the edges of `faces` (indices into `vertices`) are shared; the edges of a
    /// degenerate triangle's collapsed corner are passed over.
    pub fn of(vertices: &[Point], faces: &[[usize; 3]]) -> Edges {
        // Directed edges and how often each occurs, in the order first seen.
        let mut count: HashMap<(usize, usize), u32> = HashMap::new();
        let mut order = Vec::new();
        for f in faces {
            for e in 0..3 {
                let (a, b) = (f[e], f[(e + 1) % 3]);
                if a == b {
                    continue;
                }
                let c = count.entry((a, b)).or_insert(0);
                if *c == 0 {
                    order.push((a, b));
                }
                *c += 1;
            }
        }
        let uses = |a: usize, b: usize| count.get(&(a, b)).copied().unwrap_or(0);
        let mut edges = Edges::default();
        let note = |n: &mut usize, example: &mut Option<(Point, Point)>, a: usize, b: usize| {
            *n += 1;
            example.get_or_insert((vertices[a], vertices[b]));
        };
        for &(a, b) in &order {
            let (along, back) = (uses(a, b), uses(b, a));
            // Each undirected edge once: from its first-seen direction.
            let first = back == 0 || (a, b) < (b, a);
            match along + back {
                1 => note(&mut edges.open, &mut edges.open_example, a, b),
                2 if back == 0 => note(&mut edges.same_way, &mut edges.same_way_example, a, b),
                2 => {}
                _ if first => note(&mut edges.crowded, &mut edges.crowded_example, a, b),
                _ => {}
            }
        }
        edges
    }

    pub fn closed(&self) -> bool {
        self.open == 0 && self.crowded == 0 && self.same_way == 0
    }
}

/// A triangle surface with what finds its triangles near a point quickly.
#[derive(Debug, Clone)]
pub struct Surface {
    tris: Vec<Triangle>,
    /// Each triangle's unit normal, to the front.
    normals: Vec<Point>,
    min: Point,
    max: Point,
    buckets: Buckets,
    clusters: Vec<Cluster>,
}

/// Triangles by the cells of a uniform grid their bounding boxes overlap.
#[derive(Debug, Clone)]
struct Buckets {
    origin: Point,
    cell: f64,
    n: [usize; 3],
    /// Cell k holds `tris[start[k]..start[k + 1]]`.
    start: Vec<u32>,
    tris: Vec<u32>,
}

/// Triangles whose centroids share a cell of a coarse grid, summed for far points.
#[derive(Debug, Clone)]
struct Cluster {
    centre: Point,
    radius: f64,
    area: Point,
    tris: Vec<u32>,
}

impl Surface {
    /// The surface of `faces`; triangles of zero area are left out (they bound nothing).
    /// `None` when none is left.
    pub fn new(vertices: &[Point], faces: &[[usize; 3]]) -> Option<Surface> {
        let tris: Vec<Triangle> = faces
            .iter()
            .map(|f| f.map(|v| vertices[v]))
            .filter(|t| norm(area_vector(t)) > 0.0)
            .collect();
        if tris.is_empty() {
            return None;
        }
        let normals = tris
            .iter()
            .map(|t| {
                let a = area_vector(t);
                a.map(|x| x / norm(a))
            })
            .collect();
        let (mut min, mut max) = ([f64::MAX; 3], [f64::MIN; 3]);
        for p in tris.iter().flatten() {
            for a in 0..3 {
                min[a] = min[a].min(p[a]);
                max[a] = max[a].max(p[a]);
            }
        }
        let side = (tris.len() as f64).cbrt().ceil().clamp(1.0, 128.0);
        let buckets = Buckets::new(&tris, min, max, side);
        let clusters = Cluster::group(&tris, min, max, (side / 2.0).ceil().min(16.0));
        Some(Surface {
            tris,
            normals,
            min,
            max,
            buckets,
            clusters,
        })
    }

    /// The box around the surface.
    pub fn bounds(&self) -> (Point, Point) {
        (self.min, self.max)
    }

    pub fn area(&self) -> f64 {
        self.tris.iter().map(|t| norm(area_vector(t))).sum()
    }

    /// The volume a closed surface encloses: positive when its faces look out, negative when
    /// they look in (a container); the tetrahedra from the box's centre, summed.
    pub fn signed_volume(&self) -> f64 {
        let o = [0, 1, 2].map(|a| 0.5 * (self.min[a] + self.max[a]));
        (self.tris.iter())
            .map(|t| {
                let [a, b, c] = t.map(|q| sub(q, o));
                dot(a, cross(b, c)) / 6.0
            })
            .sum()
    }

    pub fn triangles(&self) -> usize {
        self.tris.len()
    }

    /// The generalised winding number at `p`: 1 inside a closed surface, 0 outside.
    pub fn winding_number(&self, p: Point) -> f64 {
        let mut omega = 0.0;
        for c in &self.clusters {
            let d = sub(c.centre, p);
            let r = norm(d);
            if r > DIPOLE_BEYOND * c.radius {
                omega += dot(c.area, d) / (r * r * r);
            } else {
                omega += (c.tris.iter())
                    .map(|&t| solid_angle(p, &self.tris[t as usize]))
                    .sum::<f64>();
            }
        }
        omega / (4.0 * std::f64::consts::PI)
    }

    /// The distance from `p` to the surface and on which side `p` lies there (the sign of
    /// (p − q)·n, n the angle-weighted pseudonormal at the closest point q: negative
    /// behind), when a triangle is within `reach`.
    pub fn side(&self, p: Point, reach: f64) -> Option<(f64, f64)> {
        let near = self.buckets.near(p, reach);
        let mut best: Option<(f64, Point)> = None;
        let mut found = Vec::with_capacity(near.len());
        for t in near {
            let (q, feature) = closest_point(p, &self.tris[t as usize]);
            let d = norm(sub(p, q));
            if d < reach {
                found.push((t, q, feature));
                if best.is_none_or(|(b, _)| d < b) {
                    best = Some((d, q));
                }
            }
        }
        let (d, q) = best?;
        // The triangles that share the closest point (to rounding) weigh its pseudonormal;
        // one as near elsewhere (across the medial axis of a thin part) does not.
        let tie = 1e-9 * reach;
        let mut pseudonormal = [0.0; 3];
        for &(t, qt, feature) in &found {
            if norm(sub(qt, q)) <= tie {
                let w = feature.angle(&self.tris[t as usize]);
                let n = self.normals[t as usize];
                for a in 0..3 {
                    pseudonormal[a] += w * n[a];
                }
            }
        }
        Some((d, dot(sub(p, q), pseudonormal)))
    }

    /// Whether `p` belongs to the wall of thickness `depth` behind the surface: less than
    /// `depth` behind it, or within `on` of it.
    pub fn behind(&self, p: Point, depth: f64, on: f64) -> bool {
        self.side(p, depth)
            .is_some_and(|(d, s)| d <= on || (d < depth && s < 0.0))
    }

    /// The wall behind the surface on the lattice `origin + (i + ½) dx`: every point less than
    /// `depth` behind it or within 1e-9 dx of it, as lattice indices in ascending order.
    /// `None` when more than `limit` points are near the surface (checked as they are found).
    pub fn wall(&self, origin: Point, dx: f64, depth: f64, limit: usize) -> Option<Vec<[i64; 3]>> {
        let near = self.near_points(origin, dx, depth, limit)?;
        let at = |i: [i64; 3]| [0, 1, 2].map(|a| origin[a] + (i[a] as f64 + 0.5) * dx);
        Some(
            near.into_iter()
                .filter(|&i| self.behind(at(i), depth, 1e-9 * dx))
                .collect(),
        )
    }

    /// The lattice points less than `reach` from some triangle, ascending, once each: each
    /// triangle visits the points between the planes `reach` in front of and behind it.
    fn near_points(
        &self,
        origin: Point,
        dx: f64,
        reach: f64,
        limit: usize,
    ) -> Option<Vec<[i64; 3]>> {
        let index = |x: f64, a: usize, up: bool| {
            let f = (x - origin[a]) / dx - 0.5;
            (if up { f.floor() } else { f.ceil() }) as i64
        };
        let at = |i: i64, a: usize| origin[a] + (i as f64 + 0.5) * dx;
        let mut out: Vec<[i64; 3]> = Vec::new();
        for (tri, n) in self.tris.iter().zip(&self.normals) {
            // Along the axis the normal is nearest to, the points within `reach` of the
            // triangle's plane lie within reach / |n_a| of it.
            let a = (0..3)
                .max_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs()))
                .unwrap_or(2);
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            let lo = |k: usize| tri.iter().map(|q| q[k]).fold(f64::MAX, f64::min) - reach;
            let hi = |k: usize| tri.iter().map(|q| q[k]).fold(f64::MIN, f64::max) + reach;
            let plane = dot(*n, tri[0]);
            let half = reach / n[a].abs();
            for ib in index(lo(b), b, false)..=index(hi(b), b, true) {
                for ic in index(lo(c), c, false)..=index(hi(c), c, true) {
                    let (xb, xc) = (at(ib, b), at(ic, c));
                    let xa = (plane - n[b] * xb - n[c] * xc) / n[a];
                    let first = index((xa - half).max(lo(a)), a, false);
                    let last = index((xa + half).min(hi(a)), a, true);
                    for ia in first..=last {
                        let mut idx = [0; 3];
                        (idx[a], idx[b], idx[c]) = (ia, ib, ic);
                        let p = [0, 1, 2].map(|k| at(idx[k], k));
                        if super::triangle::distance(p, tri) < reach {
                            out.push(idx);
                        }
                    }
                    if out.len() > 4 * limit {
                        // Duplicates go before the count is judged.
                        out.sort_unstable();
                        out.dedup();
                        if out.len() > limit {
                            return None;
                        }
                    }
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        (out.len() <= limit).then_some(out)
    }

    /// The points of the lattice `origin + (i + ½) dx`, `i` from `lo` to `hi`, inside the
    /// surface (winding number ½ or more). Along each line of z the number is computed near
    /// the surface and once for each stretch away from it, where it does not change.
    pub fn inside_points(
        &self,
        origin: Point,
        dx: f64,
        (lo, hi): ([i64; 3], [i64; 3]),
    ) -> Vec<[i64; 3]> {
        let at = |i: [i64; 3]| [0, 1, 2].map(|a| origin[a] + (i[a] as f64 + 0.5) * dx);
        let mut out = Vec::new();
        for i in lo[0]..=hi[0] {
            for j in lo[1]..=hi[1] {
                let mut stretch: Option<bool> = None;
                for k in lo[2]..=hi[2] {
                    let p = at([i, j, k]);
                    let near = self.side(p, dx).is_some();
                    let inside = match (near, stretch) {
                        (false, Some(inside)) => inside,
                        _ => self.winding_number(p) >= 0.5,
                    };
                    stretch = (!near).then_some(inside);
                    if inside {
                        out.push([i, j, k]);
                    }
                }
            }
        }
        out
    }

    /// The thinnest the surface is where its two sides face away from each other within
    /// `within` (a wall, a plate, the sides of a closed building), and where: from each
    /// triangle's centroid a ray goes behind it to the first triangle facing the other way.
    pub fn thinnest(&self, within: f64) -> Option<(f64, Point)> {
        let mut thinnest: Option<(f64, Point)> = None;
        for (t, (tri, n)) in self.tris.iter().zip(&self.normals).enumerate() {
            let centroid = [0, 1, 2].map(|a| (tri[0][a] + tri[1][a] + tri[2][a]) / 3.0);
            let back = n.map(|x| -x);
            let end = [0, 1, 2].map(|a| centroid[a] + within * back[a]);
            for u in self.buckets.along(centroid, end) {
                if u as usize == t || dot(self.normals[u as usize], *n) >= 0.0 {
                    continue;
                }
                if let Some(d) = ray_hit(centroid, back, &self.tris[u as usize]) {
                    if d < within && thinnest.is_none_or(|(b, _)| d < b) {
                        thinnest = Some((d, centroid));
                    }
                }
            }
        }
        thinnest
    }
}

impl Buckets {
    /// A grid of about `side`³ cubic cells over the box `min`–`max`.
    fn new(tris: &[Triangle], min: Point, max: Point, side: f64) -> Buckets {
        let extent = [0, 1, 2].map(|a| max[a] - min[a]);
        let largest = extent
            .iter()
            .copied()
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        let cell = largest / side;
        let n = extent.map(|e| ((e / cell).ceil() as usize).clamp(1, 128));
        let mut buckets = Buckets {
            origin: min,
            cell,
            n,
            start: Vec::new(),
            tris: Vec::new(),
        };
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); n[0] * n[1] * n[2]];
        for (t, tri) in tris.iter().enumerate() {
            let lo = [0, 1, 2].map(|a| tri.iter().map(|p| p[a]).fold(f64::MAX, f64::min));
            let hi = [0, 1, 2].map(|a| tri.iter().map(|p| p[a]).fold(f64::MIN, f64::max));
            for k in buckets.cells(lo, hi) {
                lists[k].push(t as u32);
            }
        }
        buckets.start.push(0);
        for l in lists {
            buckets.tris.extend(l);
            buckets.start.push(buckets.tris.len() as u32);
        }
        buckets
    }

    /// The cells the box `lo`–`hi` overlaps (clamped to the grid).
    fn cells(&self, lo: Point, hi: Point) -> impl Iterator<Item = usize> + '_ {
        let index = |x: f64, a: usize| {
            let f = ((x - self.origin[a]) / self.cell).floor();
            (f.max(0.0) as usize).min(self.n[a] - 1)
        };
        let first = [0, 1, 2].map(|a| index(lo[a], a));
        let last = [0, 1, 2].map(|a| index(hi[a], a));
        let n = self.n;
        (first[2]..=last[2]).flat_map(move |k| {
            (first[1]..=last[1])
                .flat_map(move |j| (first[0]..=last[0]).map(move |i| i + n[0] * (j + n[1] * k)))
        })
    }

    /// Whether the box `lo`–`hi` overlaps the grid's box at all.
    fn overlaps(&self, lo: Point, hi: Point) -> bool {
        (0..3).all(|a| {
            hi[a] >= self.origin[a] && lo[a] <= self.origin[a] + self.n[a] as f64 * self.cell
        })
    }

    fn of(&self, k: usize) -> &[u32] {
        &self.tris[self.start[k] as usize..self.start[k + 1] as usize]
    }

    /// The triangles of the cells within `reach` of `p`, ascending, once each.
    fn near(&self, p: Point, reach: f64) -> Vec<u32> {
        let (lo, hi) = (p.map(|x| x - reach), p.map(|x| x + reach));
        self.in_box(lo, hi)
    }

    /// The triangles of the cells the segment from `a` to `b` passes (those of its box).
    fn along(&self, a: Point, b: Point) -> Vec<u32> {
        let lo = [0, 1, 2].map(|k| a[k].min(b[k]));
        let hi = [0, 1, 2].map(|k| a[k].max(b[k]));
        self.in_box(lo, hi)
    }

    fn in_box(&self, lo: Point, hi: Point) -> Vec<u32> {
        if !self.overlaps(lo, hi) {
            return Vec::new();
        }
        let mut out: Vec<u32> = self
            .cells(lo, hi)
            .flat_map(|k| self.of(k))
            .copied()
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }
}

impl Cluster {
    /// The triangles grouped by the cell of a grid of about `side`³ cells that holds their
    /// centroids.
    fn group(tris: &[Triangle], min: Point, max: Point, side: f64) -> Vec<Cluster> {
        let largest = (0..3).map(|a| max[a] - min[a]).fold(0.0, f64::max);
        let cell = largest.max(f64::MIN_POSITIVE) / side;
        let mut by_cell: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for (t, tri) in tris.iter().enumerate() {
            let key = [0, 1, 2].map(|a| {
                let centroid = (tri[0][a] + tri[1][a] + tri[2][a]) / 3.0;
                ((centroid - min[a]) / cell).floor() as i64
            });
            by_cell.entry(key).or_default().push(t as u32);
        }
        let mut keys: Vec<[i64; 3]> = by_cell.keys().copied().collect();
        keys.sort_unstable();
        keys.into_iter()
            .map(|k| Cluster::of(tris, by_cell.remove(&k).unwrap_or_default()))
            .collect()
    }

    fn of(tris: &[Triangle], members: Vec<u32>) -> Cluster {
        let (mut area, mut weighted, mut total) = ([0.0; 3], [0.0; 3], 0.0);
        for &t in &members {
            let tri = &tris[t as usize];
            let a = area_vector(tri);
            let size = norm(a);
            for k in 0..3 {
                area[k] += a[k];
                weighted[k] += size * (tri[0][k] + tri[1][k] + tri[2][k]) / 3.0;
            }
            total += size;
        }
        let centre = weighted.map(|x| x / total);
        let radius = (members.iter())
            .flat_map(|&t| tris[t as usize])
            .map(|q| norm(sub(q, centre)))
            .fold(0.0, f64::max);
        Cluster {
            centre,
            radius,
            area,
            tris: members,
        }
    }
}

#[cfg(test)]
pub(crate) mod tests;

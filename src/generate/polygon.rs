//! Simple polygons as the shape of a 2D body (a wedge, a hull section): checking the outline,
//! the area's mass properties at uniform density, the particles in layers that follow the
//! outline, which points lie inside it and how far a point is from its outline. Inside means an
//! odd number of edge crossings on the vertical line above the point (the even–odd rule), the
//! lines going through points shifted by a fixed tiny offset as for meshes (`mesh.rs`),
//! so a line does not run exactly through a vertex drawn on round numbers.

use super::aabb::Aabb;

/// What is wrong with an outline: a problem and the index of a vertex or edge to look at.
#[derive(Debug, PartialEq)]
pub(crate) enum PolygonError {
    /// Fewer than three vertices.
    TooFew(usize),
    /// Vertex `at` repeats vertex `of`, the one before it.
    Repeated { at: usize, of: usize },
    /// Edges j and k (from vertex j to j + 1, k to k + 1) cross or overlap.
    Crossing(usize, usize),
    /// The outline encloses no area.
    NoArea,
}

impl std::fmt::Display for PolygonError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PolygonError::TooFew(n) => write!(f, "has {n} vertices; an outline needs at least 3"),
            PolygonError::Repeated { at, of } => {
                write!(
                    f,
                    "repeats vertex {of} at vertex {at} (an edge of length 0)"
                )
            }
            PolygonError::Crossing(j, k) => write!(
                f,
                "is not a simple outline: the edge from vertex {j} crosses or overlaps the edge \
                 from vertex {k}"
            ),
            PolygonError::NoArea => write!(f, "encloses no area"),
        }
    }
}

/// A simple polygon, counter-clockwise, and the area it bounds.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Polygon {
    vertices: Vec<[f64; 2]>,
    bounds: Aabb,
    area: f64,
    centroid: [f64; 2],
    /// ∫ (x − c)(x − c)ᵀ dA about the centroid c, in x–y [m⁴].
    second: [[f64; 2]; 2],
}

impl Polygon {
    /// The polygon through `vertices` in order (either sense; the last joins the first).
    pub(crate) fn new(vertices: &[[f64; 2]]) -> Result<Polygon, PolygonError> {
        let n = vertices.len();
        if n < 3 {
            return Err(PolygonError::TooFew(n));
        }
        if let Some(k) = (0..n).find(|&k| vertices[k] == vertices[(k + n - 1) % n]) {
            return Err(PolygonError::Repeated {
                at: k,
                of: (k + n - 1) % n,
            });
        }
        for j in 0..n {
            // Edges that share a vertex meet there; they must not fold back along each other.
            for k in j + 1..n {
                let adjacent = k == j + 1 || (j == 0 && k == n - 1);
                let (a, b) = (vertices[j], vertices[(j + 1) % n]);
                let (c, d) = (vertices[k], vertices[(k + 1) % n]);
                if meet(a, b, c, d, adjacent) {
                    return Err(PolygonError::Crossing(j, k));
                }
            }
        }
        let mut v = vertices.to_vec();
        // Sums over the triangles (0, a, b) from the first vertex, which keeps the terms small:
        // with D = a × b, A = D/2, ∫r dA = D/6 (a + b), and
        // ∫r rᵀ dA = D/24 (2 a aᵀ + a bᵀ + b aᵀ + 2 b bᵀ).
        let o = v[0];
        let (mut area, mut first, mut second) = (0.0, [0.0; 2], [[0.0; 2]; 2]);
        for k in 0..n {
            let a = [v[k][0] - o[0], v[k][1] - o[1]];
            let b = [v[(k + 1) % n][0] - o[0], v[(k + 1) % n][1] - o[1]];
            let d = a[0] * b[1] - a[1] * b[0];
            area += d / 2.0;
            for i in 0..2 {
                first[i] += d / 6.0 * (a[i] + b[i]);
                for j in 0..2 {
                    second[i][j] += d / 24.0
                        * (2.0 * a[i] * a[j] + a[i] * b[j] + b[i] * a[j] + 2.0 * b[i] * b[j]);
                }
            }
        }
        if !(area.abs() > 0.0 && area.is_finite()) {
            return Err(PolygonError::NoArea);
        }
        // The centroid relative to o, the parallel-axis shift to it, and the sign of a
        // clockwise outline (every sum above changes sign with the sense) taken out.
        let rel = [first[0] / area, first[1] / area];
        for i in 0..2 {
            for j in 0..2 {
                second[i][j] = (second[i][j] - area * rel[i] * rel[j]) * area.signum();
            }
        }
        if area < 0.0 {
            v.reverse();
        }
        let mut bounds = Aabb {
            min: [f64::MAX, f64::MAX, 0.0],
            max: [f64::MIN, f64::MIN, 0.0],
        };
        for p in &v {
            for (a, &x) in p.iter().enumerate() {
                bounds.min[a] = bounds.min[a].min(x);
                bounds.max[a] = bounds.max[a].max(x);
            }
        }
        Ok(Polygon {
            vertices: v,
            bounds,
            area: area.abs(),
            centroid: [o[0] + rel[0], o[1] + rel[1]],
            second,
        })
    }

    pub(crate) fn bounds(&self) -> Aabb {
        self.bounds
    }

    pub(crate) fn area(&self) -> f64 {
        self.area
    }

    pub(crate) fn centroid(&self) -> [f64; 3] {
        [self.centroid[0], self.centroid[1], 0.0]
    }

    /// The inertia tensor about the centroid of a uniform plate of `mass` in the x–y plane
    /// (only its zz term moves a 2D body).
    pub(crate) fn inertia(&self, mass: f64) -> [[f64; 3]; 3] {
        let k = mass / self.area;
        let s = &self.second;
        [
            [k * s[1][1], -k * s[0][1], 0.0],
            [-k * s[1][0], k * s[0][0], 0.0],
            [0.0, 0.0, k * (s[0][0] + s[1][1])],
        ]
    }

    fn edges(&self) -> impl Iterator<Item = ([f64; 2], [f64; 2])> + '_ {
        let n = self.vertices.len();
        (0..n).map(move |k| (self.vertices[k], self.vertices[(k + 1) % n]))
    }

    /// The heights at which the vertical line through x crosses the outline, ascending.
    fn crossings(&self, x: f64) -> Vec<f64> {
        let size =
            (self.bounds.max[0] - self.bounds.min[0]).max(self.bounds.max[1] - self.bounds.min[1]);
        let x = x + crate::generate::mesh::LINE_SHIFT[0] * size;
        let mut y: Vec<f64> = self
            .edges()
            .filter(|(a, b)| (a[0] < x) != (b[0] < x))
            .map(|(a, b)| a[1] + (x - a[0]) / (b[0] - a[0]) * (b[1] - a[1]))
            .collect();
        y.sort_by(f64::total_cmp);
        y
    }

    /// Whether `p` is inside the area.
    pub(crate) fn contains(&self, p: [f64; 3]) -> bool {
        crate::generate::mesh::odd_above(p[1], &self.crossings(p[0]))
    }

    /// The distance from `p` to the outline.
    pub(crate) fn distance(&self, p: [f64; 3]) -> f64 {
        self.edges()
            .map(|(a, b)| {
                let (ab, ap) = ([b[0] - a[0], b[1] - a[1]], [p[0] - a[0], p[1] - a[1]]);
                let s = ((ap[0] * ab[0] + ap[1] * ab[1]) / (ab[0] * ab[0] + ab[1] * ab[1]))
                    .clamp(0.0, 1.0);
                (ap[0] - s * ab[0]).hypot(ap[1] - s * ab[1])
            })
            .fold(f64::MAX, f64::min)
    }

    /// The body's particles: layers that follow the outline, as a circle's rings do (a smooth
    /// surface rather than a lattice's staircase), at depths d = dx/2, 3dx/2, … (those under
    /// `depth` when given, else until nothing fits). Layer d is the outline moved inward by d:
    /// each edge's parallel at d, cut where it meets its neighbour's at a convex corner, and an
    /// arc of radius d about each reflex corner; its points are spaced evenly along it, about
    /// dx apart, from the first corner. Points nearer than d to another part of the outline
    /// (where the layers from two sides meet) are left out. A rectangle whose sides are whole
    /// multiples of dx gets a box body's lattice, ring by ring.
    pub(crate) fn points(&self, dx: f64, depth: Option<f64>) -> Vec<[f64; 3]> {
        let mut out = Vec::new();
        for k in 0.. {
            let d = (k as f64 + 0.5) * dx;
            if depth.is_some_and(|depth| d >= depth) {
                break;
            }
            let pieces = self.layer(d);
            let length: f64 = pieces.iter().map(Piece::length).sum();
            let count = (length / dx).round() as usize;
            let before = out.len();
            let (mut piece, mut start) = (0, 0.0);
            for j in 0..count {
                let mut u = j as f64 * length / count as f64 - start;
                while u > pieces[piece].length() && piece + 1 < pieces.len() {
                    start += pieces[piece].length();
                    u -= pieces[piece].length();
                    piece += 1;
                }
                let q = pieces[piece].at(u);
                let q = [q[0], q[1], 0.0];
                if self.contains(q) && self.distance(q) >= d * (1.0 - 1e-9) {
                    out.push(q);
                }
            }
            if out.len() == before {
                break;
            }
        }
        out
    }

    /// At least as many particles as [`Polygon::points`] makes: the points of every layer
    /// that can hold one, before any is left out. A point d inside has a disc of radius d
    /// inside, so 2d is at most the bounding box's smaller side and π d² at most the area; the
    /// sum stops early once it passes `cap` (a budget it is checked against).
    pub(crate) fn particle_bound(&self, dx: f64, depth: Option<f64>, cap: f64) -> f64 {
        let side =
            (self.bounds.max[0] - self.bounds.min[0]).min(self.bounds.max[1] - self.bounds.min[1]);
        let deepest = (0.5 * side).min((self.area / std::f64::consts::PI).sqrt());
        let deepest = depth.map_or(deepest, |depth| deepest.min(depth));
        let mut total = 0.0;
        for k in 0.. {
            let d = (k as f64 + 0.5) * dx;
            if d > deepest * (1.0 + 1e-9) || total > cap {
                break;
            }
            let length: f64 = self.layer(d).iter().map(Piece::length).sum();
            total += (length / dx).round();
        }
        total
    }

    /// The outline moved inward by `d`, as segments and arcs in order.
    fn layer(&self, d: f64) -> Vec<Piece> {
        let n = self.vertices.len();
        let tangent = |e: usize| {
            let (a, b) = (self.vertices[e % n], self.vertices[(e + 1) % n]);
            let len = (b[0] - a[0]).hypot(b[1] - a[1]);
            ([(b[0] - a[0]) / len, (b[1] - a[1]) / len], len)
        };
        // The turn from edge e to edge e + 1 at their shared corner: > 0 convex (left, the
        // outline being counter-clockwise), < 0 reflex.
        let turn = |e: usize| {
            let ((t, _), (u, _)) = (tangent(e), tangent(e + 1));
            (t[0] * u[1] - t[1] * u[0]).atan2(t[0] * u[0] + t[1] * u[1])
        };
        let mut pieces = Vec::new();
        for e in 0..n {
            let (t, len) = tangent(e);
            let normal = [-t[1], t[0]];
            let a = self.vertices[e];
            let (before, after) = (turn(e + n - 1), turn(e));
            // At a convex corner the parallels meet d tan(turn/2) from the corner's foot.
            let cut = |turn: f64| {
                if turn > 0.0 {
                    d * (0.5 * turn).tan()
                } else {
                    0.0
                }
            };
            let (s0, s1) = (cut(before), len - cut(after));
            if s1 > s0 {
                let at = |s: f64| {
                    [
                        a[0] + d * normal[0] + s * t[0],
                        a[1] + d * normal[1] + s * t[1],
                    ]
                };
                pieces.push(Piece::Segment(at(s0), at(s1)));
            }
            if after < 0.0 {
                pieces.push(Piece::Arc {
                    center: self.vertices[(e + 1) % n],
                    radius: d,
                    from: normal[1].atan2(normal[0]),
                    sweep: after,
                });
            }
        }
        pieces
    }
}

/// A part of a layer: a segment, or an arc of `sweep` radians (negative: clockwise) from the
/// direction `from`.
enum Piece {
    Segment([f64; 2], [f64; 2]),
    Arc {
        center: [f64; 2],
        radius: f64,
        from: f64,
        sweep: f64,
    },
}

impl Piece {
    fn length(&self) -> f64 {
        match *self {
            Piece::Segment(a, b) => (b[0] - a[0]).hypot(b[1] - a[1]),
            Piece::Arc { radius, sweep, .. } => radius * sweep.abs(),
        }
    }

    /// The point `u` along it.
    fn at(&self, u: f64) -> [f64; 2] {
        match *self {
            Piece::Segment(a, b) => {
                let s = u / self.length();
                [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])]
            }
            Piece::Arc {
                center,
                radius,
                from,
                sweep,
            } => {
                let angle = from + sweep.signum() * u / radius;
                [
                    center[0] + radius * angle.cos(),
                    center[1] + radius * angle.sin(),
                ]
            }
        }
    }
}

/// Whether the segments ab and cd share a point; `adjacent` ones (b = c or d = a) only where
/// they fold back along each other.
fn meet(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2], adjacent: bool) -> bool {
    let orient = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    };
    // Whether r, on the line pq, lies within the segment.
    let within = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        (0..2).all(|k| p[k].min(q[k]) <= r[k] && r[k] <= p[k].max(q[k]))
    };
    if adjacent {
        // The shared vertex is fine; the far end of one on the other is a fold.
        let (far_cd, far_ab) = if b == c { (d, a) } else { (c, b) };
        return (orient(a, b, far_cd) == 0.0 && within(a, b, far_cd))
            || (orient(c, d, far_ab) == 0.0 && within(c, d, far_ab));
    }
    let (d1, d2) = (orient(c, d, a), orient(c, d, b));
    let (d3, d4) = (orient(a, b, c), orient(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && within(c, d, a))
        || (d2 == 0.0 && within(c, d, b))
        || (d3 == 0.0 && within(a, b, c))
        || (d4 == 0.0 && within(a, b, d))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * b.abs()
    }

    /// A rectangle: the area, centroid and polar moment m (a² + b²)/12 of a box, in either
    /// sense; its lattice is a box body's.
    #[test]
    fn a_rectangle_is_a_box() {
        let r = [[0.1, 0.2], [0.5, 0.2], [0.5, 0.5], [0.1, 0.5]];
        let mut cw = r;
        cw.reverse();
        for v in [r, cw] {
            let p = Polygon::new(&v).unwrap();
            assert!(close(p.area(), 0.12, 1e-12));
            assert!(close(p.centroid()[0], 0.3, 1e-12) && close(p.centroid()[1], 0.35, 1e-12));
            assert!(close(
                p.inertia(2.0)[2][2],
                2.0 * (0.16 + 0.09) / 12.0,
                1e-12
            ));
            // The box's 4 x 3 cell centres, ring by ring.
            let pts = p.points(0.1, None);
            assert_eq!(pts.len(), 4 * 3);
            for i in 0..4 {
                for j in 0..3 {
                    let want = [0.15 + 0.1 * i as f64, 0.25 + 0.1 * j as f64];
                    assert!(
                        pts.iter()
                            .any(|q| (q[0] - want[0]).hypot(q[1] - want[1]) < 1e-12),
                        "{want:?} missing from {pts:?}"
                    );
                }
            }
            // One layer: all but the middle two.
            assert_eq!(p.points(0.1, Some(0.1)).len(), 10);
            assert_eq!(p.particle_bound(0.1, None, f64::MAX), 12.0);
        }
    }

    /// A right triangle with legs a, b at the origin: A = ab/2, centroid (a/3, b/3), and
    /// I_z = m (a² + b²)/18 about the centroid (textbook); off the bounds' centre.
    #[test]
    fn a_right_triangle_has_its_textbook_mass_properties() {
        let (a, b, o) = (0.3, 0.2, [1.0, -0.5]);
        let p = Polygon::new(&[o, [o[0] + a, o[1]], [o[0], o[1] + b]]).unwrap();
        assert!(close(p.area(), a * b / 2.0, 1e-12));
        assert!(close(p.centroid()[0], o[0] + a / 3.0, 1e-12));
        assert!(close(p.centroid()[1], o[1] + b / 3.0, 1e-12));
        let i = p.inertia(3.0);
        assert!(close(i[2][2], 3.0 * (a * a + b * b) / 18.0, 1e-12));
        // ∫y'² dA = a b³/36, ∫x'y' dA = −a² b²/72.
        assert!(close(
            i[0][0],
            3.0 / (a * b / 2.0) * a * b.powi(3) / 36.0,
            1e-12
        ));
        assert!(close(
            i[0][1],
            3.0 / (a * b / 2.0) * a * a * b * b / 72.0,
            1e-12
        ));
    }

    /// A regular 64-gon: inside and out as the circle it approximates, away from its edge;
    /// its lattice fills its area; a shell lies within its depth of the outline.
    #[test]
    fn a_many_sided_polygon_is_nearly_a_disc() {
        let (c, r) = ([0.3, 0.4], 0.1);
        let v: Vec<[f64; 2]> = (0..64)
            .map(|k| {
                let t = 2.0 * std::f64::consts::PI * k as f64 / 64.0;
                [c[0] + r * t.cos(), c[1] + r * t.sin()]
            })
            .collect();
        let p = Polygon::new(&v).unwrap();
        assert!(close(p.area(), std::f64::consts::PI * r * r, 0.002));
        for k in 0..400 {
            let (t, s) = (0.1 * k as f64, 0.002 * k as f64);
            let q = [c[0] + s * t.cos(), c[1] + s * t.sin(), 0.0];
            if (s - r).abs() > 0.002 * r {
                assert_eq!(p.contains(q), s < r, "{q:?}");
            }
        }
        let dx = 0.005;
        let n = p.points(dx, None).len() as f64;
        assert!(close(n * dx * dx, p.area(), 0.03), "{n}");
        let shell = p.points(dx, Some(2.0 * dx));
        assert!(!shell.is_empty() && shell.len() < n as usize);
        assert!(shell
            .iter()
            .all(|q| p.distance(*q) < 2.0 * dx && p.contains(*q)));
    }

    /// An L (a reflex corner, arcs in its layers) and a 30° wedge (a sharp corner): particles
    /// no closer than a quarter spacing (half in the L), no hole in the area (every point
    /// inside and dx/2 or more from the outline, where particles can be, is within a spacing of
    /// one), and one layer of a shell at dx/2 from the outline.
    #[test]
    fn layers_fill_an_l_and_a_wedge_without_holes_or_crowding() {
        let l = [
            [0.0, 0.0],
            [0.3, 0.0],
            [0.3, 0.1],
            [0.1, 0.1],
            [0.1, 0.3],
            [0.0, 0.3],
        ];
        let t = 15f64.to_radians().tan();
        let wedge = [[0.0, 0.0], [0.2 * t, 0.2], [-0.2 * t, 0.2]];
        let dx = 0.01;
        for (outline, closest) in [(&l[..], 0.5), (&wedge[..], 0.25)] {
            let p = Polygon::new(outline).unwrap();
            let pts = p.points(dx, None);
            let mut least = f64::MAX;
            for (i, a) in pts.iter().enumerate() {
                assert!(p.contains(*a));
                for b in &pts[i + 1..] {
                    least = least.min((a[0] - b[0]).hypot(a[1] - b[1]));
                }
            }
            assert!(least >= closest * dx, "{outline:?}: {least}");
            let b = p.bounds();
            for i in 0..100 {
                for j in 0..100 {
                    let q = [
                        b.min[0] + (i as f64 + 0.5) / 100.0 * (b.max[0] - b.min[0]),
                        b.min[1] + (j as f64 + 0.5) / 100.0 * (b.max[1] - b.min[1]),
                        0.0,
                    ];
                    if p.contains(q) && p.distance(q) >= 0.5 * dx {
                        let near = pts
                            .iter()
                            .map(|a| (a[0] - q[0]).hypot(a[1] - q[1]))
                            .fold(f64::MAX, f64::min);
                        assert!(near < dx, "{outline:?}: a hole at {q:?} ({near})");
                    }
                }
            }
            assert!(
                close(pts.len() as f64 * dx * dx, p.area(), 0.05),
                "{}",
                pts.len()
            );
            let shell = p.points(dx, Some(dx));
            assert!(shell.iter().all(|q| close(p.distance(*q), 0.5 * dx, 1e-9)));
        }
    }

    #[test]
    fn broken_outlines_are_refused() {
        assert_eq!(
            Polygon::new(&[[0.0, 0.0], [1.0, 0.0]]),
            Err(PolygonError::TooFew(2))
        );
        assert_eq!(
            Polygon::new(&[[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
            Err(PolygonError::Repeated { at: 2, of: 1 })
        );
        // The last corner back on the first.
        assert_eq!(
            Polygon::new(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.0, 0.0]]),
            Err(PolygonError::Repeated { at: 0, of: 3 })
        );
        // A bow tie: the edges from vertex 0 and from vertex 2 cross.
        assert_eq!(
            Polygon::new(&[[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]]),
            Err(PolygonError::Crossing(0, 2))
        );
        // A spike folding back along itself.
        assert_eq!(
            Polygon::new(&[[0.0, 0.0], [2.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
            Err(PolygonError::Crossing(0, 1))
        );
        // Three points on a line: the closing edge (from vertex 2) runs back over edge 0.
        assert_eq!(
            Polygon::new(&[[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]),
            Err(PolygonError::Crossing(0, 2))
        );
        for e in [
            PolygonError::TooFew(2),
            PolygonError::Crossing(0, 2),
            PolygonError::NoArea,
        ] {
            assert!(!e.to_string().is_empty());
        }
    }
}

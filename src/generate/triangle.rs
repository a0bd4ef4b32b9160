//! One triangle in space: its closest point to a point (and which of its vertices, edges or
//! face that is), the solid angle it subtends, its area vector and a ray's hit on it. The
//! surfaces (`surface.rs`) and the closed body meshes (`crate::case::mesh`) are made of these.

pub type Point = [f64; 3];
pub type Triangle = [Point; 3];

pub fn sub(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn dot(a: Point, b: Point) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: Point, b: Point) -> Point {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub fn norm(a: Point) -> f64 {
    dot(a, a).sqrt()
}

/// Half the cross product of two edges: the area times the unit normal, which points to the
/// side from which a, b, c run counter-clockwise.
pub fn area_vector([a, b, c]: &Triangle) -> Point {
    cross(sub(*b, *a), sub(*c, *a)).map(|x| 0.5 * x)
}

/// Where on a triangle its closest point to a point lies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Feature {
    Face,
    /// The edge from vertex k to vertex (k + 1) mod 3.
    Edge(usize),
    Vertex(usize),
}

impl Feature {
    /// The angle the triangle spans about its closest point: 2π inside the face, π on an
    /// edge, the interior angle at a vertex. Summing the normals of the triangles nearest to
    /// a point with these weights gives the angle-weighted pseudonormal (Bærentzen & Aanæs
    /// 2005), whose side tells inside from outside at edges and vertices too.
    pub fn angle(self, tri: &Triangle) -> f64 {
        match self {
            Feature::Face => std::f64::consts::TAU,
            Feature::Edge(_) => std::f64::consts::PI,
            Feature::Vertex(k) => {
                let (u, w) = (sub(tri[(k + 1) % 3], tri[k]), sub(tri[(k + 2) % 3], tri[k]));
                (dot(u, w) / (norm(u) * norm(w))).clamp(-1.0, 1.0).acos()
            }
        }
    }
}

/// The closest point of the triangle to `p` and its feature (Ericson, Real-Time Collision
/// Detection, 2005, §5.1.5: the Voronoi regions of the vertices, edges and face).
pub fn closest_point(p: Point, [a, b, c]: &Triangle) -> (Point, Feature) {
    let (ab, ac, ap) = (sub(*b, *a), sub(*c, *a), sub(p, *a));
    let at = |s: f64, t: f64| [0, 1, 2].map(|k| a[k] + s * ab[k] + t * ac[k]);
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (*a, Feature::Vertex(0));
    }
    let bp = sub(p, *b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (*b, Feature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (at(d1 / (d1 - d3), 0.0), Feature::Edge(0));
    }
    let cp = sub(p, *c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (*c, Feature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (at(0.0, d2 / (d2 - d6)), Feature::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (at(1.0 - w, w), Feature::Edge(1));
    }
    let denom = va + vb + vc;
    (at(vb / denom, vc / denom), Feature::Face)
}

/// The distance from `p` to the triangle.
pub fn distance(p: Point, tri: &Triangle) -> f64 {
    norm(sub(p, closest_point(p, tri).0))
}

/// The signed solid angle the triangle subtends at `p`, positive when `p` sees it from
/// behind (against its area vector): Van Oosterom & Strackee (1983), tan(Ω/2) =
/// a·(b × c) / (|a||b||c| + (a·b)|c| + (b·c)|a| + (c·a)|b|) with a, b, c the vertices
/// relative to `p`.
pub fn solid_angle(p: Point, tri: &Triangle) -> f64 {
    let [a, b, c] = tri.map(|q| sub(q, p));
    let (la, lb, lc) = (norm(a), norm(b), norm(c));
    let numerator = dot(a, cross(b, c));
    let denominator = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
    2.0 * numerator.atan2(denominator)
}

/// Where the ray `origin + t dir` (t > 0) meets the triangle, as t: Möller & Trumbore (1997).
pub fn ray_hit(origin: Point, dir: Point, [a, b, c]: &Triangle) -> Option<f64> {
    let (e1, e2) = (sub(*b, *a), sub(*c, *a));
    let pv = cross(dir, e2);
    let det = dot(e1, pv);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let tv = sub(origin, *a);
    let u = dot(tv, pv) / det;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qv = cross(tv, e1);
    let v = dot(dir, qv) / det;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = dot(e2, qv) / det;
    (t > 0.0).then_some(t)
}

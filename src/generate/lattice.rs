//! Particle lattices: fluid blocks, tank walls and obstacles, all with spacing dx and particles
//! at cell centres, `origin + (i + 0.5) dx` for integer i. 2D cases use the x and y axes and
//! put every particle at z = 0.

use super::aabb::Aabb;

/// Largest magnitude an index may take; larger boxes are refused by the particle-count check
/// before any index is used.
const MAX_INDEX: f64 = 1e15;

/// Number of cells of size `dx` that best fill `len`: round(len / dx); may be huge.
pub(crate) fn cells(len: f64, dx: f64) -> f64 {
    (len / dx).round()
}

/// A cell-centred lattice.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Lattice {
    pub origin: [f64; 3],
    pub dx: f64,
    pub dim: usize,
}

impl Lattice {
    pub(crate) fn pos(&self, idx: [i64; 3]) -> [f64; 3] {
        let mut p = [0.0; 3];
        for a in 0..self.dim {
            p[a] = self.origin[a] + (idx[a] as f64 + 0.5) * self.dx;
        }
        p
    }

    /// The inclusive index range of the lattice points inside `b` (with a relative tolerance of
    /// 1e-9 dx), as float indices; `None` when no point is inside.
    pub(crate) fn range_in(&self, b: &Aabb) -> Option<([f64; 3], [f64; 3])> {
        let (mut lo, mut hi) = ([0.0; 3], [0.0; 3]);
        for a in 0..self.dim {
            lo[a] = ((b.min[a] - self.origin[a]) / self.dx - 0.5 - 1e-9).ceil();
            hi[a] = ((b.max[a] - self.origin[a]) / self.dx - 0.5 + 1e-9).floor();
            if hi[a] < lo[a] {
                return None;
            }
            lo[a] = lo[a].clamp(-MAX_INDEX, MAX_INDEX);
            hi[a] = hi[a].clamp(-MAX_INDEX, MAX_INDEX);
        }
        Some((lo, hi))
    }
}

/// Points of a box of `n` cells per axis starting at `min` (n[a] = 1 for the unused axis in 2D).
pub(crate) fn block_points(min: [f64; 3], n: [i64; 3], dx: f64, dim: usize) -> Vec<[f64; 3]> {
    let lat = Lattice {
        origin: min,
        dx,
        dim,
    };
    let mut out = Vec::with_capacity((n[0] * n[1] * n[2]).max(0) as usize);
    for i in 0..n[0] {
        for j in 0..n[1] {
            for k in 0..n[2] {
                out.push(lat.pos([i, j, k]));
            }
        }
    }
    out
}

/// Points of the lattice range `lo..=hi` (float indices from [`Lattice::range_in`]).
pub(crate) fn range_points(
    lat: &Lattice,
    lo: [f64; 3],
    hi: [f64; 3],
) -> impl Iterator<Item = [i64; 3]> {
    let (lo, hi) = (lo.map(|v| v as i64), hi.map(|v| v as i64));
    debug_assert!(lo
        .iter()
        .zip(&hi)
        .skip(lat.dim)
        .all(|(l, h)| *l == 0 && *h == 0));
    (lo[0]..=hi[0]).flat_map(move |i| {
        (lo[1]..=hi[1]).flat_map(move |j| (lo[2]..=hi[2]).map(move |k| [i, j, k]))
    })
}

/// The wall of a tank whose inner box holds `n` cells per axis from the lattice origin:
/// `layers` layers outside the inner box on every side (the lid only when `!open_top`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct TankWall {
    pub n: [i64; 3],
    pub layers: i64,
    pub open_top: bool,
    pub dim: usize,
}

impl TankWall {
    /// Index range (exclusive end) of the outer box along `a`.
    pub(crate) fn outer(&self, a: usize) -> (i64, i64) {
        if a >= self.dim {
            (0, 1)
        } else if a == self.dim - 1 && self.open_top {
            (-self.layers, self.n[a])
        } else {
            (-self.layers, self.n[a] + self.layers)
        }
    }

    pub(crate) fn contains(&self, idx: [i64; 3]) -> bool {
        let in_outer = (0..self.dim).all(|a| {
            let (lo, hi) = self.outer(a);
            lo <= idx[a] && idx[a] < hi
        });
        let in_inner = (0..self.dim).all(|a| 0 <= idx[a] && idx[a] < self.n[a]);
        in_outer && !in_inner
    }

    /// Number of wall particles, as a float (for the size check before building).
    pub(crate) fn count(&self) -> f64 {
        let outer: f64 = (0..self.dim)
            .map(|a| (self.outer(a).1 - self.outer(a).0) as f64)
            .product();
        let inner: f64 = (0..self.dim).map(|a| self.n[a] as f64).product();
        outer - inner
    }

    /// All wall lattice indices, each once. Walks the columns so that the cost is the wall's
    /// size, not the tank's volume.
    pub(crate) fn indices(&self) -> Vec<[i64; 3]> {
        let v = self.dim - 1;
        let (xl, xh) = self.outer(0);
        let (yl, yh) = if v == 2 { self.outer(1) } else { (0, 1) };
        let (zl, zh) = self.outer(v);
        let mut out = Vec::with_capacity(self.count().max(0.0) as usize);
        for i in xl..xh {
            for j in yl..yh {
                let inside = (0..self.n[0]).contains(&i) && (v < 2 || (0..self.n[1]).contains(&j));
                let mut push = |k: i64| {
                    out.push(if v == 2 { [i, j, k] } else { [i, k, 0] });
                };
                if inside {
                    (zl..0).for_each(&mut push);
                    (self.n[v]..zh).for_each(&mut push);
                } else {
                    (zl..zh).for_each(&mut push);
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tank_wall_is_the_outer_box_minus_the_inner_box() {
        for (dim, open_top) in [(2, true), (2, false), (3, true), (3, false)] {
            let w = TankWall {
                n: [4, 3, if dim == 3 { 5 } else { 1 }],
                layers: 2,
                open_top,
                dim,
            };
            let idx = w.indices();
            assert_eq!(idx.len() as f64, w.count());
            let mut sorted = idx.clone();
            sorted.sort();
            sorted.dedup();
            assert_eq!(sorted.len(), idx.len(), "duplicates");
            assert!(idx.iter().all(|&i| w.contains(i)));
            let mut brute = 0;
            for i in -3..10 {
                for j in -3..10 {
                    for k in if dim == 3 { -3..10 } else { 0..1 } {
                        brute += w.contains([i, j, k]) as usize;
                    }
                }
            }
            assert_eq!(brute, idx.len());
        }
    }

    #[test]
    fn lattice_range_inside_a_box() {
        let lat = Lattice {
            origin: [0.0; 3],
            dx: 0.1,
            dim: 2,
        };
        let b = Aabb {
            min: [0.1, 0.0, 0.0],
            max: [0.4, 0.1, 0.0],
        };
        let (lo, hi) = lat.range_in(&b).unwrap();
        assert_eq!((lo[0], hi[0], lo[1], hi[1]), (1.0, 3.0, 0.0, 0.0));
        assert_eq!(range_points(&lat, lo, hi).count(), 3);
        let thin = Aabb {
            min: [0.01, 0.0, 0.0],
            max: [0.04, 0.1, 0.0],
        };
        assert!(lat.range_in(&thin).is_none());
    }
}

//! Water where the place holds it (`[[fill]]`, docs/cases.md "Fills"): the lattice points
//! connected to a seed through open points, as water poured at the seed would reach them,
//! rather than every point of a box. What is open (below the level, not in the ground, a wall
//! or a building) is the caller's to say.

/// A box of lattice indices, `lo` to `hi` inclusive along each axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IndexBox {
    pub lo: [i64; 3],
    pub hi: [i64; 3],
}

impl IndexBox {
    /// The points along each axis.
    pub fn size(&self) -> [u64; 3] {
        [0, 1, 2].map(|a| (self.hi[a] - self.lo[a] + 1).max(0) as u64)
    }

    /// The number of points.
    pub fn points(&self) -> u64 {
        self.size().iter().product()
    }

    pub fn contains(&self, p: [i64; 3]) -> bool {
        (0..3).all(|a| self.lo[a] <= p[a] && p[a] <= self.hi[a])
    }

    /// Every point, in the order x, then y, then z.
    pub fn iter(&self) -> impl Iterator<Item = [i64; 3]> + '_ {
        (0..self.points()).map(|i| self.point(i))
    }

    fn index(&self, p: [i64; 3]) -> u64 {
        let [_, ny, nz] = self.size();
        let r = [0, 1, 2].map(|a| (p[a] - self.lo[a]) as u64);
        (r[0] * ny + r[1]) * nz + r[2]
    }

    fn point(&self, i: u64) -> [i64; 3] {
        let [_, ny, nz] = self.size();
        let r = [i / (ny * nz), (i / nz) % ny, i % nz];
        [0, 1, 2].map(|a| self.lo[a] + r[a] as i64)
    }
}

/// The points of `bound` connected to `seed` by steps to one of the six neighbours through
/// points where `open` holds, `seed` included, in the box's order (x, then y, then z); `None`
/// as soon as they are more than `limit`. `seed` must be open and in the box; the box's points
/// are marked in a bitset (one bit each), so the caller bounds [`IndexBox::points`].
pub fn flood(
    bound: &IndexBox,
    seed: [i64; 3],
    limit: usize,
    open: impl Fn([i64; 3]) -> bool,
) -> Option<Vec<[i64; 3]>> {
    debug_assert!(bound.contains(seed) && open(seed));
    let mut reached = vec![0u64; bound.points().div_ceil(64) as usize];
    let mut mark = |i: u64| {
        let (word, bit) = ((i / 64) as usize, 1u64 << (i % 64));
        let new = reached[word] & bit == 0;
        reached[word] |= bit;
        new
    };
    mark(bound.index(seed));
    let mut stack = vec![seed];
    let mut count = 1usize;
    while let Some(p) = stack.pop() {
        for a in 0..3 {
            for step in [-1, 1] {
                let mut q = p;
                q[a] += step;
                if bound.contains(q) && open(q) && mark(bound.index(q)) {
                    stack.push(q);
                    count += 1;
                    if count > limit {
                        return None;
                    }
                }
            }
        }
    }
    let mut points = Vec::with_capacity(count);
    for (w, word) in reached.iter().enumerate() {
        let mut bits = *word;
        while bits != 0 {
            let i = w as u64 * 64 + u64::from(bits.trailing_zeros());
            points.push(bound.point(i));
            bits &= bits - 1;
        }
    }
    Some(points)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bowl: open points below z = 3 except a wall at x = 4 from z = 0 to 5 that splits the
    /// box in two; a seed west of the wall fills only the west.
    #[test]
    fn the_water_reaches_what_is_connected_and_no_more() {
        let bound = IndexBox {
            lo: [0, 0, 0],
            hi: [9, 2, 5],
        };
        let open = |p: [i64; 3]| p[2] <= 3 && p[0] != 4;
        let west = flood(&bound, [1, 1, 1], 1000, open).unwrap();
        assert_eq!(west.len(), 4 * 3 * 4);
        assert!(west.iter().all(|p| p[0] < 4 && p[2] <= 3));
        assert!(west.windows(2).all(|w| w[0] < w[1]), "in the box's order");
        // An opening in the wall at the bottom joins the two halves.
        let open = |p: [i64; 3]| p[2] <= 3 && !(p[0] == 4 && p[2] > 0);
        assert_eq!(
            flood(&bound, [1, 1, 1], 1000, open).unwrap().len(),
            9 * 3 * 4 + 3
        );
        assert_eq!(flood(&bound, [1, 1, 1], 110, open), None, "over the limit");
    }

    #[test]
    fn indices_go_and_come_back() {
        let b = IndexBox {
            lo: [-3, 2, -1],
            hi: [4, 5, 0],
        };
        for i in 0..b.points() {
            assert_eq!(b.index(b.point(i)), i);
        }
        assert_eq!(b.points(), 8 * 4 * 2);
    }
}

//! Geometry of the neighbour grid and of the position blocks, chosen once per run.
//!
//! Cells are h or the kernel support 2h (with a tiny margin against f32 rounding at cell
//! faces): [`CellEdge`].
//! Positions are stored as f32 offsets inside blocks of `cells_per_block` cells, with block
//! coordinates packed in 11/11/10 bits; the block is as small as the domain allows, so offsets
//! keep ~7 significant digits relative to the block, not to the whole domain. The slot table is
//! a power of two no larger than the particle count's, so memory scales with particles even
//! for an almost empty domain.

use std::ops::Range;

use anyhow::{bail, Result};

use crate::layout::MAX_BLOCK;
use crate::scenario::{CellEdge, Domain, Scenario};

#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    pub origin: [f64; 3],
    pub extent: [f64; 3],
    /// Cell edge per axis: 2h, or on a periodic axis the period divided into whole cells.
    pub cell_size: [f64; 3],
    pub cells: [u32; 3],
    pub cells_per_block: u32,
    /// Block edge per axis as the GPU sees it (f32), used by the host too so both agree.
    pub block_size: [f32; 3],
    pub periodic: [bool; 3],
    pub blocks: [u32; 3],
    /// Hash slots (power of two).
    pub slots: u32,
    /// Cells per kernel support along an axis (1: cells of 2h, 2: cells of h): how many cells
    /// on each side of its own a particle's neighbours can be in.
    pub reach: u32,
    /// The slot of cell (x, y, z) is x + stride[0] y + stride[1] z modulo the slots
    /// ([`Grid::slot_of_cell`]): the cell's linear index, or strides under which no two cells
    /// of a neighbourhood share a slot ([`hash_strides`]).
    pub stride: [u32; 2],
    /// Whether no two cells of any neighbourhood share a slot (on a periodic grid: every
    /// cell has its own slot).
    rows: bool,
}

/// Whether no two cells of a neighbourhood of (2 reach + 1)^d cells share a slot under the
/// strides `a`, `b`: two such cells differ by at most 2 reach along each axis (fewer on a
/// short one), and share a slot when dx + a dy + b dz is a multiple of the slot count.
fn distinct_around(cells: [u32; 3], slots: u64, reach: u32, [a, b]: [u32; 2]) -> bool {
    let most = cells.map(|c| (2 * reach as i64).min(c as i64 - 1));
    (-most[2]..=most[2]).all(|dz| {
        (-most[1]..=most[1]).all(|dy| {
            (-most[0]..=most[0]).all(|dx| {
                let v = dx + a as i64 * dy + b as i64 * dz;
                (dx, dy, dz) == (0, 0, 0) || v.rem_euclid(slots as i64) != 0
            })
        })
    })
}

/// The slots of a table for `cells` cells holding `particles` particles: the smaller of the
/// next powers of two of the two (at least 1 024 for the particles), so that memory follows
/// the particles in an almost empty domain and the cells in a full one.
fn table_slots(cells: u64, particles: usize) -> u64 {
    let particles = (particles.max(1024) as u64).next_power_of_two();
    cells.next_power_of_two().min(particles)
}

/// The strides of the slot hash (`Grid::stride`): the linear index's (gx, gx gy) where no two
/// cells of a neighbourhood share a slot under them (always where there are as many slots as
/// cells), otherwise the first strides from there up that keep the cells of every
/// neighbourhood in distinct slots (searched for y alone, then for z), so that a row of cells
/// along x is consecutive slots and no slot needs visiting twice; `None` if none is found
/// within 4 096 tries each (a table of a few slots).
fn hash_strides(cells: [u32; 3], slots: u64, reach: u32) -> Option<[u32; 2]> {
    let linear = [cells[0], cells[0].wrapping_mul(cells[1])];
    if distinct_around(cells, slots, reach, linear) {
        return Some(linear);
    }
    let flat = [cells[0], cells[1], 1];
    let a = (0..4096)
        .map(|k| linear[0].wrapping_add(k))
        .find(|&a| distinct_around(flat, slots, reach, [a, 0]))?;
    let b0 = a.wrapping_mul(cells[1]);
    (0..4096)
        .map(|k| b0.wrapping_add(k))
        .find(|&b| distinct_around(cells, slots, reach, [a, b]))
        .map(|b| [a, b])
}

impl Grid {
    /// The grid of `sc` (its domain, h, particle count and cell edge).
    pub fn of(sc: &Scenario) -> Result<Self> {
        let ph = &sc.physics;
        let n = sc.particles.len();
        Self::new(&sc.domain, ph.h, ph.dim, n, sc.periodic, ph.cell)
    }

    /// The grid of cells `cell` (by default h where its rows are contiguous, otherwise 2h:
    /// [`Grid::contiguous_rows`]).
    pub fn new(
        domain: &Domain,
        h: f64,
        dim: u32,
        n_particles: usize,
        periodic: [bool; 3],
        cell: Option<CellEdge>,
    ) -> Result<Self> {
        let of = |reach| Self::with_reach(domain, h, dim, n_particles, periodic, reach);
        match cell {
            Some(CellEdge::Support) => of(1),
            Some(CellEdge::Half) => {
                let g = of(2)?;
                if !g.contiguous_rows() {
                    bail!(
                        "particles.cell = \"h\" needs a slot table that keeps the cells \
                         around any cell apart (on a periodic grid, a slot per cell: {} slots \
                         here for {} cells): set particles.cell = \"2h\" (or leave it out)",
                        g.slots,
                        g.cells.iter().map(|&c| c as u64).product::<u64>()
                    );
                }
                Ok(g)
            }
            None => match of(2) {
                Ok(g) if g.contiguous_rows() => Ok(g),
                _ => of(1),
            },
        }
    }

    fn with_reach(
        domain: &Domain,
        h: f64,
        dim: u32,
        n_particles: usize,
        periodic: [bool; 3],
        reach: u32,
    ) -> Result<Self> {
        let support = 2.0 * h * (1.0 + 1e-4);
        let edge = support / reach as f64;
        let mut cell_size = [edge; 3];
        let mut extent = [0.0; 3];
        let mut cells = [1u32; 3];
        for a in 0..dim as usize {
            extent[a] = domain.max[a] - domain.min[a];
            if extent[a].is_nan() || extent[a] <= 0.0 || !extent[a].is_finite() {
                bail!("the domain has no extent along axis {a}");
            }
            let mut n = (extent[a] / edge).ceil();
            if periodic[a] {
                // Whole cells tile the period, so neighbour cells wrap exactly.
                n = (extent[a] / edge).floor();
                // The cells around a cell must be distinct cells (no image counted twice).
                if n < (2 * reach + 1) as f64 {
                    let least = (2 * reach + 1) as f64 * edge;
                    bail!("the periodic axis {a} is {} m long: at least {least:.4} m ({} cells of {edge:.4} m) are needed", extent[a], 2 * reach + 1);
                }
                cell_size[a] = extent[a] / n;
            }
            if n > u32::MAX as f64 / 4.0 {
                bail!("the domain is {n} cells long along axis {a}: too many for the grid");
            }
            cells[a] = (n as u32).max(1);
        }
        if (0..3).any(|a| periodic[a] && a >= dim as usize) {
            bail!("a periodic axis beyond the case's dimension");
        }
        let mut k = 1u32;
        for a in 0..3 {
            k = k.max(cells[a].div_ceil(MAX_BLOCK[a] + 1));
        }
        let blocks = [0, 1, 2].map(|a| cells[a].div_ceil(k));
        let block_size = cell_size.map(|c| (k as f64 * c) as f32);
        let total_cells: u64 = cells.iter().map(|&c| c as u64).product();
        let slots = table_slots(total_cells, n_particles);
        if slots > (1 << 30) {
            bail!("{slots} hash slots needed: too many particles for one GPU");
        }
        let strides = hash_strides(cells, slots, reach);
        // On a periodic grid the cells around a cell wrap, which `hash_strides` does not
        // model; with a slot per cell (the linear index) they are distinct all the same.
        let rows = if periodic.iter().any(|&p| p) {
            slots >= total_cells
        } else {
            strides.is_some()
        };
        let stride = strides.unwrap_or([cells[0], cells[0].wrapping_mul(cells[1])]);
        Ok(Self {
            origin: domain.min,
            extent,
            cell_size,
            cells,
            cells_per_block: k,
            block_size,
            periodic,
            blocks,
            slots: slots as u32,
            reach,
            stride,
            rows,
        })
    }

    /// This grid as a subdomain takes it (a rank of a run over several, `Solver::build`): the
    /// same cells and blocks, its slot table sized as a whole run's is, by the smaller of its
    /// `particles` (its own at the start) and of its cells (the cell layers `layers` along
    /// `axis`: its own and its halo), and the strides searched for that size
    /// ([`hash_strides`]); doubled until its rows are contiguous, never past this grid's.
    ///
    /// The sums keep the whole run's order, bit for bit: along contiguous rows a particle
    /// visits the cells around it row by row, x ascending, whatever slots they have, and a
    /// cell's particles in their (kind, id) order, whichever far cells share their slot (the
    /// distance test rejects those). Without contiguous rows (a periodic grid with a hashed
    /// table) a particle visits slots, whose sharing the table decides, so such a grid is kept
    /// whole, as is a periodic one with rows (it needs a slot per cell).
    pub fn for_subdomain(&self, particles: usize, axis: usize, layers: Range<u32>) -> Grid {
        if !self.rows || self.periodic.iter().any(|&p| p) {
            return self.clone();
        }
        let across: u64 = (0..3)
            .filter(|&a| a != axis)
            .map(|a| self.cells[a] as u64)
            .product();
        let mut slots = table_slots(across * layers.len() as u64, particles);
        while slots < self.slots as u64 {
            if let Some(stride) = hash_strides(self.cells, slots, self.reach) {
                let slots = slots as u32;
                return Grid {
                    slots,
                    stride,
                    ..self.clone()
                };
            }
            slots *= 2;
        }
        self.clone()
    }

    /// Packs a world position into (block, f32 offset); positions outside the domain are
    /// clamped to its edge blocks (the builder keeps particles inside).
    pub fn to_block(&self, p: [f64; 3]) -> ([f32; 3], [u32; 3]) {
        let mut off = [0f32; 3];
        let mut b = [0u32; 3];
        for a in 0..3 {
            let bs = self.block_size[a] as f64;
            let rel = p[a] - self.origin[a];
            let bi = (rel / bs).floor().clamp(0.0, (self.blocks[a] - 1) as f64);
            b[a] = bi as u32;
            off[a] = (rel - bi * bs) as f32;
        }
        (off, b)
    }

    pub fn to_world(&self, off: [f32; 3], b: [u32; 3]) -> [f64; 3] {
        [0, 1, 2].map(|a| self.origin[a] + b[a] as f64 * self.block_size[a] as f64 + off[a] as f64)
    }

    /// Whether no two cells of any neighbourhood (the (2 reach + 1)^d cells around a cell)
    /// share a slot ([`hash_strides`]; on a periodic grid, whether every cell has its own
    /// slot): the cells of a row along x then have consecutive slots (modulo the table's size),
    /// so `neighbour_rows` (shaders/lib/neighbours.wgsl) takes a row as one run of slots (two
    /// where it wraps past the table's end or a periodic x axis) and needs no check for
    /// repeated slots.
    pub fn contiguous_rows(&self) -> bool {
        self.rows
    }

    /// The slot of a world position, as `slot_of_cell(cell_of(..))` computes it on the GPU.
    pub fn slot_of(&self, off: [f32; 3], b: [u32; 3]) -> u32 {
        self.slot_of_cell(self.cell_of(off, b))
    }

    /// The cell of a world position, as `cell_of` in shaders/lib/common.wgsl: a position on the
    /// far face is in the last cell, one at a period's end in cell 0.
    pub fn cell_of(&self, off: [f32; 3], b: [u32; 3]) -> [i64; 3] {
        let k = self.cells_per_block as i64;
        [0, 1, 2].map(|a| {
            let inv = (1.0 / self.cell_size[a]) as f32;
            let local = ((off[a] * inv).floor() as i64).clamp(0, k - 1);
            let c = b[a] as i64 * k + local;
            let n = self.cells[a] as i64;
            if self.periodic[a] {
                c % n
            } else {
                c.min(n - 1)
            }
        })
    }

    /// Where a position of block offset `off` is in its cell (`cell_of`'s cell within the
    /// block), in cells per axis, in f32 as `neighbour_ranges` computes it: 0 ≤ f < 1 but for
    /// rounding.
    pub fn place_in_cell(&self, off: [f32; 3]) -> [f32; 3] {
        let k = (self.cells_per_block - 1) as f32;
        [0, 1, 2].map(|a| {
            let cells = off[a] * (1.0 / self.cell_size[a]) as f32;
            cells - cells.floor().clamp(0.0, k)
        })
    }

    /// The squared distance between two world positions, to the nearest image on periodic
    /// axes (as `rel_pos` in shaders/lib/common.wgsl takes it).
    pub fn distance2(&self, x: [f64; 3], y: [f64; 3]) -> f64 {
        (0..3)
            .map(|a| {
                let d = x[a] - y[a];
                let l = self.extent[a];
                if self.periodic[a] {
                    d - l * (d / l).round()
                } else {
                    d
                }
            })
            .map(|d| d * d)
            .sum()
    }

    /// The hash slot of cell `c` (which may lie outside the grid), as `slot_of_cell` in
    /// shaders/lib/common.wgsl: its linear index in wrapping u32 arithmetic, masked.
    pub fn slot_of_cell(&self, c: [i64; 3]) -> u32 {
        let u = c.map(|x| x as u32);
        let [a, b] = self.stride;
        let key = u[0]
            .wrapping_add(a.wrapping_mul(u[1]))
            .wrapping_add(b.wrapping_mul(u[2]));
        key & (self.slots - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn domain(max: [f64; 3]) -> Domain {
        Domain { min: [0.0; 3], max }
    }

    const TWO_H: Option<CellEdge> = Some(CellEdge::Support);

    #[test]
    fn small_domain_has_one_cell_blocks_and_no_collisions() {
        for cell in [None, TWO_H] {
            let g = Grid::new(&domain([1.0, 0.5, 0.0]), 0.013, 2, 10_000, [false; 3], cell);
            let g = g.unwrap();
            assert_eq!(g.reach, if cell.is_none() { 2 } else { 1 });
            assert_eq!(g.cells_per_block, 1);
            assert_eq!(g.cells[2], 1);
            assert!(g.slots as u64 >= g.cells.iter().map(|&c| c as u64).product::<u64>());
            assert!(g.contiguous_rows());
        }
    }

    /// A periodic grid takes cells of h with rows where every cell has its own slot (10 000
    /// particles: 4 096 slots for 76 × 39 cells of h), otherwise cells of 2h, with rows where
    /// these have a slot each (1 000 particles: 1 024 slots for 38 × 20 cells of 2h), one range
    /// per slot where not (a domain 4 times longer); it refuses cells of h asked for there.
    #[test]
    fn a_periodic_grid_takes_rows_where_each_cell_has_a_slot() {
        let periodic = [true, false, false];
        let g = Grid::new(&domain([1.0, 0.5, 0.0]), 0.013, 2, 10_000, periodic, None);
        let g = g.unwrap();
        assert_eq!((g.reach, g.cells, g.slots), (2, [76, 39, 1], 4096));
        assert!(g.contiguous_rows());
        let g = Grid::new(&domain([1.0, 0.5, 0.0]), 0.013, 2, 1000, periodic, None);
        let g = g.unwrap();
        assert_eq!((g.reach, g.cells, g.slots), (1, [38, 20, 1], 1024));
        assert!(g.contiguous_rows());
        let g = Grid::new(&domain([4.0, 0.5, 0.0]), 0.013, 2, 1000, periodic, None);
        let g = g.unwrap();
        assert_eq!(
            (g.reach, g.slots),
            (1, 1024),
            "a hashed periodic grid takes cells of 2h"
        );
        assert!(!g.contiguous_rows());
        let half = Some(CellEdge::Half);
        let e = Grid::new(&domain([4.0, 0.5, 0.0]), 0.013, 2, 1000, periodic, half);
        assert!(e
            .unwrap_err()
            .to_string()
            .contains("particles.cell = \"2h\""));
    }

    /// Asserts that the cells of `g` around `c` (inside the grid) have distinct slots, each
    /// row's consecutive; the rows that wrap past the table's end.
    fn rows_around(g: &Grid, dim: u32, c: [i64; 3]) -> u32 {
        let r = g.reach as i64;
        let zr = if dim == 3 { r } else { 0 };
        let (mut slots, mut wrapped) = (Vec::new(), 0);
        for dz in -zr..=zr {
            for dy in -r..=r {
                let row: Vec<u32> = (-r..=r)
                    .map(|dx| [c[0] + dx, c[1] + dy, c[2] + dz])
                    .filter(|n| (0..3).all(|a| n[a] >= 0 && n[a] < g.cells[a] as i64))
                    .map(|n| g.slot_of_cell(n))
                    .collect();
                for w in row.windows(2) {
                    assert_eq!(w[1], (w[0] + 1) & (g.slots - 1), "row around {c:?}");
                    wrapped += (w[1] < w[0]) as u32;
                }
                slots.extend(row);
            }
        }
        let n = slots.len();
        slots.sort_unstable();
        slots.dedup();
        assert_eq!(slots.len(), n, "cells around {c:?} share a slot");
        wrapped
    }

    /// A long 2D channel has more cells of h than slots, yet within any neighbourhood no two
    /// cells share a slot and a row's slots follow each other (wrapping at the table's end):
    /// what `neighbour_ranges` relies on.
    #[test]
    fn a_hashed_grid_keeps_its_rows_contiguous() {
        let g = Grid::new(
            &domain([100.0, 1.0, 0.0]),
            0.01,
            2,
            100_000,
            [false; 3],
            None,
        );
        let g = g.unwrap();
        assert_eq!((g.reach, g.cells[0], g.cells[1]), (2, 10_000, 100));
        assert!(g.slots < g.cells[0] * g.cells[1] && g.contiguous_rows());
        let mut wrapped = 0;
        // The cell whose linear index is the slot count is where the table wraps.
        let at_end = [(g.slots % g.cells[0]) as i64, (g.slots / g.cells[0]) as i64];
        for c in [[0, 0], at_end, [1311, 99], [5000, 50], [9999, 99]] {
            wrapped += rows_around(&g, 2, [c[0], c[1], 0]);
        }
        assert!(
            wrapped > 0,
            "no row crossed the table's end: the test tests less"
        );
    }

    #[test]
    fn a_position_past_the_far_face_is_in_the_last_cell() {
        // 5 000 cells along x in blocks of 3: the last block's last cell is beyond the grid,
        // where only a position rounded past the face can fall.
        let g = Grid::new(
            &domain([100.0, 100.0, 10.0]),
            0.01,
            3,
            1000,
            [false; 3],
            TWO_H,
        );
        let g = g.unwrap();
        assert_eq!((g.cells[0], g.cells_per_block), (5000, 3));
        assert!(g.blocks[0] * g.cells_per_block > g.cells[0]);
        let past = [0.999 * g.block_size[0], 0.0, 0.0];
        let last = (g.cells[0] - 1) & (g.slots - 1);
        assert_eq!(g.slot_of(past, [g.blocks[0] - 1, 0, 0]), last);
    }

    #[test]
    fn large_domain_keeps_offsets_small_and_slots_bounded() {
        // A 100 m × 100 m × 10 m flood at dx = 5 mm, h = 2 dx: far more cells of h than slots,
        // and more in a plane, yet rows (under these strides no neighbourhood shares a slot).
        let d = domain([100.0, 100.0, 10.0]);
        let g = Grid::new(&d, 0.01, 3, 1_000_000, [false; 3], None).unwrap();
        assert_eq!(g.reach, 2);
        assert!(g.blocks.iter().zip(MAX_BLOCK).all(|(b, m)| *b <= m + 1));
        assert!(g.block_size[0] < 0.1, "block {:?} m", g.block_size);
        assert_eq!(g.slots, 1 << 20);
        assert!(g.contiguous_rows());
        // f32 resolution of an offset is far below the particle spacing.
        let ulp = g.block_size[0] * f32::EPSILON;
        assert!((ulp as f64) < 1e-6 * 0.005 * 2.0);
    }

    /// On grids whose linear index would put cells of a neighbourhood in one slot, the searched
    /// strides keep every neighbourhood's cells (brute force over cells along the grid) in
    /// distinct slots, its rows in consecutive ones; a few slots cannot, and say so.
    #[test]
    fn searched_strides_keep_every_neighbourhood_apart() {
        let cases = [
            (domain([100.0, 100.0, 10.0]), 3, 1_000_000),
            (domain([8.0, 8.0, 8.0]), 3, 3000),
            (domain([300.0, 20.0, 0.0]), 2, 20_000),
        ];
        let mut searched = 0;
        for (d, dim, n) in cases {
            for cell in [None, TWO_H] {
                let g = Grid::new(&d, 0.01, dim, n, [false; 3], cell).unwrap();
                assert!(g.contiguous_rows(), "{d:?} {cell:?}");
                searched += (g.stride != [g.cells[0], g.cells[0].wrapping_mul(g.cells[1])]) as u32;
                for k in 0..50u32 {
                    let c = [0, 1, 2]
                        .map(|a| ((k * (7919 + 104_729 * a)) % g.cells[a as usize]) as i64);
                    rows_around(&g, dim, c);
                }
            }
        }
        assert!(
            searched > 0,
            "no grid needed its strides searched: the test tests less"
        );
        assert_eq!(hash_strides([100, 100, 100], 4, 2), None);
    }

    /// The codes a rows walk (`neighbour_rows`, the whole (2 reach + 1)^d block) visits around
    /// cell `c` over `cells` (each particle's cell and code word), sorted by slot then code as
    /// the GPU sort orders them, keeping those of the cells around `c` (what the distance test
    /// can keep); and how many it passed over (far cells sharing a visited slot).
    fn rows_walk(g: &Grid, dim: u32, cells: &[([i64; 3], u32)], c: [i64; 3]) -> (Vec<u32>, u32) {
        let mut sorted: Vec<(u32, u32, [i64; 3])> = cells
            .iter()
            .map(|&(cell, code)| (g.slot_of_cell(cell), code, cell))
            .collect();
        sorted.sort_unstable_by_key(|&(s, code, _)| (s, code));
        let r = g.reach as i64;
        let near = |cell: [i64; 3]| (0..3).all(|a| (cell[a] - c[a]).abs() <= r);
        let (mut kept, mut passed) = (Vec::new(), 0);
        let mut visit = |lo: u32, hi: u32| {
            for &(_, code, cell) in sorted.iter().filter(|e| (lo..hi).contains(&e.0)) {
                if near(cell) {
                    kept.push(code);
                } else {
                    passed += 1;
                }
            }
        };
        let zr = if dim == 3 { r } else { 0 };
        for dz in -zr..=zr {
            for dy in -r..=r {
                let (y, z) = (c[1] + dy, c[2] + dz);
                if y < 0 || z < 0 || y >= g.cells[1] as i64 || z >= g.cells[2] as i64 {
                    continue;
                }
                let x0 = (c[0] - r).max(0);
                let x1 = (c[0] + r).min(g.cells[0] as i64 - 1);
                let s0 = g.slot_of_cell([x0, y, z]);
                let s1 = s0 + (x1 - x0 + 1) as u32;
                visit(s0, s1.min(g.slots));
                visit(0, s1.saturating_sub(g.slots));
            }
        }
        (kept, passed)
    }

    /// A subdomain's smaller table (`Grid::for_subdomain`) shares slots between far cells, yet
    /// the walk around every particle visits its neighbours in the whole run's order.
    #[test]
    fn a_subdomains_table_keeps_the_whole_runs_neighbour_order() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = move |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % n) as i64
        };
        let cases = [
            (domain([300.0, 20.0, 0.0]), 2, [600, 400, 1]),
            (domain([100.0, 100.0, 10.0]), 3, [60, 60, 20]),
        ];
        for (d, dim, region) in cases {
            let whole = Grid::new(&d, 0.01, dim, 1_000_000, [false; 3], TWO_H).unwrap();
            let rank = whole.for_subdomain(20_000, 0, 0..whole.cells[0]);
            assert!(rank.contiguous_rows());
            assert!(
                rank.slots < whole.slots / 16,
                "{} {}",
                rank.slots,
                whole.slots
            );
            let cells: Vec<([i64; 3], u32)> = (0..20_000u32)
                .map(|code| (region.map(&mut next), code))
                .collect();
            let mut passed = 0;
            for &(c, _) in cells.iter().step_by(97) {
                let (order, _) = rows_walk(&whole, dim, &cells, c);
                let (rank_order, p) = rows_walk(&rank, dim, &cells, c);
                assert_eq!(order, rank_order, "around {c:?}");
                assert!(!order.is_empty());
                passed += p;
            }
            assert!(passed > 0, "no slot was shared: the test tests less");
        }
    }

    /// A subdomain's table is sized by its particles or by its cells, whichever is fewer, and
    /// is never larger than the whole run's; a periodic grid keeps its table.
    #[test]
    fn a_subdomains_table_follows_its_particles_or_its_cells() {
        let g = Grid::new(
            &domain([10.0, 5.0, 0.0]),
            0.013,
            2,
            100_000,
            [false; 3],
            TWO_H,
        )
        .unwrap();
        assert_eq!((g.cells, g.slots), ([385, 193, 1], 1 << 17));
        let all = 0..g.cells[0];
        assert_eq!(g.for_subdomain(1000, 0, all.clone()).slots, 1024);
        assert_eq!(g.for_subdomain(1_000_000, 0, all.clone()), g);
        // 40 layers of 193 cells: 7 720 cells, 8 192 slots for 50 000 particles.
        let part = g.for_subdomain(50_000, 0, 100..140);
        assert_eq!(part.slots, 8192);
        assert!(part.contiguous_rows());
        let periodic = [true, false, false];
        let g = Grid::new(&domain([4.0, 0.5, 0.0]), 0.013, 2, 100_000, periodic, TWO_H).unwrap();
        assert_eq!(g.for_subdomain(1000, 1, 0..2), g);
    }

    #[test]
    fn block_round_trip_is_precise_anywhere() {
        let g = Grid::new(
            &domain([100.0, 100.0, 10.0]),
            0.01,
            3,
            1000,
            [false; 3],
            None,
        );
        let g = g.unwrap();
        for p in [
            [0.0, 0.0, 0.0],
            [99.99, 50.123456, 9.87654],
            [37.5, 0.001, 4.0],
        ] {
            let (off, b) = g.to_block(p);
            let q = g.to_world(off, b);
            for a in 0..3 {
                assert!((p[a] - q[a]).abs() < 1e-8, "{p:?} -> {q:?}");
            }
        }
    }
}

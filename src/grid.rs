//! Geometry of the neighbour grid and of the position blocks, chosen once per run.
//!
//! Cells are the kernel support 2h (with a tiny margin against f32 rounding at cell faces).
//! Positions are stored as f32 offsets inside blocks of `cells_per_block` cells, with block
//! coordinates packed in 11/11/10 bits; the block is as small as the domain allows, so offsets
//! keep ~7 significant digits relative to the block, not to the whole domain. The slot table is
//! a power of two no larger than the particle count's, so memory scales with particles even
//! for an almost empty domain.

use anyhow::{bail, Result};

use crate::layout::MAX_BLOCK;
use crate::scenario::Domain;

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
}

impl Grid {
    pub fn new(
        domain: &Domain,
        h: f64,
        dim: u32,
        n_particles: usize,
        periodic: [bool; 3],
    ) -> Result<Self> {
        let support = 2.0 * h * (1.0 + 1e-4);
        let mut cell_size = [support; 3];
        let mut extent = [0.0; 3];
        let mut cells = [1u32; 3];
        for a in 0..dim as usize {
            extent[a] = domain.max[a] - domain.min[a];
            if extent[a].is_nan() || extent[a] <= 0.0 || !extent[a].is_finite() {
                bail!("the domain has no extent along axis {a}");
            }
            let mut n = (extent[a] / support).ceil();
            if periodic[a] {
                // Whole cells tile the period, so neighbour cells wrap exactly.
                n = (extent[a] / support).floor();
                if n < 3.0 {
                    bail!("the periodic axis {a} is {} m long: at least 3 kernel supports (3 × 2h = {} m) are needed", extent[a], 3.0 * support);
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
        let slots = total_cells
            .next_power_of_two()
            .min((n_particles.max(1024) as u64).next_power_of_two());
        if slots > (1 << 30) {
            bail!("{slots} hash slots needed: too many particles for one GPU");
        }
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
        })
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

    /// Whether every cell has a slot of its own (its linear index) and no axis is periodic: the
    /// cells of a row along x then have consecutive slots (`neighbour_ranges` in
    /// shaders/lib/neighbours.wgsl).
    pub fn dense(&self) -> bool {
        let total: u64 = self.cells.iter().map(|&c| c as u64).product();
        !self.periodic.iter().any(|&p| p) && total <= self.slots as u64
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

    /// The hash slot of cell `c` (which may lie outside the grid), as `slot_of_cell` in
    /// shaders/lib/common.wgsl: its linear index in wrapping u32 arithmetic, masked.
    pub fn slot_of_cell(&self, c: [i64; 3]) -> u32 {
        let u = c.map(|x| x as u32);
        let lin = u[0].wrapping_add(
            self.cells[0].wrapping_mul(u[1].wrapping_add(self.cells[1].wrapping_mul(u[2]))),
        );
        lin & (self.slots - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn domain(max: [f64; 3]) -> Domain {
        Domain { min: [0.0; 3], max }
    }

    #[test]
    fn small_domain_has_one_cell_blocks_and_no_collisions() {
        let g = Grid::new(&domain([1.0, 0.5, 0.0]), 0.013, 2, 10_000, [false; 3]).unwrap();
        assert_eq!(g.cells_per_block, 1);
        assert_eq!(g.cells[2], 1);
        assert!(g.slots as u64 >= g.cells.iter().map(|&c| c as u64).product::<u64>());
        assert!(g.dense());
        let periodic = Grid::new(
            &domain([1.0, 0.5, 0.0]),
            0.013,
            2,
            10_000,
            [true, false, false],
        );
        assert!(!periodic.unwrap().dense());
    }

    #[test]
    fn a_position_past_the_far_face_is_in_the_last_cell() {
        // 5 000 cells along x in blocks of 3: the last block's last cell is beyond the grid,
        // where only a position rounded past the face can fall.
        let g = Grid::new(&domain([100.0, 100.0, 10.0]), 0.01, 3, 1000, [false; 3]).unwrap();
        assert_eq!((g.cells[0], g.cells_per_block), (5000, 3));
        assert!(g.blocks[0] * g.cells_per_block > g.cells[0]);
        let past = [0.999 * g.block_size[0], 0.0, 0.0];
        let last = (g.cells[0] - 1) & (g.slots - 1);
        assert_eq!(g.slot_of(past, [g.blocks[0] - 1, 0, 0]), last);
    }

    #[test]
    fn large_domain_keeps_offsets_small_and_slots_bounded() {
        // A 100 m × 100 m × 10 m flood at dx = 5 mm, h = 2 dx.
        let g = Grid::new(
            &domain([100.0, 100.0, 10.0]),
            0.01,
            3,
            1_000_000,
            [false; 3],
        )
        .unwrap();
        assert!(g.blocks.iter().zip(MAX_BLOCK).all(|(b, m)| *b <= m + 1));
        assert!(g.block_size[0] < 0.1, "block {:?} m", g.block_size);
        assert_eq!(g.slots, 1 << 20);
        assert!(!g.dense(), "a sparse domain shares slots");
        // f32 resolution of an offset is far below the particle spacing.
        let ulp = g.block_size[0] * f32::EPSILON;
        assert!((ulp as f64) < 1e-6 * 0.005 * 2.0);
    }

    #[test]
    fn block_round_trip_is_precise_anywhere() {
        let g = Grid::new(&domain([100.0, 100.0, 10.0]), 0.01, 3, 1000, [false; 3]).unwrap();
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

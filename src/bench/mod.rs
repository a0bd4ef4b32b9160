//! `wgsph bench`: timing a case's steps ([`measure`]), and its work report: what a step does
//! per particle beside what it costs, the figures that predict a GPU's speed from its
//! bandwidth and show a regression on any adapter.

pub mod traffic;

use std::time::Instant;

use anyhow::{Context, Result};

use crate::gpu::GpuContext;
use crate::grid::Grid;
use crate::layout::KIND_EXCLUDED;
use crate::output::Particles;
use crate::scenario::{Kind, Scenario};
use crate::sph::profile::StageTime;
use crate::sph::Solver;
use traffic::{StepCounts, Traffic};

/// The neighbour search's work in one state of the particles: per particle in the grid, and
/// per fluid particle (whose loop, `fluid_rates`, does the most per neighbour).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeighbourWork {
    /// Particles the neighbour loop tests: those of the cell-list ranges around each.
    pub candidates: f64,
    /// Candidates within the kernel's support 2h (the particle itself included).
    pub neighbours: f64,
    pub fluid_candidates: f64,
    pub fluid_neighbours: f64,
}

/// The candidates and neighbours of `particles` on `grid`, counted on the host as the GPU's
/// `neighbour_rows` (shaders/lib/neighbours.wgsl) visits them: where rows are contiguous
/// the slots of the cells of each row around a particle's cell that its support reaches,
/// inside the grid, otherwise the distinct slots of the 3^d cells around, with every particle
/// a slot holds, or, for a particle whose loop sums the fluid alone (`fluid_only`, by index:
/// a fixed boundary particle's), only the slot's fluid (which the sort puts first; the code word
/// that ends the slot's fluid is not counted). Excluded particles are in no cell.
pub fn neighbour_work(
    grid: &Grid,
    dim: u32,
    h: f64,
    particles: &Particles,
    fluid_only: &[bool],
) -> NeighbourWork {
    let live: Vec<usize> = (0..particles.pos.len())
        .filter(|&i| particles.kind[i] != KIND_EXCLUDED)
        .collect();
    let cells: Vec<([i64; 3], [f32; 3])> = live
        .iter()
        .map(|&i| {
            let (off, b) = grid.to_block(particles.pos[i]);
            (grid.cell_of(off, b), grid.place_in_cell(off))
        })
        .collect();
    // The particles of each slot (indices into `live`).
    let mut by_slot: std::collections::HashMap<u32, Vec<usize>> = Default::default();
    for (k, (c, _)) in cells.iter().enumerate() {
        by_slot.entry(grid.slot_of_cell(*c)).or_default().push(k);
    }
    let support2 = (2.0 * h) * (2.0 * h);
    // (candidates, neighbours, particles) of all and of the fluid.
    let mut all = [0u64; 3];
    let mut fluid = [0u64; 3];
    let is_fluid = |k: usize| particles.kind[live[k]] == Kind::Fluid as u32;
    for (k, (c, f)) in cells.iter().enumerate() {
        let x = particles.pos[live[k]];
        let mut mine = [0u64, 0, 1];
        for slot in slots_around(grid, dim, *c, *f) {
            let Some(list) = by_slot.get(&slot) else {
                continue;
            };
            let tested = list
                .iter()
                .filter(|&&j| !fluid_only[live[k]] || is_fluid(j));
            for &j in tested {
                mine[0] += 1;
                mine[1] += (grid.distance2(x, particles.pos[live[j]]) < support2) as u64;
            }
        }
        for a in 0..3 {
            all[a] += mine[a];
            fluid[a] += if is_fluid(k) { mine[a] } else { 0 };
        }
    }
    let per = |s: [u64; 3], a: usize| s[a] as f64 / s[2].max(1) as f64;
    NeighbourWork {
        candidates: per(all, 0),
        neighbours: per(all, 1),
        fluid_candidates: per(fluid, 0),
        fluid_neighbours: per(fluid, 1),
    }
}

/// The slots whose particles the GPU tests around cell `c` (each once), from a point at `f`
/// in it (`Grid::place_in_cell`).
fn slots_around(grid: &Grid, dim: u32, c: [i64; 3], f: [f32; 3]) -> Vec<u32> {
    let g = grid.cells.map(|n| n as i64);
    let mut slots = Vec::new();
    // A cell's index along each axis, wrapped on a periodic one.
    let wrap = |n: [i64; 3]| -> [i64; 3] {
        [0, 1, 2].map(|a| {
            if grid.periodic[a] {
                n[a].rem_euclid(g[a])
            } else {
                n[a]
            }
        })
    };
    // The same, `None` outside the grid.
    let inside = |n: [i64; 3]| Some(wrap(n)).filter(|w| (0..3).all(|a| (0..g[a]).contains(&w[a])));
    if grid.contiguous_rows() {
        let r = grid.reach as i64;
        let zr = if dim == 3 { r } else { 0 };
        let reach2 = (r * r) as f32;
        for dz in -zr..=zr {
            for dy in -r..=r {
                let gap2 = cell_gap(f[1], dy).powi(2) + cell_gap(f[2], dz).powi(2);
                if gap2 >= reach2 {
                    continue;
                }
                let w = (reach2 - gap2).sqrt();
                let from = ((f[0] - w).floor() as i64).max(-r);
                let to = ((f[0] + w).floor() as i64).min(r);
                let row = (from..=to).filter_map(|dx| inside([c[0] + dx, c[1] + dy, c[2] + dz]));
                slots.extend(row.map(|n| grid.slot_of_cell(n)));
            }
        }
        return slots;
    }
    let zr = if dim == 3 { 1 } else { 0 };
    for dz in -zr..=zr {
        for dy in -1..=1 {
            for dx in -1..=1 {
                let s = grid.slot_of_cell(wrap([c[0] + dx, c[1] + dy, c[2] + dz]));
                if !slots.contains(&s) {
                    slots.push(s);
                }
            }
        }
    }
    slots
}

/// `cell_gap` of shaders/lib/neighbours.wgsl: the distance in cells from `f` in a cell to the
/// cells `d` away.
fn cell_gap(f: f32, d: i64) -> f32 {
    match d {
        0 => 0.0,
        d if d > 0 => (d as f32 - f).max(0.0),
        d => (f - (d + 1) as f32).max(0.0),
    }
}

/// What `wgsph bench` measures: `steps` steps of a case after `warmup`, on one adapter.
#[derive(Clone, Debug)]
pub struct BenchReport {
    pub case: String,
    pub adapter: String,
    pub particles: u64,
    pub steps: u64,
    pub wall_s: f64,
    /// Simulated seconds over the timed steps.
    pub simulated_s: f64,
    pub gpu_bytes: u64,
    pub dispatches_per_step: u64,
    /// The neighbour search's work in the last state.
    pub work: NeighbourWork,
    /// What the traffic estimate counted with: the work, the kinds' shares, the slots.
    pub counts: StepCounts,
    /// Bytes read and written per particle-step by each stage, estimated from the work
    /// (src/bench/traffic.rs).
    pub traffic: Traffic,
    /// Each stage's GPU time over as many steps again, when asked for.
    pub stages: Option<Vec<StageTime>>,
    /// With `[maps]`: the wall time of one flood-map sample, s (the mean of [`MAP_SAMPLES`],
    /// the records read back once after them).
    pub map_sample_s: Option<f64>,
}

/// The flood-map samples [`measure`] times.
pub const MAP_SAMPLES: u32 = 5;

/// The mean wall time of one flood-map sample of `solver`'s present state, s.
fn time_map_samples(solver: &Solver) -> Result<f64> {
    solver.map_cells()?;
    let start = Instant::now();
    for _ in 0..MAP_SAMPLES {
        solver.sample_maps()?;
    }
    solver.map_cells()?;
    Ok(start.elapsed().as_secs_f64() / MAP_SAMPLES as f64)
}

impl BenchReport {
    pub fn particle_steps_per_s(&self) -> f64 {
        self.steps as f64 * self.particles as f64 / self.wall_s
    }

    /// Simulated seconds per wall second: the fair figure between integrators of different
    /// steps (and force evaluations a step).
    pub fn simulated_per_wall(&self) -> f64 {
        self.simulated_s / self.wall_s
    }

    pub fn mean_dt_s(&self) -> f64 {
        self.simulated_s / self.steps.max(1) as f64
    }
}

/// Times `steps` steps of `sc` on `ctx` after `warmup` untimed ones (shader compilation,
/// caches); with `stages`, then each stage's GPU time over `steps` more (needs timestamp
/// queries). `wgsph bench` and the Python package's `bench` print or return this.
pub fn measure(
    ctx: &GpuContext,
    sc: &Scenario,
    steps: u64,
    warmup: u64,
    stages: bool,
) -> Result<BenchReport> {
    let mut solver = Solver::new(ctx, sc).context("setting up the GPU solver")?;
    solver.run_steps(warmup)?;
    let t0 = solver.time();
    let start = Instant::now();
    solver.run_steps(steps)?;
    let wall_s = start.elapsed().as_secs_f64();
    let simulated_s = solver.time() - t0;
    let particles = solver.read_particles()?;
    // Every loop of a fixed boundary particle or inlet sums the fluid alone (interaction.wgsl's
    // `wall_continuity` and `boundary_rates`, ghost.wgsl's `fluid_at`); a body's and a
    // solid's take every kind.
    let fluid_only: Vec<bool> = (particles.kind.iter().zip(&particles.id))
        .map(|(&k, &id)| {
            let fixed = Kind::from_code(k).is_some_and(|k| !k.is_fluid() && !k.is_solid());
            fixed && solver.body_of_id(id).is_none()
        })
        .collect();
    let work = neighbour_work(
        &solver.grid,
        sc.physics.dim,
        sc.physics.h,
        &particles,
        &fluid_only,
    );
    let counts = step_counts(sc, &solver.grid, &particles, work);
    let traffic = Traffic::of_step(&solver.stage_names(), &counts);
    let stages = match stages {
        true => Some(solver.profile_steps(steps)?),
        false => None,
    };
    let map_sample_s = match sc.maps {
        Some(_) => Some(time_map_samples(&solver)?),
        None => None,
    };
    Ok(BenchReport {
        case: sc.name.clone(),
        adapter: ctx.describe(),
        particles: solver.particle_count(),
        steps,
        wall_s,
        simulated_s,
        gpu_bytes: solver.gpu_bytes(),
        dispatches_per_step: solver.dispatches_per_step(),
        work,
        counts,
        traffic,
        stages,
        map_sample_s,
    })
}

/// What the traffic estimate needs of `sc` in the state `particles`, with its `work`.
pub fn step_counts(
    sc: &Scenario,
    grid: &Grid,
    particles: &Particles,
    work: NeighbourWork,
) -> StepCounts {
    let live = particles
        .kind
        .iter()
        .filter(|&&k| k != KIND_EXCLUDED)
        .count();
    let share = |kinds: &[Kind]| {
        let of = |k: u32| kinds.iter().any(|&kind| kind as u32 == k);
        particles.kind.iter().filter(|&&k| of(k)).count() as f64 / live.max(1) as f64
    };
    let density_filter_every = match sc.physics.density_filter {
        crate::scenario::DensityFilter::None => None,
        crate::scenario::DensityFilter::Shepard { every }
        | crate::scenario::DensityFilter::Mls { every } => Some(every),
    };
    StepCounts {
        dim: sc.physics.dim,
        contiguous_rows: grid.contiguous_rows(),
        reach: grid.reach,
        slots_per_particle: (grid.slots as f64 + 3.0) / live.max(1) as f64,
        fluid_fraction: share(&[Kind::Fluid]),
        ghost_fraction: share(&[Kind::GhostNoSlip, Kind::GhostFreeSlip]),
        energy: sc.physics.energy,
        density_filter_every,
        work,
    }
}

/// What `wgsph bench` measures under mpirun: the whole run's figures and each rank's.
#[derive(Clone, Debug)]
pub struct RankedBenchReport {
    pub case: String,
    pub particles: u64,
    pub steps: u64,
    /// The slowest rank's wall time over the timed steps.
    pub wall_s: f64,
    pub simulated_s: f64,
    /// Each rank's part of the timed steps (its adapter named on rank 0 only).
    pub ranks: Vec<crate::ranks::RankSummary>,
}

impl RankedBenchReport {
    /// Particle-steps per second of the whole run.
    pub fn particle_steps_per_s(&self) -> f64 {
        self.steps as f64 * self.particles as f64 / self.wall_s
    }

    /// How much more than the mean the rank with the most own particles holds.
    pub fn imbalance(&self) -> f64 {
        let own: Vec<f64> = self.ranks.iter().map(|r| r.own_particles as f64).collect();
        let mean = own.iter().sum::<f64>() / own.len().max(1) as f64;
        own.iter().fold(0.0f64, |m, &x| m.max(x)) / mean.max(1.0) - 1.0
    }
}

/// Times `steps` steps of `sc` cut into one slab per rank of `ranks`, after `warmup`, on every
/// rank together (each on its `ctx`); every rank returns the same report, but for the
/// adapters' names (rank 0's only).
pub fn measure_ranked(
    ctx: &GpuContext,
    sc: &Scenario,
    steps: u64,
    warmup: u64,
    ranks: &dyn crate::ranks::Ranks,
) -> Result<RankedBenchReport> {
    let slabs = crate::decomposition::slabs_for(sc, ranks.size())?;
    let mut solver =
        Solver::subdomain(ctx, sc, &slabs, ranks).context("setting up the subdomain")?;
    solver.run_steps_ranked(warmup, ranks)?;
    let before = solver.ranked().expect("a subdomain").clone();
    let t0 = solver.time();
    let start = Instant::now();
    solver.run_steps_ranked(steps, ranks)?;
    let wall_s = -ranks.min(-start.elapsed().as_secs_f64());
    let ranks = solver.rank_summaries(&before, &ctx.describe(), ranks)?;
    Ok(RankedBenchReport {
        case: sc.name.clone(),
        particles: sc.particles.len() as u64,
        steps,
        wall_s,
        simulated_s: solver.time() - t0,
        ranks,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::CellEdge;
    use crate::scenario::Domain;

    /// Every particle within the support of another is in a slot `slots_around` visits from
    /// it (the rows cut to the support's reach, as `neighbour_ranges` cuts them), on grids of
    /// cells of h with hashed rows that wrap past the table's end and of cells of 2h, in 2D
    /// and 3D, for particles anywhere in their cells; and the cut rows visit fewer cells.
    #[test]
    fn the_cut_rows_keep_every_neighbour() {
        let mut seed = 12345u64;
        let mut next = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let h = 0.026;
        // (dim, domain edge, particles, the grid's particle count: 1 024 and 4 096 slots, or
        // a slot per cell on the periodic grids, periodic along x and the last axis).
        let periodic = |dim: usize| [true, dim == 2, dim == 3];
        for (dim, edge, n, slots_for, wraps) in [
            (2, 1.3, 3000, 1000, [false; 3]),
            (3, 0.47, 3000, 3000, [false; 3]),
            (2, 1.3, 3000, 4000, periodic(2)),
            (3, 0.47, 3000, 60_000, periodic(3)),
        ] {
            let mut max = [edge; 3];
            if dim == 2 {
                max[2] = 0.0;
            }
            let domain = Domain { min: [0.0; 3], max };
            let pos: Vec<[f64; 3]> = (0..n).map(|_| max.map(|m| m * next())).collect();
            for cell in [None, Some(CellEdge::Support)] {
                let grid = Grid::new(&domain, h, dim, slots_for, wraps, cell).unwrap();
                let hashed = grid.slots < grid.cells.iter().product();
                assert_eq!(grid.reach, if cell.is_none() { 2 } else { 1 });
                assert!(grid.contiguous_rows() || (cell.is_some() && hashed));
                if wraps == [false; 3] {
                    assert_eq!(hashed, cell.is_none(), "{dim}D: hashed rows");
                }
                let placed: Vec<([i64; 3], [f32; 3])> = (pos.iter())
                    .map(|&p| {
                        let (off, b) = grid.to_block(p);
                        (grid.cell_of(off, b), grid.place_in_cell(off))
                    })
                    .collect();
                let mut visited = 0;
                for (i, x) in pos.iter().enumerate() {
                    let (c, f) = placed[i];
                    let slots = slots_around(&grid, dim, c, f);
                    visited += slots.len();
                    for (j, y) in pos.iter().enumerate() {
                        if grid.distance2(*x, *y) < 4.0 * h * h {
                            let slot = grid.slot_of_cell(placed[j].0);
                            assert!(slots.contains(&slot), "{dim}D {cell:?}: {i} misses {j}");
                        }
                    }
                }
                let side = (2 * grid.reach + 1) as f64;
                let full = n as f64 * side.powi(dim as i32);
                println!("{dim}D reach {}: {visited} cells of {full}", grid.reach);
                assert!(
                    (visited as f64) < 0.95 * full,
                    "{dim}D {cell:?}: rows not cut"
                );
            }
        }
    }

    /// A 2D square lattice of spacing dx on a dense grid of cells 2h = 2.6 dx: away from the
    /// edges a particle has the lattice points within 2.6 dx as neighbours (21, itself
    /// included) and its 3 × 3 cells' particles as candidates; an excluded particle counts in
    /// neither.
    #[test]
    fn a_lattice_has_the_neighbours_of_its_spacing() {
        let (dx, h) = (0.01, 0.013);
        let domain = Domain {
            min: [0.0; 3],
            max: [1.0, 1.0, 0.0],
        };
        let n = 100;
        let mut pos = Vec::new();
        for i in 0..n {
            for j in 0..n {
                pos.push([(i as f64 + 0.5) * dx, (j as f64 + 0.5) * dx, 0.0]);
            }
        }
        let count = pos.len();
        let mut p = Particles {
            pos,
            vel: vec![[0.0; 3]; count],
            rho: vec![1000.0; count],
            pressure: vec![0.0; count],
            kind: vec![0; count],
            id: (0..count as u32).collect(),
            energy: None,
            stress: None,
        };
        let grid = Grid::new(&domain, h, 2, count, [false; 3], Some(CellEdge::Support)).unwrap();
        assert!(grid.contiguous_rows());
        let w = neighbour_work(&grid, 2, h, &p, &vec![false; count]);
        // Interior: 21 lattice points within 2.6 dx; the edges have fewer.
        assert!(w.neighbours < 21.0 && w.neighbours > 19.0, "{w:?}");
        assert_eq!(
            (w.fluid_candidates, w.fluid_neighbours),
            (w.candidates, w.neighbours)
        );
        // 3 × 3 cells of (2.6 dx)² hold about 9 × 6.76 particles.
        let cell_area = (2.0 * h * (1.0 + 1e-4) / dx).powi(2);
        assert!(
            w.candidates < 9.0 * cell_area && w.candidates > 0.8 * 9.0 * cell_area,
            "{w:?}"
        );
        p.kind[50 * n + 50] = KIND_EXCLUDED;
        let without = neighbour_work(&grid, 2, h, &p, &vec![false; count]);
        assert!(without.neighbours < w.neighbours);
        // With the left half fixed walls that sum the fluid alone, a wall tests only the fluid
        // of its slots (none, deep in the walls); the fluid's loops are unchanged.
        let wall: Vec<bool> = p.pos.iter().map(|x| x[0] < 0.5).collect();
        p.kind = wall.iter().map(|&w| w as u32).collect();
        let all = neighbour_work(&grid, 2, h, &p, &vec![false; count]);
        let fluid_only = neighbour_work(&grid, 2, h, &p, &wall);
        assert_eq!(
            (fluid_only.fluid_candidates, fluid_only.fluid_neighbours),
            (all.fluid_candidates, all.fluid_neighbours)
        );
        // The walls within 2.6 dx of the fluid: about 3 columns in 50 test fluid.
        assert!(
            fluid_only.candidates < 0.5 * all.candidates + 0.1 * all.fluid_candidates,
            "{fluid_only:?} against {all:?}"
        );
        assert!(fluid_only.candidates > 0.5 * all.fluid_candidates);
    }
}

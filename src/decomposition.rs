//! Domain decomposition of a run over several ranks (issue 32): slabs of the one global cell
//! grid along one axis, cut where they balance the ranks' work, the cell layers each rank sends
//! its neighbours as halo, where a particle that left its slab goes, and when to move the cuts.
//!
//! Every rank keeps the global grid, so a particle's cell, and with it the order the sort gives
//! a cell's particles (by id), does not depend on where the cuts are: a particle sums its
//! neighbours in the same order in a subdomain as in the whole run.

use std::ops::Range;

use anyhow::{bail, Result};
use glam::DVec3;

use crate::grid::Grid;
use crate::scenario::CellEdge;
use crate::scenario::{InletPressure, Kind, Motion, Particle, Probe, ProbeKind, Scenario};

/// Cell layers of halo `sc` needs. Cells are the kernel support 2h, so one layer holds every
/// particle a neighbour's particle reaches. Fixed ghosts (and elastic solid particles, for
/// their interface pressure) take their pressure and velocity from
/// the fluid within a support of them (`fluid_at`) earlier in the same step, so a ghost copy
/// next to the cut needs the fluid one layer further: two layers, of which the outer one's
/// copies (wrong values, read by no own particle) only serve the inner one's. (The density
/// filter, which reads corrected neighbours, swaps them again: `Solver::filter_over_ranks`.)
///
/// An extrapolated inlet buffer (`inlet_pressure`) takes its pressure from the fluid around its
/// mirror image across the inlet's plane, up to twice the buffer's depth away, plus a support:
/// the halo then reaches that far past the layer next to the cut.
pub fn halo_layers(sc: &Scenario) -> u32 {
    let ghosts = [Kind::GhostNoSlip, Kind::GhostFreeSlip];
    let ghost_layers = match sc.particles.iter().any(|p| ghosts.contains(&p.kind)) {
        true => 2,
        false => 1,
    };
    // An elastic solid's interface pressure comes from the fluid around it as a ghost's does.
    let ghost_layers = match sc.solids.is_some() {
        true => 2,
        false => ghost_layers,
    };
    let cell = 2.0 * sc.physics.h;
    let mirror_layers = sc
        .inlets
        .iter()
        .filter(|i| i.pressure == InletPressure::Extrapolated)
        .map(|i| 1 + ((2.0 * i.thickness + cell) / cell).ceil() as u32)
        .max()
        .unwrap_or(1);
    ghost_layers.max(mirror_layers)
}

/// A step's work of a particle that moves (fluid, solid, inlet), the unit of the balance.
pub const MOVING_WEIGHT: f64 = 1.0;

/// A step's work of a boundary particle relative to a moving one: a wall or ghost particle
/// only sums its density rate over the fluid (or is interpolated) and is never integrated.
/// Measured on lavapipe from two ranks' step times against their fluid and boundary particles
/// (dynamic walls, the 3D dam break; docs/performance.md, 2026-12-06), not yet on a GPU.
pub const BOUNDARY_WEIGHT: f64 = 0.15;

/// Move the cuts when the most loaded rank carries this much more than the mean.
pub const REBALANCE_THRESHOLD: f64 = 0.1;

/// A particle's weight in the balance.
pub fn weight(kind: Kind) -> f64 {
    match kind {
        Kind::Fluid | Kind::Solid | Kind::Inlet => MOVING_WEIGHT,
        Kind::Wall
        | Kind::GhostNoSlip
        | Kind::GhostFreeSlip
        | Kind::Repulsive
        | Kind::SolidClamped => BOUNDARY_WEIGHT,
    }
}

/// The axis to cut: the one with the most cells (slabs across it are the thinnest faces for
/// the most ranks). A periodic axis is not cut: its halos would wrap around the period.
pub fn cut_axis(grid: &Grid, dim: u32) -> Result<usize> {
    longest_axis(grid, 0..dim as usize)
        .ok_or_else(|| anyhow::anyhow!("every axis of the case is periodic: no axis to cut"))
}

/// Of `axes`, the one that is not periodic with the most cells (the first of equals).
fn longest_axis(grid: &Grid, axes: Range<usize>) -> Option<usize> {
    axes.filter(|&a| !grid.periodic[a])
        .max_by_key(|&a| (grid.cells[a], std::cmp::Reverse(a)))
}

/// The axis to cut `sc` along on `grid`: [`cut_axis`], but where `sc` has a wave gauge (which
/// reads the cells of a whole vertical line) the longest other axis that is not periodic,
/// if there is one.
pub fn case_cut_axis(sc: &Scenario, grid: &Grid) -> Result<usize> {
    let dim = sc.physics.dim;
    let axis = cut_axis(grid, dim)?;
    let up = dim as usize - 1;
    let gauges = (sc.probes.iter()).any(|p| matches!(p.kind, ProbeKind::Height { .. }));
    if !gauges || axis != up {
        return Ok(axis);
    }
    Ok(longest_axis(grid, 0..up).unwrap_or(axis))
}

/// The weighted particles of each cell layer along `axis`.
pub fn layer_load(grid: &Grid, axis: usize, particles: &[Particle]) -> Vec<f64> {
    let mut load = vec![0.0; grid.cells[axis] as usize];
    for p in particles {
        let (off, b) = grid.to_block(p.pos);
        load[grid.cell_of(off, b)[axis] as usize] += weight(p.kind);
    }
    load
}

/// The grid of a run over several ranks: cells of 2h, also where one run takes cells of h by
/// default (halos, cuts and probes' reach are counted in cell layers one support thick).
pub fn ranks_grid(sc: &Scenario) -> Result<Grid> {
    let ph = &sc.physics;
    if ph.cell == Some(CellEdge::Half) {
        bail!(
            "particles.cell = \"h\": a run over several ranks takes cells of 2h (its halos and \
             cuts are whole cell layers one support thick); set particles.cell = \"2h\" or \
             leave it out"
        );
    }
    let n = sc.particles.len();
    let two_h = Some(CellEdge::Support);
    Grid::new(&sc.domain, ph.h, ph.dim, n, sc.periodic, two_h)
}

/// `sc` cut into `ranks` slabs of its grid (as the solver makes it) along [`case_cut_axis`], balanced
/// over its particles' [`layer_load`], no cut through a probe's [`probe_layers`] (nor within
/// [`PROBE_CLEARANCE`] layers of one on a free body).
pub fn slabs_for(sc: &Scenario, ranks: usize) -> Result<Slabs> {
    let grid = ranks_grid(sc)?;
    let axis = case_cut_axis(sc, &grid)?;
    let mut whole = Vec::new();
    let mut moving = Vec::new();
    for (p, layers) in sc.probes.iter().zip(probe_layers(sc, &grid, axis)?) {
        match (layers, on_free_body(sc, p)) {
            (Some(l), true) => moving.push(widened(l, PROBE_CLEARANCE, grid.cells[axis])),
            (Some(l), false) => whole.push(l),
            (None, _) => {}
        }
    }
    let load = layer_load(&grid, axis, &sc.particles);
    Slabs::balanced_keeping(axis, &load, ranks, halo_layers(sc), whole)?.clear_of_moving(
        &load,
        halo_layers(sc),
        &moving,
    )
}

/// How many cell layers a probe on a free body may move before the run moves the cuts out of
/// its way (`Solver::keep_probes_whole`): more than a step moves it (the CFL condition keeps a
/// step's travel under h, half a layer), so the probe is whole at the end of the step the cuts
/// were looked at before.
pub const PROBE_MARGIN: u32 = 1;

/// How far the cuts are placed from the layers a probe on a free body reads when they move out
/// of its way: more than [`PROBE_MARGIN`], so that they do not move again at the next step.
pub const PROBE_CLEARANCE: u32 = 2;

/// Whether `p` moves with a body that moves freely (and is not a front, which reads no layers):
/// its layers are known only as the run goes.
pub fn on_free_body(sc: &Scenario, p: &Probe) -> bool {
    let free = |b: usize| !matches!(sc.bodies[b].motion, Motion::Prescribed(_));
    p.body.is_some_and(free) && !matches!(p.kind, ProbeKind::Front { .. })
}

/// `layers` and `by` more on each side, within the grid's `count` layers.
pub fn widened(layers: Range<u32>, by: u32, count: u32) -> Range<u32> {
    layers.start.saturating_sub(by)..(layers.end + by).min(count)
}

/// The cell layers along `axis` each of `sc`'s probes reads (`None`: a front, which is a
/// maximum over the fluid and combines over ranks exactly). A probe read within one rank's
/// layers gives that rank the value one whole run gives, so the cuts keep these whole.
///
/// A point probe reads the 3^d cells around its point (probes.wgsl `fluid_sums`), a gauge
/// those around its vertical line, a wall patch the cells of its box (`probe_wall_force`);
/// each range has one layer more on each side against the GPU's f32 rounding of the point.
/// A probe attached to a body of prescribed motion (a moving tank) reads, over the run, the
/// layers of every place the motion takes it to at the probe times: their union. One attached
/// to a free body ([`on_free_body`]): those where it stands at the start (its path is not known
/// before the run; the run moves the cuts out of its way as it goes).
pub fn probe_layers(sc: &Scenario, grid: &Grid, axis: usize) -> Result<Vec<Option<Range<u32>>>> {
    let up = sc.physics.dim as usize - 1;
    sc.probes
        .iter()
        .map(|p| {
            if matches!(p.kind, ProbeKind::Height { .. }) && axis == up {
                bail!(
                    "probe '{}' is a wave gauge, but a run over several ranks can cut this \
                     case only along the vertical (its other axes are periodic): the gauge \
                     would read water on every rank; run it on one rank",
                    p.name
                );
            }
            if matches!(p.kind, ProbeKind::Discharge { .. }) && axis == up && up == 2 {
                bail!(
                    "probe '{}' is a discharge section, as tall as the domain, but a run over \
                     several ranks can cut this case only along the vertical (its other axes \
                     are periodic): the section would have water on every rank; run it on \
                     one rank",
                    p.name
                );
            }
            let Some(b) = p
                .body
                .filter(|_| !matches!(p.kind, ProbeKind::Front { .. }))
            else {
                // A front reads no layers, wherever it stands.
                return Ok(layers_read(p, sc.physics.h, grid, axis));
            };
            let body = &sc.bodies[b];
            let Motion::Prescribed(motion) = &body.motion else {
                return Ok(layers_read(p, sc.physics.h, grid, axis));
            };
            let center0 = DVec3::from_array(body.center);
            let every = sc.time.probe_every_s;
            let times = (0..=(sc.time.end_s / every).ceil() as u64)
                .map(|k| (k as f64 * every).min(sc.time.end_s));
            Ok(times
                .filter_map(|t| {
                    let placed =
                        crate::sph::probes::moved(p, body.center, &motion.pose(center0, t));
                    layers_read(&placed, sc.physics.h, grid, axis)
                })
                .reduce(|a, b| a.start.min(b.start)..a.end.max(b.end)))
        })
        .collect()
}

/// The cell layers along `axis` probe `p` reads where it stands ([`probe_layers`]; `h` the
/// smoothing length).
pub fn layers_read(p: &Probe, h: f64, grid: &Grid, axis: usize) -> Option<Range<u32>> {
    let layers = grid.cells[axis] as i64;
    let layer_of = |x: f64| ((x - grid.origin[axis]) / grid.cell_size[axis]).floor() as i64;
    let span =
        |lo: i64, hi: i64| Some((lo - 1).clamp(0, layers) as u32..(hi + 2).clamp(0, layers) as u32);
    match &p.kind {
        ProbeKind::Pressure { point } => span(layer_of(point[axis]) - 1, layer_of(point[axis]) + 1),
        ProbeKind::Height { base, .. } => span(layer_of(base[axis]) - 1, layer_of(base[axis]) + 1),
        ProbeKind::WallPressure(patch) => {
            let e = patch.radius + 4.0 * h;
            span(
                layer_of(patch.point[axis] - e),
                layer_of(patch.point[axis] + e),
            )
        }
        ProbeKind::Discharge { from, to } => span(
            layer_of(from[axis].min(to[axis]) - 2.0 * h),
            layer_of(from[axis].max(to[axis]) + 2.0 * h),
        ),
        ProbeKind::Front { .. } => None,
    }
}

/// Slabs along one axis of the global grid: rank r owns the cell layers `bounds[r] ..
/// bounds[r + 1]`.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Slabs {
    pub axis: usize,
    bounds: Vec<u32>,
    /// Layer ranges no cut may split (the probes' [`probe_layers`]), also when they move.
    whole: Vec<Range<u32>>,
}

/// What one rank sends one neighbour every step: its particles in these cell layers.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct HaloSend {
    pub to: usize,
    pub layers: Range<u32>,
}

impl Slabs {
    /// Cuts `load` (one entry per cell layer) into `ranks` slabs of as equal a load as whole
    /// layers allow, each at least `min_layers` thick so that a halo of that many layers comes
    /// from the next rank only.
    pub fn balanced(axis: usize, load: &[f64], ranks: usize, min_layers: u32) -> Result<Self> {
        Self::balanced_keeping(axis, load, ranks, min_layers, Vec::new())
    }

    /// As [`Slabs::balanced`], with no cut inside any of the layer ranges `whole` (a cut at a
    /// range's start or end is fine): where the balance would cut one, the nearest allowed
    /// cut in load is taken.
    pub fn balanced_keeping(
        axis: usize,
        load: &[f64],
        ranks: usize,
        min_layers: u32,
        whole: Vec<Range<u32>>,
    ) -> Result<Self> {
        let layers = load.len() as u32;
        if ranks == 0 {
            bail!("no ranks to cut the domain for");
        }
        if (ranks as u64) * (min_layers.max(1) as u64) > layers as u64 {
            bail!(
                "{ranks} ranks need at least {} cell layers along axis {axis} ({} each for the \
                 halo), but the domain has {layers}: use fewer ranks or a finer particles.dx_m",
                ranks as u64 * min_layers.max(1) as u64,
                min_layers.max(1)
            );
        }
        let min_layers = min_layers.max(1);
        let mut prefix = vec![0.0; load.len() + 1];
        for (c, l) in load.iter().enumerate() {
            prefix[c + 1] = prefix[c] + l;
        }
        let total = prefix[load.len()];
        let mut bounds = vec![0u32];
        for k in 1..ranks {
            let lo = bounds[k - 1] + min_layers;
            let hi = layers - (ranks - k) as u32 * min_layers;
            let target = total * k as f64 / ranks as f64;
            // The cut whose prefix is nearest the target, within the thickness limits.
            let mut cut = lo;
            while cut < hi && prefix[cut as usize + 1] <= target {
                cut += 1;
            }
            if cut > lo && target - prefix[cut as usize - 1] < prefix[cut as usize] - target {
                cut -= 1;
            }
            let cut = cut.clamp(lo, hi);
            let allowed = |c: u32| !whole.iter().any(|r| r.start < c && c < r.end);
            let off_target = |c: u32| (prefix[c as usize] - target).abs();
            let nearest_allowed = || {
                (lo..=hi)
                    .filter(|&c| allowed(c))
                    .min_by(|&a, &b| off_target(a).total_cmp(&off_target(b)))
            };
            let Some(cut) = allowed(cut).then_some(cut).or_else(nearest_allowed) else {
                bail!(
                    "no cut between cell layers {lo} and {hi} along axis {axis} leaves every \
                     probe within one rank (a probe is read within one rank's layers): use \
                     fewer ranks, or move the probes apart"
                );
            };
            bounds.push(cut);
        }
        bounds.push(layers);
        Ok(Self {
            axis,
            bounds,
            whole,
        })
    }

    /// These cuts, or where one of them lies inside one of the layer ranges `moving` (the
    /// layers probes on free bodies read now: kept whole now, not remembered), new cuts
    /// balanced over `load` that keep those whole as well as [`Slabs::balanced_keeping`]'s.
    pub fn clear_of_moving(
        self,
        load: &[f64],
        min_layers: u32,
        moving: &[Range<u32>],
    ) -> Result<Self> {
        if !moving.iter().any(|m| self.splits(m)) {
            return Ok(self);
        }
        self.balanced_now(load, min_layers, moving)
    }

    /// Cuts balanced over `load` as [`Slabs::balanced_keeping`] with these cuts' ranges kept
    /// whole and `moving` too, which the result does not remember.
    fn balanced_now(&self, load: &[f64], min_layers: u32, moving: &[Range<u32>]) -> Result<Self> {
        let keep = self.whole.iter().chain(moving).cloned().collect();
        let next = Self::balanced_keeping(self.axis, load, self.ranks(), min_layers, keep)?;
        Ok(Self {
            whole: self.whole.clone(),
            ..next
        })
    }

    /// Whether a cut lies inside `layers` (one at its start or end does not).
    pub fn splits(&self, layers: &Range<u32>) -> bool {
        let inner = &self.bounds[1..self.bounds.len() - 1];
        inner.iter().any(|&b| layers.start < b && b < layers.end)
    }

    pub fn ranks(&self) -> usize {
        self.bounds.len() - 1
    }

    /// The cell layers rank `r` owns.
    pub fn range(&self, r: usize) -> Range<u32> {
        self.bounds[r]..self.bounds[r + 1]
    }

    /// The rank that owns cell layer `layer` (layers past the grid belong to the last rank, as
    /// `Grid::cell_of` clamps positions into the grid).
    pub fn owner(&self, layer: u32) -> usize {
        let inner = &self.bounds[1..self.bounds.len() - 1];
        inner.partition_point(|&b| b <= layer)
    }

    /// The layers rank `r` sends each neighbour: its own within `layers` of their common cut.
    /// With cells of the kernel support, one layer holds every particle a neighbour's particle
    /// can reach.
    pub fn halo_sends(&self, r: usize, layers: u32) -> Vec<HaloSend> {
        let own = self.range(r);
        let mut sends = Vec::new();
        if r > 0 {
            sends.push(HaloSend {
                to: r - 1,
                layers: own.start..(own.start + layers).min(own.end),
            });
        }
        if r + 1 < self.ranks() {
            sends.push(HaloSend {
                to: r + 1,
                layers: own.end.saturating_sub(layers).max(own.start)..own.end,
            });
        }
        sends
    }

    /// Each rank's share of `load`.
    pub fn rank_loads(&self, load: &[f64]) -> Vec<f64> {
        (0..self.ranks())
            .map(|r| {
                let range = self.range(r);
                load[range.start as usize..range.end as usize].iter().sum()
            })
            .collect()
    }

    /// How much more than the mean the most loaded rank carries (0: perfectly balanced).
    pub fn imbalance(&self, load: &[f64]) -> f64 {
        let loads = self.rank_loads(load);
        let mean = loads.iter().sum::<f64>() / loads.len() as f64;
        if mean <= 0.0 {
            return 0.0;
        }
        loads.iter().fold(0.0f64, |m, &l| m.max(l)) / mean - 1.0
    }

    /// New cuts for `load` when the present ones are beyond [`REBALANCE_THRESHOLD`] and the new
    /// ones are better; `None` keeps the present ones. The new ones keep the layer ranges
    /// `moving` whole too (as [`Slabs::clear_of_moving`]).
    pub fn rebalanced(&self, load: &[f64], min_layers: u32, moving: &[Range<u32>]) -> Option<Self> {
        let now = self.imbalance(load);
        if now <= REBALANCE_THRESHOLD {
            return None;
        }
        let next = self.balanced_now(load, min_layers, moving).ok()?;
        (next.imbalance(load) < now && next != *self).then_some(next)
    }
}

/// `n` fluid particles at rest at random places in `grid` (a fixed sequence from `seed`), for
/// brute-force tests of the halos.
#[cfg(test)]
pub(crate) fn random_fluid(grid: &Grid, n: usize, seed: u64) -> Vec<Particle> {
    let mut rng = seed;
    let mut uniform = |scale: f64| {
        rng = rng
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        scale * ((rng >> 11) as f64 / (1u64 << 53) as f64)
    };
    (0..n)
        .map(|_| Particle {
            pos: [0, 1, 2].map(|a| uniform(grid.extent[a])),
            vel: [0.0; 3],
            rho: 1000.0,
            kind: Kind::Fluid,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Domain;

    fn grid(cells: [f64; 3], dim: u32) -> Grid {
        let h = 0.05;
        let support = 2.0 * h * (1.0 + 1e-4);
        let max = cells.map(|c| c * support * 0.99999);
        Grid::new(
            &Domain { min: [0.0; 3], max },
            h,
            dim,
            100_000,
            [false; 3],
            TWO_H,
        )
        .unwrap()
    }

    #[test]
    fn uniform_load_gives_equal_slabs() {
        let s = Slabs::balanced(0, &[1.0; 40], 4, 1).unwrap();
        assert_eq!(
            (0..4).map(|r| s.range(r)).collect::<Vec<_>>(),
            [0..10, 10..20, 20..30, 30..40]
        );
        assert_eq!(s.imbalance(&[1.0; 40]), 0.0);
    }

    #[test]
    fn a_water_column_at_one_end_draws_the_cuts_to_it() {
        // A dam break: 10 layers of water then a dry floor (boundary only).
        let load: Vec<f64> = (0..50).map(|c| if c < 10 { 20.0 } else { 1.0 }).collect();
        let s = Slabs::balanced(0, &load, 2, 1).unwrap();
        assert!(s.range(0).end < 10, "{s:?}");
        assert!(s.imbalance(&load) < 0.1, "{}", s.imbalance(&load));
        let even = Slabs {
            axis: 0,
            bounds: vec![0, 25, 50],
            whole: Vec::new(),
        };
        assert!(even.imbalance(&load) > 0.5);
        assert_eq!(even.rebalanced(&load, 1, &[]).as_ref(), Some(&s));
        assert_eq!(s.rebalanced(&load, 1, &[]), None);
    }

    #[test]
    fn no_cut_splits_a_probes_layers() {
        let load = [1.0; 40];
        // Balanced, the cut would be at 20, inside 17..23: the nearest allowed cut in load.
        let probe = 17..23;
        let s = Slabs::balanced_keeping(0, &load, 2, 1, vec![probe]).unwrap();
        assert!([17, 23].contains(&s.range(0).end), "{s:?}");
        // Moving the cuts keeps the range whole too.
        let mut heavy = load;
        heavy[..10].iter_mut().for_each(|l| *l = 10.0);
        let next = s.rebalanced(&heavy, 1, &[]).expect("imbalanced");
        assert!(next.range(0).end <= 17, "{next:?}");
        assert!(!next.whole.is_empty());
        // A range over every place a cut may go leaves none.
        let everywhere = 0..40;
        let err = Slabs::balanced_keeping(0, &load, 2, 1, vec![everywhere])
            .unwrap_err()
            .to_string();
        assert!(err.contains("leaves every probe within one rank"), "{err}");
    }

    #[test]
    fn slabs_keep_their_minimum_thickness() {
        let mut load = vec![0.0; 12];
        load[0] = 100.0;
        let s = Slabs::balanced(0, &load, 3, 3).unwrap();
        for r in 0..3 {
            assert!(s.range(r).len() >= 3, "{s:?}");
        }
        assert_eq!(s.range(2).end, 12);
        let err = Slabs::balanced(0, &load, 5, 3).unwrap_err().to_string();
        assert!(
            err.contains("5 ranks need at least 15 cell layers"),
            "{err}"
        );
    }

    #[test]
    fn every_layer_has_one_owner() {
        let load: Vec<f64> = (0..37).map(|c| (c % 7) as f64 + 0.5).collect();
        let s = Slabs::balanced(2, &load, 5, 2).unwrap();
        for layer in 0..37 {
            let owners: Vec<usize> = (0..5).filter(|&r| s.range(r).contains(&layer)).collect();
            assert_eq!(owners, [s.owner(layer)], "layer {layer}");
        }
        // Past the grid (a position rounded past the far face): the last rank.
        assert_eq!(s.owner(40), 4);
    }

    /// Every pair of particles within the kernel support owned by different ranks: each is in
    /// a halo the other's rank receives (brute force over random particles).
    #[test]
    fn halos_hold_every_neighbour_across_a_cut() {
        let g = grid([30.0, 8.0, 6.0], 3);
        let axis = cut_axis(&g, 3).unwrap();
        assert_eq!(axis, 0);
        let particles = random_fluid(&g, 3000, 12345);
        let load = layer_load(&g, axis, &particles);
        assert_eq!(load.iter().sum::<f64>(), 3000.0);
        let s = Slabs::balanced(axis, &load, 3, 1).unwrap();
        let layer = |p: &Particle| {
            let (off, b) = g.to_block(p.pos);
            g.cell_of(off, b)[axis] as u32
        };
        let support = 2.0 * 0.05;
        let mut crossing = 0;
        for i in &particles {
            for j in &particles {
                let d2: f64 = (0..3).map(|a| (i.pos[a] - j.pos[a]).powi(2)).sum();
                let (ri, rj) = (s.owner(layer(i)), s.owner(layer(j)));
                if d2 > support * support || ri == rj {
                    continue;
                }
                crossing += 1;
                let sent = s
                    .halo_sends(rj, 1)
                    .into_iter()
                    .any(|h| h.to == ri && h.layers.contains(&layer(j)));
                assert!(
                    sent,
                    "particle at {:?} (rank {rj}) not sent to rank {ri}",
                    j.pos
                );
            }
        }
        assert!(crossing > 0, "no pair across a cut: the test tests nothing");
    }

    const TWO_H: Option<CellEdge> = Some(CellEdge::Support);

    #[test]
    fn a_periodic_axis_is_not_cut() {
        let h = 0.05;
        let g = Grid::new(
            &Domain {
                min: [0.0; 3],
                max: [3.0, 1.0, 0.0],
            },
            h,
            2,
            1000,
            [true, false, false],
            TWO_H,
        )
        .unwrap();
        assert_eq!(cut_axis(&g, 2).unwrap(), 1);
    }

    fn load(case: &str, set: &[&str]) -> Scenario {
        let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        crate::case::load(std::path::Path::new(case), &set).unwrap()
    }

    /// A tank taller than wide is cut along the vertical, but with a wave gauge along x: the
    /// gauge then lies whole on one rank. Where x is periodic, the gauge is refused by name.
    #[test]
    fn a_tall_tank_with_a_wave_gauge_is_cut_across_the_vertical() {
        let text = std::fs::read_to_string("cases/hydrostatic_2d.toml").unwrap();
        let tall = text
            .replace("max_m = [1.0, 0.6]", "max_m = [0.4, 1.2]")
            .replace("max_m = [1.0, 0.5]", "max_m = [0.4, 1.0]")
            .replace("[0.5, 0.05]", "[0.2, 0.05]")
            .replace("[0.5, 0.0]", "[0.2, 0.0]");
        let sc = crate::case::load_str(&tall, "tall.toml", &[]).unwrap();
        let g = ranks_grid(&sc).unwrap();
        assert_eq!(cut_axis(&g, 2).unwrap(), 1);
        assert_eq!(case_cut_axis(&sc, &g).unwrap(), 0);
        let slabs = slabs_for(&sc, 2).unwrap();
        assert_eq!(slabs.axis, 0);
        let gauge = sc.probes.iter().position(|p| p.name == "height").unwrap();
        let layers = probe_layers(&sc, &g, 0).unwrap()[gauge].clone().unwrap();
        assert!((0..2).any(|r| {
            let own = slabs.range(r);
            own.start <= layers.start && layers.end <= own.end
        }));
        let mut sc = sc;
        (sc.periodic, sc.domain.min[0], sc.domain.max[0]) = ([true, false, false], 0.0, 0.4);
        let e = slabs_for(&sc, 2).unwrap_err().to_string();
        assert!(e.contains("probe 'height' is a wave gauge"), "{e}");
    }

    /// A discharge section reads the layers within 2h of it: few across it, all of its length
    /// along it; the cuts of two ranks of the dam break (along the vertical: its tank is taller
    /// than wide) keep a level section across the tank on one rank.
    #[test]
    fn a_discharge_section_reads_the_layers_within_the_support_of_it() {
        let section = "\n[[probe]]\nname = \"Q\"\nkind = \"discharge\"\nfrom_m = [0.55, 0.3]\n\
                       to_m = [0.05, 0.3]\n";
        let text = std::fs::read_to_string("cases/dam_break_2d.toml").unwrap() + section;
        let sc = crate::case::load_str(&text, "q.toml", &[]).unwrap();
        let g = ranks_grid(&sc).unwrap();
        let q = sc.probes.iter().position(|p| p.name == "Q").unwrap();
        let h = sc.physics.h;
        let across = layers_read(&sc.probes[q], h, &g, 1).unwrap();
        let along = layers_read(&sc.probes[q], h, &g, 0).unwrap();
        let layer = |x: f64, a: usize| ((x - g.origin[a]) / g.cell_size[a]).floor() as u32;
        assert!(across.start <= layer(0.3 - 2.0 * h, 1) && layer(0.3 + 2.0 * h, 1) < across.end);
        assert!(
            across.len() as f64 <= 4.0 * h / g.cell_size[1] + 5.0,
            "{across:?}"
        );
        assert!(
            along.start <= layer(0.05, 0) && layer(0.55, 0) < along.end,
            "{along:?}"
        );
        let slabs = slabs_for(&sc, 2).unwrap();
        assert_eq!(slabs.axis, 1);
        assert!((0..2).any(|r| {
            let own = slabs.range(r);
            own.start <= across.start && across.end <= own.end
        }));
    }

    /// A probe on the rolling sloshing tank reads, over the run, the layers of its whole path
    /// (which the cuts then keep whole): more than where it stands at t = 0, and they hold it at
    /// every probe time. One on a free body reads those where it stands at the start.
    #[test]
    fn a_probe_on_a_moving_tank_reads_the_layers_of_its_path() {
        let sc = load("cases/sloshing_2d.toml", &["time.end_s=2.0"]);
        let ph = &sc.physics;
        let g = ranks_grid(&sc).unwrap();
        let axis = cut_axis(&g, ph.dim).unwrap();
        let path = probe_layers(&sc, &g, axis).unwrap();
        let mut wider = 0;
        for (p, layers) in sc.probes.iter().zip(&path) {
            let (Some(b), Some(layers)) = (p.body, layers) else {
                continue;
            };
            let Motion::Prescribed(motion) = &sc.bodies[b].motion else {
                panic!("the tank moves as prescribed");
            };
            let c0 = DVec3::from_array(sc.bodies[b].center);
            let at_start = layers_read(p, ph.h, &g, axis).unwrap();
            wider += (layers.len() > at_start.len()) as u32;
            for k in 0..=200 {
                let t = k as f64 * 0.01;
                let placed = crate::sph::probes::moved(p, sc.bodies[b].center, &motion.pose(c0, t));
                let here = layers_read(&placed, ph.h, &g, axis).unwrap();
                assert!(
                    layers.start <= here.start && here.end <= layers.end,
                    "{}: {here:?} at t = {t} outside {layers:?}",
                    p.name
                );
            }
        }
        assert!(
            wider > 0,
            "no probe moved across a layer: the test tests nothing"
        );
        let mut free = load("cases/floating_box_2d.toml", &[]);
        free.probes[0].body = Some(0);
        assert!(on_free_body(&free, &free.probes[0]));
        let at_start = layers_read(&free.probes[0], free.physics.h, &g, axis);
        assert_eq!(probe_layers(&free, &g, axis).unwrap()[0], at_start);
        // A front on it reads no layers (the ranks take the largest reach).
        free.probes[0].kind = ProbeKind::Front {
            origin: [0.0; 3],
            axis: [1.0, 0.0, 0.0],
            continuous: false,
        };
        assert_eq!(probe_layers(&free, &g, axis).unwrap()[0], None);
        assert!(!on_free_body(&free, &free.probes[0]));
    }
}

//! One rank's part of a run over several ranks (issue 32; docs/scaling.md): the particles of its
//! own cell layers (slabs of the one global grid, `decomposition::Slabs`) first in arrays of
//! [`capacity`], the rest of them excluded; each step swaps its halo and migrants with its
//! neighbours between the predictor and the sort (`Passes::record_to_exchange`,
//! `record_from_exchange`), the ranks agree on the time step and the stop rules, and every
//! [`REBALANCE_EVERY`] steps they may move the cuts (`Solver::rebalance`).
//!
//! The grid and the particle ids are the whole run's, the slot table sized by the rank's own
//! particles (`Grid::for_subdomain`), and the sort orders each slot by code word (kind, then
//! id), so an own particle sums the same neighbours in the same order as in one whole run: the
//! ranks' particles together are bit-identical to it (tests/mpi.rs).

use std::ops::Range;

use anyhow::{bail, ensure, Context, Result};

use super::passes::Passes;
use super::profile::Recorder;
use super::Solver;
use super::{bodies, halo};
use crate::decomposition::{
    layers_read, on_free_body, probe_layers, widened, Slabs, PROBE_CLEARANCE, PROBE_MARGIN,
};
use crate::gpu::GpuContext;
use crate::grid::Grid;
use crate::layout::Packed;
use crate::layout::{unpack_block, HaloCtl, IdSplit, Pos, KIND_EXCLUDED, KIND_SHIFT};
use crate::ranks::Ranks;
use crate::ranks::{RankSummary, Split};
use crate::scenario::{Kind, Scenario};

/// A subdomain's counts, over all ranks where they say so (a checkpoint keeps them).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Ranked {
    /// Live particles of the whole run at the start.
    live_at_start: u64,
    /// Particles of the whole run that left the domain or became non-finite.
    pub(super) excluded: u64,
    /// Fluid particles of the whole run the outlets removed (each rank's GPU counts its own).
    pub(super) drained: u64,
    /// Inlet particles of the whole run that joined, less those a level made wait again (each
    /// rank's GPU counts its own).
    #[serde(default)]
    pub(super) joined: i64,
    /// Where the first step unpacks (no sort has run yet): after the own particles.
    first_tail: Option<u32>,
    /// This rank's totals: halo copies and migrants sent, and their bytes.
    pub halo_sent: u64,
    pub migrants_sent: u64,
    pub bytes_sent: u64,
    /// This rank's own particles at the last packing.
    pub owned: u32,
    /// This rank's wall time in each part of its steps, summed: [`Split`].
    pub split: Split,
    /// Steps taken, those that overlapped the exchange, and of them those whose exchange
    /// ended while the interior's sums were still running (the exchange wholly hidden behind
    /// them; `Solver::ranked_step`).
    #[serde(default)]
    pub exchanges: u64,
    #[serde(default)]
    pub overlapped: u64,
    #[serde(default)]
    pub hidden: u64,
    /// The present cuts (set once the subdomain is made), and how often they moved.
    pub slabs: Option<Slabs>,
    pub rebalances: u32,
    /// The most rounds one move of the cuts took (`Solver::redistribute`: more than one where
    /// a cut moved past a neighbour's slab).
    #[serde(default)]
    pub moving_rounds: u32,
    /// The whole run's steps when these counts were taken.
    pub steps: u64,
    /// The cell layers each probe reads (`decomposition::probe_layers`; none for fronts): the
    /// rank that owns them samples it.
    pub(super) probe_layers: Vec<Option<Range<u32>>>,
    /// The probes on free bodies (`decomposition::on_free_body`): their layers are those where
    /// they stand, which the cuts keep whole as they go (`Solver::keep_probes_whole`).
    #[serde(skip)]
    pub(super) moving_probes: Vec<usize>,
}

/// What an overlapped step's GPU does while the host swaps (`Solver::submit_interior`):
/// whether the interior's sums are done.
struct Interior {
    summed: std::sync::Arc<std::sync::atomic::AtomicBool>,
}

/// Steps between two looks at the ranks' balance (`Solver::rebalance`).
pub const REBALANCE_EVERY: u64 = 100;

impl Ranked {
    /// A subdomain of a run of `live` particles, with `own` of them first in its arrays and
    /// then `waiting` inlet particles.
    pub(super) fn new(live: u64, own: u32, waiting: u32) -> Self {
        Self {
            live_at_start: live,
            first_tail: Some(own + waiting),
            ..Default::default()
        }
    }
}

/// The particles a subdomain's arrays hold: its own at the start twice over (its halo, the
/// water that flows in before the cuts move, and the entries the last step's halo copies
/// still take until the next sort), with room for a small slab's halo; never more than twice
/// the whole run's `n` (a rank that owns almost everything still takes its halo and
/// migrants); and the `waiting` inlet particles it holds. A rank that receives more than fits
/// stops with a message saying so.
pub fn capacity(own: u32, waiting: u32, n: u32) -> u32 {
    own.saturating_mul(2)
        .saturating_add(4096)
        .min(n.saturating_mul(2))
        .saturating_add(waiting)
}

/// The cell layer along `axis` of a particle at `p` (`layer_of` in shaders/halo.wgsl).
fn layer_of(grid: &Grid, axis: usize, p: Pos) -> i64 {
    grid.cell_of(p.off, unpack_block(p.block))[axis]
}

/// The records a subdomain's packing buffer starts with: twice the halo copies the first
/// `own` entries of `packed` (its own particles at the start) make, each own particle within
/// `ctl`'s halo layers of a cut with a neighbour one copy (a solid particle two: its stress
/// state follows), and 64 more. The packing grows it when a step packs more
/// (`Halo::reserve`: water reaching a cut, cuts moving), up to one binding.
pub fn starting_records(packed: &Packed, own: u32, grid: &Grid, ctl: &HaloCtl) -> u32 {
    let axis = ctl.axis as usize;
    let copies: u64 = (0..own as usize)
        .map(|k| {
            let layer = layer_of(grid, axis, packed.pos[k]) as u32;
            let below = ctl.lower != 0 && layer < ctl.own_lo + ctl.layers;
            let above = ctl.upper != 0 && layer + ctl.layers >= ctl.own_hi;
            let solid = Kind::from_code(packed.code[k] >> KIND_SHIFT).is_some_and(Kind::is_solid);
            (below as u64 + above as u64) * (1 + solid as u64)
        })
        .sum();
    (2 * copies + 64).min(u32::MAX as u64) as u32
}

/// The cell layers `ctl`'s subdomain holds particles of at the start: its own and its halo
/// layers on each side, within the grid (what its slot table is sized by, with its particles:
/// `Grid::for_subdomain`).
pub fn window(ctl: &HaloCtl, grid: &Grid) -> Range<u32> {
    widened(
        ctl.own_lo..ctl.own_hi,
        ctl.layers,
        grid.cells[ctl.axis as usize],
    )
}

/// Which entries of `packed` are `ctl`'s subdomain's at the start: its own live particles, and
/// the inlet particles waiting behind their buffers (`Inlet::dormant`, the only excluded ones
/// at the start) whose place, where they will join at the back of the buffer, lies in its own
/// layers (a rank holds a waiting particle until `inlet_flow` wakes it there, and the cuts
/// move it as they move: `Solver::redistribute`). The own come first, then the waiting; every
/// other entry is free: excluded, its id the free one (the sort puts free entries after the
/// waiting ones, which keep theirs). Returns (own, waiting).
pub fn exclude_others(packed: &mut Packed, grid: &Grid, ctl: &HaloCtl) -> (u32, u32) {
    let axis = ctl.axis as usize;
    let held: Vec<bool> = (packed.pos.iter())
        .map(|&p| {
            let layer = layer_of(grid, axis, p).clamp(0, grid.cells[axis] as i64 - 1) as u32;
            (ctl.own_lo..ctl.own_hi).contains(&layer)
        })
        .collect();
    let excluded = |k: usize| packed.code[k] >> KIND_SHIFT == KIND_EXCLUDED;
    let n = held.len();
    let first: Vec<usize> = (0..n).filter(|&k| held[k] && !excluded(k)).collect();
    let waiting: Vec<usize> = (0..n).filter(|&k| held[k] && excluded(k)).collect();
    let free = (0..n).filter(|&k| !held[k]);
    let order: Vec<usize> = first.iter().chain(&waiting).copied().chain(free).collect();
    let kept = first.len() + waiting.len();
    packed.pos = order.iter().map(|&k| packed.pos[k]).collect();
    packed.velrho = order.iter().map(|&k| packed.velrho[k]).collect();
    let free = free_code(packed.ids);
    packed.code = order
        .iter()
        .enumerate()
        .map(|(at, &k)| match at < kept {
            true => packed.code[k],
            false => free,
        })
        .collect();
    let free_id = packed.ids.free_id();
    packed.id = (order.iter().enumerate())
        .map(|(at, &k)| if at < kept { packed.id[k] } else { free_id })
        .collect();
    (first.len() as u32, waiting.len() as u32)
}

/// The code word of a free entry of a subdomain's arrays: excluded, of the free id
/// (`IdSplit::free_id`), the largest, so that the sort puts the free entries last in the
/// excluded slot, after the inlet particles still waiting (`halo_pack` finds the free tail
/// there). No particle has it (the run's ids stay below it).
fn free_code(ids: IdSplit) -> u32 {
    ids.code_word(KIND_EXCLUDED, ids.free_id())
}

/// `packed` cut or padded to `capacity` entries, the padding free.
pub fn resize(packed: &mut Packed, capacity: usize) {
    packed.pos.resize(capacity, Pos::default());
    packed.velrho.resize(capacity, [0.0; 4]);
    packed.code.resize(capacity, free_code(packed.ids));
    packed.id.resize(capacity, packed.ids.free_id());
}

impl Solver {
    /// Rank `ranks.rank()`'s subdomain of `sc` cut by `slabs`, warmed up (its first sort and
    /// rates, with its neighbours' halos; every rank must call this together).
    pub fn subdomain(
        ctx: &GpuContext,
        sc: &Scenario,
        slabs: &Slabs,
        ranks: &dyn Ranks,
    ) -> Result<Self> {
        ensure!(
            slabs.ranks() == ranks.size(),
            "{} slabs for {} ranks",
            slabs.ranks(),
            ranks.size()
        );
        let ctl = halo::control(slabs, ranks.rank(), crate::decomposition::halo_layers(sc));
        ensure!(
            (0..slabs.ranks()).all(|r| slabs.range(r).len() as u32 >= ctl.layers),
            "the cuts {slabs:?} leave a slab thinner than the {} cell layers of halo this case \
             needs",
            ctl.layers
        );
        let mut solver = Self::build(ctx, sc, Some(ctl))?;
        let probes = probe_layers(sc, &solver.grid, slabs.axis)?;
        for (p, layers) in sc.probes.iter().zip(&probes) {
            if let Some(l) = layers.clone().filter(|l| !l.is_empty()) {
                ensure!(
                    slabs.owner(l.start) == slabs.owner(l.end - 1),
                    "probe '{}' reads cell layers {l:?}, which the cuts {slabs:?} split",
                    p.name
                );
            }
        }
        let ranked = solver.ranked.as_mut().expect("a subdomain");
        ranked.slabs = Some(slabs.clone());
        ranked.probe_layers = probes;
        ranked.moving_probes = (0..sc.probes.len())
            .filter(|&k| on_free_body(sc, &sc.probes[k]))
            .collect();
        solver.ranked_step(ranks)?;
        solver.initial_dt = solver.state.dt_cfl;
        solver.check_first_dt()?;
        Ok(solver)
    }

    /// Takes `count` steps of CFL size on every rank together (as [`Solver::run_steps`]),
    /// looking at the balance every [`REBALANCE_EVERY`] steps.
    pub fn run_steps_ranked(&mut self, count: u64, ranks: &dyn Ranks) -> Result<()> {
        self.start_untargeted();
        for _ in 0..count {
            self.step_and_balance(ranks)?;
        }
        self.peaks.absorb(&self.state);
        self.check_stability()
    }

    /// Advances every rank together to exactly `t_target` as [`Solver::advance_to`] advances
    /// one whole run: the same steps (the ranks agree on each) in the same batches, re-based
    /// alike, the steps of a batch past the arrival included (`batch_to_target`: they compute
    /// the rates the next interval starts from); looks at the balance every
    /// [`REBALANCE_EVERY`] steps.
    pub fn advance_to_ranked(&mut self, t_target: f64, ranks: &dyn Ranks) -> Result<()> {
        self.advance_toward_ranked(t_target, ranks, &mut |_| false)
            .map(|_| ())
    }

    /// [`Solver::advance_toward`] over the ranks: every rank halts where any one's `halt`
    /// says so (a signal reaches them at different batches).
    pub fn advance_toward_ranked(
        &mut self,
        t_target: f64,
        ranks: &dyn Ranks,
        halt: &mut dyn FnMut(&Self) -> bool,
    ) -> Result<bool> {
        self.start_targeted(t_target);
        while self.state.dt > 0.0 {
            for _ in 0..self.batch_to_target() {
                self.step_and_balance(ranks)?;
            }
            self.peaks.absorb(&self.state);
            self.check_stability()?;
            if self.state.dt <= 0.0 {
                break;
            }
            if ranks.min(if halt(self) { 0.0 } else { 1.0 }) == 0.0 {
                return Ok(false);
            }
            self.start_targeted(t_target);
        }
        self.arrive(t_target);
        Ok(true)
    }

    /// One step of every rank, and the balance looked at every [`REBALANCE_EVERY`] steps
    /// taken (a step of dt = 0 is not one).
    fn step_and_balance(&mut self, ranks: &dyn Ranks) -> Result<()> {
        self.keep_probes_whole(ranks)?;
        let before = self.state.steps;
        self.ranked_step(ranks)?;
        let taken = (self.state.steps - before) as u64;
        self.steps += taken;
        self.ranked.as_mut().expect("a subdomain").steps = self.steps;
        if taken > 0 && self.steps.is_multiple_of(REBALANCE_EVERY) {
            self.rebalance(ranks)?;
        }
        Ok(())
    }

    /// Moves the cuts to where the ranks' present load balances, if the most loaded rank is
    /// beyond `decomposition::REBALANCE_THRESHOLD` over the mean (every rank together, between
    /// steps); whether they moved. Particles move exactly, so the run goes on as it would have.
    pub fn rebalance(&mut self, ranks: &dyn Ranks) -> Result<bool> {
        let (load, thickness) = self.layer_loads(ranks)?;
        let slabs = self.slabs();
        let moving = self.moving_probe_layers(PROBE_CLEARANCE);
        let Some(next) = slabs.rebalanced(&load, thickness, &moving) else {
            return Ok(false);
        };
        log::info!(
            "rank {}: cuts moved, imbalance {:.1} % -> {:.1} %",
            ranks.rank(),
            100.0 * slabs.imbalance(&load),
            100.0 * next.imbalance(&load)
        );
        self.redistribute(next, ranks)?;
        Ok(true)
    }

    /// Moves the cuts out of the way of the probes on free bodies before a step, where one
    /// lies within [`PROBE_MARGIN`] layers of what such a probe reads now: the new cuts balance
    /// the ranks' present load and stand [`PROBE_CLEARANCE`] layers clear of those probes
    /// (every rank together: each sees the same bodies, so each decides the same). A probe is
    /// then read whole by one rank at the end of the step, as one whole run reads it.
    fn keep_probes_whole(&mut self, ranks: &dyn Ranks) -> Result<()> {
        let near = self.moving_probe_layers(PROBE_MARGIN);
        if !near.iter().any(|l| self.slabs().splits(l)) {
            return Ok(());
        }
        let (load, thickness) = self.layer_loads(ranks)?;
        let clear = self.moving_probe_layers(PROBE_CLEARANCE);
        let next = (self
            .slabs()
            .clone()
            .clear_of_moving(&load, thickness, &clear))
        .context("moving the cuts out of the way of a probe on a free body")?;
        log::info!(
            "rank {}: cuts moved out of the way of a probe on a free body at t = {:.4} s",
            ranks.rank(),
            self.time()
        );
        self.redistribute(next, ranks)
    }

    /// The present cuts.
    fn slabs(&self) -> &Slabs {
        let ranked = self.ranked.as_ref().expect("a subdomain");
        ranked.slabs.as_ref().expect("a subdomain's cuts")
    }

    /// Every rank's own particles per cell layer, summed in rank order (every rank together),
    /// and the halo's thickness in layers, which a slab may not be thinner than.
    fn layer_loads(&self, ranks: &dyn Ranks) -> Result<(Vec<f64>, u32)> {
        let halo = self.passes.halo();
        let mine = halo.layer_load(&self.device, &self.queue, self.parity)?;
        Ok((ranks.sum_in_rank_order(&mine), halo.thickness))
    }

    /// The cell layers each probe on a free body reads where it stands now, `by` layers more
    /// on each side.
    pub(super) fn moving_probe_layers(&self, by: u32) -> Vec<Range<u32>> {
        let ranked = self.ranked.as_ref().expect("a subdomain");
        if ranked.moving_probes.is_empty() {
            return Vec::new();
        }
        let (Some(slabs), Some(placed)) = (&ranked.slabs, self.attached_probes_placed()) else {
            return Vec::new();
        };
        let count = self.grid.cells[slabs.axis];
        (ranked.moving_probes.iter())
            .filter_map(|&k| layers_read(&placed[k], self.params.h as f64, &self.grid, slabs.axis))
            .map(|l| widened(l, by, count))
            .collect()
    }

    /// Puts a checkpoint's subdomain counts and cuts back, after [`Solver::restore_state`]
    /// (every rank together, with the cuts the checkpoint's ranks had), and sorts the restored
    /// arrays so that the next step's packing finds the free tail.
    pub fn restore_subdomain(&mut self, saved: &Ranked, ranks: &dyn Ranks) -> Result<()> {
        let slabs = saved
            .slabs
            .clone()
            .context("the saved subdomain has no cuts")?;
        ensure!(
            slabs.ranks() == ranks.size(),
            "the checkpoint was written by {} ranks; resume it on as many",
            slabs.ranks()
        );
        let halo = self.passes.halo();
        halo.set_cuts(&self.queue, &slabs, ranks.rank(), false);
        let ranked = self.ranked.as_mut().expect("a subdomain");
        *ranked = Ranked {
            first_tail: None,
            moving_probes: std::mem::take(&mut ranked.moving_probes),
            ..saved.clone()
        };
        self.sort_in_place();
        self.faults.check()
    }

    /// Sorts the present arrays (into the other parity), as a step's sort would: the free tail
    /// is the excluded slot's start again. The last rates follow the particles.
    fn sort_in_place(&mut self) {
        let mut encoder = self.device.create_command_encoder(&Default::default());
        self.passes.cell_list.clear(&mut encoder, &self.buffers);
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            self.passes.cell_list.encode(&mut pass, self.parity);
            if let Some(b) = &self.passes.bodies {
                b.encode_index(&mut pass, 1 - self.parity);
            }
        }
        // The sort gathered the last rates into `rate_sorted`; the next predictor reads `rate`.
        let b = &self.buffers;
        encoder.copy_buffer_to_buffer(&b.rate_sorted, 0, &b.rate, 0, b.rate.size());
        self.queue.submit([encoder.finish()]);
        self.parity = 1 - self.parity;
    }

    /// Sends every particle to its owner under `next`, with the excluded ones that keep their
    /// ids (inlet particles waiting at the place they will join from, particles drained or
    /// gone out of the domain: halo.wgsl `packs`), then sorts, so that the next step's packing
    /// finds the free tail; the last rates follow the sort. A particle moves one
    /// neighbour a round, packed, swapped and unpacked as a step's migrants are (no record
    /// passes through the host), towards its owner; the rounds end when no rank sent one: one
    /// round where no cut moved past a neighbour's slab, at most one per rank.
    fn redistribute(&mut self, next: Slabs, ranks: &dyn Ranks) -> Result<()> {
        let rank = ranks.rank();
        // No halo this time.
        self.passes.halo().set_cuts(&self.queue, &next, rank, true);
        let mut rounds = 0u32;
        loop {
            let p = self.parity;
            let mut packed = self.pack(false, p, |passes, mut pass| {
                passes.halo().encode_pack(&mut pass, p)
            })?;
            if ranks.sum_in_rank_order(&[packed.migrants() as f64])[0] == 0.0 {
                break;
            }
            ensure!(
                (rounds as usize) < ranks.size(),
                "particles still moving to their ranks after {rounds} rounds of moving the cuts"
            );
            rounds += 1;
            let (incoming, _) = self.swap(std::mem::take(&mut packed.messages), ranks)?;
            self.place_arrivals(&incoming, None, p, packed.tail, None)?;
            // What was sent goes before what arrived comes in: an arrival on its way further
            // lies outside the slab too.
            let halo = self.passes.halo();
            self.submit_pass("halo drop and unpack", |pass| {
                halo.encode_drop(pass, p);
                halo.encode_forget(pass, p);
                halo.encode_unpack(pass, p, false);
            });
            self.sort_in_place();
        }
        let halo = self.passes.halo();
        halo.set_cuts(&self.queue, &next, rank, false);
        let ranked = self.ranked.as_mut().expect("a subdomain");
        ranked.slabs = Some(next);
        ranked.rebalances += 1;
        ranked.moving_rounds = ranked.moving_rounds.max(rounds);
        self.faults.check()
    }

    /// Every rank's part of the steps since `since` (this rank's counts then), in rank order,
    /// on every rank; the adapters' names on rank 0 only (empty elsewhere). Every rank
    /// together.
    pub fn rank_summaries(
        &self,
        since: &Ranked,
        adapter: &str,
        ranks: &dyn Ranks,
    ) -> Result<Vec<RankSummary>> {
        let now = self.ranked.as_ref().expect("a subdomain");
        let steps = (self.steps - since.steps).max(1) as f64;
        let per = |x: u64, x0: u64| (x - x0) as f64 / steps;
        let split = now.split - since.split;
        let mine = [
            now.owned as f64,
            per(now.halo_sent, since.halo_sent),
            per(now.migrants_sent, since.migrants_sent),
            per(now.bytes_sent, since.bytes_sent),
            split.pack / steps,
            split.exchange / steps,
            split.compute / steps,
            split.agree / steps,
            (now.rebalances - since.rebalances) as f64,
            self.grid.slots as f64,
            (now.overlapped - since.overlapped) as f64
                / (now.exchanges - since.exchanges).max(1) as f64,
            (now.hidden - since.hidden) as f64 / (now.overlapped - since.overlapped).max(1) as f64,
        ];
        let mut adapters = ranks.gather_text(adapter)?.into_iter();
        Ok(ranks
            .gather(&mine)
            .into_iter()
            .map(|v| RankSummary {
                adapter: adapters.next().unwrap_or_default(),
                own_particles: v[0] as u64,
                halo_particles_per_step: v[1],
                migrants_per_step: v[2],
                halo_bytes_per_step: v[3],
                seconds_per_step: Split {
                    pack: v[4],
                    exchange: v[5],
                    compute: v[6],
                    agree: v[7],
                },
                rebalances: v[8] as u32,
                hash_slots: v[9] as u64,
                overlapped: v[10],
                exchange_hidden: v[11],
            })
            .collect())
    }

    /// This rank's counts (halo and migrants sent), if it is a subdomain.
    pub fn ranked(&self) -> Option<&Ranked> {
        self.ranked.as_ref()
    }

    /// One step of a subdomain: predict and pack, swap with the neighbours, unpack, the rest
    /// of the step; then the ranks' smallest time step and their summed counts. An overlapped
    /// subdomain (`Passes::overlap`) sorts and sums its interior on the GPU while the host
    /// swaps, then writes what arrived after its sorted particles and takes the rest of the
    /// step from there, sorting again: its arrays come back to the parity they started in.
    fn ranked_step(&mut self, ranks: &dyn Ranks) -> Result<()> {
        let start = std::time::Instant::now();
        let body_dt = self.bodies.is_some().then(|| self.predict_bodies());
        let p = self.parity;
        let mut packed = self.pack(true, p, |passes, pass| {
            passes.record_to_exchange(&mut Recorder::Shared(pass), p)
        })?;
        let packed_at = std::time::Instant::now();
        let k = self.ranked.as_ref().expect("a subdomain").exchanges;
        let overlaps = (self.passes.overlap.as_ref()).is_some_and(|o| o.choice.overlaps(k));
        let interior = overlaps.then(|| self.submit_interior(p));

        let (incoming, bytes) = self.swap(std::mem::take(&mut packed.messages), ranks)?;
        self.share_tl_positions(ranks)?;
        let swapped_at = std::time::Instant::now();
        let ranked = self.ranked.as_mut().expect("a subdomain");
        ranked.bytes_sent += bytes;
        let first_tail = ranked.first_tail.take();
        ranked.exchanges += 1;
        ranked.migrants_sent += packed.migrants() as u64;
        ranked.halo_sent += packed.copies() as u64;
        ranked.owned = packed.owned;
        let p = self.place_arrivals(&incoming, interior, p, packed.tail, first_tail)?;

        // The GPU counts a step of dt > 0 (integrate.wgsl `timestep`): whether the density
        // filter fires is known now. Its submission frees the entries this step excluded, or
        // this one does.
        let steps_before = self.state.steps;
        let filters = self.passes.density_filter.as_ref().is_some_and(|f| {
            f.fires_after(steps_before, steps_before + (self.state.dt > 0.0) as u32)
        });
        let mut encoder = self.device.create_command_encoder(&Default::default());
        self.passes.cell_list.clear(&mut encoder, &self.buffers);
        {
            let mut r = Recorder::Shared(encoder.begin_compute_pass(&Default::default()));
            self.passes.record_from_exchange(&mut r, p, overlaps);
            if !filters {
                let halo = self.passes.halo();
                r.stage("halo_forget", |pass| halo.encode_forget(pass, 1 - p));
            }
        }
        let (local, particle_loads) = match body_dt {
            Some(_) => {
                let (state, loads) = self.submit_reading_loads(encoder)?;
                (state, Some(loads))
            }
            None => {
                self.queue.submit([encoder.finish()]);
                (self.read_state()?, None)
            }
        };
        self.parity = 1 - p;
        let computed_at = std::time::Instant::now();
        if let Some(o) = &mut self.passes.overlap {
            o.choice.record(k, (computed_at - start).as_secs_f64());
        }
        self.agree(local, packed.owned + packed.migrants(), ranks);
        if let (Some(dt), Some(mine)) = (body_dt, particle_loads) {
            self.correct_bodies(dt, &mine, ranks);
        }
        if filters {
            ensure!(
                self.state.steps == steps_before + 1,
                "the GPU took no step where the density filter was to fire"
            );
            self.filter_over_ranks(ranks)?;
        }
        let split = &mut self.ranked.as_mut().expect("a subdomain").split;
        split.pack += (packed_at - start).as_secs_f64();
        split.exchange += (swapped_at - packed_at).as_secs_f64();
        split.compute += (computed_at - swapped_at).as_secs_f64();
        split.agree += computed_at.elapsed().as_secs_f64();
        Ok(())
    }

    /// Every total-Lagrangian particle's position, shared by the ranks, for the TL passes: a
    /// particle's acceleration reads the positions four reference lists away, further than
    /// any halo, so every rank computes the whole solid's stresses. Each rank has gathered
    /// the positions of the TL particles it holds after its predictor, with the packing
    /// (`TotalLagrangian::encode_index`, copied out by `pack`); the ranks add them up in rank order as
    /// integer-valued words, each held by one rank and so added to zeros only (the same
    /// bits), and every rank writes them back. The corrector moves no particle
    /// (integrate.wgsl), so these are also the positions an output's stresses read. Stops
    /// the run where a particle is held by no rank (it left the domain) or by several (every
    /// rank alike: they see the same sums). Nothing without TL solids.
    fn share_tl_positions(&self, ranks: &dyn Ranks) -> Result<()> {
        let Some(t) = &self.passes.total_lagrangian else {
            return Ok(());
        };
        const WORDS: usize = 5;
        let held = t.read_held(&self.device)?;
        let mut mine = vec![0.0; WORDS * held.len()];
        for (w, p) in mine.chunks_exact_mut(WORDS).zip(&held) {
            if let Some(p) = p {
                w[0] = 1.0;
                for d in 0..3 {
                    w[1 + d] = p.off[d].to_bits() as f64;
                }
                w[4] = p.block as f64;
            }
        }
        let all = ranks.sum_in_rank_order(&mine);
        let mut pos = Vec::with_capacity(held.len());
        for (k, w) in all.chunks_exact(WORDS).enumerate() {
            ensure!(
                w[0] == 1.0,
                "the total-Lagrangian solid particle of id {} is held by {} ranks, where one \
                 must hold it (none: it left the domain)",
                t.first_id() as usize + k,
                w[0]
            );
            pos.push(Pos {
                off: [0, 1, 2].map(|d| f32::from_bits(w[1 + d] as u32)),
                block: w[4] as u32,
            });
        }
        t.write_positions(&self.queue, &pos);
        self.faults.check()
    }

    /// Submits the passes `record` records (the last of them `halo_pack`, on the arrays of
    /// parity `p`) and reads back what they packed; with `tl_positions`, also copies the
    /// total-Lagrangian positions they gathered for [`Solver::share_tl_positions`]. Where the
    /// records did not fit, grows the packing buffer and packs again (the packing only reads
    /// the arrays). Waits for the GPU.
    fn pack(
        &mut self,
        tl_positions: bool,
        p: usize,
        record: impl FnOnce(&Passes, wgpu::ComputePass<'_>),
    ) -> Result<halo::Packed> {
        let packed = self.submit_packing(tl_positions, record)?;
        let Some(needed) = packed.needed else {
            return Ok(packed);
        };
        self.reserve_records(needed as usize)?;
        let packed = self.submit_packing(false, |passes, mut pass| {
            passes.halo().encode_pack(&mut pass, p)
        })?;
        ensure!(
            packed.needed.is_none(),
            "the halo records did not fit twice"
        );
        Ok(packed)
    }

    /// One submission of [`Solver::pack`]: the counters cleared, the passes `record` records,
    /// the counters (and with `tl_positions` the total-Lagrangian positions) copied; then what
    /// was packed, read back.
    fn submit_packing(
        &self,
        tl_positions: bool,
        record: impl FnOnce(&Passes, wgpu::ComputePass<'_>),
    ) -> Result<halo::Packed> {
        let halo = self.passes.halo();
        let mut encoder = self.device.create_command_encoder(&Default::default());
        halo.clear(&mut encoder);
        record(
            &self.passes,
            encoder.begin_compute_pass(&Default::default()),
        );
        halo.copy_counts(&mut encoder);
        if let Some(t) = self
            .passes
            .total_lagrangian
            .as_ref()
            .filter(|_| tl_positions)
        {
            t.copy_held(&mut encoder);
        }
        self.queue.submit([encoder.finish()]);
        let packed = halo.read(&self.device, &self.queue)?;
        self.faults.check()?;
        Ok(packed)
    }

    /// Makes the halo's packing buffer hold `needed` records (`Halo::reserve`).
    fn reserve_records(&mut self, needed: usize) -> Result<()> {
        let halo = self.passes.halo_mut();
        halo.reserve(&self.device, &self.queue, &self.buffers, needed)
    }

    /// Sends the messages `lower` and `upper` to the neighbour below and above (where there is
    /// one), and returns what the neighbours sent this rank (every rank together) and the
    /// bytes this rank sent.
    fn swap(&self, [lower, upper]: [Vec<u8>; 2], ranks: &dyn Ranks) -> Result<(Vec<Vec<u8>>, u64)> {
        let rank = ranks.rank();
        let mut sends = Vec::new();
        if rank > 0 {
            sends.push((rank - 1, lower));
        }
        if rank + 1 < ranks.size() {
            sends.push((rank + 1, upper));
        }
        let from: Vec<usize> = sends.iter().map(|(to, _)| *to).collect();
        let bytes = sends.iter().map(|(_, b)| b.len() as u64).sum();
        Ok((ranks.exchange(&sends, &from)?, bytes))
    }

    /// The density filter of a step it fires on (`DensityFilter::fires_after`), over ranks: it
    /// reads the corrected densities of the neighbours, the halo copies' included, which
    /// `halo_drop` excluded before the corrector. So the ranks pack their own halo particles
    /// again, corrected, and swap them as a step swaps its halo; each rank gives its copies
    /// their owners' code word and density back (`halo_restore`, which finds them by id),
    /// filters, excludes them again and frees the step's excluded entries (every rank
    /// together).
    fn filter_over_ranks(&mut self, ranks: &dyn Ranks) -> Result<()> {
        let q = self.parity;
        self.passes.halo_mut().set_lean(&self.queue, true);
        let packed = self.pack(false, q, |passes, mut pass| {
            passes.halo().encode_pack(&mut pass, q)
        });
        self.passes.halo_mut().set_lean(&self.queue, false);
        let mut packed = packed?;
        ensure!(
            packed.migrants() == 0,
            "{} particles outside the subdomain after the corrector",
            packed.migrants()
        );
        let (incoming, bytes) = self.swap(std::mem::take(&mut packed.messages), ranks)?;
        self.ranked.as_mut().expect("a subdomain").bytes_sent += bytes;
        let halo = self.passes.halo_mut();
        halo.upload_restoring(&self.device, &self.queue, &self.buffers, &incoming)?;
        let halo = self.passes.halo();
        let filter = self.passes.density_filter.as_ref().expect("a filter");
        let mut encoder = self.device.create_command_encoder(&Default::default());
        halo.clear_index(&mut encoder);
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            halo.encode_restore(&mut pass, q);
            filter.encode(&mut pass, q);
            halo.encode_drop(&mut pass, q);
            halo.encode_forget(&mut pass, q);
        }
        self.queue.submit([encoder.finish()]);
        self.faults.check()
    }

    /// Uploads what arrived for `halo_unpack`, which writes it into the arrays the rest of the
    /// step starts from, and returns their parity: after an overlapped step's first sort
    /// (`interior`), into the other parity than `p`, from where that sort left its free tail
    /// (on the GPU: the host does not wait for it); else into `p`'s, from the last sort's free
    /// tail on (`tail`, which the packing found on the GPU), or from `first_tail` before any
    /// sort. The first sort of an overlapped step frees what the last step excluded, so the
    /// arrivals find as much room there at least.
    fn place_arrivals(
        &mut self,
        incoming: &[Vec<u8>],
        interior: Option<Interior>,
        p: usize,
        tail: u32,
        first_tail: Option<u32>,
    ) -> Result<usize> {
        let tail = first_tail.unwrap_or(tail);
        let halo = self.passes.halo_mut();
        let b = &self.buffers;
        let particles = halo.upload_arrivals(&self.device, &self.queue, b, incoming, false)?;
        let free = self.buffers.n.saturating_sub(tail);
        if particles > free {
            bail!(
                "the subdomain received {particles} halo and migrant particles but has room \
                 for {free} ({} in all): more water flowed into it than its arrays were made \
                 for before the cuts moved",
                self.buffers.n
            );
        }
        let Some(interior) = interior else {
            if first_tail.is_some() {
                halo.set_tail(&self.queue, tail);
            }
            return Ok(p);
        };
        // Runs the callback of `interior.summed` if the GPU is done with the sums.
        let _ = self.device.poll(wgpu::PollType::Poll);
        let ranked = self.ranked.as_mut().expect("a subdomain");
        ranked.overlapped += 1;
        if !interior.summed.load(std::sync::atomic::Ordering::Acquire) {
            ranked.hidden += 1;
        }
        Ok(1 - p)
    }

    /// Submits an overlapped step's first sort of the arrays of parity `p` (and where their
    /// free tail then starts), then, apart, the sums of the particles that need nothing from
    /// the exchange; waits for neither.
    fn submit_interior(&self, p: usize) -> Interior {
        let mut encoder = self.device.create_command_encoder(&Default::default());
        self.passes.cell_list.clear(&mut encoder, &self.buffers);
        self.passes.record_before_arrival(
            &mut Recorder::Shared(encoder.begin_compute_pass(&Default::default())),
            p,
        );
        self.queue.submit([encoder.finish()]);
        let mut encoder = self.device.create_command_encoder(&Default::default());
        self.passes.record_interior(
            &mut Recorder::Shared(encoder.begin_compute_pass(&Default::default())),
            1 - p,
        );
        self.queue.submit([encoder.finish()]);
        let summed = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let done = summed.clone();
        self.queue
            .on_submitted_work_done(move || done.store(true, std::sync::atomic::Ordering::Release));
        Interior { summed }
    }

    /// Corrects the bodies over dt with the loads of every rank's body particles (`mine`:
    /// this rank's, zero where it holds none), summed as one whole run sums them: every rank
    /// then moves the bodies alike.
    fn correct_bodies(&mut self, dt: f64, mine: &[[f32; 4]], ranks: &dyn Ranks) {
        let all = bodies::owners_values(ranks, mine);
        let gpu = self.passes.bodies.as_ref().expect("a run with bodies");
        let loads = gpu.loads_of_particles(&all);
        let host = &mut self.bodies.as_mut().expect("a run with bodies").set;
        host.correct(dt, &loads);
    }

    /// The ranks' common view after a step: the smallest time step (the GPU's choice
    /// (integrate.wgsl `timestep`) repeated with it, so every rank takes the step one whole run
    /// would), and the counts the stop rules read, summed; `live`: this rank's own particles
    /// and migrants sent at packing. The host's state keeps this rank's drained count (it
    /// goes back to the GPU with a checkpoint), `Ranked::drained` the run's; so with the
    /// inlet particles that joined.
    fn agree(&mut self, local: crate::layout::SimState, live: u32, ranks: &dyn Ranks) {
        let dt = ranks.min(local.dt_cfl as f64) as f32;
        let mut gpu = local;
        gpu.dt_cfl = dt;
        let remaining = gpu.t_target_rel - gpu.t_rel;
        gpu.dt = if remaining <= 1e-4 * dt {
            0.0
        } else {
            dt.min(remaining)
        };
        self.queue
            .write_buffer(&self.buffers.state, 0, bytemuck::bytes_of(&gpu));
        let sums = ranks.sum_in_rank_order(&[
            live as f64,
            local.nan_count as f64,
            local.beyond_warn_peak as f64,
            local.beyond_stop_peak as f64,
            local.drained as f64,
            // A net count: a rank whose particles left a buffer more than joined one holds a
            // negative one.
            local.net_joined() as f64,
        ]);
        let peak = -ranks.min(-(local.density_variation_peak as f64));
        let ranked = self.ranked.as_mut().expect("a subdomain");
        ranked.drained = sums[4] as u64;
        ranked.joined = sums[5] as i64;
        // What is neither live on a rank nor drained left the domain (the drained are
        // excluded too, but counted apart, as one whole run counts them); the inlet particles
        // that joined add to the live.
        ranked.excluded = ((ranked.live_at_start as i64 + ranked.joined).max(0) as u64)
            .saturating_sub(sums[0] as u64)
            .saturating_sub(ranked.drained);
        self.state = gpu;
        self.state.nan_count = sums[1] as u32;
        self.state.beyond_warn_peak = sums[2] as u32;
        self.state.beyond_stop_peak = sums[3] as u32;
        self.state.density_variation_peak = peak as f32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::ID_MASK;

    fn load(case: &str, set: &[&str]) -> Scenario {
        let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        crate::case::load(std::path::Path::new(case), &set).unwrap()
    }

    /// The middle one of three subdomains of the elastic gate (water on a solid) starts with
    /// room for twice the halo copies it sends each way, a solid particle's twice (its stress
    /// state follows), and 64 more; without neighbours, for 64.
    #[test]
    fn a_packing_buffer_starts_with_room_for_twice_the_halo() {
        let sc = load("cases/elastic_gate_2d.toml", &[]);
        let grid = crate::decomposition::ranks_grid(&sc).unwrap();
        let axis = crate::decomposition::cut_axis(&grid, sc.physics.dim).unwrap();
        let layers = grid.cells[axis];
        let mut ctl = HaloCtl {
            axis: axis as u32,
            own_lo: layers / 3,
            own_hi: 2 * layers / 3,
            layers: 2,
            lower: 1,
            upper: 1,
            ..Default::default()
        };
        let mut packed = super::super::initial::pack(&sc, &grid);
        let (own, _) = exclude_others(&mut packed, &grid, &ctl);
        let near = |lo: u32, hi: u32| -> u32 {
            (sc.particles.iter())
                .filter(|p| {
                    let (off, b) = grid.to_block(p.pos);
                    (lo..hi).contains(&(grid.cell_of(off, b)[axis] as u32))
                })
                .map(|p| 1 + p.kind.is_solid() as u32)
                .sum()
        };
        let halo = near(ctl.own_lo, ctl.own_lo + 2) + near(ctl.own_hi - 2, ctl.own_hi);
        assert!(halo > 0);
        assert_eq!(starting_records(&packed, own, &grid, &ctl), 2 * halo + 64);
        (ctl.lower, ctl.upper) = (0, 0);
        assert_eq!(starting_records(&packed, own, &grid, &ctl), 64);
    }

    /// Three subdomains of the water injection: each holds its own live particles first,
    /// unchanged, then the inlet particles waiting to join in its layers, ids kept, then free
    /// entries; together they hold every live particle and every waiting one exactly once.
    #[test]
    fn subdomains_hold_their_own_and_their_waiting_inlet_particles() {
        let sc = load("cases/water_injection_2d.toml", &[]);
        let ph = &sc.physics;
        let grid = crate::decomposition::ranks_grid(&sc).unwrap();
        let axis = crate::decomposition::cut_axis(&grid, ph.dim).unwrap();
        let whole = super::super::initial::pack(&sc, &grid);
        let layers = grid.cells[axis];
        let (mut live, mut waiting) = (Vec::new(), Vec::new());
        for r in 0..3 {
            let mut packed = super::super::initial::pack(&sc, &grid);
            let ctl = HaloCtl {
                axis: axis as u32,
                own_lo: r * layers / 3,
                own_hi: (r + 1) * layers / 3,
                ..Default::default()
            };
            let (own, held) = exclude_others(&mut packed, &grid, &ctl);
            let (own, held) = (own as usize, held as usize);
            for (k, &c) in packed.code.iter().enumerate() {
                let id = packed.id[k] as usize;
                let excluded = c >> KIND_SHIFT == KIND_EXCLUDED;
                assert_eq!(excluded, k >= own, "entry {k}");
                if k < own {
                    assert_eq!(
                        (c, packed.pos[k], packed.velrho[k]),
                        (whole.code[id], whole.pos[id], whole.velrho[id])
                    );
                    let p = packed.pos[k];
                    let layer = grid.cell_of(p.off, unpack_block(p.block))[axis];
                    assert!((ctl.own_lo..ctl.own_hi).contains(&(layer as u32)));
                    live.push(id);
                } else if k < own + held {
                    assert_eq!(c, whole.code[id], "a waiting particle keeps its code");
                    waiting.push(id);
                } else {
                    assert_eq!((c, packed.id[k]), (free_code(packed.ids), ID_MASK));
                }
            }
        }
        live.sort();
        waiting.sort();
        let kind = |id: &usize| whole.code[*id] >> KIND_SHIFT;
        let all_live: Vec<usize> = (0..whole.code.len())
            .filter(|id| kind(id) != KIND_EXCLUDED)
            .collect();
        let dormant: Vec<usize> = (0..whole.code.len())
            .filter(|id| kind(id) == KIND_EXCLUDED)
            .collect();
        assert_eq!(live, all_live);
        assert_eq!(waiting, dormant);
        assert_eq!(dormant.len(), sc.dormant_count());
        assert!(
            !dormant.is_empty(),
            "no waiting particle: the test tests nothing"
        );
    }
}

//! The GPU solver: one module per pass, listed and ordered in `passes`. A step is
//! predict → cell-list sort → interaction → correct + time step, all on the GPU in one
//! command encoder; the host reads back a 48-byte state once per batch of steps.
//!
//! The solver is built from pure pieces: `params` (the uniform from the case), `initial` (the
//! packed particles, what the case holds), `shader` (the compile-time choices); `readback`
//! reads the particles, `state` saves and restores a run.

pub mod bodies;
pub mod buffers;
pub mod capacity;
pub mod cell_list;
pub mod density_filter;
pub mod elastic;
pub mod flood_maps;
pub mod ghost;
pub mod halo;
#[cfg(feature = "test-hooks")]
mod hooks;
pub mod initial;
pub mod integrate;
pub mod interaction;
pub mod open_boundaries;
pub mod overlap;
pub mod params;
pub mod passes;
pub mod probes;
pub mod profile;
mod ranked_probes;
mod readback;
pub mod shader;
pub mod state;
pub mod subdomain;
pub mod total_lagrangian;

use anyhow::{bail, Result};

use crate::body::BodySet;
use crate::gpu::buffers::{map_read, read, readback_buffer};
use crate::gpu::context::GpuFaults;
use crate::gpu::GpuContext;
use crate::grid::Grid;
use crate::layout::{unpack_block, HaloCtl, IdSplit, Params, Pos, SimState, KIND_EXCLUDED};
use crate::scenario::{Kind, Scenario};
use buffers::{CaseTables, InitialParticles, ParticleBuffers};
pub use capacity::{capacity, check_capacity, host_memory_available, run_budget, Capacity};
use passes::Passes;
use profile::{Profiler, Recorder, StageTime};
use shader::ShaderConfig;

/// Most steps recorded into one submission before the host looks at the state again.
const MAX_BATCH: u32 = 64;

/// The most particle-steps of a batch of a large case: the host looks at the state after every
/// batch (progress, a signal to stop: `Solver::advance_toward`), so a batch is cut to about this
/// much work, a few seconds on a CPU adapter and milliseconds on a GPU, whatever the probe
/// interval (issue 64: a run at dx = 5 mm answered SIGTERM after 24 s). A count, not a time, so
/// that the batches, where the GPU's f32 clock is re-based, are the case's alone.
const BATCH_PARTICLE_STEPS: u64 = 1 << 21;

/// The largest density variation and the most fluid particles beyond the warning and stop
/// limits in any one step, since the host last cleared them (`Solver::clear_density_peaks`):
/// the GPU's peaks count from each batch's upload, the host keeps their largest.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DensityPeaks {
    pub variation: f32,
    pub beyond_warn: u32,
    pub beyond_stop: u32,
}

impl DensityPeaks {
    /// Takes in the peaks of the steps of `state` since its upload.
    fn absorb(&mut self, state: &SimState) {
        self.variation = self.variation.max(state.density_variation_peak);
        self.beyond_warn = self.beyond_warn.max(state.beyond_warn_peak);
        self.beyond_stop = self.beyond_stop.max(state.beyond_stop_peak);
    }
}

/// A part of the step that benchmarks time on its own.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Key, scan, scatter, rank and reorder.
    CellList,
    /// The neighbour sum.
    Interaction,
    /// A whole step.
    Step,
}

/// The weakly-compressible check over a span of steps: the fluid's largest density variation
/// |ρ/ρ0 − 1| and the largest share of its particles beyond `time.density_variation_warn` and
/// `_stop` in any one step. A share is judged, not the largest variation: a few particles at
/// an impact carry its acoustic pressure peak (ρ0 c0 u, a density variation of u/c0, 10 % at
/// Mach 0.1) in a run that is sound, as the shipped dam break does at the wall.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DensityVariation {
    pub max: f64,
    pub share_beyond_warn: f64,
    pub share_beyond_stop: f64,
}

impl DensityVariation {
    /// The share of the fluid beyond a limit that counts as the fluid being beyond it.
    pub const SHARE: f64 = 0.01;

    pub fn beyond_warn(&self) -> bool {
        self.share_beyond_warn > Self::SHARE
    }

    pub fn beyond_stop(&self) -> bool {
        self.share_beyond_stop > Self::SHARE
    }
}

/// The steps that arrive `left` seconds ahead at steps of `dt`, and one more, from 1 to `cap`:
/// counted in f64, as a probe time 2^32 steps away overflowed a count in u32 (issue 64).
fn batch_steps(left: f32, dt: f32, cap: u32) -> u32 {
    // NaN: `max` takes the other (no time left; a step of 1e-30 s).
    let steps = (left.max(0.0) as f64 / (dt as f64).max(1e-30)).ceil() + 1.0;
    (steps.min(cap as f64) as u32).max(1)
}

/// The stop of a run that lost more than `fraction` of its `fluid` fluid and solid particles
/// out of the domain: `excluded` is of every kind, so walls the case moves out of the domain
/// count too (issue 64: "702 of 75 particles left the domain").
fn left_the_domain(excluded: u64, fluid: u64, fraction: f64) -> String {
    let walls = match excluded > fluid {
        true => " (more than there are: walls or bodies the case moves left it too)",
        false => "",
    };
    format!(
        "{excluded} particles left the domain, more than {:.0} % of the case's {fluid} fluid \
         and solid particles{walls}; check that the case keeps them in [domain]",
        100.0 * fraction,
    )
}

/// Why a run stopped before its end.
#[derive(Debug, thiserror::Error)]
#[error("run unstable at step {step}, t = {time_s:.6} s: {reason}")]
pub struct Unstable {
    pub step: u64,
    pub time_s: f64,
    pub reason: String,
}

pub use crate::particles::Particles;

/// (positions, (v, ρ), code words) as stored on the GPU; with wide ids the code words are
/// followed by the ids' high words (`Solver::ids`).
pub type RawParticles = (Vec<Pos>, Vec<[f32; 4]>, Vec<u32>);

/// Moving bodies' host side: their dynamics, and the buffer the state and the per-workgroup
/// loads are read back into after every step.
struct HostBodies {
    set: BodySet,
    staging: wgpu::Buffer,
}

pub struct Solver {
    device: wgpu::Device,
    queue: wgpu::Queue,
    /// Asynchronous GPU failures (out of memory, device lost), checked after every wait.
    faults: GpuFaults,
    pub grid: Grid,
    pub params: Params,
    buffers: ParticleBuffers,
    passes: Passes,
    energy: bool,
    /// How the particles' ids are stored.
    ids: IdSplit,
    /// Solid particles (the length of the solid arrays).
    n_solid: u32,
    /// The case's probes and the bodies' centres at t = 0, when a probe moves with a body.
    attached_probes: Option<(Vec<crate::scenario::Probe>, Vec<[f64; 3]>)>,
    /// Each probe's face on a fixed wall (`probes::probe_faces`).
    probe_faces: Vec<u32>,
    /// The continuous fronts' bins (`probes::FrontBins`).
    front_bins: probes::FrontBins,
    bodies: Option<HostBodies>,
    parity: usize,
    t_base: f64,
    steps: u64,
    state: SimState,
    initial_dt: f32,
    n_fluid: u64,
    /// Inlet particles behind their buffers at t = 0 (excluded until they join).
    dormant_at_start: u32,
    /// Stop when more than this fraction of the fluid has been excluded.
    pub max_excluded_fraction: f64,
    /// `time.density_variation_stop` (the check: [`DensityVariation::beyond_stop`]).
    density_variation_stop: f64,
    /// Fluid particles at t = 0 and the inlets' buffers' (not those waiting to join).
    n_fluid_at_start: u64,
    /// Per-stage timestamps, while [`Solver::profile_steps`] runs.
    profiler: Option<Profiler>,
    /// The density peaks since the host last cleared them.
    peaks: DensityPeaks,
    /// The most steps of a batch ([`BATCH_PARTICLE_STEPS`] over the whole case's particles).
    batch_cap: u32,
    /// A subdomain's counts over all ranks (`subdomain::Ranked`); None in a whole run.
    ranked: Option<subdomain::Ranked>,
}

impl Solver {
    pub fn new(ctx: &GpuContext, sc: &Scenario) -> Result<Self> {
        let mut solver = Self::build(ctx, sc, None)?;
        // Warm-up: one step with dt = 0 sorts the particles, evaluates the initial rates and
        // chooses the first dt; it moves nothing and is not counted.
        solver.take_steps(1)?;
        solver.initial_dt = solver.state.dt_cfl;
        solver.check_first_dt()?;
        Ok(solver)
    }

    /// The solver of `sc` before its warm-up step: of the whole case, or with `subdomain` of
    /// the particles in its own cell layers (the others excluded) and its halo pass.
    fn build(ctx: &GpuContext, sc: &Scenario, mut subdomain: Option<HaloCtl>) -> Result<Self> {
        let ph = &sc.physics;
        let n = sc.particles.len();
        if n == 0 {
            bail!("the case has no particles");
        }
        capacity::check_ids(n)?;
        if subdomain.is_none() {
            check_capacity(ctx, n)?;
        }
        if subdomain.is_some() && sc.maps.is_some() {
            bail!(
                "flood maps ([maps]) are not yet made over several ranks: run the case on one \
                 rank, or remove [maps]"
            );
        }
        let mut grid = match subdomain {
            Some(_) => crate::decomposition::ranks_grid(sc)?,
            None => Grid::of(sc)?,
        };
        // A subdomain packs the whole case to choose its own particles; a whole run packs and
        // writes its particles in pieces once its buffers are made.
        let mut packed = subdomain.is_some().then(|| initial::pack(sc, &grid));
        let mut capacity = n as u32;
        let ranked = (subdomain.as_mut().zip(packed.as_mut()))
            .map(|(ctl, packed)| -> Result<_> {
                let (own, waiting) = subdomain::exclude_others(packed, &grid, ctl);
                capacity = subdomain::capacity(own, waiting, n as u32);
                check_capacity(ctx, capacity as usize)?;
                subdomain::resize(packed, capacity as usize);
                ctl.capacity = subdomain::starting_records(packed, own, &grid, ctl);
                let window = subdomain::window(ctl, &grid);
                grid = grid.for_subdomain((own + waiting) as usize, ctl.axis as usize, window);
                let live = (n - sc.dormant_count()) as u64;
                Ok(subdomain::Ranked::new(live, own, waiting))
            })
            .transpose()?;
        let mut params = Params::from_scenario(sc, &grid)?;
        params.n_particles = capacity;
        let cfg = ShaderConfig::of(sc, &grid)?.for_adapter(&ctx.info);
        probes::check_wall_pressure(sc)?;
        let device = ctx.device.clone();
        // Allocation failures are caught here to name what was being allocated; later ones
        // reach `faults`.
        let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let probe_faces = probes::probe_faces(&sc.probes, &sc.walls);
        let front_bins = probes::FrontBins::new(&grid, ph.h, &sc.probes)?;
        let defs = probes::probe_defs(&sc.probes, grid.origin, &probe_faces, front_bins);
        let body_motions = bodies::initial_motions(sc, params.body_id_base);
        let solid = initial::solid_states(sc)?;
        let buffers = ParticleBuffers::new(
            &device,
            &params,
            grid.slots,
            &InitialParticles {
                capacity,
                wide_ids: initial::id_split(sc).wide,
                body_particles: &bodies::body_particles(sc),
                body_motions: &body_motions,
                solid: &solid,
            },
            &CaseTables {
                probes: &defs,
                mirror_planes: &params::mirror_planes(sc, grid.origin),
                wall_sensors: &params::wall_sensors(sc, grid.origin),
            },
            cfg.tables,
            ph.energy,
        );
        match &packed {
            Some(packed) => buffers.write_particles(&ctx.queue, 0, packed),
            None => initial::write_in_pieces(sc, &grid, &buffers, ctx)?,
        }
        drop(packed);
        let passes = Passes::new(
            &device,
            sc,
            cfg,
            &grid,
            &buffers,
            &defs,
            body_motions,
            subdomain,
        )?;
        let bodies = passes.bodies.as_ref().map(|gpu| HostBodies {
            set: BodySet::new(&sc.bodies, ph.gravity, ph.dim),
            staging: readback_buffer(
                &device,
                "state and body loads",
                std::mem::size_of::<SimState>() as u64 + gpu.loads_buffer().1,
            ),
        });
        if let Some(e) = pollster::block_on(oom.pop()) {
            bail!(
                "the GPU ran out of memory allocating the buffers of {n} particles ({} MiB, \
                 {:.0} bytes a particle): use a coarser particles.dx_m or a GPU with more \
                 memory ({e})",
                buffers.bytes() >> 20,
                buffers.bytes() as f64 / n as f64
            );
        }
        let solver = Self {
            device,
            queue: ctx.queue.clone(),
            faults: ctx.faults.clone(),
            grid,
            params,
            buffers,
            passes,
            energy: ph.energy,
            ids: cfg.ids,
            n_solid: solid.len() as u32,
            probe_faces,
            front_bins,
            attached_probes: sc.probes.iter().any(|p| p.body.is_some()).then(|| {
                (
                    sc.probes.clone(),
                    sc.bodies.iter().map(|b| b.center).collect(),
                )
            }),
            bodies,
            parity: 0,
            t_base: 0.0,
            steps: 0,
            state: SimState::default(),
            initial_dt: 0.0,
            // Fluid (inlets' included) and free solid particles: the ones that move and can
            // leave the domain.
            n_fluid: (sc.count(Kind::Fluid) + sc.count(Kind::Inlet) + sc.count(Kind::Solid)) as u64,
            dormant_at_start: sc.dormant_count() as u32,
            max_excluded_fraction: 0.05,
            density_variation_stop: sc.time.density_variation_stop,
            // The buffers' particles become fluid without joining (issue 64: left out, an
            // inlet's run could report "400 % of the fluid's particles").
            n_fluid_at_start: (sc.count(Kind::Fluid) + sc.count(Kind::Inlet) - sc.dormant_count())
                as u64,
            profiler: None,
            peaks: DensityPeaks::default(),
            batch_cap: (BATCH_PARTICLE_STEPS / n as u64).clamp(1, MAX_BATCH as u64) as u32,
            ranked,
        };
        // The first step's `body_move` finds the body particles where the case put them.
        solver.index_bodies();
        Ok(solver)
    }

    /// The bodies' host state (poses and last loads), if the case has bodies.
    pub fn bodies(&self) -> Option<&BodySet> {
        self.bodies.as_ref().map(|h| &h.set)
    }

    pub fn time(&self) -> f64 {
        self.t_base + self.state.t_rel as f64
    }

    pub fn steps(&self) -> u64 {
        self.steps
    }

    pub fn dt(&self) -> f64 {
        self.state.dt_cfl as f64
    }

    /// How far the fluid went from the weakly-compressible regime in the steps since the
    /// peaks were last cleared ([`clear_density_peaks`](Self::clear_density_peaks)).
    pub fn density_variation(&self) -> DensityVariation {
        let peaks = &self.peaks;
        let fluid = self.fluid_counted();
        let share = |count: u32| count as f64 / fluid.max(1) as f64;
        DensityVariation {
            max: peaks.variation as f64,
            share_beyond_warn: share(peaks.beyond_warn),
            share_beyond_stop: share(peaks.beyond_stop),
        }
    }

    /// The fluid particles the density check's shares are of: those at the start and in the
    /// inlets' buffers (which become fluid without joining), those that joined since, less
    /// those drained.
    pub fn fluid_counted(&self) -> u64 {
        let joined = match &self.ranked {
            Some(ranked) => ranked.joined,
            None => self.state.net_joined(),
        };
        ((self.n_fluid_at_start as i64 + joined).max(0) as u64).saturating_sub(self.drained())
    }

    /// Starts the density peaks anew (after the run has looked at them for a probe interval).
    pub fn clear_density_peaks(&mut self) {
        self.peaks = DensityPeaks::default();
    }

    /// The first time step, after the warm-up: a positive normal f32 the clock can advance
    /// by. The loader refuses the cases it can tell (`case::runnable`); this catches the rest
    /// (a zero step ran "completed" with 0 steps, issue 64).
    fn check_first_dt(&self) -> Result<()> {
        let dt = self.state.dt_cfl;
        if dt.is_normal() && dt > 0.0 {
            return Ok(());
        }
        bail!(
            "the first time step is {dt:e} s (time.cfl × h over the fastest speed: the sound \
             speed, the flow, a body's motion, a solid's P wave), which the GPU cannot step by; \
             give realistic speeds, time.cfl about 0.2 and particles.dx_m"
        )
    }

    /// Particles that left the domain or became non-finite (not counting inlet particles that
    /// still wait behind their buffers, nor the fluid outlets removed, which sit in the same
    /// excluded slot).
    pub fn excluded(&self) -> u64 {
        if let Some(ranked) = &self.ranked {
            return ranked.excluded;
        }
        let dormant = (self.dormant_at_start as i64 - self.state.net_joined()).max(0) as u32;
        let s = &self.state;
        s.excluded.saturating_sub(dormant).saturating_sub(s.drained) as u64
    }

    /// Fluid particles the outlets have removed.
    pub fn drained(&self) -> u64 {
        if let Some(ranked) = &self.ranked {
            return ranked.drained;
        }
        self.state.drained as u64
    }

    pub fn particle_count(&self) -> u64 {
        self.buffers.n as u64
    }

    /// GPU memory of the run's buffers, in bytes.
    pub fn gpu_bytes(&self) -> u64 {
        self.buffers.bytes() + self.passes.bytes()
    }

    fn read_state(&self) -> Result<SimState> {
        let state = read::<SimState>(&self.device, &self.queue, &self.buffers.state, 1);
        // A lost device fails the wait; say why rather than how.
        self.faults.check()?;
        Ok(state?[0])
    }

    /// Takes `count` steps (as the GPU state says: dt 0 once arrived) and reads the state back.
    /// Without bodies the steps go in one submission; with bodies one at a time, each between
    /// the host's predictor and corrector of the bodies.
    fn take_steps(&mut self, count: u32) -> Result<()> {
        if self.ranked.is_some() {
            bail!("a subdomain steps with its neighbours: Solver::run_steps_ranked");
        }
        if self.bodies.is_none() {
            let encoder = self.encode_steps(count);
            self.queue.submit([encoder.finish()]);
            self.state = self.read_state()?;
            self.peaks.absorb(&self.state);
            return self.faults.check();
        }
        for _ in 0..count {
            self.step_with_bodies()?;
            self.peaks.absorb(&self.state);
        }
        Ok(())
    }

    /// One step with bodies: the host predicts every body to t + dt and uploads the poses, the
    /// GPU steps and sums the loads, the host reads back the state and the loads (the only
    /// per-step readback) and corrects the bodies.
    fn step_with_bodies(&mut self) -> Result<()> {
        let dt = self.predict_bodies();
        let encoder = self.encode_steps(1);
        let (state, partials) = self.submit_reading_loads(encoder)?;
        self.state = state;
        let gpu = self.passes.bodies.as_ref().expect("a run with bodies");
        let loads = gpu.loads(&partials);
        let host = &mut self.bodies.as_mut().expect("a run with bodies").set;
        host.correct(dt, &loads);
        Ok(())
    }

    /// The host's part of a step with bodies before the GPU's: every body predicted to
    /// t + dt and its pose uploaded; dt.
    fn predict_bodies(&mut self) -> f64 {
        let dt = self.state.dt as f64;
        let t_next = self.time() + dt;
        let host = &mut self.bodies.as_mut().expect("a run with bodies").set;
        let poses = host.predict(t_next, dt);
        let accelerations = host.accelerations(t_next);
        let gpu = self.passes.bodies.as_mut().expect("a run with bodies");
        gpu.upload(&self.queue, &self.grid, &poses, &accelerations);
        dt
    }

    /// Submits `encoder` with the state and the bodies' loads copied after it, and reads both
    /// back (the loads as `Bodies::loads_buffer` says: per workgroup, or per particle).
    fn submit_reading_loads(
        &self,
        mut encoder: wgpu::CommandEncoder,
    ) -> Result<(SimState, Vec<[f32; 4]>)> {
        let gpu = self.passes.bodies.as_ref().expect("a run with bodies");
        let staging = &self.bodies.as_ref().expect("a run with bodies").staging;
        let state_bytes = std::mem::size_of::<SimState>() as u64;
        let (loads, loads_bytes) = gpu.loads_buffer();
        encoder.copy_buffer_to_buffer(&self.buffers.state, 0, staging, 0, state_bytes);
        encoder.copy_buffer_to_buffer(loads, 0, staging, state_bytes, loads_bytes);
        self.queue.submit([encoder.finish()]);
        let bytes = map_read::<u8>(&self.device, staging);
        // A lost device fails the wait; say why rather than how.
        self.faults.check()?;
        let bytes = bytes?;
        let state = bytemuck::pod_read_unaligned(&bytes[..state_bytes as usize]);
        Ok((
            state,
            bytemuck::pod_collect_to_vec(&bytes[state_bytes as usize..]),
        ))
    }

    /// Records one compute pass with `record` and submits it.
    fn submit_pass(&self, label: &str, record: impl FnOnce(&mut wgpu::ComputePass<'_>)) {
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
        record(
            &mut encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(label),
                timestamp_writes: None,
            }),
        );
        self.queue.submit([encoder.finish()]);
    }

    /// Records where the arrays of the present parity hold each live body particle, after
    /// they were written or sorted outside a step (the next step's `body_move` reads it).
    fn index_bodies(&self) {
        if let Some(b) = &self.passes.bodies {
            self.submit_pass("body index", |pass| b.encode_index(pass, self.parity));
        }
    }

    /// Records `count` steps into one command encoder (with the profiler on, each stage in a
    /// timed pass of its own: one step per encoder).
    fn encode_steps(&mut self, count: u32) -> wgpu::CommandEncoder {
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("steps"),
            });
        let mut profiler = self.profiler.take();
        assert!(
            profiler.is_none() || count == 1,
            "profiling records one step per encoder"
        );
        for _ in 0..count {
            self.passes.cell_list.clear(&mut encoder, &self.buffers);
            let recorder = match profiler.as_mut() {
                Some(profiler) => Recorder::Timed {
                    encoder: &mut encoder,
                    profiler,
                },
                None => {
                    Recorder::Shared(encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: Some("step"),
                        timestamp_writes: None,
                    }))
                }
            };
            self.record_step(recorder);
        }
        if let Some(p) = &profiler {
            p.resolve(&mut encoder);
        }
        self.profiler = profiler;
        encoder
    }

    /// The dispatches one step records (counted by recording a step that is never submitted).
    pub fn dispatches_per_step(&mut self) -> u64 {
        let before = crate::gpu::kernel::dispatches_recorded();
        drop(self.encode_steps(1));
        // The step was not taken: the parity stays.
        self.parity = 1 - self.parity;
        crate::gpu::kernel::dispatches_recorded() - before
    }

    /// The names of a step's stages, in order (`Passes::record_step`); records nothing.
    pub fn stage_names(&self) -> Vec<&'static str> {
        let mut names = Vec::new();
        self.passes
            .record_step(Recorder::Names(&mut names), self.parity);
        names
    }

    /// The stages of one step (`Passes::record_step`); flips the parity.
    fn record_step(&mut self, r: Recorder<'_>) {
        self.passes.record_step(r, self.parity);
        self.parity = 1 - self.parity;
    }

    /// Re-bases the GPU's f32 clock on the host's f64 one, so that it only ever counts a short
    /// span (one batch): the state to upload (with the time to run still to be set).
    fn rebased_state(&mut self) -> SimState {
        self.t_base += self.state.t_rel as f64;
        let mut st = self.state;
        st.t_rel = 0.0;
        st.t_base = self.t_base as f32;
        // The GPU's density-variation peaks count from each upload; the host keeps theirs.
        st.density_variation_peak = 0.0;
        st.beyond_warn_peak = 0;
        st.beyond_stop_peak = 0;
        st
    }

    /// Sets the GPU state for steps up to `t_target` (the first of them as the GPU's
    /// `timestep` would choose it).
    fn start_targeted(&mut self, t_target: f64) {
        let mut st = self.rebased_state();
        let remaining = t_target - self.t_base;
        st.t_target_rel = remaining as f32;
        st.dt = if remaining > 1e-4 * st.dt_cfl as f64 {
            st.dt_cfl.min(remaining as f32)
        } else {
            0.0
        };
        self.queue
            .write_buffer(&self.buffers.state, 0, bytemuck::bytes_of(&st));
        self.state = st;
    }

    /// The steps to record at once on the way to the target time: enough to arrive at the
    /// present dt, and one more. Steps recorded past the arrival take dt = 0: they move nothing
    /// but sort and compute the rates, and the time step, at the state arrived at, from which
    /// the next interval starts.
    /// At most `batch_cap` steps ([`batch_steps`]).
    fn batch_to_target(&self) -> u32 {
        let left = self.state.t_target_rel - self.state.t_rel;
        batch_steps(left, self.state.dt_cfl, self.batch_cap)
    }

    /// Arrived at `t_target`: the host clock takes it exactly (the GPU's f32 clock is re-based
    /// on the next call anyway).
    fn arrive(&mut self, t_target: f64) {
        self.t_base = self.t_base.max(t_target);
        self.state.t_rel = 0.0;
    }

    /// Advances to exactly `t_target` (the last step is shortened to land on it).
    pub fn advance_to(&mut self, t_target: f64) -> Result<()> {
        self.advance_toward(t_target, &mut |_| false).map(|_| ())
    }

    /// Advances toward `t_target` as [`advance_to`](Self::advance_to) does, asking `halt`
    /// between batches of steps (at most [`BATCH_PARTICLE_STEPS`] of work each): when it says
    /// so, stops there, short of the target, and returns false. Such a state is one a
    /// checkpoint holds: `advance_toward` the same target again, in this process or a resumed
    /// one, continues it bit for bit (the next batch re-bases the f32 clock from it, as it
    /// would have). True once arrived.
    pub fn advance_toward(
        &mut self,
        t_target: f64,
        halt: &mut dyn FnMut(&Self) -> bool,
    ) -> Result<bool> {
        self.start_targeted(t_target);
        while self.state.dt > 0.0 {
            let batch = self.batch_to_target();
            let before = self.state.steps;
            self.take_steps(batch)?;
            self.steps += (self.state.steps - before) as u64;
            self.check_stability()?;
            // The GPU's dt of 0: arrived (its remainder within 1e-4 of a step).
            if self.state.dt <= 0.0 {
                break;
            }
            if halt(self) {
                return Ok(false);
            }
            self.start_targeted(t_target);
        }
        self.arrive(t_target);
        Ok(true)
    }

    /// Takes exactly `count` steps of CFL size (no target time), for benchmarks; waits for the
    /// GPU at the end and checks stability.
    pub fn run_steps(&mut self, count: u64) -> Result<()> {
        let st = self.start_untargeted();
        let mut left = count;
        while left > 0 {
            let batch = left.min(MAX_BATCH as u64) as u32;
            if self.bodies.is_some() {
                self.take_steps(batch)?;
            } else {
                // Benchmarks: no readback between batches.
                let encoder = self.encode_steps(batch);
                self.queue.submit([encoder.finish()]);
            }
            left -= batch as u64;
        }
        self.state = self.read_state()?;
        self.peaks.absorb(&self.state);
        self.steps += (self.state.steps - st.steps) as u64;
        self.check_stability()
    }

    /// Sets the GPU state for steps of CFL size with no target time (benchmarks) and returns it.
    fn start_untargeted(&mut self) -> SimState {
        self.clear_density_peaks();
        let mut st = self.rebased_state();
        st.t_target_rel = f32::MAX;
        st.dt = st.dt_cfl;
        self.queue
            .write_buffer(&self.buffers.state, 0, bytemuck::bytes_of(&st));
        self.state = st;
        st
    }

    /// Takes `count` steps as [`Solver::run_steps`] does, one submission each, with every stage
    /// in a timed pass of its own, and returns each stage's GPU time summed over the steps (in
    /// the step's order). The particles evolve exactly as without profiling.
    pub fn profile_steps(&mut self, count: u64) -> Result<Vec<StageTime>> {
        if self.profiler.is_none() {
            self.profiler = Some(Profiler::new(&self.device, &self.queue)?);
        }
        self.start_untargeted();
        let result = (0..count).try_for_each(|_| {
            let before = self.state.steps;
            self.take_steps(1)?;
            self.steps += (self.state.steps - before) as u64;
            self.profiler
                .as_mut()
                .expect("profiling")
                .collect(&self.device)
        });
        let profiler = self.profiler.take().expect("profiling");
        result?;
        self.check_stability()?;
        Ok(profiler.totals().to_vec())
    }

    /// Benchmark hook: records `reps` repetitions of `stage`, submits them and waits. After
    /// `CellList` alone the rates no longer match the particle order, so a solver timed that way
    /// is for benchmarking only.
    pub fn time_stage(&mut self, stage: Stage, reps: u64) -> Result<std::time::Duration> {
        if stage == Stage::Step {
            let start = std::time::Instant::now();
            self.run_steps(reps)?;
            return Ok(start.elapsed());
        }
        let start = std::time::Instant::now();
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("stage"),
            });
        for _ in 0..reps {
            if stage == Stage::CellList {
                self.passes.cell_list.clear(&mut encoder, &self.buffers);
            }
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("stage"),
                timestamp_writes: None,
            });
            match stage {
                Stage::CellList => {
                    self.passes.cell_list.encode(&mut pass, self.parity);
                    self.parity = 1 - self.parity;
                }
                Stage::Interaction | Stage::Step => {
                    self.passes.interaction.encode(&mut pass, self.parity)
                }
            }
        }
        self.queue.submit([encoder.finish()]);
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| anyhow::anyhow!("GPU wait failed: {e}"))?;
        Ok(start.elapsed())
    }

    fn check_stability(&self) -> Result<()> {
        let s = &self.state;
        let fail = |reason: String| -> Result<()> {
            Err(Unstable {
                step: self.steps,
                time_s: self.time(),
                reason,
            }
            .into())
        };
        if s.nan_count > 0 {
            return fail(format!(
                "{} fluid or solid particle(s) became non-finite; reduce time.cfl or check the case",
                s.nan_count
            ));
        }
        let excluded = self.excluded();
        if excluded as f64 > self.max_excluded_fraction * self.n_fluid as f64 {
            return fail(left_the_domain(
                excluded,
                self.n_fluid,
                self.max_excluded_fraction,
            ));
        }
        let density = self.density_variation();
        if density.beyond_stop() {
            return fail(format!(
                "{:.1} % of the fluid's particles are more than time.density_variation_stop = \
                 {:.1} % from ρ0 (up to {:.1} %): the flow is no longer weakly compressible; \
                 raise physics.sound_speed_coef or lower time.cfl",
                100.0 * density.share_beyond_stop,
                100.0 * self.density_variation_stop,
                100.0 * density.max
            ));
        }
        if s.dt_cfl.is_nan() || s.dt_cfl <= 1e-4 * self.initial_dt {
            return fail(format!(
                "the time step collapsed to {:e} s (started at {:e} s)",
                s.dt_cfl, self.initial_dt
            ));
        }
        Ok(())
    }

    /// Samples every probe at the current time.
    pub fn sample_probes(&self) -> Result<Vec<f64>> {
        if self.passes.probes.is_empty() {
            return Ok(Vec::new());
        }
        self.place_attached_probes();
        let mut encoder = self.device.create_command_encoder(&Default::default());
        self.passes
            .probes
            .encode(&mut encoder, &self.buffers, self.parity);
        self.queue.submit([encoder.finish()]);
        Ok(self.passes.probes.decode(&self.probe_words()?))
    }

    /// Samples the flood maps (`[maps]`) at the current time; nothing without maps.
    pub fn sample_maps(&self) -> Result<()> {
        let Some(maps) = &self.passes.flood_maps else {
            return Ok(());
        };
        let mut encoder = self.device.create_command_encoder(&Default::default());
        maps.encode(&self.queue, &mut encoder, self.parity, self.time());
        self.queue.submit([encoder.finish()]);
        self.faults.check()
    }

    /// The flood maps' cell records (`[maps]`), row by row from the south; None without maps.
    pub fn map_cells(&self) -> Result<Option<Vec<crate::layout::MapCell>>> {
        (self.passes.flood_maps.as_ref())
            .map(|m| m.read(&self.device, &self.queue))
            .transpose()
    }

    /// Puts back the flood maps' records of a checkpoint.
    pub fn restore_map_cells(&self, cells: &[crate::layout::MapCell]) -> Result<()> {
        match &self.passes.flood_maps {
            Some(m) => m.restore(&self.queue, cells),
            None => bail!("the checkpoint has flood maps and the case has no [maps]"),
        }
    }

    /// Moves the probes attached to bodies to where their bodies are now; returns them, all
    /// probes in order (None without attached probes).
    fn place_attached_probes(&self) -> Option<Vec<crate::scenario::Probe>> {
        let placed = self.attached_probes_placed()?;
        let defs = probes::probe_defs(
            &placed,
            self.grid.origin,
            &self.probe_faces,
            self.front_bins,
        );
        self.queue
            .write_buffer(&self.buffers.probes, 0, bytemuck::cast_slice(&defs));
        Some(placed)
    }

    /// Every probe in order, those attached to bodies where their bodies are now (None without
    /// attached probes).
    fn attached_probes_placed(&self) -> Option<Vec<crate::scenario::Probe>> {
        let (Some((list, centers)), Some(set)) = (&self.attached_probes, self.bodies()) else {
            return None;
        };
        let placed = list.iter().map(|p| match p.body {
            Some(k) => probes::moved(p, centers[k], &set.pose(k)),
            None => p.clone(),
        });
        Some(placed.collect())
    }

    /// The probes' raw words (`probe_out`) as the last encoding left them.
    fn probe_words(&self) -> Result<Vec<u32>> {
        let n = self.params.n_probes as usize;
        read::<u32>(&self.device, &self.queue, &self.buffers.probe_out, n)
    }

    /// World positions of the tracked points (`Scenario::points`, in order) at the current
    /// time, NaN for a particle that left the domain; empty without points. A subdomain
    /// samples with every rank of `ranks` together.
    pub fn sample_points(&self, ranks: Option<&dyn crate::ranks::Ranks>) -> Result<Vec<[f64; 3]>> {
        let Some(tracker) = &self.passes.points else {
            return Ok(Vec::new());
        };
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("track points"),
            });
        tracker.encode(&mut encoder, self.parity);
        self.queue.submit([encoder.finish()]);
        let pos = tracker.read(&self.device, &self.queue, ranks)?;
        self.faults.check()?;
        Ok(pos
            .iter()
            .map(|p| match p {
                Some(p) => self.grid.to_world(p.off, unpack_block(p.block)),
                None => [f64::NAN; 3],
            })
            .collect())
    }

    /// The first solid particle's id (the index base of `read_solid`).
    pub fn solid_id_base(&self) -> u32 {
        self.params.solid_id_base
    }

    /// Whether body `b` moves as prescribed, whatever its load (`kind = "fixed"`, `"sine"`,
    /// `"series"` or the moving tank; its GPU flag).
    pub fn body_is_kinematic(&self, b: u32) -> bool {
        (self.passes.bodies.as_ref()).is_some_and(|gpu| gpu.is_kinematic(b))
    }

    /// The body particle `id` belongs to, if any.
    pub fn body_of_id(&self, id: u32) -> Option<u32> {
        let gpu = self.passes.bodies.as_ref()?;
        id.checked_sub(self.params.body_id_base)
            .and_then(|k| gpu.body_of(k))
    }

    /// The velocity and acceleration at `x` of the solid particle `id` belongs to, as the GPU
    /// moves it this step: a body's rigid motion (from the last upload); zero for every other
    /// particle.
    pub fn wall_motion_of(&self, id: u32, x: [f64; 3]) -> [[f64; 3]; 2] {
        match (self.body_of_id(id), &self.passes.bodies) {
            (Some(b), Some(gpu)) => gpu.wall_motion(b, x),
            _ => [[0.0; 3]; 2],
        }
    }
}

/// Kind word of an excluded particle, for callers filtering outputs.
pub const EXCLUDED: u32 = KIND_EXCLUDED;

#[cfg(test)]
mod tests {
    use super::{batch_steps, left_the_domain};

    /// More particles out of the domain than there are fluid and solid ones: the message says
    /// that walls or bodies left too, rather than "702 of 75" (issue 64).
    #[test]
    fn a_stop_for_particles_out_of_the_domain_says_what_they_were() {
        let fluid = left_the_domain(8, 75, 0.05);
        assert!(fluid.starts_with("8 particles left the domain, more than 5 % of the case's 75"));
        assert!(!fluid.contains("walls"), "{fluid}");
        let walls = left_the_domain(702, 75, 0.05);
        assert!(
            walls.contains("walls or bodies the case moves left it too"),
            "{walls}"
        );
        assert!(!walls.contains("702 of 75"), "{walls}");
    }

    #[test]
    fn a_batch_is_the_steps_to_the_target_and_one_more_within_its_cap() {
        assert_eq!(batch_steps(1.0, 0.25, 64), 5);
        assert_eq!(batch_steps(0.0, 0.25, 64), 1);
        assert_eq!(batch_steps(-1.0, 0.25, 64), 1);
        assert_eq!(batch_steps(1.0, 1e-3, 64), 64);
        assert_eq!(batch_steps(1.0, 1e-3, 2), 2);
        // 2^32 steps and more away, a step of 0 or NaN: the cap, not an overflow.
        for (left, dt) in [(1.0, 1e-30), (f32::MAX, 1e-38), (1.0, 0.0), (1.0, f32::NAN)] {
            assert_eq!(batch_steps(left, dt, 64), 64, "{left} / {dt}");
        }
        assert_eq!(batch_steps(f32::NAN, 1.0, 64), 1);
    }
}

//! Running a scenario to its end with outputs: particle snapshots (VTU, and PNG when asked for)
//! at every output time, probe samples at every probe time, run.json at the end (also when the
//! run stops early). Progress is reported after every batch of steps to a [`Progress`].

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{bail, Context, Result};

use crate::body;
use crate::checkpoint::{
    fingerprint, rank_checkpoint_file, CaseSource, Checkpoint, CheckpointPolicy, OutputState,
    RankCheckpoint, CHECKPOINT_FILE,
};
use crate::decomposition::slabs_for;
use crate::gpu::GpuContext;
use crate::output::flood_maps::{ground_layer, map_layers, MAPS_DIR};
use crate::output::{
    FirstPositions, OutputDir, ParticleFile, Piece, ProbeWriter, RunSummary, SNAPSHOTS_DIR,
};
use crate::plot::color_scale::SnapshotField;
use crate::plot::snapshot::{draw_particle_file, SnapshotPainter};
use crate::progress::{Progress, RunStatus};
use crate::ranks::Ranks;
use crate::scenario::{GaugeSurface, Kind, OutputBoundary, ProbeKind, Scenario};
use crate::sph::{check_capacity, DensityVariation, Solver, Unstable};

/// Column name of a probe's CSV in a case of dimension `dim`.
pub fn probe_column(kind: &ProbeKind, dim: u32) -> &'static str {
    match kind {
        ProbeKind::Pressure { .. } | ProbeKind::WallPressure(_) => "pressure_pa",
        ProbeKind::Height {
            surface: GaugeSurface::FluidHalf,
            ..
        } => "height_m",
        ProbeKind::Height {
            surface: GaugeSurface::WaterFraction,
            ..
        } => "depth_m",
        ProbeKind::Front { .. } => "front_m",
        // Per metre of width in 2D.
        ProbeKind::Discharge { .. } if dim == 2 => "discharge_m2_s",
        ProbeKind::Discharge { .. } => "discharge_m3_s",
    }
}

/// Options of a run beyond its case.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Also draw every particle snapshot as DIR/snapshots/NNNNNN.png (3D: in perspective, on
    /// the run's device), coloured by this field.
    pub snapshot_png: Option<SnapshotField>,
    pub checkpoint: CheckpointPolicy,
    /// The case file and overrides, recorded in checkpoints for `wgsph resume`.
    pub source: Option<CaseSource>,
    /// Set (by a signal handler) to stop with a checkpoint after the batch of steps under way
    /// (between two probe times, too).
    pub interrupt: Option<Arc<AtomicBool>>,
    /// Stop with a checkpoint at the first probe time at or after this simulated time, as if
    /// interrupted (batch jobs with a time limit split a run this way; so do the tests).
    pub halt_at_s: Option<f64>,
    /// Seconds the case took to read and build into particles, for run.json
    /// (`case_build_s`).
    pub case_build_s: Option<f64>,
    /// Test hook: destroys the GPU device at the first probe interval after this simulated
    /// time, as a driver reset would.
    #[cfg(feature = "test-hooks")]
    pub lose_device_after_s: Option<f64>,
}

/// The particles of `sc` as run.json counts them: fluid, boundary (every wall treatment),
/// elastic solid, inlet.
pub fn particle_counts(sc: &Scenario) -> [u64; 4] {
    [
        sc.count(Kind::Fluid),
        sc.boundary_count(),
        sc.solid_count(),
        sc.count(Kind::Inlet),
    ]
    .map(|n| n as u64)
}

/// The scenario of the run in `dir`, loaded again as its run.json records it: its case file
/// (or `case` in its place) with its overrides. A built-in case ([`crate::case::BUILT_IN`])
/// whose file is not on disk here is loaded from the copy built into the binary. Errors when
/// run.json lacks what is needed, or when the case as loaded now has other particle counts
/// than the run had (the file changed since): the drawings would not be of that run.
pub fn scenario_of_run(dir: &Path, case: Option<&Path>) -> Result<Scenario> {
    let s = RunSummary::read(dir)?;
    let overrides = s.overrides.clone().unwrap_or_default();
    let file = match (case, &s.case_file) {
        (Some(c), _) => c.to_path_buf(),
        (None, Some(f)) => f.into(),
        (None, None) => bail!(
            "{} does not record the run's case file (a run made before it was recorded, or \
             through the library): pass it with --case FILE",
            dir.join(crate::output::RUN_SUMMARY_FILE).display()
        ),
    };
    let sc = match crate::case::built_in(&s.case, &file) {
        Some(b) if case.is_none() && !file.is_file() => b.load(&overrides)?,
        _ => crate::case::load(&file, &overrides)?,
    };
    let (had, has) = (
        [
            s.particles_fluid,
            s.particles_wall,
            s.particles_solid,
            s.particles_inlet,
        ],
        particle_counts(&sc),
    );
    if had != has {
        bail!(
            "{} with {overrides:?} now gives {has:?} particles (fluid, boundary, solid, inlet), \
             the run in {} had {had:?}: the case changed since the run; pass the file it was \
             made with as --case FILE",
            file.display(),
            dir.display()
        );
    }
    Ok(sc)
}

/// `checkpoint::fingerprint` of `sc` as run.json records it.
pub fn fingerprint_hex(sc: &Scenario) -> String {
    format!("{:016x}", fingerprint(sc))
}

/// What a finished (or stopped) run reports.
pub struct RunReport {
    pub summary: RunSummary,
    /// Set when the run stopped before its end (instability, GPU failure); outputs up to then
    /// and the last checkpoint are kept.
    pub stopped: Option<anyhow::Error>,
    /// Set when the run stopped on request (interrupt, `halt_at_s`) with a checkpoint at this
    /// simulated time; `wgsph resume` continues it.
    pub interrupted_at_s: Option<f64>,
    /// Set by [`resume`] when the run had already completed to the case's end: nothing was
    /// computed, `summary` is its run.json.
    pub already_complete: bool,
}

/// The summary of the run in `dir` if it completed to `sc`'s end time, from `sc` (the same
/// fingerprint): a resume has nothing to compute.
fn completed_run(dir: &Path, sc: &Scenario) -> Option<RunSummary> {
    let done = RunSummary::read(dir).ok()?;
    let end = sc.time.end_s;
    (done.status == "completed"
        && done.fingerprint.as_deref() == Some(&fingerprint_hex(sc))
        && done.simulated_time_s >= end - 1e-9 * end)
        .then_some(done)
}

/// Particle outputs at an output time: the VTU snapshot and, when asked for, its PNG (drawn
/// from the same read-back).
struct ParticleOutputs {
    out: OutputDir,
    png: Option<SnapshotPainter>,
    /// With `time.output_boundary = "first"`: the ids and positions of that first output (of
    /// this process's particles); the later outputs leave out the boundary particles still
    /// there.
    first_pos: Option<FirstPositions>,
    boundary_first: bool,
    /// A subdomain's piece holds its own particles only: its live ones and those excluded on
    /// it (waiting behind an inlet, drained, left the domain), not its free entries (where
    /// halo copies and the other ranks' particles were).
    own_only: bool,
    /// Over several ranks with `time.output_boundary = "first"` and pictures: the first
    /// output, joined, that the later ones are completed from to be drawn.
    first_drawn: Option<crate::output::Particles>,
}

impl ParticleOutputs {
    fn write(&mut self, solver: &Solver) -> Result<()> {
        let mut p = solver.read_particles()?;
        if self.own_only {
            p = p.without_id(solver.ids().free_id());
        }
        let index = self.out.snapshot_count();
        let fewer = match &self.first_pos {
            Some(first) if self.boundary_first => Some(p.without_unmoved_boundary(first)),
            _ => None,
        };
        let written = fewer.as_ref().unwrap_or(&p);
        let extra = written.extra_arrays();
        let extra: Vec<(&str, &[f32])> = extra.iter().map(|(n, v)| (*n, v.as_slice())).collect();
        self.out
            .write_snapshot(&written.snapshot(solver.time(), &extra))?;
        if self.boundary_first && self.first_pos.is_none() {
            self.first_pos = Some(FirstPositions::of(&p));
        }
        // The picture is of every particle (over ranks, drawn from the joined pieces:
        // `draw_published`).
        if let Some(view) = self.png.as_ref().filter(|_| !self.own_only) {
            let png = self.png_path(index);
            self.out.claim(&png)?;
            view.write_png(&png, &p.snapshot(solver.time(), &[]))?;
        }
        Ok(())
    }

    /// DIR/snapshots/NNNNNN.png of output `index`.
    fn png_path(&self, index: usize) -> std::path::PathBuf {
        (self.out.path().join(SNAPSHOTS_DIR)).join(format!("{index:06}.png"))
    }

    /// Over several ranks, on rank 0 (which alone holds the painter): the output just
    /// published, every rank's piece read back through its `.pvtu`, drawn as one whole run
    /// draws it (completed from the first output with `time.output_boundary = "first"`).
    fn draw_published(&mut self, sc: &Scenario) -> Result<()> {
        let index = self.out.snapshot_count().saturating_sub(1);
        let (Some(view), Some(file)) = (&self.png, self.out.snapshot_file(index)) else {
            return Ok(());
        };
        let png = self.png_path(index);
        self.out.claim(&png)?;
        let read = draw_particle_file(&file, self.first_drawn.as_ref(), sc, view, &png)?;
        if self.boundary_first && self.first_drawn.is_none() {
            self.first_drawn = Some(read.particles);
        }
        Ok(())
    }
}

/// The bodies' CSVs (`probes/body_<name>.csv`) and the tracked points'
/// (`probes/point_<name>.csv`: position and displacement from t = 0), one row per probe time.
struct BodyOutputs {
    csv: ProbeWriter,
    /// Whether this process writes them: one whole run, or rank 0 of several (every rank
    /// holds the same bodies).
    writes: bool,
    dim: u32,
    /// Initial position of every tracked point.
    point_starts: Vec<[f64; 3]>,
}

/// Columns of a tracked point's CSV (after `t_s`).
fn point_columns(dim: u32) -> Vec<String> {
    let axes = &["x", "y", "z"][..dim as usize];
    let at = axes.iter().map(|a| format!("{a}_m"));
    let moved = axes.iter().map(|a| format!("u{a}_m"));
    at.chain(moved).collect()
}

impl BodyOutputs {
    fn new(out: &mut OutputDir, sc: &Scenario, writes: bool) -> Result<Self> {
        let dim = sc.physics.dim;
        let bodies = sc
            .bodies
            .iter()
            .map(|b| (format!("body_{}", b.name), body::csv_columns(dim)));
        let points = sc
            .points
            .iter()
            .map(|p| (format!("point_{}", p.name), point_columns(dim)));
        let tables: Vec<(String, Vec<String>)> = bodies.chain(points).filter(|_| writes).collect();
        Ok(Self {
            csv: out.table_writer(&tables)?,
            writes,
            dim,
            // The case's positions: the GPU holds them to f32 offsets in their blocks (and
            // places body particles from the body's pose), so a point at rest reports a
            // displacement of a few nanometres.
            point_starts: sc
                .points
                .iter()
                .map(|p| sc.particles[p.particle as usize].pos)
                .collect(),
        })
    }

    /// Every rank together: the points are sampled where their particles are.
    fn record(&mut self, solver: &Solver, ranks: Option<&dyn Ranks>) -> Result<()> {
        let points = solver.sample_points(ranks)?;
        if !self.writes {
            return Ok(());
        }
        let mut rows: Vec<Vec<f64>> = Vec::new();
        if let Some(set) = solver.bodies() {
            rows.extend(
                (0..set.len()).map(|k| body::csv_row(&set.pose(k), &set.load(k), self.dim)),
            );
        }
        let d = self.dim as usize;
        for (x, x0) in points.iter().zip(&self.point_starts) {
            let moved = (0..d).map(|a| x[a] - x0[a]);
            rows.push(x[..d].iter().copied().chain(moved).collect());
        }
        if !rows.is_empty() {
            self.csv.record_rows(solver.time(), &rows)?;
        }
        Ok(())
    }
}

/// Sample times of a series with interval `every` up to `end` (inclusive, `end` always last,
/// also when `every` is longer than the run: an interval of 1e9 s sampled nothing, and the run
/// "completed" at t = 0, issue 64).
fn schedule(every: f64, end: f64) -> impl Iterator<Item = f64> {
    let n = (end / every - 1e-9).ceil().max(1.0) as u64;
    (1..=n).map(move |k| (k as f64 * every).min(end))
}

/// Runs `sc` on `ctx`, writing into `dir` (after removing an earlier run's outputs there);
/// `progress` hears once per probe interval.
pub fn run(
    ctx: &GpuContext,
    sc: &Scenario,
    dir: &Path,
    options: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<RunReport> {
    check_capacity(ctx, sc.particles.len())?;
    start(ctx, sc, dir, options, progress, None)
}

/// Runs `sc` split over `ranks` (issue 32; every rank calls this together, each on its own
/// `ctx`), into the one folder `dir`: each rank writes its piece of every particle output,
/// rank 0 the `.pvtu` naming the pieces, the series, the probes' tables (the values one whole
/// run gives) and run.json with every rank's part; each rank checkpoints its subdomain
/// ([`RankCheckpoint`]), and [`resume_on_ranks`] continues from them. A rank that fails
/// otherwise than by the run going unstable (which every rank sees at the same step) ends the
/// job, naming itself.
pub fn run_on_ranks(
    ctx: &GpuContext,
    sc: &Scenario,
    dir: &Path,
    options: &RunOptions,
    progress: &mut dyn Progress,
    ranks: &dyn Ranks,
) -> Result<RunReport> {
    start(ctx, sc, dir, options, progress, Some(ranks))
}

/// The run from t = 0: the folder taken and emptied of an earlier run's outputs (by rank 0,
/// before any other rank writes into it), the first outputs, then the steps.
fn start(
    ctx: &GpuContext,
    sc: &Scenario,
    dir: &Path,
    options: &RunOptions,
    progress: &mut dyn Progress,
    ranks: Option<&dyn Ranks>,
) -> Result<RunReport> {
    let first = ranks.is_none_or(|r| r.rank() == 0);
    // Held until this returns, on every path: no second run writes here meanwhile.
    let _lock = match first {
        true => {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create the output folder {}", dir.display()))?;
            let lock = crate::output::DirLock::acquire(dir)?;
            crate::output::clear_for_new_run(dir)?;
            Some(lock)
        }
        false => None,
    };
    if let Some(r) = ranks {
        r.barrier();
    }
    let mut runner = Runner::create(ctx, sc, dir, options, ranks)?;
    runner.write_particles()?;
    runner.record_probes()?;
    runner.solver.sample_maps()?;
    runner.bodies.record(&runner.solver, runner.ranks)?;
    runner.go(progress)
}

/// Continues the run in `dir` from its checkpoint. `sc` must be the scenario the run was built
/// from (checked by its fingerprint), except for its time control: a later `time.end_s`
/// extends the run, other intervals apply from the checkpoint on. On the same adapter the
/// continued run is bit-identical to an uninterrupted one.
pub fn resume(
    ctx: &GpuContext,
    sc: &Scenario,
    dir: &Path,
    options: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<RunReport> {
    resume_with(ctx, sc, dir, options, progress, None)
}

/// Continues the run over `ranks` in `dir` from its checkpoint (every rank together, as many
/// as wrote it), as [`resume`] continues one whole run: bit-identical to an uninterrupted run
/// over as many ranks on the same adapters.
pub fn resume_on_ranks(
    ctx: &GpuContext,
    sc: &Scenario,
    dir: &Path,
    options: &RunOptions,
    progress: &mut dyn Progress,
    ranks: &dyn Ranks,
) -> Result<RunReport> {
    resume_with(ctx, sc, dir, options, progress, Some(ranks))
}

/// This rank's checkpoint in `dir`: `checkpoint.bin` (one whole run, or rank 0 of several,
/// whose file is the manifest), or the file of rank r of the generation the manifest names.
/// Errors when the checkpoint is of another case or was written by another number of ranks.
fn checkpoint_of_rank(dir: &Path, sc: &Scenario, ranks: Option<&dyn Ranks>) -> Result<Checkpoint> {
    let path = dir.join(CHECKPOINT_FILE);
    let manifest = Checkpoint::read(&path)?;
    if manifest.fingerprint != fingerprint(sc) {
        bail!(
            "{} was written by a different case than '{}' (particles, physics, walls, probes or \
             bodies differ); resume with the case file and --set overrides the run started with",
            path.display(),
            sc.name
        );
    }
    let written_by = manifest.subdomain.as_ref().map_or(1, |s| s.ranks);
    let size = ranks.map_or(1, |r| r.size());
    if written_by != size {
        bail!(
            "{} was written by a run over {written_by} rank(s); resume it on as many \
             (`mpirun -np {written_by} wgsph resume {}`{})",
            path.display(),
            dir.display(),
            if written_by == 1 {
                ", or without mpirun"
            } else {
                ""
            }
        );
    }
    let (Some(r), Some(part)) = (ranks, &manifest.subdomain) else {
        return Ok(manifest);
    };
    if r.rank() == 0 {
        return Ok(manifest);
    }
    let mine = dir.join(rank_checkpoint_file(r.rank(), part.generation));
    let ck = Checkpoint::read(&mine)?;
    if ck.time_s.to_bits() != manifest.time_s.to_bits() || ck.fingerprint != manifest.fingerprint {
        bail!(
            "{} (t = {} s) does not belong with {} (t = {} s): the run was stopped while \
             checkpointing and the files are not of one set",
            mine.display(),
            ck.time_s,
            path.display(),
            manifest.time_s
        );
    }
    Ok(ck)
}

/// [`resume`] of one whole run or of every rank of several.
fn resume_with(
    ctx: &GpuContext,
    sc: &Scenario,
    dir: &Path,
    options: &RunOptions,
    progress: &mut dyn Progress,
    ranks: Option<&dyn Ranks>,
) -> Result<RunReport> {
    let first = ranks.is_none_or(|r| r.rank() == 0);
    // Held until this returns: no other run or resume writes here meanwhile. A folder that
    // is not there has no checkpoint either, which Checkpoint::read says.
    let _lock = (first && dir.is_dir())
        .then(|| crate::output::DirLock::acquire(dir))
        .transpose()?;
    if let Some(summary) = completed_run(dir, sc) {
        log::info!(
            "{}: the run in {} is already complete (t = {:.6} s, time.end_s = {} s): nothing to \
             compute; give a later time.end_s (--set time.end_s=...) to continue it",
            sc.name,
            dir.display(),
            summary.simulated_time_s,
            sc.time.end_s
        );
        return Ok(RunReport {
            summary,
            stopped: None,
            interrupted_at_s: None,
            already_complete: true,
        });
    }
    let ck = checkpoint_of_rank(dir, sc, ranks)?;
    let end = sc.time.end_s;
    if ck.time_s >= end + 1e-9 * end {
        // Not "completed": nothing would be computed, and run.json would say nothing of it
        // (issue 64).
        bail!(
            "the checkpoint in {} is at t = {} s, past time.end_s = {end} s: there is nothing \
             to compute; give a later time.end_s (--set time.end_s=...) to continue the run",
            dir.display(),
            ck.time_s
        );
    }
    if first {
        // A run's checkpoint: the outputs beside it are the run's, written before wgsph kept
        // a manifest of them if none lists them.
        crate::output::adopt_unlisted_outputs(dir)?;
    }
    if ck.adapter != ctx.info.name {
        log::warn!(
            "resuming on '{}' a run checkpointed on '{}': it continues, but not bit-identically",
            ctx.info.name,
            ck.adapter
        );
    }
    if ranks.is_none() {
        check_capacity(ctx, sc.particles.len())?;
    }
    let mut runner = Runner::create(ctx, sc, dir, options, ranks)?;
    runner
        .solver
        .restore_state(&ck.solver)
        .context("restoring the checkpoint")?;
    if let (Some(r), Some(part)) = (ranks, &ck.subdomain) {
        runner
            .solver
            .restore_subdomain(&part.ranked, r)
            .context("restoring the checkpoint's subdomain")?;
        // The next checkpoint goes to the other set: this one stays until it is complete.
        runner.generation = 1 - part.generation;
    }
    let o = ck.outputs;
    runner.outputs.out.resume_series(o.snapshots)?;
    if runner.outputs.boundary_first {
        // The later outputs leave out what the first one holds: read it back (over ranks,
        // every rank's piece of it, through its `.pvtu`).
        let first = (runner.outputs.out.snapshot_file(0))
            .context("the run's first particle output is not in its series")?;
        let first = ParticleFile::read(&first)?.particles;
        runner.outputs.first_pos = Some(FirstPositions::of(&first));
        if runner.ranks.is_some() && runner.outputs.png.is_some() {
            runner.outputs.first_drawn = Some(first);
        }
    }
    runner.probes.restore(&o.probe_tables)?;
    runner.bodies.csv.restore(&o.body_tables)?;
    runner.next_output = o.next_output_s;
    runner.wall_before = o.wall_s;
    runner.last_checkpoint = Some(ck.time_s);
    runner.density = DensityWatch {
        max: o.max_density_variation,
        episodes: o.density_episodes,
        ..DensityWatch::new(sc, ck.time_s)
    };
    runner.next_checkpoint_sim = options
        .checkpoint
        .every_sim_s
        .map(|every| ck.time_s + every);
    log::info!(
        "{}: resuming from t = {:.6} s (step {}) in {}",
        sc.name,
        ck.time_s,
        runner.solver.steps(),
        dir.display()
    );
    runner.go(progress)
}

/// A run in progress: the solver, its outputs and the schedule of outputs and checkpoints.
struct Runner<'a> {
    ctx: &'a GpuContext,
    sc: &'a Scenario,
    options: &'a RunOptions,
    solver: Solver,
    probes: ProbeWriter,
    bodies: BodyOutputs,
    outputs: ParticleOutputs,
    next_output: f64,
    next_checkpoint_sim: Option<f64>,
    /// Wall time spent before this process (resumed runs).
    wall_before: f64,
    started: Instant,
    last_checkpoint_wall: Instant,
    /// Simulated time of the last checkpoint written (or resumed from).
    last_checkpoint: Option<f64>,
    density: DensityWatch,
    /// The ranks of a run split over several (None: one whole run).
    ranks: Option<&'a dyn Ranks>,
    /// Of a run over several ranks: the set the next checkpoint's rank files go to
    /// ([`RankCheckpoint`]).
    generation: u32,
}

/// The weakly-compressible check of a run ([`DensityVariation`]) over each probe interval
/// against `time.density_variation_warn` and `_stop`.
#[derive(Clone, Copy, Debug)]
struct DensityWatch {
    warn: f64,
    stop: f64,
    /// The largest variation so far and the end of the probe interval it was seen in.
    max: (f64, f64),
    /// When the fluid last went beyond `warn` (None while within it), and the largest share
    /// of it beyond since.
    beyond: Option<(f64, f64)>,
    /// The end of the last probe interval that was sound (the fluid within `warn`, and no
    /// particle of it beyond `stop`: a blow-up can start in a few particles): a run stopped
    /// unstable keeps its outputs up to here.
    last_sound_s: f64,
    /// How many times the fluid went beyond `warn`.
    episodes: u32,
}

impl DensityWatch {
    fn new(sc: &Scenario, t0: f64) -> Self {
        Self {
            warn: sc.time.density_variation_warn,
            stop: sc.time.density_variation_stop,
            max: (0.0, t0),
            beyond: None,
            last_sound_s: t0,
            episodes: 0,
        }
    }

    /// The largest variation `d` shows, seen at `t`.
    fn record_max(&mut self, d: DensityVariation, t: f64) {
        if d.max > self.max.0 {
            self.max = (d.max, t);
        }
    }

    /// Takes the check `d` of the interval ending at `t`, warning when the fluid first goes
    /// beyond the limit and saying when it comes back (later episodes at debug level: an
    /// impact can take a run across the limit and back several times; the summary counts).
    fn observe(&mut self, name: &str, d: DensityVariation, t: f64) {
        self.record_max(d, t);
        // The first crossing and return are logged; later ones at debug level.
        let level = |first: u32, loud| {
            if self.episodes <= first {
                loud
            } else {
                log::Level::Debug
            }
        };
        match (d.beyond_warn(), self.beyond) {
            (true, None) => {
                log::log!(
                    level(0, log::Level::Warn),
                    "{name}: at t = {t:.4} s {:.1} % of the fluid's particles are more than \
                     time.density_variation_warn = {:.1} % from ρ0 (up to {:.1} %), beyond the \
                     weakly-compressible limit: raise physics.sound_speed_coef (c0 at least 10 \
                     times the fastest flow) or lower time.cfl",
                    100.0 * d.share_beyond_warn,
                    100.0 * self.warn,
                    100.0 * d.max
                );
                self.beyond = Some((t, d.share_beyond_warn));
                self.episodes += 1;
            }
            (true, Some((since, share))) => {
                self.beyond = Some((since, share.max(d.share_beyond_warn)));
            }
            (false, Some((since, share))) => {
                log::log!(
                    level(1, log::Level::Info),
                    "{name}: at t = {t:.4} s the fluid is back within ±{:.1} % of ρ0 (beyond it \
                     since t = {since:.4} s, with up to {:.1} % of its particles)",
                    100.0 * self.warn,
                    100.0 * share
                );
                self.beyond = None;
            }
            (false, None) => {}
        }
        if !d.beyond_warn() && d.max <= self.stop {
            self.last_sound_s = t;
        }
    }

    /// The run summary's warning, if the fluid ever went beyond the limit.
    fn warning(&self) -> Option<String> {
        (self.episodes > 0).then(|| {
            format!(
                "more than {:.0} % of the fluid's particles were beyond \
                 time.density_variation_warn = {:.1} % from ρ0 (the weakly-compressible limit) \
                 {} time(s) during the run; the largest variation was {:.1} % at t ≈ {:.4} s",
                100.0 * DensityVariation::SHARE,
                100.0 * self.warn,
                self.episodes,
                100.0 * self.max.0,
                self.max.1
            )
        })
    }
}

impl<'a> Runner<'a> {
    /// Creates the output writers and the solver (at t = 0).
    fn create(
        ctx: &'a GpuContext,
        sc: &'a Scenario,
        dir: &Path,
        options: &'a RunOptions,
        ranks: Option<&'a dyn Ranks>,
    ) -> Result<Self> {
        let mut out = match ranks {
            Some(r) => OutputDir::for_piece(
                dir,
                Piece {
                    rank: r.rank(),
                    ranks: r.size(),
                },
            )?,
            None => OutputDir::create(dir)?,
        };
        let first = ranks.is_none_or(|r| r.rank() == 0);
        let png = match options.snapshot_png {
            // Over several ranks rank 0 draws (`ParticleOutputs::draw_published`).
            Some(field) if first => {
                let pngs = dir.join(SNAPSHOTS_DIR);
                std::fs::create_dir_all(&pngs)
                    .with_context(|| format!("cannot create {}", pngs.display()))?;
                Some(SnapshotPainter::for_scenario(Some(ctx), sc, field, false)?)
            }
            _ => None,
        };
        // Rank 0 writes the tables.
        let names: Vec<(String, String)> = (sc.probes.iter())
            .filter(|_| first)
            .map(|p| {
                (
                    p.name.clone(),
                    probe_column(&p.kind, sc.physics.dim).to_string(),
                )
            })
            .collect();
        let probes = out.probe_writer(&names)?;
        let solver = match ranks {
            Some(r) => Solver::subdomain(ctx, sc, &slabs_for(sc, r.size())?, r),
            None => Solver::new(ctx, sc),
        }
        .context("setting up the GPU solver")?;
        let bodies = BodyOutputs::new(&mut out, sc, first)?;
        let some = |n: usize, what: &str| match n {
            0 => String::new(),
            n => format!(", {n} {what}"),
        };
        let solid = some(sc.solid_count(), "solid");
        let inlet = some(sc.count(Kind::Inlet), "inlet");
        let ids = solver.ids();
        let wide = match ids.wide {
            true => format!(", wide ids ({} bits in the code word)", ids.low_bits),
            false => String::new(),
        };
        log::info!(
            "{}: {} particles ({} fluid, {} boundary{solid}{inlet}{wide}) on {}, {:.1} bytes/particle on the GPU, first dt {:.3e} s",
            sc.name,
            sc.particles.len(),
            sc.count(Kind::Fluid),
            sc.boundary_count(),
            ctx.describe(),
            solver.gpu_bytes() as f64 / sc.particles.len() as f64,
            solver.dt()
        );
        for w in sc.warnings.iter().filter(|_| first) {
            log::warn!("{}: {w}", sc.name);
        }
        Ok(Self {
            ctx,
            sc,
            options,
            solver,
            probes,
            bodies,
            outputs: ParticleOutputs {
                out,
                png,
                first_pos: None,
                boundary_first: sc.time.output_boundary == OutputBoundary::First,
                own_only: ranks.is_some(),
                first_drawn: None,
            },
            next_output: sc.time.output_every_s.min(sc.time.end_s),
            next_checkpoint_sim: options.checkpoint.every_sim_s,
            wall_before: 0.0,
            started: Instant::now(),
            last_checkpoint_wall: Instant::now(),
            last_checkpoint: None,
            density: DensityWatch::new(sc, 0.0),
            ranks,
            generation: 0,
        })
    }

    /// Whether this process writes the run's tables and run.json: one whole run, or rank 0.
    fn first(&self) -> bool {
        self.ranks.is_none_or(|r| r.rank() == 0)
    }

    /// The particle outputs at the present time; over several ranks, every rank's piece, then
    /// (rank 0) the `.pvtu` and the series.
    fn write_particles(&mut self) -> Result<()> {
        self.outputs.write(&self.solver)?;
        if let Some(r) = self.ranks {
            r.barrier();
            self.outputs.out.publish_pieces()?;
            self.outputs.draw_published(self.sc)?;
        }
        Ok(())
    }

    /// Samples the probes (every rank together) and records them (rank 0).
    fn record_probes(&mut self) -> Result<()> {
        if self.sc.probes.is_empty() {
            return Ok(());
        }
        let values = match self.ranks {
            Some(r) => self.solver.sample_probes_ranked(r)?,
            None => self.solver.sample_probes()?,
        };
        if self.first() {
            self.probes.record(self.solver.time(), &values)?;
        }
        Ok(())
    }

    /// The flood maps so far (`[maps]`): `DIR/maps/*.asc` and their pictures.
    fn write_maps(&mut self) -> Result<()> {
        let (Some(maps), Some(cells)) = (&self.sc.maps, self.solver.map_cells()?) else {
            return Ok(());
        };
        let origin = self.sc.world_origin_m;
        let ground = ground_layer(maps, origin);
        let layers = map_layers(maps, &cells, origin);
        let title = format!("{}, t = 0 to {:.4} s", self.sc.name, self.solver.time());
        let out = &mut self.outputs.out;
        out.write_maps(std::slice::from_ref(&ground))?;
        out.write_maps(&layers)?;
        for layer in &layers {
            let path = out
                .path()
                .join(MAPS_DIR)
                .join(format!("{}.png", layer.stem));
            out.claim(&path)?;
            crate::plot::flood_map::draw_map(
                &path,
                &layer.grid,
                &ground.grid,
                &title,
                layer.label,
            )?;
        }
        Ok(())
    }

    /// Every rank's part of the run, on rank 0 (every rank together); None for one whole run.
    fn rank_summaries(&self) -> Result<Option<Vec<crate::ranks::RankSummary>>> {
        let Some(r) = self.ranks else {
            return Ok(None);
        };
        // Per step over the whole run (a resumed one's counts go on from its checkpoint).
        let adapter = self.ctx.describe();
        let since = Default::default();
        Ok(Some(self.solver.rank_summaries(&since, &adapter, r)?))
    }

    fn status(&self) -> RunStatus {
        RunStatus {
            time_s: self.solver.time(),
            end_s: self.sc.time.end_s,
            dt_s: self.solver.dt(),
            steps: self.solver.steps(),
            particles: self.sc.particles.len() as u64,
            excluded: self.solver.excluded(),
            drained: self.solver.drained(),
            outputs: self.outputs.out.snapshot_count(),
            wall_s: self.wall_before + self.started.elapsed().as_secs_f64(),
        }
    }

    /// Steps from the solver's time to the end, recording outputs, probes and checkpoints.
    fn go(mut self, progress: &mut dyn Progress) -> Result<RunReport> {
        let sc = self.sc;
        let t0 = self.solver.time();
        let mut stopped = None;
        let mut interrupted_at_s = None;
        for t in schedule(sc.time.probe_every_s, sc.time.end_s).filter(|&t| t > t0) {
            // Any failure from here on (instability, GPU failure, a full disk) ends the run
            // with what was written so far and the last checkpoint kept.
            match self.probe_interval(t, progress) {
                Err(e) => {
                    // Every rank sees the run go unstable at the same step; anything else
                    // befalls one rank, and the others would wait for it.
                    if let Some(r) = self
                        .ranks
                        .filter(|_| e.downcast_ref::<Unstable>().is_none())
                    {
                        r.abort(&e);
                    }
                    stopped = Some(e);
                    break;
                }
                Ok(halt) => {
                    progress.update(&self.status());
                    if halt {
                        interrupted_at_s = Some(self.solver.time());
                        break;
                    }
                }
            }
        }
        if stopped.is_some() {
            // The interval the run stopped in, unobserved.
            let t = self.solver.time();
            self.density.record_max(self.solver.density_variation(), t);
        }
        let trimmed = match &stopped {
            Some(e) if e.downcast_ref::<Unstable>().is_some() => self.keep_sound_outputs()?,
            _ => None,
        };
        self.probes.flush()?;
        self.bodies.csv.flush()?;
        self.write_maps()?;
        let end = self.status();
        progress.finish(&end);
        let resume_hint = match self.last_checkpoint {
            Some(t) => format!(
                "; the last checkpoint (t = {t:.6} s) is kept: continue with `wgsph resume {}`",
                self.outputs.out.path().display()
            ),
            None => String::new(),
        };
        if let Some(e) = &stopped {
            // The case's doubts (a speed beyond c0/10, say) may be the cause the stop can't tell.
            let doubts = match (e.downcast_ref::<Unstable>(), sc.warnings.len()) {
                (Some(_), n) if n > 0 => format!("; the case's {n} warning(s) may say why"),
                _ => String::new(),
            };
            log::error!(
                "stopped: {e:#}{doubts}; outputs up to t = {:.6} s are kept{}{resume_hint}",
                self.outputs.out.snapshots().last().map_or(0.0, |(t, _)| *t),
                trimmed.as_deref().unwrap_or_default()
            );
        }
        let mut warnings = sc.warnings.clone();
        warnings.extend(self.density.warning());
        if let Some(t) = interrupted_at_s {
            log::warn!("interrupted at t = {t:.6} s{resume_hint}");
        }
        let n = sc.particles.len() as f64;
        let counts = particle_counts(sc);
        let ranks = self.rank_summaries()?;
        let (wall_s, gpu_bytes) = match self.ranks {
            // The slowest rank's time; every rank's buffers.
            Some(r) => (
                -r.min(-end.wall_s),
                r.sum_in_rank_order(&[self.solver.gpu_bytes() as f64])[0],
            ),
            None => (end.wall_s, self.solver.gpu_bytes() as f64),
        };
        let end = RunStatus { wall_s, ..end };
        let summary = RunSummary {
            case: sc.name.clone(),
            adapter: self.ctx.info.name.clone(),
            backend: format!("{:?}", self.ctx.info.backend),
            dimension: sc.physics.dim,
            particles_fluid: counts[0],
            particles_wall: counts[1],
            particles_solid: counts[2],
            particles_inlet: counts[3],
            particles_excluded: end.excluded,
            particles_drained: end.drained,
            steps: end.steps,
            simulated_time_s: end.time_s,
            wall_time_s: end.wall_s,
            particle_steps_per_s: end.particle_steps_per_s(),
            gpu_bytes_per_particle: gpu_bytes / n,
            outputs: end.outputs as u64,
            status: match (&stopped, interrupted_at_s) {
                (Some(e), _) => format!("stopped: {e:#}{resume_hint}"),
                (None, Some(_)) => format!("interrupted{resume_hint}"),
                (None, None) => "completed".into(),
            },
            warnings,
            max_density_variation: Some(self.density.max.0),
            overrides: self.options.source.as_ref().map(|s| s.overrides.clone()),
            fingerprint: Some(fingerprint_hex(sc)),
            case_file: self
                .options
                .source
                .as_ref()
                .map(|s| s.path.to_string_lossy().into_owned()),
            ranks,
            world_origin_m: sc.world_origin_m,
            case_build_s: self.options.case_build_s,
        };
        if self.first() {
            self.outputs.out.write_run_summary(&summary)?;
        }
        Ok(RunReport {
            summary,
            stopped,
            interrupted_at_s,
            already_complete: false,
        })
    }

    /// A run stopped unstable: drops the outputs after the last sound probe interval
    /// ([`DensityWatch::last_sound_s`]: particle files, PNGs, probe and body rows), which
    /// already show the instability. Says what it dropped.
    fn keep_sound_outputs(&mut self) -> Result<Option<String>> {
        let t = self.density.last_sound_s;
        let dropped = self.outputs.out.truncate_after(t)?;
        for index in dropped.clone() {
            let png = self
                .outputs
                .out
                .path()
                .join(SNAPSHOTS_DIR)
                .join(format!("{index:06}.png"));
            // Absent when the run draws no pictures.
            let _ = std::fs::remove_file(png);
        }
        self.probes.truncate_after(t);
        self.bodies.csv.truncate_after(t);
        Ok((t < self.solver.time()).then(|| {
            format!(
                " ({} particle output(s) and the probe rows after t = {t:.6} s, the last sound \
                 state (within ±{:.1} % of ρ0 but for at most 1 % of the fluid, none beyond \
                 ±{:.1} %), were removed)",
                dropped.len(),
                100.0 * self.density.warn,
                100.0 * self.density.stop
            )
        }))
    }

    /// Advances to the probe time `t` and writes what is due there: probe rows, particle
    /// outputs, a checkpoint. True when the run must stop here on request (with a checkpoint),
    /// which a signal makes it do between two batches of steps, short of `t`.
    fn probe_interval(&mut self, t: f64, progress: &mut dyn Progress) -> Result<bool> {
        let sc = self.sc;
        let every_out = sc.time.output_every_s;
        #[cfg(feature = "test-hooks")]
        if self
            .options
            .lose_device_after_s
            .is_some_and(|lose| self.solver.time() >= lose)
        {
            self.solver.lose_device();
        }
        if !self.advance(t, progress)? {
            self.write_checkpoint()?;
            return Ok(true);
        }
        if self.first() {
            self.density.observe(
                &sc.name,
                self.solver.density_variation(),
                self.solver.time(),
            );
        } else {
            self.density
                .record_max(self.solver.density_variation(), self.solver.time());
        }
        self.solver.clear_density_peaks();
        self.record_probes()?;
        self.solver.sample_maps()?;
        self.bodies.record(&self.solver, self.ranks)?;
        if self.solver.time() >= self.next_output - 1e-9 * every_out {
            self.write_particles()?;
            self.probes.flush()?;
            self.bodies.csv.flush()?;
            log::debug!(
                "output {} at t = {:.4} s",
                self.outputs.out.snapshot_count() - 1,
                self.solver.time()
            );
            self.next_output = (self.next_output + every_out).min(sc.time.end_s);
        }
        let mut halt = self.interrupted()
            || self
                .options
                .halt_at_s
                .is_some_and(|h| self.solver.time() >= h - 1e-12 * sc.time.end_s);
        let end = self.solver.time() >= sc.time.end_s;
        let mut due = self.checkpoint_due();
        if let Some(r) = self.ranks {
            // Every rank stops, or checkpoints, where any one would (a signal, or a wall-clock
            // interval, reaches them at different steps).
            let any = |yes: bool| r.min(if yes { 0.0 } else { 1.0 }) == 0.0;
            (halt, due) = (any(halt), any(due));
        }
        if !end && (halt || due) {
            self.write_checkpoint()?;
        }
        Ok(halt && !end)
    }

    /// Advances the solver to the probe time `t`, telling `progress` where it stands and
    /// looking for a signal to stop after every batch of steps (a few seconds of work at
    /// most, whatever the probe interval: issue 64); false when a signal stopped it short of
    /// `t`, in a state a checkpoint holds and a resume continues bit for bit.
    fn advance(&mut self, t: f64, progress: &mut dyn Progress) -> Result<bool> {
        let at_start = self.status();
        let (started, wall_before) = (self.started, self.wall_before);
        let interrupt = self.options.interrupt.clone();
        let mut between = |s: &Solver| {
            progress.update(&RunStatus {
                time_s: s.time(),
                dt_s: s.dt(),
                steps: s.steps(),
                excluded: s.excluded(),
                drained: s.drained(),
                wall_s: wall_before + started.elapsed().as_secs_f64(),
                ..at_start.clone()
            });
            interrupt
                .as_ref()
                .is_some_and(|f| f.load(Ordering::Relaxed))
        };
        match self.ranks {
            Some(r) => self.solver.advance_toward_ranked(t, r, &mut between),
            None => self.solver.advance_toward(t, &mut between),
        }
    }

    fn interrupted(&self) -> bool {
        self.options
            .interrupt
            .as_ref()
            .is_some_and(|f| f.load(Ordering::Relaxed))
    }

    fn checkpoint_due(&mut self) -> bool {
        let t = self.solver.time();
        let policy = self.options.checkpoint;
        let mut due = false;
        if let (Some(next), Some(every)) = (self.next_checkpoint_sim, policy.every_sim_s) {
            if t >= next - 1e-9 * every {
                due = true;
                // The next one is due a full interval after this probe time.
                self.next_checkpoint_sim = Some(t + every);
            }
        }
        if let Some(every) = policy.every_wall_s {
            due |= self.last_checkpoint_wall.elapsed().as_secs_f64() >= every;
        }
        due
    }

    /// Writes DIR/checkpoint.bin with the solver state and the outputs so far, after making
    /// the outputs durable (so the files on disk match the checkpoint).
    fn write_checkpoint(&mut self) -> Result<()> {
        self.probes.flush()?;
        self.bodies.csv.flush()?;
        let ck = Checkpoint {
            case_name: self.sc.name.clone(),
            fingerprint: fingerprint(self.sc),
            source: self.options.source.clone(),
            snapshot_field: self.options.snapshot_png.map(|f| f.to_string()),
            adapter: self.ctx.info.name.clone(),
            policy: Some(self.options.checkpoint),
            time_s: self.solver.time(),
            outputs: OutputState {
                next_output_s: self.next_output,
                snapshots: self.outputs.out.snapshots().to_vec(),
                probe_tables: self.probes.texts(),
                body_tables: self.bodies.csv.texts(),
                wall_s: self.wall_before + self.started.elapsed().as_secs_f64(),
                max_density_variation: self.density.max,
                density_episodes: self.density.episodes,
            },
            solver: self.solver.save_state()?,
            subdomain: self.ranks.map(|r| RankCheckpoint {
                rank: r.rank(),
                ranks: r.size(),
                generation: self.generation,
                ranked: self.solver.ranked().cloned().unwrap_or_default(),
            }),
        };
        let dir = self.outputs.out.path().to_path_buf();
        let mut write = |name: &str| -> Result<()> {
            let path = dir.join(name);
            self.outputs.out.claim(&path)?;
            ck.write(&path)
        };
        match self.ranks {
            None => write(CHECKPOINT_FILE)?,
            Some(r) => {
                // The other ranks' files first; rank 0's, the manifest naming them, once
                // they are all complete.
                if r.rank() != 0 {
                    write(&rank_checkpoint_file(r.rank(), self.generation))?;
                }
                r.barrier();
                if r.rank() == 0 {
                    write(CHECKPOINT_FILE)?;
                }
                self.generation = 1 - self.generation;
            }
        }
        self.last_checkpoint = Some(ck.time_s);
        self.last_checkpoint_wall = Instant::now();
        log::debug!("checkpoint at t = {:.6} s", ck.time_s);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::schedule;

    #[test]
    fn schedule_ends_exactly_at_end() {
        let t: Vec<f64> = schedule(0.1, 0.25).collect();
        assert_eq!(t.len(), 3);
        assert!((t[0] - 0.1).abs() < 1e-15 && (t[2] - 0.25).abs() < 1e-15);
        assert_eq!(schedule(0.1, 0.3).count(), 3);
        for every in [0.3, 1.0, 1e9, 1e300, f64::MAX] {
            assert_eq!(schedule(every, 0.3).collect::<Vec<_>>(), [0.3], "{every}");
        }
    }
}

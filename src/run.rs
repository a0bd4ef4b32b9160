//! Running a scenario to its end with outputs: particle snapshots (VTU, and PNG when asked for)
//! at every output time, probe samples at every probe time, run.json at the end (also when the
//! run stops early). Progress is reported once per probe interval to a [`Progress`].

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};

use crate::body;
use crate::gpu::GpuContext;
use crate::output::{OutputDir, ProbeWriter, RunSummary, Snapshot, SNAPSHOTS_DIR};
use crate::plot::snapshot::{SnapshotField, SnapshotView};
use crate::progress::{Progress, RunStatus};
use crate::scenario::{Kind, ProbeKind, Scenario};
use crate::sph::Solver;

/// Column name of a probe's CSV.
pub fn probe_column(kind: &ProbeKind) -> &'static str {
    match kind {
        ProbeKind::Pressure { .. } => "pressure_pa",
        ProbeKind::Height { .. } => "height_m",
        ProbeKind::Front { .. } => "front_m",
    }
}

/// Optional outputs of a run.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Also draw every particle snapshot as DIR/snapshots/NNNNNN.png, coloured by this field.
    pub snapshot_png: Option<SnapshotField>,
}

/// What a finished (or stopped) run reports.
pub struct RunReport {
    pub summary: RunSummary,
    /// Set when the run stopped before its end (instability); outputs up to then are kept.
    pub stopped: Option<anyhow::Error>,
}

/// Particle outputs at an output time: the VTU snapshot and, when asked for, its PNG (drawn
/// from the same read-back).
struct ParticleOutputs {
    out: OutputDir,
    png: Option<SnapshotView>,
}

impl ParticleOutputs {
    fn write(&mut self, solver: &Solver) -> Result<()> {
        let p = solver.read_particles()?;
        let extra = match &p.energy {
            Some(e) => vec![("energy", e.as_slice())],
            None => vec![],
        };
        let snap = Snapshot {
            time_s: solver.time(),
            pos: &p.pos,
            vel: &p.vel,
            rho: &p.rho,
            pressure: &p.pressure,
            kind: &p.kind,
            id: &p.id,
            extra: &extra,
        };
        let index = self.out.snapshot_count();
        self.out.write_snapshot(&snap)?;
        if let Some(view) = &self.png {
            let path = self
                .out
                .path()
                .join(SNAPSHOTS_DIR)
                .join(format!("{index:06}.png"));
            view.write_png(&path, &snap)?;
        }
        Ok(())
    }
}

/// The bodies' CSVs (`probes/body_<name>.csv`), one row per probe time.
struct BodyOutputs {
    csv: ProbeWriter,
    dim: u32,
}

impl BodyOutputs {
    fn new(out: &OutputDir, sc: &Scenario) -> Result<Self> {
        let tables: Vec<(String, Vec<String>)> = sc
            .bodies
            .iter()
            .map(|b| {
                (
                    format!("body_{}", b.name),
                    body::csv_columns(sc.physics.dim),
                )
            })
            .collect();
        Ok(Self {
            csv: out.table_writer(&tables)?,
            dim: sc.physics.dim,
        })
    }

    fn record(&mut self, solver: &Solver) -> Result<()> {
        if let Some(set) = solver.bodies() {
            let rows: Vec<Vec<f64>> = (0..set.len())
                .map(|k| body::csv_row(&set.pose(k), &set.load(k), self.dim))
                .collect();
            self.csv.record_rows(solver.time(), &rows)?;
        }
        Ok(())
    }
}

/// Sample times of a series with interval `every` up to `end` (inclusive, `end` always last).
fn schedule(every: f64, end: f64) -> impl Iterator<Item = f64> {
    let n = (end / every - 1e-9).ceil().max(0.0) as u64;
    (1..=n).map(move |k| (k as f64 * every).min(end))
}

/// Runs `sc` on `ctx`, writing into `dir`; `progress` hears once per probe interval.
pub fn run(
    ctx: &GpuContext,
    sc: &Scenario,
    dir: &Path,
    options: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<RunReport> {
    let out = OutputDir::create(dir)?;
    let png = match options.snapshot_png {
        Some(field) => {
            let pngs = dir.join(SNAPSHOTS_DIR);
            std::fs::create_dir_all(&pngs)
                .with_context(|| format!("cannot create {}", pngs.display()))?;
            Some(SnapshotView::for_scenario(sc, field)?)
        }
        None => None,
    };
    let names: Vec<(String, String)> = sc
        .probes
        .iter()
        .map(|p| (p.name.clone(), probe_column(&p.kind).to_string()))
        .collect();
    let mut probes = out.probe_writer(&names)?;
    let mut bodies = BodyOutputs::new(&out, sc)?;
    let mut outputs = ParticleOutputs { out, png };
    let mut solver = Solver::new(ctx, sc).context("setting up the GPU solver")?;
    log::info!(
        "{}: {} particles ({} fluid, {} wall) on {}, {:.1} bytes/particle on the GPU, first dt {:.3e} s",
        sc.name,
        sc.particles.len(),
        sc.count(Kind::Fluid),
        sc.count(Kind::Wall),
        ctx.describe(),
        solver.gpu_bytes() as f64 / sc.particles.len() as f64,
        solver.dt()
    );
    outputs.write(&solver)?;
    if !sc.probes.is_empty() {
        probes.record(0.0, &solver.sample_probes()?)?;
    }
    bodies.record(&solver)?;
    let started = Instant::now();
    let status = |solver: &Solver, outputs: &ParticleOutputs| RunStatus {
        time_s: solver.time(),
        end_s: sc.time.end_s,
        dt_s: solver.dt(),
        steps: solver.steps(),
        particles: sc.particles.len() as u64,
        excluded: solver.excluded(),
        outputs: outputs.out.snapshot_count(),
        wall_s: started.elapsed().as_secs_f64(),
    };
    let every_out = sc.time.output_every_s;
    let mut next_output = every_out.min(sc.time.end_s);
    let mut stopped = None;
    for t in schedule(sc.time.probe_every_s, sc.time.end_s) {
        if let Err(e) = solver.advance_to(t) {
            stopped = Some(e);
            break;
        }
        if !sc.probes.is_empty() {
            probes.record(solver.time(), &solver.sample_probes()?)?;
        }
        bodies.record(&solver)?;
        if solver.time() >= next_output - 1e-9 * every_out {
            outputs.write(&solver)?;
            probes.flush()?;
            bodies.csv.flush()?;
            log::debug!(
                "output {} at t = {:.4} s",
                outputs.out.snapshot_count() - 1,
                solver.time()
            );
            next_output = (next_output + every_out).min(sc.time.end_s);
        }
        progress.update(&status(&solver, &outputs));
    }
    probes.flush()?;
    bodies.csv.flush()?;
    let end = status(&solver, &outputs);
    progress.finish(&end);
    if let Some(e) = &stopped {
        log::error!(
            "stopped: {e:#}; outputs up to t = {:.6} s are kept",
            next_output - every_out
        );
    }
    let n = sc.particles.len() as f64;
    let summary = RunSummary {
        case: sc.name.clone(),
        adapter: ctx.info.name.clone(),
        backend: format!("{:?}", ctx.info.backend),
        dimension: sc.physics.dim,
        particles_fluid: sc.count(Kind::Fluid) as u64,
        particles_wall: sc.count(Kind::Wall) as u64,
        particles_excluded: end.excluded,
        steps: end.steps,
        simulated_time_s: end.time_s,
        wall_time_s: end.wall_s,
        particle_steps_per_s: end.particle_steps_per_s(),
        gpu_bytes_per_particle: solver.gpu_bytes() as f64 / n,
        outputs: end.outputs as u64,
        status: match &stopped {
            None => "completed".into(),
            Some(e) => format!("stopped: {e:#}"),
        },
    };
    outputs.out.write_run_summary(&summary)?;
    Ok(RunReport { summary, stopped })
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
    }
}

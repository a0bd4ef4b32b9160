//! The `wgsph` command: run a case, plot a run, list adapters, benchmark.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use indicatif::MultiProgress;

use wgsph::checkpoint::{CaseSource, CheckpointPolicy};
use wgsph::gpu::context::list_adapters;
use wgsph::gpu::{AdapterChoice, GpuContext};
use wgsph::plot::color_scale::SnapshotField;
use wgsph::plot::snapshot::SnapshotPainter;
use wgsph::probe_reach::sig;
use wgsph::progress::{LogLines, Progress, ProgressBarView};
use wgsph::resume::ResumePlan;
use wgsph::run::{RunOptions, RunReport};

#[derive(Parser)]
#[command(
    name = "wgsph",
    version,
    about = "GPU SPH for fluid–solid interaction (wgpu/WGSL)"
)]
struct Cli {
    /// Adapter: auto (hardware GPU, else CPU), gpu, or cpu. Default: $WGSPH_ADAPTER, else auto.
    #[arg(long, global = true)]
    adapter: Option<AdapterChoice>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a case file and write outputs (VTU series, probe CSVs, run.json), showing progress
    /// (a bar on a terminal, else a log line about every 10 s on stderr).
    Run {
        /// The case file (TOML), e.g. cases/dam_break_2d.toml.
        case: PathBuf,
        /// Output directory (default: out/<case name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a case field, e.g. --set particles.dx_m=0.005 (repeatable).
        #[arg(long = "set", value_name = "FIELD=VALUE")]
        set: Vec<String>,
        /// Also draw every particle output as DIR/snapshots/NNNNNN.png (3D: a perspective
        /// view of the particles, the walls on the camera's side cut away).
        #[arg(long)]
        snapshots: bool,
        /// Colour of the fluid in the snapshots (default: pressure).
        #[arg(long, value_name = "pressure|speed", requires = "snapshots")]
        snapshot_field: Option<SnapshotField>,
        /// Checkpoint (DIR/checkpoint.bin) every so many simulated seconds (0.5 or 0.5s) or
        /// wall minutes (10min), or 'never'. Default: 30min. Ctrl-C and SIGTERM always write
        /// one and stop; `wgsph resume DIR` continues.
        #[arg(long, value_name = "SECONDS|MINUTESmin|never")]
        checkpoint_every: Option<CheckpointPolicy>,
        /// Print only errors: no progress, no summary line. Otherwise RUST_LOG sets the log
        /// levels (default: warn,wgsph=info).
        #[arg(long, short)]
        quiet: bool,
    },
    /// Continue a run from its checkpoint (DIR/checkpoint.bin) with the case file and
    /// overrides it started with; on the same adapter the result is bit-identical to an
    /// uninterrupted run.
    Resume {
        /// The run's output directory.
        dir: PathBuf,
        /// Change the time control, e.g. --set time.end_s=2 to run longer (repeatable; the
        /// particles, physics, walls, probes and bodies must stay as they were).
        #[arg(long = "set", value_name = "FIELD=VALUE")]
        set: Vec<String>,
        /// As for `run` (default: the run's own policy is not stored; 30min).
        #[arg(long, value_name = "SECONDS|MINUTESmin|never")]
        checkpoint_every: Option<CheckpointPolicy>,
        #[arg(long, short)]
        quiet: bool,
    },
    /// Plot every probe time series of a finished run as PNG (DIR/plots/<probe>.png), and every
    /// column of a body's or tracked point's table (DIR/plots/<table>_<column>.png).
    Plot {
        /// The run's output directory (the --out of `wgsph run`).
        dir: PathBuf,
        /// Overlay reference data on a probe and report the error against it:
        /// PROBE=FILE.csv[:XSCALE:YSCALE] ('#' comments, a header, two columns; x and y are
        /// multiplied by the scales). Repeatable. Errors also go to DIR/plots/errors.csv.
        #[arg(long = "reference", value_name = "PROBE=FILE[:XSCALE:YSCALE]")]
        references: Vec<wgsph::plot::ReferenceSpec>,
        /// Draw the same probes of another run on the same axes: LABEL=DIR, split at the last
        /// '=' (the label may contain one, DIR may not). Repeatable.
        #[arg(long = "with", value_name = "LABEL=DIR")]
        others: Vec<wgsph::plot::OtherRun>,
        /// Legend label of DIR's run (default: its case name).
        #[arg(long)]
        label: Option<String>,
        /// Plot only this probe, or this column of a table: TABLE.COLUMN, e.g.
        /// point_free_end.ux_m (repeatable; default: all).
        #[arg(long = "probe", value_name = "NAME")]
        probes: Vec<String>,
        /// Plot (and compare) only up to this time, in seconds.
        #[arg(long)]
        t_max: Option<f64>,
        /// Centred moving average of the simulated series over this many seconds, before
        /// drawing and comparing (default: raw samples).
        #[arg(long, value_name = "SECONDS")]
        smooth: Option<f64>,
        /// Also draw every particle file (particles/particles_NNNNNN.vtu) as
        /// DIR/snapshots/NNNNNN.png, the pictures `wgsph run --snapshots` draws (3D: a
        /// perspective view, on the adapter --adapter picks). The case is loaded again from
        /// the file and overrides run.json records.
        #[arg(long)]
        snapshots: bool,
        /// Colour of the fluid in the snapshots (default: pressure).
        #[arg(long, value_name = "pressure|speed", requires = "snapshots")]
        snapshot_field: Option<SnapshotField>,
        /// 3D: draw the x-z slice through the middle of the domain (|y - y_mid| < 2 dx, the
        /// water's inside) instead of the perspective view; no GPU adapter needed.
        #[arg(long, requires = "snapshots")]
        slice: bool,
        /// Also write the snapshots as one animated PNG, DIR/snapshots/animation.png, at this
        /// many frames a second (e.g. 10), for sharing.
        #[arg(long, value_name = "FPS", requires = "snapshots")]
        animation: Option<u16>,
        /// The run's case file, where run.json does not record it or it has moved (the
        /// overrides still come from run.json).
        #[arg(long, value_name = "FILE", requires = "snapshots")]
        case: Option<PathBuf>,
    },
    /// Run the shipped validation cases, compare each with its reference data and write
    /// DIR/report.md: a table (case, metric, error, bound, PASS/FAIL), wall times and PNG plots
    /// of simulation against reference (DIR/<case>/plots/).
    ///
    /// Exit status: 0 when every judged row passes; 1 when a metric is over its bound or a case
    /// goes unstable or cannot run (the report is written either way), or on an error.
    Validate {
        /// The resolutions and bounds of the CI tests (the default): about 8.5 minutes on a
        /// software adapter with 2 cores.
        #[arg(long, conflicts_with = "full")]
        quick: bool,
        /// Publication-grade resolutions and the tighter bounds of the fine-resolution tests:
        /// a GPU's work (hours on a software adapter).
        #[arg(long)]
        full: bool,
        /// Output directory: DIR/report.md, one run folder per case.
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// Run only this case (repeatable; default: every case of the mode).
        #[arg(long = "case", value_name = "NAME", value_parser = clap::builder::PossibleValuesParser::new(
            wgsph::validation::CASES.iter().map(|c| c.name)
        ))]
        cases: Vec<String>,
        /// Evaluate a case's earlier run in DIR/<case> instead of running it again, where its
        /// run.json says it completed with this mode's overrides, particle counts and end time;
        /// other cases run. To judge again after changing a metric, or to judge runs made on
        /// another machine (a GPU's, copied back).
        #[arg(long)]
        reuse: bool,
    },
    /// Reconstruct the water's surface of every particle output of a finished 3D run
    /// (DIR/particles/particles_NNNNNN.vtu) as triangle meshes, DIR/surface/surface_NNNNNN.vtu,
    /// listed in DIR/surface.pvd for ParaView (splashsurf's marching cubes over the SPH density
    /// of the fluid particles). The defaults come from the run's case, loaded again from the
    /// file and overrides run.json records; each can be overridden.
    Surface {
        /// The run's output directory.
        dir: PathBuf,
        /// Half the side of a particle's cube of fluid, m (default: dx/2).
        #[arg(long, value_name = "M")]
        particle_radius: Option<f64>,
        /// The reconstruction kernel's support radius, m (default: the run's 2h).
        #[arg(long, value_name = "M")]
        support_radius: Option<f64>,
        /// Edge of the marching-cubes grid, m (default: dx/2).
        #[arg(long, value_name = "M")]
        cube_size: Option<f64>,
        /// The surface is where the reconstructed density is this share of ρ0 (default 0.6).
        #[arg(long, value_name = "SHARE")]
        iso_threshold: Option<f64>,
        /// The run's case file, where run.json does not record it or it has moved.
        #[arg(long, value_name = "FILE")]
        case: Option<PathBuf>,
    },
    /// List the adapters wgpu sees and their limits.
    Info,
    /// Time N steps of a case (after a warm-up) and report particle-steps per second.
    Bench {
        case: PathBuf,
        /// Steps to time.
        #[arg(long, default_value_t = 200)]
        steps: u64,
        /// Steps run before timing (shader compilation, caches).
        #[arg(long, default_value_t = 20)]
        warmup: u64,
        #[arg(long = "set", value_name = "FIELD=VALUE")]
        set: Vec<String>,
        /// Then time each stage of the step on the GPU over as many steps (one submission per
        /// step, each stage in a pass of its own; needs timestamp queries).
        #[arg(long)]
        stages: bool,
    },
}

fn main() -> ExitCode {
    wgsph::gpu::context::without_mesa_device_select();
    let cli = Cli::parse();
    let quiet = matches!(
        cli.command,
        Command::Run { quiet: true, .. } | Command::Resume { quiet: true, .. }
    );
    let bars = MultiProgress::new();
    // Fails only if a logger is already set, which nothing else in the process does.
    let _ = wgsph::logging::init(quiet, bars.clone());
    match run(cli, &bars) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn context(choice: Option<AdapterChoice>) -> Result<GpuContext> {
    GpuContext::new(AdapterChoice::resolve(choice)?)
}

/// A bar when stderr is a terminal (and not `--quiet`), else plain log lines.
fn progress(quiet: bool, bars: &MultiProgress) -> Box<dyn Progress> {
    if !quiet && std::io::stderr().is_terminal() {
        Box::new(ProgressBarView::new(bars))
    } else {
        Box::new(LogLines::default())
    }
}

/// A flag set by Ctrl-C or SIGTERM: the run writes a checkpoint after the batch of steps under
/// way and stops. A second signal ends the process at once.
fn interrupt_flag() -> Result<Arc<AtomicBool>> {
    let flag = Arc::new(AtomicBool::new(false));
    let seen = flag.clone();
    ctrlc::set_handler(move || {
        if seen.swap(true, Ordering::Relaxed) {
            std::process::exit(130);
        }
        eprintln!(
            "interrupt: writing a checkpoint after the steps under way (seconds), then stopping"
        );
    })
    .context("installing the Ctrl-C handler")?;
    Ok(flag)
}

/// Exit status of a run: 0 completed, 2 stopped (unstable or GPU failure), 130 interrupted.
/// Prints the summary line unless quiet.
fn finish(report: &RunReport, dir: &std::path::Path, quiet: bool) -> ExitCode {
    let code = if report.stopped.is_some() {
        ExitCode::from(2)
    } else if report.interrupted_at_s.is_some() {
        ExitCode::from(130)
    } else {
        ExitCode::SUCCESS
    };
    if !quiet && report.already_complete {
        println!(
            "already complete: t = {:.4} s reached before; nothing computed (outputs in {}); \
             give a later --set time.end_s=... to continue it",
            report.summary.simulated_time_s,
            dir.display()
        );
    } else if !quiet {
        let s = &report.summary;
        println!(
            "{}: {} steps to t = {:.4} s in {:.1} s wall ({:.3e} particle-steps/s); outputs in {}",
            s.status,
            s.steps,
            s.simulated_time_s,
            s.wall_time_s,
            s.particle_steps_per_s,
            dir.display()
        );
    }
    code
}

fn run(cli: Cli, bars: &MultiProgress) -> Result<ExitCode> {
    let solver_command = match cli.command {
        Command::Run { .. } => Some("run"),
        Command::Resume { .. } => Some("resume"),
        Command::Bench { .. } => Some("bench"),
        _ => None,
    };
    if let Some(name) = solver_command {
        wgsph::ranks::refuse_several_ranks(name)?;
    }
    match cli.command {
        Command::Run {
            case,
            out,
            set,
            snapshots,
            snapshot_field,
            checkpoint_every,
            quiet,
        } => {
            #[cfg(feature = "mpi")]
            let several = wgsph::ranks::launched_size().is_some_and(|n| n > 1);
            #[cfg(not(feature = "mpi"))]
            let several = false;
            // The adapter first: the case is refused before its particles are made when it
            // holds more than the adapter and the host's memory do.
            let ctx = (!several).then(|| context(cli.adapter)).transpose()?;
            let started = std::time::Instant::now();
            let sc = load_case(&case, &set, ctx.as_ref())?;
            let case_build_s = started.elapsed().as_secs_f64();
            log::info!(
                "{}: {} particles built in {case_build_s:.2} s",
                sc.name,
                sc.particles.len()
            );
            let dir = out.unwrap_or_else(|| PathBuf::from("out").join(&sc.name));
            let options = RunOptions {
                snapshot_png: snapshots.then(|| snapshot_field.unwrap_or_default()),
                checkpoint: checkpoint_every.unwrap_or_else(CheckpointPolicy::default_for_runs),
                source: Some(CaseSource {
                    path: std::path::absolute(&case)
                        .with_context(|| format!("resolving {}", case.display()))?,
                    overrides: set,
                }),
                interrupt: Some(interrupt_flag()?),
                case_build_s: Some(case_build_s),
                ..Default::default()
            };
            let Some(ctx) = ctx else {
                #[cfg(feature = "mpi")]
                return on_ranks(cli.adapter, &dir, quiet, bars, |ctx, progress, ranks| {
                    wgsph::run::run_on_ranks(ctx, &sc, &dir, &options, progress, ranks)
                });
                #[cfg(not(feature = "mpi"))]
                unreachable!("one process without MPI");
            };
            let report = wgsph::run::run(&ctx, &sc, &dir, &options, &mut *progress(quiet, bars))?;
            Ok(finish(&report, &dir, quiet))
        }
        Command::Resume {
            dir,
            set,
            checkpoint_every,
            quiet,
        } => resume(cli.adapter, &dir, set, checkpoint_every, quiet, bars),
        Command::Plot {
            dir,
            references,
            others,
            label,
            probes,
            t_max,
            smooth,
            snapshots,
            snapshot_field,
            slice,
            animation,
            case,
        } => {
            if snapshots {
                let sc = wgsph::run::scenario_of_run(&dir, case.as_deref())?;
                let field = snapshot_field.unwrap_or_default();
                // Only a 3D perspective view needs an adapter.
                let ctx = (sc.physics.dim == 3 && !slice)
                    .then(|| context(cli.adapter))
                    .transpose()?;
                let painter = SnapshotPainter::for_scenario(ctx.as_ref(), &sc, field, slice)?;
                let pngs = wgsph::plot::snapshot::draw_particle_files(&dir, &sc, &painter)?;
                println!(
                    "wrote {} snapshots into {}",
                    pngs.len(),
                    dir.join(wgsph::output::SNAPSHOTS_DIR).display()
                );
                if let Some(fps) = animation {
                    let path = wgsph::plot::animation::write_animation(&dir, &pngs, fps)?;
                    println!("wrote {}", path.display());
                }
            }
            let opts = wgsph::plot::PlotOptions {
                references,
                label,
                others,
                probes,
                t_max_s: t_max,
                smooth_s: smooth,
            };
            let report = wgsph::plot::plot_run(&dir, &opts)?;
            for p in &report.pngs {
                println!("wrote {}", p.display());
            }
            report.errors.iter().for_each(print_error_row);
            if let Some(p) = &report.errors_csv {
                println!("wrote {}", p.display());
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Validate {
            quick: _,
            full,
            out,
            cases,
            reuse,
        } => {
            use wgsph::validation::{self, Mode};
            let mode = if full { Mode::Full } else { Mode::Quick };
            let selected = validation::select(mode, &cases)?;
            // Opened by the first case that runs: a report of reused runs needs no adapter.
            let gpu = validation::Gpu::lazy(|| context(cli.adapter));
            let report = validation::validate(&gpu, mode, &selected, &out, reuse, &mut || {
                progress(false, bars)
            })?;
            print!("{}", report.table());
            println!(
                "{}: wrote {}",
                if report.passed() { "PASS" } else { "FAIL" },
                out.join(validation::REPORT_FILE).display()
            );
            Ok(ExitCode::from(report.exit_status()))
        }
        Command::Surface {
            dir,
            particle_radius,
            support_radius,
            cube_size,
            iso_threshold,
            case,
        } => {
            let sc = wgsph::run::scenario_of_run(&dir, case.as_deref())?;
            let d = wgsph::surface::SurfaceParams::for_scenario(&sc);
            let params = wgsph::surface::SurfaceParams {
                particle_radius: particle_radius.unwrap_or(d.particle_radius),
                support_radius: support_radius.unwrap_or(d.support_radius),
                cube_size: cube_size.unwrap_or(d.cube_size),
                iso_threshold: iso_threshold.unwrap_or(d.iso_threshold),
                rho0: d.rho0,
            };
            surface(&dir, &sc, &params, bars)
        }
        Command::Info => info(cli.adapter),
        Command::Bench {
            case,
            steps,
            warmup,
            set,
            stages,
        } => bench(cli.adapter, &case, &set, steps, warmup, stages),
    }
}

/// `wgsph surface`: the meshes of every particle output of the run in `dir`, with a bar.
fn surface(
    dir: &std::path::Path,
    sc: &wgsph::scenario::Scenario,
    params: &wgsph::surface::SurfaceParams,
    bars: &MultiProgress,
) -> Result<ExitCode> {
    println!(
        "surface of {}: particle radius {} m, support radius {} m, cubes of {} m, threshold {} ρ0",
        sc.name,
        sig(params.particle_radius),
        sig(params.support_radius),
        sig(params.cube_size),
        sig(params.iso_threshold)
    );
    let bar = bars.add(indicatif::ProgressBar::no_length());
    let pvd = wgsph::surface::surfaces_of_run(dir, sc, params, &mut |done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    })?;
    bar.finish_and_clear();
    println!("wrote {}", pvd.display());
    Ok(ExitCode::SUCCESS)
}

/// `wgsph info`: every adapter with its limits and capacity, and the one `adapter` selects.
fn info(adapter: Option<AdapterChoice>) -> Result<ExitCode> {
    let adapters = list_adapters();
    if adapters.is_empty() {
        println!(
            "no adapter found; for a software one: apt-get install mesa-vulkan-drivers libvulkan1"
        );
    }
    for (info, limits) in adapters {
        println!(
            "{} ({:?}, {:?}, driver {} {})\n  max storage binding {} MiB, max buffer {} MiB, \
             storage buffers/stage {}, workgroups/dim {}",
            info.name,
            info.backend,
            info.device_type,
            info.driver,
            info.driver_info,
            limits.max_storage_buffer_binding_size >> 20,
            limits.max_buffer_size >> 20,
            limits.max_storage_buffers_per_shader_stage,
            limits.max_compute_workgroups_per_dimension
        );
        let cap = wgsph::sph::capacity(&limits);
        println!(
            "  fits at most {} particles (bound by {})",
            cap.particles, cap.bound_by
        );
    }
    let choice = AdapterChoice::resolve(adapter)?;
    match GpuContext::new(choice) {
        Ok(ctx) => println!("'{choice}' selects: {}", ctx.describe()),
        Err(e) => println!("'{choice}' selects nothing: {e:#}"),
    }
    Ok(ExitCode::SUCCESS)
}

/// The case at `path` with the overrides `set`, refused before its particles are made when it
/// holds more than `ctx`'s adapter (None: a run over ranks, each on a slab) and the host's
/// memory do (issue 64: 150 million particles ran the host out of memory while they were made).
fn load_case(
    path: &std::path::Path,
    set: &[String],
    ctx: Option<&GpuContext>,
) -> Result<wgsph::scenario::Scenario> {
    let (n, why) = wgsph::sph::run_budget(ctx, wgsph::sph::host_memory_available());
    let budget = wgsph::case::ParticleBudget::at_most(n as f64, why);
    Ok(wgsph::case::load_within(path, set, &budget)?)
}

/// `wgsph bench`: `steps` steps of `case` after `warmup`, particle-steps per second and bytes
/// per particle, and with `stages` each stage's GPU time.
fn bench(
    adapter: Option<AdapterChoice>,
    case: &std::path::Path,
    set: &[String],
    steps: u64,
    warmup: u64,
    stages: bool,
) -> Result<ExitCode> {
    #[cfg(feature = "mpi")]
    if wgsph::ranks::launched_size().is_some_and(|n| n > 1) {
        anyhow::ensure!(
            !stages,
            "--stages times the stages of one device: run it without mpirun"
        );
        return bench_ranked(adapter, case, set, steps, warmup);
    }
    let ctx = context(adapter)?;
    let sc = load_case(case, set, Some(&ctx))?;
    let r = wgsph::bench::measure(&ctx, &sc, steps, warmup, stages)?;
    let n = r.particles;
    println!("case            {}", r.case);
    println!("adapter         {}", r.adapter);
    println!("particles       {n}");
    println!("steps           {steps}");
    println!("wall seconds    {:.4e}", r.wall_s);
    println!("particle-steps/s {:.4e}", r.particle_steps_per_s());
    // The fair figure between integrators of different steps (and force evaluations a step).
    println!("simulated s/wall s {:.4e}", r.simulated_per_wall());
    println!("mean dt s       {:.4e}", r.mean_dt_s());
    println!("bytes/particle  {:.1}", r.gpu_bytes as f64 / n as f64);
    // Per particle and step, in the last state (src/bench.rs).
    println!(
        "candidates/particle {:.1} (fluid {:.1})",
        r.work.candidates, r.work.fluid_candidates
    );
    println!(
        "neighbours/particle {:.1} (fluid {:.1})",
        r.work.neighbours, r.work.fluid_neighbours
    );
    print_traffic(&r.traffic);
    println!("dispatches/step {}", r.dispatches_per_step);
    if let Some(sample) = r.map_sample_s {
        let step = r.wall_s / steps as f64;
        println!(
            "map sample s    {sample:.4e} (the time of {:.1} steps)",
            sample / step
        );
    }
    if let Some(times) = &r.stages {
        print_stages(times, &r.traffic, steps, n);
    }
    Ok(ExitCode::SUCCESS)
}

/// `mpirun -np N wgsph bench CASE`: the case cut into one slab per rank, every rank on its
/// adapter (named on stderr), the figures of the whole run and each rank's printed by rank 0.
/// A rank that fails ends the job, naming itself.
#[cfg(feature = "mpi")]
fn bench_ranked(
    adapter: Option<AdapterChoice>,
    case: &std::path::Path,
    set: &[String],
    steps: u64,
    warmup: u64,
) -> Result<ExitCode> {
    use wgsph::ranks::{Mpi, Ranks};
    let ranks = Mpi::init().ok_or_else(|| anyhow::anyhow!("MPI was initialised twice"))?;
    let (rank, size) = (ranks.rank(), ranks.size());
    let result = (|| {
        let sc = load_case(case, set, None)?;
        let ctx = GpuContext::for_rank(AdapterChoice::resolve(adapter)?, rank)?;
        eprintln!("rank {rank} of {size}: adapter {}", ctx.describe());
        wgsph::bench::measure_ranked(&ctx, &sc, steps, warmup, &ranks)
    })();
    let r = match result {
        Ok(r) => r,
        Err(e) => ranks.abort(&e),
    };
    if rank != 0 {
        return Ok(ExitCode::SUCCESS);
    }
    println!("case            {}", r.case);
    println!("ranks           {size} (one slab each)");
    for (k, b) in r.ranks.iter().enumerate() {
        println!("adapter {k:<7} {}", b.adapter);
    }
    println!("particles       {}", r.particles);
    println!("steps           {steps}");
    println!("wall seconds    {:.4e} (the slowest rank)", r.wall_s);
    println!("particle-steps/s {:.4e}", r.particle_steps_per_s());
    println!("simulated s/wall s {:.4e}", r.simulated_s / r.wall_s);
    println!(
        "imbalance       {:.1} % at the end (own particles: the most loaded rank over the \
         mean); cuts moved {} times",
        100.0 * r.imbalance(),
        r.ranks[0].rebalances
    );
    println!(
        "rank  own particles  halo/step  migrants/step  halo bytes/step  ms/step: pack  \
         exchange  compute  agree  % steps overlapped  % of them hidden"
    );
    for (k, b) in r.ranks.iter().enumerate() {
        let ms = |s: f64| 1e3 * s;
        println!(
            "{k:>4}  {:>13}  {:>9.1}  {:>13.2}  {:>15.0}  {:>13.3}  {:>8.3}  {:>7.3}  {:>5.3}  \
             {:>18.0}  {:>16.0}",
            b.own_particles,
            b.halo_particles_per_step,
            b.migrants_per_step,
            b.halo_bytes_per_step,
            ms(b.seconds_per_step.pack),
            ms(b.seconds_per_step.exchange),
            ms(b.seconds_per_step.compute),
            ms(b.seconds_per_step.agree),
            100.0 * b.overlapped,
            100.0 * b.exchange_hidden
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// `mpirun -np N wgsph run|resume`: `go` on every rank, each on its adapter (named on stderr),
/// rank 0 reporting; the other ranks log warnings only. A rank that fails ends the job, naming
/// itself.
#[cfg(feature = "mpi")]
fn on_ranks(
    adapter: Option<AdapterChoice>,
    dir: &std::path::Path,
    quiet: bool,
    bars: &MultiProgress,
    go: impl FnOnce(&GpuContext, &mut dyn Progress, &dyn wgsph::ranks::Ranks) -> Result<RunReport>,
) -> Result<ExitCode> {
    use wgsph::ranks::{Mpi, Ranks};
    let ranks = Mpi::init().ok_or_else(|| anyhow::anyhow!("MPI was initialised twice"))?;
    let (rank, size) = (ranks.rank(), ranks.size());
    if rank != 0 {
        log::set_max_level(log::LevelFilter::Warn);
    }
    let result = (|| {
        let ctx = GpuContext::for_rank(AdapterChoice::resolve(adapter)?, rank)?;
        eprintln!("rank {rank} of {size}: adapter {}", ctx.describe());
        let mut progress: Box<dyn Progress> = match rank {
            0 => progress(quiet, bars),
            _ => Box::new(LogLines::default()),
        };
        go(&ctx, &mut *progress, &ranks)
    })();
    match result {
        Ok(report) => Ok(finish(&report, dir, quiet || rank != 0)),
        Err(e) => ranks.abort(&e),
    }
}

/// `wgsph resume DIR`: the run continued from its checkpoint, with `set` over its overrides.
fn resume(
    adapter: Option<AdapterChoice>,
    dir: &std::path::Path,
    set: Vec<String>,
    checkpoint_every: Option<CheckpointPolicy>,
    quiet: bool,
    bars: &MultiProgress,
) -> Result<ExitCode> {
    let (sc, options) = match wgsph::resume::plan(dir, &set, checkpoint_every, None)? {
        ResumePlan::Complete(what) => {
            println!("already complete: {what}; nothing computed");
            return Ok(ExitCode::SUCCESS);
        }
        ResumePlan::Continue { scenario, options } => (scenario, options),
    };
    let options = RunOptions {
        interrupt: Some(interrupt_flag()?),
        ..options
    };
    #[cfg(feature = "mpi")]
    if wgsph::ranks::launched_size().is_some_and(|n| n > 1) {
        return on_ranks(adapter, dir, quiet, bars, |ctx, progress, ranks| {
            wgsph::run::resume_on_ranks(ctx, &sc, dir, &options, progress, ranks)
        });
    }
    let ctx = context(adapter)?;
    let report = wgsph::run::resume(&ctx, &sc, dir, &options, &mut *progress(quiet, bars))?;
    Ok(finish(&report, dir, quiet))
}

/// One line of `wgsph plot --reference`'s errors.
fn print_error_row(e: &wgsph::plot::ErrorSummary) {
    println!(
        "{}{} {} vs {}: {} points, t in [{:.4}, {:.4}] s: RMS error {:.4e}, max |error| {:.4e} at t = {:.4} s, peak {:.4e} (reference {:.4e})",
        e.run,
        if e.smooth_s > 0.0 { format!(" ({} s average)", e.smooth_s) } else { String::new() },
        e.probe,
        e.reference,
        e.points,
        e.t_start_s,
        e.t_end_s,
        e.rms_error,
        e.max_abs_error,
        e.t_max_abs_error_s,
        e.peak_sim,
        e.peak_reference
    );
}

/// The estimated bytes a particle-step moves (src/bench/traffic.rs), and the stages it leaves out.
fn print_traffic(traffic: &wgsph::bench::traffic::Traffic) {
    let total = traffic.total();
    println!(
        "bytes/particle-step  {:.0} read, {:.0} written (estimate: src/bench/traffic.rs)",
        total.read, total.written
    );
    // Counted without caches: a GPU's caches serve most of the neighbour loops' loads.
    println!(
        "  of which neighbour loops {:.0} read, the rest streamed {:.0}",
        traffic.neighbour_loop_read(),
        total.total() - traffic.neighbour_loop_read()
    );
    let unmodelled = traffic.unmodelled();
    if !unmodelled.is_empty() {
        println!("  not estimated: {}", unmodelled.join(", "));
    }
}

/// Each stage's GPU time per step, its share, its time per particle, and beside them its
/// estimated bytes per particle-step and the bandwidth they imply over its time.
fn print_stages(
    times: &[wgsph::sph::profile::StageTime],
    traffic: &wgsph::bench::traffic::Traffic,
    steps: u64,
    particles: u64,
) {
    let total: f64 = times.iter().map(|s| s.seconds).sum();
    println!("stage                   ms/step   share  ns/particle  est. B/particle   GB/s");
    let all = wgsph::sph::profile::StageTime {
        name: "all stages",
        seconds: total,
    };
    for s in times.iter().chain([&all]) {
        let per_step = s.seconds / steps as f64;
        let bytes = match s.name {
            "all stages" => Some(traffic.total().total()),
            name => traffic.of_stage(name).map(|b| b.total()),
        };
        let estimate = match bytes {
            Some(b) => format!(
                "{:>15.1} {:>6.1}",
                b,
                b * particles as f64 / per_step.max(f64::MIN_POSITIVE) * 1e-9
            ),
            None => format!("{:>15} {:>6}", "-", "-"),
        };
        println!(
            "{:<22} {:>8.4} {:>6.1} % {:>10.2} {estimate}",
            s.name,
            1e3 * per_step,
            100.0 * s.seconds / total.max(f64::MIN_POSITIVE),
            1e9 * per_step / particles as f64
        );
    }
}

//! `run`, `resume`, `bench` and `validate`: the engine's functions (those `wgsph run`,
//! `resume`, `bench` and `validate` call) on a worker thread, while the calling Python thread
//! waits with the GIL released and looks for signals every [`POLL`].
//!
//! Ctrl-C: Python's own SIGINT handler only notes the signal; `Python::check_signals` (which
//! must run on the main thread, holding the GIL) then raises KeyboardInterrupt. We turn that
//! into the engine's interrupt flag, the one the command's Ctrl-C handler sets: the run writes
//! a checkpoint after the batch of steps under way and stops, and only then is
//! KeyboardInterrupt raised.
//! No signal handler of ours is installed, so Python's (and Jupyter's) stay as they are.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc};
use std::time::Duration;

use anyhow::anyhow;
use pyo3::exceptions::{PyKeyboardInterrupt, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use wgsph::checkpoint::CheckpointPolicy;
use wgsph::gpu::{AdapterChoice, GpuContext};
use wgsph::progress::{LogLines, Progress, ProgressBarView, RunStatus};
use wgsph::resume::ResumePlan;
use wgsph::run::{RunOptions, RunReport};

use crate::case::{toml_value, Case};
use crate::errors::{to_py, RunStopped, WgsphError};
use crate::results::Run;

/// How often the waiting thread takes the GIL to look for signals: short beside a run, long
/// beside the check.
const POLL: Duration = Duration::from_millis(100);

/// What a job on the worker thread came to, and the exception of a signal seen meanwhile.
struct Waited<T> {
    result: anyhow::Result<T>,
    signal: Option<PyErr>,
}

/// Runs `work` on a worker thread and waits for it with the GIL released. A signal's exception
/// (KeyboardInterrupt for Ctrl-C) sets `flag` when given, and the wait goes on for the job to
/// stop cleanly; a second one, or the first for a job that cannot stop early (`flag` None),
/// ends the wait at once and is raised (the job stops by itself, or with the process).
fn wait_for<T: Send + 'static>(
    py: Python<'_>,
    flag: Option<&AtomicBool>,
    work: impl FnOnce() -> anyhow::Result<T> + Send + 'static,
) -> PyResult<Waited<T>> {
    let (tx, rx) = mpsc::channel();
    std::thread::Builder::new()
        .name("wgsph".into())
        .spawn(move || {
            // A panic is a bug in the engine; it reaches Python as an error, not a crash.
            let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(work))
                .unwrap_or_else(|p| Err(anyhow!("the engine panicked: {}", panic_text(&*p))));
            let _ = tx.send(result);
        })
        .map_err(|e| WgsphError::new_err(format!("cannot start a thread for the run: {e}")))?;
    let mut rx = rx;
    let mut signal: Option<PyErr> = None;
    loop {
        // The receiver goes into the GIL-free closure and back: it may move between threads
        // but not be shared.
        let (got, back) = py.allow_threads(move || (rx.recv_timeout(POLL), rx));
        rx = back;
        match got {
            Ok(result) => return Ok(Waited { result, signal }),
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                return Err(WgsphError::new_err(
                    "the run's thread ended without a result",
                ))
            }
        }
        if let Err(e) = py.check_signals() {
            match flag {
                Some(flag) if signal.is_none() => {
                    flag.store(true, Ordering::Relaxed);
                    eprintln!(
                        "interrupt: writing a checkpoint after the steps under way (seconds), then stopping \
                         (interrupt again to stop waiting for it)"
                    );
                    signal = Some(e);
                }
                _ => return Err(e),
            }
        }
    }
}

fn panic_text(p: &(dyn std::any::Any + Send)) -> &str {
    p.downcast_ref::<&str>()
        .copied()
        .or_else(|| p.downcast_ref::<String>().map(String::as_str))
        .unwrap_or("(no message)")
}

/// No progress shown (`progress=False`).
struct Silent;

impl Progress for Silent {
    fn update(&mut self, _: &RunStatus) {}
    fn finish(&mut self, _: &RunStatus) {}
}

/// What shows a run's progress: as for the command, a bar when stderr is a terminal, else a
/// log line about every 10 s (Jupyter, pipes, CI).
fn progress_view(show: bool) -> Box<dyn Progress> {
    use std::io::IsTerminal;
    match show {
        false => Box::new(Silent),
        true if std::io::stderr().is_terminal() => Box::new(ProgressBarView::new(crate::bars())),
        true => Box::new(LogLines::default()),
    }
}

/// With `progress=False` the engine's info lines (the set-up line, progress lines) are left
/// out for the call too; warnings and errors still show. Restores the level when dropped.
struct QuietInfo(Option<log::LevelFilter>);

impl QuietInfo {
    fn new(quiet: bool) -> Self {
        let before = log::max_level();
        if quiet && before > log::LevelFilter::Warn {
            log::set_max_level(log::LevelFilter::Warn);
            return QuietInfo(Some(before));
        }
        QuietInfo(None)
    }
}

impl Drop for QuietInfo {
    fn drop(&mut self) {
        if let Some(level) = self.0 {
            log::set_max_level(level);
        }
    }
}

/// The adapter `adapter` names ("auto", "gpu", "cpu"), else $WGSPH_ADAPTER's, else auto.
fn adapter_choice(adapter: Option<&str>) -> PyResult<AdapterChoice> {
    let given = adapter
        .map(str::parse::<AdapterChoice>)
        .transpose()
        .map_err(|e| PyValueError::new_err(format!("adapter: {e:#}")))?;
    AdapterChoice::resolve(given).map_err(|e| PyValueError::new_err(format!("{e:#}")))
}

fn checkpoint_policy(every: Option<&str>) -> PyResult<Option<CheckpointPolicy>> {
    every
        .map(str::parse::<CheckpointPolicy>)
        .transpose()
        .map_err(|e| PyValueError::new_err(format!("checkpoint_every: {e:#}")))
}

/// The `Run` of a finished run job, or its exception: the signal's (after the checkpoint, with
/// where it is), `RunStopped` for a run that stopped early, the engine's error.
fn finish(py: Python<'_>, waited: Waited<RunReport>, dir: PathBuf) -> PyResult<Run> {
    let report = waited.result.map_err(to_py)?;
    if let Some(signal) = waited.signal {
        if !signal.is_instance_of::<PyKeyboardInterrupt>(py) {
            return Err(signal);
        }
        let what = match report.interrupted_at_s {
            Some(t) => format!(
                "run interrupted at t = {t:.6} s with a checkpoint, {}; wgsph.resume({:?}) \
                 continues it",
                dir.join(wgsph::checkpoint::CHECKPOINT_FILE).display(),
                dir.display().to_string()
            ),
            None => format!(
                "interrupted as the run ended ({}); its outputs are in {}",
                report.summary.status,
                dir.display()
            ),
        };
        return Err(PyKeyboardInterrupt::new_err(what));
    }
    if report.stopped.is_some() {
        return Err(RunStopped::new_err(format!(
            "{}: {}",
            dir.display(),
            report.summary.status
        )));
    }
    Ok(Run::finished(
        dir,
        report.interrupted_at_s,
        report.already_complete,
    ))
}

/// Runs `case` to its end, writing into `out` (default `out/<case name>`), as `wgsph run`.
#[pyfunction]
#[pyo3(signature = (case, out = None, *, adapter = None, snapshots = false, progress = true,
                    checkpoint_every = None, snapshot_field = None))]
#[allow(clippy::too_many_arguments)]
pub fn run(
    py: Python<'_>,
    case: &Case,
    out: Option<PathBuf>,
    adapter: Option<&str>,
    snapshots: bool,
    progress: bool,
    checkpoint_every: Option<&str>,
    snapshot_field: Option<&str>,
) -> PyResult<Run> {
    let choice = adapter_choice(adapter)?;
    let field = snapshot_field
        .map(str::parse)
        .transpose()
        .map_err(|e: String| PyValueError::new_err(format!("snapshot_field: {e}")))?;
    if field.is_some() && !snapshots {
        return Err(PyValueError::new_err(
            "snapshot_field is given without snapshots=True; fix: add snapshots=True",
        ));
    }
    let sc = case.scenario.clone();
    let dir = out.unwrap_or_else(|| PathBuf::from("out").join(&sc.name));
    let flag = Arc::new(AtomicBool::new(false));
    // `..Default::default()` fills the fields the engine's `test-hooks` feature adds.
    #[allow(clippy::needless_update)]
    let options = RunOptions {
        snapshot_png: snapshots.then(|| field.unwrap_or_default()),
        checkpoint: checkpoint_policy(checkpoint_every)?
            .unwrap_or_else(CheckpointPolicy::default_for_runs),
        source: case.source(),
        interrupt: Some(flag.clone()),
        halt_at_s: None,
        ..Default::default()
    };
    run_in(py, dir, choice, &flag, progress, move |ctx, dir, view| {
        wgsph::run::run(ctx, &sc, dir, &options, view)
    })
}

/// Runs `job` (the engine's run or resume into `dir`) on a device of `choice` while Python
/// waits, Ctrl-C setting `flag`, with or without the progress bar; the run as a `Run`.
fn run_in(
    py: Python<'_>,
    dir: PathBuf,
    choice: AdapterChoice,
    flag: &AtomicBool,
    progress: bool,
    job: impl FnOnce(&GpuContext, &std::path::Path, &mut dyn Progress) -> anyhow::Result<RunReport>
        + Send
        + 'static,
) -> PyResult<Run> {
    let _quiet = QuietInfo::new(!progress);
    let job_dir = dir.clone();
    let waited = wait_for(py, Some(flag), move || {
        let ctx = GpuContext::new(choice)?;
        job(&ctx, &job_dir, &mut *progress_view(progress))
    })?;
    finish(py, waited, dir)
}

/// `FIELD=VALUE` overrides of a dict {field: value}.
fn overrides(set: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<String>> {
    let Some(set) = set else {
        return Ok(Vec::new());
    };
    set.iter()
        .map(|(k, v)| {
            let field: String = k.extract()?;
            Ok(format!("{field}={}", toml_value(&field, &v)?))
        })
        .collect()
}

/// Continues the run in `dir` from its checkpoint, as `wgsph resume`.
#[pyfunction]
#[pyo3(signature = (dir, set = None, *, case = None, adapter = None, progress = true,
                    checkpoint_every = None))]
pub fn resume(
    py: Python<'_>,
    dir: PathBuf,
    set: Option<&Bound<'_, PyDict>>,
    case: Option<Case>,
    adapter: Option<&str>,
    progress: bool,
    checkpoint_every: Option<&str>,
) -> PyResult<Run> {
    let choice = adapter_choice(adapter)?;
    let set = overrides(set)?;
    let given = case.map(|c| {
        Box::new(move |more: &[String]| c.with_more(more)) as Box<dyn Fn(&[String]) -> Result<_, _>>
    });
    let plan = wgsph::resume::plan(
        &dir,
        &set,
        checkpoint_policy(checkpoint_every)?,
        given.as_deref(),
    )
    .map_err(to_py)?;
    let (sc, options) = match plan {
        ResumePlan::Complete(what) => {
            if progress {
                eprintln!("already complete: {what}; nothing computed");
            }
            return Ok(Run::finished(dir, None, true));
        }
        ResumePlan::Continue { scenario, options } => (scenario, options),
    };
    let flag = Arc::new(AtomicBool::new(false));
    let options = RunOptions {
        interrupt: Some(flag.clone()),
        ..options
    };
    run_in(py, dir, choice, &flag, progress, move |ctx, dir, view| {
        wgsph::run::resume(ctx, &sc, dir, &options, view)
    })
}

/// Times `steps` steps of `case` after `warmup`, as `wgsph bench`.
#[pyfunction]
#[pyo3(signature = (case, steps = 200, warmup = 20, *, adapter = None, stages = false))]
pub fn bench<'py>(
    py: Python<'py>,
    case: &Case,
    steps: u64,
    warmup: u64,
    adapter: Option<&str>,
    stages: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let choice = adapter_choice(adapter)?;
    let sc = case.scenario.clone();
    let waited = wait_for(py, None, move || {
        let ctx = GpuContext::new(choice)?;
        wgsph::bench::measure(&ctx, &sc, steps, warmup, stages)
    })?;
    let r = waited.result.map_err(to_py)?;
    let d = PyDict::new(py);
    d.set_item("case", &r.case)?;
    d.set_item("adapter", &r.adapter)?;
    d.set_item("particles", r.particles)?;
    d.set_item("steps", r.steps)?;
    d.set_item("wall_s", r.wall_s)?;
    d.set_item("simulated_s", r.simulated_s)?;
    d.set_item("particle_steps_per_s", r.particle_steps_per_s())?;
    d.set_item("simulated_s_per_wall_s", r.simulated_per_wall())?;
    d.set_item("mean_dt_s", r.mean_dt_s())?;
    d.set_item(
        "gpu_bytes_per_particle",
        r.gpu_bytes as f64 / r.particles as f64,
    )?;
    d.set_item("candidates_per_particle", r.work.candidates)?;
    d.set_item("fluid_candidates_per_particle", r.work.fluid_candidates)?;
    d.set_item("neighbours_per_particle", r.work.neighbours)?;
    d.set_item("fluid_neighbours_per_particle", r.work.fluid_neighbours)?;
    d.set_item("dispatches_per_step", r.dispatches_per_step)?;
    let stages = r.stages.map(|times| {
        times
            .iter()
            .map(|s| (s.name, s.seconds))
            .collect::<Vec<_>>()
    });
    d.set_item("stages", stages)?;
    d.set_item("map_sample_s", r.map_sample_s)?;
    Ok(d)
}

/// Runs the shipped validation cases and writes `out/report.md`, as `wgsph validate`.
#[pyfunction]
#[pyo3(signature = (out, *, mode = "quick", cases = Vec::new(), reuse = false, adapter = None,
                    progress = true))]
pub fn validate<'py>(
    py: Python<'py>,
    out: PathBuf,
    mode: &str,
    cases: Vec<String>,
    reuse: bool,
    adapter: Option<&str>,
    progress: bool,
) -> PyResult<Bound<'py, PyDict>> {
    use wgsph::validation::{self, Mode};
    let mode = match mode {
        "quick" => Mode::Quick,
        "full" => Mode::Full,
        other => {
            return Err(PyValueError::new_err(format!(
                "mode = {other:?}; fix: \"quick\" or \"full\""
            )))
        }
    };
    let choice = adapter_choice(adapter)?;
    let selected =
        validation::select(mode, &cases).map_err(|e| PyValueError::new_err(format!("{e:#}")))?;
    let _quiet = QuietInfo::new(!progress);
    let job_out = out.clone();
    // The cases cannot stop early: Ctrl-C stops the waiting, the cases go on in the background
    // until the process ends.
    let waited = wait_for(py, None, move || {
        let gpu = validation::Gpu::lazy(|| GpuContext::new(choice));
        validation::validate(&gpu, mode, &selected, &job_out, reuse, &mut || {
            progress_view(progress)
        })
    })?;
    let report = waited.result.map_err(to_py)?;
    let d = PyDict::new(py);
    d.set_item("passed", report.passed())?;
    d.set_item("exit_status", report.exit_status())?;
    d.set_item("adapter", &report.adapter)?;
    d.set_item(
        "report",
        out.join(validation::REPORT_FILE).display().to_string(),
    )?;
    d.set_item("table", report.table())?;
    let rows = PyList::empty(py);
    for [case, metric, error, bound, result] in report.rows() {
        let row = PyDict::new(py);
        row.set_item("case", case)?;
        row.set_item("metric", metric)?;
        row.set_item("error", error)?;
        row.set_item("bound", bound)?;
        row.set_item("result", result)?;
        rows.append(row)?;
    }
    d.set_item("rows", rows)?;
    Ok(d)
}

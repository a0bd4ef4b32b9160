//! `wgsph validate`: the shipped cases that have reference data, run and compared with it.
//!
//! [`CASES`] is the table: for each case its case file (embedded, so the command works from any
//! directory), the `--set` overrides of the quick and the full mode, the reference with its
//! citation, and the function that turns the run's outputs (probe CSVs, body CSVs, run.json)
//! into metrics and figures. The metrics live in one file per case family ([`hydrostatic`],
//! [`dam_break`], [`lobovsky`], [`bodies`], [`sloshing`], [`plate`], [`gate`], [`spheric`],
//! [`sfz`]); the
//! integration tests
//! (`tests/validation/`) call
//! the same functions, so a bound asserted in CI and a row of the report are the same code.
//!
//! A metric's bound depends on the [`Mode`]: quick mode judges with the coarse bounds the CI
//! tests assert, full mode with the tighter bounds of the `#[ignore]`d fine-resolution tests. A
//! metric without a bound in a mode is reported, not judged.

pub mod bodies;
pub mod dam_break;
pub mod gate;
pub mod hydrostatic;
pub mod lobovsky;
pub mod plate;
mod report;
pub mod sfz;
pub mod sloshing;
pub mod spheric;

use std::cell::OnceCell;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, bail, Context, Result};

use crate::checkpoint::CaseSource;
use crate::gpu::GpuContext;
use crate::output::{RunSummary, PROBES_DIR};
use crate::plot::{self, Curve, PLOTS_DIR};
use crate::progress::Progress;
use crate::run::{fingerprint_hex, RunOptions};
use crate::scenario::Scenario;

pub use report::{Report, REPORT_FILE};

/// Resolution and bounds of a validation run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// The resolutions and bounds of the CI tests: minutes on a software adapter.
    Quick,
    /// The fine resolutions and tighter bounds of the ignored tests: a GPU's work.
    Full,
}

impl Mode {
    pub fn name(self) -> &'static str {
        match self {
            Mode::Quick => "quick",
            Mode::Full => "full",
        }
    }
}

/// How a metric's value is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    /// A fraction, shown in per cent (relative errors).
    Percent,
    /// A plain number (dimensionless values, ratios).
    Number,
    /// A whole number (particle counts).
    Count,
}

/// What a metric's value must satisfy to pass. Every comparison is false for NaN, so a metric
/// that could not be computed fails.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bound {
    /// |value| < limit.
    Within(f64),
    /// lo < value < hi.
    Between(f64, f64),
    /// value ≤ limit.
    AtMost(f64),
}

impl Bound {
    pub fn holds(self, v: f64) -> bool {
        match self {
            Bound::Within(b) => v.abs() < b,
            Bound::Between(lo, hi) => lo < v && v < hi,
            Bound::AtMost(b) => v <= b,
        }
    }
}

/// The judgement of one metric.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    Pass,
    Fail,
    /// Reported, not judged in this mode.
    Info,
}

/// One row of the report.
#[derive(Clone, Debug)]
pub struct Metric {
    pub name: String,
    pub value: f64,
    pub unit: Unit,
    /// `None`: reported, not judged in this mode.
    pub bound: Option<Bound>,
    /// The numbers the value was computed from, for the case's section of the report.
    pub detail: String,
}

impl Metric {
    pub fn verdict(&self) -> Verdict {
        match self.bound {
            None => Verdict::Info,
            Some(b) if b.holds(self.value) => Verdict::Pass,
            Some(_) => Verdict::Fail,
        }
    }
}

/// A plot of a case (simulation against reference, in the reference's units), drawn to
/// `DIR/<case>/plots/<name>.png`.
#[derive(Clone, Debug)]
pub struct Figure {
    pub name: String,
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub curves: Vec<Curve>,
}

/// What a case's outputs give: metric rows and figures.
#[derive(Clone, Debug, Default)]
pub struct Evaluation {
    pub metrics: Vec<Metric>,
    pub figures: Vec<Figure>,
}

/// A shipped case with reference data.
pub struct Case {
    /// Also the folder of its outputs, `DIR/<name>`.
    pub name: &'static str,
    /// The case file, relative to the repository root; its text is built in
    /// ([`crate::case::BUILT_IN`], under this case's name).
    pub file: &'static str,
    /// The reference: a data file (relative to the repository root) or an analytic solution.
    pub reference: &'static str,
    /// Where the reference data comes from (empty for an analytic reference).
    pub citation: &'static str,
    overrides: fn(Mode) -> Option<Vec<String>>,
    evaluate: fn(&Scenario, &Path, Mode) -> Result<Evaluation>,
}

impl std::fmt::Debug for Case {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Case")
            .field("name", &self.name)
            .field("file", &self.file)
            .finish_non_exhaustive()
    }
}

impl Case {
    /// The `--set` overrides of `mode`; `None` when the case is not run in that mode.
    pub fn overrides(&self, mode: Mode) -> Option<Vec<String>> {
        (self.overrides)(mode)
    }

    /// The case with `overrides` applied.
    pub fn scenario(&self, overrides: &[String]) -> Result<Scenario> {
        let built_in = crate::case::built_in(self.name, Path::new(self.file))
            .with_context(|| format!("{} ({}) is not a built-in case", self.name, self.file))?;
        Ok(built_in.load(overrides)?)
    }

    /// Metrics and figures of the finished run of `sc` in `dir`, judged with the bounds of
    /// `bounds`.
    pub fn evaluate(&self, sc: &Scenario, dir: &Path, bounds: Mode) -> Result<Evaluation> {
        (self.evaluate)(sc, dir, bounds)
    }
}

/// Every validation case, in report order.
pub static CASES: &[Case] = &[
    Case {
        name: "hydrostatic_2d",
        file: "cases/hydrostatic_2d.toml",
        reference: "analytic: p = ρ0 g (H − z)",
        citation: "",
        overrides: hydrostatic::overrides,
        evaluate: hydrostatic::evaluate,
    },
    Case {
        name: "hydrostatic_3d",
        file: "cases/hydrostatic_3d.toml",
        reference: "analytic: p = ρ0 g (H − z)",
        citation: "",
        overrides: hydrostatic::overrides_3d,
        evaluate: hydrostatic::evaluate_3d,
    },
    Case {
        name: "dam_break_2d",
        file: "cases/dam_break_2d.toml",
        reference: dam_break::REFERENCE,
        citation: dam_break::CITATION,
        overrides: dam_break::overrides,
        evaluate: dam_break::evaluate,
    },
    Case {
        name: "dam_break_lobovsky_2d",
        file: "cases/dam_break_lobovsky_2d.toml",
        reference: lobovsky::REFERENCE,
        citation: lobovsky::CITATION,
        overrides: lobovsky::overrides,
        evaluate: lobovsky::evaluate,
    },
    Case {
        name: "floating_box_2d",
        file: "cases/floating_box_2d.toml",
        reference: "analytic: Archimedes' draft ρ_b/ρ0 · h",
        citation: "",
        overrides: bodies::floating_box_overrides,
        evaluate: bodies::evaluate_floating_box,
    },
    Case {
        name: "water_entry_cylinder_2d",
        file: "cases/water_entry_cylinder_2d.toml",
        reference: bodies::ENTRY_500.file,
        citation: bodies::ENTRY_CITATION,
        overrides: bodies::water_entry_500_overrides,
        evaluate: bodies::evaluate_water_entry_500,
    },
    Case {
        name: "water_entry_cylinder_2d_rho1000",
        file: "cases/water_entry_cylinder_2d.toml",
        reference: bodies::ENTRY_1000.file,
        citation: bodies::ENTRY_CITATION,
        overrides: bodies::water_entry_1000_overrides,
        evaluate: bodies::evaluate_water_entry_1000,
    },
    Case {
        name: "sloshing_2d",
        file: "cases/sloshing_2d.toml",
        reference: "tests/data/sloshing_akyildiz_unal_2006_pitch_probe{2,8}.csv",
        citation: sloshing::CITATION,
        overrides: sloshing::overrides,
        evaluate: sloshing::evaluate,
    },
    Case {
        name: "oscillating_plate_2d",
        file: "cases/oscillating_plate_2d.toml",
        reference: "analytic: Euler–Bernoulli first-mode period (shared/validation/analytic_oscillating_plate_frequency.csv)",
        citation: "",
        overrides: plate::overrides,
        evaluate: plate::evaluate,
    },
    Case {
        name: "oscillating_plate_tl_2d",
        file: "cases/oscillating_plate_tl_2d.toml",
        reference: "analytic: Euler–Bernoulli first-mode period (shared/validation/analytic_oscillating_plate_frequency.csv)",
        citation: "",
        overrides: plate::overrides,
        evaluate: plate::evaluate_tl,
    },
    Case {
        name: "oscillating_plate_thin_2d",
        file: "cases/oscillating_plate_thin_2d.toml",
        reference: "analytic: Euler–Bernoulli first-mode period",
        citation: "",
        overrides: plate::overrides_thin,
        evaluate: plate::evaluate_tl,
    },
    Case {
        name: "elastic_gate_2d",
        file: "cases/elastic_gate_2d.toml",
        reference: gate::X_DISPLACEMENT.file,
        citation: gate::CITATION,
        overrides: gate::overrides,
        evaluate: gate::evaluate,
    },
    Case {
        name: "dam_break_3d",
        file: "cases/dam_break_3d.toml",
        reference: spheric::REFERENCE,
        citation: spheric::CITATION,
        overrides: spheric::overrides,
        evaluate: spheric::evaluate,
    },    Case {
        name: "sfz_building_3d",
        file: "cases/sfz_building_3d.toml",
        reference: sfz::REFERENCE,
        citation: sfz::CITATION,
        overrides: sfz::overrides,
        evaluate: sfz::evaluate,
    },
];

/// The case called `name`.
pub fn find(name: &str) -> Option<&'static Case> {
    CASES.iter().find(|c| c.name == name)
}

/// The cases `validate` runs in `mode`: those named (all of the mode's when `names` is empty).
/// An unknown name, or one that `mode` does not run, is an error that lists the choices.
pub fn select(mode: Mode, names: &[String]) -> Result<Vec<&'static Case>> {
    let in_mode: Vec<&'static Case> = CASES
        .iter()
        .filter(|c| c.overrides(mode).is_some())
        .collect();
    if names.is_empty() {
        return Ok(in_mode);
    }
    let list = |cases: &[&Case]| cases.iter().map(|c| c.name).collect::<Vec<_>>().join(", ");
    let mut out = Vec::new();
    for name in names {
        match find(name) {
            None => bail!(
                "unknown validation case {name:?}; cases: {}",
                list(&CASES.iter().collect::<Vec<_>>())
            ),
            Some(c) if c.overrides(mode).is_none() => bail!(
                "case {name:?} is not run in {} mode; {} mode runs: {}",
                mode.name(),
                mode.name(),
                list(&in_mode)
            ),
            Some(c) if !out.iter().any(|o: &&Case| o.name == c.name) => out.push(c),
            Some(_) => {}
        }
    }
    Ok(out)
}

/// The outcome of one case: its metrics, or why it has none.
#[derive(Clone, Debug)]
pub struct CaseOutcome {
    pub name: String,
    pub file: String,
    pub reference: String,
    pub citation: String,
    pub overrides: Vec<String>,
    /// The run's output folder.
    pub dir: PathBuf,
    /// run.json of the run, when it ran.
    pub summary: Option<RunSummary>,
    pub metrics: Vec<Metric>,
    /// Set when the case could not be set up, run to its end, evaluated or plotted: a FAIL row.
    pub failure: Option<String>,
    /// The PNGs written.
    pub plots: Vec<PathBuf>,
    /// Wall time of the whole case (run, evaluation, plots), seconds.
    pub wall_s: f64,
    /// Whether an earlier run in `dir` was evaluated rather than a new one made (`--reuse`).
    pub reused: bool,
}

impl CaseOutcome {
    /// The case's wall time with its run's: an earlier run's (from its run.json) and this
    /// evaluation's when the run was reused, else the whole case's.
    pub fn run_wall_s(&self) -> f64 {
        match (&self.summary, self.reused) {
            (Some(r), true) => r.wall_time_s + self.wall_s,
            _ => self.wall_s,
        }
    }

    /// No failure and no metric over its bound.
    pub fn passed(&self) -> bool {
        self.failure.is_none() && self.metrics.iter().all(|m| m.verdict() != Verdict::Fail)
    }
}

/// The GPU context of a validation: one given, or one opened when the first case runs, so that
/// a report whose every case evaluates an earlier run (`--reuse`) needs no adapter at all.
pub enum Gpu<'a> {
    Given(&'a GpuContext),
    Lazy {
        open: Box<dyn Fn() -> Result<GpuContext> + 'a>,
        opened: Box<OnceCell<GpuContext>>,
    },
}

impl<'a> Gpu<'a> {
    /// A context that `open` makes at its first use.
    pub fn lazy(open: impl Fn() -> Result<GpuContext> + 'a) -> Self {
        Gpu::Lazy {
            open: Box::new(open),
            opened: Box::default(),
        }
    }

    /// The context, opened now if it was not.
    pub fn get(&self) -> Result<&GpuContext> {
        match self {
            Gpu::Given(ctx) => Ok(ctx),
            Gpu::Lazy { open, opened } => {
                if opened.get().is_none() {
                    let ctx = open()?;
                    let _ = opened.set(ctx);
                }
                Ok(opened.get().expect("set above"))
            }
        }
    }

    /// The adapter's description, or None when no case needed one.
    pub fn describe(&self) -> Option<String> {
        match self {
            Gpu::Given(ctx) => Some(ctx.describe()),
            Gpu::Lazy { opened, .. } => opened.get().map(GpuContext::describe),
        }
    }
}

/// Runs `case` with `overrides` into `dir`, then evaluates it with the bounds of `bounds` and
/// draws its figures into `dir/plots`. With `reuse`, a completed earlier run of the same set-up
/// in `dir` ([`reusable_run`]) is evaluated instead of running again. Never fails: what goes
/// wrong is the outcome's `failure`.
pub fn run_case(
    gpu: &Gpu,
    case: &Case,
    overrides: &[String],
    bounds: Mode,
    dir: &Path,
    reuse: bool,
    progress: &mut dyn Progress,
) -> CaseOutcome {
    let start = Instant::now();
    let mut outcome = CaseOutcome {
        name: case.name.to_string(),
        file: case.file.to_string(),
        reference: case.reference.to_string(),
        citation: case.citation.to_string(),
        overrides: overrides.to_vec(),
        dir: dir.to_path_buf(),
        summary: None,
        metrics: Vec::new(),
        failure: None,
        plots: Vec::new(),
        wall_s: 0.0,
        reused: false,
    };
    if let Err(e) = run_and_evaluate(gpu, case, bounds, reuse, progress, &mut outcome) {
        outcome.failure = Some(format!("{e:#}"));
    }
    outcome.wall_s = start.elapsed().as_secs_f64();
    outcome
}

fn run_and_evaluate(
    gpu: &Gpu,
    case: &Case,
    bounds: Mode,
    reuse: bool,
    progress: &mut dyn Progress,
    outcome: &mut CaseOutcome,
) -> Result<()> {
    let sc = case.scenario(&outcome.overrides)?;
    let dir = outcome.dir.clone();
    let earlier = if reuse {
        reusable_run(&sc, &outcome.overrides, &dir)
    } else {
        Err("not asked to".into())
    };
    match earlier {
        Ok(summary) => {
            log::info!(
                "{}: evaluating the earlier run in {}",
                sc.name,
                dir.display()
            );
            outcome.summary = Some(summary);
            outcome.reused = true;
        }
        Err(why) => {
            if reuse {
                log::info!("{}: running again ({why})", sc.name);
            }
            // The case's file and overrides go into run.json (and checkpoints) with the run.
            let options = RunOptions {
                source: Some(CaseSource {
                    path: case.file.into(),
                    overrides: outcome.overrides.clone(),
                }),
                ..RunOptions::default()
            };
            let report = crate::run::run(gpu.get()?, &sc, &dir, &options, progress)?;
            outcome.summary = Some(report.summary);
            if let Some(e) = report.stopped {
                // The metrics of a run cut short would compare part of a series: none are given.
                bail!("run stopped: {e:#}");
            }
        }
    }
    let eval = case
        .evaluate(&sc, &dir, bounds)
        .context("evaluating the outputs")?;
    outcome.metrics = eval.metrics;
    outcome.plots = draw(&dir, &eval.figures)?;
    Ok(())
}

/// The run summary of the earlier run in `dir` when it can stand for a run of `sc` loaded with
/// `overrides`: it completed, it is of this case, made with these overrides (run.json records
/// them), with the particle counts `sc` has and to `sc`'s end time. Otherwise why not. A
/// different scenario fingerprint (another engine version or machine) is logged, not refused:
/// the run is judged as it was made.
pub fn reusable_run(
    sc: &Scenario,
    overrides: &[String],
    dir: &Path,
) -> std::result::Result<RunSummary, String> {
    let s = RunSummary::read(dir).map_err(|e| e.to_string())?;
    let counts = |s: &RunSummary| {
        [
            s.particles_fluid,
            s.particles_wall,
            s.particles_solid,
            s.particles_inlet,
        ]
    };
    let expected = crate::run::particle_counts(sc);
    let end = sc.time.end_s;
    if s.status != "completed" {
        return Err(format!("the run did not complete: {}", s.status));
    } else if s.case != sc.name {
        return Err(format!("the run is of case {}", s.case));
    } else if s.overrides.as_deref() != Some(overrides) {
        return Err(match &s.overrides {
            None => "its run.json records no overrides (a run before they were written)".into(),
            Some(o) => format!("it was made with other overrides: {o:?}"),
        });
    } else if counts(&s) != expected {
        return Err(format!(
            "its particle counts (fluid, boundary, solid, inlet) {:?} are not the case's \
             {expected:?}",
            counts(&s)
        ));
    } else if (s.simulated_time_s - end).abs() > 1e-6 * end.max(1.0) {
        return Err(format!(
            "it ended at t = {} s, not the case's {end} s",
            s.simulated_time_s
        ));
    }
    let here = fingerprint_hex(sc);
    if s.fingerprint.as_deref() != Some(here.as_str()) {
        log::info!(
            "{}: the earlier run's scenario fingerprint {:?} is not this build's {here} (another \
             engine version or machine): judged as it was made",
            sc.name,
            s.fingerprint
        );
    }
    Ok(s)
}

/// Draws `figures` into `dir/plots`; returns the PNG paths.
pub fn draw(dir: &Path, figures: &[Figure]) -> Result<Vec<PathBuf>> {
    let plots = dir.join(PLOTS_DIR);
    std::fs::create_dir_all(&plots)
        .with_context(|| format!("cannot create {}", plots.display()))?;
    let mut manifest = crate::output::Manifest::open(dir, 0)?;
    figures
        .iter()
        .map(|f| {
            let png = plots.join(format!("{}.png", f.name));
            manifest.claim_path(&png)?;
            plot::render_png(&png, &f.title, &f.x_label, &f.y_label, &f.curves)?;
            Ok(png)
        })
        .collect()
}

/// Runs `cases` in `mode` into `out/<case>`, writes `out/report.md` and returns the report.
/// With `reuse`, a case's completed earlier run there is evaluated instead ([`reusable_run`]).
/// `progress` gives the progress display of each run.
pub fn validate(
    gpu: &Gpu,
    mode: Mode,
    cases: &[&Case],
    out: &Path,
    reuse: bool,
    progress: &mut dyn FnMut() -> Box<dyn Progress>,
) -> Result<Report> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let mut outcomes = Vec::new();
    for (k, case) in cases.iter().enumerate() {
        let overrides = case
            .overrides(mode)
            .ok_or_else(|| anyhow!("case {} is not run in {} mode", case.name, mode.name()))?;
        let dir = out.join(case.name);
        log::info!(
            "validate [{}/{}] {}: {} {} into {}",
            k + 1,
            cases.len(),
            case.name,
            case.file,
            overrides
                .iter()
                .map(|o| format!("--set {o}"))
                .collect::<Vec<_>>()
                .join(" "),
            dir.display()
        );
        let o = run_case(gpu, case, &overrides, mode, &dir, reuse, &mut *progress());
        for m in &o.metrics {
            log::info!("{}: {} = {}", o.name, m.name, report::value_text(m));
        }
        if let Some(f) = &o.failure {
            log::error!("{}: {f}", o.name);
        }
        outcomes.push(o);
    }
    let report = Report {
        mode,
        adapter: gpu
            .describe()
            .unwrap_or_else(|| "none opened: every case evaluated an earlier run".into()),
        cases: outcomes,
    };
    report.write(out)?;
    Ok(report)
}

// ---- reading a run's outputs -------------------------------------------------------------

/// `(t, value)` of `DIR/probes/<probe>.csv`.
pub fn probe_series(dir: &Path, probe: &str) -> Result<Vec<(f64, f64)>> {
    Ok(plot::read_csv(&dir.join(PROBES_DIR).join(format!("{probe}.csv")))?.points)
}

/// The first time `series` reaches `level`.
pub fn arrival(series: &[(f64, f64)], level: f64) -> Option<f64> {
    series.iter().find(|p| p.1 >= level).map(|p| p.0)
}

/// (t, value) of the largest value of `series`.
pub fn peak(series: &[(f64, f64)]) -> (f64, f64) {
    series
        .iter()
        .filter(|p| p.1.is_finite())
        .fold((f64::NAN, f64::NEG_INFINITY), |a, p| {
            if p.1 > a.1 {
                *p
            } else {
                a
            }
        })
}

/// The samples of `series` in [from, to].
pub fn within(series: &[(f64, f64)], (from, to): (f64, f64)) -> Vec<(f64, f64)> {
    (series.iter())
        .filter(|p| p.0 >= from && p.0 <= to)
        .copied()
        .collect()
}

/// The mean value of `series`.
pub fn mean(series: &[(f64, f64)]) -> f64 {
    series.iter().map(|p| p.1).sum::<f64>() / series.len() as f64
}

/// `(t, column)` of a body's table, `DIR/probes/body_<body>.csv` (`t_s` first, then the
/// columns of [`crate::body::csv_columns`]).
pub fn body_series(dir: &Path, body: &str, column: &str) -> Result<Vec<(f64, f64)>> {
    table_series(dir, &format!("body_{body}"), column)
}

/// `(t, column)` of a table with several columns, `DIR/probes/<table>.csv` (`t_s` first): a
/// body's or a tracked point's.
pub fn table_series(dir: &Path, table: &str, column: &str) -> Result<Vec<(f64, f64)>> {
    let path = dir.join(PROBES_DIR).join(format!("{table}.csv"));
    Ok(plot::read_table_column(&path, column)?.points)
}

/// Reference data embedded at build time: `file` (relative to the repository root) and its text.
pub struct Reference {
    pub file: &'static str,
    pub text: &'static str,
}

impl Reference {
    /// The two columns of the reference CSV.
    pub fn points(&self) -> Result<Vec<(f64, f64)>> {
        Ok(plot::parse_csv(self.text, self.file)?.points)
    }
}

/// Fluid particles that left the domain or went non-finite (run.json), which none should.
/// `judged`: with the bound 0, or only reported.
pub fn lost_particles(dir: &Path, judged: bool) -> Result<Metric> {
    let s = RunSummary::read(dir)?;
    Ok(Metric {
        name: "fluid particles lost".into(),
        value: s.particles_excluded as f64,
        unit: Unit::Count,
        bound: judged.then_some(Bound::AtMost(0.0)),
        detail: format!(
            "{} of {} fluid particles excluded",
            s.particles_excluded, s.particles_fluid
        ),
    })
}

/// |g| of every shipped case file, m/s²: end times given in the reference's time unit are
/// turned into seconds with it before the case is loaded.
pub(crate) const CASE_G: f64 = 9.81;

/// |g| of the scenario.
pub(crate) fn gravity(sc: &Scenario) -> f64 {
    sc.physics.gravity.iter().map(|g| g * g).sum::<f64>().sqrt()
}

/// The simulated curve of a figure.
pub(crate) fn sim_curve(label: &str, points: Vec<(f64, f64)>) -> Curve {
    Curve {
        label: label.to_string(),
        points,
        reference: false,
    }
}

/// The reference curve of a figure.
pub(crate) fn reference_curve(label: &str, points: Vec<(f64, f64)>) -> Curve {
    Curve {
        label: label.to_string(),
        points,
        reference: true,
    }
}

#[cfg(test)]
mod tests;

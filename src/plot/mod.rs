//! `wgsph plot DIR`: PNG plots of the probe time series of a finished run.
//!
//! One PNG per probe CSV (`DIR/probes/<name>.csv`) is written to `DIR/plots/<name>.png`, and
//! one per column of a table (a body's or a tracked point's `DIR/probes/<table>.csv`), named
//! `<table>.<column>` and drawn to `DIR/plots/<table>_<column>.png`,
//! atomically (rendered into memory, encoded and written with [`write_atomic`]). Reference data
//! (`PROBE=FILE.csv[:xscale:yscale]`) is drawn over a probe after scaling its columns, and the
//! simulation's error against it — simulation interpolated linearly at the reference's times —
//! is returned and written to `DIR/plots/errors.csv`. Other runs of the same case can be drawn
//! on the same axes (`--with LABEL=DIR`), e.g. to compare wall treatments.
//!
//! Text is drawn with the embedded DejaVu Sans (`assets/fonts/`, Bitstream Vera licence) through
//! plotters' pure-Rust `ab_glyph` path: no system font or library is needed.

pub mod animation;
pub mod color_scale;
pub mod flood_map;
pub mod perspective;
pub mod snapshot;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use anyhow::{anyhow, bail, Context, Result};
use plotters::prelude::*;

use crate::output::flood_maps::{map_label, map_stems, read_map, GROUND_MAP, MAPS_DIR};
pub use crate::output::PLOTS_DIR;
use crate::output::{fmt_f64, write_atomic, Manifest, PROBES_DIR, RUN_SUMMARY_FILE};
/// Error summary written next to the plots when references are given.
pub const ERRORS_FILE: &str = "errors.csv";

/// Size of every PNG, pixels.
const WIDTH: u32 = 900;
const HEIGHT: u32 = 540;

static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// A two-column CSV: the header's column names and the rows.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub columns: (String, String),
    pub points: Vec<(f64, f64)>,
}

/// Parses a CSV with `#` comment lines, one header line and two numeric columns per row (extra
/// columns are an error; blank lines are skipped; `nan`/`inf` are accepted). Errors name the
/// line number; `name` is used in them (a file path).
pub fn parse_csv(text: &str, name: &str) -> Result<Series> {
    let mut columns = None;
    let mut points = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != 2 {
            bail!(
                "{name}:{}: expected 2 comma-separated columns, found {}: {line:?}",
                i + 1,
                fields.len()
            );
        }
        if columns.is_none() {
            columns = Some((fields[0].to_string(), fields[1].to_string()));
            continue;
        }
        let num = |s: &str| {
            s.parse::<f64>()
                .map_err(|_| anyhow!("{name}:{}: {s:?} is not a number", i + 1))
        };
        points.push((num(fields[0])?, num(fields[1])?));
    }
    let columns = columns.ok_or_else(|| anyhow!("{name}: no header line (and no data)"))?;
    Ok(Series { columns, points })
}

/// Reads and parses a CSV file (see [`parse_csv`]).
pub fn read_csv(path: &Path) -> Result<Series> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    parse_csv(&text, &path.display().to_string())
}

/// `PROBE=FILE[:xscale:yscale]`: reference data drawn over a probe, its x multiplied by
/// `xscale` and y by `yscale` (default 1 and 1), e.g. dimensionless t·sqrt(g/H) and p/(ρgH)
/// turned into seconds and pascals with xscale = sqrt(H/g), yscale = ρgH.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceSpec {
    pub probe: String,
    pub file: PathBuf,
    pub xscale: f64,
    pub yscale: f64,
}

impl FromStr for ReferenceSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let usage = "expected PROBE=FILE.csv or PROBE=FILE.csv:XSCALE:YSCALE";
        let (probe, rest) = s
            .split_once('=')
            .ok_or_else(|| format!("{s:?}: no '='; {usage}"))?;
        if probe.is_empty() || rest.is_empty() {
            return Err(format!("{s:?}: empty probe name or file; {usage}"));
        }
        let parts: Vec<&str> = rest.rsplitn(3, ':').collect();
        let num = |v: &str| v.parse::<f64>().ok().filter(|x| x.is_finite() && *x != 0.0);
        let (file, xscale, yscale) = match parts.as_slice() {
            [y, x, file] if num(x).is_some() && num(y).is_some() => {
                (*file, num(x).unwrap(), num(y).unwrap())
            }
            _ if parts.len() >= 2 && parts[0].parse::<f64>().is_ok() => {
                return Err(format!(
                    "{s:?}: give both scales, finite and non-zero; {usage}"
                ))
            }
            _ => (rest, 1.0, 1.0),
        };
        Ok(ReferenceSpec {
            probe: probe.to_string(),
            file: PathBuf::from(file),
            xscale,
            yscale,
        })
    }
}

/// `LABEL=DIR`: another run drawn on the same axes. Split at the last '=', so that a label may
/// say `dx=0.04` (a directory name with '=' cannot be given).
#[derive(Clone, Debug, PartialEq)]
pub struct OtherRun {
    pub label: String,
    pub dir: PathBuf,
}

impl FromStr for OtherRun {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s.rsplit_once('=') {
            Some((l, d)) if !l.is_empty() && !d.is_empty() => Ok(OtherRun {
                label: l.to_string(),
                dir: PathBuf::from(d),
            }),
            _ => Err(format!("{s:?}: expected LABEL=DIR")),
        }
    }
}

/// What to plot.
#[derive(Clone, Debug, Default)]
pub struct PlotOptions {
    /// Reference overlays (several per probe allowed).
    pub references: Vec<ReferenceSpec>,
    /// Label of the main run in legends and errors.csv (default: its case name).
    pub label: Option<String>,
    /// Other runs drawn on the same axes; their probes are matched by name.
    pub others: Vec<OtherRun>,
    /// Only these probes (all when empty).
    pub probes: Vec<String>,
    /// Plot only t ≤ this (and compute errors only there).
    pub t_max_s: Option<f64>,
    /// Centred moving average of the simulated series over this many seconds before drawing
    /// and comparing (0 or `None`: raw samples). SPH point pressures carry acoustic noise that
    /// an experimental sensor of finite size and bandwidth does not see.
    pub smooth_s: Option<f64>,
}

/// Error of one run's probe against one reference, over the reference points that fall in the
/// simulated time range. Values are in the probe's unit.
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorSummary {
    pub run: String,
    /// Moving-average window applied to the simulation, s (0: raw).
    pub smooth_s: f64,
    pub probe: String,
    pub reference: String,
    /// Reference points compared (inside the simulated time range).
    pub points: usize,
    pub t_start_s: f64,
    pub t_end_s: f64,
    /// sqrt(mean((sim − ref)²)).
    pub rms_error: f64,
    /// max |sim − ref| and where.
    pub max_abs_error: f64,
    pub t_max_abs_error_s: f64,
    /// Largest value of the simulation and of the reference over the compared window.
    pub peak_sim: f64,
    pub peak_reference: f64,
}

/// Linear interpolation of `series` (non-decreasing in t) at `t`; `None` outside its range or
/// where a neighbour is not finite.
pub fn interpolate(series: &[(f64, f64)], t: f64) -> Option<f64> {
    let first = series.first()?.0;
    let last = series.last()?.0;
    if !(t >= first && t <= last) {
        return None;
    }
    let k = series.partition_point(|p| p.0 < t);
    if k < series.len() && series[k].0 == t {
        return Some(series[k].1).filter(|v| v.is_finite());
    }
    let (t0, y0) = series[k - 1];
    let (t1, y1) = series[k];
    let y = if t1 > t0 {
        y0 + (y1 - y0) * (t - t0) / (t1 - t0)
    } else {
        y1
    };
    Some(y).filter(|v| v.is_finite())
}

/// Compares `sim` with `reference` at the reference's points (sim interpolated); reference
/// points outside the simulated range are skipped. `None` when no point can be compared.
pub fn compare(sim: &[(f64, f64)], reference: &[(f64, f64)]) -> Option<ErrorSummary> {
    let mut n = 0usize;
    let mut sum2 = 0.0;
    let (mut max_err, mut t_max_err) = (0.0f64, f64::NAN);
    let (mut t_start, mut t_end) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut peak_ref = f64::NEG_INFINITY;
    for &(t, r) in reference {
        let Some(s) = interpolate(sim, t) else {
            continue;
        };
        if !r.is_finite() {
            continue;
        }
        let e = s - r;
        n += 1;
        sum2 += e * e;
        if e.abs() > max_err || n == 1 {
            max_err = e.abs();
            t_max_err = t;
        }
        t_start = t_start.min(t);
        t_end = t_end.max(t);
        peak_ref = peak_ref.max(r);
    }
    if n == 0 {
        return None;
    }
    let peak_sim = sim
        .iter()
        .filter(|p| p.0 >= t_start && p.0 <= t_end && p.1.is_finite())
        .map(|p| p.1)
        .chain(
            [interpolate(sim, t_start), interpolate(sim, t_end)]
                .into_iter()
                .flatten(),
        )
        .fold(f64::NEG_INFINITY, f64::max);
    Some(ErrorSummary {
        run: String::new(),
        smooth_s: 0.0,
        probe: String::new(),
        reference: String::new(),
        points: n,
        t_start_s: t_start,
        t_end_s: t_end,
        rms_error: (sum2 / n as f64).sqrt(),
        max_abs_error: max_err,
        t_max_abs_error_s: t_max_err,
        peak_sim,
        peak_reference: peak_ref,
    })
}

/// Axis label of a probe column: `pressure_pa` → "pressure [Pa]", `height_m` → "height [m]",
/// `front_m` → "front [m]", `discharge_m3_s` → "discharge [m³/s]"; anything else as written.
pub fn axis_label(column: &str) -> String {
    match column {
        "pressure_pa" => "pressure [Pa]".into(),
        "height_m" => "height [m]".into(),
        "front_m" => "front [m]".into(),
        "discharge_m3_s" => "discharge [m³/s]".into(),
        "discharge_m2_s" => "discharge [m²/s]".into(),
        c => match c.rsplit_once('_') {
            Some((q, "m")) => format!("{q} [m]"),
            Some((q, "pa")) => format!("{q} [Pa]"),
            Some((q, "s")) => format!("{q} [s]"),
            _ => c.to_string(),
        },
    }
}

/// What [`plot_run`] wrote.
#[derive(Debug, Default)]
pub struct PlotReport {
    pub pngs: Vec<PathBuf>,
    /// One per (run, reference) pair that could be compared.
    pub errors: Vec<ErrorSummary>,
    /// Path of errors.csv when references were given.
    pub errors_csv: Option<PathBuf>,
}

/// One curve on a plot: a coloured line, or (`reference`) a thin black line with dots.
#[derive(Clone, Debug)]
pub struct Curve {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub reference: bool,
}

fn case_name(dir: &Path) -> String {
    std::fs::read_to_string(dir.join(RUN_SUMMARY_FILE))
        .ok()
        .and_then(|s| serde_json::from_str::<serde_json::Value>(&s).ok())
        .and_then(|v| v.get("case")?.as_str().map(str::to_string))
        .unwrap_or_else(|| {
            dir.file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| "run".into())
        })
}

/// Separates a table from one of its columns in a probe name: `body_box.y_m` is the column
/// `y_m` of `probes/body_box.csv` (probe and body names have no dots).
const TABLE_COLUMN: char = '.';

/// Probe names, sorted: the file stems of DIR/probes/*.csv, and `<table>.<column>` for each
/// value column of a table.
pub fn probe_names(dir: &Path) -> Result<Vec<String>> {
    let pdir = dir.join(PROBES_DIR);
    let mut names = Vec::new();
    for e in std::fs::read_dir(&pdir).with_context(|| {
        format!(
            "cannot list {} (is {} the output folder of a run?)",
            pdir.display(),
            dir.display()
        )
    })? {
        let p = e?.path();
        if p.extension().is_some_and(|x| x == "csv") && p.is_file() {
            if let Some(s) = p.file_stem().and_then(|s| s.to_str()) {
                match header_columns(&p) {
                    Some(columns) if columns.len() > 2 => {
                        names.extend(columns[1..].iter().map(|c| format!("{s}{TABLE_COLUMN}{c}")))
                    }
                    _ => names.push(s.to_string()),
                }
            }
        }
    }
    names.sort();
    Ok(names)
}

/// The column names of the CSV's header (its first line that is not blank or a `#` comment).
fn header_columns(path: &Path) -> Option<Vec<String>> {
    use std::io::BufRead;
    let file = std::fs::File::open(path).ok()?;
    std::io::BufReader::new(file)
        .lines()
        .map_while(Result::ok)
        .find(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|header| header.split(',').map(|c| c.trim().to_string()).collect())
}

/// `(t, column)` of a CSV table with several columns (time first; `#` comments and blank lines
/// skipped): a body's or a tracked point's. Errors name the file, line and column.
pub fn read_table_column(path: &Path, column: &str) -> Result<Series> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    parse_table_column(&text, &path.display().to_string(), column)
}

/// [`read_table_column`] of the text of a table; `name` (a file path) is used in errors.
pub fn parse_table_column(text: &str, name: &str, column: &str) -> Result<Series> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#'));
    let header = lines
        .next()
        .ok_or_else(|| anyhow!("{name}: no header line (and no data)"))?
        .1;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let col = names
        .iter()
        .position(|c| *c == column)
        .ok_or_else(|| anyhow!("{name}: no column {column:?} in {header:?}"))?;
    let points = lines
        .map(|(i, l)| {
            let fields: Vec<&str> = l.split(',').collect();
            let num = |k: usize| -> Result<f64> {
                let s = fields
                    .get(k)
                    .ok_or_else(|| anyhow!("{name}:{}: too few columns", i + 1))?;
                s.trim()
                    .parse()
                    .map_err(|_| anyhow!("{name}:{}: {s:?} is not a number", i + 1))
            };
            Ok((num(0)?, num(col)?))
        })
        .collect::<Result<_>>()?;
    Ok(Series {
        columns: (names[0].to_string(), column.to_string()),
        points,
    })
}

/// The series of the probe `name` (see [`probe_names`]) in the run in `dir`.
pub fn read_probe(dir: &Path, name: &str) -> Result<Series> {
    match name.split_once(TABLE_COLUMN) {
        Some((table, column)) => {
            read_table_column(&dir.join(PROBES_DIR).join(format!("{table}.csv")), column)
        }
        None => read_csv(&dir.join(PROBES_DIR).join(format!("{name}.csv"))),
    }
}

/// Centred moving average over a window of `width` (same units as t): each sample becomes the
/// mean of the finite samples within ±width/2 of it (edges included). `width` ≤ 0 returns the series unchanged.
pub fn moving_average(series: &[(f64, f64)], width: f64) -> Vec<(f64, f64)> {
    if width.is_nan() || width <= 0.0 {
        return series.to_vec();
    }
    // A sample exactly at the window's edge is in, whatever the rounding of t.
    let half = 0.5 * width * (1.0 + 1e-9);
    let (mut lo, mut hi) = (0usize, 0usize);
    let (mut sum, mut n) = (0.0, 0usize);
    let mut out = Vec::with_capacity(series.len());
    for &(t, y) in series {
        while hi < series.len() && series[hi].0 <= t + half {
            if series[hi].1.is_finite() {
                sum += series[hi].1;
                n += 1;
            }
            hi += 1;
        }
        while series[lo].0 < t - half {
            if series[lo].1.is_finite() {
                sum -= series[lo].1;
                n -= 1;
            }
            lo += 1;
        }
        let v = if y.is_finite() && n > 0 {
            sum / n as f64
        } else {
            f64::NAN
        };
        out.push((t, v));
    }
    out
}

fn clip(points: Vec<(f64, f64)>, t_max: Option<f64>) -> Vec<(f64, f64)> {
    match t_max {
        Some(tm) => points.into_iter().filter(|p| p.0 <= tm + 1e-12).collect(),
        None => points,
    }
}

/// Plots every probe of the run in `dir` (see the module doc). Errors name the file involved.
pub fn plot_run(dir: &Path, opts: &PlotOptions) -> Result<PlotReport> {
    let case = case_name(dir);
    let main_label = opts.label.clone().unwrap_or_else(|| case.clone());
    let mut names = probe_names(dir)?;
    let maps: Vec<String> = (map_stems(dir).into_iter())
        .filter(|s| s != GROUND_MAP)
        .collect();
    if names.is_empty() && maps.is_empty() {
        bail!(
            "{} has no probe CSV and {} no map",
            dir.join(PROBES_DIR).display(),
            dir.join(MAPS_DIR).display()
        );
    }
    for want in opts
        .probes
        .iter()
        .chain(opts.references.iter().map(|r| &r.probe))
    {
        if !names.contains(want) {
            bail!(
                "probe {want:?} not found in {}; probes: {}",
                dir.join(PROBES_DIR).display(),
                names.join(", ")
            );
        }
    }
    if !opts.probes.is_empty() {
        names.retain(|n| opts.probes.contains(n));
    }
    let plots = dir.join(PLOTS_DIR);
    std::fs::create_dir_all(&plots)
        .with_context(|| format!("cannot create {}", plots.display()))?;
    // The plots join the run's files: the next run into the folder removes them.
    let mut manifest = Manifest::open(dir, 0)?;
    let mut report = PlotReport::default();
    for name in &names {
        let main = read_probe(dir, name)?;
        let smooth = opts.smooth_s.unwrap_or(0.0);
        let prep = |points| moving_average(&clip(points, opts.t_max_s), smooth);
        let mut runs = vec![(main_label.clone(), prep(main.points))];
        for o in &opts.others {
            runs.push((o.label.clone(), prep(read_probe(&o.dir, name)?.points)));
        }
        let mut curves: Vec<Curve> = runs
            .iter()
            .map(|(label, points)| Curve {
                label: label.clone(),
                points: points.clone(),
                reference: false,
            })
            .collect();
        for r in opts.references.iter().filter(|r| &r.probe == name) {
            let data = read_csv(&r.file)?;
            let scaled: Vec<(f64, f64)> = data
                .points
                .iter()
                .map(|&(x, y)| (x * r.xscale, y * r.yscale))
                .collect();
            let scaled = clip(scaled, opts.t_max_s);
            let ref_name = r
                .file
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            for (label, sim) in &runs {
                if let Some(mut e) = compare(sim, &scaled) {
                    e.run = label.clone();
                    e.smooth_s = smooth;
                    e.probe = name.clone();
                    e.reference = r.file.display().to_string();
                    report.errors.push(e);
                }
            }
            // Drawn over the simulated time range only.
            let t_end = runs
                .iter()
                .filter_map(|r| r.1.last().map(|p| p.0))
                .fold(f64::NEG_INFINITY, f64::max);
            curves.push(Curve {
                label: format!("reference: {ref_name}"),
                points: scaled.into_iter().filter(|p| p.0 <= t_end).collect(),
                reference: true,
            });
        }
        let png = plots.join(format!("{}.png", name.replace(TABLE_COLUMN, "_")));
        let title = if smooth > 0.0 {
            format!(
                "{case}: {name} ({} ms moving average)",
                fmt_f64(1e3 * smooth)
            )
        } else {
            format!("{case}: {name}")
        };
        manifest.claim_path(&png)?;
        render_png(&png, &title, "t [s]", &axis_label(&main.columns.1), &curves)?;
        report.pngs.push(png);
    }
    if opts.probes.is_empty() {
        report
            .pngs
            .extend(draw_run_maps(dir, &case, &maps, &mut manifest)?);
    }
    if !opts.references.is_empty() {
        let path = plots.join(ERRORS_FILE);
        let text = errors_csv(&report.errors);
        manifest.claim_path(&path)?;
        write_atomic(&path, |w| w.write_all(text.as_bytes()))?;
        report.errors_csv = Some(path);
    }
    Ok(report)
}

/// Draws each of the run's maps `stems` over the hillshade of its ground (`maps/ground_m.asc`)
/// to `plots/map_<stem>.png`, as the run drew them in `maps/`.
fn draw_run_maps(
    dir: &Path,
    case: &str,
    stems: &[String],
    manifest: &mut Manifest,
) -> Result<Vec<PathBuf>> {
    if stems.is_empty() {
        return Ok(Vec::new());
    }
    let ground = read_map(dir, GROUND_MAP)?;
    let mut pngs = Vec::new();
    for stem in stems {
        let map = read_map(dir, stem)?;
        let png = dir.join(PLOTS_DIR).join(format!("map_{stem}.png"));
        manifest.claim_path(&png)?;
        let label = map_label(stem).unwrap_or(stem);
        flood_map::draw_map(&png, &map, &ground, case, label)?;
        pngs.push(png);
    }
    Ok(pngs)
}

/// errors.csv text: a header and one row per comparison.
pub fn errors_csv(errors: &[ErrorSummary]) -> String {
    let mut s = String::from(
        "run,smooth_s,probe,reference,points,t_start_s,t_end_s,rms_error,max_abs_error,t_max_abs_error_s,peak_sim,peak_reference\n",
    );
    let q = |v: &str| {
        if v.contains([',', '"', '\n']) {
            format!("\"{}\"", v.replace('"', "\"\""))
        } else {
            v.to_string()
        }
    };
    for e in errors {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{}",
            q(&e.run),
            fmt_f64(e.smooth_s),
            q(&e.probe),
            q(&e.reference),
            e.points,
            fmt_f64(e.t_start_s),
            fmt_f64(e.t_end_s),
            fmt_f64(e.rms_error),
            fmt_f64(e.max_abs_error),
            fmt_f64(e.t_max_abs_error_s),
            fmt_f64(e.peak_sim),
            fmt_f64(e.peak_reference)
        );
    }
    s
}

fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // The embedded file is a valid TrueType font; a failure here is a build defect.
        if plotters::style::register_font("sans-serif", FontStyle::Normal, FONT).is_err() {
            panic!("embedded font assets/fonts/DejaVuSans.ttf is not a valid font");
        }
    });
}

const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// The largest magnitude an axis reaches: beyond it the span of an axis overflows f64, and
/// plotters' tick loop (which steps over the span) never ends (issue 64: a probe table spanning
/// ±1e308). Values beyond it are drawn clipped at the axis' end.
const AXIS_LIMIT: f64 = 1e300;

/// The smallest span of an axis relative to its magnitude: below it the ticks' step is lost in
/// the values' rounding (1e16 + 0.2 == 1e16) and plotters' tick loop never ends.
const AXIS_RESOLUTION: f64 = 1e-9;

/// Axis range of the finite values, padded by 5 % (and widened when degenerate), within
/// ±[`AXIS_LIMIT`] and at least [`AXIS_RESOLUTION`] of its magnitude wide.
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let (lo, hi) = (lo.max(-AXIS_LIMIT), hi.min(AXIS_LIMIT));
    let magnitude = lo.abs().max(hi.abs());
    let span = hi - lo;
    let pad = if span > AXIS_RESOLUTION * magnitude {
        0.05 * span
    } else {
        0.5 * magnitude.max(1.0)
    };
    (lo - pad, hi + pad)
}

/// Finite runs of a curve (a NaN splits the line).
fn segments(points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let mut out = vec![Vec::new()];
    for &p in points {
        if p.0.is_finite() && p.1.is_finite() {
            out.last_mut().unwrap().push(p);
        } else if !out.last().unwrap().is_empty() {
            out.push(Vec::new());
        }
    }
    out.retain(|s| !s.is_empty());
    out
}

/// Renders the curves into an RGB buffer and writes it to `path` as PNG, atomically. NaN
/// points split a line; the axes span the finite points of every curve.
pub fn render_png(
    path: &Path,
    title: &str,
    xlabel: &str,
    ylabel: &str,
    curves: &[Curve],
) -> Result<()> {
    register_font();
    let mut buf = vec![0u8; (WIDTH * HEIGHT * 3) as usize];
    let (x0, x1) = range(curves.iter().flat_map(|c| c.points.iter().map(|p| p.0)));
    let (y0, y1) = range(curves.iter().flat_map(|c| c.points.iter().map(|p| p.1)));
    let draw = |buf: &mut [u8]| -> std::result::Result<(), Box<dyn std::error::Error + '_>> {
        let root = BitMapBackend::with_buffer(buf, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(80)
            .build_cartesian_2d(x0..x1, y0..y1)?;
        chart
            .configure_mesh()
            .x_desc(xlabel)
            .y_desc(ylabel)
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 16))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()?;
        let mut color_index = 0;
        for c in curves {
            let color = if c.reference {
                BLACK
            } else {
                let col = COLORS[color_index % COLORS.len()];
                color_index += 1;
                col
            };
            let style = ShapeStyle::from(&color).stroke_width(if c.reference { 1 } else { 2 });
            let mut labelled = false;
            for mut seg in segments(&c.points) {
                // Beyond the axes (past AXIS_LIMIT), a point's pixel overflows plotters' i32.
                for p in &mut seg {
                    *p = (p.0.clamp(x0, x1), p.1.clamp(y0, y1));
                }
                let series = chart.draw_series(LineSeries::new(seg.clone(), style))?;
                if !labelled {
                    series
                        .label(c.label.clone())
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
                    labelled = true;
                }
                if c.reference {
                    chart.draw_series(
                        seg.iter()
                            .map(|&p| Circle::new(p, 2, ShapeStyle::from(&BLACK).filled())),
                    )?;
                }
            }
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .position(SeriesLabelPosition::UpperRight)
            .draw()?;
        root.present()?;
        Ok(())
    };
    draw(&mut buf).map_err(|e| anyhow!("drawing {}: {e}", path.display()))?;
    write_png(path, (WIDTH, HEIGHT), &buf)
}

/// Writes an 8-bit RGB buffer of `size` pixels to `path` as PNG, atomically.
fn write_png(path: &Path, size: (u32, u32), rgb: &[u8]) -> Result<()> {
    write_atomic(path, |w| {
        let mut enc = png::Encoder::new(w, size.0, size.1);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header().map_err(std::io::Error::other)?;
        writer
            .write_image_data(rgb)
            .map_err(std::io::Error::other)?;
        writer.finish().map_err(std::io::Error::other)
    })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_reader_skips_comments_and_reads_header() {
        let text = "# source: a paper\n# second comment\nt_sqrt_g_over_H,p_over_rho_g_H\n0.081,0.023\n\n 2.435 , 1.612\n3,nan\n";
        let s = parse_csv(text, "x.csv").unwrap();
        assert_eq!(
            s.columns,
            ("t_sqrt_g_over_H".into(), "p_over_rho_g_H".into())
        );
        assert_eq!(s.points.len(), 3);
        assert_eq!(s.points[0], (0.081, 0.023));
        assert_eq!(s.points[1], (2.435, 1.612));
        assert!(s.points[2].1.is_nan());
    }

    #[test]
    fn csv_reader_errors_name_the_line() {
        let e = parse_csv("t_s,p\n0,1\n1,abc\n", "f.csv").unwrap_err();
        assert!(
            e.to_string().contains("f.csv:3") && e.to_string().contains("abc"),
            "{e}"
        );
        let e = parse_csv("t_s,p\n0,1,2\n", "f.csv").unwrap_err();
        assert!(e.to_string().contains("f.csv:2"), "{e}");
        assert!(parse_csv("# only comments\n", "f.csv").is_err());
        // The real reference file of the Lobovsky case reads.
        let r = read_csv(Path::new(
            "tests/data/db_lobovsky_2014_H300_sensor1_pressure.csv",
        ))
        .unwrap();
        assert!(r.points.len() > 50);
    }

    #[test]
    fn reference_spec_parses() {
        let r: ReferenceSpec = "sensor1=data/x.csv:0.17:2943".parse().unwrap();
        assert_eq!(r.probe, "sensor1");
        assert_eq!(r.file, PathBuf::from("data/x.csv"));
        assert_eq!((r.xscale, r.yscale), (0.17, 2943.0));
        let r: ReferenceSpec = "p=x.csv".parse().unwrap();
        assert_eq!(
            (r.file.to_str().unwrap(), r.xscale, r.yscale),
            ("x.csv", 1.0, 1.0)
        );
        assert!("p=x.csv:2".parse::<ReferenceSpec>().is_err());
        assert!("p=x.csv:0:1".parse::<ReferenceSpec>().is_err());
        assert!("x.csv".parse::<ReferenceSpec>().is_err());
        assert!("=x.csv".parse::<ReferenceSpec>().is_err());
        let o: OtherRun = "mirror=out/m".parse().unwrap();
        assert_eq!(
            (o.label.as_str(), o.dir.to_str().unwrap()),
            ("mirror", "out/m")
        );
        let o: OtherRun = "3D, dx=0.04=out/s3d".parse().unwrap();
        assert_eq!(
            (o.label.as_str(), o.dir.to_str().unwrap()),
            ("3D, dx=0.04", "out/s3d")
        );
        assert!("out/m".parse::<OtherRun>().is_err());
        assert!("dx=".parse::<OtherRun>().is_err());
    }

    #[test]
    fn interpolation_and_errors() {
        let sim = [(0.0, 0.0), (1.0, 10.0), (2.0, 10.0), (3.0, f64::NAN)];
        assert_eq!(interpolate(&sim, 0.25), Some(2.5));
        assert_eq!(interpolate(&sim, 1.0), Some(10.0));
        assert_eq!(interpolate(&sim, 1.5), Some(10.0));
        assert_eq!(interpolate(&sim, -0.1), None);
        assert_eq!(interpolate(&sim, 2.5), None); // a NaN neighbour
        assert_eq!(interpolate(&sim, 3.5), None);
        // Reference at t = 0.5 (sim 5), 1.5 (sim 10), 5 (outside: skipped).
        let reference = [(0.5, 4.0), (1.5, 13.0), (5.0, 100.0)];
        let e = compare(&sim, &reference).unwrap();
        assert_eq!(e.points, 2);
        assert_eq!((e.t_start_s, e.t_end_s), (0.5, 1.5));
        assert!((e.rms_error - ((1.0 + 9.0) / 2.0f64).sqrt()).abs() < 1e-12);
        assert_eq!((e.max_abs_error, e.t_max_abs_error_s), (3.0, 1.5));
        assert_eq!((e.peak_sim, e.peak_reference), (10.0, 13.0));
        assert!(compare(&sim, &[(9.0, 1.0)]).is_none());
        // Identical series: zero error.
        let s2 = [(0.0, 1.0), (1.0, 3.0)];
        let e = compare(&s2, &s2).unwrap();
        assert_eq!((e.rms_error, e.max_abs_error), (0.0, 0.0));
    }

    #[test]
    fn moving_average_is_centred() {
        let s: Vec<(f64, f64)> = (0..6).map(|k| (k as f64, (k * k) as f64)).collect();
        let m = moving_average(&s, 2.0); // ±1 sample
        assert_eq!(m[0], (0.0, 0.5));
        assert_eq!(m[1], (1.0, 5.0 / 3.0));
        assert_eq!(m[5], (5.0, 20.5));
        assert_eq!(moving_average(&s, 0.0), s);
        let n = moving_average(&[(0.0, 1.0), (1.0, f64::NAN), (2.0, 3.0)], 4.0);
        assert_eq!((n[0].1, n[2].1), (2.0, 2.0));
        assert!(n[1].1.is_nan());
    }

    /// Values no axis can span (±1e308: the span overflows), or a span lost in the values'
    /// rounding, drew forever inside plotters (issue 64); each must give a picture, soon.
    #[test]
    fn extreme_values_are_drawn_and_do_not_hang() {
        let dir = std::env::temp_dir().join(format!("wgsph-plot-extreme-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let cases: Vec<Vec<(f64, f64)>> = vec![
            vec![(0.0, -1e308), (1.0, 1e308)],
            vec![(0.0, f64::MIN), (1.0, f64::MAX)],
            vec![(-1e308, 0.0), (1e308, 1.0)],
            vec![(0.0, 1e16), (1.0, 1e16 + 2.0)],
            vec![(0.0, 1e300), (1.0, 1e300)],
            vec![(0.0, 0.0), (1.0, 1e-300)],
            vec![(0.0, -5e-324), (1e-310, 5e-324)],
            vec![(0.0, f64::NAN), (1.0, f64::INFINITY)],
        ];
        let (tx, rx) = std::sync::mpsc::channel();
        let d = dir.clone();
        std::thread::spawn(move || {
            for (k, points) in cases.into_iter().enumerate() {
                let path = d.join(format!("{k}.png"));
                let curve = Curve {
                    label: "p".into(),
                    points,
                    reference: false,
                };
                tx.send((k, render_png(&path, "t", "x", "y", &[curve]).map(|_| path)))
                    .unwrap();
            }
        });
        for k in 0..8 {
            let (i, drawn) = rx
                .recv_timeout(std::time::Duration::from_secs(60))
                .unwrap_or_else(|_| panic!("case {k}: still drawing after 60 s"));
            let path = drawn.unwrap_or_else(|e| panic!("case {i}: {e:#}"));
            assert!(std::fs::metadata(&path).unwrap().len() > 1000, "case {i}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A damaged probe table (cut short, words overwritten, a byte flipped) is an error or
    /// a series, never a panic, read whole or by column.
    #[test]
    fn a_damaged_probe_table_is_an_error_not_a_panic() {
        let text = "t_s,x_m,y_m\n0,0.5,0.3\n0.1,0.5,nan\n0.2,-inf,1e308\n";
        let whole = |b: &[u8]| parse_csv(&String::from_utf8_lossy(b), "p.csv");
        let column = |b: &[u8]| parse_table_column(&String::from_utf8_lossy(b), "p.csv", "y_m");
        assert_eq!(column(text.as_bytes()).unwrap().points.len(), 3);
        crate::output::test_util::survives_damage("a table", text.as_bytes(), 1, whole);
        crate::output::test_util::survives_damage("a table's column", text.as_bytes(), 1, column);
    }

    #[test]
    fn axis_labels_have_units() {
        assert_eq!(axis_label("pressure_pa"), "pressure [Pa]");
        assert_eq!(axis_label("height_m"), "height [m]");
        assert_eq!(axis_label("front_m"), "front [m]");
        assert_eq!(axis_label("discharge_m3_s"), "discharge [m³/s]");
        assert_eq!(axis_label("discharge_m2_s"), "discharge [m²/s]");
        assert_eq!(axis_label("speed"), "speed");
    }

    #[test]
    fn plots_a_synthetic_run_directory() {
        let dir = std::env::temp_dir().join(format!("wgsph-plot-test-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("probes")).unwrap();
        std::fs::write(dir.join("run.json"), r#"{"case": "synthetic"}"#).unwrap();
        let mut p = String::from("t_s,pressure_pa\n");
        let mut h = String::from("t_s,height_m\n");
        for k in 0..=100 {
            let t = 0.01 * k as f64;
            let _ = writeln!(p, "{t},{}", 1000.0 * t);
            let _ = writeln!(h, "{t},{}", if k == 50 { f64::NAN } else { 0.3 - 0.1 * t });
        }
        std::fs::write(dir.join("probes/p1.csv"), p).unwrap();
        std::fs::write(dir.join("probes/gauge.csv"), h).unwrap();
        // A body's table: one plot per column.
        std::fs::write(
            dir.join("probes/body_box.csv"),
            "t_s,x_m,y_m,angle_deg\n0,0.5,0.3,0\n0.1,0.5,0.29,1\n",
        )
        .unwrap();
        let y = read_probe(&dir, "body_box.y_m").unwrap();
        assert_eq!(y.columns, ("t_s".to_string(), "y_m".to_string()));
        assert_eq!(y.points, vec![(0.0, 0.3), (0.1, 0.29)]);
        let err = read_probe(&dir, "body_box.z_m").unwrap_err().to_string();
        assert!(
            err.contains("body_box.csv") && err.contains("\"z_m\""),
            "{err}"
        );
        // Dimensionless reference: y = 2 t* with t* = t / 0.5, scaled back: x·0.5, y·250.
        let refp = dir.join("ref.csv");
        std::fs::write(
            &refp,
            "# made up\nt_star,p_star\n0.2,0.4\n1.0,2.0\n1.8,3.6\n9,9\n",
        )
        .unwrap();
        let opts = PlotOptions {
            references: vec![format!("p1={}:0.5:250", refp.display()).parse().unwrap()],
            ..Default::default()
        };
        let rep = plot_run(&dir, &opts).unwrap();
        assert_eq!(rep.pngs.len(), 5);
        for png in &rep.pngs {
            let bytes = std::fs::read(png).unwrap();
            assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{}", png.display());
            assert!(bytes.len() > 2000);
        }
        for png in [
            "p1",
            "gauge",
            "body_box_x_m",
            "body_box_y_m",
            "body_box_angle_deg",
        ] {
            assert!(dir.join(format!("plots/{png}.png")).is_file(), "{png}");
        }
        // Reference (0.1 s, 100 Pa), (0.5 s, 500 Pa), (0.9 s, 900 Pa): the simulation matches.
        assert_eq!(rep.errors.len(), 1);
        let e = &rep.errors[0];
        assert_eq!(
            (e.run.as_str(), e.probe.as_str(), e.points),
            ("synthetic", "p1", 3)
        );
        assert!(e.rms_error < 1e-9 && e.max_abs_error < 1e-9, "{e:?}");
        let csv = std::fs::read_to_string(dir.join("plots/errors.csv")).unwrap();
        assert!(csv.starts_with("run,smooth_s,probe,reference,points,"));
        assert_eq!(csv.lines().count(), 2);
        // No temporary files left.
        let names: Vec<_> = std::fs::read_dir(dir.join("plots"))
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        assert_eq!(names.len(), 6, "{names:?}");
        // A reference for an unknown probe is an error naming the probes.
        let bad = PlotOptions {
            references: vec!["nope=x.csv".parse().unwrap()],
            ..Default::default()
        };
        let msg = plot_run(&dir, &bad).unwrap_err().to_string();
        assert!(msg.contains("gauge, p1"), "{msg}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

//! `DIR/report.md`: the table of every metric and a section per case with its plots.
//!
//! The header holds what reproduces the report (version, mode, command, adapter) and no date,
//! so two reports of the same build on the same adapter differ only in their measured numbers
//! and wall times.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Result;

use super::{Bound, CaseOutcome, Metric, Mode, Unit, Verdict};
use crate::output::write_listed;

/// The report's file name inside the output folder.
pub const REPORT_FILE: &str = "report.md";

/// The outcome of `wgsph validate`.
#[derive(Clone, Debug)]
pub struct Report {
    pub mode: Mode,
    /// The adapter the cases ran on.
    pub adapter: String,
    pub cases: Vec<CaseOutcome>,
}

/// One row of the table: case, metric, error, bound, result.
pub type Row = [String; 5];

impl Report {
    /// Every case passed: no failure, no metric over its bound.
    pub fn passed(&self) -> bool {
        self.cases.iter().all(CaseOutcome::passed)
    }

    /// The process exit status: 0 when every row passes, 1 otherwise.
    pub fn exit_status(&self) -> u8 {
        if self.passed() {
            0
        } else {
            1
        }
    }

    /// The table's rows: one per metric, and a FAIL row for a case without metrics (it could not
    /// be set up, went unstable, or its outputs could not be evaluated).
    pub fn rows(&self) -> Vec<Row> {
        let mut rows = Vec::new();
        for c in &self.cases {
            if let Some(f) = &c.failure {
                rows.push([
                    c.name.clone(),
                    "run".into(),
                    f.clone(),
                    "completes".into(),
                    "FAIL".into(),
                ]);
            }
            for m in &c.metrics {
                rows.push([
                    c.name.clone(),
                    m.name.clone(),
                    value_text(m),
                    bound_text(m),
                    match m.verdict() {
                        Verdict::Pass => "PASS",
                        Verdict::Fail => "FAIL",
                        Verdict::Info => "info",
                    }
                    .into(),
                ]);
            }
        }
        rows
    }

    /// The table as markdown.
    pub fn table(&self) -> String {
        let mut s =
            String::from("| case | metric | error | bound | result |\n|---|---|---|---|---|\n");
        for r in self.rows() {
            let cells: Vec<String> = r.iter().map(|c| cell(c)).collect();
            let _ = writeln!(s, "| {} |", cells.join(" | "));
        }
        s
    }

    /// The whole report; plot links are relative to `out`, the folder report.md is written to.
    pub fn markdown(&self, out: &Path) -> String {
        let mut s = String::from("# wgsph validation report\n\n");
        let flag = match self.mode {
            Mode::Quick => "--quick",
            Mode::Full => "--full",
        };
        let names: Vec<&str> = self.cases.iter().map(|c| c.name.as_str()).collect();
        // `--case` only when the cases are not the mode's whole set.
        let all: Vec<&str> = super::select(self.mode, &[])
            .map(|cases| cases.iter().map(|c| c.name).collect())
            .unwrap_or_default();
        let case_args: String = if names == all {
            String::new()
        } else {
            names.iter().map(|n| format!(" --case {n}")).collect()
        };
        let _ = writeln!(
            s,
            "- wgsph {}, {} mode",
            env!("CARGO_PKG_VERSION"),
            self.mode.name()
        );
        let _ = writeln!(s, "- command: `wgsph validate {flag} --out DIR{case_args}`");
        let _ = writeln!(s, "- adapter: {}", self.adapter);
        let (fails, judged) = self.cases.iter().fold((0, 0), |(f, j), c| {
            let rows = c
                .metrics
                .iter()
                .filter(|m| m.verdict() != Verdict::Info)
                .count()
                + usize::from(c.failure.is_some());
            let failed = c
                .metrics
                .iter()
                .filter(|m| m.verdict() == Verdict::Fail)
                .count()
                + usize::from(c.failure.is_some());
            (f + failed, j + rows)
        });
        let _ = writeln!(
            s,
            "- result: **{}** ({} of {judged} judged rows pass; \"info\" rows are reported, not judged in this mode)\n",
            if self.passed() { "PASS" } else { "FAIL" },
            judged - fails
        );
        s.push_str(&self.table());
        s.push_str(
            "\n## Wall time\n\n| case | particles | steps | wall time |\n|---|---|---|---|\n",
        );
        for c in &self.cases {
            let (particles, steps) = match &c.summary {
                Some(r) => (
                    (r.particles_fluid + r.particles_wall + r.particles_solid + r.particles_inlet)
                        .to_string(),
                    r.steps.to_string(),
                ),
                None => ("–".into(), "–".into()),
            };
            let time = match (&c.summary, c.reused) {
                (Some(r), true) => format!(
                    "{:.1} s (the earlier run's; evaluated in {:.1} s)",
                    r.wall_time_s, c.wall_s
                ),
                _ => format!("{:.1} s", c.wall_s),
            };
            let _ = writeln!(s, "| {} | {particles} | {steps} | {time} |", c.name);
        }
        let total: f64 = self.cases.iter().map(CaseOutcome::run_wall_s).sum();
        let _ = writeln!(s, "| total | | | {total:.1} s |");
        for c in &self.cases {
            let _ = writeln!(s, "\n## {}\n", c.name);
            let set: String = c.overrides.iter().map(|o| format!(" --set {o}")).collect();
            let _ = writeln!(
                s,
                "- case: `{}`{}",
                c.file,
                if set.is_empty() {
                    String::new()
                } else {
                    format!(", `{}`", set.trim_start())
                }
            );
            if c.citation.is_empty() {
                let _ = writeln!(s, "- reference: {}", c.reference);
            } else {
                let _ = writeln!(s, "- reference: `{}`: {}", c.reference, c.citation);
            }
            let _ = writeln!(s, "- outputs: `{}`", relative(&c.dir, out).display());
            if let Some(r) = &c.summary {
                let _ = writeln!(
                    s,
                    "- run: {}; t = {:.4} s, {} steps, {} fluid + {} boundary + {} solid particles, {:.1} s in the time loop{}",
                    r.status, r.simulated_time_s, r.steps, r.particles_fluid, r.particles_wall, r.particles_solid, r.wall_time_s,
                    if c.reused { format!(" (an earlier run on {}, evaluated again: `--reuse`)", r.adapter) } else { String::new() }
                );
            }
            if let Some(f) = &c.failure {
                let _ = writeln!(s, "- **FAIL**: {f}");
            }
            for m in &c.metrics {
                let _ = writeln!(s, "- {}: {} — {}", m.name, value_text(m), m.detail);
            }
            for p in &c.plots {
                let rel = relative(p, out);
                let name = p
                    .file_stem()
                    .map(|n| n.to_string_lossy())
                    .unwrap_or_default();
                let _ = writeln!(s, "\n![{} {name}]({})", c.name, link(&rel));
            }
        }
        s
    }

    /// Writes `out/report.md` atomically; returns its path.
    pub fn write(&self, out: &Path) -> Result<PathBuf> {
        let text = self.markdown(out);
        write_listed(out, REPORT_FILE, |w| w.write_all(text.as_bytes()))?;
        Ok(out.join(REPORT_FILE))
    }
}

/// `path` relative to `base` when it lies inside it.
fn relative(path: &Path, base: &Path) -> PathBuf {
    path.strip_prefix(base).unwrap_or(path).to_path_buf()
}

/// A markdown link target with '/' separators and spaces escaped.
fn link(path: &Path) -> String {
    let parts: Vec<String> = path
        .components()
        .map(|c| c.as_os_str().to_string_lossy().replace(' ', "%20"))
        .collect();
    parts.join("/")
}

/// A table cell: no '|' or line break may end it early.
fn cell(text: &str) -> String {
    text.replace('|', "\\|").replace(['\n', '\r'], " ")
}

/// A number with about four significant digits.
fn number(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    let magnitude = if v == 0.0 {
        0
    } else {
        v.abs().log10().floor() as i32
    };
    let decimals = (3 - magnitude).clamp(0, 6) as usize;
    format!("{v:.decimals$}")
}

/// A limit without float noise (0.3 * 100 = 30.000000000000004 reads "30").
fn limit(v: f64) -> String {
    let r = (v * 1e9).round() / 1e9;
    format!("{r}")
}

/// The metric's value as the error column shows it.
pub(crate) fn value_text(m: &Metric) -> String {
    match m.unit {
        Unit::Percent if m.value.is_finite() => format!("{:+.2} %", 100.0 * m.value),
        Unit::Percent => format!("{}", m.value),
        Unit::Number => number(m.value),
        Unit::Count => format!("{:.0}", m.value),
    }
}

/// The bound column: what the value must satisfy, in the value's unit.
fn bound_text(m: &Metric) -> String {
    let Some(b) = m.bound else {
        return "–".into();
    };
    let (scale, unit) = match m.unit {
        Unit::Percent => (100.0, " %"),
        _ => (1.0, ""),
    };
    let signed = |v: f64| {
        if m.unit == Unit::Percent && v > 0.0 {
            format!("+{}{unit}", limit(scale * v))
        } else {
            format!("{}{unit}", limit(scale * v))
        }
    };
    match b {
        Bound::Within(x) => format!("±{}{unit}", limit(scale * x)),
        Bound::Between(lo, hi) => format!("({}, {})", signed(lo), signed(hi)),
        Bound::AtMost(x) => format!("≤ {}{unit}", limit(scale * x)),
    }
}

//! Progress of a run as it goes: a bar on a terminal ([`ProgressBarView`], indicatif) or plain
//! log lines at a wall-clock cadence elsewhere ([`LogLines`]: CI, nohup, piped output).
//!
//! [`crate::run::run`] reports a [`RunStatus`] after every batch of steps (a few seconds of work
//! at most) and at every probe time, built from what the solver already holds on the host (its
//! 48-byte state is read back once per batch of steps anyway), so showing progress costs no
//! GPU readback.

use std::time::Duration;

use indicatif::{MultiProgress, ProgressBar, ProgressStyle};

/// Where a run stands.
#[derive(Clone, Debug, PartialEq)]
pub struct RunStatus {
    pub time_s: f64,
    pub end_s: f64,
    /// The current (CFL) time step [s].
    pub dt_s: f64,
    pub steps: u64,
    /// Particles of every kind: the particle-steps of run.json count them all.
    pub particles: u64,
    /// Particles that left the domain and are no longer integrated.
    pub excluded: u64,
    /// Fluid particles the outlets removed.
    pub drained: u64,
    /// Particle outputs written so far.
    pub outputs: usize,
    /// Wall time since the time loop started [s].
    pub wall_s: f64,
}

impl RunStatus {
    /// Simulated fraction, 0 to 1.
    pub fn fraction(&self) -> f64 {
        if self.end_s > 0.0 {
            (self.time_s / self.end_s).clamp(0.0, 1.0)
        } else {
            1.0
        }
    }

    /// Mean steps per wall second since the start.
    pub fn steps_per_s(&self) -> f64 {
        self.steps as f64 / self.wall_s.max(1e-9)
    }

    pub fn particle_steps_per_s(&self) -> f64 {
        self.steps_per_s() * self.particles as f64
    }

    /// Wall seconds left at the mean rate of simulated time per wall second so far; `None`
    /// before any time has been simulated.
    pub fn eta_s(&self) -> Option<f64> {
        (self.time_s > 0.0 && self.wall_s > 0.0)
            .then(|| (self.end_s - self.time_s).max(0.0) * self.wall_s / self.time_s)
    }

    /// "dt 1.230e-5 s  850 steps/s  2.100e6 particle-steps/s  ETA 1m 05s  excluded 0"
    fn details(&self) -> String {
        format!(
            "dt {:.3e} s  {} steps/s  {:.3e} particle-steps/s  ETA {}  excluded {}",
            self.dt_s,
            format_rate(self.steps_per_s()),
            self.particle_steps_per_s(),
            self.eta_s().map_or_else(|| "?".into(), format_duration),
            self.excluded
        )
    }

    /// One plain log line.
    pub fn line(&self) -> String {
        format!(
            "t = {:.4}/{} s ({:.0} %)  steps {}  outputs {}  {}",
            self.time_s,
            self.end_s,
            100.0 * self.fraction(),
            self.steps,
            self.outputs,
            self.details()
        )
    }
}

/// A rate with three significant digits or more, without an exponent: "850", "12.5", "1.85".
pub fn format_rate(x: f64) -> String {
    match x.abs() {
        a if a >= 100.0 => format!("{x:.0}"),
        a if a >= 10.0 => format!("{x:.1}"),
        _ => format!("{x:.2}"),
    }
}

/// "42 s", "3m 07s", "2h 05m": rounded to whole seconds (minutes past an hour).
pub fn format_duration(seconds: f64) -> String {
    if !seconds.is_finite() {
        return "?".into();
    }
    let s = seconds.max(0.0).round() as u64;
    match s {
        0..60 => format!("{s} s"),
        60..3600 => format!("{}m {:02}s", s / 60, s % 60),
        _ => format!("{}h {:02}m", s / 3600, (s % 3600) / 60),
    }
}

/// Receives a run's status as it goes.
pub trait Progress {
    /// Called after every batch of steps (a few seconds apart at most) and once per probe
    /// interval, after the solver reached the probe time.
    fn update(&mut self, status: &RunStatus);
    /// Called once when the run ends, completed or stopped early.
    fn finish(&mut self, status: &RunStatus);
}

/// Plain `log::info!` lines: the first update, then whenever `every_s` of wall time have
/// passed since the previous line (checked at each update, i.e. once per probe interval).
/// The end is left to the caller's summary.
#[derive(Clone, Debug)]
pub struct LogLines {
    every_s: f64,
    last_line_s: Option<f64>,
}

impl LogLines {
    /// The cadence of `wgsph run` off a terminal: a line about every 10 s of wall time, which
    /// keeps a day-long run's log to a few thousand lines.
    pub const EVERY: Duration = Duration::from_secs(10);

    pub fn new(every: Duration) -> Self {
        LogLines {
            every_s: every.as_secs_f64(),
            last_line_s: None,
        }
    }

    /// Whether a line is due at wall time `wall_s` (and if so, counts it as written).
    pub fn due(&mut self, wall_s: f64) -> bool {
        let due = self
            .last_line_s
            .is_none_or(|last| wall_s - last >= self.every_s);
        if due {
            self.last_line_s = Some(wall_s);
        }
        due
    }
}

impl Default for LogLines {
    fn default() -> Self {
        LogLines::new(LogLines::EVERY)
    }
}

impl Progress for LogLines {
    fn update(&mut self, status: &RunStatus) {
        if self.due(status.wall_s) {
            log::info!("{}", status.line());
        }
    }

    fn finish(&mut self, _status: &RunStatus) {}
}

/// A terminal progress bar (on stderr) with simulated time, dt, rates, ETA and excluded
/// particles. Log lines printed meanwhile go through [`crate::logging`], which hides the bar
/// while writing them.
pub struct ProgressBarView {
    bar: ProgressBar,
}

impl ProgressBarView {
    /// Bar positions per unit of simulated fraction.
    const LENGTH: u64 = 10_000;

    /// A bar added to `bars` (the set the logger knows about).
    pub fn new(bars: &MultiProgress) -> Self {
        let bar = bars.add(ProgressBar::new(Self::LENGTH));
        // The template is a constant: a parse failure is a defect caught by the unit test.
        if let Ok(style) = ProgressStyle::with_template(Self::TEMPLATE) {
            bar.set_style(style.progress_chars("=> "));
        }
        // Redraws the elapsed time while a long probe interval runs.
        bar.enable_steady_tick(Duration::from_secs(1));
        ProgressBarView { bar }
    }

    const TEMPLATE: &'static str = "[{elapsed_precise}] {bar:30} {prefix} {msg}";
}

impl Progress for ProgressBarView {
    fn update(&mut self, status: &RunStatus) {
        self.bar
            .set_position((status.fraction() * Self::LENGTH as f64).round() as u64);
        self.bar
            .set_prefix(format!("t {:.4}/{} s", status.time_s, status.end_s));
        self.bar.set_message(status.details());
    }

    fn finish(&mut self, status: &RunStatus) {
        self.update(status);
        if status.fraction() >= 1.0 {
            self.bar.finish();
        } else {
            self.bar.abandon();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn status(time_s: f64, wall_s: f64) -> RunStatus {
        RunStatus {
            time_s,
            end_s: 2.0,
            dt_s: 1e-4,
            steps: 5000,
            particles: 1000,
            excluded: 3,
            drained: 0,
            outputs: 4,
            wall_s,
        }
    }

    #[test]
    fn rates_and_eta() {
        let s = status(0.5, 10.0);
        assert_eq!(s.fraction(), 0.25);
        assert_eq!(s.steps_per_s(), 500.0);
        assert_eq!(s.particle_steps_per_s(), 5e5);
        // 0.5 s simulated in 10 s: 1.5 s left takes 30 s.
        assert_eq!(s.eta_s(), Some(30.0));
        assert_eq!(status(0.0, 0.0).eta_s(), None);
        assert_eq!(status(2.5, 10.0).fraction(), 1.0);
        let line = s.line();
        for part in [
            "t = 0.5000/2 s (25 %)",
            "steps 5000",
            "outputs 4",
            "dt 1.000e-4 s",
            "500 steps/s",
            "5.000e5 particle-steps/s",
            "ETA 30 s",
            "excluded 3",
        ] {
            assert!(line.contains(part), "{part:?} not in {line:?}");
        }
        assert!(status(0.0, 0.0).line().contains("ETA ?"));
    }

    #[test]
    fn rates_keep_three_digits() {
        assert_eq!(format_rate(1234.4), "1234");
        assert_eq!(format_rate(12.54), "12.5");
        assert_eq!(format_rate(1.854), "1.85");
    }

    #[test]
    fn durations_read_naturally() {
        assert_eq!(format_duration(0.2), "0 s");
        assert_eq!(format_duration(42.4), "42 s");
        assert_eq!(format_duration(187.0), "3m 07s");
        assert_eq!(format_duration(7500.0), "2h 05m");
        assert_eq!(format_duration(f64::INFINITY), "?");
    }

    #[test]
    fn log_lines_first_then_every_interval() {
        let mut l = LogLines::new(Duration::from_secs(10));
        // 10 s are counted from the previous line (10.6 s), not from the start.
        let due: Vec<bool> = [0.5, 3.0, 9.0, 10.6, 15.0, 20.5, 20.7, 21.0, 40.0]
            .into_iter()
            .map(|w| l.due(w))
            .collect();
        assert_eq!(
            due,
            [true, false, false, true, false, false, true, false, true]
        );
    }

    #[test]
    fn bar_template_parses() {
        assert!(ProgressStyle::with_template(ProgressBarView::TEMPLATE).is_ok());
    }
}

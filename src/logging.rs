//! Log lines of the `wgsph` command: `log` records (wgsph's and its libraries', wgpu's
//! included) filtered by level with RUST_LOG syntax through env_logger, written to stderr with
//! the wall time since start. While a progress bar is on screen each line is written with the
//! bar hidden, so the two never garble each other.

use std::io::Write as _;
use std::time::Instant;

use indicatif::MultiProgress;
use log::{Log, Metadata, Record};

/// Levels when RUST_LOG is not set: wgsph's progress and notes, only warnings from libraries
/// (wgpu and naga are chatty at info).
pub const DEFAULT_FILTER: &str = "warn,wgsph=info";

/// The filter in force: errors only with `--quiet` (whatever RUST_LOG says), else RUST_LOG
/// when set, else [`DEFAULT_FILTER`].
pub fn filter_spec(quiet: bool, rust_log: Option<&str>) -> &str {
    match rust_log {
        _ if quiet => "error",
        Some(s) if !s.trim().is_empty() => s,
        _ => DEFAULT_FILTER,
    }
}

/// env_logger's logger, writing with the bars in `bars` hidden.
struct BarAwareLogger {
    inner: env_logger::Logger,
    bars: MultiProgress,
}

impl Log for BarAwareLogger {
    fn enabled(&self, metadata: &Metadata) -> bool {
        self.inner.enabled(metadata)
    }

    fn log(&self, record: &Record) {
        if self.inner.matches(record) {
            self.bars.suspend(|| self.inner.log(record));
        }
    }

    fn flush(&self) {
        self.inner.flush();
    }
}

/// Installs the logger for the process (see the module doc). `bars` are the progress bars to
/// hide while a line is written. Lines look like `[   12.3 s INFO ] t = ...`; records from
/// other crates also name their module.
pub fn init(quiet: bool, bars: MultiProgress) -> Result<(), log::SetLoggerError> {
    let rust_log = std::env::var("RUST_LOG").ok();
    let start = Instant::now();
    let inner = env_logger::Builder::new()
        .parse_filters(filter_spec(quiet, rust_log.as_deref()))
        .format(move |buf, record| {
            let wall = start.elapsed().as_secs_f64();
            let level = record.level();
            if record.target().starts_with("wgsph") {
                writeln!(buf, "[{wall:7.1} s {level:<5}] {}", record.args())
            } else {
                let target = record.target();
                writeln!(buf, "[{wall:7.1} s {level:<5}] {target}: {}", record.args())
            }
        })
        .build();
    log::set_max_level(inner.filter());
    log::set_boxed_logger(Box::new(BarAwareLogger { inner, bars }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quiet_wins_then_rust_log_then_default() {
        assert_eq!(filter_spec(true, Some("debug")), "error");
        assert_eq!(filter_spec(true, None), "error");
        assert_eq!(filter_spec(false, Some("wgsph=debug")), "wgsph=debug");
        assert_eq!(filter_spec(false, Some(" ")), DEFAULT_FILTER);
        assert_eq!(filter_spec(false, None), DEFAULT_FILTER);
    }
}

//! The Python package's compiled module, `wgsph._wgsph` (re-exported by `wgsph/__init__.py`):
//! thin wrappers over the engine's own functions, the ones the `wgsph` command calls, so the
//! package and the command cannot drift apart.
//!
//! - `case.rs`: `Case` (load, built-in cases, `set` with `--set`'s checks, `to_toml`);
//! - `jobs.rs`: `run`, `resume`, `bench`, `validate`, run on a worker thread with the GIL
//!   released, Ctrl-C turned into the engine's stop-with-a-checkpoint flag;
//! - `results.rs`: `Run`, a run folder's outputs read with the engine's readers as NumPy arrays;
//! - `errors.rs`: the exceptions and how engine errors map onto them.

use std::sync::OnceLock;

use indicatif::MultiProgress;
use pyo3::prelude::*;

mod case;
mod errors;
mod jobs;
mod results;

/// The progress bars of runs, shared with the logger so a log line never garbles a bar.
fn bars() -> &'static MultiProgress {
    static BARS: OnceLock<MultiProgress> = OnceLock::new();
    BARS.get_or_init(MultiProgress::new)
}

#[pymodule]
fn _wgsph(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // The engine's log lines (warnings about a case, progress lines off a terminal) on stderr,
    // filtered by RUST_LOG as for the command. Fails only when a logger is already installed
    // in the process (another Rust extension's): then that one shows them.
    let _ = wgsph::logging::init(false, bars().clone());
    errors::register(m)?;
    m.add_class::<case::Case>()?;
    m.add_class::<results::Run>()?;
    m.add_function(wrap_pyfunction!(jobs::run, m)?)?;
    m.add_function(wrap_pyfunction!(jobs::resume, m)?)?;
    m.add_function(wrap_pyfunction!(jobs::bench, m)?)?;
    m.add_function(wrap_pyfunction!(jobs::validate, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

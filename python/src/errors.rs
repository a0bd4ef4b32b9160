//! The package's exceptions and the mapping of engine errors onto them. Messages are the
//! engine's own, as the `wgsph` command prints them after `error: ` (anyhow's `{:#}`: the
//! error and its causes), so a message names the field, the file and the fix in both.

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

create_exception!(
    wgsph,
    CaseError,
    PyValueError,
    "A case file, or a value given to Case.set, is not a valid case: the message names the \
     file, the line, the field and the fix, as `wgsph run --set` does."
);
create_exception!(
    wgsph,
    WgsphError,
    PyRuntimeError,
    "The engine failed: no adapter, a GPU failure, an output folder that cannot be written, a \
     run folder that cannot be read."
);
create_exception!(
    wgsph,
    RunStopped,
    WgsphError,
    "A run stopped before its end (it went unstable, or the GPU failed): its outputs up to then \
     and its last checkpoint are kept; wgsph.Run.open(dir) reads them."
);

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("CaseError", py.get_type::<CaseError>())?;
    m.add("WgsphError", py.get_type::<WgsphError>())?;
    m.add("RunStopped", py.get_type::<RunStopped>())?;
    Ok(())
}

/// The engine's message for `e`, as the command prints it.
pub fn message(e: &anyhow::Error) -> String {
    format!("{e:#}")
}

/// `e` as a Python exception: `CaseError` when a case is to blame, else `WgsphError`.
pub fn to_py(e: anyhow::Error) -> PyErr {
    if e.downcast_ref::<wgsph::case::CaseError>().is_some() {
        CaseError::new_err(message(&e))
    } else {
        WgsphError::new_err(message(&e))
    }
}

/// A case error as a Python exception, with the command's text.
pub fn case_err(e: wgsph::case::CaseError) -> PyErr {
    to_py(anyhow::Error::from(e))
}

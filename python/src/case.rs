//! `wgsph.Case`: a case file's text, the overrides set on it, and the scenario they build,
//! checked by the engine's loader on every change (the same checks and messages as `--set`).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

use wgsph::case::BUILT_IN;
use wgsph::scenario::Scenario;

use crate::errors::{case_err, CaseError};

/// The name a case given as text has in messages; relative paths in it (meshes, motion
/// series) are read from the current folder, as for a file there.
const TEXT_FILE: &str = "case.toml";

/// A case: its text, where it came from, and the `--set` overrides applied to it.
#[pyclass(module = "wgsph")]
#[derive(Clone)]
pub struct Case {
    /// The case file's text as read or given (no override applied).
    text: String,
    /// Its name in messages: the path as given, `cases/<name>.toml` for a built-in case.
    file: String,
    /// The file's absolute path, for a case loaded from a file: runs record it (and the
    /// overrides) in their checkpoints, so `wgsph resume DIR` can load the case again.
    path: Option<PathBuf>,
    overrides: Vec<String>,
    pub scenario: Arc<Scenario>,
}

impl Case {
    fn build(
        text: String,
        file: String,
        path: Option<PathBuf>,
        overrides: Vec<String>,
    ) -> PyResult<Self> {
        let sc = scenario(&text, &file, &overrides).map_err(case_err)?;
        Ok(Case {
            text,
            file,
            path,
            overrides,
            scenario: Arc::new(sc),
        })
    }

    /// The case file and overrides a run records, when the case came from a file.
    pub fn source(&self) -> Option<wgsph::checkpoint::CaseSource> {
        self.path.as_ref().map(|p| wgsph::checkpoint::CaseSource {
            path: p.clone(),
            overrides: self.overrides.clone(),
        })
    }

    /// This case's scenario with `more` overrides after its own (a resume's time control).
    pub fn with_more(&self, more: &[String]) -> Result<Scenario, wgsph::case::CaseError> {
        let all: Vec<String> = self.overrides.iter().chain(more).cloned().collect();
        scenario(&self.text, &self.file, &all)
    }
}

/// The scenario of a case's text with `overrides`, refused naming particles.dx_m before its
/// particles are made when the host's memory cannot hold them (`sph::run_budget` without an
/// adapter; issue 64): a run checks its device's own limit when it opens it.
fn scenario(
    text: &str,
    file: &str,
    overrides: &[String],
) -> Result<Scenario, wgsph::case::CaseError> {
    wgsph::case::load_str_within(text, file, overrides, &host_budget())
}

fn host_budget() -> wgsph::case::ParticleBudget {
    let (n, why) = wgsph::sph::run_budget(None, wgsph::sph::host_memory_available());
    wgsph::case::ParticleBudget::at_most(n as f64, why)
}

/// The names of the built-in cases: those whose name is their file's (a validation variant
/// of a file, such as the ρ = 1000 water entry, is that file with overrides, not a case).
fn built_in_cases() -> impl Iterator<Item = &'static wgsph::case::BuiltIn> {
    BUILT_IN
        .iter()
        .filter(|b| Path::new(b.file).file_stem().and_then(|s| s.to_str()) == Some(b.name))
}

/// VALUE of `--set FIELD=VALUE` for a Python value: a str as written (the command's rule: a
/// TOML value, else a bare string), numbers, booleans and lists as TOML.
pub fn toml_value(field: &str, v: &Bound<'_, PyAny>) -> PyResult<String> {
    if v.is_instance_of::<PyString>() {
        return v.extract();
    }
    if v.is_instance_of::<PyBool>() {
        return Ok(if v.extract::<bool>()? {
            "true"
        } else {
            "false"
        }
        .into());
    }
    if v.is_instance_of::<PyInt>() {
        return Ok(v.extract::<i64>()?.to_string());
    }
    if v.is_instance_of::<PyFloat>() {
        let x: f64 = v.extract()?;
        return Ok(match x {
            _ if x.is_nan() => "nan".into(),
            _ if x.is_infinite() => if x > 0.0 { "inf" } else { "-inf" }.into(),
            // Rust's shortest round-trip form is TOML: 0.005, 1e-7, 2.0.
            _ => format!("{x:?}"),
        });
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items = v
            .try_iter()?
            .map(|item| toml_value(field, &item?))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(format!("[{}]", items.join(", ")));
    }
    // NumPy scalars and other numbers: as the float they convert to.
    if let Ok(x) = v.extract::<f64>() {
        return toml_value(field, &PyFloat::new(v.py(), x));
    }
    Err(PyTypeError::new_err(format!(
        "{field}: a {} cannot be set; fix: give a number, a bool, a str or a list of them",
        v.get_type().name()?
    )))
}

#[pymethods]
impl Case {
    /// Loads the case file at `path` (errors: `CaseError`, naming the file, line, field, fix).
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        // The engine's loader first: its bounded read and its messages for a file it cannot
        // read; the text it read is then read again to keep.
        let sc = wgsph::case::load_within(&path, &[], &host_budget()).map_err(case_err)?;
        let text = std::fs::read_to_string(&path).map_err(|e| {
            case_err(wgsph::case::CaseError::Read {
                file: path.display().to_string(),
                source: e,
            })
        })?;
        Ok(Case {
            text,
            file: path.display().to_string(),
            path: std::path::absolute(&path).ok(),
            overrides: Vec::new(),
            scenario: Arc::new(sc),
        })
    }

    /// A case from its TOML text; `file` is its name in messages (relative paths in the case
    /// are read from that file's folder).
    #[staticmethod]
    #[pyo3(signature = (text, file = TEXT_FILE.to_string()))]
    fn from_toml(text: String, file: String) -> PyResult<Self> {
        Self::build(text, file, None, Vec::new())
    }

    /// A case built into the package by name (`Case.built_in_names()` lists them).
    #[staticmethod]
    fn built_in(name: &str) -> PyResult<Self> {
        let Some(b) = built_in_cases().find(|b| b.name == name) else {
            let names: Vec<&str> = built_in_cases().map(|b| b.name).collect();
            return Err(CaseError::new_err(format!(
                "no built-in case {name:?}; fix: use one of {}",
                names.join(", ")
            )));
        };
        Self::build(b.text.into(), b.file.into(), None, Vec::new())
    }

    /// The names `Case.built_in` takes.
    #[staticmethod]
    fn built_in_names() -> Vec<&'static str> {
        built_in_cases().map(|b| b.name).collect()
    }

    /// Sets a field, as `--set FIELD=VALUE` does: the case is checked again with it, and on an
    /// error (`CaseError`, the command's message) it is left as it was.
    fn set(&mut self, field: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let arg = format!("{field}={}", toml_value(field, value)?);
        let mut overrides = self.overrides.clone();
        overrides.push(arg);
        let sc = scenario(&self.text, &self.file, &overrides).map_err(case_err)?;
        self.overrides = overrides;
        self.scenario = Arc::new(sc);
        Ok(())
    }

    /// A copy, to set fields on without changing this one.
    fn copy(&self) -> Self {
        self.clone()
    }

    /// The case's TOML: the file's text as written when nothing is set, else its document with
    /// the overrides applied (comments are then lost).
    fn to_toml(&self) -> PyResult<String> {
        wgsph::case::with_overrides(&self.text, &self.file, &self.overrides).map_err(case_err)
    }

    /// The case's name (its `name` field, else the file's stem).
    #[getter]
    fn name(&self) -> String {
        self.scenario.name.clone()
    }

    /// 2 or 3.
    #[getter]
    fn dimension(&self) -> u32 {
        self.scenario.physics.dim
    }

    #[getter]
    fn end_s(&self) -> f64 {
        self.scenario.time.end_s
    }

    /// The file's name in messages.
    #[getter]
    fn file(&self) -> String {
        self.file.clone()
    }

    /// The overrides set, as `FIELD=VALUE` strings (what `--set` would be given).
    #[getter]
    fn overrides(&self) -> Vec<String> {
        self.overrides.clone()
    }

    /// Particle counts as run.json gives them: fluid, boundary, solid, inlet.
    #[getter]
    fn particles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let counts = wgsph::run::particle_counts(&self.scenario);
        let d = PyDict::new(py);
        for (k, n) in ["fluid", "boundary", "solid", "inlet"].iter().zip(counts) {
            d.set_item(k, n)?;
        }
        Ok(d)
    }

    fn __repr__(&self) -> String {
        let [fluid, boundary, solid, inlet] = wgsph::run::particle_counts(&self.scenario);
        format!(
            "Case({:?}, file={:?}, overrides={:?}, particles: {fluid} fluid, {boundary} \
             boundary, {solid} solid, {inlet} inlet)",
            self.scenario.name, self.file, self.overrides
        )
    }
}

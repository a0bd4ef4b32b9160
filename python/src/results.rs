//! `wgsph.Run`: a run folder's outputs as NumPy arrays, read with the engine's own readers
//! (the probe CSVs with `wgsph plot`'s, the particle files with the one `plot --snapshots` and
//! `surface` use), so what Python sees is what the command reads.

use std::path::{Path, PathBuf};

use pyo3::exceptions::{PyIndexError, PyKeyError};
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyDict};

use wgsph::output::flood_maps::{map_stems, read_map};
use wgsph::output::{particle_files, ParticleFile, PARTICLES_DIR, PROBES_DIR, RUN_SUMMARY_FILE};

use crate::errors::{to_py, WgsphError};

/// A run folder: one `wgsph.run` wrote, or `wgsph run` (`Run.open(dir)`).
#[pyclass(module = "wgsph", frozen)]
pub struct Run {
    dir: PathBuf,
    interrupted_at_s: Option<f64>,
    already_complete: bool,
}

impl Run {
    pub fn finished(dir: PathBuf, interrupted_at_s: Option<f64>, already_complete: bool) -> Self {
        Run {
            dir,
            interrupted_at_s,
            already_complete,
        }
    }

    fn probes_dir(&self) -> PathBuf {
        self.dir.join(PROBES_DIR)
    }

    /// Every probe name, as `wgsph plot` lists them (`table.column` for a table's columns).
    fn names(&self) -> PyResult<Vec<String>> {
        if !self.probes_dir().is_dir() {
            return Ok(Vec::new());
        }
        wgsph::plot::probe_names(&self.dir).map_err(to_py)
    }

    fn unknown(&self, what: &str, name: &str, known: &[String]) -> PyErr {
        PyKeyError::new_err(format!(
            "no {what} {name:?} in {}; it has: {}",
            self.dir.display(),
            if known.is_empty() {
                "none".to_string()
            } else {
                known.join(", ")
            }
        ))
    }
}

/// A value type of the arrays, with its NumPy dtype (little-endian, as the files are).
trait Dtype: bytemuck::Pod {
    const DTYPE: &'static str;
}

impl Dtype for f64 {
    const DTYPE: &'static str = "<f8";
}

impl Dtype for f32 {
    const DTYPE: &'static str = "<f4";
}

impl Dtype for u32 {
    const DTYPE: &'static str = "<u4";
}

/// `values` as a 1-D NumPy array: one copy into a bytearray that the array then owns through
/// `numpy.frombuffer` (writable, no second copy). Done through NumPy's Python API rather than
/// its C API (rust-numpy): nothing to keep in step with NumPy's versions, and a smaller build.
fn array1<'py, T: Dtype>(py: Python<'py>, values: &[T]) -> PyResult<Bound<'py, PyAny>> {
    let bytes = PyByteArray::new(py, bytemuck::cast_slice(values));
    py.import("numpy")?
        .call_method1("frombuffer", (bytes, T::DTYPE))
}

/// Rows of three as an (n, 3) array.
fn array_n3<'py, T: Dtype>(py: Python<'py>, rows: &[[T; 3]]) -> PyResult<Bound<'py, PyAny>> {
    let flat: &[T] = bytemuck::cast_slice(rows);
    array1(py, flat)?.call_method1("reshape", ((rows.len(), 3),))
}

#[pymethods]
impl Run {
    /// Opens an existing run folder (one with run.json, probes/ or particles/).
    #[staticmethod]
    fn open(dir: PathBuf) -> PyResult<Self> {
        let is_run = [RUN_SUMMARY_FILE, PROBES_DIR, PARTICLES_DIR]
            .iter()
            .any(|f| dir.join(f).exists());
        if !is_run {
            return Err(WgsphError::new_err(format!(
                "{} is not a run folder: it has no {RUN_SUMMARY_FILE}, {PROBES_DIR}/ or \
                 {PARTICLES_DIR}/; fix: give the folder `wgsph run --out` or wgsph.run(out=...) \
                 wrote",
                dir.display()
            )));
        }
        Ok(Run::finished(dir, None, false))
    }

    /// The run's folder.
    #[getter]
    fn dir(&self) -> String {
        self.dir.display().to_string()
    }

    /// run.json as a dict, or None while the run has not ended (or was killed).
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        let path = self.dir.join(RUN_SUMMARY_FILE);
        if !path.is_file() {
            return Ok(None);
        }
        // The engine's reader checks the file; Python's json gives every field as written.
        wgsph::output::RunSummary::read(&self.dir).map_err(|e| to_py(e.into()))?;
        let text = std::fs::read_to_string(&path)
            .map_err(|e| WgsphError::new_err(format!("cannot read {}: {e}", path.display())))?;
        Ok(Some(py.import("json")?.call_method1("loads", (text,))?))
    }

    /// run.json's status ("completed", "interrupted ...", "stopped: ..."), or None.
    #[getter]
    fn status(&self) -> PyResult<Option<String>> {
        if !self.dir.join(RUN_SUMMARY_FILE).is_file() {
            return Ok(None);
        }
        let s = wgsph::output::RunSummary::read(&self.dir).map_err(|e| to_py(e.into()))?;
        Ok(Some(s.status))
    }

    /// The simulated time of the checkpoint the run stopped at, when this call interrupted it.
    #[getter]
    fn interrupted_at_s(&self) -> Option<f64> {
        self.interrupted_at_s
    }

    /// True when `resume` found the run already complete and computed nothing.
    #[getter]
    fn already_complete(&self) -> bool {
        self.already_complete
    }

    /// Every probe name: the probe CSVs' stems, and `table.column` for each column of a body's
    /// or tracked point's table (`body_box.y_m`).
    fn probes(&self) -> PyResult<Vec<String>> {
        self.names()
    }

    /// `(t, values)` of a probe (or of a table's column, `table.column`), as float64 arrays;
    /// NaN where the probe had no value.
    fn probe<'py>(
        &self,
        py: Python<'py>,
        name: &str,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let names = self.names()?;
        if !names.iter().any(|n| n == name) {
            return Err(self.unknown("probe", name, &names));
        }
        let series = wgsph::plot::read_probe(&self.dir, name).map_err(to_py)?;
        let (t, v): (Vec<f64>, Vec<f64>) = series.points.into_iter().unzip();
        Ok((array1(py, &t)?, array1(py, &v)?))
    }

    /// A table (`probes/<name>.csv`: a body's, `body_<name>`, or a tracked point's,
    /// `point_<name>`) as a dict of float64 arrays in the file's column order, time first.
    fn table<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyDict>> {
        let path = self.probes_dir().join(format!("{name}.csv"));
        let text = match std::fs::read_to_string(&path) {
            Ok(text) => text,
            Err(_) => {
                let tables: Vec<String> = self
                    .names()?
                    .iter()
                    .filter_map(|n| n.split_once('.').map(|(t, _)| t.to_string()))
                    .collect::<std::collections::BTreeSet<_>>()
                    .into_iter()
                    .collect();
                return Err(self.unknown("table", name, &tables));
            }
        };
        // The header names the columns (the first line not blank or a `#` comment); each is
        // read with the engine's parser, which checks every row.
        let header = text
            .lines()
            .find(|l| !l.trim().is_empty() && !l.starts_with('#'))
            .unwrap_or_default();
        let columns: Vec<&str> = header.split(',').map(str::trim).collect();
        let file = path.display().to_string();
        let d = PyDict::new(py);
        for (k, column) in columns.iter().enumerate().skip(1) {
            let series = wgsph::plot::parse_table_column(&text, &file, column).map_err(to_py)?;
            if k == 1 {
                let t: Vec<f64> = series.points.iter().map(|p| p.0).collect();
                d.set_item(&series.columns.0, array1(py, &t)?)?;
            }
            let v: Vec<f64> = series.points.iter().map(|p| p.1).collect();
            d.set_item(*column, array1(py, &v)?)?;
        }
        if d.is_empty() {
            return Err(WgsphError::new_err(format!(
                "{file}: no columns after the time in its header {header:?}"
            )));
        }
        Ok(d)
    }

    /// A body's table, `probes/body_<name>.csv` (see `table`).
    fn body<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyDict>> {
        self.table(py, &format!("body_{name}"))
    }

    /// A tracked point's table, `probes/point_<name>.csv` (see `table`).
    fn point<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyDict>> {
        self.table(py, &format!("point_{name}"))
    }

    /// The number of particle outputs.
    #[getter]
    fn outputs(&self) -> PyResult<usize> {
        Ok(self.files()?.len())
    }

    /// Particle output `i` (negative from the end) as a dict: position (n, 3) float64,
    /// velocity (n, 3) float32, density, pressure (float32), kind, id (uint32), the extra
    /// fields the run writes (energy, tau_xx ...), and time_s (a float). With `complete`, an
    /// output that left out unmoved walls (`time.output_boundary = "first"`) gets them back
    /// from the first output.
    #[pyo3(signature = (i = -1, complete = false))]
    fn particles<'py>(
        &self,
        py: Python<'py>,
        i: isize,
        complete: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let files = self.files()?;
        let n = files.len() as isize;
        let k = if i < 0 { i + n } else { i };
        if !(0..n).contains(&k) {
            return Err(PyIndexError::new_err(format!(
                "particle output {i} of {n} in {}",
                self.dir.join(PARTICLES_DIR).display()
            )));
        }
        let read = |path: &Path| ParticleFile::read(path).map_err(|e| to_py(e.into()));
        let file = read(&files[k as usize].1)?;
        let p = if complete && k > 0 {
            file.particles.completed_from(&read(&files[0].1)?.particles)
        } else {
            file.particles
        };
        let d = PyDict::new(py);
        d.set_item("time_s", file.time_s)?;
        d.set_item("position", array_n3(py, &p.pos)?)?;
        d.set_item("velocity", array_n3(py, &p.vel)?)?;
        d.set_item("density", array1(py, &p.rho)?)?;
        d.set_item("pressure", array1(py, &p.pressure)?)?;
        d.set_item("kind", array1(py, &p.kind)?)?;
        d.set_item("id", array1(py, &p.id)?)?;
        for (name, values) in p.extra_arrays() {
            d.set_item(name, array1(py, &values)?)?;
        }
        Ok(d)
    }

    /// The flood maps' names (`maps/<name>.asc`: `max_depth_m`, `arrival_s`, …), sorted;
    /// empty for a case without `[maps]`.
    fn maps(&self) -> Vec<String> {
        map_stems(&self.dir)
    }

    /// A flood map as a dict: `values`, a float64 array of shape (rows, columns), row 0 the
    /// southernmost, NaN where the map has no value (a cell never wet); `x` and `y`, the cells'
    /// centres in world coordinates along each axis. Read with the engine's ESRI ASCII reader.
    fn map<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyDict>> {
        let names = self.maps();
        if !names.iter().any(|n| n == name) {
            return Err(self.unknown("map", name, &names));
        }
        let grid = read_map(&self.dir, name).map_err(to_py)?;
        let along = |a: usize, n: usize| -> Vec<f64> {
            (0..n)
                .map(|i| grid.first_centre[a] + i as f64 * grid.cell[a])
                .collect()
        };
        let d = PyDict::new(py);
        let values = array1(py, &grid.z)?.call_method1("reshape", ((grid.nrows, grid.ncols),))?;
        d.set_item("values", values)?;
        d.set_item("x", array1(py, &along(0, grid.ncols))?)?;
        d.set_item("y", array1(py, &along(1, grid.nrows))?)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!("Run({:?})", self.dir.display().to_string())
    }
}

impl Run {
    fn files(&self) -> PyResult<Vec<(usize, PathBuf)>> {
        if !self.dir.join(PARTICLES_DIR).is_dir() {
            return Ok(Vec::new());
        }
        particle_files(&self.dir).map_err(|e| to_py(e.into()))
    }
}

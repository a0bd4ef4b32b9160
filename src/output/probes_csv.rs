//! Probe time series as CSV files, one per probe, rewritten atomically on flush.

use std::collections::HashSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::{fmt_f64, write_atomic, Manifest, OutputError};

struct ProbeFile {
    path: PathBuf,
    /// Value columns after `t_s`.
    columns: usize,
    /// Full CSV text (header + every recorded row), kept in memory and rewritten on flush.
    text: String,
}

/// Writes one CSV per probe (`t_s,<column>` header, one `t,value` row per [`record`] call).
///
/// Crash safety is by atomic rewrite: all rows stay in memory (already formatted) and every
/// [`flush`] rewrites each CSV to a temporary file and renames it into place, so a killed run
/// never leaves a truncated CSV — at worst the rows recorded since the last flush are missing.
/// Dropping the writer flushes pending rows (best effort, errors ignored); call [`flush`] at the
/// end of a run to see errors.
///
/// [`record`]: ProbeWriter::record
/// [`flush`]: ProbeWriter::flush
pub struct ProbeWriter {
    dir: PathBuf,
    files: Vec<ProbeFile>,
    rows: usize,
    dirty: bool,
}

impl ProbeWriter {
    /// Validates the names and writes each `dir/<name>.csv` with its header line only.
    /// Each file is listed in `manifest` (the output folder's) before it is written.
    pub(crate) fn create(
        dir: &Path,
        names_and_columns: &[(String, String)],
        manifest: &mut Manifest,
    ) -> Result<Self, OutputError> {
        let tables: Vec<(String, Vec<String>)> = names_and_columns
            .iter()
            .map(|(n, c)| (n.clone(), vec![c.clone()]))
            .collect();
        Self::create_tables(dir, &tables, manifest)
    }

    /// As [`create`](ProbeWriter::create) with several value columns per file
    /// (`t_s,<c1>,<c2>,...`), filled by [`record_rows`](ProbeWriter::record_rows).
    pub(crate) fn create_tables(
        dir: &Path,
        tables: &[(String, Vec<String>)],
        manifest: &mut Manifest,
    ) -> Result<Self, OutputError> {
        let mut seen = HashSet::new();
        let mut files = Vec::with_capacity(tables.len());
        for (name, columns) in tables {
            let bad = |reason| OutputError::ProbeName {
                dir: dir.to_path_buf(),
                name: name.clone(),
                reason,
            };
            if name.is_empty() || name == "." || name == ".." {
                return Err(bad("not usable as a file name"));
            }
            if name.contains(['/', '\\', '\0', '\n', '\r']) {
                return Err(bad("contains a path separator or control character"));
            }
            if columns.is_empty()
                || columns
                    .iter()
                    .any(|c| c.is_empty() || c.contains([',', '"', '\n', '\r']))
            {
                return Err(bad(
                    "its column name is empty or contains ',', '\"' or a line break",
                ));
            }
            if !seen.insert(name.as_str()) {
                return Err(bad("used twice"));
            }
            files.push(ProbeFile {
                path: dir.join(format!("{name}.csv")),
                columns: columns.len(),
                text: format!("t_s,{}\n", columns.join(",")),
            });
        }
        for f in &files {
            manifest.claim_path(&f.path)?;
        }
        let mut w = ProbeWriter {
            dir: dir.to_path_buf(),
            files,
            rows: 0,
            dirty: true,
        };
        w.flush()?;
        Ok(w)
    }

    /// Number of probes.
    pub fn len(&self) -> usize {
        self.files.len()
    }

    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }

    /// Number of rows recorded so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Paths of the CSV files, in probe order.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.files.iter().map(|f| f.path.as_path())
    }

    /// Records one row `t,value` per probe; `values.len()` must equal the number of probes.
    /// Rows only reach the disk on [`flush`](ProbeWriter::flush).
    pub fn record(&mut self, t_s: f64, values: &[f64]) -> Result<(), OutputError> {
        if values.len() != self.files.len() {
            return Err(OutputError::ProbeCount {
                dir: self.dir.clone(),
                expected: self.files.len(),
                got: values.len(),
            });
        }
        let rows: Vec<Vec<f64>> = values.iter().map(|&v| vec![v]).collect();
        self.record_rows(t_s, &rows)
    }

    /// Records one row `t,v1,v2,...` per file; `rows[k]` must have file k's column count.
    pub fn record_rows(&mut self, t_s: f64, rows: &[Vec<f64>]) -> Result<(), OutputError> {
        let shape_ok = rows.len() == self.files.len()
            && self
                .files
                .iter()
                .zip(rows)
                .all(|(f, r)| r.len() == f.columns);
        if !shape_ok {
            return Err(OutputError::ProbeCount {
                dir: self.dir.clone(),
                expected: self.files.iter().map(|f| f.columns).sum(),
                got: rows.iter().map(Vec::len).sum(),
            });
        }
        for (f, row) in self.files.iter_mut().zip(rows) {
            // Writing into a String cannot fail.
            let _ = write!(f.text, "{}", fmt_f64(t_s));
            for &v in row {
                let _ = write!(f.text, ",{}", fmt_f64(v));
            }
            f.text.push('\n');
        }
        self.rows += 1;
        self.dirty = true;
        Ok(())
    }

    /// The full text of every file (header and rows recorded so far), for checkpoints.
    pub fn texts(&self) -> Vec<String> {
        self.files.iter().map(|f| f.text.clone()).collect()
    }

    /// Resuming a run: replaces the rows with `texts` (what [`texts`](Self::texts) gave for the
    /// same files) and rewrites the files, dropping rows a killed run wrote after its
    /// checkpoint.
    pub fn restore(&mut self, texts: &[String]) -> Result<(), OutputError> {
        if texts.len() != self.files.len() {
            return Err(OutputError::Resume {
                path: self.dir.clone(),
                reason: format!(
                    "the checkpoint has {} tables, the case {}",
                    texts.len(),
                    self.files.len()
                ),
            });
        }
        for (f, text) in self.files.iter().zip(texts) {
            let header = f.text.lines().next().unwrap_or_default();
            if text.lines().next() != Some(header) || !text.ends_with('\n') {
                return Err(OutputError::Resume {
                    path: f.path.clone(),
                    reason: format!("the checkpoint's table does not start with '{header}'"),
                });
            }
        }
        for (f, text) in self.files.iter_mut().zip(texts) {
            f.text = text.clone();
        }
        self.rows = texts.first().map_or(0, |t| t.lines().count() - 1);
        self.dirty = true;
        self.flush()
    }

    /// Drops the rows after `t_s` (a run stopped unstable keeps what was still sound); they
    /// leave the files on the next [`flush`](Self::flush).
    pub fn truncate_after(&mut self, t_s: f64) {
        for f in &mut self.files {
            let mut kept = 0;
            let mut end = 0;
            for (k, line) in f.text.split_inclusive('\n').enumerate() {
                // The header, then rows whose time (written round-trip exact) is within t_s.
                let t = line.split(',').next().and_then(|t| t.parse::<f64>().ok());
                if k > 0 && t.is_none_or(|t| t > t_s) {
                    break;
                }
                kept = k;
                end += line.len();
            }
            f.text.truncate(end);
            self.rows = kept;
        }
        self.dirty = true;
    }

    /// Makes the recorded rows durable by atomically rewriting every CSV (no-op when nothing was
    /// recorded since the last successful flush).
    pub fn flush(&mut self) -> Result<(), OutputError> {
        if !self.dirty {
            return Ok(());
        }
        for f in &self.files {
            write_atomic(&f.path, |w| w.write_all(f.text.as_bytes()))?;
        }
        self.dirty = false;
        Ok(())
    }
}

impl Drop for ProbeWriter {
    fn drop(&mut self) {
        let _ = self.flush();
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_util::temp_dir;
    use super::super::{OutputDir, OutputError};

    fn cols(v: &[(&str, &str)]) -> Vec<(String, String)> {
        v.iter()
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .collect()
    }

    #[test]
    fn header_rows_and_flush() {
        let d = temp_dir("probes");
        let mut out = OutputDir::create(&d).unwrap();
        let mut w = out
            .probe_writer(&cols(&[
                ("p1", "pressure_pa"),
                ("h_left", "height_m"),
                ("front", "front_m"),
            ]))
            .unwrap();
        assert_eq!(w.len(), 3);
        // Headers exist right away.
        let p1 = d.join("probes/p1.csv");
        assert_eq!(std::fs::read_to_string(&p1).unwrap(), "t_s,pressure_pa\n");
        assert_eq!(
            std::fs::read_to_string(d.join("probes/front.csv")).unwrap(),
            "t_s,front_m\n"
        );

        w.record(0.0, &[101325.0, 0.3, 0.0]).unwrap();
        w.record(0.1 + 0.2, &[f64::NAN, 1.0 / 3.0, 1e-300]).unwrap();
        // Not yet durable.
        assert_eq!(std::fs::read_to_string(&p1).unwrap(), "t_s,pressure_pa\n");
        w.flush().unwrap();
        assert_eq!(
            std::fs::read_to_string(&p1).unwrap(),
            "t_s,pressure_pa\n0,101325\n0.30000000000000004,nan\n"
        );
        let h = std::fs::read_to_string(d.join("probes/h_left.csv")).unwrap();
        let last = h.lines().last().unwrap();
        let (t, v) = last.split_once(',').unwrap();
        assert_eq!(t.parse::<f64>().unwrap(), 0.1 + 0.2);
        assert_eq!(v.parse::<f64>().unwrap(), 1.0 / 3.0);
        assert_eq!(
            std::fs::read_to_string(d.join("probes/front.csv")).unwrap(),
            "t_s,front_m\n0,0\n0.30000000000000004,1e-300\n"
        );
        assert_eq!(w.rows(), 2);

        // More rows, flush again: whole file rewritten, no temp files left over.
        w.record(1.0, &[1.0, 2.0, 3.0]).unwrap();
        w.flush().unwrap();
        w.flush().unwrap();
        assert_eq!(std::fs::read_to_string(&p1).unwrap().lines().count(), 4);
        let names: Vec<_> = std::fs::read_dir(d.join("probes"))
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        assert_eq!(names.len(), 3, "{names:?}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// A stopped run's rows after a time are dropped from every file, exactly at the time
    /// written (round-trip), and recording goes on after them.
    #[test]
    fn truncate_after_keeps_the_rows_up_to_a_time() {
        let d = temp_dir("probes-truncate");
        let mut out = OutputDir::create(&d).unwrap();
        let mut w = out
            .probe_writer(&cols(&[("a", "height_m"), ("b", "front_m")]))
            .unwrap();
        for k in 0..5 {
            let t = 0.1 * k as f64;
            w.record(t, &[t, 2.0 * t]).unwrap();
        }
        w.truncate_after(0.1 + 0.1);
        assert_eq!(w.rows(), 3);
        w.flush().unwrap();
        assert_eq!(
            std::fs::read_to_string(d.join("probes/b.csv")).unwrap(),
            "t_s,front_m\n0,0\n0.1,0.2\n0.2,0.4\n"
        );
        w.truncate_after(-1.0);
        w.record(7.0, &[1.0, 2.0]).unwrap();
        w.flush().unwrap();
        assert_eq!(
            std::fs::read_to_string(d.join("probes/a.csv")).unwrap(),
            "t_s,height_m\n7,1\n"
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn drop_flushes_pending_rows() {
        let d = temp_dir("probes-drop");
        let mut out = OutputDir::create(&d).unwrap();
        {
            let mut w = out.probe_writer(&cols(&[("a", "height_m")])).unwrap();
            w.record(0.5, &[2.0]).unwrap();
        }
        assert_eq!(
            std::fs::read_to_string(d.join("probes/a.csv")).unwrap(),
            "t_s,height_m\n0.5,2\n"
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn wrong_value_count_and_bad_names() {
        let d = temp_dir("probes-err");
        let mut out = OutputDir::create(&d).unwrap();
        let mut w = out
            .probe_writer(&cols(&[("a", "height_m"), ("b", "height_m")]))
            .unwrap();
        let err = w.record(0.0, &[1.0]).unwrap_err();
        assert!(matches!(
            err,
            OutputError::ProbeCount {
                expected: 2,
                got: 1,
                ..
            }
        ));
        assert!(err.to_string().contains("probes"));
        assert_eq!(w.rows(), 0);

        for bad in [
            cols(&[("", "x")]),
            cols(&[("..", "x")]),
            cols(&[("a/b", "x")]),
            cols(&[("a", "x,y")]),
            cols(&[("a", "x"), ("a", "y")]),
        ] {
            let err = out.probe_writer(&bad).err().expect("must fail");
            assert!(matches!(err, OutputError::ProbeName { .. }), "{err}");
        }
        // No probes at all is allowed.
        let mut empty = out.probe_writer(&[]).unwrap();
        empty.record(0.0, &[]).unwrap();
        empty.flush().unwrap();
        std::fs::remove_dir_all(&d).unwrap();
    }
}

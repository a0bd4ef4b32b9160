//! Time series read from CSV files beside the case: a body's prescribed motion, an inlet's
//! hydrograph. `#` comments, one optional header line, then rows of numbers separated by
//! commas, the first column the time, strictly increasing.

use std::path::Path;

use super::check::read_bounded;
use super::error::CaseError;
use super::locate::Ctx;

/// A row of a series and the line of the file it is on (1-based).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Row {
    pub line: usize,
    pub values: Vec<f64>,
}

/// The rows of the CSV `file` (relative to `case_dir`) that the field `field` names, each of
/// the columns `columns` (their names with units, for the messages).
pub(super) fn read(
    ctx: &Ctx<'_>,
    field: &str,
    file: &str,
    case_dir: &Path,
    columns: &[&str],
) -> Result<Vec<Row>, CaseError> {
    let full = case_dir.join(file);
    let refuse =
        |problem: String, fix: String| ctx.err(field, Some(format!("{file:?}")), problem, fix);
    // A file, not a device or a pipe (reading /dev/zero would never end), and of a size that
    // a series can have.
    const MAX_BYTES: u64 = 64 << 20;
    if let Ok(meta) = std::fs::metadata(&full) {
        if !meta.is_file() {
            return Err(refuse(
                format!("{} is not a regular file", full.display()),
                "give the path of a CSV file relative to the case file".into(),
            ));
        }
        if meta.len() > MAX_BYTES {
            return Err(refuse(
                format!(
                    "{} has {} bytes, more than the {MAX_BYTES} a time series may have",
                    full.display(),
                    meta.len()
                ),
                "give the path of a CSV file relative to the case file".into(),
            ));
        }
    }
    let text = read_bounded(&full, MAX_BYTES).map_err(|e| {
        refuse(
            format!("cannot read {}: {e}", full.display()),
            "give the path of the CSV relative to the case file".into(),
        )
    })?;
    let n = columns.len();
    let row_fix = format!(
        "write rows of {n} numbers: {}, with t increasing",
        columns.join(", ")
    );
    let mut rows: Vec<Row> = Vec::new();
    let mut header = false;
    for (k, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let bad = |problem: String| {
            refuse(
                format!("{} line {}: {problem}", full.display(), k + 1),
                row_fix.clone(),
            )
        };
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let values = match fields.iter().map(|f| f.parse::<f64>()).collect() {
            Ok(v) => v,
            // One header line (before any data) is skipped.
            Err(_) if rows.is_empty() && !header => {
                header = true;
                continue;
            }
            // Other separators than the comma (issue 64: every row of a ';' file was taken
            // for a header, and the file said to have no data rows).
            Err(_) if line.contains([';', '\t']) || !line.contains(',') => {
                return Err(bad(format!(
                    "{line:?} is not {n} comma-separated numbers (a CSV of this case \
                     separates its columns by commas, not ';', tabs or spaces)"
                )))
            }
            Err(_) => return Err(bad(format!("{line:?} is not {n} numbers"))),
        };
        let values: Vec<f64> = values;
        if values.len() != n || values.iter().any(|v| !v.is_finite()) {
            return Err(bad(format!("{line:?} is not {n} finite numbers")));
        }
        if rows.last().is_some_and(|last| values[0] <= last.values[0]) {
            return Err(bad(format!("t = {} does not increase", values[0])));
        }
        rows.push(Row {
            line: k + 1,
            values,
        });
    }
    if rows.is_empty() {
        return Err(refuse(
            format!("{} has no data rows", full.display()),
            format!("add rows {}", columns.join(", ")),
        ));
    }
    Ok(rows)
}

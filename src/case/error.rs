//! The error type of the case loader: every message names the file, the line (when the field is
//! written in the file), the field's dotted path, what is wrong and how to fix it.

use std::fmt;

/// Why a case file could not be turned into a [`crate::scenario::Scenario`].
#[derive(Debug, thiserror::Error)]
pub enum CaseError {
    /// The file could not be read (a missing file, no permission), or is not UTF-8 text (a
    /// UTF-16 or binary file: issue 64, where the fix said to check the permissions).
    #[error(
        "{file}: cannot read the case file: {source}; fix: {}",
        match source.kind() {
            std::io::ErrorKind::InvalidData => "save it as UTF-8 text (a case file is TOML, \
                docs/cases.md); a UTF-16 file or a binary one is not a case file",
            _ => "check the path and its permissions",
        }
    )]
    Read {
        file: String,
        #[source]
        source: std::io::Error,
    },
    /// The file (or a `--set` override) is not a valid case.
    #[error("{0}")]
    Invalid(Box<Diagnostic>),
}

impl CaseError {
    /// The 1-based line in the case file, when the error is tied to one.
    pub fn line(&self) -> Option<usize> {
        match self {
            CaseError::Invalid(d) => d.line,
            CaseError::Read { .. } => None,
        }
    }

    /// The dotted path of the offending field (`particles.dx_m`, `probe[2].point_m`), if any.
    pub fn field(&self) -> Option<&str> {
        match self {
            CaseError::Invalid(d) => d.path.as_deref(),
            CaseError::Read { .. } => None,
        }
    }
}

/// One problem found in a case file.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagnostic {
    /// The case file's name as given.
    pub file: String,
    /// 1-based line, when the field is written in the file.
    pub line: Option<usize>,
    /// 1-based column (syntax errors only).
    pub column: Option<usize>,
    /// The `--set` argument the offending value came from, if it came from one.
    pub set_by: Option<String>,
    /// Dotted path of the field.
    pub path: Option<String>,
    /// The offending value, as written or as read.
    pub value: Option<String>,
    /// What is wrong.
    pub problem: String,
    /// How to fix it.
    pub fix: Option<String>,
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
            if let Some(col) = self.column {
                write!(f, ":{col}")?;
            }
        }
        write!(f, ": ")?;
        if let Some(path) = self.path.as_deref().filter(|p| !p.is_empty()) {
            write!(f, "{path}")?;
            if let Some(v) = &self.value {
                write!(f, " = {v}")?;
            }
            if let Some(arg) = &self.set_by {
                write!(f, " (from --set {arg})")?;
            }
            write!(f, ": ")?;
        } else if let Some(arg) = &self.set_by {
            write!(f, "--set {arg}: ")?;
        }
        write!(f, "{}", self.problem)?;
        if let Some(fix) = &self.fix {
            write!(f, "; fix: {fix}")?;
        }
        Ok(())
    }
}

impl From<Diagnostic> for CaseError {
    fn from(d: Diagnostic) -> Self {
        CaseError::Invalid(Box::new(d))
    }
}

/// A number as a message writes it: to 12 significant digits, so that a computed length reads
/// `0.15` and not `0.15000000000000002`, and in exponent form when very large or small (`1e300`,
/// not three hundred digits).
pub(super) fn num(v: f64) -> String {
    let v = if v.is_finite() {
        format!("{v:.11e}").parse().unwrap_or(v)
    } else {
        v
    };
    if v != 0.0 && v.is_finite() && !(1e-6..1e16).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

//! Where things are in the case file: dotted field paths ↔ byte spans ↔ line numbers, and the
//! context ([`Ctx`]) every check uses to build an error that names file, line and field.

use std::ops::Range;

use toml::de::{DeTable, DeValue};

use super::error::{CaseError, Diagnostic};

/// One key or array element of the parsed document.
struct Entry {
    path: String,
    /// The key's span (absent for array elements).
    key: Option<Range<usize>>,
    /// The value's span (for tables, the header).
    value: Range<usize>,
}

/// Dotted paths (`a.b[0].c`) of a TOML text, with their spans.
pub(super) struct Index {
    entries: Vec<Entry>,
    line_starts: Vec<usize>,
}

impl Index {
    pub(super) fn new(text: &str, root: &DeTable<'_>) -> Index {
        let mut entries = Vec::new();
        walk_table(root, "", &mut entries);
        let mut line_starts = vec![0];
        line_starts.extend(text.match_indices('\n').map(|(i, _)| i + 1));
        Index {
            entries,
            line_starts,
        }
    }

    /// 1-based (line, column) of a byte offset.
    pub(super) fn line_col(&self, pos: usize) -> (usize, usize) {
        let line = self.line_starts.partition_point(|&s| s <= pos).max(1);
        (line, pos - self.line_starts[line - 1] + 1)
    }

    /// The line where `path` is written (its key, or its table header), if it is.
    pub(super) fn line_of(&self, path: &str) -> Option<usize> {
        let e = self.entries.iter().find(|e| e.path == path)?;
        let pos = e.key.as_ref().map_or(e.value.start, |k| k.start);
        Some(self.line_col(pos).0)
    }

    pub(super) fn contains(&self, path: &str) -> bool {
        self.entries.iter().any(|e| e.path == path)
    }

    /// The innermost path whose key or value span encloses `span` ("" for the document root).
    pub(super) fn path_at(&self, span: &Range<usize>) -> String {
        if span.is_empty() {
            return String::new();
        }
        let encloses = |r: &Range<usize>| r.start <= span.start && span.end <= r.end;
        self.entries
            .iter()
            .flat_map(|e| e.key.iter().chain(Some(&e.value)).map(move |r| (r, e)))
            .filter(|(r, _)| encloses(r))
            // The smallest span; on a tie (a `[[list]]` and its entry share the header) the
            // deeper path.
            .min_by_key(|(r, e)| (r.len(), std::cmp::Reverse(e.path.len())))
            .map(|(_, e)| e.path.clone())
            .unwrap_or_default()
    }
}

fn walk_table(table: &DeTable<'_>, prefix: &str, out: &mut Vec<Entry>) {
    for (key, value) in table.iter() {
        let path = join(prefix, key.get_ref());
        out.push(Entry {
            path: path.clone(),
            key: Some(key.span()),
            value: value.span(),
        });
        walk_value(value.get_ref(), &path, out);
    }
}

fn walk_value(value: &DeValue<'_>, path: &str, out: &mut Vec<Entry>) {
    if let Some(t) = value.as_table() {
        walk_table(t, path, out);
    } else if let Some(items) = value.as_array() {
        for (i, item) in items.iter().enumerate() {
            let p = format!("{path}[{i}]");
            out.push(Entry {
                path: p.clone(),
                key: None,
                value: item.span(),
            });
            walk_value(item.get_ref(), &p, out);
        }
    }
}

/// `prefix.key`, or `key` at the root.
pub(super) fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_string()
    } else {
        format!("{prefix}.{key}")
    }
}

/// Everything an error message needs: file name, the original file's index, the overrides.
pub(super) struct Ctx<'a> {
    pub file: &'a str,
    pub index: &'a Index,
    /// (normalised dotted key, the raw `--set` argument).
    pub overrides: &'a [(String, String)],
}

impl Ctx<'_> {
    /// Where the value at `path` came from: a `--set` (returned), or a line of the file. A path
    /// that is not in the file (a missing field) points at the nearest enclosing table.
    fn origin(&self, path: &str) -> (Option<usize>, Option<String>) {
        let under = |p: &str, key: &str| {
            p == key || p.starts_with(&format!("{key}.")) || p.starts_with(&format!("{key}["))
        };
        // The value was replaced by an override at or above it.
        if let Some((_, arg)) = self.overrides.iter().rev().find(|(k, _)| under(path, k)) {
            return (None, Some(arg.clone()));
        }
        let mut p = path;
        loop {
            if !p.is_empty() && self.index.contains(p) {
                return (self.index.line_of(p), None);
            }
            // A table that an override created.
            if let Some((_, arg)) = self
                .overrides
                .iter()
                .rev()
                .find(|(k, _)| !p.is_empty() && under(k, p))
            {
                return (None, Some(arg.clone()));
            }
            match p.rfind(['.', '[']) {
                Some(cut) => p = &p[..cut],
                None => return (None, None),
            }
        }
    }

    /// An error about the field at `path`.
    pub(super) fn err(
        &self,
        path: &str,
        value: Option<String>,
        problem: impl Into<String>,
        fix: impl Into<String>,
    ) -> CaseError {
        let (line, set_by) = self.origin(path);
        Diagnostic {
            file: self.file.to_string(),
            line,
            column: None,
            set_by,
            path: Some(path.to_string()),
            value,
            problem: problem.into(),
            fix: Some(fix.into()).filter(|f: &String| !f.is_empty()),
        }
        .into()
    }
}

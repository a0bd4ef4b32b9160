//! Turns the TOML library's errors (syntax, and serde's unknown/missing/wrong-type field errors)
//! into [`CaseError`]s that name the file, line, field path and a fix.

use toml::de::{DeTable, DeValue};
use toml::Spanned;

use super::error::{CaseError, Diagnostic};
use super::locate::{join, Ctx, Index};
use super::schema::help;

/// A TOML syntax error in the file itself.
pub(super) fn syntax(file: &str, text: &str, err: &toml::de::Error) -> CaseError {
    let pos = err.span().map_or(0, |s| s.start).min(text.len());
    let before = text.get(..pos).unwrap_or("");
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let line_text = text[line_start..].lines().next().unwrap_or("").trim();
    let mut problem = format!("TOML syntax error: {}", err.message().trim());
    if !line_text.is_empty() {
        problem.push_str(&format!(" (in `{}`)", shorten(line_text)));
    }
    Diagnostic {
        file: file.to_string(),
        line: Some(before.matches('\n').count() + 1),
        column: Some(before[line_start..].chars().count() + 1),
        set_by: None,
        path: None,
        value: None,
        problem,
        fix: Some(
            "correct the TOML syntax at that position (see docs/cases.md for examples)".into(),
        ),
    }
    .into()
}

/// A schema error reported while deserialising `text` (the file, or the file with overrides
/// applied, re-serialised); `index` indexes `text`, `ctx` the original file.
pub(super) fn schema(ctx: &Ctx<'_>, text: &str, index: &Index, err: &toml::de::Error) -> CaseError {
    let span = err.span().unwrap_or(0..0);
    let path = index.path_at(&span);
    let msg = err.message();
    let written = text.get(span.clone()).map(|s| shorten(s.trim()));

    if let Some(field) = quoted_after(msg, "missing field ") {
        let full = join(&path, &field);
        let fix = match help(&full) {
            Some(h) => format!("add `{}` ({})", h.example, h.meaning),
            None => format!("add `{field}`"),
        };
        let place = if path.is_empty() {
            "at the top of the file".to_string()
        } else {
            format!("in [{}]", strip_index(&path))
        };
        return ctx.err(
            &full,
            None,
            format!("required field is missing {place}"),
            fix,
        );
    }
    if msg.starts_with("unknown field ") {
        let allowed = backticked(msg.split_once("expected").map_or("", |(_, r)| r));
        let scope = if path.contains('.') {
            format!(
                "in [{}]",
                strip_index(&path[..path.rfind('.').unwrap_or(0)])
            )
        } else {
            "at the top level".to_string()
        };
        let problem = if allowed.is_empty() {
            format!("unknown field: no fields are allowed {scope}")
        } else {
            format!(
                "unknown field; the fields allowed {scope} are: {}",
                allowed.join(", ")
            )
        };
        return ctx.err(
            &path,
            None,
            problem,
            "remove it or correct its spelling (see docs/cases.md)",
        );
    }
    if msg.starts_with("unknown variant ") {
        let allowed = backticked(msg.split_once("expected").map_or("", |(_, r)| r));
        let quoted: Vec<String> = allowed.iter().map(|a| format!("\"{a}\"")).collect();
        return ctx.err(
            &path,
            written,
            format!("unknown value; allowed: {}", quoted.join(", ")),
            format!("use one of {}", quoted.join(", ")),
        );
    }
    let serde_type = msg
        .strip_prefix("invalid type: ")
        .or_else(|| msg.strip_prefix("invalid value: "));
    if serde_type.is_some() || msg.starts_with("wanted ") {
        let rest = serde_type.unwrap_or("");
        let found = match serde_type {
            Some(r) => found_kind(r.split(", expected").next().unwrap_or(r)),
            None => found_in_text(written.as_deref().unwrap_or("")),
        };
        let (meaning, example) = expectation(&path, rest);
        // An integer where an integer goes is one out of the field's range (issue 64: "expected
        // an integer, found an integer" for 10^20).
        let problem = match meaning.starts_with(found) {
            true => format!("out of range: expected {meaning}, found {found} beyond it"),
            false => format!("wrong type: expected {meaning}, found {found}"),
        };
        return ctx.err(
            &path,
            written,
            problem,
            match example {
                Some(e) if e.starts_with('[') => format!("write it as {e}"),
                Some(e) => format!("write it like `{e}`"),
                None => "give a plain number".to_string(),
            },
        );
    }
    ctx.err(
        &path,
        written,
        msg.to_string(),
        "see docs/cases.md for the allowed fields and values",
    )
}

/// Refuses a table written as anything else, before deserialising. serde fills a struct from a
/// sequence by position, so `time = [1.0, 0.02]` would silently become `end_s = 1.0` and
/// `output_every_s = 0.02`; a case file names its fields. A path is a table when its help entry
/// says so ([`FieldHelp::ty`](super::schema::FieldHelp::ty)), `[[...]]` elements included.
pub(super) fn tables_are_tables(
    ctx: &Ctx<'_>,
    text: &str,
    doc: &DeTable<'_>,
) -> Result<(), CaseError> {
    for (key, value) in doc.iter() {
        check_table_shape(ctx, text, &join("", key.get_ref()), value)?;
    }
    Ok(())
}

fn check_table_shape(
    ctx: &Ctx<'_>,
    text: &str,
    path: &str,
    value: &Spanned<DeValue<'_>>,
) -> Result<(), CaseError> {
    let v = value.get_ref();
    if let Some(h) = help(path).filter(|h| h.ty() == "a table") {
        if v.as_table().is_none() {
            let found = match v {
                DeValue::String(_) => "a string",
                DeValue::Integer(_) => "an integer",
                DeValue::Float(_) => "a number with a fraction",
                DeValue::Boolean(_) => "a boolean",
                DeValue::Datetime(_) => "a date",
                DeValue::Array(_) => "an array",
                DeValue::Table(_) => "a table",
            };
            return Err(ctx.err(
                path,
                text.get(value.span()).map(|s| shorten(s.trim())),
                format!(
                    "wrong type: expected a table ({}), found {found}",
                    h.meaning
                ),
                format!("write it as {}, each field by name", h.example),
            ));
        }
    }
    if let Some(t) = v.as_table() {
        for (key, item) in t.iter() {
            check_table_shape(ctx, text, &join(path, key.get_ref()), item)?;
        }
    } else if let Some(items) = v.as_array() {
        for (i, item) in items.iter().enumerate() {
            check_table_shape(ctx, text, &format!("{path}[{i}]"), item)?;
        }
    }
    Ok(())
}

/// What the field at `path` should hold, and an example line.
fn expectation(path: &str, serde_rest: &str) -> (String, Option<&'static str>) {
    if let Some(h) = help(path) {
        return (format!("{} ({})", h.ty(), h.meaning), Some(h.example));
    }
    if path.ends_with(']') {
        return ("a number".to_string(), None);
    }
    let expected = serde_rest
        .split(", expected ")
        .nth(1)
        .unwrap_or("another type");
    (expected.to_string(), None)
}

/// serde's "string \"a\"" / "integer `3`" → "a string" / "an integer".
fn found_kind(unexpected: &str) -> &'static str {
    let u = unexpected.trim_start();
    [
        ("string", "a string"),
        ("integer", "an integer"),
        ("floating point", "a number with a fraction"),
        ("boolean", "a boolean"),
        ("sequence", "an array"),
        ("map", "a table"),
        ("char", "a string"),
    ]
    .iter()
    .find(|(k, _)| u.starts_with(k))
    .map_or("another type", |(_, v)| v)
}

/// The TOML type of a value as written.
fn found_in_text(text: &str) -> &'static str {
    match text.chars().next() {
        Some('"' | '\'') => "a string",
        Some('[') => "an array",
        Some('{') => "a table",
        Some('t' | 'f') => "a boolean",
        Some(_) => "a number",
        None => "another type",
    }
}

/// The first `...` quoted word after `prefix`.
fn quoted_after(msg: &str, prefix: &str) -> Option<String> {
    let rest = msg.strip_prefix(prefix)?.strip_prefix('`')?;
    Some(rest.split('`').next()?.to_string())
}

/// All `...` quoted words of `s`.
fn backticked(s: &str) -> Vec<String> {
    s.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// `probe[2]` → `probe` (table names as written in a file).
fn strip_index(path: &str) -> String {
    let mut out = String::new();
    let mut depth = 0;
    for c in path.chars() {
        match c {
            '[' => depth += 1,
            ']' => depth -= 1,
            _ if depth == 0 => out.push(c),
            _ => {}
        }
    }
    out
}

/// At most 60 characters, on one line.
pub(super) fn shorten(s: &str) -> String {
    let one_line: String = s
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    if one_line.chars().count() > 60 {
        format!("{}…", one_line.chars().take(57).collect::<String>())
    } else {
        one_line
    }
}

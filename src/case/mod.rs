//! Case files: a TOML description of a run (`cases/*.toml`, documented in `docs/cases.md`)
//! turned into the [`Scenario`](crate::scenario::Scenario) the solver consumes.
//!
//! Pipeline: parse the TOML (syntax errors with line and column) → apply `--set` overrides to
//! the document → deserialise into the schema (unknown, missing and mistyped fields) → check every
//! field (`validate.rs`) → check the geometry and build the particles (`build.rs`). Every error
//! names the file, the line, the field's dotted path, what is wrong and a fix.

mod bodies;
mod build;
mod diagnose;
mod error;
mod lattice;
mod locate;
mod overrides;
mod probes;
mod schema;
mod solids;
mod validate;

#[cfg(test)]
mod tests;

use std::path::Path;

pub use build::MAX_PARTICLES;
pub use error::{CaseError, Diagnostic};

use crate::scenario::Scenario;
use locate::{Ctx, Index};
use schema::RawCase;

/// Reads and builds the case file at `path`, with `--set KEY=VALUE` overrides applied.
pub fn load(path: &Path, overrides: &[String]) -> Result<Scenario, CaseError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| CaseError::Read {
        file: file.clone(),
        source,
    })?;
    load_str(&text, &file, overrides)
}

/// Builds a case from its text; `file_name` is used in messages and, without a `name` field,
/// its stem becomes the case name.
pub fn load_str(text: &str, file_name: &str, overrides: &[String]) -> Result<Scenario, CaseError> {
    let doc = toml::de::DeTable::parse(text).map_err(|e| diagnose::syntax(file_name, text, &e))?;
    let index = Index::new(text, doc.get_ref());

    let parsed: Vec<overrides::Override> = overrides
        .iter()
        .map(|arg| overrides::parse(file_name, arg))
        .collect::<Result<_, _>>()?;
    let keys: Vec<(String, String)> = parsed
        .iter()
        .map(|o| (o.key.clone(), o.arg.clone()))
        .collect();
    let ctx = Ctx {
        file: file_name,
        index: &index,
        overrides: &keys,
    };

    // With overrides, edit the document and deserialise its re-serialised text; error spans then
    // point into that text, and are mapped back to field paths (and so to the file's lines).
    let edited;
    let (de_text, de_index) = if parsed.is_empty() {
        (text, None)
    } else {
        let mut table: toml::Table = text
            .parse()
            .map_err(|e| diagnose::syntax(file_name, text, &e))?;
        for o in &parsed {
            overrides::apply(file_name, &mut table, o)?;
        }
        edited = toml::to_string(&table).map_err(|e| {
            ctx.err(
                "",
                None,
                format!("cannot apply the overrides: {e}"),
                "check the --set values",
            )
        })?;
        let doc = toml::de::DeTable::parse(&edited)
            .map_err(|e| diagnose::syntax(file_name, &edited, &e))?;
        (edited.as_str(), Some(Index::new(&edited, doc.get_ref())))
    };
    let raw: RawCase = toml::from_str(de_text)
        .map_err(|e| diagnose::schema(&ctx, de_text, de_index.as_ref().unwrap_or(&index), &e))?;

    let stem = Path::new(file_name)
        .file_stem()
        .map_or_else(|| "case".to_string(), |s| s.to_string_lossy().into_owned());
    let case_dir = Path::new(file_name).parent().unwrap_or(Path::new("."));
    let case = validate::validate(&ctx, &raw, &stem, case_dir)?;
    build::build(&ctx, case)
}

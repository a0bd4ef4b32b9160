//! Case files: a TOML description of a run (`cases/*.toml`, documented in `docs/cases.md`)
//! turned into the [`Scenario`](crate::scenario::Scenario) the solver consumes.
//!
//! Pipeline: parse the TOML (syntax errors with line and column) → apply `--set` overrides to
//! the document → deserialise into the schema (unknown, missing and mistyped fields) → check every
//! field (`validate.rs`) → check the geometry and build the particles (`build.rs`). Every error
//! names the file, the line, the field's dotted path, what is wrong and a fix.
//!
//! The files form layers; each imports only from the layers below it (no file imports one of
//! its own layer or above, but where noted), so there are no import circles:
//!
//! 1. the foundation: `error.rs` ([`CaseError`], [`Diagnostic`], how numbers are written),
//!    `locate.rs` (field paths, lines and the context every check reports through) and
//!    `schema.rs` (the deserialised TOML); `diagnose.rs` (parse and schema errors) and
//!    `overrides.rs` (`--set`) use only these;
//! 2. `check.rs`: the checking primitives: boxes, the checks of one number, vector or box,
//!    wall treatments, inside tests, how a box is written in a message, bounded file reads;
//! 3. size limits: `limits.rs`;
//! 4. the checks and particles of one kind of table each: `probes.rs`, `open_boundaries.rs`,
//!    `solids.rs`, `bodies.rs`, `terrain.rs`, `buildings.rs` (which stands on the terrain),
//!    `surface.rs`, `fill.rs`, and `friction.rs` (which names bodies and solids). Their
//!    geometry (lattices, boxes, polygons, closed and open meshes, terrains, footprints, fills)
//!    is `crate::generate`'s, which knows nothing of case files;
//! 5. `validate.rs`: the whole checked case (`Case`);
//! 6. the build: `warnings.rs`, `domain.rs` and `runnable.rs` (the f32 range, time step and
//!    schedule of the built case), used by `build.rs`;
//! 7. this file (the loader) with `built_in.rs` ([`BUILT_IN`], the case files built into the
//!    binary, loaded through this file) and the tests.

mod bodies;
mod build;
mod buildings;
mod built_in;
mod check;
mod diagnose;
mod domain;
mod error;
mod fill;
mod friction;
mod limits;
mod locate;
mod maps;
mod open_boundaries;
mod overrides;
mod probes;
mod runnable;
mod schema;
mod solids;
mod surface;
mod terrain;
mod time_series;
mod validate;
mod warnings;

#[cfg(test)]
mod tests;

use std::path::Path;

pub use built_in::{built_in, BuiltIn, BUILT_IN};
pub(crate) use check::read_bounded;
pub use error::{CaseError, Diagnostic};
pub use limits::{ParticleBudget, MAX_PARTICLES};

use crate::scenario::Scenario;
use locate::{Ctx, Index};
use schema::RawCase;

/// The largest case file read: case files are a few kilobytes, and without a bound a path such
/// as /dev/zero would be read forever.
const MAX_CASE_BYTES: u64 = 16 << 20;

/// Reads and builds the case file at `path`, with `--set KEY=VALUE` overrides applied.
pub fn load(path: &Path, overrides: &[String]) -> Result<Scenario, CaseError> {
    load_within(path, overrides, &ParticleBudget::default())
}

/// [`load`] with at most `budget` particles (what the adapter and the host's memory hold, say),
/// refused before any is made.
pub fn load_within(
    path: &Path,
    overrides: &[String],
    budget: &ParticleBudget,
) -> Result<Scenario, CaseError> {
    let file = path.display().to_string();
    let text = read_bounded(path, MAX_CASE_BYTES).map_err(|source| CaseError::Read {
        file: file.clone(),
        source,
    })?;
    load_str_within(&text, &file, overrides, budget)
}

/// Builds a case from its text; `file_name` is used in messages and, without a `name` field,
/// its stem becomes the case name.
pub fn load_str(text: &str, file_name: &str, overrides: &[String]) -> Result<Scenario, CaseError> {
    load_str_limited(text, file_name, overrides, MAX_PARTICLES)
}

/// [`load_str`] with a particle budget of `max_particles` instead of [`MAX_PARTICLES`]: a case
/// that would create more particles is refused (naming `particles.dx_m`) before any is made.
/// For tests that build thousands of cases and must stay small and fast (`tests/case_fuzz/`).
pub fn load_str_limited(
    text: &str,
    file_name: &str,
    overrides: &[String],
    max_particles: f64,
) -> Result<Scenario, CaseError> {
    let budget = ParticleBudget::at_most(max_particles, "this caller's");
    load_str_within(text, file_name, overrides, &budget)
}

/// [`load_str`] with at most `budget` particles, refused before any is made.
pub fn load_str_within(
    text: &str,
    file_name: &str,
    overrides: &[String],
    budget: &ParticleBudget,
) -> Result<Scenario, CaseError> {
    let doc = toml::de::DeTable::parse(text).map_err(|e| diagnose::syntax(file_name, text, &e))?;
    let index = Index::new(text, doc.get_ref());

    let (parsed, keys) = parse_overrides(file_name, overrides)?;
    let ctx = Ctx {
        file: file_name,
        index: &index,
        overrides: &keys,
    };

    // With overrides, edit the document and deserialise its re-serialised text; error spans then
    // point into that text, and are mapped back to field paths (and so to the file's lines).
    let edited;
    let (de_text, de_index, de_doc) = if parsed.is_empty() {
        (text, None, doc)
    } else {
        edited = edit(&ctx, text, &parsed)?;
        // The edit of a valid document is valid TOML; should it not be, the overrides are to
        // blame, not a line of the file.
        let doc = toml::de::DeTable::parse(&edited).map_err(|e| {
            ctx.err(
                "",
                None,
                format!("cannot apply the overrides: {}", e.message().trim()),
                "check the --set values",
            )
        })?;
        let edited_index = Index::new(&edited, doc.get_ref());
        (edited.as_str(), Some(edited_index), doc)
    };
    diagnose::tables_are_tables(&ctx, de_text, de_doc.get_ref())?;
    let raw: RawCase = toml::from_str(de_text)
        .map_err(|e| diagnose::schema(&ctx, de_text, de_index.as_ref().unwrap_or(&index), &e))?;

    let stem = Path::new(file_name)
        .file_stem()
        .map_or_else(|| "case".to_string(), |s| s.to_string_lossy().into_owned());
    let case_dir = Path::new(file_name).parent().unwrap_or(Path::new("."));
    let case = validate::validate(&ctx, &raw, &stem, case_dir)?;
    build::build(&ctx, case, budget)
}

/// The case text with `parsed` overrides applied to its document, re-serialised (the loader
/// checks this text; comments and layout are lost).
fn edit(ctx: &Ctx, text: &str, parsed: &[overrides::Override]) -> Result<String, CaseError> {
    let mut table: toml::Table = text
        .parse()
        .map_err(|e| diagnose::syntax(ctx.file, text, &e))?;
    for o in parsed {
        overrides::apply(ctx.file, &mut table, o)?;
    }
    toml::to_string(&table).map_err(|e| {
        ctx.err(
            "",
            None,
            format!("cannot apply the overrides: {e}"),
            "check the --set values",
        )
    })
}

/// The parsed `--set` arguments and, for messages, each one's key with its argument.
type ParsedOverrides = (Vec<overrides::Override>, Vec<(String, String)>);

fn parse_overrides(file_name: &str, overrides: &[String]) -> Result<ParsedOverrides, CaseError> {
    let parsed: Vec<overrides::Override> = overrides
        .iter()
        .map(|arg| overrides::parse(file_name, arg))
        .collect::<Result<_, _>>()?;
    let keys = parsed
        .iter()
        .map(|o| (o.key.clone(), o.arg.clone()))
        .collect();
    Ok((parsed, keys))
}

/// The text of a case with `--set KEY=VALUE` overrides applied, as the loader reads it: `text`
/// itself without overrides, else its document re-serialised with them (comments and layout
/// lost). Errors as [`load_str`]'s for the same file and overrides. For writing a case out
/// again (the Python package's `Case.to_toml`).
pub fn with_overrides(
    text: &str,
    file_name: &str,
    overrides: &[String],
) -> Result<String, CaseError> {
    let doc = toml::de::DeTable::parse(text).map_err(|e| diagnose::syntax(file_name, text, &e))?;
    let index = Index::new(text, doc.get_ref());
    let (parsed, keys) = parse_overrides(file_name, overrides)?;
    if parsed.is_empty() {
        return Ok(text.to_string());
    }
    let ctx = Ctx {
        file: file_name,
        index: &index,
        overrides: &keys,
    };
    edit(&ctx, text, &parsed)
}

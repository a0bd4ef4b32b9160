//! Continuing a run folder from its checkpoint: what `wgsph resume DIR` and the Python
//! package's `resume` share (the case and options to continue with), so the two cannot drift.

use std::path::Path;

use anyhow::{bail, Result};

use crate::case::CaseError;
use crate::checkpoint::{CaseSource, Checkpoint, CheckpointPolicy, CHECKPOINT_FILE};
use crate::output::RunSummary;
use crate::run::RunOptions;
use crate::scenario::Scenario;

/// Loads the case of a checkpoint that does not record its file (a run made through the
/// library, or from a case given as text), with the overrides to apply.
pub type UnrecordedCase<'a> = &'a dyn Fn(&[String]) -> Result<Scenario, CaseError>;

/// What resuming the run in a folder comes to.
pub enum ResumePlan {
    /// The run completed to its end and left no checkpoint, and no override asks for more:
    /// nothing to compute. The text says so, naming the folder and the time reached.
    Complete(String),
    /// Continue `scenario` (the checkpoint's case with its overrides, then `set`'s) with
    /// `options`; the caller adds its interrupt flag.
    Continue {
        /// Boxed: a scenario is large beside the other variant.
        scenario: Box<Scenario>,
        options: RunOptions,
    },
}

/// How to resume the run in `dir` with `set` over its overrides and `checkpoint_every` over
/// its checkpoint policy. `unrecorded` loads the case where the checkpoint records no case
/// file; without it such a checkpoint is refused, saying how to give the case.
pub fn plan(
    dir: &Path,
    set: &[String],
    checkpoint_every: Option<CheckpointPolicy>,
    unrecorded: Option<UnrecordedCase>,
) -> Result<ResumePlan> {
    let ck_path = dir.join(CHECKPOINT_FILE);
    if !ck_path.is_file() {
        // A short run completes before its first checkpoint: say so rather than that the
        // checkpoint is missing.
        if let Ok(done) = RunSummary::read(dir) {
            if done.status == "completed" {
                let what = format!(
                    "{}: the run is already complete (t = {:.4} s) and left no checkpoint",
                    dir.display(),
                    done.simulated_time_s
                );
                if set.is_empty() {
                    return Ok(ResumePlan::Complete(what));
                }
                bail!(
                    "{what} to continue from with {set:?}: run the case again with the later \
                     time.end_s (and --checkpoint-every to extend it later)"
                );
            }
        }
    }
    let ck = Checkpoint::read(&ck_path)?;
    let (scenario, source) = match (ck.source.clone(), unrecorded) {
        (Some(source), _) => {
            let overrides: Vec<String> = source.overrides.iter().chain(set).cloned().collect();
            let sc = crate::case::load(&source.path, &overrides)?;
            let source = CaseSource {
                path: source.path,
                overrides,
            };
            (sc, Some(source))
        }
        (None, Some(load)) => (load(set)?, None),
        (None, None) => bail!(
            "{} does not record its case file (the run was made through the library or from a \
             case given as text): give the case to resume with (Python: wgsph.resume(dir, \
             case=...); Rust: wgsph::run::resume)",
            ck_path.display()
        ),
    };
    // `..Default::default()` fills the fields the `test-hooks` feature adds.
    #[allow(clippy::needless_update)]
    let options = RunOptions {
        snapshot_png: ck
            .snapshot_field
            .as_deref()
            .map(|f| f.parse().map_err(anyhow::Error::msg))
            .transpose()?,
        // The run's own policy unless given anew (a checkpoint written before the policy was
        // recorded: the default).
        checkpoint: checkpoint_every
            .or(ck.policy)
            .unwrap_or_else(CheckpointPolicy::default_for_runs),
        source,
        interrupt: None,
        halt_at_s: None,
        ..Default::default()
    };
    Ok(ResumePlan::Continue {
        scenario: Box::new(scenario),
        options,
    })
}

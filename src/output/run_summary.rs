//! Run summary written to `DIR/run.json`.

use std::path::Path;

use super::{write_atomic, OutputError};
use crate::ranks::RankSummary;

/// Summary of a run, written as JSON at the end (and possibly on stop). Non-finite floats are
/// written as `null` (JSON has no NaN).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RunSummary {
    pub case: String,
    pub adapter: String,
    pub backend: String,
    pub dimension: u32,
    pub particles_fluid: u64,
    /// Boundary particles of every wall treatment (walls, obstacles, bodies).
    pub particles_wall: u64,
    /// Elastic solid particles, clamped ones included.
    #[serde(default)]
    pub particles_solid: u64,
    /// Inlet particles (the buffers and the layers waiting behind them).
    #[serde(default)]
    pub particles_inlet: u64,
    /// Particles that left the domain or became non-finite.
    pub particles_excluded: u64,
    /// Fluid particles the outlets removed.
    #[serde(default)]
    pub particles_drained: u64,
    pub steps: u64,
    pub simulated_time_s: f64,
    pub wall_time_s: f64,
    pub particle_steps_per_s: f64,
    pub gpu_bytes_per_particle: f64,
    pub outputs: u64,
    /// "completed" | "stopped: <reason>"
    pub status: String,
    /// The case's warnings (`Scenario::warnings`), and the run's (the density beyond
    /// `time.density_variation_warn`).
    #[serde(default)]
    pub warnings: Vec<String>,
    /// The fluid's largest density variation |ρ/ρ0 − 1| over the run (over the probe
    /// intervals; None in a summary written before it was measured).
    #[serde(default)]
    pub max_density_variation: Option<f64>,
    /// The `--set` overrides the case was loaded with, where the run knows them (`wgsph run`,
    /// `resume`, `validate`; None through the library without a `CaseSource`). `wgsph validate
    /// --reuse` takes a run made with its mode's overrides.
    #[serde(default)]
    pub overrides: Option<Vec<String>>,
    /// The scenario's fingerprint (`checkpoint::fingerprint`: physics, walls, probes, bodies
    /// and every particle), 16 hex digits: the same case and overrides built by another engine
    /// version, or on another machine whose libm rounds a density differently, differ here.
    #[serde(default)]
    pub fingerprint: Option<String>,
    /// The case file the run was loaded from, as the run was given it (absolute for `wgsph
    /// run`; a validation case's path in the repository), where the run knows it. `wgsph plot
    /// --snapshots` loads the case from it with `overrides` to draw the particle files.
    #[serde(default)]
    pub case_file: Option<String>,
    /// A run over several ranks: each rank's part, in rank order (absent for one whole run).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ranks: Option<Vec<RankSummary>>,
    /// The world coordinates of the positions' (0, 0, 0) (`Scenario::world_origin_m`).
    #[serde(default)]
    pub world_origin_m: [f64; 3],
    /// Seconds the case took to read and build into particles (issue 59), where the run knows
    /// it (`wgsph run`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub case_build_s: Option<f64>,
}

impl RunSummary {
    /// Reads `DIR/run.json`; errors name the file.
    pub fn read(dir: &Path) -> Result<Self, OutputError> {
        let path = dir.join(super::RUN_SUMMARY_FILE);
        let text = std::fs::read_to_string(&path).map_err(|e| OutputError::io("read", &path, e))?;
        serde_json::from_str(&text).map_err(|e| OutputError::Read {
            path,
            reason: e.to_string(),
        })
    }
}

pub(crate) fn write_run_summary(path: &Path, summary: &RunSummary) -> Result<(), OutputError> {
    let mut json = serde_json::to_vec_pretty(summary).map_err(|error| OutputError::Json {
        path: path.to_path_buf(),
        error,
    })?;
    json.push(b'\n');
    write_atomic(path, |w| w.write_all(&json))
}

#[cfg(test)]
mod tests {
    use super::super::test_util::temp_dir;
    use super::super::OutputDir;
    use super::*;

    fn sample() -> RunSummary {
        RunSummary {
            overrides: Some(vec!["time.end_s=1".into()]),
            fingerprint: Some("0123456789abcdef".into()),
            case_file: Some("/cases/x.toml".into()),
            ranks: None,
            world_origin_m: [0.0; 3],
            case_build_s: Some(1.25),
            case: "dam_break_2d".into(),
            adapter: "NVIDIA H100 \"quoted\"".into(),
            backend: "Vulkan".into(),
            dimension: 2,
            particles_fluid: 123_456,
            particles_wall: 7_890,
            particles_solid: 0,
            particles_inlet: 0,
            particles_excluded: 0,
            particles_drained: 0,
            steps: 10_000,
            simulated_time_s: 0.1 + 0.2,
            wall_time_s: 12.5,
            particle_steps_per_s: 1.0 / 3.0 * 1e9,
            gpu_bytes_per_particle: 212.0,
            outputs: 51,
            status: "completed".into(),
            warnings: vec!["body[0] ('plate') has fixed ghosts and is 0.01 m thick".into()],
            // A widened f32 that serde_json's default float parser reads back one ulp off.
            max_density_variation: Some(f64::from(0.010_712_147_f32)),
        }
    }

    #[test]
    fn writes_and_reads_back() {
        let d = temp_dir("summary");
        let mut out = OutputDir::create(&d).unwrap();
        let s = sample();
        out.write_run_summary(&s).unwrap();
        let text = std::fs::read_to_string(d.join("run.json")).unwrap();
        let back: RunSummary = serde_json::from_str(&text).unwrap();
        assert_eq!(back, s);
        assert!(text.contains("\"status\": \"completed\""));
        // Rewrite with a different status.
        let s2 = RunSummary {
            status: "stopped: NaN in density".into(),
            ..s
        };
        out.write_run_summary(&s2).unwrap();
        let back: RunSummary =
            serde_json::from_str(&std::fs::read_to_string(d.join("run.json")).unwrap()).unwrap();
        assert_eq!(back.status, "stopped: NaN in density");
        // run.json, particles, probes and the manifest listing run.json.
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 4);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn nan_becomes_null() {
        let d = temp_dir("summary-nan");
        let mut out = OutputDir::create(&d).unwrap();
        let s = RunSummary {
            wall_time_s: f64::NAN,
            particle_steps_per_s: f64::INFINITY,
            ..sample()
        };
        out.write_run_summary(&s).unwrap();
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("run.json")).unwrap()).unwrap();
        assert!(v["wall_time_s"].is_null());
        assert!(v["particle_steps_per_s"].is_null());
        assert_eq!(v["steps"], 10_000);
        std::fs::remove_dir_all(&d).unwrap();
    }
}

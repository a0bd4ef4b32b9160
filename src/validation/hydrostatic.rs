//! Hydrostatic tanks (`cases/hydrostatic_2d.toml`, `cases/hydrostatic_3d.toml`): the bottom
//! pressure probe against the analytic ρ0 g (H − z), and the floor sensor (the fluid's force on
//! the floor) against the weight of the water above it, ρ0 g H, both averaged once the
//! start-up acoustic waves have decayed. H is the top of the case's fluid block.

use std::path::Path;

use anyhow::{anyhow, bail, Result};

use super::{
    gravity, lost_particles, probe_series, reference_curve, sim_curve, Bound, Evaluation, Figure,
    Metric, Mode, Unit,
};
use crate::scenario::{ProbeKind, Scenario};

/// The pressure probe compared.
pub const PROBE: &str = "p_bottom";
/// The 3D tank's second pressure probe, 0.05 m above the floor, reported.
pub const LOW_PROBE: &str = "p_low";
/// The wall-pressure probe on the floor compared.
pub const FLOOR_PROBE: &str = "p_floor";
/// Samples after this time are averaged (the acoustic waves of the start have decayed), s.
pub const SETTLED_AFTER_S: f64 = 1.0;
/// Bound of the relative error of the mean pressure, both modes.
pub const BOUND: f64 = 0.02;
/// The 3D tank's, half a spacing above the floor (issue 36).
pub const BOUND_3D: f64 = 0.01;
/// Bound of the floor sensor's: the force on the floor is the weight of the water whatever the
/// particles' pressure bias, so a correct wall holds it closer.
pub const FLOOR_BOUND: f64 = 0.01;

/// Quick: the shipped dx = 0.02 m (H/dx = 25); full: dx = 0.01 m (H/dx = 50). Both 2 s.
pub fn overrides(mode: Mode) -> Option<Vec<String>> {
    let mut set = vec!["time.end_s=2".to_string()];
    if mode == Mode::Full {
        set.push("particles.dx_m=0.01".into());
    }
    Some(set)
}

/// The 3D tank: quick at dx = 0.04 m (H/dx = 10), full at the shipped dx = 0.02 m, both 2 s;
/// the bottom probe half a spacing above the floor's face at either (`face_m`).
pub fn overrides_3d(mode: Mode) -> Option<Vec<String>> {
    let mut set = vec!["time.end_s=2".to_string()];
    if mode == Mode::Quick {
        set.push("particles.dx_m=0.04".into());
    }
    Some(set)
}

/// The still water's depth: the top of the fluid's lattice (its highest particles lie half a
/// spacing below it).
pub fn depth(sc: &Scenario) -> f64 {
    let up = sc.physics.dim as usize - 1;
    (sc.particles.iter())
        .filter(|p| p.kind.is_fluid())
        .map(|p| p.pos[up])
        .fold(f64::MIN, f64::max)
        + 0.5 * sc.physics.dx
}

/// A probe's mean pressure against the hydrostatic one at its point.
#[derive(Clone, Debug)]
pub struct MeanPressure {
    pub mean_pa: f64,
    pub exact_pa: f64,
    /// Depth of the probe below the still surface, m.
    pub depth_m: f64,
    pub samples: usize,
}

impl MeanPressure {
    /// Relative error of the mean.
    pub fn error(&self) -> f64 {
        (self.mean_pa - self.exact_pa) / self.exact_pa
    }
}

/// The mean of the samples of the pressure or wall-pressure probe `name` with
/// t > [`SETTLED_AFTER_S`] (`series`: (t, p)) against ρ0 |g| (H − z) at the probe's point.
pub fn mean_pressure(sc: &Scenario, name: &str, series: &[(f64, f64)]) -> Result<MeanPressure> {
    let probe = sc
        .probes
        .iter()
        .find(|p| p.name == name)
        .ok_or_else(|| anyhow!("the case has no probe {name:?}"))?;
    let point = match &probe.kind {
        ProbeKind::Pressure { point } => *point,
        ProbeKind::WallPressure(patch) => patch.point,
        _ => bail!("probe {name:?} is not a pressure or wall-pressure probe"),
    };
    let vertical = sc.physics.dim as usize - 1;
    let depth_m = depth(sc) - point[vertical];
    let exact_pa = sc.physics.rho0 * gravity(sc) * depth_m;
    let late: Vec<f64> = series
        .iter()
        .filter(|(t, _)| *t > SETTLED_AFTER_S + 1e-9)
        .map(|p| p.1)
        .collect();
    if late.is_empty() {
        bail!("no {name} sample after t = {SETTLED_AFTER_S} s");
    }
    Ok(MeanPressure {
        mean_pa: late.iter().sum::<f64>() / late.len() as f64,
        exact_pa,
        depth_m,
        samples: late.len(),
    })
}

pub fn evaluate(sc: &Scenario, dir: &Path, _bounds: Mode) -> Result<Evaluation> {
    judge(sc, dir, BOUND)
}

pub fn evaluate_3d(sc: &Scenario, dir: &Path, _bounds: Mode) -> Result<Evaluation> {
    judge(sc, dir, BOUND_3D)
}

/// The rows of a tank whose bottom probe is held to `bound`; a `p_low` probe is reported.
fn judge(sc: &Scenario, dir: &Path, bound: f64) -> Result<Evaluation> {
    let mut metrics = Vec::new();
    let mut figures = Vec::new();
    let low = (sc.probes.iter().any(|p| p.name == LOW_PROBE)).then_some((
        LOW_PROBE,
        "pressure 0.05 m above the floor",
        None,
    ));
    let probes = [
        (PROBE, "bottom pressure", Some(bound)),
        (
            FLOOR_PROBE,
            "floor sensor (force on the floor)",
            Some(FLOOR_BOUND),
        ),
    ];
    for (name, what, bound) in probes.into_iter().chain(low) {
        let series = probe_series(dir, name)?;
        let b = mean_pressure(sc, name, &series)?;
        let end = series.last().map_or(sc.time.end_s, |p| p.0);
        metrics.push(Metric {
            name: format!("{what}, mean over t > {SETTLED_AFTER_S} s, vs ρ0 g (H − z)"),
            value: b.error(),
            unit: Unit::Percent,
            bound: bound.map(Bound::Within),
            detail: format!(
                "{:.1} Pa ({} samples) at depth {:.4} m, analytic {:.1} Pa",
                b.mean_pa, b.samples, b.depth_m, b.exact_pa
            ),
        });
        figures.push(Figure {
            name: name.into(),
            title: format!("{}: {name}", sc.name),
            x_label: "t [s]".into(),
            y_label: "pressure [Pa]".into(),
            curves: vec![
                sim_curve("wgsph", series),
                reference_curve("ρ0 g (H − z)", vec![(0.0, b.exact_pa), (end, b.exact_pa)]),
            ],
        });
    }
    metrics.push(lost_particles(dir, true)?);
    Ok(Evaluation { metrics, figures })
}

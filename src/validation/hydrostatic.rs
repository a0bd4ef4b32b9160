//! Hydrostatic tank (`cases/hydrostatic_2d.toml`): the bottom pressure probe against the
//! analytic ρ0 g (H − z), and the floor sensor (the fluid's force on the floor) against the
//! weight of the water above it, ρ0 g H, both averaged once the start-up acoustic waves have
//! decayed.

use std::path::Path;

use anyhow::{anyhow, bail, Result};

use super::{
    gravity, lost_particles, probe_series, reference_curve, sim_curve, Bound, Evaluation, Figure,
    Metric, Mode, Unit,
};
use crate::scenario::{ProbeKind, Scenario};

/// Water depth H of the case file (its fluid block's top), m.
pub const DEPTH_M: f64 = 0.5;
/// The pressure probe compared.
pub const PROBE: &str = "p_bottom";
/// The wall-pressure probe on the floor compared.
pub const FLOOR_PROBE: &str = "p_floor";
/// Samples after this time are averaged (the acoustic waves of the start have decayed), s.
pub const SETTLED_AFTER_S: f64 = 1.0;
/// Bound of the relative error of the mean pressure, both modes.
pub const BOUND: f64 = 0.02;
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
    let depth_m = DEPTH_M - point[vertical];
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
    let mut metrics = Vec::new();
    let mut figures = Vec::new();
    for (name, what, bound) in [
        (PROBE, "bottom pressure", BOUND),
        (
            FLOOR_PROBE,
            "floor sensor (force on the floor)",
            FLOOR_BOUND,
        ),
    ] {
        let series = probe_series(dir, name)?;
        let b = mean_pressure(sc, name, &series)?;
        let end = series.last().map_or(sc.time.end_s, |p| p.0);
        metrics.push(Metric {
            name: format!("{what}, mean over t > {SETTLED_AFTER_S} s, vs ρ0 g (H − z)"),
            value: b.error(),
            unit: Unit::Percent,
            bound: Some(Bound::Within(bound)),
            detail: format!(
                "{:.1} Pa ({} samples) at depth {} m, analytic {:.1} Pa",
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

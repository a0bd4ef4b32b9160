//! Dam break through an elastic gate (`cases/elastic_gate_2d.toml`, Antoci, Gallati & Sibilla
//! 2007): the horizontal and vertical displacement of the gate's free end against the
//! experiment's, normalised by the largest measured displacement (the series pass through
//! small values, where a relative error means nothing).

use std::path::Path;

use anyhow::{anyhow, Result};

use super::{
    lost_particles, reference_curve, sim_curve, table_series, Bound, Evaluation, Figure, Metric,
    Mode, Reference, Unit,
};
use crate::plot::interpolate;
use crate::scenario::Scenario;

pub const CITATION: &str = "Antoci, Gallati & Sibilla (2007), Comput. Struct. 85:879-890, \
     measured free-end displacement (digitised; via Ng et al. 2020)";
pub const X_DISPLACEMENT: Reference = Reference {
    file: "tests/data/antoci_2007_elastic_gate_x_displacement.csv",
    text: include_str!("../../tests/data/antoci_2007_elastic_gate_x_displacement.csv"),
};
pub const Y_DISPLACEMENT: Reference = Reference {
    file: "tests/data/antoci_2007_elastic_gate_y_displacement.csv",
    text: include_str!("../../tests/data/antoci_2007_elastic_gate_y_displacement.csv"),
};
/// The tracked point of the case file: `probes/point_free_end.csv`.
pub const POINT: &str = "free_end";
/// Bound of the largest error over the peak measured displacement (full mode).
pub const BOUND: f64 = 0.2;

/// Full mode only, the shipped case (dx = 1 mm, 5 particles through the gate, 0.4 s): about
/// 250 000 steps of 17 000 particles, hours on a software adapter. Quick mode does not run it.
pub fn overrides(mode: Mode) -> Option<Vec<String>> {
    (mode == Mode::Full).then(Vec::new)
}

/// One displacement component of the free end against the experiment.
#[derive(Clone, Debug)]
pub struct Displacement {
    /// (t, displacement) of the run and of the experiment [s, m].
    pub sim: Vec<(f64, f64)>,
    pub experiment: Vec<(f64, f64)>,
    /// (t, simulated, measured) at the experiment's times.
    pub points: Vec<(f64, f64, f64)>,
}

impl Displacement {
    /// The largest |simulated − measured| over the largest |measured|, with its sign.
    pub fn worst_error(&self) -> f64 {
        let peak = self
            .experiment
            .iter()
            .map(|p| p.1.abs())
            .fold(0.0, f64::max);
        self.points
            .iter()
            .map(|(_, s, w)| (s - w) / peak)
            .fold(0.0, |a: f64, e| if e.abs() > a.abs() { e } else { a })
    }
}

/// `column` (`ux_m` or `uy_m`) of the free end in the run in `dir` against `reference`.
pub fn displacement(dir: &Path, column: &str, reference: &Reference) -> Result<Displacement> {
    let sim = table_series(dir, &format!("point_{POINT}"), column)?;
    let experiment = reference.points()?;
    let points = experiment
        .iter()
        .map(|&(t, want)| {
            let got = interpolate(&sim, t)
                .ok_or_else(|| anyhow!("no finite free-end displacement at t = {t} s"))?;
            Ok((t, got, want))
        })
        .collect::<Result<_>>()?;
    Ok(Displacement {
        sim,
        experiment,
        points,
    })
}

pub fn evaluate(sc: &Scenario, dir: &Path, bounds: Mode) -> Result<Evaluation> {
    let mut metrics = Vec::new();
    let mut figures = Vec::new();
    for (axis, column, reference) in [
        ("x", "ux_m", &X_DISPLACEMENT),
        ("y", "uy_m", &Y_DISPLACEMENT),
    ] {
        let d = displacement(dir, column, reference)?;
        let detail = d
            .points
            .iter()
            .map(|(t, s, w)| format!("t {t:.3} s: {:.1} vs {:.1} mm", 1e3 * s, 1e3 * w))
            .collect::<Vec<_>>()
            .join("; ");
        metrics.push(Metric {
            name: format!("free-end {axis} displacement, largest error / peak measured"),
            value: d.worst_error(),
            unit: Unit::Percent,
            bound: (bounds == Mode::Full).then_some(Bound::Within(BOUND)),
            detail,
        });
        figures.push(Figure {
            name: format!("free_end_{axis}"),
            title: format!("{}: free end, {axis} displacement", sc.name),
            x_label: "t [s]".into(),
            y_label: format!("{axis} displacement [m]"),
            curves: vec![
                sim_curve("wgsph", d.sim),
                reference_curve("Antoci et al. (2007)", d.experiment),
            ],
        });
    }
    metrics.push(lost_particles(dir, false)?);
    Ok(Evaluation { metrics, figures })
}

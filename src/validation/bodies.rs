//! Rigid bodies: a floating box against Archimedes (`cases/floating_box_2d.toml`) and the water
//! entry of a free-falling cylinder against Greenhow & Lin (1983)
//! (`cases/water_entry_cylinder_2d.toml`).

use std::path::Path;

use anyhow::{anyhow, bail, Result};

use super::{
    body_series, gravity, lost_particles, probe_series, reference_curve, sim_curve, Bound,
    Evaluation, Figure, Metric, Mode, Reference, Unit, CASE_G,
};
use crate::plot::interpolate;
use crate::scenario::{Motion, ProbeKind, Scenario};

// ---- floating box ------------------------------------------------------------------------

/// The box of the case file: name, height [m] and density relative to the water's.
pub const BOX: &str = "box";
pub const BOX_HEIGHT_M: f64 = 0.1;
pub const BOX_DENSITY_RATIO: f64 = 0.5;
/// Bound of the relative error of the mean draft: quick, full.
pub const DRAFT_BOUND: (f64, f64) = (0.25, 0.02);

/// Archimedes: a box floats with the draft ρ_b/ρ0 · h.
pub fn archimedes_draft() -> f64 {
    BOX_DENSITY_RATIO * BOX_HEIGHT_M
}

/// Quick: dx = 0.02 m (the box 5 particles high), 2 s; full: dx = 0.01 m, 3 s. The draft is
/// averaged over the second half of the run, after the box has settled.
pub fn floating_box_overrides(mode: Mode) -> Option<Vec<String>> {
    Some(match mode {
        Mode::Quick => vec!["particles.dx_m=0.02".into(), "time.end_s=2".into()],
        Mode::Full => vec!["particles.dx_m=0.01".into(), "time.end_s=3".into()],
    })
}

/// The draft of the box over time.
#[derive(Clone, Debug)]
pub struct Draft {
    /// (t, still-water level − box bottom) at every probe time, m.
    pub series: Vec<(f64, f64)>,
    /// Its mean over t ≥ `from_s`.
    pub mean_m: f64,
    pub from_s: f64,
}

impl Draft {
    pub fn error(&self) -> f64 {
        self.mean_m / archimedes_draft() - 1.0
    }
}

/// The draft from the run in `dir`: the mean of the wave gauges (the still-water level) minus
/// the bottom of the box, averaged over the second half of the run.
pub fn draft(sc: &Scenario, dir: &Path) -> Result<Draft> {
    let gauges: Vec<Vec<(f64, f64)>> = sc
        .probes
        .iter()
        .filter(|p| matches!(p.kind, ProbeKind::Height { .. }))
        .map(|p| probe_series(dir, &p.name))
        .collect::<Result<_>>()?;
    if gauges.is_empty() {
        bail!("the case has no wave gauge");
    }
    let vertical = ["x_m", "y_m", "z_m"][sc.physics.dim as usize - 1];
    let center = body_series(dir, BOX, vertical)?;
    let series = center
        .iter()
        .enumerate()
        .map(|(k, &(t, c))| {
            let mut level = 0.0;
            for g in &gauges {
                match g.get(k) {
                    Some(&(tg, h)) if tg == t => level += h,
                    _ => bail!("the gauges and the body were not sampled at the same times"),
                }
            }
            Ok((t, level / gauges.len() as f64 - (c - 0.5 * BOX_HEIGHT_M)))
        })
        .collect::<Result<Vec<_>>>()?;
    let from_s = 0.5 * sc.time.end_s;
    let late: Vec<f64> = series
        .iter()
        .filter(|(t, _)| *t >= from_s - 1e-9)
        .map(|p| p.1)
        .collect();
    if late.is_empty() {
        bail!("no sample after t = {from_s} s");
    }
    Ok(Draft {
        mean_m: late.iter().sum::<f64>() / late.len() as f64,
        series,
        from_s,
    })
}

pub fn evaluate_floating_box(sc: &Scenario, dir: &Path, bounds: Mode) -> Result<Evaluation> {
    let d = draft(sc, dir)?;
    let bound = match bounds {
        Mode::Quick => DRAFT_BOUND.0,
        Mode::Full => DRAFT_BOUND.1,
    };
    let end = d.series.last().map_or(sc.time.end_s, |p| p.0);
    Ok(Evaluation {
        metrics: vec![
            Metric {
                name: format!("mean draft over t ≥ {} s vs ρ_b/ρ0 · h", d.from_s),
                value: d.error(),
                unit: Unit::Percent,
                bound: Some(Bound::Within(bound)),
                detail: format!(
                    "{:.4} m vs Archimedes {:.4} m (dx = {} m)",
                    d.mean_m,
                    archimedes_draft(),
                    sc.physics.dx
                ),
            },
            lost_particles(dir, false)?,
        ],
        figures: vec![Figure {
            name: "draft".into(),
            title: format!("{}: draft of the box", sc.name),
            x_label: "t [s]".into(),
            y_label: "draft [m]".into(),
            curves: vec![
                sim_curve("wgsph", d.series),
                reference_curve(
                    "Archimedes",
                    vec![(0.0, archimedes_draft()), (end, archimedes_draft())],
                ),
            ],
        }],
    })
}

// ---- water entry -------------------------------------------------------------------------

pub const ENTRY_CITATION: &str = "Greenhow & Lin (1983), MIT Dept. of Ocean Engineering \
     report, as compiled in Sun et al. (2018); digitised in dineshadepu/02_particles_dispersion";
pub const ENTRY_500: Reference = Reference {
    file: "tests/data/water_entry_cylinder_rho500_greenhow_lin.csv",
    text: include_str!("../../tests/data/water_entry_cylinder_rho500_greenhow_lin.csv"),
};
pub const ENTRY_1000: Reference = Reference {
    file: "tests/data/water_entry_cylinder_rho1000_greenhow_lin.csv",
    text: include_str!("../../tests/data/water_entry_cylinder_rho1000_greenhow_lin.csv"),
};
/// The cylinder of the case file: name and diameter [m].
pub const CYLINDER: &str = "cylinder";
pub const DIAMETER_M: f64 = 0.11;
/// Reference penetrations below this (the first contact point) have no relative error to speak
/// of and are skipped.
pub const MIN_PENETRATION: f64 = 0.1;
/// Bound of the largest relative error of the penetration: quick, full.
pub const PENETRATION_BOUND: (f64, f64) = (0.30, 0.10);

/// t* per second: sqrt(g/D).
fn t_scale(g: f64) -> f64 {
    (g / DIAMETER_M).sqrt()
}

/// Quick: dx = 0.01 m (D/11); full: dx = 0.005 m (D/22). Run to the reference's last time and
/// a little beyond, `density` the cylinder's.
fn water_entry_overrides(mode: Mode, density: &str, reference: &Reference) -> Vec<String> {
    let t_last = reference
        .points()
        .ok()
        .and_then(|p| p.last().map(|p| p.0))
        .unwrap_or(f64::NAN);
    let dx = match mode {
        Mode::Quick => "0.01",
        Mode::Full => "0.005",
    };
    vec![
        format!("particles.dx_m={dx}"),
        format!("body[0].density_kg_m3={density}"),
        format!("time.end_s={:.6}", t_last / t_scale(CASE_G) + 0.005),
    ]
}

/// ρ = 500 kg/m³: both modes.
pub fn water_entry_500_overrides(mode: Mode) -> Option<Vec<String>> {
    Some(water_entry_overrides(mode, "500", &ENTRY_500))
}

/// ρ = 1000 kg/m³: full mode only (not measured at the quick resolution).
pub fn water_entry_1000_overrides(mode: Mode) -> Option<Vec<String>> {
    (mode == Mode::Full).then(|| water_entry_overrides(mode, "1000", &ENTRY_1000))
}

/// The cylinder's penetration against the experiment.
#[derive(Clone, Debug)]
pub struct Penetration {
    /// (t*, (y0 − y_c)/D) of the run.
    pub sim: Vec<(f64, f64)>,
    /// (t*, penetration) of the experiment.
    pub experiment: Vec<(f64, f64)>,
    /// (t*, simulated, measured, relative error) at the experiment's times with a penetration of
    /// at least [`MIN_PENETRATION`].
    pub points: Vec<(f64, f64, f64, f64)>,
}

impl Penetration {
    /// The error of largest magnitude (with its sign).
    pub fn worst_error(&self) -> f64 {
        self.points
            .iter()
            .map(|p| p.3)
            .fold(0.0, |w, e| if e.abs() > w.abs() { e } else { w })
    }
}

/// Penetration (y0 − y_c)/D of the cylinder in the run in `dir` against `reference`, y0 the
/// centre's height at t = 0 (the first contact).
pub fn penetration(sc: &Scenario, dir: &Path, reference: &Reference) -> Result<Penetration> {
    let vertical_axis = sc.physics.dim as usize - 1;
    let y0 = sc
        .bodies
        .first()
        .ok_or_else(|| anyhow!("the case has no body"))?
        .center[vertical_axis];
    let ts = t_scale(gravity(sc));
    let column = ["x_m", "y_m", "z_m"][vertical_axis];
    let sim: Vec<(f64, f64)> = body_series(dir, CYLINDER, column)?
        .into_iter()
        .map(|(t, y)| (t * ts, (y0 - y) / DIAMETER_M))
        .collect();
    let experiment = reference.points()?;
    let points = experiment
        .iter()
        .filter(|p| p.1 >= MIN_PENETRATION)
        .map(|&(t, want)| {
            let got = interpolate(&sim, t)
                .ok_or_else(|| anyhow!("no finite body position at t* = {t}"))?;
            Ok((t, got, want, got / want - 1.0))
        })
        .collect::<Result<_>>()?;
    Ok(Penetration {
        sim,
        experiment,
        points,
    })
}

fn evaluate_water_entry(
    sc: &Scenario,
    dir: &Path,
    bounds: Mode,
    reference: &Reference,
) -> Result<Evaluation> {
    let p = penetration(sc, dir, reference)?;
    let bound = match bounds {
        Mode::Quick => PENETRATION_BOUND.0,
        Mode::Full => PENETRATION_BOUND.1,
    };
    let detail = p
        .points
        .iter()
        .map(|(t, s, w, e)| format!("t* {t:.3}: {s:.3} vs {w:.3} ({:+.1} %)", 100.0 * e))
        .collect::<Vec<_>>()
        .join("; ");
    // Free fall from the entry speed, the deepest any cylinder can be (the water only ever
    // pushes it up): drawn so that a reference point beyond it shows for what it is.
    let vertical = sc.physics.dim as usize - 1;
    let v0 = match sc.bodies.first().map(|b| &b.motion) {
        Some(Motion::Free { velocity, .. }) => -velocity[vertical],
        _ => f64::NAN,
    };
    let g = gravity(sc);
    let ts = t_scale(g);
    // Only as far as the comparison's own range, so as not to squash it.
    let t_end = p.sim.last().map_or(0.0, |q| q.0);
    let top = 1.1 * (p.sim.iter().chain(&p.experiment)).fold(0.0, |m, q| q.1.max(m));
    let free_fall: Vec<(f64, f64)> = (0..=60)
        .map(|k| t_end * k as f64 / 60.0)
        .map(|t_star| {
            let t = t_star / ts;
            (t_star, (v0 * t + 0.5 * g * t * t) / DIAMETER_M)
        })
        .take_while(|q| q.1 <= top)
        .collect();
    Ok(Evaluation {
        metrics: vec![
            Metric {
                name: "penetration (y0 − y)/D, largest error".into(),
                value: p.worst_error(),
                unit: Unit::Percent,
                bound: Some(Bound::Within(bound)),
                detail,
            },
            lost_particles(dir, false)?,
        ],
        figures: vec![Figure {
            name: "penetration".into(),
            title: format!("{}: penetration", sc.name),
            x_label: "t* = t·sqrt(g/D)".into(),
            y_label: "(y0 − y)/D".into(),
            curves: vec![
                sim_curve("wgsph", p.sim),
                sim_curve("free fall from the entry speed (no water)", free_fall),
                reference_curve("Greenhow & Lin (1983)", p.experiment),
            ],
        }],
    })
}

pub fn evaluate_water_entry_500(sc: &Scenario, dir: &Path, bounds: Mode) -> Result<Evaluation> {
    evaluate_water_entry(sc, dir, bounds, &ENTRY_500)
}

pub fn evaluate_water_entry_1000(sc: &Scenario, dir: &Path, bounds: Mode) -> Result<Evaluation> {
    evaluate_water_entry(sc, dir, bounds, &ENTRY_1000)
}

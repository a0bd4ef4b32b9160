//! 2D dam break of Lobovsky et al. (2014), H = 300 mm (`cases/dam_break_lobovsky_2d.toml`):
//! the pressure of sensor 1 (3 mm above the floor on the downstream wall) and sensor 3 (30 mm)
//! through the first impact, in the experiment's units p* = p/(ρgH) against t* = t·sqrt(g/H).
//! Sensor 1 is read by a particle-pressure probe; sensor 3 by one and by a wall-force sensor.

use std::path::Path;

use anyhow::{bail, Result};

use super::{
    gravity, lost_particles, probe_series, reference_curve, sim_curve, Bound, Evaluation, Figure,
    Metric, Mode, Reference, Unit, CASE_G,
};
use crate::plot::{compare, moving_average};
use crate::scenario::Scenario;

pub const REFERENCE: &str = "tests/data/db_lobovsky_2014_H300_sensor1_pressure.csv";
pub const CITATION: &str = "Lobovsky et al. (2014), J. Fluids Struct. 48:407–434, H = 300 mm, \
     sensor 1 (digitised by the PySPH authors)";
/// The reference data, embedded.
pub const DATA: Reference = Reference {
    file: REFERENCE,
    text: include_str!("../../tests/data/db_lobovsky_2014_H300_sensor1_pressure.csv"),
};

/// Sensor 3 (30 mm above the floor), the same curve's source.
pub const REFERENCE_SENSOR3: &str = "tests/data/db_lobovsky_2014_H300_sensor3_pressure.csv";
pub const DATA_SENSOR3: Reference = Reference {
    file: REFERENCE_SENSOR3,
    text: include_str!("../../tests/data/db_lobovsky_2014_H300_sensor3_pressure.csv"),
};
/// Sensor 3's particle probe and wall-force sensor (`kind = "wall_pressure"`). Sensor 1's
/// force sensor (`wall1`) is not compared: next to the floor the kernel puts part of its load
/// on the corner's particles, outside any sensor (docs/validation.md).
pub const PROBES_SENSOR3: [&str; 2] = ["sensor3", "wall3"];

/// Water column height H of the case file, m.
pub const H: f64 = 0.3;
/// The probe compared.
pub const PROBE: &str = "sensor1";
/// The run ends at t* = 3, after the first impact (t* ≈ 2.4).
pub const T_END: f64 = 3.0;
/// Threshold of p* that marks the first pressure rise (the impact of the surge front).
pub const RISE: f64 = 0.2;
/// Moving-average window of the simulated pressure, s. One SPH particle-scale probe carries
/// acoustic spikes (the water-hammer scale ρ·c0·u) that a sensor of finite size and the
/// digitised experimental curve do not show; peaks and RMS errors are given raw and averaged.
pub const SMOOTH_S: f64 = 0.005;
/// Bound of the relative error of the impact time: quick, full.
pub const IMPACT_BOUND: (f64, f64) = (0.10, 0.03);
/// Full mode: the averaged peak within 30 % of the experiment's. Quick mode asks only for a
/// factor 2 (a relative error in (−50 %, +100 %)).
pub const PEAK_BOUND_FULL: f64 = 0.30;

/// t* per second: sqrt(g/H).
fn t_scale(g: f64) -> f64 {
    (g / H).sqrt()
}

/// Heights of the four probes of the case file, m (moved with the wall's first particle layer
/// when dx changes: they sit half a spacing inside the water).
const PROBE_HEIGHTS_M: [f64; 4] = [0.003, 0.015, 0.03, 0.08];
/// x of the tank's right wall, m.
const RIGHT_WALL_M: f64 = 1.61;

/// Quick: the shipped dx = 0.01 m (H/dx = 30, 1,800 fluid particles); full: dx = 0.005 m
/// (H/dx = 60, 7,200), the probes moved to half the new spacing from the wall. Both to t* = 3,
/// particle outputs at the middle and the end only.
pub fn overrides(mode: Mode) -> Option<Vec<String>> {
    let end = T_END / t_scale(CASE_G);
    let mut set = vec![
        format!("time.end_s={end:.6}"),
        format!("time.output_every_s={:.6}", end / 2.0),
    ];
    if mode == Mode::Full {
        let dx = 0.005;
        set.push(format!("particles.dx_m={dx}"));
        for (k, z) in PROBE_HEIGHTS_M.iter().enumerate() {
            set.push(format!(
                "probe[{k}].point_m=[{:.4}, {z}]",
                RIGHT_WALL_M - 0.5 * dx
            ));
        }
    }
    Some(set)
}

/// A sensor against the experiment, dimensionless.
#[derive(Clone, Debug)]
pub struct Sensor {
    /// (t*, p*) of the run, raw and averaged over [`SMOOTH_S`].
    pub sim: Vec<(f64, f64)>,
    pub averaged: Vec<(f64, f64)>,
    /// (t*, p*) of the experiment, t* ≤ T_END.
    pub experiment: Vec<(f64, f64)>,
    /// First t* with p* ≥ [`RISE`]; NaN when the simulated pressure never rises.
    pub t_rise: f64,
    pub t_rise_experiment: f64,
    /// (t*, p*) of the largest p*: raw and averaged simulation, experiment.
    pub peak_raw: (f64, f64),
    pub peak: (f64, f64),
    pub peak_experiment: (f64, f64),
    /// RMS error of p* at the experiment's times, raw and averaged, and how many points.
    pub rms_raw: f64,
    pub rms: f64,
    pub points: usize,
    /// c0 / sqrt(gH) of the run.
    pub c0_star: f64,
}

impl Sensor {
    pub fn impact_error(&self) -> f64 {
        self.t_rise / self.t_rise_experiment - 1.0
    }

    pub fn peak_error(&self) -> f64 {
        self.peak.1 / self.peak_experiment.1 - 1.0
    }

    /// The sanity range of the raw peak: at least a stagnation pressure of the front, p* > 1
    /// (ρ(2 sqrt(gH))²/2 is p* = 2), and below the water-hammer scale of the weakly
    /// compressible fluid, ρ·c0·2 sqrt(gH), which is p* = 2 c0/sqrt(gH).
    pub fn raw_peak_range(&self) -> (f64, f64) {
        (1.0, 2.0 * self.c0_star)
    }
}

/// First t* where p* reaches [`RISE`].
fn first_rise(series: &[(f64, f64)]) -> Option<f64> {
    series.iter().find(|p| p.1 >= RISE).map(|p| p.0)
}

/// (t*, p*) of the largest finite p* with t* ≤ T_END.
fn peak(series: &[(f64, f64)]) -> (f64, f64) {
    series
        .iter()
        .filter(|p| p.0 <= T_END && p.1.is_finite())
        .fold((f64::NAN, f64::NEG_INFINITY), |a, p| {
            if p.1 > a.1 {
                *p
            } else {
                a
            }
        })
}

/// Compares the series of `probe` (`series`: t [s], p [Pa]) with the experiment's `reference`.
pub fn sensor(
    sc: &Scenario,
    probe: &str,
    reference: &Reference,
    series: &[(f64, f64)],
) -> Result<Sensor> {
    let g = gravity(sc);
    let (ts, ps) = (t_scale(g), sc.physics.rho0 * g * H);
    let sim: Vec<(f64, f64)> = series.iter().map(|&(t, p)| (t * ts, p / ps)).collect();
    if !sim.iter().all(|p| p.1.is_finite()) {
        bail!("non-finite pressure in {probe}");
    }
    let experiment: Vec<(f64, f64)> = reference
        .points()?
        .into_iter()
        .filter(|p| p.0 <= T_END)
        .collect();
    let averaged = moving_average(&sim, SMOOTH_S * ts);
    let (Some(raw), Some(avg)) = (compare(&sim, &experiment), compare(&averaged, &experiment))
    else {
        bail!("the run does not overlap the experiment's times");
    };
    Ok(Sensor {
        t_rise: first_rise(&sim).unwrap_or(f64::NAN),
        t_rise_experiment: first_rise(&experiment).unwrap_or(f64::NAN),
        peak_raw: peak(&sim),
        peak: peak(&averaged),
        peak_experiment: peak(&experiment),
        rms_raw: raw.rms_error,
        rms: avg.rms_error,
        points: avg.points,
        c0_star: sc.physics.c0 / (g * H).sqrt(),
        sim,
        averaged,
        experiment,
    })
}

/// Impact time, averaged peak and RMS rows of one sensor's comparison.
fn rows(probe: &str, s: &Sensor, impact_bound: f64, peak_bound: Bound) -> [Metric; 3] {
    let ms = 1e3 * SMOOTH_S;
    [
        Metric {
            name: format!("{probe}: impact time (first p* ≥ {RISE})"),
            value: s.impact_error(),
            unit: Unit::Percent,
            bound: Some(Bound::Within(impact_bound)),
            detail: format!(
                "t* = {:.3} vs experiment {:.3}",
                s.t_rise, s.t_rise_experiment
            ),
        },
        Metric {
            name: format!("{probe}: peak p*, {ms} ms moving average"),
            value: s.peak_error(),
            unit: Unit::Percent,
            bound: Some(peak_bound),
            detail: format!(
                "{:.3} at t* = {:.3} vs experiment {:.3} at {:.3}",
                s.peak.1, s.peak.0, s.peak_experiment.1, s.peak_experiment.0
            ),
        },
        Metric {
            name: format!("{probe}: RMS error of p*, {ms} ms moving average"),
            value: s.rms,
            unit: Unit::Number,
            bound: None,
            detail: format!(
                "at {} experimental times t* ≤ {T_END}; raw {:.3}",
                s.points, s.rms_raw
            ),
        },
    ]
}

pub fn evaluate(sc: &Scenario, dir: &Path, bounds: Mode) -> Result<Evaluation> {
    let s = sensor(sc, PROBE, &DATA, &probe_series(dir, PROBE)?)?;
    let ms = 1e3 * SMOOTH_S;
    let (impact_bound, peak_bound) = match bounds {
        Mode::Quick => (IMPACT_BOUND.0, Bound::Between(-0.5, 1.0)),
        Mode::Full => (IMPACT_BOUND.1, Bound::Within(PEAK_BOUND_FULL)),
    };
    let (lo, hi) = s.raw_peak_range();
    let [impact, peak, rms] = rows(PROBE, &s, impact_bound, peak_bound);
    let mut metrics = vec![
        lost_particles(dir, true)?,
        impact,
        Metric {
            name: format!("{PROBE}: raw peak p* (sanity range)"),
            value: s.peak_raw.1,
            unit: Unit::Number,
            bound: Some(Bound::Between(lo, hi)),
            detail: format!(
                "at t* = {:.3}; an acoustic spike of one SPH probe, between the front's \
                 stagnation pressure and the water-hammer scale 2 c0/sqrt(gH)",
                s.peak_raw.0
            ),
        },
        peak,
        rms,
    ];
    let mut figures = vec![Figure {
        name: PROBE.into(),
        title: format!("{}: {PROBE} ({ms} ms moving average)", sc.name),
        x_label: "t* = t·sqrt(g/H)".into(),
        y_label: "p* = p/(ρgH)".into(),
        curves: vec![
            sim_curve("wgsph", s.averaged),
            reference_curve("Lobovsky et al. (2014)", s.experiment),
        ],
    }];
    let mut curves = Vec::new();
    let mut experiment = Vec::new();
    for probe in PROBES_SENSOR3 {
        let s3 = sensor(sc, probe, &DATA_SENSOR3, &probe_series(dir, probe)?)?;
        metrics.extend(rows(probe, &s3, impact_bound, peak_bound));
        curves.push(sim_curve(&format!("wgsph, {probe}"), s3.averaged));
        experiment = s3.experiment;
    }
    curves.push(reference_curve(
        "Lobovsky et al. (2014), sensor 3",
        experiment,
    ));
    figures.push(Figure {
        name: "sensor3".into(),
        title: format!(
            "{}: sensor 3, probe and wall force ({ms} ms moving average)",
            sc.name
        ),
        x_label: "t* = t·sqrt(g/H)".into(),
        y_label: "p* = p/(ρgH)".into(),
        curves,
    });
    Ok(Evaluation { metrics, figures })
}

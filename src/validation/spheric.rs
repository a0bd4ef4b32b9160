//! 3D dam break with an obstacle, SPHERIC Test 2 (Kleefsman et al. 2005, the MARIN experiment;
//! `cases/dam_break_3d.toml`): pressures P1 and P3 on the box's face towards the water, P5 and
//! P7 on its top (particle probes; P1 and P5 also read by the wall-force sensors W1 and W5),
//! and water heights H1–H4 along the tank's middle, against the experiment over its 6 s
//! record (pressures averaged over the reference's 0.02 s sample spacing). Full mode only
//! (303 852 particles at the shipped dx = 0.55/34 m, a GPU's run). No row is judged yet: the
//! bounds wait for the first full run on a GPU (docs/validation.md).

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{anyhow, Result};

use super::{
    lost_particles, probe_series, reference_curve, sim_curve, Evaluation, Figure, Metric, Mode,
    Unit,
};
use crate::plot::{compare, moving_average, parse_table_column};
use crate::scenario::Scenario;

pub const REFERENCE: &str = "tests/data/spheric2_kleefsman_coarse_0p02s.csv";
pub const CITATION: &str = "Kleefsman et al. (2005), J. Comput. Phys. 206:363–393, SPHERIC \
     Test 2 (MARIN experiment), raw samples every 0.02 s";
const DATA: &str = include_str!("../../tests/data/spheric2_kleefsman_coarse_0p02s.csv");

/// Each probe of the case file compared, and its column in the reference: the particle probes,
/// and the wall-force sensors W1 and W5 on the box's faces at P1 and P5. W5 lies within 2h of
/// the front face, so its column of wall particles also takes that face's impact (a suction
/// along +z with no water on the top; docs/validation.md): read its row with that in mind.
pub const SERIES: [(&str, &str); 10] = [
    ("P1", "P1_Pa"),
    ("W1", "P1_Pa"),
    ("P3", "P3_Pa"),
    ("P5", "P5_Pa"),
    ("P7", "P7_Pa"),
    ("W5", "P5_Pa"),
    ("H1", "H1_geom_eq_xlsH3_m"),
    ("H2", "H2_m"),
    ("H3", "H3_geom_eq_xlsH1_m"),
    ("H4", "H4_m"),
];
/// The probes' sampling in full mode, s: the impact at P1 rises within one of the reference's
/// 0.02 s samples.
pub const PROBE_EVERY_S: f64 = 0.005;
/// The gauges the front passes before the box, whose bore arrival is timed.
pub const BORE_GAUGES: [&str; 2] = ["H3", "H2"];
/// The bore's arrival at a gauge: the first time the water there stands this high, m. The
/// experiment's front has a tip a few millimetres thick ahead of its bore, which runs at
/// dx ≈ 0.02 m do not resolve (docs/validation.md): 2.5–3 spacings up, the bore is timed
/// rather than the tip.
pub const BORE_LEVEL_M: f64 = 0.05;
/// Moving-average window of the simulated pressures, s: the reference's sample spacing. With
/// c0 = 10 √(gH) ≈ 23 m/s the impact rings at the artificial sound's period over the front's
/// thickness (≈ 4 · 0.15 m / c0 ≈ 25 ms), spikes a real sensor in water (c ≈ 1 500 m/s) never
/// sees and 0.02 s raw samples would catch only by chance. Impact times use the raw series.
pub const SMOOTH_S: f64 = 0.02;
/// The impact at P1 (probe and wall sensor): the first time the pressure reaches this share of
/// the experiment's peak.
pub const IMPACT_SHARE: f64 = 0.1;

/// Full mode: the shipped case, probes every [`PROBE_EVERY_S`]. Quick mode does not run it.
pub fn overrides(mode: Mode) -> Option<Vec<String>> {
    (mode == Mode::Full).then(|| vec![format!("time.probe_every_s={PROBE_EVERY_S}")])
}

/// The experiment's series `column` (t [s], value).
pub fn experiment(column: &str) -> Result<Vec<(f64, f64)>> {
    Ok(parse_table_column(DATA, REFERENCE, column)?.points)
}

/// The first time `series` reaches `level`.
fn arrival(series: &[(f64, f64)], level: f64) -> Option<f64> {
    series.iter().find(|p| p.1 >= level).map(|p| p.0)
}

/// (t, value) of the largest value of `series`.
fn peak(series: &[(f64, f64)]) -> (f64, f64) {
    series
        .iter()
        .filter(|p| p.1.is_finite())
        .fold((f64::NAN, f64::NEG_INFINITY), |a, p| {
            if p.1 > a.1 {
                *p
            } else {
                a
            }
        })
}

pub fn evaluate(sc: &Scenario, dir: &Path, _bounds: Mode) -> Result<Evaluation> {
    let mut metrics = vec![lost_particles(dir, false)?];
    let mut figures = Vec::new();
    for (probe, column) in SERIES {
        let sim = probe_series(dir, probe)?;
        let exp = experiment(column)?;
        let pressure = column.ends_with("_Pa");
        let (unit, what) = if pressure {
            ("Pa", "pressure")
        } else {
            ("m", "water height")
        };
        let shown = if pressure {
            moving_average(&sim, SMOOTH_S)
        } else {
            sim.clone()
        };
        let overlap = |s: &[(f64, f64)]| {
            compare(s, &exp)
                .ok_or_else(|| anyhow!("{probe}: the run does not overlap the experiment's times"))
        };
        let e = overlap(&shown)?;
        let scale = exp.iter().map(|p| p.1.abs()).fold(0.0, f64::max);
        let (ps, pe) = (peak(&shown), peak(&exp));
        let mut detail = format!(
            "at {} experimental times in [{:.2}, {:.2}] s; peak {:.4} {unit} at {:.3} s vs \
             experiment {:.4} {unit} at {:.3} s",
            e.points, e.t_start_s, e.t_end_s, ps.1, ps.0, pe.1, pe.0
        );
        let averaged = if pressure {
            let (raw, raw_peak) = (overlap(&sim)?, peak(&sim));
            let _ = write!(
                detail,
                "; raw: {:.1} %, peak {:.4} {unit} at {:.3} s",
                100.0 * raw.rms_error / scale,
                raw_peak.1,
                raw_peak.0
            );
            format!(", {:.0} ms moving average", 1e3 * SMOOTH_S)
        } else {
            String::new()
        };
        metrics.push(Metric {
            name: format!("{probe}: RMS difference{averaged} / the experiment's largest value"),
            value: e.rms_error / scale,
            unit: Unit::Percent,
            bound: None,
            detail,
        });
        let timed = if column == "P1_Pa" {
            let level = IMPACT_SHARE * pe.1;
            let name = format!(
                "{probe}: impact time (first p ≥ {:.0} % of P1's measured peak)",
                100.0 * IMPACT_SHARE
            );
            Some((name, level, format!("{level:.0} Pa")))
        } else if BORE_GAUGES.contains(&probe) {
            let name = format!("{probe}: bore arrival (first height ≥ {BORE_LEVEL_M} m)");
            Some((name, BORE_LEVEL_M, format!("{BORE_LEVEL_M} m")))
        } else {
            None
        };
        if let Some((name, level, reached)) = timed {
            let (ts, te) = (arrival(&sim, level), arrival(&exp, level));
            metrics.push(Metric {
                name,
                value: ts.zip(te).map_or(f64::NAN, |(s, e)| s / e - 1.0),
                unit: Unit::Percent,
                bound: None,
                detail: format!(
                    "{reached} reached at {} s vs experiment {} s (its samples are 0.02 s apart)",
                    ts.map_or("never".into(), |t| format!("{t:.3}")),
                    te.map_or("never".into(), |t| format!("{t:.3}"))
                ),
            });
        }
        figures.push(Figure {
            name: probe.into(),
            title: format!(
                "{}: {what} {probe}{averaged} (measured: {})",
                sc.name,
                &column[..2]
            ),
            x_label: "t [s]".into(),
            y_label: format!("{what} [{unit}]"),
            curves: vec![
                sim_curve("wgsph", shown),
                reference_curve("Kleefsman et al. (2005)", exp),
            ],
        });
    }
    Ok(Evaluation { metrics, figures })
}

//! The dam break against an isolated building of Soares-Frazão & Zech (2007,
//! `cases/sfz_building_3d.toml`): the water depth at the six gauges G1–G6 against the
//! experiment's records (every 0.01 s), as the front's arrival, the whole record and the mean
//! over the quasi-steady window. Full mode only, at dx = 0.04 m (a GPU's run); every row is
//! reported, none judged yet: the bounds are to be set from the first GPU runs at two
//! resolutions (issue 60, docs/validation.md "Urban dam break").

use anyhow::{anyhow, Result};

use super::{
    arrival, mean, probe_series, reference_curve, sim_curve, within, Evaluation, Figure, Metric,
    Mode, Unit,
};
use crate::plot::{compare, parse_csv};
use crate::scenario::Scenario;

pub const REFERENCE: &str = "tests/data/sfz_2007_building_G{1..6}_depth.csv";
pub const CITATION: &str = "Soares-Frazão & Zech (2007), J. Hydraul. Res. 45 (sup1), 27–36: \
     measured depths at G1–G6 every 0.01 s (the data set distributed with the paper)";

/// Each gauge of the case file and its record.
const GAUGES: [(&str, &str); 6] = [
    (
        "G1",
        include_str!("../../tests/data/sfz_2007_building_G1_depth.csv"),
    ),
    (
        "G2",
        include_str!("../../tests/data/sfz_2007_building_G2_depth.csv"),
    ),
    (
        "G3",
        include_str!("../../tests/data/sfz_2007_building_G3_depth.csv"),
    ),
    (
        "G4",
        include_str!("../../tests/data/sfz_2007_building_G4_depth.csv"),
    ),
    (
        "G5",
        include_str!("../../tests/data/sfz_2007_building_G5_depth.csv"),
    ),
    (
        "G6",
        include_str!("../../tests/data/sfz_2007_building_G6_depth.csv"),
    ),
];

/// The front's arrival at a gauge downstream: the first time the water there stands this deep,
/// m. The records read 0 before the front (their wet bed of 0.02 m does not show) and jump to
/// 0.02 m or more as it passes.
pub const ARRIVAL_DEPTH_M: f64 = 0.015;
/// The flow around the building is about steady over this window (the measured depths at
/// G1 and G3–G5 vary by about 10 %; the wave reflected from the flume's end reaches G2 at 14 s).
pub const STEADY_WINDOW_S: (f64, f64) = (10.0, 13.0);
/// Full mode: dx = 0.04 m (the reservoir ten particles deep; the wet bed, half a spacing, left
/// dry: its front runs ahead of the experiment's on a wet bed), to the end of the steady window.
pub const FULL_DX_M: f64 = 0.04;
/// The flume cut at x = 12 m, its outlet there: the flow leaves freely, as it does over the
/// rest of the 28 m channel within the record's first 13 s, for a run of about half the
/// particles.
pub const TRUNCATED: [&str; 3] = [
    "tank.max_m=[12.0, 1.8, 0.8]",
    "outlet[0].min_m=[11.7, -1.8, -0.1]",
    "outlet[0].max_m=[12.0, 1.8, 0.8]",
];

pub fn overrides(mode: Mode) -> Option<Vec<String>> {
    (mode == Mode::Full).then(|| {
        let mut set = vec![
            format!("particles.dx_m={FULL_DX_M}"),
            format!("time.end_s={}", STEADY_WINDOW_S.1),
            "time.probe_every_s=0.02".into(),
        ];
        set.extend(TRUNCATED.map(String::from));
        set
    })
}

/// The record of gauge `name` (t [s], depth [m]).
pub fn experiment(name: &str) -> Result<Vec<(f64, f64)>> {
    let (_, text) = (GAUGES.iter())
        .find(|(g, _)| *g == name)
        .ok_or_else(|| anyhow!("no gauge {name}"))?;
    Ok(parse_csv(text, &REFERENCE.replace("{1..6}", &name[1..]))?.points)
}

fn row(gauge: &str, name: &str, value: f64, unit: Unit, detail: String) -> Metric {
    Metric {
        name: format!("{gauge}: {name}"),
        value,
        unit,
        bound: None,
        detail,
    }
}

/// The rows of one gauge: the front's arrival (downstream gauges), the RMS difference over the
/// record, and the mean over [`STEADY_WINDOW_S`].
fn gauge_rows(gauge: &str, sim: &[(f64, f64)], exp: &[(f64, f64)]) -> Result<Vec<Metric>> {
    let mut rows = Vec::new();
    if gauge != "G6" {
        let (ts, te) = (arrival(sim, ARRIVAL_DEPTH_M), arrival(exp, ARRIVAL_DEPTH_M));
        let show = |t: Option<f64>| t.map_or("never".into(), |t| format!("{t:.2} s"));
        rows.push(row(
            gauge,
            &format!("arrival (first depth ≥ {ARRIVAL_DEPTH_M} m) − measured, s"),
            ts.zip(te).map_or(f64::NAN, |(s, e)| s - e),
            Unit::Number,
            format!("{} vs measured {}", show(ts), show(te)),
        ));
    }
    let e = compare(sim, exp).ok_or_else(|| anyhow!("{gauge}: the run misses the record"))?;
    let scale = exp.iter().map(|p| p.1).fold(0.0, f64::max);
    rows.push(row(
        gauge,
        "RMS difference / the record's largest depth",
        e.rms_error / scale,
        Unit::Percent,
        format!(
            "over [{:.2}, {:.2}] s, {} samples; largest measured depth {scale:.3} m",
            e.t_start_s, e.t_end_s, e.points
        ),
    ));
    let (ms, me) = (
        mean(&within(sim, STEADY_WINDOW_S)),
        mean(&within(exp, STEADY_WINDOW_S)),
    );
    rows.push(row(
        gauge,
        &format!(
            "mean depth over [{}, {}] s, relative",
            STEADY_WINDOW_S.0, STEADY_WINDOW_S.1
        ),
        ms / me - 1.0,
        Unit::Percent,
        format!("{ms:.4} m vs measured {me:.4} m"),
    ));
    Ok(rows)
}

pub fn evaluate(sc: &Scenario, dir: &std::path::Path, _mode: Mode) -> Result<Evaluation> {
    let mut out = Evaluation::default();
    for (gauge, _) in GAUGES {
        let (sim, exp) = (probe_series(dir, gauge)?, experiment(gauge)?);
        out.metrics.extend(gauge_rows(gauge, &sim, &exp)?);
        out.figures.push(Figure {
            name: gauge.into(),
            title: format!("{}: water depth at {gauge}", sc.name),
            x_label: "t [s]".into(),
            y_label: "depth [m]".into(),
            curves: vec![
                sim_curve("wgsph", sim),
                reference_curve("Soares-Frazão & Zech (2007)", exp),
            ],
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The records parse, start as the experiment did (the reservoir 0.4 m deep at G6, the
    /// channel dry) and the front reaches G2 first, at 0.85 s (the paper's Fig. 9).
    #[test]
    fn the_records_read_as_the_experiment_ran() {
        let first: Vec<f64> = (GAUGES.iter())
            .map(|(g, _)| arrival(&experiment(g).unwrap(), ARRIVAL_DEPTH_M).unwrap())
            .collect();
        assert_eq!(first[1], 0.85);
        assert!(
            first[..5].iter().all(|t| (0.85..3.0).contains(t)),
            "{first:?}"
        );
        assert_eq!(experiment("G6").unwrap()[0], (0.0, 0.4));
        for (g, _) in GAUGES {
            let e = experiment(g).unwrap();
            assert_eq!(e.len(), 3001, "{g}");
            assert_eq!(e.last().unwrap().0, 30.0);
        }
    }

    /// A run equal to the record differs by nothing, arrives on time; one 10 % deeper reads
    /// +10 % over the steady window.
    #[test]
    fn a_perfect_run_scores_zero() {
        let exp = experiment("G3").unwrap();
        let rows = gauge_rows("G3", &exp, &exp).unwrap();
        assert!(rows.iter().all(|m| m.value.abs() < 1e-12), "{rows:?}");
        let deeper: Vec<(f64, f64)> = exp.iter().map(|&(t, d)| (t, 1.1 * d)).collect();
        let rows = gauge_rows("G3", &deeper, &exp).unwrap();
        assert!((rows[2].value - 0.1).abs() < 1e-9, "{rows:?}");
    }
}

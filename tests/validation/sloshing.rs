//! Sloshing in a pitching tank against Akyildiz & Unal (2006), Fig. 5 (layer 3): pressure at
//! transducers 2 and 8, probes attached to the tank's end walls (`cases/sloshing_2d.toml`).
//!
//! The experiment's transducer 2 reads about 0.3 kPa above the hydrostatic pressure at its
//! stated height over the whole record (its mean is 3.2 kPa; ρ g (0.465 − 0.17) = 2.89 kPa), and
//! transducer 8 never reads below 0.24 kPa although it is 15 mm under the still surface and
//! the tank lifts it by up to 32 mm. So the comparison is made on the fluctuation (each series
//! minus its own mean over the compared samples: amplitude and phase), and the offset is
//! reported. The simulated mean of transducer 2 is checked against the hydrostatic value.

use std::path::Path;

use wgsph::plot::{interpolate, read_csv};
use wgsph::progress::LogLines;
use wgsph::run::RunOptions;

/// Comparison of one transducer over the experiment's samples in [from, to].
struct Comparison {
    samples: usize,
    /// Mean of simulated minus measured [kPa].
    offset_kpa: f64,
    /// RMS of the difference of the fluctuations, over the RMS of the measured fluctuation.
    fluctuation_error: f64,
    /// Mean of the simulated series at the samples [kPa].
    sim_mean_kpa: f64,
}

fn compare(dir: &Path, probe: &str, transducer: u32, from: f64, to: f64) -> Comparison {
    let exp = read_csv(&Path::new("tests/data").join(format!(
        "sloshing_akyildiz_unal_2006_pitch_probe{transducer}.csv"
    )))
    .unwrap()
    .points;
    let sim = read_csv(&dir.join("probes").join(format!("{probe}.csv")))
        .unwrap()
        .points;
    let pairs: Vec<(f64, f64)> = exp
        .iter()
        .filter(|(t, _)| (from..=to).contains(t))
        .map(|&(t, p)| (interpolate(&sim, t).expect("simulated sample") / 1000.0, p))
        .collect();
    let n = pairs.len() as f64;
    let mean_sim = pairs.iter().map(|p| p.0).sum::<f64>() / n;
    let mean_exp = pairs.iter().map(|p| p.1).sum::<f64>() / n;
    let diff2: f64 = pairs
        .iter()
        .map(|(s, e)| ((s - mean_sim) - (e - mean_exp)).powi(2))
        .sum();
    let exp2: f64 = pairs.iter().map(|(_, e)| (e - mean_exp).powi(2)).sum();
    Comparison {
        samples: pairs.len(),
        offset_kpa: mean_sim - mean_exp,
        fluctuation_error: (diff2 / exp2).sqrt(),
        sim_mean_kpa: mean_sim,
    }
}

fn run(case: &str, dx: &str, end: f64, tag: &str) -> crate::common::Scratch {
    let set = vec![
        format!("particles.dx_m={dx}"),
        format!("time.end_s={end}"),
        "time.output_every_s=1".to_string(),
    ];
    let sc = wgsph::case::load(Path::new(case), &set).unwrap();
    let dir = crate::common::Scratch::new(&format!("sloshing-{tag}"));
    let report = wgsph::run::run(
        crate::common::gpu(),
        &sc,
        &dir,
        &RunOptions::default(),
        &mut LogLines::default(),
    )
    .unwrap();
    assert!(report.stopped.is_none(), "{}", report.summary.status);
    dir
}

fn report(dir: &Path, from: f64, to: f64) -> (Comparison, Comparison) {
    let p2 = compare(dir, "p2", 2, from, to);
    let p8 = compare(dir, "p8", 8, from, to);
    for (name, c) in [("transducer 2", &p2), ("transducer 8", &p8)] {
        println!(
            "{name}, t in [{from}, {to}] s, {} samples: fluctuation error {:.1} % of the \
             measured fluctuation, offset {:+.3} kPa, simulated mean {:.3} kPa",
            c.samples,
            100.0 * c.fluctuation_error,
            c.offset_kpa,
            c.sim_mean_kpa
        );
    }
    (p2, p8)
}

/// Bound on transducer 2's fluctuation error at dx = 0.02 over the first period (measured
/// 25.3 % on lavapipe; docs/validation.md).
const BOUND_COARSE: f64 = 0.35;

/// Hydrostatic pressure at transducer 2 under the still surface [kPa].
const P2_HYDROSTATIC_KPA: f64 = 9.81 * (0.465 - 0.17);

#[test]
fn sloshing_transducer_2_follows_the_experiment_coarse() {
    let dir = run("cases/sloshing_2d.toml", "0.02", 3.2, "coarse");
    // The first pitch period (t < π s) without the first half second of start-up.
    let (p2, _) = report(&dir, 0.5, 3.2);
    assert!(p2.samples >= 7);
    assert!(
        p2.fluctuation_error < BOUND_COARSE,
        "transducer 2: fluctuation error {:.1} %",
        100.0 * p2.fluctuation_error
    );
    assert!(
        (p2.sim_mean_kpa - P2_HYDROSTATIC_KPA).abs() < 0.05 * P2_HYDROSTATIC_KPA,
        "mean {:.3} kPa vs hydrostatic {P2_HYDROSTATIC_KPA:.3} kPa",
        p2.sim_mean_kpa
    );
}

#[test]
#[ignore = "10 s of sloshing at dx = 0.01: 86 635 steps, about 45 min on lavapipe; passes (measured 19.1 % and 18.1 %, docs/validation.md)"]
fn sloshing_transducers_follow_the_experiment_fine() {
    let dir = run("cases/sloshing_2d.toml", "0.01", 10.0, "fine");
    // As in the PySPH comparison of this case: after the start-up, t in [3, 10] s.
    let (p2, p8) = report(&dir, 3.0, 10.0);
    assert!(p2.fluctuation_error < 0.3, "transducer 2");
    assert!(p8.fluctuation_error < 0.5, "transducer 8");
}

/// The experiment's own geometry, 3D (`cases/sloshing_3d.toml`), at its shipped dx = 0.02 m,
/// judged as the fine 2D run.
#[test]
#[ignore = "not run yet: 10 s of the 3D tank at dx = 0.02 m (43 000 particles) is about 8 h on lavapipe, a GPU job; at dx = 0.04 transducer 2 is 16.1 % off, 8 35.9 % (docs/validation.md)"]
fn sloshing_3d_transducers_follow_the_experiment() {
    let dir = run("cases/sloshing_3d.toml", "0.02", 10.0, "3d");
    let (p2, p8) = report(&dir, 3.0, 10.0);
    assert!(p2.fluctuation_error < 0.3, "transducer 2");
    assert!(p8.fluctuation_error < 0.5, "transducer 8");
}

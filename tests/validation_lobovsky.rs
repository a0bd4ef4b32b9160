//! Layer 3: the 2D dam break of Lobovsky et al. (2014), H = 300 mm, against the measured
//! pressure of sensor 1 (3 mm above the floor on the downstream wall), in the experiment's
//! units: p/(ρgH) against t·sqrt(g/H). `cases/dam_break_lobovsky_2d.toml` at its shipped
//! resolution (dx = 0.01 m, H/dx = 30) is run through the first impact (t·sqrt(g/H) ≤ 3), then
//! `wgsph plot` draws it over the experiment. Numbers are printed and recorded in
//! docs/validation.md.

mod common;
use common::gpu;
use std::path::{Path, PathBuf};
use std::process::Command;

use wgsph::plot::{compare, moving_average, read_csv};

const H: f64 = 0.3;
const G: f64 = 9.81;
const RHO: f64 = 1000.0;
const REFERENCE: &str = "tests/data/db_lobovsky_2014_H300_sensor1_pressure.csv";
/// Threshold of p/(ρgH) that marks the first pressure rise (the impact of the surge front).
const RISE: f64 = 0.2;
/// Moving-average window of the simulated pressure, s. One SPH particle-scale probe carries
/// acoustic spikes (the water-hammer scale ρ·c0·u) that a sensor of finite size and the
/// digitised experimental curve do not show; peaks and RMS errors are given raw and averaged.
const SMOOTH_S: f64 = 0.005;

fn t_scale() -> f64 {
    (G / H).sqrt()
}

/// First t* where p* reaches `RISE`.
fn first_rise(series: &[(f64, f64)]) -> Option<f64> {
    series.iter().find(|p| p.1 >= RISE).map(|p| p.0)
}

/// (t*, p*) of the largest p* with t* ≤ t_end.
fn peak(series: &[(f64, f64)], t_end: f64) -> (f64, f64) {
    series
        .iter()
        .filter(|p| p.0 <= t_end && p.1.is_finite())
        .fold((f64::NAN, f64::NEG_INFINITY), |a, p| {
            if p.1 > a.1 {
                *p
            } else {
                a
            }
        })
}

struct Outcome {
    dir: PathBuf,
    t_rise: f64,
    t_rise_exp: f64,
    /// Raw and averaged (SMOOTH_S) simulation peaks (t*, p*).
    peak_raw: (f64, f64),
    peak: (f64, f64),
    peak_exp: (f64, f64),
    /// RMS error of p*, raw and averaged.
    rms_raw: f64,
    rms: f64,
    /// c0 / sqrt(gH) of the run.
    c0_star: f64,
}

/// Runs the case up to t* = t_end (in units of sqrt(H/g)) and compares sensor 1.
fn run_to(t_end: f64, tag: &str, set: &[&str]) -> Outcome {
    let mut set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    let end_s = t_end / t_scale();
    set.push(format!("time.end_s={end_s}"));
    set.push(format!("time.output_every_s={}", end_s / 2.0));
    let sc = wgsph::case::load(Path::new("cases/dam_break_lobovsky_2d.toml"), &set).unwrap();
    let dir = std::env::temp_dir().join(format!("wgsph-lobovsky-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let report = wgsph::run::run(
        gpu(),
        &sc,
        &dir,
        &Default::default(),
        &mut wgsph::progress::LogLines::default(),
    )
    .unwrap();
    assert!(report.stopped.is_none(), "{}", report.summary.status);
    assert_eq!(report.summary.particles_excluded, 0);

    let sim: Vec<(f64, f64)> = read_csv(&dir.join("probes/sensor1.csv"))
        .unwrap()
        .points
        .iter()
        .map(|&(t, p)| (t * t_scale(), p / (RHO * G * H)))
        .collect();
    assert!(sim.iter().all(|p| p.1.is_finite()), "non-finite pressure");
    let exp: Vec<(f64, f64)> = read_csv(Path::new(REFERENCE))
        .unwrap()
        .points
        .into_iter()
        .filter(|p| p.0 <= t_end)
        .collect();
    let avg = moving_average(&sim, SMOOTH_S * t_scale());
    let err_raw = compare(&sim, &exp).expect("overlapping time ranges");
    let err = compare(&avg, &exp).unwrap();
    let out = Outcome {
        dir,
        t_rise: first_rise(&sim).expect("no impact on the wall"),
        t_rise_exp: first_rise(&exp).unwrap(),
        peak_raw: peak(&sim, t_end),
        peak: peak(&avg, t_end),
        peak_exp: peak(&exp, t_end),
        rms_raw: err_raw.rms_error,
        rms: err.rms_error,
        c0_star: sc.physics.c0 / (G * H).sqrt(),
    };
    println!(
        "Lobovsky sensor1 (p* = p/(rho g H), t* = t sqrt(g/H)), t* <= {t_end}: first rise (p* >= {RISE}) \
         at t* = {:.3} (experiment {:.3}, {:+.1} %); peak p* = {:.3} at t* = {:.3} raw, {:.3} at {:.3} \
         averaged over {} ms (experiment {:.3} at {:.3}); RMS error of p* over {} experimental points \
         in [{:.3}, {:.3}]: {:.3} raw, {:.3} averaged",
        out.t_rise,
        out.t_rise_exp,
        100.0 * (out.t_rise / out.t_rise_exp - 1.0),
        out.peak_raw.1,
        out.peak_raw.0,
        out.peak.1,
        out.peak.0,
        1e3 * SMOOTH_S,
        out.peak_exp.1,
        out.peak_exp.0,
        err.points,
        err.t_start_s,
        err.t_end_s,
        out.rms_raw,
        out.rms
    );
    out
}

#[test]
fn lobovsky_sensor1_first_impact_matches_experiment() {
    let o = run_to(3.0, "impact", &[]);
    // Impact time: the surge front's arrival, set by the dam-break front speed; within 10 %.
    let rel = (o.t_rise / o.t_rise_exp - 1.0).abs();
    assert!(
        rel < 0.10,
        "first pressure rise at t* = {:.3}, experiment {:.3}",
        o.t_rise,
        o.t_rise_exp
    );
    // The raw peak of one SPH probe at H/dx = 30 is an acoustic spike: only a sanity range.
    // At least a stagnation pressure of the front, p* > 1 (ρ(2 sqrt(gH))²/2 is p* = 2), and
    // below the water-hammer scale of the weakly compressible fluid, ρ·c0·2 sqrt(gH), which is
    // p* = 2 c0/sqrt(gH) (= 40 with sound_speed_coef = 20).
    assert!(
        o.peak_raw.1 > 1.0 && o.peak_raw.1 < 2.0 * o.c0_star,
        "raw peak p* = {:.3} outside [1, {:.1}]",
        o.peak_raw.1,
        2.0 * o.c0_star
    );
    // Averaged over 5 ms, the peak is within a factor 2 of the experiment's (2.84).
    let ratio = o.peak.1 / o.peak_exp.1;
    assert!(
        ratio > 0.5 && ratio < 2.0,
        "averaged peak p* = {:.3}, experiment {:.3}",
        o.peak.1,
        o.peak_exp.1
    );

    // `wgsph plot` with the experiment overlaid in SI units.
    let refarg = format!("sensor1={REFERENCE}:{}:{}", 1.0 / t_scale(), RHO * G * H);
    let out = Command::new(env!("CARGO_BIN_EXE_wgsph"))
        .arg("plot")
        .arg(&o.dir)
        .args(["--reference", &refarg, "--smooth", &SMOOTH_S.to_string()])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    print!("{stdout}");
    for probe in ["sensor1", "sensor2", "sensor3", "sensor4"] {
        let png = std::fs::read(o.dir.join(format!("plots/{probe}.png"))).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    }
    let errors = std::fs::read_to_string(o.dir.join("plots/errors.csv")).unwrap();
    assert_eq!(errors.lines().count(), 2, "{errors}");
    // The RMS error in errors.csv (averaged simulation) is in pascals: p* times ρgH.
    let rms_pa: f64 = errors
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .nth(7)
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        (rms_pa / (RHO * G * H) / o.rms - 1.0).abs() < 1e-4,
        "{errors}"
    );
    let _ = std::fs::remove_dir_all(&o.dir);
}

/// Stricter comparison, not met at the shipped resolution (dx = 0.01 m, H/dx = 30): impact
/// time within 3 % and the averaged peak within 30 % of the experiment. Measured: see
/// docs/validation.md (impact +5.0 %, averaged peak +29.8 %, just inside). Kept visible rather
/// than loosened; run with `cargo test --release --test validation_lobovsky -- --ignored --nocapture`.
#[test]
#[ignore = "not met at dx = 0.01 m: impact +5.0 % (docs/validation.md)"]
fn lobovsky_sensor1_impact_within_3_percent_and_peak_within_30_percent() {
    let o = run_to(3.0, "strict", &[]);
    let _ = std::fs::remove_dir_all(&o.dir);
    assert!(
        (o.t_rise / o.t_rise_exp - 1.0).abs() < 0.03,
        "impact at t* = {:.3}, experiment {:.3}",
        o.t_rise,
        o.t_rise_exp
    );
    assert!(
        (o.peak.1 / o.peak_exp.1 - 1.0).abs() < 0.3,
        "averaged peak p* = {:.3}, experiment {:.3}",
        o.peak.1,
        o.peak_exp.1
    );
}

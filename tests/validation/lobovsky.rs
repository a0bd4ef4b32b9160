//! Layer 3: the 2D dam break of Lobovsky et al. (2014), H = 300 mm, against the measured
//! pressure of sensors 1 and 3 (3 and 30 mm above the floor on the downstream wall), in the experiment's
//! units: p/(ρgH) against t·sqrt(g/H). `cases/dam_break_lobovsky_2d.toml` at its shipped
//! resolution (dx = 0.01 m, H/dx = 30) is run through the first impact (t·sqrt(g/H) ≤ 3), then
//! `wgsph plot` draws it over the experiment. The comparison is `wgsph validate`'s
//! (`validation::lobovsky`); numbers are printed and recorded in docs/validation.md.

use std::process::Command;

use wgsph::validation::{lobovsky, probe_series, CaseOutcome, Mode};

/// The case at its shipped resolution to t* = 3, judged with the bounds of `bounds`.
fn run(tag: &str, bounds: Mode) -> (CaseOutcome, crate::common::Scratch) {
    crate::common::validate_case("dam_break_lobovsky_2d", Mode::Quick, bounds, tag)
}

/// Impact time within 10 %, the raw peak between the front's stagnation pressure and the
/// water-hammer scale, the 5 ms averaged peak within a factor 2 of the experiment's, no
/// particle lost (`validation::lobovsky`, quick bounds); sensor 3's impact time and averaged
/// peak to the same bounds, from its particle probe and from its wall-force sensor.
#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 3 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn lobovsky_sensor1_first_impact_matches_experiment() {
    let (o, _dir) = run("impact", Mode::Quick);
    assert!(o.passed(), "{}", crate::common::rows(&o));

    // `wgsph plot` with the experiment overlaid in SI units.
    let case = wgsph::validation::find("dam_break_lobovsky_2d").unwrap();
    let sc = case.scenario(&o.overrides).unwrap();
    let series = probe_series(&o.dir, lobovsky::PROBE).unwrap();
    let s = lobovsky::sensor(&sc, lobovsky::PROBE, &lobovsky::DATA, &series).unwrap();
    let (g, rho) = (9.81, sc.physics.rho0);
    let refarg = format!(
        "sensor1={}:{}:{}",
        lobovsky::REFERENCE,
        (lobovsky::H / g).sqrt(),
        rho * g * lobovsky::H
    );
    let out = Command::new(env!("CARGO_BIN_EXE_wgsph"))
        .arg("plot")
        .arg(&o.dir)
        .args([
            "--reference",
            &refarg,
            "--smooth",
            &lobovsky::SMOOTH_S.to_string(),
        ])
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
        (rms_pa / (rho * g * lobovsky::H) / s.rms - 1.0).abs() < 1e-4,
        "{errors}"
    );
}

/// Stricter comparison, not met at the shipped resolution (dx = 0.01 m, H/dx = 30): impact
/// time within 3 % and the averaged peak within 30 % of the experiment (the full mode's bounds).
/// Measured: see docs/validation.md (impact +5.0 %, averaged peak +29.8 %, just inside). Kept
/// visible rather than loosened; run with
/// `cargo test --release --test all validation::lobovsky -- --ignored --nocapture`.
#[test]
#[ignore = "not met at dx = 0.01 m: impact +5.0 % (docs/validation.md)"]
fn lobovsky_sensor1_impact_within_3_percent_and_peak_within_30_percent() {
    let (o, _dir) = run("strict", Mode::Full);
    assert!(o.passed(), "{}", crate::common::rows(&o));
}

/// The same bounds at the full mode's resolution, dx = 0.005 m (H/dx = 60, the probes half the
/// new spacing from the wall): measured impact +0.96 %, averaged peak +10.3 % (raw p* 18.9).
/// Run with `cargo test --release --test all lobovsky_sensor1_fine -- --ignored
/// --nocapture`.
#[test]
#[ignore = "run time: 15 600 steps of 8 900 particles, 250 s on lavapipe (passes: impact +0.96 %, peak +10.3 %)"]
fn lobovsky_sensor1_fine_resolution_meets_the_full_bounds() {
    let (o, _dir) =
        crate::common::validate_case("dam_break_lobovsky_2d", Mode::Full, Mode::Full, "fine");
    assert!(o.passed(), "{}", crate::common::rows(&o));
}

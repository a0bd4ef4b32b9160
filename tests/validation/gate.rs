//! Layer 3 for elastic solids in water: the dam break through a rubber gate (Antoci, Gallati &
//! Sibilla 2007), `cases/elastic_gate_2d.toml` at its shipped resolution, the free end's
//! displacement against the experiment and against three published SPH solutions
//! (`wgsph validate --full --case elastic_gate_2d`). Both run the whole case: 0.4 s is about
//! 215 000 steps of 16 700 particles, hours on lavapipe (a GPU job). The CI test runs the
//! opening only, coarser (`--quick`).

use crate::common::validate_case;
use wgsph::validation::Mode;

/// The gate's opening at CI resolution (`wgsph validate --quick --case elastic_gate_2d`):
/// dx = 5/3 mm (3 particles through the gate), to 85 ms, against the experiment's samples at
/// 40 and 80 ms (bound 10 % of the peak measured) and the published solutions' band (10 %).
/// About 27 500 steps of 6 400 particles, 4 minutes on lavapipe.
#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 20 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn elastic_gate_opens_as_measured_coarse() {
    let (o, _dir) = validate_case("elastic_gate_2d", Mode::Quick, Mode::Quick, "quick");
    assert!(o.passed(), "{}", crate::common::rows(&o));
}

#[test]
#[ignore = "fails (and 3 h on lavapipe): run to 0.4 s, the gate follows the experiment to 120 ms (x -9 %, y -15 % of the measured peak) and then closes again while the measured one stays open (x -23 %, y -41 % at 160 ms; worst x -35 %, y -52 %), as the three published SPH solutions do (docs/validation.md)"]
fn elastic_gate_free_end_follows_antoci_2007() {
    let (o, _dir) = validate_case("elastic_gate_2d", Mode::Full, Mode::Full, "full");
    assert!(o.passed(), "{}", crate::common::rows(&o));
}

#[test]
#[ignore = "3 h on lavapipe (a GPU job); passes: run to 0.4 s on lavapipe, within the published solutions' band by x +1.3 %, y -4.3 % of the measured peak (bound 10 %; docs/validation.md)"]
fn elastic_gate_free_end_stays_within_the_published_sph_solutions() {
    let (o, _dir) = validate_case("elastic_gate_2d", Mode::Full, Mode::Full, "band");
    let rows = crate::common::rows(&o);
    assert!(o.failure.is_none(), "{rows}");
    let band: Vec<_> = o
        .metrics
        .iter()
        .filter(|m| m.name.contains("outside 3 published SPH solutions"))
        .collect();
    assert_eq!(band.len(), 2, "{rows}");
    for m in band {
        assert_eq!(m.verdict(), wgsph::validation::Verdict::Pass, "{rows}");
    }
}

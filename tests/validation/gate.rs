//! Layer 3 for elastic solids in water: the dam break through a rubber gate (Antoci, Gallati &
//! Sibilla 2007), `cases/elastic_gate_2d.toml` at its shipped resolution, the free end's
//! displacement against the experiment and against three published SPH solutions
//! (`wgsph validate --full --case elastic_gate_2d`).

use crate::common::validate_case;
use wgsph::validation::Mode;

#[test]
#[ignore = "fails, and 3.3 h on lavapipe (a GPU job): run to 0.36 s, the gate closes again from 100 ms while the measured one stays open (x -40 %, y -64 % of the measured peak), as the three published SPH solutions do, but further (outside their band by x -10 % at 185 ms, y -20 % at 165 ms; docs/validation.md)"]
fn elastic_gate_free_end_follows_antoci_2007() {
    let (o, _dir) = validate_case("elastic_gate_2d", Mode::Full, Mode::Full, "full");
    assert!(o.passed(), "{}", crate::common::rows(&o));
}

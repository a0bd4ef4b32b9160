//! Layer 3 for elastic solids in water: the dam break through a rubber gate (Antoci, Gallati &
//! Sibilla 2007), `cases/elastic_gate_2d.toml` at its shipped resolution, the free end's
//! displacement against the experiment (`wgsph validate --full --case elastic_gate_2d`).

use crate::common::validate_case;
use wgsph::validation::Mode;

#[test]
#[ignore = "not run to its end yet: 0.4 s is about 250 000 steps of 17 000 particles, ~4 h on lavapipe (a GPU job); the first 110 ms ran stably on lavapipe: right at 40 ms (x +3 %), too little opening by 80 ms (x −9 %, y −23 % of the peak, over the 20 % bound); the total-Lagrangian solid levels off too (x −16 %, y −27 % at 120 ms; docs/validation.md)"]
fn elastic_gate_free_end_follows_antoci_2007() {
    let (o, _dir) = validate_case("elastic_gate_2d", Mode::Full, Mode::Full, "full");
    assert!(o.passed(), "{}", crate::common::rows(&o));
}

//! The case files built into the binary: the shipped cases that `wgsph validate` runs (its
//! `CASES` table names them), so that it works from any directory, and a run of one of them
//! can be loaded again where its case file is not on disk (`run::scenario_of_run`).

use std::path::Path;

use crate::scenario::Scenario;

use super::CaseError;

/// A case file built into the binary.
#[derive(Debug, Clone, Copy)]
pub struct BuiltIn {
    /// The case's name: that of the validation case that runs it (a file may be built in under
    /// several names, each a variant its validation case sets with overrides).
    pub name: &'static str,
    /// The case file, relative to the repository root.
    pub file: &'static str,
    /// The file's text.
    pub text: &'static str,
}

impl BuiltIn {
    /// The case with `overrides` applied, loaded from the built-in text.
    pub fn load(&self, overrides: &[String]) -> Result<Scenario, CaseError> {
        super::load_str(self.text, self.file, overrides)
    }
}

/// Every built-in case, in the validation report's order.
pub static BUILT_IN: &[BuiltIn] = &[
    BuiltIn {
        name: "hydrostatic_2d",
        file: "cases/hydrostatic_2d.toml",
        text: include_str!("../../cases/hydrostatic_2d.toml"),
    },
    BuiltIn {
        name: "hydrostatic_3d",
        file: "cases/hydrostatic_3d.toml",
        text: include_str!("../../cases/hydrostatic_3d.toml"),
    },
    BuiltIn {
        name: "dam_break_2d",
        file: "cases/dam_break_2d.toml",
        text: include_str!("../../cases/dam_break_2d.toml"),
    },
    BuiltIn {
        name: "dam_break_lobovsky_2d",
        file: "cases/dam_break_lobovsky_2d.toml",
        text: include_str!("../../cases/dam_break_lobovsky_2d.toml"),
    },
    BuiltIn {
        name: "floating_box_2d",
        file: "cases/floating_box_2d.toml",
        text: include_str!("../../cases/floating_box_2d.toml"),
    },
    BuiltIn {
        name: "water_entry_cylinder_2d",
        file: "cases/water_entry_cylinder_2d.toml",
        text: include_str!("../../cases/water_entry_cylinder_2d.toml"),
    },
    BuiltIn {
        name: "water_entry_cylinder_2d_rho1000",
        file: "cases/water_entry_cylinder_2d.toml",
        text: include_str!("../../cases/water_entry_cylinder_2d.toml"),
    },
    BuiltIn {
        name: "sloshing_2d",
        file: "cases/sloshing_2d.toml",
        text: include_str!("../../cases/sloshing_2d.toml"),
    },
    BuiltIn {
        name: "oscillating_plate_2d",
        file: "cases/oscillating_plate_2d.toml",
        text: include_str!("../../cases/oscillating_plate_2d.toml"),
    },
    BuiltIn {
        name: "oscillating_plate_tl_2d",
        file: "cases/oscillating_plate_tl_2d.toml",
        text: include_str!("../../cases/oscillating_plate_tl_2d.toml"),
    },
    BuiltIn {
        name: "oscillating_plate_thin_2d",
        file: "cases/oscillating_plate_thin_2d.toml",
        text: include_str!("../../cases/oscillating_plate_thin_2d.toml"),
    },
    BuiltIn {
        name: "elastic_gate_2d",
        file: "cases/elastic_gate_2d.toml",
        text: include_str!("../../cases/elastic_gate_2d.toml"),
    },
    BuiltIn {
        name: "dam_break_3d",
        file: "cases/dam_break_3d.toml",
        text: include_str!("../../cases/dam_break_3d.toml"),
    }, // Its bed, dam and building are files beside it (cases/sfz_building/): it loads from the
    // repository root only.
    BuiltIn {
        name: "sfz_building_3d",
        file: "cases/sfz_building_3d.toml",
        text: include_str!("../../cases/sfz_building_3d.toml"),
    },
];

/// The built-in case called `name` whose case file is `file` (both as a run records them).
pub fn built_in(name: &str, file: &Path) -> Option<&'static BuiltIn> {
    BUILT_IN
        .iter()
        .find(|b| b.name == name && Path::new(b.file) == file)
}

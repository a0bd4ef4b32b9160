//! `[physics] density_filter` and `density_filter_every` in case files.

use super::*;
use crate::scenario::DensityFilter;

fn filter_of(text: &str, overrides: &[&str]) -> DensityFilter {
    load_str(text, "cases/t.toml", &sets(overrides))
        .unwrap()
        .physics
        .density_filter
}

/// BASE with `lines` added to `[physics]` (after line 7, `sound_speed_coef = 10.0`).
fn physics_with(lines: &str) -> String {
    base_with(
        "sound_speed_coef = 10.0",
        &format!("sound_speed_coef = 10.0\n{lines}"),
    )
}

#[test]
fn density_filter_defaults_and_values() {
    assert_eq!(filter_of(BASE, &[]), DensityFilter::None);
    assert_eq!(
        filter_of(&physics_with("density_filter = \"none\""), &[]),
        DensityFilter::None
    );
    assert_eq!(
        filter_of(&physics_with("density_filter = \"shepard\""), &[]),
        DensityFilter::Shepard { every: 30 }
    );
    assert_eq!(
        filter_of(
            &physics_with("density_filter = \"mls\"\ndensity_filter_every = 1"),
            &[]
        ),
        DensityFilter::Mls { every: 1 }
    );
    assert_eq!(
        filter_of(
            BASE,
            &[
                "physics.density_filter=mls",
                "physics.density_filter_every=10000"
            ]
        ),
        DensityFilter::Mls { every: 10000 }
    );
    // The shipped cases build with either filter.
    for case in [HYDROSTATIC, DAM_2D, DAM_3D] {
        assert_eq!(
            filter_of(case, &["physics.density_filter=shepard"]),
            DensityFilter::Shepard { every: 30 }
        );
    }
}

#[test]
fn bad_density_filters_are_refused() {
    for every in ["0", "-3", "10001", "99999999999"] {
        assert_err(
            &physics_with(&format!(
                "density_filter = \"shepard\"\ndensity_filter_every = {every}"
            )),
            &[],
            Some(9),
            &[
                &format!("physics.density_filter_every = {every}"),
                "between 1 and 10000",
            ],
        );
    }
    assert_err(
        &physics_with("density_filter_every = 30"),
        &[],
        Some(8),
        &[
            "physics.density_filter_every = 30",
            "only used with density_filter",
            "\"none\"",
        ],
    );
    assert_err(
        &physics_with("density_filter = \"none\"\ndensity_filter_every = 5"),
        &[],
        Some(9),
        &["physics.density_filter_every", "only used"],
    );
    assert_err(
        &physics_with("density_filter = \"delta\""),
        &[],
        Some(8),
        &[
            "physics.density_filter = \"delta\"",
            "\"none\", \"shepard\", \"mls\"",
        ],
    );
    assert_err(
        &physics_with("density_filter = \"mls\"\ndensity_filter_every = 2.5"),
        &[],
        Some(9),
        &["physics.density_filter_every", "wrong type", "integer"],
    );
    assert_err(
        &physics_with("density_filter = true"),
        &[],
        Some(8),
        &["physics.density_filter", "wrong type", "string"],
    );
    // The same checks through --set (no line: the value is not in the file).
    assert_err(
        BASE,
        &[
            "physics.density_filter=mls",
            "physics.density_filter_every=0",
        ],
        None,
        &[
            "physics.density_filter_every",
            "--set",
            "between 1 and 10000",
        ],
    );
}

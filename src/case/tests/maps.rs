//! `[maps]`: the grid and ground of the 3D dam break's maps, and the loader's errors.

use super::*;

/// The 3D dam break with `maps` as its `[maps]` table.
fn dam_break_with(maps: &str) -> String {
    format!("{DAM_3D}\n[maps]\n{maps}\n")
}

const COARSE: &[&str] = &["particles.dx_m=0.0322"];

#[test]
fn maps_default_to_the_domain_in_cells_of_two_spacings_on_the_walls_tops() {
    let s = load_str(&dam_break_with(""), "cases/t.toml", &sets(COARSE)).unwrap();
    let m = s.maps.as_ref().unwrap();
    let dx = 0.0322;
    assert_eq!(m.cell, 2.0 * dx);
    assert_eq!(m.wet_depth, dx);
    // The domain's plan, whole cells covering it.
    for a in 0..2 {
        assert!((m.first_centre[a] - 0.5 * m.cell - s.domain.min[a]).abs() < 1e-12);
    }
    for (a, n) in [m.nx, m.ny].into_iter().enumerate() {
        let covered = n as f64 * m.cell;
        let extent = s.domain.max[a] - s.domain.min[a];
        assert!(
            covered >= extent - 1e-9 && covered < extent + m.cell,
            "axis {a}"
        );
    }
    // The ground: the floor's face inside the tank, the obstacle's top over it.
    let obstacle = ([0.6635, 0.295], [0.8245, 0.698]);
    let (mut floor, mut roof) = (0, 0);
    for c in 0..m.cells() {
        let [x, y] = m.centre(c);
        let inside_by = |lo: [f64; 2], hi: [f64; 2], margin: f64| {
            x > lo[0] + margin && x < hi[0] - margin && y > lo[1] + margin && y < hi[1] - margin
        };
        if inside_by(obstacle.0, obstacle.1, 0.5 * dx) {
            roof += 1;
            assert!(
                (m.ground[c] - 0.161).abs() <= 0.5 * dx,
                "{x}, {y}: {}",
                m.ground[c]
            );
        } else if inside_by([0.0; 2], [3.22, 1.0], 0.5 * dx)
            && !inside_by(obstacle.0, obstacle.1, -dx)
        {
            floor += 1;
            assert!(m.ground[c].abs() < 1e-9, "{x}, {y}: {}", m.ground[c]);
        }
    }
    assert!(
        roof >= 2 && floor > 250,
        "{roof} cells on the obstacle, {floor} on the floor"
    );
    // A run's checkpoint is of its maps too.
    let other = load_str(&dam_break_with("cell_m = 0.15"), "t.toml", &sets(COARSE)).unwrap();
    assert_ne!(
        crate::checkpoint::fingerprint(&s),
        crate::checkpoint::fingerprint(&other)
    );
}

#[test]
fn bad_maps_are_refused_with_the_field_and_a_fix() {
    let bad = [
        (
            "cell_m = 0.01",
            vec!["maps.cell_m", "smaller than particles.dx_m"],
        ),
        ("cell_m = -1.0", vec!["maps.cell_m", "must be > 0"]),
        (
            "min_m = [-2.0, 0.0]",
            vec!["maps.min_m", "outside the domain"],
        ),
        (
            "max_m = [1.0, 9.0]",
            vec!["maps.max_m", "outside the domain"],
        ),
        (
            "min_m = [1.0, 0.5]\nmax_m = [0.5, 0.9]",
            vec!["maps.max_m", "north-east of maps.min_m"],
        ),
        ("min_m = [1.0, 0.5, 0.0]", vec!["maps.min_m"]),
        ("wet_depth_m = 0.0", vec!["maps.wet_depth_m", "must be > 0"]),
        ("cells = 3", vec!["unknown field", "cell_m"]),
    ];
    for (table, words) in bad {
        let e = err_of(&dam_break_with(table), COARSE);
        for w in &words {
            assert!(e.contains(w), "{table}: `{w}` expected in: {e}");
        }
        assert!(e.contains("fix:"), "{table}: no fix in {e}");
    }
    // A 2D case has no plan to map.
    let e = err_of(&format!("{BASE}\n[maps]\n"), &[]);
    assert!(
        e.contains("maps") && e.contains("3D") && e.contains("fix:"),
        "{e}"
    );
}

/// A grid larger than one storage binding holds is refused before any particle is made, with
/// the cell size that would fit.
#[test]
fn a_map_grid_larger_than_the_gpu_holds_is_refused() {
    let text = dam_break_with("cell_m = 0.05").replace(
        "[tank]",
        "[domain]\nmin_m = [-1.0, -1.0, -0.5]\nmax_m = [200.0, 200.0, 2.0]\n\n[tank]",
    );
    let e = err_of(&text, COARSE);
    for w in ["maps.cell_m", "cells, more than", "use cell_m = 0.099"] {
        assert!(e.contains(w), "`{w}` expected in: {e}");
    }
}

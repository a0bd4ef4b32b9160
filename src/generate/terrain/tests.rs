use super::*;
use proptest::prelude::*;

/// A 3 × 2 grid of cells 2 m wide whose south-west corner is at (100, 200): rows from the
/// north, as the file writes them.
const SMALL: &str = "ncols 3\nnrows 2\nxllcorner 100\nyllcorner 200\ncellsize 2\n\
                     NODATA_value -9999\n1 2 3\n4 5 6\n";

fn plane(x: f64, y: f64) -> f64 {
    1.5 + 0.2 * x - 0.05 * y
}

/// A grid of the plane [`plane`], `n` × `n` cells of `cell` from the origin.
fn plane_grid(n: usize, cell: f64) -> ElevationGrid {
    let mut text = format!("ncols {n}\nnrows {n}\nxllcenter 0\nyllcenter 0\ncellsize {cell}\n");
    for row in (0..n).rev() {
        let values: Vec<String> = (0..n)
            .map(|col| format!("{}", plane(col as f64 * cell, row as f64 * cell)))
            .collect();
        text.push_str(&values.join(" "));
        text.push('\n');
    }
    parse_asc(&text).unwrap()
}

#[test]
fn the_header_places_the_cells_and_the_rows_run_from_the_north() {
    let g = parse_asc(SMALL).unwrap();
    assert_eq!((g.ncols, g.nrows), (3, 2));
    assert_eq!(g.first_centre, [101.0, 201.0]);
    assert_eq!(g.cell, [2.0, 2.0]);
    // The file's last row is the southernmost.
    assert_eq!(g.z, vec![4.0, 5.0, 6.0, 1.0, 2.0, 3.0]);
    assert_eq!(g.extent(), ([100.0, 200.0], [106.0, 204.0]));
    assert_eq!(g.elevation(101.0, 203.0), 1.0);
    assert_eq!(g.elevation(105.0, 201.0), 6.0);
    // Halfway between the four south-west centres.
    assert_eq!(g.elevation(102.0, 202.0), 3.0);
}

#[test]
fn centres_cell_sizes_and_keys_in_any_case_are_read() {
    let g = parse_asc("NCOLS 2\nNROWS 1\nXLLCENTER 10\nYLLCENTER -5\nDX 1\nDY 3\n\n7.5\n-2e1\n")
        .unwrap();
    assert_eq!(g.first_centre, [10.0, -5.0]);
    assert_eq!(g.cell, [1.0, 3.0]);
    assert_eq!(g.z, vec![7.5, -20.0]);
}

#[test]
fn bad_headers_and_values_name_the_line_and_the_fix() {
    let cases: [(&str, Option<usize>, &str); 8] = [
        (
            "nrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n5\n",
            Some(5),
            "no ncols",
        ),
        (
            "ncols 1\nnrows 1\nxllcorner 0\nyllcorner 0\nmesh 1\ncellsize 1\n5\n",
            Some(5),
            "\"mesh\" is not a key",
        ),
        (
            "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n5\n",
            Some(6),
            "1 values",
        ),
        (
            "ncols 1\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n5,2\n",
            Some(6),
            "\"5,2\"",
        ),
        (
            "ncols 1\nnrows 1\nxllcorner 0\nxllcenter 0\nyllcorner 0\ncellsize 1\n5\n",
            Some(7),
            "neither or twice",
        ),
        (
            "ncols 1\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize -1\n5\n",
            Some(5),
            "not a positive length",
        ),
        (
            "ncols 1.5\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n5\n",
            Some(1),
            "whole number",
        ),
        (
            "ncols 1\nncols 1\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n5\n",
            Some(2),
            "twice",
        ),
    ];
    for (text, line, words) in cases {
        let e = parse_asc(text).unwrap_err();
        assert_eq!(e.line, line, "{text:?}: {e:?}");
        assert!(e.problem.contains(words), "{text:?}: {}", e.problem);
        assert!(!e.fix.is_empty());
    }
}

#[test]
fn cells_without_data_are_refused_or_filled_as_the_case_chooses() {
    let text = SMALL
        .replace("1 2 3", "1 -9999 3")
        .replace("4 5 6", "nan 5 6");
    let g = parse_asc(&text).unwrap();
    assert_eq!(g.missing(), 2);
    let e = g.clone().filled(NodataRule::Refuse).unwrap_err();
    assert!(
        e.problem.contains("2 of its 6 cells")
            && e.problem.contains("row 2 from the north, column 1")
            && e.problem.contains("x = 101 m, y = 201 m"),
        "{}",
        e.problem
    );
    assert!(e.fix.contains("terrain.nodata"), "{}", e.fix);
    let nearest = g.clone().filled(NodataRule::Nearest).unwrap();
    // (0, south) reached first from its east neighbour 5, (1, north) from its south 5.
    assert_eq!(nearest.z, vec![5.0, 5.0, 6.0, 1.0, 5.0, 3.0]);
    let level = g.filled(NodataRule::Elevation(-1.0)).unwrap();
    assert_eq!(level.z, vec![-1.0, 5.0, 6.0, 1.0, -1.0, 3.0]);
    let none =
        parse_asc("ncols 1\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value 0\n0\n")
            .unwrap();
    assert!(none
        .filled(NodataRule::Nearest)
        .unwrap_err()
        .problem
        .contains("no cell has data"));
}

#[test]
fn the_surface_of_a_tilted_plane_is_the_plane() {
    let g = plane_grid(6, 0.5);
    let mut rng = 12345u64;
    let mut next = || {
        rng = rng
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (rng >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..200 {
        let (x, y) = (2.5 * next(), 2.5 * next());
        assert!((g.elevation(x, y) - plane(x, y)).abs() < 1e-12);
        let [gx, gy] = g.gradient(x, y);
        assert!((gx - 0.2).abs() < 1e-12 && (gy + 0.05).abs() < 1e-12);
    }
    // Held beyond the outermost centres.
    assert_eq!(g.elevation(-1.0, 0.0), plane(0.0, 0.0));
    assert_eq!(g.gradient(-1.0, 3.0), [0.0, 0.0]);
}

#[test]
fn a_column_covers_the_support_across_the_surface_and_closes_a_step() {
    let flat = plane_grid(4, 1.0).shifted([0.0, 0.0, 0.0]);
    let c = flat.column(1.5, 1.5, 0.1, 3);
    assert_eq!(c.count, 4, "slope 0.2: 3 √1.0425 = 3.06 layers across");
    assert!((c.particle_z(0, 0.1) - (plane(1.5, 1.5) - 0.05)).abs() < 1e-12);
    // On a 45° slope three layers across take 3 √2 → 5 spacings down.
    let slope =
        parse_asc("ncols 3\nnrows 1\nxllcenter 0\nyllcenter 0\ncellsize 1\n2 2 1\n").unwrap();
    assert_eq!(slope.column(1.5, 0.0, 0.1, 3).count, 5);
    // Where the flat top meets the slope, the column on the flat reaches below its neighbour
    // 0.1 m on, which is 0.05 m lower: 1 spacing and 3 layers.
    let brink = slope.column(0.95, 0.0, 0.1, 3);
    assert_eq!((brink.surface, brink.count), (2.0, 4));
    assert!((brink.bottom(0.1) - 1.65).abs() < 1e-12);
}

#[test]
fn shifting_moves_the_grid_and_its_elevations() {
    let g = parse_asc(SMALL).unwrap().shifted([100.0, 200.0, 1.0]);
    assert_eq!(g.first_centre, [1.0, 1.0]);
    assert_eq!(g.elevation(1.0, 3.0), 0.0);
    assert_eq!(g.z.iter().copied().fold(f64::MIN, f64::max), 5.0);
}

proptest! {
    /// Whatever the text, the reader answers with a grid or an error; a grid it answers with
    /// has the cells its header promises.
    #[test]
    fn any_text_is_read_or_refused(text in "(ncols|nrows|xllcorner|yllcenter|cellsize|NODATA_value| |\n|-?[0-9]{1,3}|\\.|e|nan)*") {
        if let Ok(g) = parse_asc(&text) {
            prop_assert_eq!(g.z.len(), g.ncols * g.nrows);
        }
    }
}

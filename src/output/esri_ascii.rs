//! Plan maps (a flood's maximum depth, speed, …) as ESRI ASCII grids (`.asc`, GDAL's
//! `AAIGrid`), which every GIS program opens.
//!
//! The grid is an [`ElevationGrid`] whose `z` holds the map's values, NaN where a cell has none
//! (a cell never wet). The file is the one [`parse_asc`](crate::generate::terrain::parse_asc)
//! reads: a header (`ncols`, `nrows`, `xllcorner`, `yllcorner`, `cellsize`, `NODATA_value`),
//! then the rows from the north, each value in the shortest digits that parse back to the same
//! f64 ([`fmt_f64`]), a cell without a value as [`NODATA`].

use std::fmt::Write as _;

use anyhow::{bail, Result};

use crate::generate::terrain::ElevationGrid;
use crate::output::fmt_f64;

/// The value written for a cell without one (NaN in the grid): the usual choice of GIS exports.
pub const NODATA: f64 = -9999.0;

/// The text of `grid` as an ESRI ASCII grid.
///
/// Errors (rather than writing a file that reads back differently) when the cells are not
/// square (the format has one `cellsize`; resample first), when `z` does not hold
/// `ncols × nrows` values, when the corner or cell size is not finite and positive, or when a
/// value is infinite or equal to [`NODATA`] (it would read back as a cell without a value).
pub fn asc_text(grid: &ElevationGrid) -> Result<String> {
    check_shape(grid)?;
    let (ncols, nrows) = (grid.ncols, grid.nrows);
    let corner = [0, 1].map(|a| grid.first_centre[a] - 0.5 * grid.cell[a]);
    let mut text = String::with_capacity(64 + 12 * grid.z.len());
    // Writing to a String cannot fail: the results are ignored.
    let _ = writeln!(text, "ncols         {ncols}");
    let _ = writeln!(text, "nrows         {nrows}");
    let _ = writeln!(text, "xllcorner     {}", fmt_f64(corner[0]));
    let _ = writeln!(text, "yllcorner     {}", fmt_f64(corner[1]));
    let _ = writeln!(text, "cellsize      {}", fmt_f64(grid.cell[0]));
    let _ = writeln!(text, "NODATA_value  {}", fmt_f64(NODATA));
    // The format lists rows from the north; the grid stores them from the south.
    for row in grid.z.chunks_exact(ncols).rev() {
        for (k, &v) in row.iter().enumerate() {
            let sep = if k == 0 { "" } else { " " };
            let v = if v.is_nan() { NODATA } else { v };
            let _ = write!(text, "{sep}{}", fmt_f64(v));
        }
        text.push('\n');
    }
    Ok(text)
}

/// What would make the file not read back as `grid`.
fn check_shape(grid: &ElevationGrid) -> Result<()> {
    let [dx, dy] = grid.cell;
    if dx != dy {
        bail!(
            "cells of {dx} × {dy} m are not square: an ESRI ASCII grid has a single cellsize \
             (resample the map onto square cells)"
        );
    }
    if !(dx.is_finite() && dx > 0.0 && grid.first_centre.iter().all(|c| c.is_finite())) {
        bail!(
            "a grid's cell size must be finite and positive and its corner finite, not cell {dx} \
             m at {:?}",
            grid.first_centre
        );
    }
    if grid.ncols == 0
        || grid.nrows == 0
        || Some(grid.z.len()) != grid.ncols.checked_mul(grid.nrows)
    {
        bail!(
            "the grid holds {} values for {} × {} cells",
            grid.z.len(),
            grid.ncols,
            grid.nrows
        );
    }
    if let Some(k) = grid.z.iter().position(|v| v.is_infinite() || *v == NODATA) {
        bail!(
            "cell (column {}, row {} from the south) holds {}, which the format cannot tell \
             from a cell without a value (NODATA_value {NODATA}) or cannot write",
            k % grid.ncols,
            k / grid.ncols,
            grid.z[k]
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::terrain::parse_asc;

    /// 4 × 3 cells of 0.5 m, corner at (1000, −21) (binary fractions: the centre ± half a
    /// cell is exact, so the corner read back gives the same centre), with values no short
    /// decimal holds and cells without a value.
    fn grid() -> ElevationGrid {
        let nan = f64::NAN;
        ElevationGrid {
            ncols: 4,
            nrows: 3,
            first_centre: [1000.25, -20.75],
            cell: [0.5, 0.5],
            z: vec![
                0.1 + 0.2,
                1.0 / 3.0,
                nan,
                -0.0,
                1e-300,
                nan,
                nan,
                123456789.123,
                2.5,
                -1.2345678901234567e-7,
                1e20,
                nan,
            ],
        }
    }

    #[test]
    fn a_grid_round_trips_through_the_reader() {
        let g = grid();
        let text = asc_text(&g).unwrap();
        let back = parse_asc(&text).unwrap();
        assert_eq!((back.ncols, back.nrows), (4, 3));
        assert_eq!(back.first_centre, g.first_centre);
        assert_eq!(back.cell, g.cell);
        for (k, (a, b)) in g.z.iter().zip(&back.z).enumerate() {
            assert!(
                a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                "cell {k}: {a:e} read back as {b:e}"
            );
        }
        assert!(text.contains("xllcorner     1000\n"), "{text}");
        assert!(text.contains("yllcorner     -21\n"), "{text}");
        assert!(text.contains("cellsize      0.5\n"), "{text}");
        assert!(text.contains("NODATA_value  -9999\n"), "{text}");
    }

    #[test]
    fn rows_are_written_from_the_north() {
        let text = asc_text(&grid()).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 6 + 3);
        // The grid's last row (northernmost) first, the first row (southernmost) last.
        assert_eq!(lines[6], "2.5 -1.2345678901234566e-7 1e20 -9999");
        assert_eq!(lines[8], "0.30000000000000004 0.3333333333333333 -9999 -0");
    }

    #[test]
    fn grids_the_format_cannot_hold_are_refused() {
        let not_square = ElevationGrid {
            cell: [0.5, 0.25],
            ..grid()
        };
        let e = asc_text(&not_square).unwrap_err().to_string();
        assert!(e.contains("not square"), "{e}");
        let short = ElevationGrid {
            z: vec![0.0; 11],
            ..grid()
        };
        assert!(asc_text(&short).is_err());
        let mut nodata = grid();
        nodata.z[5] = NODATA;
        let e = asc_text(&nodata).unwrap_err().to_string();
        assert!(e.contains("column 1, row 1"), "{e}");
        let mut infinite = grid();
        infinite.z[0] = f64::INFINITY;
        assert!(asc_text(&infinite).is_err());
    }
}

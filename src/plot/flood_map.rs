//! Flood maps as PNG: a plan map (maximum depth, speed, …) in viridis over a grey hillshade of
//! the ground, with axes in metres, a colour bar and a title.
//!
//! The map and the ground are [`ElevationGrid`]s on the same cells; the map's NaN cells (never
//! wet) show the hillshade alone, its other cells a blend of [`COLOR_WEIGHT`] colour and the
//! rest shade, so the terrain shows through the water. The picture is painted pixel by pixel
//! (each pixel takes the cell under its centre), so its cost follows the image, not the grid.

use std::ops::Range;
use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::color_scale::{
    draw_colorbar, plot_area, ColorScale, BACKGROUND, COLORBAR_WIDTH, MARGIN, X_LABEL_AREA,
};
use super::{register_font, AXIS_LIMIT, AXIS_RESOLUTION};
use crate::generate::terrain::ElevationGrid;
use crate::output::write_atomic;

/// The sun of the hillshade: the cartographic convention (light from the north-west, 45° up),
/// under which slopes facing up-left on a north-up map are lit and relief reads as raised.
const SUN_AZIMUTH_DEG: f64 = 315.0;
const SUN_ALTITUDE_DEG: f64 = 45.0;
/// Weight of the map's colour over the shade in a wet cell (the shade keeps the rest).
const COLOR_WEIGHT: f64 = 0.75;
/// Ground without data (NaN elevation).
const NO_GROUND: RGBColor = WHITE;
/// Pixels of the layout besides those of `color_scale`.
const TITLE_HEIGHT: u32 = 34;
/// Wide enough for seven-digit map coordinates (UTM northings).
const Y_LABEL_AREA: u32 = 84;
/// Longer side of the plotting area: with labels and colour bar the image stays under 1000 px.
const PLOT_LONG_SIDE: f64 = 760.0;
/// Shorter side at least this (a long thin grid would leave no room for its axis).
const PLOT_MIN_SIDE: f64 = 150.0;

type Coord = Cartesian2d<RangedCoordf64, RangedCoordf64>;

/// The hillshade of `ground`, per cell, in [0, 1]: the cosine of the angle between the surface's
/// normal and the sun (azimuth 315°, altitude 45°), 0 for slopes turned away from it; a flat
/// cell gives sin 45° ≈ 0.707. Slopes are Horn's (1981) 3 × 3 finite differences. At the grid's
/// edges the neighbours are clamped into the grid and the difference is taken over the distance
/// actually spanned, so a plane shades the same everywhere; a neighbour without data stands in
/// as the centre's elevation (the slope leans towards flat there). A cell without data is NaN.
///
/// Panics when `ground.z` does not hold `ncols × nrows` values.
pub fn hillshade(ground: &ElevationGrid) -> Vec<f64> {
    assert_eq!(
        Some(ground.z.len()),
        ground.ncols.checked_mul(ground.nrows),
        "hillshade of a grid whose z does not hold ncols × nrows values"
    );
    let sun = sun_direction();
    (0..ground.nrows)
        .flat_map(|r| (0..ground.ncols).map(move |c| (r, c)))
        .map(|(r, c)| shade_at(ground, r, c, sun))
        .collect()
}

/// Unit vector towards the sun: x east, y north, z up; azimuth clockwise from north.
fn sun_direction() -> [f64; 3] {
    let (az, alt) = (SUN_AZIMUTH_DEG.to_radians(), SUN_ALTITUDE_DEG.to_radians());
    [alt.cos() * az.sin(), alt.cos() * az.cos(), alt.sin()]
}

fn shade_at(g: &ElevationGrid, r: usize, c: usize, sun: [f64; 3]) -> f64 {
    if g.z[r * g.ncols + c].is_nan() {
        return f64::NAN;
    }
    let [zx, zy] = horn_gradient(g, r, c);
    // The normal of z = f(x, y) is (−z_x, −z_y, 1), normalised.
    let lit = (-zx * sun[0] - zy * sun[1] + sun[2]) / (zx * zx + zy * zy + 1.0).sqrt();
    lit.clamp(0.0, 1.0)
}

/// (∂z/∂x, ∂z/∂y) at cell (row `r` from the south, column `c`): Horn (1981), "Hill shading and
/// the reflectance map", Proc. IEEE 69(1): the differences of the three columns (rows) either
/// side weighted 1, 2, 1, which smooths across the difference and so resists noise in the grid.
fn horn_gradient(g: &ElevationGrid, r: usize, c: usize) -> [f64; 2] {
    let centre = g.z[r * g.ncols + c];
    let z = |rr: usize, cc: usize| {
        let v = g.z[rr * g.ncols + cc];
        if v.is_nan() {
            centre
        } else {
            v
        }
    };
    let (west, east) = (c.saturating_sub(1), (c + 1).min(g.ncols - 1));
    let (south, north) = (r.saturating_sub(1), (r + 1).min(g.nrows - 1));
    let column = |cc: usize| z(south, cc) + 2.0 * z(r, cc) + z(north, cc);
    let row = |rr: usize| z(rr, west) + 2.0 * z(rr, c) + z(rr, east);
    // The weights sum to 4; the difference spans (east − west) cells (2 inside, 1 at an edge).
    let slope = |high: f64, low: f64, cells: usize, size: f64| {
        if cells == 0 {
            0.0
        } else {
            (high - low) / (4.0 * cells as f64 * size)
        }
    };
    [
        slope(column(east), column(west), east - west, g.cell[0]),
        slope(row(north), row(south), north - south, g.cell[1]),
    ]
}

/// A rendered map: RGB pixels and where world coordinates land in them.
struct MapImage {
    size: (u32, u32),
    rgb: Vec<u8>,
    /// Where world points land: the tests look up the pixel of a cell with it.
    #[cfg_attr(not(test), allow(dead_code))]
    coord: Coord,
}

/// The PNG of map `values` over the hillshade of `ground` (see the module doc), titled `title`,
/// its colour bar labelled `label` (with the unit, e.g. "maximum depth [m]").
///
/// The colour scale runs from min(0, smallest value) to max(0, largest value) over the finite
/// values, so a depth or speed map reads from dry or still; all zeros take [0, 1]. A map
/// without a finite value draws the hillshade alone with the note "no cell was wet".
/// Errors when the two grids are not on the same cells or a grid's `z` does not hold
/// `ncols × nrows` values.
pub fn render_map(
    values: &ElevationGrid,
    ground: &ElevationGrid,
    title: &str,
    label: &str,
) -> Result<Vec<u8>> {
    let image = render(values, ground, title, label)?;
    encode_png(image.size, &image.rgb)
}

/// [`render_map`] written to `path`, atomically; errors name the file.
pub fn draw_map(
    path: &Path,
    values: &ElevationGrid,
    ground: &ElevationGrid,
    title: &str,
    label: &str,
) -> Result<()> {
    let png = render_map(values, ground, title, label)
        .with_context(|| format!("cannot draw {}", path.display()))?;
    write_atomic(path, |w| w.write_all(&png))?;
    Ok(())
}

fn render(
    values: &ElevationGrid,
    ground: &ElevationGrid,
    title: &str,
    label: &str,
) -> Result<MapImage> {
    let extent = check_grids(values, ground)?;
    register_font();
    let scale = value_scale(&values.z);
    let size = image_size(&extent);
    let mut rgb = vec![0u8; size.0 as usize * size.1 as usize * 3];
    let coord = draw_frame(&mut rgb, size, extent, scale.as_ref(), title, label)
        .map_err(|e| anyhow!("drawing the map {title:?}: {e}"))?;
    let shade = hillshade(ground);
    paint_cells(&mut rgb, size.0, &coord, values, &shade, scale.as_ref());
    Ok(MapImage { size, rgb, coord })
}

/// The world extent [m] of the grids (cell edges), after checking that they share their cells.
fn check_grids(values: &ElevationGrid, ground: &ElevationGrid) -> Result<[Range<f64>; 2]> {
    let same = values.ncols == ground.ncols
        && values.nrows == ground.nrows
        && values.first_centre == ground.first_centre
        && values.cell == ground.cell;
    if !same {
        bail!(
            "the map ({} × {} cells of {:?} m from centre {:?}) and the ground ({} × {} of {:?} \
             from {:?}) are not on the same cells",
            values.ncols,
            values.nrows,
            values.cell,
            values.first_centre,
            ground.ncols,
            ground.nrows,
            ground.cell,
            ground.first_centre
        );
    }
    let cells = ground.ncols.checked_mul(ground.nrows).filter(|&n| n > 0);
    for (name, g) in [("map", values), ("ground", ground)] {
        if Some(g.z.len()) != cells {
            bail!(
                "the {name} holds {} values for {} × {} cells",
                g.z.len(),
                g.ncols,
                g.nrows
            );
        }
    }
    let axis = |a: usize, n: usize| {
        let start = ground.first_centre[a] - 0.5 * ground.cell[a];
        start..start + n as f64 * ground.cell[a]
    };
    let extent = [axis(0, ground.ncols), axis(1, ground.nrows)];
    for r in &extent {
        // Beyond these an axis' ticks overflow or are lost in rounding (issue 64).
        let magnitude = r.start.abs().max(r.end.abs());
        if !(magnitude < AXIS_LIMIT && r.end - r.start > AXIS_RESOLUTION * magnitude) {
            bail!(
                "the grid spans {r:?} m (cells {:?} m): not an extent a map can draw",
                ground.cell
            );
        }
    }
    Ok(extent)
}

/// The colour scale of the finite values (see [`render_map`]); None when there is none.
fn value_scale(values: &[f64]) -> Option<ColorScale> {
    let finite = values.iter().filter(|v| v.is_finite());
    let (lo, hi) = finite.fold((0.0f64, 0.0f64), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    if !values.iter().any(|v| v.is_finite()) {
        return None;
    }
    // Clamped: a span past ±1e300 overflows, and the colour bar's ticks with it (issue 64).
    let (lo, hi) = (lo.max(-AXIS_LIMIT), hi.min(AXIS_LIMIT));
    let hi = if hi > lo { hi } else { lo + 1.0 };
    ColorScale::new(lo, hi).ok()
}

/// Image size: the plotting area keeps the grid's aspect ratio (square cells look square)
/// unless its shorter side would fall under [`PLOT_MIN_SIDE`].
fn image_size(extent: &[Range<f64>; 2]) -> (u32, u32) {
    let [lx, ly] = extent.clone().map(|r| r.end - r.start);
    let (pw, ph) = plot_area(lx, ly, PLOT_LONG_SIDE, PLOT_MIN_SIDE);
    (
        pw.round() as u32 + Y_LABEL_AREA + 2 * MARGIN + COLORBAR_WIDTH,
        ph.round() as u32 + X_LABEL_AREA + 2 * MARGIN + TITLE_HEIGHT,
    )
}

/// Title, axes and colour bar (or the "no cell was wet" note); the cells are painted after.
fn draw_frame<'b>(
    rgb: &'b mut [u8],
    size: (u32, u32),
    extent: [Range<f64>; 2],
    scale: Option<&ColorScale>,
    title: &str,
    label: &str,
) -> std::result::Result<Coord, Box<dyn std::error::Error + 'b>> {
    let root = BitMapBackend::with_buffer(rgb, size).into_drawing_area();
    root.fill(&BACKGROUND)?;
    let (top, body) = root.split_vertically(TITLE_HEIGHT);
    top.draw_text(
        title,
        &("sans-serif", 20).into_text_style(&top),
        ((MARGIN + Y_LABEL_AREA) as i32, 10),
    )?;
    let (main, bar) = body.split_horizontally(size.0 - COLORBAR_WIDTH);
    let [x, y] = extent;
    let (dx, dy) = (tick_decimals(&x), tick_decimals(&y));
    // Room for each label: a long coordinate is ~60 px wide, a line of text ~20 px high.
    let plot_width = size.0 - Y_LABEL_AREA - 2 * MARGIN - COLORBAR_WIDTH;
    let plot_height = size.1 - X_LABEL_AREA - 2 * MARGIN - TITLE_HEIGHT;
    let (x_labels, y_labels) = ((plot_width / 90).max(3), (plot_height / 40).max(3));
    let mut chart = ChartBuilder::on(&main)
        .margin(MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(x, y)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .disable_y_mesh()
        .x_labels(x_labels as usize)
        .y_labels(y_labels as usize)
        .x_label_formatter(&|v| format!("{v:.dx$}"))
        .y_label_formatter(&|v| format!("{v:.dy$}"))
        .x_desc("x [m]")
        .y_desc("y [m]")
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()?;
    match scale {
        Some(scale) => draw_colorbar(&bar, scale, label)?,
        None => bar.draw_text(
            "no cell was wet",
            &("sans-serif", 14).into_text_style(&bar),
            (4, 2 * MARGIN as i32),
        )?,
    }
    root.present()?;
    Ok(chart.as_coord_spec().clone())
}

/// Decimals of an axis' tick labels: enough for ticks about a tenth of its span apart, and no
/// more ("5124400", not "5124400.0": map coordinates are long enough without).
fn tick_decimals(axis: &Range<f64>) -> usize {
    (1.0 - (axis.end - axis.start).log10().floor()).clamp(0.0, 9.0) as usize
}

/// Paints every pixel of the plotting area with the cell under its centre.
fn paint_cells(
    rgb: &mut [u8],
    width: u32,
    coord: &Coord,
    values: &ElevationGrid,
    shade: &[f64],
    scale: Option<&ColorScale>,
) {
    let (xr, yr) = (coord.get_x_range(), coord.get_y_range());
    // Pixels of the west and east edges, of the south and north (plotters' own mapping).
    let (p0, p1) = (
        coord.translate(&(xr.start, yr.start)),
        coord.translate(&(xr.end, yr.end)),
    );
    let cols = pixel_cells(p0.0, p1.0, values.ncols);
    let rows = pixel_cells(p0.1, p1.1, values.nrows);
    for &(py, row) in &rows {
        for &(px, col) in &cols {
            let k = row * values.ncols + col;
            let [r, g, b] = cell_color(values.z[k], shade[k], scale);
            let at = 3 * (py as usize * width as usize + px as usize);
            rgb[at..at + 3].copy_from_slice(&[r, g, b]);
        }
    }
}

/// (pixel, cell) along one axis: the pixels from `first` (the edge at the grid's start) to
/// `last` (its end), each with the cell of the `n` under its centre.
fn pixel_cells(first: i32, last: i32, n: usize) -> Vec<(i32, usize)> {
    let span = (last - first) as f64;
    let step = if last >= first { 1 } else { -1 };
    (0..=(last - first).abs())
        .map(|k| {
            // plotters puts value t (0..1 along the axis) at first + floor(span t) (ceil when
            // the axis runs backwards, as y does): this pixel holds t of k / span to
            // (k + 1) / span, its centre (k + ½) / |span|.
            let t = if span == 0.0 {
                0.5
            } else {
                (k as f64 + 0.5) / span.abs()
            };
            let cell = ((t * n as f64).floor().max(0.0) as usize).min(n - 1);
            (first + step * k, cell)
        })
        .collect()
}

/// The colour of a cell: the grey of its shade (white without ground), blended with the map's
/// colour where the map has a value.
fn cell_color(value: f64, shade: f64, scale: Option<&ColorScale>) -> [u8; 3] {
    let ground = if shade.is_nan() {
        [NO_GROUND.0, NO_GROUND.1, NO_GROUND.2]
    } else {
        [(255.0 * shade).round() as u8; 3]
    };
    match scale {
        Some(scale) if !value.is_nan() => {
            let c = scale.color(value);
            let mix = |color: u8, grey: u8| {
                (COLOR_WEIGHT * color as f64 + (1.0 - COLOR_WEIGHT) * grey as f64).round() as u8
            };
            [
                mix(c.0, ground[0]),
                mix(c.1, ground[1]),
                mix(c.2, ground[2]),
            ]
        }
        _ => ground,
    }
}

fn encode_png(size: (u32, u32), rgb: &[u8]) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    let mut enc = png::Encoder::new(&mut bytes, size.0, size.1);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut writer = enc.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `ncols × nrows` cells of `cell` m, the south-west one centred at (100, 200), with
    /// elevation f(x, y) at each centre.
    fn plane(ncols: usize, nrows: usize, cell: f64, f: impl Fn(f64, f64) -> f64) -> ElevationGrid {
        let first_centre = [100.0, 200.0];
        let z = (0..nrows)
            .flat_map(|r| (0..ncols).map(move |c| (r, c)))
            .map(|(r, c)| {
                f(
                    first_centre[0] + c as f64 * cell,
                    first_centre[1] + r as f64 * cell,
                )
            })
            .collect();
        ElevationGrid {
            ncols,
            nrows,
            first_centre,
            cell: [cell, cell],
            z,
        }
    }

    fn uniform(shade: &[f64]) -> f64 {
        assert!(
            shade.iter().all(|s| (s - shade[0]).abs() < 1e-12),
            "{shade:?}"
        );
        shade[0]
    }

    #[test]
    fn hillshade_of_a_flat_plane_is_the_cosine_of_the_zenith() {
        let s = uniform(&hillshade(&plane(5, 4, 2.0, |_, _| 3.0)));
        assert!((s - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-12, "{s}");
    }

    /// A plane shades the same at every cell, edges included (the clamped differences span
    /// the distance they cover); facing the sun is brighter than flat, facing away darker.
    #[test]
    fn hillshade_of_planes_facing_towards_and_away_from_the_sun() {
        let flat = std::f64::consts::FRAC_1_SQRT_2;
        // Down towards the north-west, 45° steep: its normal points at the sun.
        let toward = uniform(&hillshade(&plane(6, 5, 0.5, |x, y| (x - y) / 2f64.sqrt())));
        // Down towards the south-east, 45° steep: the sun grazes it.
        let away = uniform(&hillshade(&plane(6, 5, 0.5, |x, y| (y - x) / 2f64.sqrt())));
        assert!((toward - 1.0).abs() < 1e-12, "{toward}");
        assert!(away.abs() < 1e-12, "{away}");
        // Gentler: still brighter and darker than flat.
        let toward = uniform(&hillshade(&plane(6, 5, 0.5, |x, y| 0.1 * (x - y))));
        let away = uniform(&hillshade(&plane(6, 5, 0.5, |x, y| 0.1 * (y - x))));
        assert!(toward > flat && flat > away, "{toward} {flat} {away}");
        // One column or row: no difference across it, the other axis still counts.
        let strip = uniform(&hillshade(&plane(1, 4, 1.0, |_, y| -0.1 * y)));
        assert!(strip > flat, "{strip}");
    }

    #[test]
    fn hillshade_of_cells_without_ground_is_nan() {
        let mut g = plane(4, 4, 1.0, |x, _| 0.2 * x);
        g.z[5] = f64::NAN;
        let s = hillshade(&g);
        assert!(s[5].is_nan());
        assert!(s.iter().enumerate().all(|(k, v)| k == 5 || v.is_finite()));
        // Cells not next to the hole (row 3 or column 3) keep the plane's shade.
        let whole = hillshade(&plane(4, 4, 1.0, |x, _| 0.2 * x));
        for k in (0..16).filter(|k| k / 4 == 3 || k % 4 == 3) {
            assert!((s[k] - whole[k]).abs() < 1e-12, "cell {k}");
        }
        // Its neighbours lean towards flat across it.
        let flat = std::f64::consts::FRAC_1_SQRT_2;
        assert!((s[4] - flat).abs() < (whole[4] - flat).abs());
    }

    /// 20 × 10 cells of 2 m on a slope; the map wet on the east half only.
    fn synthetic() -> (ElevationGrid, ElevationGrid) {
        let ground = plane(20, 10, 2.0, |x, y| 0.1 * x + 0.05 * y);
        let mut values = ground.clone();
        for (k, v) in values.z.iter_mut().enumerate() {
            let col = k % 20;
            *v = if col < 10 { f64::NAN } else { 0.1 * col as f64 };
        }
        (values, ground)
    }

    fn pixel(img: &MapImage, rgb: &[u8], x: f64, y: f64) -> [u8; 3] {
        let (c, r) = img.coord.translate(&(x, y));
        let k = 3 * (r as usize * img.size.0 as usize + c as usize);
        [rgb[k], rgb[k + 1], rgb[k + 2]]
    }

    fn decode(png_bytes: &[u8]) -> ((u32, u32), Vec<u8>) {
        let decoder = png::Decoder::new(std::io::Cursor::new(png_bytes));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        buf.truncate(info.buffer_size());
        ((info.width, info.height), buf)
    }

    #[test]
    fn renders_wet_cells_in_colour_over_the_grey_hillshade() {
        let (values, ground) = synthetic();
        let png = render_map(&values, &ground, "maximum depth", "maximum depth [m]").unwrap();
        let (size, rgb) = decode(&png);
        let img = render(&values, &ground, "maximum depth", "maximum depth [m]").unwrap();
        assert_eq!(size, img.size);
        assert_eq!(rgb, img.rgb);
        assert!(size.0 <= 1000, "{size:?}");
        // The plotting area keeps the grid's 40 × 20 m aspect.
        let (a, b) = (
            img.coord.translate(&(99.0, 199.0)),
            img.coord.translate(&(139.0, 219.0)),
        );
        // plotters spans W − 1 and H − 1 pixels from edge to edge: within a pixel.
        assert!(((b.0 - a.0) - 2 * (a.1 - b.1)).abs() <= 1, "{a:?} {b:?}");
        // Cell (3, 5), never wet: grey, its hillshade.
        let shade = hillshade(&ground);
        let grey = (255.0 * shade[5 * 20 + 3]).round() as u8;
        assert_eq!(pixel(&img, &rgb, 106.0, 210.0), [grey; 3]);
        // Cell (15, 5): the blend of its colour over the shade, not grey.
        let wet = pixel(&img, &rgb, 130.0, 210.0);
        assert!(!(wet[0] == wet[1] && wet[1] == wet[2]), "{wet:?}");
        let scale = ColorScale::new(0.0, 1.9).unwrap();
        assert_eq!(wet, cell_color(1.5, shade[5 * 20 + 15], Some(&scale)));
        // Corners of the grid take the corner cells (the south-west one dry: grey).
        let sw = pixel(&img, &rgb, 99.05, 199.05);
        assert_eq!(sw, [(255.0 * shade[0]).round() as u8; 3]);
    }

    #[test]
    fn a_map_never_wet_or_of_one_value_is_drawn() {
        let (mut values, ground) = synthetic();
        values.z.iter_mut().for_each(|v| *v = f64::NAN);
        let img = render(&values, &ground, "dry", "maximum depth [m]").unwrap();
        let shade = hillshade(&ground);
        let grey = (255.0 * shade[5 * 20 + 15]).round() as u8;
        assert_eq!(pixel(&img, &img.rgb, 130.0, 210.0), [grey; 3]);
        for level in [0.3, 0.0, -2.0] {
            values.z.iter_mut().for_each(|v| *v = level);
            assert!(render_map(&values, &ground, "flat", "depth [m]").is_ok());
        }
        assert_eq!(value_scale(&[0.3, f64::NAN]).unwrap().range(), (0.0, 0.3));
        assert_eq!(value_scale(&[0.0]).unwrap().range(), (0.0, 1.0));
        assert_eq!(value_scale(&[-2.0, -1.0]).unwrap().range(), (-2.0, 0.0));
        assert_eq!(
            value_scale(&[f64::INFINITY, 2.0]).unwrap().range(),
            (0.0, 2.0)
        );
        assert!(value_scale(&[f64::NAN, f64::INFINITY]).is_none());
        let huge = value_scale(&[f64::MAX, f64::MIN]).unwrap().range();
        assert_eq!(huge, (-AXIS_LIMIT, AXIS_LIMIT));
    }

    #[test]
    fn grids_on_other_cells_are_refused() {
        let (values, ground) = synthetic();
        let shifted = ElevationGrid {
            first_centre: [100.5, 200.0],
            ..values.clone()
        };
        let e = render_map(&shifted, &ground, "t", "l")
            .unwrap_err()
            .to_string();
        assert!(e.contains("not on the same cells"), "{e}");
        let short = ElevationGrid {
            z: vec![0.0; 10],
            ..values.clone()
        };
        assert!(render_map(&short, &ground, "t", "l").is_err());
        let empty = ElevationGrid {
            ncols: 0,
            z: vec![],
            ..values
        };
        let empty_ground = ElevationGrid {
            ncols: 0,
            z: vec![],
            ..ground
        };
        assert!(render_map(&empty, &empty_ground, "t", "l").is_err());
    }

    #[test]
    fn draws_a_png_file_atomically() {
        let dir = crate::output::test_util::temp_dir("flood-map");
        let (values, ground) = synthetic();
        let path = dir.join("max_depth.png");
        draw_map(&path, &values, &ground, "t", "maximum depth [m]").unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        let e = format!(
            "{:#}",
            draw_map(
                &dir.join("bad.png"),
                &values,
                &plane(3, 3, 1.0, |_, _| 0.0),
                "t",
                "l"
            )
            .unwrap_err()
        );
        assert!(e.contains("bad.png"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

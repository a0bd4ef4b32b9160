//! `[terrain]`: ground from an ESRI ASCII grid (or the same as a GeoTIFF) under a tank of
//! water.

use super::*;

/// World coordinates of the grid's south-west corner (UTM-like: f32 would keep them to 0.5 m).
const WEST: f64 = 512_000.0;
const SOUTH: f64 = 5_400_000.0;

/// The tilted plane z = 0.05 + 0.25 x (case coordinates) on 6 × 6 cells of 0.1 m, as an
/// ESRI ASCII grid at (WEST, SOUTH).
fn tilted_grid() -> String {
    let mut text = format!("ncols 6\nnrows 6\nxllcorner {WEST}\nyllcorner {SOUTH}\ncellsize 0.1\n");
    for _row in 0..6 {
        let row: Vec<String> = (0..6)
            .map(|c| format!("{:.4}", 0.05 + 0.25 * (0.05 + 0.1 * c as f64)))
            .collect();
        text.push_str(&row.join(" "));
        text.push('\n');
    }
    text
}

/// Water 0.32 m deep in a 0.6 m tank whose floor is the grid `ground.asc`, plus `terrain`
/// lines in `[terrain]`.
fn case(terrain: &str) -> String {
    format!(
        r#"{}
[tank]
min_m = [0.0, 0.0, 0.0]
max_m = [0.6, 0.6, 0.48]
[terrain]
file = "ground.asc"
{terrain}
[[fluid_block]]
min_m = [0.0, 0.0, 0.0]
max_m = [0.6, 0.6, 0.32]
"#,
        head_3d(0.04)
    )
}

/// The surface over x: the plane between the outermost cells' centres, held beyond them.
fn surface(x: f64) -> f64 {
    0.05 + 0.25 * x.clamp(0.05, 0.55)
}

#[test]
fn the_ground_follows_the_grid_and_the_water_lies_on_it() {
    let dir = folder("terrain_tilted");
    std::fs::write(dir.join("ground.asc"), tilted_grid()).unwrap();
    let s = load_in(&dir, &case("")).unwrap();
    assert_eq!(s.world_origin_m, [WEST, SOUTH, 0.0]);
    let dx = 0.04;
    // The ground's particles: the walls inside the tank's inner box (the tank's own are
    // outside it; the ground's below the tank's floor are left to the floor).
    let inside = |p: &Particle| (0..2).all(|a| 0.0 < p.pos[a] && p.pos[a] < 0.6) && p.pos[2] > 0.0;
    let ground: Vec<&Particle> = s
        .particles
        .iter()
        .filter(|p| p.kind == Kind::Wall && inside(p))
        .collect();
    for p in &ground {
        // Each a whole number of spacings, plus a half, below the surface over it.
        let k = (surface(p.pos[0]) - p.pos[2]) / dx - 0.5;
        assert!((k - k.round()).abs() < 1e-9 && k > -1e-9, "{:?}", p.pos);
    }
    // Every column's top particle half a spacing under the surface: 15 × 15 columns.
    let tops = ground
        .iter()
        .filter(|p| (surface(p.pos[0]) - 0.5 * dx - p.pos[2]).abs() < 1e-9)
        .count();
    assert_eq!(tops, 15 * 15);
    // The water rests on the ground: each column's lowest particle half a spacing above the
    // surface, the others a spacing apart, up to within half a spacing of the block's top.
    let fluid: Vec<&Particle> = s
        .particles
        .iter()
        .filter(|p| p.kind == Kind::Fluid)
        .collect();
    assert_columns_rest_on(&fluid, surface, 0.32, 15 * 15);
    // f32 keeps the local positions to well under a spacing.
    assert!(s
        .particles
        .iter()
        .all(|p| p.pos.iter().all(|c| c.abs() < 10.0)));
}

#[test]
fn a_geotiff_ground_is_the_ascii_grid_of_the_same_cells() {
    let dir = folder("terrain_geotiff");
    let grid = crate::generate::terrain::parse_asc(&tilted_grid()).unwrap();
    std::fs::write(dir.join("ground.asc"), tilted_grid()).unwrap();
    std::fs::write(
        dir.join("ground.TIF"),
        crate::generate::geotiff::tests::geotiff_of(&grid),
    )
    .unwrap();
    let from_asc = load_in(&dir, &case("")).unwrap();
    let from_tif = load_in(&dir, &case("").replace("ground.asc", "ground.TIF")).unwrap();
    // The corner comes back from the tie point within rounding of the world coordinates.
    for a in 0..3 {
        assert!((from_tif.world_origin_m[a] - from_asc.world_origin_m[a]).abs() < 1e-6);
    }
    assert_eq!(from_tif.particles.len(), from_asc.particles.len());
    for (t, a) in from_tif.particles.iter().zip(&from_asc.particles) {
        assert_eq!(t.kind, a.kind);
        assert!(
            (0..3).all(|k| (t.pos[k] - a.pos[k]).abs() < 1e-6),
            "{:?} {:?}",
            t.pos,
            a.pos
        );
    }
}

/// Each of the `columns` columns of `fluid`: its lowest particle half a spacing above
/// `surface`, the others a spacing apart, its top particle's cell within half a spacing of
/// `level`.
pub(super) fn assert_columns_rest_on(
    fluid: &[&Particle],
    surface: impl Fn(f64) -> f64,
    level: f64,
    columns: usize,
) {
    let dx = 0.04;
    let mut by_column: Vec<(i64, i64, Vec<f64>)> = Vec::new();
    for p in fluid {
        let key = (
            (p.pos[0] / dx).floor() as i64,
            (p.pos[1] / dx).floor() as i64,
        );
        match by_column.iter_mut().find(|c| (c.0, c.1) == key) {
            Some(c) => c.2.push(p.pos[2]),
            None => by_column.push((key.0, key.1, vec![p.pos[2]])),
        }
    }
    assert_eq!(by_column.len(), columns);
    for (i, _, mut z) in by_column {
        z.sort_by(f64::total_cmp);
        let x = (i as f64 + 0.5) * dx;
        assert!(
            (z[0] - surface(x) - 0.5 * dx).abs() < 1e-9,
            "x = {x}: lowest {}",
            z[0]
        );
        assert!(
            z.windows(2).all(|w| (w[1] - w[0] - dx).abs() < 1e-9),
            "x = {x}: {z:?}"
        );
        let top = z[z.len() - 1] + 0.5 * dx;
        assert!((top - level).abs() <= 0.5 * dx + 1e-9, "x = {x}: top {top}");
    }
}

#[test]
fn an_origin_and_cells_without_data_are_taken_as_the_case_says() {
    let dir = folder("terrain_nodata");
    let holed = tilted_grid().replacen("0.0625", "-9999", 1);
    std::fs::write(
        dir.join("ground.asc"),
        holed.replace("cellsize 0.1\n", "cellsize 0.1\nNODATA_value -9999\n"),
    )
    .unwrap();
    let e = load_in(&dir, &case("")).unwrap_err().to_string();
    for w in [
        "terrain.file",
        "ground.asc",
        "1 of its 36 cells have no data",
        "nodata",
    ] {
        assert!(e.contains(w), "`{w}` in: {e}");
    }
    let origin = format!(
        "nodata = \"nearest\"\norigin_m = [{}, {}, 0.01]",
        WEST - 0.1,
        SOUTH
    );
    let s = load_in(&dir, &case(&origin)).unwrap();
    assert_eq!(s.world_origin_m, [WEST - 0.1, SOUTH, 0.01]);
    // The grid lies 0.1 m east of the case's origin: no ground in the first 0.1 m.
    let west_ground = s
        .particles
        .iter()
        .filter(|p| p.kind == Kind::Wall && p.pos[2] > 0.0 && p.pos[0] < 0.1 && p.pos[0] > 0.0)
        .filter(|p| 0.0 < p.pos[1] && p.pos[1] < 0.6)
        .count();
    assert_eq!(west_ground, 0);
    let level = load_in(
        &dir,
        &case("nodata = \"elevation\"\nnodata_elevation_m = 0.4"),
    );
    assert!(level.is_ok());
}

/// A 2D case with a terrain.
const TWO_D: &str = r#"
dimension = 2
[particles]
dx_m = 0.04
[physics]
sound_speed_coef = 10.0
[time]
end_s = 0.1
output_every_s = 0.05
[terrain]
file = "ground.asc"
[[fluid_block]]
min_m = [0.0, 0.1]
max_m = [0.6, 0.32]
"#;

#[test]
fn bad_terrains_are_refused_naming_the_field_and_the_fix() {
    let dir = folder("terrain_bad");
    std::fs::write(dir.join("ground.asc"), tilted_grid()).unwrap();
    std::fs::write(dir.join("ground.tif"), "II*").unwrap();
    std::fs::write(
        dir.join("short.asc"),
        tilted_grid().replace("ncols 6", "ncols 7"),
    )
    .unwrap();
    let cases: [(String, &[&str]); 13] = [
        (TWO_D.to_string(), &["terrain", "2D", "dimension = 3"]),
        (
            case("").replace("ground.asc", "none.asc"),
            &["terrain.file", "none.asc", "relative to the case file"],
        ),
        (
            case("").replace("ground.asc", "ground.xyz"),
            &[
                "terrain.file",
                "ground.xyz",
                "(.asc)",
                "(.tif, .tiff)",
                "gdal_translate",
            ],
        ),
        (
            case("").replace("ground.asc", "ground.tif"),
            &["terrain.file", "ground.tif", "tiff crate", "gdal_translate"],
        ),
        (
            case("").replace("ground.asc", "short.asc"),
            &["terrain.file", "short.asc, line 11", "36 values", "7 × 6"],
        ),
        (case("wall = \"mirror\""), &["terrain.wall", "dynamic"]),
        (case("layers = 9"), &["terrain.layers", "between 1 and 8"]),
        (
            case("nodata = \"elevation\""),
            &["terrain.nodata", "nodata_elevation_m"],
        ),
        (
            case("nodata_elevation_m = 1.0"),
            &["terrain.nodata_elevation_m", r#"nodata = "elevation""#],
        ),
        // UTM coordinates taken as the case's: the grid 5 400 km away.
        (
            case("origin_m = [0.0, 0.0, 0.0]"),
            &[
                "terrain.origin_m",
                "5400000.6 m from the case's origin",
                "near the grid",
            ],
        ),
        // An origin 2 km off: the grid lies outside the domain.
        (
            case(&format!("origin_m = [{}, {}, 0.0]", WEST - 2000.0, SOUTH)),
            &["terrain.file", "no particle column", "origin_m"],
        ),
        // An origin far from the grid (the case fuzzer's i64::MIN) is named, not the fill it
        // would leave without ground.
        (
            case("origin_m = [0.0, 0.0, -9223372036854775808]"),
            &[
                "terrain.origin_m",
                "from the case's origin",
                "near the grid",
            ],
        ),
        (
            case(&format!("origin_m = [{}, 3.0e6, 0.0]", WEST)),
            &["terrain.origin_m", "more than 1000000 m"],
        ),
    ];
    for (text, words) in cases {
        let e = match load_in(&dir, &text) {
            Ok(_) => panic!("accepted: {text}"),
            Err(e) => e.to_string(),
        };
        for w in words {
            assert!(e.contains(w), "`{w}` expected in: {e}");
        }
        assert!(e.contains("fix:"), "no fix in: {e}");
    }
}

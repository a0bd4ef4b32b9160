//! `[[buildings]]`: a building with a courtyard, from a GeoJSON footprint, on a terrain, with
//! water poured around it.

use std::path::{Path, PathBuf};

use super::*;

const DX: f64 = 0.04;

/// A flat ground at 0.05 m, 12 × 8 cells of 0.1 m, at the world's (1000, 2000).
const GROUND: &str = "ncols 12\nnrows 8\nxllcorner 1000\nyllcorner 2000\ncellsize 0.1\n";

/// A square building 0.4 m wide and 0.2 m high with a courtyard 0.16 m wide, in world
/// coordinates.
const FOOTPRINT: &str = r#"{"type": "FeatureCollection", "features": [
  {"type": "Feature", "properties": {"levels": 2, "h": 0.2},
   "geometry": {"type": "Polygon", "coordinates": [
     [[1000.32, 2000.2], [1000.72, 2000.2], [1000.72, 2000.6], [1000.32, 2000.6], [1000.32, 2000.2]],
     [[1000.44, 2000.32], [1000.6, 2000.32], [1000.6, 2000.48], [1000.44, 2000.48], [1000.44, 2000.32]]]}}
]}"#;

fn town(test: &str) -> PathBuf {
    let dir = folder(test);
    let rows = vec![["0.05"; 12].join(" "); 8].join("\n");
    std::fs::write(dir.join("ground.asc"), format!("{GROUND}{rows}\n")).unwrap();
    std::fs::write(dir.join("town.geojson"), FOOTPRINT).unwrap();
    dir
}

fn case(buildings: &str) -> String {
    format!(
        r#"{}
[tank]
min_m = [0.0, 0.0, 0.0]
max_m = [1.2, 0.8, 0.4]
[terrain]
file = "ground.asc"
[[buildings]]
file = "town.geojson"
{buildings}
[[fill]]
seed_m = [0.1, 0.1, 0.1]
level_m = 0.15
"#,
        head_3d(DX)
    )
}

/// Inside the footprint: the square less the courtyard (their edges halfway between the
/// lattice's columns).
fn in_footprint(x: f64, y: f64) -> bool {
    let square = (0.32..0.72).contains(&x) && (0.2..0.6).contains(&y);
    square && !in_yard(x, y)
}

fn in_yard(x: f64, y: f64) -> bool {
    (0.44..0.6).contains(&x) && (0.32..0.48).contains(&y)
}

#[test]
fn a_building_stands_on_the_ground_and_the_water_stays_out_of_it() {
    let dir = town("buildings_stand");
    let s = load_in(&dir, &case("height_property = \"h\"")).unwrap();
    let inside_tank = |p: &&Particle| (0..2).all(|a| 0.0 < p.pos[a] && p.pos[a] < [1.2, 0.8][a]);
    let walls: Vec<&Particle> = s
        .particles
        .iter()
        .filter(|p| p.kind == Kind::Wall && p.pos[2] > 0.0)
        .filter(inside_tank)
        .collect();
    let building: Vec<&&Particle> = walls
        .iter()
        .filter(|p| in_footprint(p.pos[0], p.pos[1]))
        .collect();
    let ground: Vec<&&Particle> = walls
        .iter()
        .filter(|p| !in_footprint(p.pos[0], p.pos[1]))
        .collect();
    // The ground is at 0.05 m: its particles at 0.03 m (the ones below the tank's floor are
    // the floor's); the building's reach from the floor to its roof at 0.05 + 0.2 m.
    assert!(
        ground.iter().all(|p| (p.pos[2] - 0.03).abs() < 1e-9),
        "ground under the building"
    );
    let top = building.iter().map(|p| p.pos[2]).fold(f64::MIN, f64::max);
    assert!((top + 0.5 * DX - 0.25).abs() <= DX, "roof {top}");
    // Walls all the way down where the outline is; a roof, not a solid block, further in.
    let at = |x: f64, y: f64| {
        building
            .iter()
            .filter(|p| (p.pos[0] - x).abs() < 1e-9 && (p.pos[1] - y).abs() < 1e-9)
            .count()
    };
    assert!(at(0.34, 0.22) >= 6, "the wall's column: {}", at(0.34, 0.22));
    let fluid: Vec<&Particle> = s
        .particles
        .iter()
        .filter(|p| p.kind == Kind::Fluid)
        .collect();
    assert!(!fluid.is_empty());
    for p in &fluid {
        assert!(
            !in_footprint(p.pos[0], p.pos[1]),
            "water in the building: {:?}",
            p.pos
        );
        // The courtyard's walls stand above the level: the water poured outside is not in it.
        assert!(
            !((0.42..0.58).contains(&p.pos[0]) && (0.32..0.48).contains(&p.pos[1])),
            "{:?}",
            p.pos
        );
    }
}

#[test]
fn bad_buildings_are_refused_naming_the_field_and_the_fix() {
    let dir = town("buildings_bad");
    std::fs::write(
        dir.join("far.geojson"),
        FOOTPRINT
            .replace("1000.", "9000.")
            .replace("2000.", "9000."),
    )
    .unwrap();
    let cases: [(String, &[&str]); 5] = [
        (
            case(""),
            &[
                "buildings[0].file",
                "feature 0 has no height",
                "default_height_m",
            ],
        ),
        (
            case("height_property = \"levels\"\nlayers = 0"),
            &["buildings[0].layers", "between 1 and 8"],
        ),
        (
            case("default_height_m = 1.0").replace("town.geojson", "far.geojson"),
            &["buildings[0].file", "none of its 1 footprints", "ogr2ogr"],
        ),
        (
            case("default_height_m = 1.0").replace("town.geojson", "none.geojson"),
            &[
                "buildings[0].file",
                "none.geojson",
                "relative to the case file",
            ],
        ),
        (
            case("default_height_m = -1.0"),
            &["buildings[0].default_height_m"],
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

/// The shipped town (cases/town_flood_3d.toml) is built from its files: the ground's grid in
/// world coordinates with a cell without data, six footprints (one without a height), the
/// reservoir filled behind the gate only.
#[test]
fn the_town_is_built_from_its_files() {
    let s = load(Path::new("cases/town_flood_3d.toml"), &[]).unwrap();
    assert_eq!(s.world_origin_m, [2_600_000.0, 1_200_000.0, 431.0]);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let fluid: Vec<&Particle> = s
        .particles
        .iter()
        .filter(|p| p.kind == Kind::Fluid)
        .collect();
    assert!(fluid.len() > 500, "{}", fluid.len());
    assert!(fluid
        .iter()
        .all(|p| p.pos[0] < 1.44 && p.pos[2] <= 0.55 + 1e-9));
    let text = std::fs::read_to_string("cases/town/buildings.geojson").unwrap();
    let footprints = crate::generate::footprint::parse_geojson(&text, "height").unwrap();
    assert_eq!(footprints.len(), 6);
    for f in footprints {
        let f = f.shifted(s.world_origin_m);
        let walls = s
            .particles
            .iter()
            .filter(|p| p.kind == Kind::Wall && f.contains(p.pos[0], p.pos[1]))
            .count();
        assert!(walls > 20, "feature {}: {walls} particles", f.feature);
    }
}

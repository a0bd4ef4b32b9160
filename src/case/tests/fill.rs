//! `[[fill]]`: water poured at a seed up to a level, over a terrain of two basins parted by a
//! ridge.

use std::path::{Path, PathBuf};

use super::*;

const DX: f64 = 0.04;

/// The ground along x: 0.05 m, with a ridge up to 0.35 m between x = 0.55 and 0.65 m.
fn ground_at(col: usize) -> f64 {
    if (5..=6).contains(&col) {
        0.35
    } else {
        0.05
    }
}

/// Two basins: 12 × 4 cells of 0.1 m.
fn write_basins(dir: &Path) {
    let mut text = "ncols 12\nnrows 4\nxllcorner 0\nyllcorner 0\ncellsize 0.1\n".to_string();
    for _ in 0..4 {
        let row: Vec<String> = (0..12).map(|c| format!("{}", ground_at(c))).collect();
        text.push_str(&row.join(" "));
        text.push('\n');
    }
    std::fs::write(dir.join("basins.asc"), text).unwrap();
}

fn basins(test: &str) -> PathBuf {
    let dir = folder(test);
    write_basins(&dir);
    dir
}

/// The basins in a tank 1.2 m × 0.4 m, with `fill` (and any other tables) appended.
fn case(more: &str) -> String {
    format!(
        r#"{}
[tank]
min_m = [0.0, 0.0, 0.0]
max_m = [1.2, 0.4, 0.6]
[terrain]
file = "basins.asc"
{more}
"#,
        head_3d(DX)
    )
}

/// The grid as the terrain reads it.
fn grid(dir: &Path) -> crate::generate::terrain::ElevationGrid {
    let text = std::fs::read_to_string(dir.join("basins.asc")).unwrap();
    crate::generate::terrain::parse_asc(&text).unwrap()
}

#[test]
fn water_fills_the_seeds_basin_below_the_level_and_nowhere_else() {
    let dir = basins("fill_basins");
    let level = 0.25;
    let s = load_in(
        &dir,
        &case(&format!(
            "[[fill]]\nseed_m = [0.2, 0.2, 0.1]\nlevel_m = {level}"
        )),
    )
    .unwrap();
    let g = grid(&dir);
    let surface = |x: f64, y: f64| g.elevation(x, y);
    let fluid: Vec<&Particle> = s
        .particles
        .iter()
        .filter(|p| p.kind == Kind::Fluid)
        .collect();
    assert!(!fluid.is_empty());
    for p in &fluid {
        let [x, y, z] = p.pos;
        assert!(
            z >= surface(x, y) + 0.5 * DX - 1e-9,
            "in the ground: {:?}",
            p.pos
        );
        assert!(z <= level + 1e-9, "above the level: {:?}", p.pos);
        assert!(x < 0.55, "beyond the ridge: {:?}", p.pos);
    }
    // The west basin's flat part (x < 0.45 m: 11 × 10 columns) is water from the ground to
    // the level, resting on the ground.
    let flat: Vec<&Particle> = fluid.iter().copied().filter(|p| p.pos[0] < 0.45).collect();
    super::terrain::assert_columns_rest_on(&flat, |_| 0.05, level, 11 * 10);
    // Hydrostatic below the top of the water's cells.
    let deepest = fluid
        .iter()
        .min_by(|a, b| a.pos[2].total_cmp(&b.pos[2]))
        .unwrap();
    assert!(deepest.rho > 1000.0);
    // Above the ridge, both basins are one.
    let both = load_in(
        &dir,
        &case("[[fill]]\nseed_m = [0.2, 0.2, 0.1]\nlevel_m = 0.45"),
    )
    .unwrap();
    assert!(both
        .particles
        .iter()
        .any(|p| p.kind == Kind::Fluid && p.pos[0] > 0.8));
}

#[test]
fn water_flows_around_an_obstacle_and_a_body_not_into_them() {
    let dir = basins("fill_around");
    let s = load_in(
        &dir,
        &case(
            "[[fill]]\nseed_m = [0.1, 0.3, 0.1]\nlevel_m = 0.25\n\
             [[obstacle]]\nmin_m = [0.2, 0.0, 0.0]\nmax_m = [0.28, 0.2, 0.6]\n\
             [[body]]\nname = \"post\"\nshape = \"box\"\nmin_m = [0.36, 0.2, 0.08]\n\
             max_m = [0.44, 0.28, 0.4]\n[body.motion]\nkind = \"fixed\"",
        ),
    )
    .unwrap();
    for p in s.particles.iter().filter(|p| p.kind == Kind::Fluid) {
        let [x, y, z] = p.pos;
        let in_obstacle = (0.2..0.28).contains(&x) && y < 0.2;
        let in_body = (0.36..0.44).contains(&x) && (0.2..0.28).contains(&y) && z > 0.08;
        assert!(!in_obstacle && !in_body, "{:?}", p.pos);
    }
}

#[test]
fn a_seed_with_nowhere_to_start_is_refused() {
    let dir = basins("fill_seeds");
    let cases: [(&str, &[&str]); 5] = [
        (
            "seed_m = [0.6, 0.2, 0.2]\nlevel_m = 0.3",
            &["fill[0].seed_m", "lies in the terrain"],
        ),
        (
            "seed_m = [0.2, 0.2, 0.3]\nlevel_m = 0.25",
            &["fill[0].seed_m", "above the fill's level_m"],
        ),
        (
            "seed_m = [1.5, 0.2, 0.1]\nlevel_m = 0.25",
            &["fill[0].seed_m", "outside the tank's inner box"],
        ),
        (
            "seed_m = [0.2, 0.2, 0.01]\nlevel_m = 0.02",
            &["fill[0].level_m", "leaves no water"],
        ),
        ("seed_m = [0.2, 0.2]\nlevel_m = 0.25", &["fill[0].seed_m"]),
    ];
    for (fill, words) in cases {
        let text = case(&format!("[[fill]]\n{fill}"));
        assert_refused(load_in(&dir, &text), words, fill);
    }
    // Nothing to hold the water: no tank, domain or terrain.
    let e = load_str(
        "dimension = 2\n[particles]\ndx_m = 0.04\n[physics]\nsound_speed_coef = 10.0\n\
         [time]\nend_s = 0.1\noutput_every_s = 0.05\n[[fill]]\nseed_m = [0.2, 0.1]\n\
         level_m = 0.3\n",
        "c.toml",
        &[],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("nothing holds the fill's water"), "{e}");
}

/// A 2D fill in a domain: the water of a box, as a fluid block from the floor to the level.
#[test]
fn a_fill_in_an_empty_tank_is_the_block_up_to_its_level() {
    let tank = "dimension = 2\n[particles]\ndx_m = 0.04\n[physics]\nsound_speed_coef = 10.0\n\
                [time]\nend_s = 0.1\noutput_every_s = 0.05\n[tank]\nmin_m = [0.0, 0.0]\n\
                max_m = [0.8, 0.6]\n";
    let filled = load_str(
        &format!("{tank}[[fill]]\nseed_m = [0.5, 0.1]\nlevel_m = 0.32\n"),
        "c.toml",
        &[],
    )
    .unwrap();
    let block = load_str(
        &format!("{tank}[[fluid_block]]\nmin_m = [0.0, 0.0]\nmax_m = [0.8, 0.32]\n"),
        "c.toml",
        &[],
    )
    .unwrap();
    assert_eq!(filled.particles, block.particles);
}

//! Flood maps (`[maps]`) on cases whose answer is known: a still tank, whose depth map must
//! read the water's depth in every cell over the water, the cells beside the walls included,
//! and NODATA over the walls; films one and two particles deep on a floor.

use crate::common::*;
use wgsph::layout::MapCell;
use wgsph::progress::LogLines;
use wgsph::scenario::{FloodMaps, GaugeSurface, Probe, ProbeKind, Scenario};
use wgsph::sph::Solver;

/// A tank `side` m square (walls 3 layers, open top) holding water `depth` m deep (a whole
/// number of spacings: the block's lattice fills it exactly), mapped with cells of `cell` m
/// over the whole domain, or over the tank's inside alone.
fn tank(side: f64, depth: f64, dx: f64, cell: f64, inside_only: bool) -> Scenario {
    let area = match inside_only {
        true => format!("min_m = [0.0, 0.0]\nmax_m = [{side}, {side}]"),
        false => String::new(),
    };
    let text = format!(
        r#"
name = "still_tank_maps"
dimension = 3
[particles]
dx_m = {dx}
[physics]
gravity_m_s2 = [0.0, 0.0, -9.81]
sound_speed_coef = 10.0
viscosity = "artificial"
alpha = 0.02
[time]
end_s = 1.0
output_every_s = 0.5
[tank]
min_m = [0.0, 0.0, 0.0]
max_m = [{side}, {side}, 0.5]
layers = 3
open_top = true
[[fluid_block]]
min_m = [0.0, 0.0, 0.0]
max_m = [{side}, {side}, {depth}]
[maps]
cell_m = {cell}
{area}
"#
    );
    wgsph::case::load_str(&text, "still_tank_maps.toml", &[]).unwrap()
}

/// Each cell's centre, whether it lies over the tank's inside (`side` m square from the origin),
/// and its record.
fn cells_over(maps: &FloodMaps, cells: &[MapCell], side: f64) -> Vec<([f64; 2], bool, MapCell)> {
    (0..maps.cells())
        .map(|c| {
            let x = maps.centre(c);
            let inside = x.iter().all(|&v| (0.0..side).contains(&v));
            (x, inside, cells[c])
        })
        .collect()
}

/// The still tank: every cell over the water wet with its depth within dx/2, at the start
/// (the hydrostatic lattice) and after the water has stood 0.2 s (measured: within 0.2 and
/// 1.4 mm of dx = 40 mm); every cell over the walls never wet (NODATA).
#[test]
fn a_still_tanks_depth_map_reads_its_depth_and_nodata_over_the_walls() {
    let (side, depth, dx) = (0.4, 0.32, 0.04);
    let sc = tank(side, depth, dx, 0.05, false);
    let maps = sc.maps.clone().unwrap();
    // The ground under the inside is the floor's face, z = 0.
    for (c, g) in maps.ground.iter().enumerate() {
        if cells_over(&maps, &vec![MapCell::UNSEEN; maps.cells()], side)[c].1 {
            assert!(g.abs() < 1e-9, "cell {c}: ground {g}");
        }
    }
    let mut solver = Solver::new(gpu(), &sc).unwrap();
    for t in [0.0, 0.2] {
        solver.advance_to(t).unwrap();
        solver.sample_maps().unwrap();
        let cells = solver.map_cells().unwrap().unwrap();
        let (mut inside, mut worst) = (0, 0.0f64);
        for (x, over_water, cell) in cells_over(&maps, &cells, side) {
            if over_water {
                inside += 1;
                let err = (cell.depth as f64 - depth).abs();
                worst = worst.max(err);
                assert!(cell.wet_samples > 0, "t = {t}: the cell at {x:?} reads dry");
                assert!(
                    err <= 0.5 * dx,
                    "t = {t}: the cell at {x:?} reads {} m of the {depth} m",
                    cell.depth
                );
            } else {
                assert_eq!(
                    cell.wet_samples, 0,
                    "t = {t}: the cell at {x:?} over the walls"
                );
            }
        }
        println!("t = {t}: {inside} cells over the water, worst depth error {worst:.4} m");
        assert!(inside >= 36, "{inside} cells over the water");
    }
}

/// Films one and two particles deep (dx = 0.02 m) on a tank's floor read wet everywhere, their
/// depths their thickness within dx/4 (measured: 0.0187 and 0.0399 m), and so does a depth
/// gauge (`kind = "depth"`) in the middle (0.0188 and 0.0399 m; a wave gauge there reads
/// 0.0166 and 0.0399 m): the normalised criterion ψ = φ_f / (1 − φ_s) sees a sheet the
/// gauges' φ_f ≥ ½ cannot (docs/design/flood_maps.md).
#[test]
fn films_one_and_two_particles_deep_read_wet() {
    let dx = 0.02;
    for layers in [1.0, 2.0] {
        let mut sc = tank(0.2, layers * dx, dx, 0.04, true);
        // A depth gauge and a wave gauge on one line in the middle, their feet on the floor.
        for (name, surface) in [
            ("depth", GaugeSurface::WaterFraction),
            ("height", GaugeSurface::FluidHalf),
        ] {
            sc.probes.push(Probe {
                name: name.into(),
                kind: ProbeKind::Height {
                    base: [0.1, 0.1, 0.0],
                    surface,
                },
                body: None,
            });
        }
        let maps = sc.maps.clone().unwrap();
        let solver = Solver::new(gpu(), &sc).unwrap();
        solver.sample_maps().unwrap();
        let gauges = solver.sample_probes().unwrap();
        println!(
            "{layers} layer(s): depth gauge {:.4} m, wave gauge {:.4} m",
            gauges[0], gauges[1]
        );
        assert!(
            (gauges[0] - layers * dx).abs() <= 0.25 * dx,
            "depth gauge {}",
            gauges[0]
        );
        let cells = solver.map_cells().unwrap().unwrap();
        let depths: Vec<f64> = (cells_over(&maps, &cells, 0.2).into_iter())
            .filter(|(_, inside, _)| *inside)
            .map(|(x, _, cell)| {
                assert!(
                    cell.wet_samples > 0,
                    "{layers} layer(s): the cell at {x:?} reads dry"
                );
                cell.depth as f64
            })
            .collect();
        let (lo, hi) = depths
            .iter()
            .fold((f64::MAX, 0.0f64), |(lo, hi), &d| (lo.min(d), hi.max(d)));
        println!(
            "{layers} layer(s) of {dx} m: depths {lo:.4} to {hi:.4} m over {} cells",
            depths.len()
        );
        assert!(
            (lo - layers * dx).abs() <= 0.25 * dx && (hi - layers * dx).abs() <= 0.25 * dx,
            "{layers} layer(s): depths {lo} to {hi} m"
        );
    }
}

/// A run with `[maps]` writes every map as an ESRI ASCII grid and a picture, NODATA where the
/// water never was, and `wgsph plot` draws them again for the finished run.
#[test]
fn a_run_writes_its_maps_and_plot_draws_them() {
    let mut sc = tank(0.4, 0.12, 0.04, 0.05, false);
    // The water over the tank's west half only.
    let east = sc
        .particles
        .iter()
        .filter(|p| p.kind == wgsph::scenario::Kind::Fluid && p.pos[0] > 0.2);
    let n_east = east.count();
    assert!(n_east > 0);
    sc.particles
        .retain(|p| p.kind != wgsph::scenario::Kind::Fluid || p.pos[0] < 0.2);
    sc.time.end_s = 0.02;
    sc.time.output_every_s = 0.02;
    let dir = Scratch::new("flood-maps-run");
    let report = wgsph::run::run(
        gpu(),
        &sc,
        &dir,
        &Default::default(),
        &mut LogLines::default(),
    )
    .unwrap();
    assert!(report.stopped.is_none());
    let maps = dir.join("maps");
    for stem in [
        "ground_m",
        "max_depth_m",
        "max_speed_m_s",
        "max_hazard_m2_s",
        "arrival_s",
        "final_depth_m",
        "final_u_m_s",
        "final_v_m_s",
    ] {
        let text = std::fs::read_to_string(maps.join(format!("{stem}.asc"))).unwrap();
        let grid = wgsph::generate::terrain::parse_asc(&text).unwrap();
        assert_eq!(
            (grid.ncols, grid.nrows),
            (sc.maps.as_ref().unwrap().nx, sc.maps.as_ref().unwrap().ny)
        );
        if stem != "ground_m" {
            assert!(maps.join(format!("{stem}.png")).is_file(), "{stem}.png");
        }
    }
    let depth = wgsph::generate::terrain::parse_asc(
        &std::fs::read_to_string(maps.join("max_depth_m.asc")).unwrap(),
    )
    .unwrap();
    let m = sc.maps.as_ref().unwrap();
    for (c, z) in depth.z.iter().enumerate() {
        let [x, y] = m.centre(c);
        let over_water = x > 0.0 && x < 0.2 && y > 0.0 && y < 0.4;
        let far = x > 0.3 || !(-0.01..=0.41).contains(&y);
        if over_water {
            assert!((z - 0.12).abs() <= 0.02, "{x}, {y}: {z}");
        } else if far {
            assert!(z.is_nan(), "{x}, {y}: {z} where the water never was");
        }
    }
    let arrival = wgsph::generate::terrain::parse_asc(
        &std::fs::read_to_string(maps.join("arrival_s.asc")).unwrap(),
    )
    .unwrap();
    assert!(
        arrival.z.contains(&0.0),
        "the water at the start arrived at t = 0"
    );
    let plots = wgsph::plot::plot_run(&dir, &Default::default()).unwrap();
    assert!(
        plots
            .pngs
            .iter()
            .any(|p| p.ends_with("plots/map_max_depth_m.png")),
        "{:?}",
        plots.pngs
    );
}

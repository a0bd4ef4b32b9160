//! `[[surface]]` walls from STL and OBJ files, and fills inside a mesh or over a polygon: the
//! same particles as the boxes they draw, and the loader's diagnostics.

use super::shapes::write_stl;
use super::*;
use crate::generate::surface::tests::cuboid;
use std::path::Path;

/// A spacing f32 holds exactly, so that an STL's corners fall where the lattice puts them.
const DX: f64 = 0.0625;

/// A 3D tank 1 m × 0.5 m × 0.5 m with water 0.25 m deep and `more` appended.
fn tank(more: &str) -> String {
    format!(
        "{}[tank]\nmin_m = [0.0, 0.0, 0.0]\nmax_m = [1.0, 0.5, 0.5]\n[[fluid_block]]\n\
         min_m = [0.0, 0.0, 0.0]\nmax_m = [1.0, 0.5, 0.25]\n{more}\n",
        head_3d(DX)
    )
}

/// The box [lo, hi] as an OBJ in millimetres, turned −90° about z (x → −y) and moved by
/// `shift`: `scale = 0.001`, `rotate_deg = [0, 0, 90]` and `translate_m = shift` put it back.
fn write_obj_mm(path: &Path, (lo, hi): ([f64; 3], [f64; 3]), shift: [f64; 3]) {
    let (v, f) = cuboid(lo, hi);
    let mut text = String::from("# a box, in millimetres\n");
    for p in v {
        let q = [p[0] - shift[0], p[1] - shift[1], p[2] - shift[2]];
        // Turned by −90° about z: (x, y) → (y, −x).
        text.push_str(&format!(
            "v {} {} {}\n",
            1e3 * q[1],
            -1e3 * q[0],
            1e3 * q[2]
        ));
    }
    for t in f {
        text.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    std::fs::write(path, text).unwrap();
}

/// The particles as text, ordered, to compare sets made in another order.
fn sorted(s: &Scenario) -> Vec<String> {
    let mut out: Vec<_> = (s.particles.iter())
        .map(|p| format!("{:?} {:?} {}", p.pos, p.kind, p.rho))
        .collect();
    out.sort();
    out
}

/// The same particles, or the first few of each that the other lacks.
fn assert_same(a: &Scenario, b: &Scenario, what: &str) {
    let (a, b) = (sorted(a), sorted(b));
    let only = |x: &[String], y: &[String]| -> Vec<String> {
        x.iter()
            .filter(|p| y.binary_search(p).is_err())
            .take(5)
            .cloned()
            .collect()
    };
    assert!(
        a == b,
        "{what}: {} against {} particles; only in the first: {:?}; only in the second: {:?}",
        a.len(),
        b.len(),
        only(&a, &b),
        only(&b, &a)
    );
}

const LO: [f64; 3] = [0.375, 0.125, 0.0];
const HI: [f64; 3] = [0.625, 0.3125, 0.375];

/// Issue 59: "a box given as an STL wall gives exactly the particles of the same box
/// obstacle", for every particle treatment (the box is no thicker than the wall's depth, so
/// its whole inside is wall); an OBJ of it in millimetres, turned and moved, placed back by
/// scale, rotate_deg and translate_m, gives them too.
#[test]
fn a_box_given_as_a_mesh_wall_gives_the_particles_of_the_same_box_obstacle() {
    let dir = folder("surface_box");
    write_stl(&dir.join("box.stl"), &cuboid(LO, HI));
    let shift = [0.5, 0.25, 0.0];
    write_obj_mm(&dir.join("box.obj"), (LO, HI), shift);
    for wall in ["dynamic", "fixed_ghost", "repulsive"] {
        let obstacle = load_in(
            &dir,
            &tank(&format!(
                "[[obstacle]]\nmin_m = {LO:?}\nmax_m = {HI:?}\nwall = \"{wall}\"\n"
            )),
        )
        .unwrap();
        if wall == "repulsive" {
            // A repulsive obstacle is one layer; a repulsive surface has its layers: the
            // same only in the fluid's particles.
            continue;
        }
        let stl = load_in(
            &dir,
            &tank(&format!(
                "[[surface]]\nfile = \"box.stl\"\nwall = \"{wall}\"\n"
            )),
        )
        .unwrap();
        assert_same(&stl, &obstacle, wall);
        let obj = load_in(
            &dir,
            &tank(&format!(
                "[[surface]]\nfile = \"box.obj\"\nwall = \"{wall}\"\nscale = 0.001\n\
                 rotate_deg = [0.0, 0.0, 90.0]\ntranslate_m = {shift:?}\n"
            )),
        )
        .unwrap();
        assert_same(&obj, &obstacle, &format!("{wall}, OBJ"));
    }
}

/// An open surface, a ramp across the tank facing up: its wall lies under it, `layers` deep,
/// and water poured above it stays above it. (A fluid block reaching under an open surface
/// keeps its water beyond the wall's layers: behind an open surface is only defined near it.)
#[test]
fn water_stands_on_an_open_ramp_not_under_it() {
    let dir = folder("surface_ramp");
    // From z = 0.05 at x = 0 to z = 0.2 at x = 1, across y, facing up.
    let v = vec![
        [0.0, -0.1, 0.05],
        [1.0, -0.1, 0.2],
        [1.0, 0.6, 0.2],
        [0.0, 0.6, 0.05],
    ];
    let f = vec![[0, 1, 2], [0, 2, 3]];
    write_stl(&dir.join("ramp.stl"), &(v, f));
    let case = format!(
        "{}[tank]\nmin_m = [0.0, 0.0, 0.0]\nmax_m = [1.0, 0.5, 0.5]\n[[surface]]\n\
         file = \"ramp.stl\"\nlayers = 2\n[[fill]]\nseed_m = [0.5, 0.25, 0.3]\nlevel_m = 0.35\n",
        head_3d(DX)
    );
    let s = load_in(&dir, &case).unwrap();
    let ramp = |x: f64| 0.05 + 0.15 * x;
    let (mut wall, mut fluid) = (0, 0);
    for p in &s.particles {
        let [x, y, z] = p.pos;
        let inside = (0.0..1.0).contains(&x) && (0.0..0.5).contains(&y) && z > 0.0;
        if !inside {
            continue;
        }
        // Distance to the ramp's plane, positive above.
        let d = (z - ramp(x)) / (1.0f64 + 0.15 * 0.15).sqrt();
        match p.kind {
            Kind::Fluid => {
                fluid += 1;
                assert!(
                    d > 0.5 * DX * (1.0 - 1e-6),
                    "fluid under the ramp: {:?}",
                    p.pos
                );
            }
            Kind::Wall if d > -2.0 * DX - 1e-9 => {
                wall += 1;
                assert!(d <= 1e-9, "wall above the ramp: {:?}", p.pos);
            }
            _ => {}
        }
    }
    assert!(fluid > 0 && wall > 0, "{fluid} fluid, {wall} wall");
}

/// Water inside a closed mesh, and over a polygon below a level, is the fluid block of the
/// same box.
#[test]
fn a_fill_inside_a_mesh_or_over_a_polygon_is_the_block_it_outlines() {
    let dir = folder("surface_fills");
    let (lo, hi) = ([0.0, 0.0, 0.0], [0.5, 0.25, 0.25]);
    write_stl(&dir.join("lake.stl"), &cuboid(lo, hi));
    let head = format!(
        "{}[tank]\nmin_m = [0.0, 0.0, 0.0]\nmax_m = [1.0, 0.5, 0.5]\n",
        head_3d(DX)
    );
    let block = load_in(
        &dir,
        &format!("{head}[[fluid_block]]\nmin_m = {lo:?}\nmax_m = {hi:?}\n"),
    )
    .unwrap();
    let mesh = load_in(&dir, &format!("{head}[[fill]]\nmesh = \"lake.stl\"\n")).unwrap();
    assert_same(&mesh, &block, "mesh fill");
    let polygon = load_in(
        &dir,
        &format!(
            "{head}[[fill]]\npolygon_m = [[0.0, 0.0], [0.5, 0.0], [0.5, 0.25], [0.0, 0.25]]\n\
             level_m = 0.25\n"
        ),
    )
    .unwrap();
    assert_same(&polygon, &block, "polygon fill");
    // A mesh's level caps its water.
    let capped = load_in(
        &dir,
        &format!("{head}[[fill]]\nmesh = \"lake.stl\"\nlevel_m = 0.125\n"),
    )
    .unwrap();
    let fluid = |s: &Scenario| s.particles.iter().filter(|p| p.kind == Kind::Fluid).count();
    assert_eq!(2 * fluid(&capped), fluid(&block));
}

/// Each bad surface or mesh fill names its field, the file and the fix, and nothing panics.
#[test]
fn bad_meshes_are_refused_with_the_file_and_the_fix() {
    let dir = folder("surface_bad");
    let (v, mut f) = cuboid(LO, HI);
    write_stl(&dir.join("box.stl"), &(v.clone(), f.clone()));
    f[3].swap(1, 2);
    write_stl(&dir.join("flipped.stl"), &(v, f));
    std::fs::write(
        dir.join("bad.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 zero\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(dir.join("box.ply"), "ply\n").unwrap();
    let cases: [(&str, &[&str]); 9] = [
        (
            "[[surface]]\nfile = \"flipped.stl\"",
            &["surface[0].file", "not oriented alike", "Re-Orient"],
        ),
        (
            "[[surface]]\nfile = \"box.stl\"\nscale = 0.001",
            &[
                "surface[0].file",
                "less than two particle spacings",
                "scale",
            ],
        ),
        (
            "[[surface]]\nfile = \"box.stl\"\ntranslate_m = [50.0, 0.0, 0.0]",
            &["surface[0].file", "outside the tank", "translate_m"],
        ),
        (
            "[[surface]]\nfile = \"bad.obj\"",
            &[
                "surface[0].file",
                "bad.obj, line 3",
                "\"zero\" is not a number",
            ],
        ),
        (
            "[[surface]]\nfile = \"box.ply\"",
            &["surface[0].file", "STL (.stl) or Wavefront OBJ"],
        ),
        (
            "[[surface]]\nfile = \"missing.stl\"",
            &["surface[0].file", "missing.stl"],
        ),
        (
            "[[surface]]\nfile = \"box.stl\"\nscale = -1.0",
            &["surface[0].scale"],
        ),
        (
            "[[fill]]\nseed_m = [0.1, 0.1, 0.1]\nmesh = \"box.stl\"\nlevel_m = 0.2",
            &[
                "fill[0]",
                "more than one place",
                "seed_m, mesh or polygon_m",
            ],
        ),
        (
            "[[fill]]\npolygon_m = [[0.0, 0.0], [0.5, 0.0]]\nlevel_m = 0.2",
            &["fill[0].polygon_m", "encloses no area"],
        ),
    ];
    for (more, words) in cases {
        assert_refused(load_in(&dir, &tank(more)), words, more);
    }
    // A surface in a 2D case.
    let e = load_str(
        "dimension = 2\n[particles]\ndx_m = 0.04\n[physics]\nsound_speed_coef = 10.0\n\
         [time]\nend_s = 0.1\noutput_every_s = 0.05\n[[fluid_block]]\nmin_m = [0.0, 0.0]\n\
         max_m = [0.2, 0.2]\n[[surface]]\nfile = \"box.stl\"\n",
        dir.join("c.toml").to_str().unwrap(),
        &[],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("this case is 2D"), "{e}");
}

/// A plate thinner than the kernel's support is built, with a warning that says where and
/// how thin; a closed box whose faces look in says so.
#[test]
fn a_thin_plate_and_a_closed_box_are_reported() {
    let dir = folder("surface_thin");
    write_stl(
        &dir.join("plate.stl"),
        &cuboid([0.25, 0.0, 0.0], [0.3125, 0.5, 0.375]),
    );
    let s = load_in(&dir, &tank("[[surface]]\nfile = \"plate.stl\"\n")).unwrap();
    let thin = s
        .warnings
        .iter()
        .find(|w| w.contains("thinner than the kernel support"));
    assert!(
        thin.is_some_and(|w| w.contains("0.0625 m thick")),
        "{:?}",
        s.warnings
    );
    assert!(
        !s.warnings.iter().any(|w| w.contains("faces look")),
        "{:?}",
        s.warnings
    );
    let s = load_in(
        &dir,
        &tank("[[surface]]\nfile = \"plate.stl\"\nflip = true\n"),
    )
    .unwrap();
    assert!(
        s.warnings.iter().any(|w| w.contains("faces look in")),
        "{:?}",
        s.warnings
    );
}

/// A later fill's water goes around an earlier one's (a wet bed poured after the reservoir
/// beside it), and a fill left out by `enabled = false` is not made.
#[test]
fn a_later_fill_goes_around_the_water_of_an_earlier_one() {
    let head = format!(
        "{}[tank]\nmin_m = [0.0, 0.0, 0.0]\nmax_m = [1.0, 0.5, 0.5]\n\
         [[fill]]\npolygon_m = [[0.0, 0.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5]]\nlevel_m = 0.25\n\
         [[fill]]\nseed_m = [0.75, 0.25, 0.05]\nlevel_m = 0.125\n",
        head_3d(DX)
    );
    let both = load_str(&head, "c.toml", &[]).unwrap();
    let fluid: Vec<[f64; 3]> = (both.particles.iter())
        .filter(|p| p.kind == Kind::Fluid)
        .map(|p| p.pos)
        .collect();
    let mut keys: Vec<_> = fluid.iter().map(|p| p.map(f64::to_bits)).collect();
    keys.sort();
    keys.dedup();
    assert_eq!(keys.len(), fluid.len(), "two fills put water on one point");
    // 8 × 8 × 4 under the reservoir's level, 8 × 8 × 2 beside it.
    assert_eq!(fluid.len(), 8 * 8 * 4 + 8 * 8 * 2);
    let without = load_str(&head, "c.toml", &sets(&["fill[1].enabled=false"])).unwrap();
    let count = without
        .particles
        .iter()
        .filter(|p| p.kind == Kind::Fluid)
        .count();
    assert_eq!(count, 8 * 8 * 4);
}

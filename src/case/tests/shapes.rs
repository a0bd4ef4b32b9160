//! `shape = "mesh"` bodies (an STL file read relative to the case file) and `shape =
//! "polygon"` bodies: their particles and mass properties, and the loader's errors.

use super::*;
use crate::generate::surface::tests::cuboid;
use std::path::Path;

/// A 3D tank half full, with one body described by `body` (a `[[body]]` table's lines).
fn case(body: &str) -> String {
    format!(
        r#"dimension = 3
[particles]
dx_m = 0.0625
[physics]
gravity_m_s2 = [0.0, 0.0, -9.81]
sound_speed_coef = 10.0
[time]
end_s = 0.1
output_every_s = 0.05
[tank]
min_m = [0.0, 0.0, 0.0]
max_m = [1.0, 1.0, 1.0]
[[fluid_block]]
min_m = [0.0, 0.0, 0.0]
max_m = [1.0, 1.0, 0.5]
[[body]]
name = "hull"
density_kg_m3 = 500.0
{body}
"#
    )
}

/// Writes the triangles as a binary STL (f32 coordinates).
pub(super) fn write_stl(path: &Path, (v, f): &(Vec<[f64; 3]>, Vec<[usize; 3]>)) {
    let tris: Vec<stl_io::Triangle> = f
        .iter()
        .map(|t| stl_io::Triangle {
            normal: stl_io::Vector::new([0.0; 3]),
            vertices: t.map(|k| stl_io::Vector::new(v[k].map(|x| x as f32))),
        })
        .collect();
    let mut out = std::fs::File::create(path).unwrap();
    stl_io::write_stl(&mut out, tris.iter()).unwrap();
}

/// A cuboid drawn as an STL or a Wavefront OBJ (on coordinates that f32 holds exactly) is the
/// same body as the box of those corners: the same particles, fluid and domain, the same mass
/// and centre, and the inertia to rounding. Filled and as a shell of fixed ghosts.
#[test]
fn a_cuboid_mesh_is_the_box_body() {
    let dir = folder("mesh_cuboid");
    let (lo, hi) = ([0.375, 0.3125, 0.375], [0.625, 0.6875, 0.75]);
    let (v, f) = cuboid(lo, hi);
    write_stl(&dir.join("hull.stl"), &(v.clone(), f.clone()));
    let obj: String = (v.iter().map(|p| format!("v {} {} {}\n", p[0], p[1], p[2])))
        .chain(
            f.iter()
                .map(|t| format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1)),
        )
        .collect();
    std::fs::write(dir.join("hull.obj"), obj).unwrap();
    let files = ["hull.stl", "hull.obj"];
    for (file, extra) in files.iter().flat_map(|f| {
        ["", "layers = 2\nwall = \"fixed_ghost\""]
            .into_iter()
            .map(move |e| (f, e))
    }) {
        let mesh = load_in(
            &dir,
            &case(&format!("shape = \"mesh\"\nfile = \"{file}\"\n{extra}")),
        )
        .unwrap();
        let bx = load_in(
            &dir,
            &case(&format!(
                "shape = \"box\"\nmin_m = {lo:?}\nmax_m = {hi:?}\n{extra}"
            )),
        )
        .unwrap();
        check_invariants(&mesh);
        assert_eq!(mesh.particles.len(), bx.particles.len(), "{extra}");
        for (p, q) in mesh.particles.iter().zip(&bx.particles) {
            assert_eq!((p.pos, p.vel, p.rho, p.kind), (q.pos, q.vel, q.rho, q.kind));
        }
        assert_eq!(mesh.domain, bx.domain);
        let (m, b) = (&mesh.bodies[0], &bx.bodies[0]);
        assert_eq!(m.particles, b.particles);
        assert!((m.mass - b.mass).abs() < 1e-12 * b.mass);
        assert_eq!(m.center, b.center);
        for a in 0..3 {
            for c in 0..3 {
                assert!(
                    (m.inertia[a][c] - b.inertia[a][c]).abs() < 1e-12 * b.inertia[0][0],
                    "{:?} vs {:?}",
                    m.inertia,
                    b.inertia
                );
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A turned cuboid: mass from the mesh's volume, a full inertia tensor, every body particle
/// inside the surface, and no fluid left within dx/2 of it.
#[test]
fn a_turned_mesh_body_takes_its_mass_properties_from_its_surface() {
    let dir = folder("mesh_turned");
    let (v, f) = cuboid([-0.15, -0.1, -0.1], [0.15, 0.1, 0.1]);
    let a = 0.5f64;
    let turn = |p: [f64; 3]| {
        [
            0.5 + a.cos() * p[0] - a.sin() * p[1],
            0.5 + a.sin() * p[0] + a.cos() * p[1],
            0.55 + p[2],
        ]
    };
    let turned = (v.iter().map(|&p| turn(p)).collect::<Vec<_>>(), f);
    write_stl(&dir.join("turned.stl"), &turned);
    let s = load_in(&dir, &case("shape = \"mesh\"\nfile = \"turned.stl\"")).unwrap();
    check_invariants(&s);
    let b = &s.bodies[0];
    assert!(
        (b.mass - 500.0 * 0.3 * 0.2 * 0.2).abs() < 1e-5 * b.mass,
        "{}",
        b.mass
    );
    assert!(
        b.inertia[0][1].abs() > 1e-3 * b.inertia[2][2],
        "{:?}",
        b.inertia
    );
    // The box's own frame: inside when every coordinate is within its half-size.
    let local = |p: [f64; 3]| {
        let (x, y) = (p[0] - 0.5, p[1] - 0.5);
        [
            a.cos() * x + a.sin() * y,
            -a.sin() * x + a.cos() * y,
            p[2] - 0.55,
        ]
    };
    let half = [0.15, 0.1, 0.1];
    let margin = |p: [f64; 3]| {
        let q = local(p);
        (0..3)
            .map(|k| half[k] - q[k].abs())
            .fold(f64::MAX, f64::min)
    };
    let dx = s.physics.dx;
    let body = &s.particles[b.particles.clone()];
    assert!(body.len() > 10);
    assert!(body.iter().all(|p| margin(p.pos) > 0.0));
    for p in s.particles.iter().filter(|p| p.kind == Kind::Fluid) {
        let q = local(p.pos);
        // Distance from the fluid particle to the box (zero inside).
        let out: f64 = (0..3)
            .map(|k| (q[k].abs() - half[k]).max(0.0).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(out >= 0.5 * dx * (1.0 - 1e-5), "fluid at {:?}", p.pos);
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The error of a case that must be refused.
fn refusal(loaded: Result<Scenario, CaseError>, text: &str) -> String {
    match loaded {
        Ok(_) => panic!("accepted: {text}"),
        Err(e) => e.to_string(),
    }
}

/// `e` names every one of `words` and gives a fix.
fn has(e: &str, words: &[&str]) {
    for w in words {
        assert!(e.contains(w), "`{w}` expected in: {e}");
    }
    assert!(e.contains("fix:"), "no fix in: {e}");
}

#[test]
fn bad_mesh_bodies_are_refused_naming_the_file() {
    let dir = folder("mesh_bad");
    let e = |text: &str| refusal(load_in(&dir, text), text);
    has(
        &e(&case("shape = \"mesh\"\nfile = \"none.stl\"")),
        &[
            "body[0].file",
            "none.stl",
            "cannot read",
            "relative to the case file",
        ],
    );
    let (v, f) = cuboid([0.4; 3], [0.6; 3]);
    write_stl(&dir.join("open.stl"), &(v.clone(), f[2..].to_vec()));
    has(
        &e(&case("shape = \"mesh\"\nfile = \"open.stl\"")),
        &["body[0].file", "open.stl is not closed", "watertight"],
    );
    std::fs::write(
        dir.join("junk.stl"),
        "solid x\nfacet normal 0 0 0\nouter loop\n",
    )
    .unwrap();
    has(
        &e(&case("shape = \"mesh\"\nfile = \"junk.stl\"")),
        &["body[0].file", "junk.stl"],
    );
    has(
        &e(&case("shape = \"mesh\"")),
        &["body[0].file", "is required for a mesh body"],
    );
    write_stl(&dir.join("ok.stl"), &(v, f));
    has(
        &e(&case(
            "shape = \"mesh\"\nfile = \"ok.stl\"\nmin_m = [0.1, 0.1, 0.1]",
        )),
        &["body[0].min_m", "is not used by a mesh body"],
    );
    // A plate thinner than a spacing, turned off the lattice's lines: no lattice point inside.
    let (v, f) = cuboid([-0.2, -0.001, -0.2], [0.2, 0.001, 0.2]);
    let a = 30f64.to_radians();
    let turn = |p: [f64; 3]| {
        [
            0.5 + a.cos() * p[0] - a.sin() * p[1],
            0.5 + a.sin() * p[0] + a.cos() * p[1],
            0.5 + p[2],
        ]
    };
    write_stl(
        &dir.join("thin.stl"),
        &(v.iter().map(|&p| turn(p)).collect(), f),
    );
    has(
        &e(&case("shape = \"mesh\"\nfile = \"thin.stl\"")),
        &["body[0].file", "no particle fits in the shape"],
    );
    // STL is a 3D shape.
    let flat = BASE.to_string()
        + "\n[[body]]\nname = \"b\"\nshape = \"mesh\"\nfile = \"ok.stl\"\nmass_kg = 1.0\n";
    has(&e(&flat), &["body[0].shape", "2D"]);
    std::fs::remove_dir_all(&dir).ok();
}

/// A 2D case (BASE at dx = 0.0625, water to 0.5 m) with one body of the given lines.
fn case_2d(body: &str) -> String {
    format!(
        "{}\n[[body]]\nname = \"b\"\ndensity_kg_m3 = 500.0\n{body}\n",
        BASE.replace("dx_m = 0.1", "dx_m = 0.0625")
    )
}

/// A rectangle drawn as a polygon is the box body of its corners: the same particles (to
/// rounding: the polygon's are placed ring by ring), fluid, mass, centre and inertia.
#[test]
fn a_rectangle_polygon_is_the_box_body() {
    let poly = load_str(
        &case_2d(
            "shape = \"polygon\"\nvertices_m = [[0.5, 0.625], [0.75, 0.625], [0.75, 0.8125], \
             [0.5, 0.8125]]",
        ),
        "c.toml",
        &[],
    )
    .unwrap();
    let bx = load_str(
        &case_2d("shape = \"box\"\nmin_m = [0.5, 0.625]\nmax_m = [0.75, 0.8125]"),
        "c.toml",
        &[],
    )
    .unwrap();
    check_invariants(&poly);
    let (p, b) = (&poly.bodies[0], &bx.bodies[0]);
    assert_eq!(p.particles, b.particles);
    assert_eq!(poly.particles.len(), bx.particles.len());
    assert_eq!(
        poly.particles[..p.particles.start],
        bx.particles[..b.particles.start]
    );
    for q in &poly.particles[p.particles.clone()] {
        assert!(
            bx.particles[b.particles.clone()]
                .iter()
                .any(|r| (0..2).all(|a| (q.pos[a] - r.pos[a]).abs() < 1e-12) && q.kind == r.kind),
            "{:?} is not a box particle",
            q.pos
        );
    }
    assert!((p.mass - b.mass).abs() < 1e-12 * b.mass);
    assert!((0..2).all(|a| (p.center[a] - b.center[a]).abs() < 1e-12));
    assert!((p.inertia[2][2] - b.inertia[2][2]).abs() < 1e-12 * b.inertia[2][2]);
}

#[test]
fn bad_polygon_bodies_are_refused_naming_the_field() {
    let e = |text: &str| refusal(load_str(text, "cases/t.toml", &[]), text);
    has(
        &e(&case_2d(
            "shape = \"polygon\"\nvertices_m = [[0.2, 0.6], [0.4, 0.8], [0.4, 0.6], [0.2, 0.8]]",
        )),
        &[
            "body[0].vertices_m",
            "not a simple outline",
            "in order around the outline",
        ],
    );
    has(
        &e(&case_2d(
            "shape = \"polygon\"\nvertices_m = [[0.2, 0.6], [0.4, 0.6, 0.1], [0.3, 0.8]]",
        )),
        &["body[0].vertices_m[1]", "2 numbers"],
    );
    has(
        &e(&case_2d(
            "shape = \"polygon\"\nvertices_m = [[0.2, 0.6], [0.4, 0.6]]",
        )),
        &["body[0].vertices_m", "at least 3"],
    );
    has(
        &e(&case_2d("shape = \"polygon\"")),
        &["body[0].vertices_m", "is required for a polygon body"],
    );
    // A sliver: no particle fits half a spacing inside it.
    has(
        &e(&case_2d(
            "shape = \"polygon\"\nvertices_m = [[0.2, 0.6], [0.6, 0.6], [0.4, 0.62]]",
        )),
        &["body[0].vertices_m", "no particle fits in the shape"],
    );
    has(
        &e(&case(
            "shape = \"polygon\"\nvertices_m = [[0.2, 0.6], [0.4, 0.6], [0.3, 0.8]]",
        )),
        &["body[0].shape", "3D"],
    );
}

/// Fixed-ghost bodies and obstacles thinner than 4h − dx (0.2625 m here: dx = 0.0625,
/// h = 1.3 dx) load with a warning naming the part, its thickness, the limit and a fix; thicker
/// ones, and thin ones of other wall treatments, load without.
#[test]
fn thin_fixed_ghost_parts_load_with_a_warning() {
    let warnings = |text: &str| load_str(text, "c.toml", &[]).unwrap().warnings;
    let ghost = "wall = \"fixed_ghost\"";
    let thin_box = "shape = \"box\"\nmin_m = [0.6, 0.6]\nmax_m = [0.9, 0.725]";
    let w = warnings(&case_2d(&format!("{thin_box}\n{ghost}")));
    assert_eq!(w.len(), 1, "{w:?}");
    for words in [
        "body[0] ('b') has fixed ghosts and is 0.125 m thick",
        "4h - dx = 0.2625 m",
        "fix: make it at least 0.2625 m thick",
    ] {
        assert!(w[0].contains(words), "{words:?} not in {:?}", w[0]);
    }
    assert!(warnings(&case_2d(thin_box)).is_empty(), "dynamic");
    let thick_box = "shape = \"box\"\nmin_m = [0.55, 0.55]\nmax_m = [0.85, 0.85]";
    assert!(warnings(&case_2d(&format!("{thick_box}\n{ghost}"))).is_empty());

    let circle =
        |r: f64| format!("shape = \"circle\"\ncenter_m = [0.75, 0.75]\nradius_m = {r}\n{ghost}");
    let w = warnings(&case_2d(&circle(0.125)));
    assert!(w.len() == 1 && w[0].contains("is 0.25 m thick"), "{w:?}");
    assert!(warnings(&case_2d(&circle(0.14))).is_empty());

    // A slanted plate 0.115 m thick: measured at its particles, so "about".
    let plate =
        "shape = \"polygon\"\nvertices_m = [[0.55, 0.6], [0.9, 0.75], [0.9, 0.875], [0.55, 0.725]]";
    let w = warnings(&case_2d(&format!("{plate}\n{ghost}")));
    assert!(
        w.len() == 1 && w[0].contains("body[0] ('b') has fixed ghosts and is about 0.1"),
        "{w:?}"
    );
    // A diamond 0.38 m thick (its particles say 0.375).
    let diamond =
        "shape = \"polygon\"\nvertices_m = [[0.72, 0.43], [0.99, 0.7], [0.72, 0.97], [0.45, 0.7]]";
    assert!(warnings(&case_2d(&format!("{diamond}\n{ghost}"))).is_empty());

    // On the lattice (points at (i + 1/2) dx), so that only its thickness warns.
    let obstacle = |max_x: f64| {
        BASE.replace("dx_m = 0.1", "dx_m = 0.0625")
            + &format!("\n[[obstacle]]\nmin_m = [0.625, 0.0]\nmax_m = [{max_x}, 0.3125]\n{ghost}\n")
    };
    let w = warnings(&obstacle(0.8125));
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with(
            "obstacle[0] ([0.625, 0.0] to [0.8125, 0.3125]) has fixed ghosts and is 0.1875"
        ),
        "{w:?}"
    );
    assert!(warnings(&obstacle(0.9375)).is_empty());

    // A mesh, in 3D: a plate 0.125 m thick, and a block 0.4 m thick.
    let dir = folder("mesh_thin");
    let mesh_case = |lo, hi| {
        write_stl(&dir.join("hull.stl"), &cuboid(lo, hi));
        load_in(
            &dir,
            &case(&format!("shape = \"mesh\"\nfile = \"hull.stl\"\n{ghost}")),
        )
        .unwrap()
        .warnings
    };
    let w = mesh_case([0.3, 0.3, 0.6], [0.7, 0.7, 0.725]);
    assert!(
        w.len() == 1 && w[0].contains("body[0] ('hull') has fixed ghosts and is about"),
        "{w:?}"
    );
    assert!(mesh_case([0.3, 0.3, 0.4], [0.7, 0.7, 0.8]).is_empty());
    std::fs::remove_dir_all(&dir).ok();
}

/// Tank walls and shell bodies of dynamic particles or fixed ghosts whose layers are thinner
/// than the kernel support 2h load with a warning that names the field and the layers needed;
/// enough layers, a filled body and repulsive walls (one layer by design) load without.
#[test]
fn wall_layers_short_of_the_kernel_support_load_with_a_warning() {
    let warnings =
        |text: &str, over: &[&str]| load_str(text, "c.toml", &sets(over)).unwrap().warnings;
    let body = "shape = \"box\"\nmin_m = [0.55, 0.55]\nmax_m = [0.85, 0.85]";
    // dx = 0.0625, h = 1.3 dx: 2h = 0.1625 m needs 3 layers; the tank has 3.
    assert!(warnings(&case_2d(body), &[]).is_empty());
    let w = warnings(&case_2d(body), &["particles.h_over_dx=2"]);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with(
            "tank.layers = 3: 3 particle layers (0.1875 m) are less than the kernel \
             support 2h = 0.25 m deep, so fluid beside the tank wall"
        ) && w[0].ends_with("fix: set tank.layers to 4 or more"),
        "{w:?}"
    );
    assert!(warnings(
        &case_2d(body),
        &["particles.h_over_dx=2", "tank.wall=\"repulsive\""]
    )
    .is_empty());
    let w = warnings(
        &case_2d(&format!("{body}\nlayers = 2\nwall = \"fixed_ghost\"")),
        &[],
    );
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with(
            "body[0].layers = 2: 2 particle layers (0.125 m) are less than the kernel support \
             2h = 0.1625 m deep, so fluid beside the body 'b' misses"
        ),
        "{w:?}"
    );
    assert!(warnings(&case_2d(&format!("{body}\nlayers = 3")), &[]).is_empty());
    assert!(warnings(
        &case_2d(&format!("{body}\nlayers = 1\nwall = \"repulsive\"")),
        &[]
    )
    .is_empty());
}

/// A speed the case sets above c0/10 (c0 = 10 sqrt(g 0.5 m) = 22.1 m/s here) loads with a
/// warning naming the fastest field; slower ones load without.
#[test]
fn speeds_above_a_tenth_of_the_sound_speed_load_with_a_warning() {
    let warnings =
        |text: &str, over: &[&str]| load_str(text, "c.toml", &sets(over)).unwrap().warnings;
    let body = |motion: &str| {
        case_2d(&format!(
            "shape = \"box\"\nmin_m = [0.55, 0.55]\nmax_m = [0.85, 0.85]\n[body.motion]\n{motion}"
        ))
    };
    let w = warnings(&body("kind = \"free\"\nvelocity_m_s = [0.0, -3.0]"), &[]);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with(
            "body[0].motion sets a speed of 3 m/s, more than c0/10 = 2.21 m/s (c0 from \
             physics.sound_speed_coef): the water is compressed by about (u/c0)² = 1.83 %"
        ) && w[0].ends_with(
            "fix: raise physics.sound_speed_coef so that c0 is at least 30 m/s (the time \
             step shrinks with it)"
        ),
        "{w:?}"
    );
    assert!(warnings(&body("kind = \"free\"\nvelocity_m_s = [0.0, -2.0]"), &[]).is_empty());
    // A sine of 0.1 m every 0.2 s: 3.14 m/s at its fastest.
    let sine = "kind = \"sine\"\npivot_m = [0.7, 0.7]\ntranslation_m = [0.1, 0.0]\nperiod_s = 0.2";
    let w = warnings(&body(sine), &[]);
    assert!(
        w.len() == 1 && w[0].starts_with("body[0].motion sets a speed of 3.14 m/s"),
        "{w:?}"
    );
    assert!(warnings(&body(sine), &["physics.sound_speed_coef=20"]).is_empty());
    let w = warnings(
        &body("kind = \"free\""),
        &["fluid_block[0].velocity_m_s=[2.5, 0.0]"],
    );
    assert!(
        w.len() == 1 && w[0].starts_with("fluid_block[0].velocity_m_s sets a speed of 2.5 m/s"),
        "{w:?}"
    );
}

/// A fluid block or obstacle whose extent is not close to a whole number of spacings loads with
/// a warning giving what it holds (and, for a block, two spacings that divide it); within 1.5 %
/// it loads without.
#[test]
fn blocks_and_obstacles_that_round_to_other_sizes_load_with_a_warning() {
    let warnings = |over: &[&str]| load_str(BASE, "c.toml", &sets(over)).unwrap().warnings;
    // 0.5 m at dx = 0.1: 5 spacings exactly.
    assert!(warnings(&[]).is_empty());
    // 0.55 m high at dx = 0.1: 6 layers (round half away from zero), 0.6 m of water.
    let w = warnings(&["fluid_block[0].max_m=[0.5, 0.55]"]);
    assert_eq!(w.len(), 1, "{w:?}");
    assert_eq!(
        w[0],
        "fluid_block[0] is 0.55 m along y but is filled with 6 spacings of dx = 0.1 m: 0.6 m \
         of water (+9.1 %), which moves its hydrostatic pressure and wave speed as much; fix: \
         a particles.dx_m that divides 0.55 m (such as 0.0916667 or 0.11), or a block of a \
         whole number of spacings"
    );
    // Both axes, short: 0.44 m holds 4 spacings (0.4 m).
    let w = warnings(&["fluid_block[0].max_m=[0.44, 0.44]"]);
    assert!(
        w.len() == 2 && w[0].contains("along x") && w[1].contains("0.4 m of water (-9.1 %)"),
        "{w:?}"
    );
    // 0.507 m: 5 spacings, 1.4 % short, under the 1.5 % that warns; 0.508 m, 1.6 %, over.
    assert!(warnings(&["fluid_block[0].max_m=[0.507, 0.5]"]).is_empty());
    let w = warnings(&["fluid_block[0].max_m=[0.508, 0.5]"]);
    assert!(
        w.len() == 1 && w[0].contains("0.5 m of water (-1.6 %)"),
        "{w:?}"
    );
    // An obstacle is the lattice points inside its box: 0.6..0.8 holds two (0.2 m), 0.6..0.74
    // one (0.1 m, -29 %).
    let obstacle = |max_x: f64| {
        load_str(
            &format!("{BASE}\n[[obstacle]]\nmin_m = [0.6, 0.0]\nmax_m = [{max_x}, 0.3]\n"),
            "c.toml",
            &[],
        )
        .unwrap()
        .warnings
    };
    assert!(obstacle(0.8).is_empty());
    let w = obstacle(0.74);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with(
            "obstacle[0] is 0.14 m along x but holds 1 lattice points of dx = 0.1 m: its \
             particles span 0.1 m (-28.6 %)"
        ),
        "{w:?}"
    );
}

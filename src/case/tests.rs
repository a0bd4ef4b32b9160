//! Tests of the whole loader: the shipped cases, overrides, and one bad file per error class.

use std::collections::HashMap;

use super::*;
use crate::scenario::{Kind, Motion, Particle, ProbeKind, Viscosity};

const HYDROSTATIC: &str = include_str!("../../cases/hydrostatic_2d.toml");
const DAM_2D: &str = include_str!("../../cases/dam_break_2d.toml");
const DAM_3D: &str = include_str!("../../cases/dam_break_3d.toml");

/// A small valid case; line numbers below refer to it.
const BASE: &str = r#"dimension = 2

[particles]
dx_m = 0.1

[physics]
sound_speed_coef = 10.0

[time]
end_s = 1.0
output_every_s = 0.1

[tank]
min_m = [0.0, 0.0]
max_m = [1.0, 1.0]

[[fluid_block]]
min_m = [0.0, 0.0]
max_m = [0.5, 0.5]

[[probe]]
name = "P1"
kind = "pressure"
point_m = [0.5, 0.05]
"#;

/// A fresh folder for one test's files (`test`: unique among the case tests).
fn folder(test: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("wgsph_case_{test}_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The case text `text` loaded as `dir/c.toml`, so that the files it names are found beside it.
fn load_in(dir: &std::path::Path, text: &str) -> Result<Scenario, CaseError> {
    load_str(text, dir.join("c.toml").to_str().unwrap(), &[])
}

/// The head of a 3D case at spacing `dx`: particles, physics and time (0.1 s).
fn head_3d(dx: f64) -> String {
    format!(
        "dimension = 3\n[particles]\ndx_m = {dx}\n[physics]\nsound_speed_coef = 10.0\n[time]\n\
         end_s = 0.1\noutput_every_s = 0.05\n"
    )
}

/// Asserts that `result` is an error whose message holds every one of `words` and a fix.
fn assert_refused(result: Result<Scenario, CaseError>, words: &[&str], input: &str) {
    let e = match result {
        Ok(_) => panic!("accepted: {input}"),
        Err(e) => e.to_string(),
    };
    for w in words {
        assert!(e.contains(w), "`{w}` expected in: {e}");
    }
    assert!(e.contains("fix:"), "no fix in: {e}");
}

fn sets(s: &[&str]) -> Vec<String> {
    s.iter().map(|s| s.to_string()).collect()
}

/// BASE with `from` replaced by `to` (which must occur).
fn base_with(from: &str, to: &str) -> String {
    assert!(BASE.contains(from), "{from}");
    BASE.replacen(from, to, 1)
}

fn err_of(text: &str, overrides: &[&str]) -> String {
    match load_str(text, "cases/t.toml", &sets(overrides)) {
        Ok(_) => panic!("expected an error for:\n{text}\n{overrides:?}"),
        Err(e) => e.to_string(),
    }
}

/// The error names the file with `line` (if given) and contains every word of `words`.
fn assert_err(text: &str, overrides: &[&str], line: Option<usize>, words: &[&str]) {
    let e = err_of(text, overrides);
    match line {
        Some(l) => assert!(
            e.starts_with(&format!("cases/t.toml:{l}:")),
            "line {l} expected: {e}"
        ),
        None => assert!(e.starts_with("cases/t.toml"), "{e}"),
    }
    for w in words {
        assert!(e.contains(w), "`{w}` expected in: {e}");
    }
    assert!(e.contains("fix:"), "no fix in: {e}");
}

// ---------------------------------------------------------------- shipped cases

/// Common invariants: particles inside the domain, no duplicates, fluid at least a spacing
/// (minus rounding) away from walls, and walls below and on both sides of every fluid column.
fn check_invariants(s: &Scenario) {
    let dx = s.physics.dx;
    let dim = s.physics.dim as usize;
    let v = dim - 1;
    assert!(s
        .particles
        .iter()
        .all(|p| (0..3).all(|a| s.domain.min[a] <= p.pos[a] && p.pos[a] <= s.domain.max[a])));
    assert!(s.particles.iter().all(|p| p.rho.is_finite()
        && p.rho >= s.physics.rho0
        && p.pos.iter().all(|c| c.is_finite())));
    // Hash grid with cell dx.
    let cell = |p: &[f64; 3]| p.map(|c| (c / dx).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<&Particle>> = HashMap::new();
    for p in &s.particles {
        grid.entry(cell(&p.pos)).or_default().push(p);
    }
    let zr = if dim == 3 { -1..=1 } else { 0..=0 };
    for p in &s.particles {
        let c = cell(&p.pos);
        for i in -1..=1 {
            for j in -1..=1 {
                for k in zr.clone() {
                    for q in grid
                        .get(&[c[0] + i, c[1] + j, c[2] + k])
                        .into_iter()
                        .flatten()
                    {
                        if std::ptr::eq(*q, p) {
                            continue;
                        }
                        let d2: f64 = (0..3).map(|a| (p.pos[a] - q.pos[a]).powi(2)).sum();
                        let min = if p.kind != q.kind {
                            0.5 * dx
                        } else {
                            0.99 * dx
                        };
                        assert!(d2.sqrt() >= min - 1e-9, "{p:?} too close to {q:?}");
                    }
                }
            }
        }
    }
    // Walls below and beside the fluid.
    let fluid: Vec<_> = s
        .particles
        .iter()
        .filter(|p| p.kind == Kind::Fluid)
        .collect();
    let walls: Vec<_> = s
        .particles
        .iter()
        .filter(|p| p.kind == Kind::Wall)
        .collect();
    let lowest = walls.iter().map(|p| p.pos[v]).fold(f64::MAX, f64::min);
    let fluid_low = fluid.iter().map(|p| p.pos[v]).fold(f64::MAX, f64::min);
    assert!(lowest < fluid_low);
    for a in 0..v {
        let (fmin, fmax) = fluid.iter().fold((f64::MAX, f64::MIN), |(l, h), p| {
            (l.min(p.pos[a]), h.max(p.pos[a]))
        });
        assert!(
            walls.iter().any(|p| p.pos[a] < fmin),
            "no wall before the fluid along axis {a}"
        );
        assert!(
            walls.iter().any(|p| p.pos[a] > fmax),
            "no wall after the fluid along axis {a}"
        );
    }
    // Hydrostatic: in every fluid column, density decreases upward.
    let mut columns: HashMap<Vec<i64>, Vec<(f64, f64)>> = HashMap::new();
    for p in &fluid {
        let key = (0..v).map(|a| (p.pos[a] / dx).floor() as i64).collect();
        columns.entry(key).or_default().push((p.pos[v], p.rho));
    }
    for col in columns.values_mut() {
        col.sort_by(|a, b| a.0.total_cmp(&b.0));
        assert!(
            col.windows(2).all(|w| w[1].1 < w[0].1),
            "density not decreasing upward: {col:?}"
        );
    }
    assert!((s.physics.particle_mass - s.physics.rho0 * dx.powi(dim as i32)).abs() < 1e-12);
}

#[test]
fn hydrostatic_2d_builds() {
    let s = load_str(HYDROSTATIC, "cases/hydrostatic_2d.toml", &[]).unwrap();
    check_invariants(&s);
    assert_eq!(s.name, "hydrostatic_2d");
    assert_eq!(s.count(Kind::Fluid), 50 * 25);
    // Outer box 56 x 33 minus the inner 50 x 30 cells.
    assert_eq!(s.count(Kind::Wall), 56 * 33 - 50 * 30);
    assert!((s.physics.particle_mass - 0.4).abs() < 1e-12);
    assert!((s.physics.h - 0.026).abs() < 1e-12);
    assert!((s.physics.c0 - 10.0 * (9.81_f64 * 0.5).sqrt()).abs() < 1e-9);
    assert_eq!(s.physics.viscosity, Viscosity::Artificial { alpha: 0.02 });
    assert_eq!(s.physics.gravity, [0.0, -9.81, 0.0]);
    assert_eq!(s.time.probe_every_s, 0.01);
    // The bottom fluid row: hydrostatic density at depth 0.49 m.
    let b = s.physics.tait_b();
    let expect = 1000.0 * (1.0 + 1000.0 * 9.81 * 0.49 / b).powf(1.0 / 7.0);
    let bottom = s
        .particles
        .iter()
        .find(|p| p.kind == Kind::Fluid && (p.pos[1] - 0.01).abs() < 1e-12)
        .unwrap();
    assert!((bottom.rho - expect).abs() < 1e-9);
    // The floor under the water is hydrostatic too; the wall above the water is at rho0.
    assert!(s
        .particles
        .iter()
        .any(|p| p.kind == Kind::Wall && p.pos[1] < 0.0 && p.rho > expect));
    assert!(s
        .particles
        .iter()
        .filter(|p| p.kind == Kind::Wall && p.pos[1] > 0.5)
        .all(|p| p.rho == 1000.0));
    assert_eq!(s.probes.len(), 3);
    assert_eq!(
        s.probes[1].kind,
        ProbeKind::Height {
            base: [0.5, 0.0, 0.0],
            surface: crate::scenario::GaugeSurface::FluidHalf,
        }
    );
    // The floor sensor: the 4 columns within 0.05 m of x = 0.5 (0.47 … 0.53), its radius
    // moved halfway to the next ones (0.45 and 0.55, on the edge, left out).
    let ProbeKind::WallPressure(patch) = s.probes[2].kind else {
        panic!("{:?}", s.probes[2]);
    };
    assert!((patch.area - 0.08).abs() < 1e-12, "{patch:?}");
    assert!((patch.radius - 0.04).abs() < 1e-12, "{patch:?}");
    // The floor's face, half a spacing above its first layer, is the point's.
    assert!(patch.face.abs() < 1e-12, "{patch:?}");
    assert!(s.walls.reactions);
    assert_eq!(s.walls.sensors, vec![patch]);
}

/// Two wall-pressure sensors on the two faces of a block's edge, each within 2h of the other's
/// face, share particles that one of them misses: a warning names both. Apart, or meeting at a
/// concave corner (floor and wall), they do not.
#[test]
fn sensors_meeting_at_an_edge_are_warned() {
    let case = |side_y: f64, floor_x: f64| {
        format!(
            "dimension = 2\n[particles]\ndx_m = 0.02\n[physics]\nsound_speed_m_s = 20.0\n\
             [time]\nend_s = 0.1\noutput_every_s = 0.1\n\
             [tank]\nmin_m = [0.0, 0.0]\nmax_m = [1.0, 0.6]\nopen_top = true\n\
             [[fluid_block]]\nmin_m = [0.0, 0.0]\nmax_m = [0.4, 0.2]\n\
             [[obstacle]]\nmin_m = [0.4, 0.0]\nmax_m = [0.6, 0.3]\n\
             [[probe]]\nname = \"top\"\nkind = \"wall_pressure\"\npoint_m = [0.426, 0.3]\n\
             normal = [0.0, 1.0]\nradius_m = 0.005\n\
             [[probe]]\nname = \"side\"\nkind = \"wall_pressure\"\npoint_m = [0.4, {side_y}]\n\
             normal = [-1.0, 0.0]\nradius_m = 0.005\n\
             [[probe]]\nname = \"floor\"\nkind = \"wall_pressure\"\npoint_m = [{floor_x}, 0.0]\n\
             normal = [0.0, 1.0]\nradius_m = 0.005\n"
        )
    };
    let shared = |side_y: f64, floor_x: f64| -> Vec<String> {
        let s = load_str(&case(side_y, floor_x), "cases/t.toml", &[]).unwrap();
        assert_eq!(s.walls.sensors.len(), 3);
        s.warnings
            .into_iter()
            .filter(|w| w.contains("meet at an edge"))
            .collect()
    };
    let near = shared(0.274, 0.2);
    assert_eq!(near.len(), 1, "{near:?}");
    // The shared particle (0.43, 0.27) lies 1.5 dx behind both faces: the top's, the first.
    assert!(
        near[0].starts_with("probe[1] ('side') and probe[0] ('top') meet"),
        "{near:?}"
    );
    // Low on the side, and the floor sensor in the concave corner beside it.
    assert!(shared(0.02, 0.39).is_empty());
}

/// A wall-pressure probe: its fields, and a patch of wall particles to sum over. Narrower than
/// the spacing, it takes the nearest column, or both when two are as near.
#[test]
fn wall_pressure_probes_are_checked() {
    let wall = |rest: &str| {
        base_with(
            "kind = \"pressure\"\npoint_m = [0.5, 0.05]",
            &format!("kind = \"wall_pressure\"\npoint_m = [0.5, 0.0]\n{rest}"),
        )
    };
    let s = load_str(
        &wall("normal = [0.0, 1.0]\nradius_m = 0.01"),
        "cases/t.toml",
        &[],
    )
    .unwrap();
    let ProbeKind::WallPressure(patch) = s.probes[0].kind else {
        panic!("{:?}", s.probes[0]);
    };
    // Columns at 0.45 and 0.55, both 0.05 from the point; the next at 0.15.
    assert!((patch.area - 0.2).abs() < 1e-12, "{patch:?}");
    assert!((patch.radius - 0.1).abs() < 1e-9, "{patch:?}");
    assert!(s.walls.reactions);
    assert_err(
        &wall("radius_m = 0.01"),
        &[],
        None,
        &["probe[0].normal", "required"],
    );
    assert_err(
        &wall("normal = [0.0, 0.0]\nradius_m = 0.01"),
        &[],
        None,
        &["probe[0].normal", "non-zero"],
    );
    assert_err(
        &wall("normal = [0.0, 1.0]\nradius_m = -0.01"),
        &[],
        None,
        &["probe[0].radius_m", "positive"],
    );
    assert_err(
        &wall("normal = [0.0, 1.0]\nradius_m = 3.0"),
        &[],
        None,
        &["probe[0].radius_m", "20 h"],
    );
    assert_err(
        &wall("normal = [0.0, 1.0]\nradius_m = 0.01"),
        &["tank.wall=\"mirror\""],
        None,
        &["probe[0].kind", "has none", "mirror walls only", "[tank]"],
    );
    assert_err(
        &wall("normal = [0.0, 1.0]\nradius_m = 0.01").replace("[0.5, 0.0]", "[0.5, 0.3]"),
        &[],
        None,
        &["probe[0].point_m", "no wall particle"],
    );
    assert_err(
        &base_with(
            "point_m = [0.5, 0.05]",
            "point_m = [0.5, 0.05]\nradius_m = 0.01",
        ),
        &[],
        None,
        &["probe[0].radius_m", "not used"],
    );
}

#[test]
fn dam_break_2d_builds() {
    let s = load_str(DAM_2D, "cases/dam_break_2d.toml", &[]).unwrap();
    check_invariants(&s);
    assert_eq!(s.count(Kind::Fluid), 40 * 80);
    let b = s
        .particles
        .iter()
        .filter(|p| p.kind == Kind::Fluid)
        .fold([f64::MAX, f64::MIN], |m, p| {
            [m[0].min(p.pos[0]), m[1].max(p.pos[0])]
        });
    assert!((b[0] - 0.00365 / 2.0).abs() < 1e-12 && (b[1] - (0.146 - 0.00365 / 2.0)).abs() < 1e-9);
    assert!(matches!(
        s.probes[0].kind,
        ProbeKind::Front {
            axis: [1.0, 0.0, 0.0],
            continuous: false,
            ..
        }
    ));
    assert!(matches!(
        s.probes[1].kind,
        ProbeKind::Front {
            continuous: true,
            ..
        }
    ));
    assert_eq!(s.time.end_s, 0.6);
    assert!(s.domain.max[0] > 0.584 && s.domain.min[0] < 0.0 && s.domain.max[1] > 0.7);
}

#[test]
fn dam_break_3d_builds() {
    let s = load_str(DAM_3D, "cases/dam_break_3d.toml", &[]).unwrap();
    check_invariants(&s);
    // dx = 0.55/34: the column is exactly 34 layers high (76 x 62 across the tank's 1.0 m).
    assert_eq!(s.count(Kind::Fluid), 76 * 62 * 34);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    // The box: 10 x 25 x 10 lattice points.
    let in_box = s
        .particles
        .iter()
        .filter(|p| {
            p.kind == Kind::Wall
                && p.pos[0] > 0.6
                && p.pos[0] < 0.9
                && p.pos[2] > 0.0
                && p.pos[1] > 0.2
                && p.pos[1] < 0.8
        })
        .count();
    assert_eq!(in_box, 10 * 25 * 10);
    assert_eq!(s.probes.len(), 14);
    // The force sensors on the box, at y = 0.5 between the lattice's columns at 0.493 and
    // 0.510: each takes the one nearest.
    let dx = 0.55 / 34.0;
    for name in ["W1", "W5"] {
        let p = s.probes.iter().find(|p| p.name == name).unwrap();
        let ProbeKind::WallPressure(patch) = p.kind else {
            panic!("{p:?}");
        };
        assert!((patch.area - dx * dx).abs() < 1e-9, "{name}: {patch:?}");
    }
    assert!(s.walls.reactions);
    assert_eq!(s.physics.gravity, [0.0, 0.0, -9.81]);
    assert!((s.physics.h - 1.5 * dx).abs() < 1e-9);
    // At dx = 0.02 the column would round to 28 layers (0.56 m): a warning.
    let coarse = load_str(
        DAM_3D,
        "cases/dam_break_3d.toml",
        &sets(&["particles.dx_m=0.02"]),
    )
    .unwrap();
    assert!(
        coarse.warnings.len() == 1 && coarse.warnings[0].contains("0.56 m of water (+1.8 %)"),
        "{:?}",
        coarse.warnings
    );
    // 160 208 fluid and 143 644 wall particles: the case grew from 179 836 when its dx went
    // from 0.02 to 0.55/34 (the column no longer rounds to 0.56 m).
    assert_eq!(s.particles.len(), 303_852);
}

/// The pressure probe `name`'s point.
fn pressure_point(s: &Scenario, name: &str) -> [f64; 3] {
    match s.probes.iter().find(|p| p.name == name).unwrap().kind {
        ProbeKind::Pressure { point } => point,
        ref k => panic!("{name}: {k:?}"),
    }
}

/// SPHERIC's pressure probes, given on the box's faces (issue 34), sample half a spacing in
/// front of the face its particles have at any dx: at the shipped dx where the probes were
/// (x = 0.8250 + dx/2 and z = 0.1618 + dx/2), and at spacings that round the box to other
/// sizes (0.0324 m: 4 lattice points along x, the box 0.129 m) a spacing in front of its
/// particles' first layer, never inside it.
#[test]
fn pressure_probes_on_faces_follow_the_resolution() {
    let s = load_str(DAM_3D, "cases/dam_break_3d.toml", &[]).unwrap();
    let dx = 0.55 / 34.0;
    let p1 = pressure_point(&s, "P1");
    assert!((p1[0] - (0.8250 + 0.5 * dx)).abs() < 1e-4, "{p1:?}");
    assert_eq!((p1[1], p1[2]), (0.5, 0.021));
    let p5 = pressure_point(&s, "P5");
    assert!((p5[2] - (0.1618 + 0.5 * dx)).abs() < 1e-4, "{p5:?}");
    assert_eq!((p5[0], p5[1]), (0.8035, 0.5));
    for dx in [0.55 / 34.0, 0.0323529, 0.025, 0.0107843] {
        let s = load_str(
            DAM_3D,
            "cases/dam_break_3d.toml",
            &sets(&[&format!("particles.dx_m={dx}")]),
        )
        .unwrap();
        let in_box = |p: &&Particle| {
            p.kind == Kind::Wall
                && (0.6..0.9).contains(&p.pos[0])
                && (0.2..0.8).contains(&p.pos[1])
                && p.pos[2] > 0.0
        };
        let box_particles: Vec<&Particle> = s.particles.iter().filter(in_box).collect();
        let front = box_particles
            .iter()
            .map(|p| p.pos[0])
            .fold(f64::MIN, f64::max);
        let top = box_particles
            .iter()
            .map(|p| p.pos[2])
            .fold(f64::MIN, f64::max);
        for (name, axis, face) in [("P1", 0, front), ("P4", 0, front), ("P5", 2, top)] {
            let x = pressure_point(&s, name)[axis];
            assert!(
                (x - (face + dx)).abs() < 1e-9,
                "dx {dx}: {name} at {x}, face {face}"
            );
        }
        assert!(
            !s.warnings.iter().any(|w| w.contains("starts inside")),
            "dx {dx}: {:?}",
            s.warnings
        );
    }
}

/// A pressure probe inside a wall is told (its point within half a spacing of a wall
/// particle); one in the water or the air beside a wall is not. A probe given by its face
/// needs that face's normal, no point_m, and a particle wall there.
#[test]
fn pressure_probes_inside_walls_and_on_faces_are_checked() {
    let inside = |point: &str| {
        let text = base_with("point_m = [0.5, 0.05]", &format!("point_m = {point}"));
        let s = load_str(&text, "cases/t.toml", &[]).unwrap();
        s.warnings.iter().any(|w| {
            w.contains("probe 'P1' (point_m) starts inside a wall") && w.contains("face_m")
        })
    };
    assert!(inside("[0.53, -0.04]"), "in the floor's first layer");
    assert!(!inside("[0.5, 0.05]"), "in the water");
    assert!(!inside("[0.95, 0.9]"), "in the air beside the right wall");
    let on_floor = base_with(
        "point_m = [0.5, 0.05]",
        "face_m = [0.52, 0.0]\nnormal = [0.0, 1.0]",
    );
    let s = load_str(&on_floor, "cases/t.toml", &[]).unwrap();
    assert_eq!(&pressure_point(&s, "P1")[..2], &[0.52, 0.05]);
    assert_err(
        &base_with(
            "point_m = [0.5, 0.05]",
            "face_m = [0.5, 0.3]\nnormal = [0.0, 1.0]",
        ),
        &[],
        Some(24),
        &["probe[0].face_m", "no wall particle", "point_m"],
    );
    assert_err(
        &base_with("point_m = [0.5, 0.05]", "face_m = [0.5, 0.0]"),
        &[],
        Some(21),
        &["probe[0].normal", "required"],
    );
    assert_err(
        &base_with(
            "point_m = [0.5, 0.05]",
            "point_m = [0.5, 0.05]\nface_m = [0.5, 0.0]\nnormal = [0.0, 1.0]",
        ),
        &[],
        Some(24),
        &["probe[0].point_m", "face_m and normal"],
    );
}

#[test]
fn load_reads_files_and_reports_missing_ones() {
    let dir = std::env::temp_dir().join(format!("wgsph_case_test_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("my_case.toml");
    std::fs::write(&path, BASE).unwrap();
    let s = load(&path, &[]).unwrap();
    assert_eq!(s.name, "my_case");
    let e = load(&dir.join("nope.toml"), &[]).unwrap_err().to_string();
    assert!(e.contains("nope.toml") && e.contains("cannot read"), "{e}");
    // An endless file is refused after a bounded read (it used to hang).
    if std::path::Path::new("/dev/zero").exists() {
        let e = load(std::path::Path::new("/dev/zero"), &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("/dev/zero") && e.contains("longer than 16 MiB"),
            "{e}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

// ---------------------------------------------------------------- overrides

#[test]
fn overrides_change_the_case() {
    let s = load_str(
        DAM_2D,
        "d.toml",
        &sets(&[
            "particles.dx_m=0.0073",
            "time.end_s=0.5",
            "physics.viscosity=laminar",
            "physics.alpha=nan",
        ]),
    );
    // alpha with laminar is refused, even when set to anything.
    assert!(s.unwrap_err().to_string().contains("physics.alpha"));
    let s = load_str(
        BASE,
        "b.toml",
        &sets(&[
            "particles.dx_m=0.05",
            "time.end_s=0.5",
            "physics.viscosity=\"laminar\"",
            "physics.nu_m2_s=1e-6",
            "probe[0].point_m=[0.25, 0.1]",
        ]),
    )
    .unwrap();
    assert_eq!(s.count(Kind::Fluid), 100);
    assert_eq!(s.time.end_s, 0.5);
    assert_eq!(s.physics.viscosity, Viscosity::Laminar { nu: 1e-6 });
    assert_eq!(
        s.probes[0].kind,
        ProbeKind::Pressure {
            point: [0.25, 0.1, 0.0]
        }
    );
    let s = load_str(
        BASE,
        "b.toml",
        &sets(&["tank.open_top=false", "fluid_block.0.velocity_m_s=[1, 0]"]),
    )
    .unwrap();
    assert!(s
        .particles
        .iter()
        .any(|p| p.kind == Kind::Wall && p.pos[1] > 1.0));
    assert!(s
        .particles
        .iter()
        .filter(|p| p.kind == Kind::Fluid)
        .all(|p| p.vel == [1.0, 0.0, 0.0]));
}

/// The street flood without its building, from the shipped file: the building (obstacle[3])
/// and its front sensor (probe[5]) left out with `--set`; the sensor left in is refused; an
/// obstacle or probe after one left out keeps its index in messages.
#[test]
fn obstacles_and_probes_can_be_left_out() {
    let text = std::fs::read_to_string("cases/street_flood_3d.toml").unwrap();
    let coarse = "particles.dx_m=0.04";
    let with = load_str(&text, "s.toml", &sets(&[coarse])).unwrap();
    let without = sets(&[
        coarse,
        "obstacle[3].enabled=false",
        "probe[5].enabled=false",
    ]);
    let without = load_str(&text, "s.toml", &without).unwrap();
    let walls = |s: &Scenario| s.count(Kind::Wall);
    // The building's particles: the wall particles in its box (x 0.8–1 m, y 0–0.2 m, above
    // the street), and no other, are gone.
    let building = |s: &Scenario| {
        (s.particles.iter())
            .filter(|p| p.kind == Kind::Wall)
            .filter(|p| {
                (0.79..1.01).contains(&p.pos[0])
                    && (0.001..0.21).contains(&p.pos[1])
                    && p.pos[2] > 0.0
            })
            .count()
    };
    assert!(building(&with) > 100, "{}", building(&with));
    assert_eq!(building(&without), 0);
    assert_eq!(walls(&with) - walls(&without), building(&with));
    assert_eq!(without.count(Kind::Fluid), with.count(Kind::Fluid));
    let names = |s: &Scenario| s.probes.iter().map(|p| p.name.clone()).collect::<Vec<_>>();
    assert!(names(&with).contains(&"front".to_string()));
    assert_eq!(names(&without).len() + 1, names(&with).len());
    assert!(!names(&without).contains(&"front".to_string()));
    // Left in, the sensor of a building that is not there finds the street's floor along its
    // normal, not a face: refused, named by its place in the file also with a probe before it
    // left out.
    let left_in = sets(&[
        coarse,
        "obstacle[3].enabled=false",
        "probe[0].enabled=false",
    ]);
    let Err(e) = load_str(&text, "s.toml", &left_in) else {
        panic!("a sensor with no face was accepted");
    };
    let e = e.to_string();
    assert!(e.contains("probe[5].point_m"), "{e}");
    // The obstacle after the one left out keeps its index in messages.
    assert!(
        (without.warnings.iter()).any(|w| w.starts_with("obstacle[4] is 0.06 m along x")),
        "{:?}",
        without.warnings
    );
    assert_err(
        &base_with(
            "[[probe]]",
            "[[obstacle]]\nmin_m = [0.6, 0.6]\nmax_m = [0.8, 0.8]\nenabled = false\n\n\
             [[obstacle]]\nmin_m = [0.6, 0.6]\nmax_m = [0.8, 0.6001]\n\n[[probe]]",
        ),
        &[],
        None,
        &["obstacle[1].max_m", "too thin"],
    );
}

#[test]
fn override_errors_name_the_set() {
    assert_err(
        BASE,
        &["particles.dxm=0.01"],
        None,
        &[
            "--set particles.dxm=0.01",
            "particles.dxm",
            "unknown field",
            "dx_m, h_over_dx, kernel",
        ],
    );
    assert_err(
        BASE,
        &["partcles.dx_m=0.01"],
        None,
        &["partcles", "unknown field", "particles"],
    );
    assert_err(
        BASE,
        &["particles.dx_m=-1"],
        None,
        &["particles.dx_m = -1 (from --set particles.dx_m=-1)", "> 0"],
    );
    assert_err(
        BASE,
        &["particles.dx_m=abc"],
        None,
        &["particles.dx_m", "--set particles.dx_m=abc", "wrong type"],
    );
    assert_err(
        BASE,
        &["particles.kernel=gauss"],
        None,
        &["particles.kernel", "\"cubic_spline\", \"wendland_c2\""],
    );
    assert_err(BASE, &["dx_m"], None, &["--set dx_m", "KEY=VALUE"]);
    assert_err(BASE, &["probe[4].name=x"], None, &["probe[4]", "1 entries"]);
    assert_err(
        BASE,
        &["domain.min_m=[0,0]"],
        None,
        &["domain.max_m", "--set domain.min_m=[0,0]", "missing"],
    );
    // An error elsewhere in the file still gets its line.
    let text = base_with("end_s = 1.0", "end_s = 0.0");
    assert_err(
        &text,
        &["particles.dx_m=0.05"],
        Some(10),
        &["time.end_s = 0", "> 0"],
    );
}

#[test]
fn every_documented_field_exists_in_the_schema() {
    // Each leaf of the field-help table, set with its example, must not be an unknown field.
    let full = DAM_3D;
    for h in schema::FIELDS {
        if !h.example.contains('=') || h.example.starts_with('[') {
            continue;
        }
        let value = h.example.split_once('=').unwrap().1.trim();
        let mut key = h.path.replace("[]", "[0]");
        // Motion fields are shared by [tank.motion] and [body.motion].
        if key.starts_with("motion.") {
            key = format!("tank.{key}");
        }
        let r = load_str(full, "f.toml", &[format!("{key}={value}")]);
        if let Err(e) = r {
            assert!(!e.to_string().contains("unknown field"), "{key}: {e}");
        }
    }
}

// ---------------------------------------------------------------- bad files

#[test]
fn syntax_errors_give_line_and_column() {
    let text = base_with("dx_m = 0.1", "dx_m = = 0.1");
    let e = err_of(&text, &[]);
    assert!(e.starts_with("cases/t.toml:4:"), "{e}");
    assert!(e.contains("syntax") && e.contains("dx_m = = 0.1"), "{e}");
    let e = err_of(&base_with("[tank]", "[tank"), &[]);
    assert!(e.starts_with("cases/t.toml:13:"), "{e}");
    let e = err_of(&base_with("end_s = 1.0", "end_s = 1.0\nend_s = 2.0"), &[]);
    assert!(
        e.starts_with("cases/t.toml:11:") && e.contains("duplicate"),
        "{e}"
    );
}

#[test]
fn unknown_fields_list_the_allowed_ones() {
    assert_err(
        &base_with("dx_m = 0.1", "dx_m = 0.1\ndxx = 3"),
        &[],
        Some(5),
        &["particles.dxx", "unknown field", "dx_m, h_over_dx, kernel"],
    );
    assert_err(
        &base_with("dimension = 2", "dimension = 2\nsolver = 1"),
        &[],
        Some(2),
        &["solver", "top level", "fluid_block"],
    );
    assert_err(
        &base_with("kind = \"pressure\"", "kind = \"pressure\"\npoint = [1, 2]"),
        &[],
        Some(24),
        &["probe[0].point", "point_m"],
    );
    assert_err(
        &format!("{BASE}\n[output]\nformat = \"vtu\"\n"),
        &[],
        Some(26),
        &["output", "unknown field"],
    );
}

#[test]
fn missing_fields_are_named() {
    assert_err(
        &base_with("dx_m = 0.1\n", ""),
        &[],
        Some(3),
        &["particles.dx_m", "missing", "dx_m = 0.01"],
    );
    assert_err(
        &base_with("end_s = 1.0\n", ""),
        &[],
        Some(9),
        &["time.end_s", "missing"],
    );
    assert_err(
        &base_with("dimension = 2\n", ""),
        &[],
        None,
        &["dimension", "missing"],
    );
    assert_err(
        &base_with("max_m = [0.5, 0.5]\n", ""),
        &[],
        Some(17),
        &["fluid_block[0].max_m", "missing"],
    );
    assert_err(
        &base_with("sound_speed_coef = 10.0\n", ""),
        &[],
        Some(6),
        &["physics.sound_speed_coef", "exactly one"],
    );
    assert_err("", &[], None, &["missing"]);
    let no_blocks = BASE.replace(
        "[[fluid_block]]\nmin_m = [0.0, 0.0]\nmax_m = [0.5, 0.5]\n",
        "",
    );
    assert_err(&no_blocks, &[], None, &["fluid_block", "at least one"]);
}

#[test]
fn wrong_types_are_named() {
    assert_err(
        &base_with("dx_m = 0.1", "dx_m = \"0.1\""),
        &[],
        Some(4),
        &["particles.dx_m = \"0.1\"", "wrong type", "found a string"],
    );
    assert_err(
        &base_with("dimension = 2", "dimension = 2.0"),
        &[],
        Some(1),
        &["dimension", "wrong type"],
    );
    assert_err(
        &base_with("max_m = [1.0, 1.0]", "max_m = [1.0, \"a\"]"),
        &[],
        Some(15),
        &["tank.max_m[1]", "wrong type"],
    );
    assert_err(
        &base_with("max_m = [1.0, 1.0]", "max_m = 1.0"),
        &[],
        Some(15),
        &["tank.max_m", "wrong type"],
    );
    let tankless = base_with("[tank]\nmin_m = [0.0, 0.0]\nmax_m = [1.0, 1.0]\n", "");
    assert_err(
        &format!("tank = 3\n{tankless}"),
        &[],
        Some(1),
        &["tank = 3", "wrong type", "found an integer"],
    );
}

/// Out-of-range numbers: (the line of [`BASE`] to replace, its replacement, the line the error
/// names, words the message contains).
const BAD_NUMBERS: &[(&str, &str, usize, &[&str])] = &[
    (
        "dx_m = 0.1",
        "dx_m = -0.01",
        4,
        &["particles.dx_m = -0.01", "must be > 0", "spacing"],
    ),
    (
        "dx_m = 0.1",
        "dx_m = 0.0",
        4,
        &["particles.dx_m = 0", "> 0"],
    ),
    (
        "dx_m = 0.1",
        "dx_m = nan",
        4,
        &["particles.dx_m = NaN", "finite"],
    ),
    (
        "dx_m = 0.1",
        "dx_m = inf",
        4,
        &["particles.dx_m = inf", "finite"],
    ),
    (
        "dx_m = 0.1",
        "dx_m = 0.1\nh_over_dx = 3.5",
        5,
        &["particles.h_over_dx = 3.5", "[1, 3]"],
    ),
    (
        "dx_m = 0.1",
        "dx_m = 0.1\nh_over_dx = 0.5",
        5,
        &["particles.h_over_dx", "[1, 3]"],
    ),
    (
        "dx_m = 0.1",
        "dx_m = 0.1\nid_low_bits = 29",
        5,
        &[
            "particles.id_low_bits = 29",
            "between 1 and 28",
            "leave it out",
        ],
    ),
    (
        "dx_m = 0.1",
        "dx_m = 0.1\nid_low_bits = 0",
        5,
        &["particles.id_low_bits = 0", "between 1 and 28"],
    ),
    ("end_s = 1.0", "end_s = 0.0", 10, &["time.end_s", "> 0"]),
    ("end_s = 1.0", "end_s = -inf", 10, &["time.end_s", "finite"]),
    (
        "output_every_s = 0.1",
        "output_every_s = 0",
        11,
        &["time.output_every_s", "> 0"],
    ),
    (
        "output_every_s = 0.1",
        "output_every_s = 0.1\nprobe_every_s = 0.2",
        12,
        &["time.probe_every_s", "(0, 0.1]"],
    ),
    (
        "output_every_s = 0.1",
        "output_every_s = 0.1\ncfl = 1.5",
        12,
        &["time.cfl", "(0, 1]"],
    ),
    (
        "output_every_s = 0.1",
        "output_every_s = 0.1\ncfl = 0",
        12,
        &["time.cfl", "(0, 1]"],
    ),
    (
        "output_every_s = 0.1",
        "output_every_s = 0.1\ndensity_variation_warn = 0",
        12,
        &["time.density_variation_warn", "(0, 1]"],
    ),
    (
        "output_every_s = 0.1",
        "output_every_s = 0.1\ndensity_variation_warn = 0.05\ndensity_variation_stop = 0.05",
        13,
        &[
            "time.density_variation_stop",
            "(0.05, 10]",
            "above density_variation_warn = 0.05",
        ],
    ),
    (
        "output_every_s = 0.1",
        "output_every_s = 0.1\noutput_boundary = \"firs\"",
        12,
        &["time.output_boundary = \"firs\"", "\"every\", \"first\""],
    ),
    (
        "output_every_s = 0.1",
        "output_every_s = 0.1\noverlap_exchange = true",
        12,
        &["time.overlap_exchange", "\"auto\""],
    ),
    (
        "sound_speed_coef = 10.0",
        "sound_speed_coef = 10.0\nrho0_kg_m3 = 0",
        8,
        &["physics.rho0_kg_m3", "> 0"],
    ),
    (
        "sound_speed_coef = 10.0",
        "sound_speed_coef = -1.0",
        7,
        &["physics.sound_speed_coef", "> 0"],
    ),
    (
        "sound_speed_coef = 10.0",
        "sound_speed_coef = 10.0\ndelta_sph = 2",
        8,
        &["physics.delta_sph", "[0, 1]"],
    ),
    (
        "sound_speed_coef = 10.0",
        "sound_speed_coef = 10.0\ndelta_sph = 0\ndelta_sph_form = \"fourtakas\"",
        9,
        &[
            "physics.delta_sph_form",
            "delta_sph = 0",
            "remove delta_sph_form",
        ],
    ),
    (
        "sound_speed_coef = 10.0",
        "sound_speed_coef = 10.0\ndelta_sph_form = \"antuono\"",
        8,
        &[
            "physics.delta_sph_form = \"antuono\"",
            "\"fourtakas\", \"molteni_colagrossi\"",
        ],
    ),
    (
        "sound_speed_coef = 10.0",
        "sound_speed_coef = 10.0\ngamma = 0.5",
        8,
        &["physics.gamma", "[1, 10]"],
    ),
    (
        "sound_speed_coef = 10.0",
        "sound_speed_coef = 10.0\nalpha = -0.1",
        8,
        &["physics.alpha", "[0, 1]"],
    ),
    (
        "max_m = [1.0, 1.0]",
        "max_m = [1.0, 1.0]\nlayers = 0",
        16,
        &["tank.layers = 0", "between 1 and 8"],
    ),
    (
        "max_m = [1.0, 1.0]",
        "max_m = [1.0, 1.0]\nlayers = 99999999999",
        16,
        &["tank.layers", "between 1 and 8"],
    ),
    (
        "dimension = 2",
        "dimension = 4",
        1,
        &["dimension = 4", "2 or 3"],
    ),
    (
        "point_m = [0.5, 0.05]",
        "point_m = [0.5, nan]",
        24,
        &["probe[0].point_m[1] = NaN", "finite"],
    ),
];

/// The weakly-compressible limits: ±3 % warns and ±10 % stops by default; a warning limit of
/// its own moves the stop to twice it when that is higher.
#[test]
fn density_variation_limits_default_and_follow_the_warning() {
    let t = |set: &[&str]| load_str(BASE, "cases/t.toml", &sets(set)).unwrap().time;
    let d = t(&[]);
    assert_eq!(
        (d.density_variation_warn, d.density_variation_stop),
        (0.03, 0.1)
    );
    let w = t(&["time.density_variation_warn=0.2"]);
    assert_eq!(
        (w.density_variation_warn, w.density_variation_stop),
        (0.2, 0.4)
    );
    let s = t(&["time.density_variation_stop=0.5"]);
    assert_eq!(
        (s.density_variation_warn, s.density_variation_stop),
        (0.03, 0.5)
    );
}

#[test]
fn bad_numbers_are_refused() {
    for (from, to, line, words) in BAD_NUMBERS {
        assert_err(&base_with(from, to), &[], Some(*line), words);
    }
}

#[test]
fn vectors_of_the_wrong_length_are_refused() {
    assert_err(
        &base_with(
            "min_m = [0.0, 0.0]\nmax_m = [1.0, 1.0]",
            "min_m = [0.0, 0.0, 0.0]\nmax_m = [1.0, 1.0]",
        ),
        &[],
        Some(14),
        &[
            "tank.min_m",
            "3 components",
            "2D case (dimension = 2) needs 2",
        ],
    );
    assert_err(
        &base_with("point_m = [0.5, 0.05]", "point_m = []"),
        &[],
        Some(24),
        &["probe[0].point_m", "0 components"],
    );
    assert_err(
        &base_with(
            "sound_speed_coef = 10.0",
            "sound_speed_coef = 10.0\ngravity_m_s2 = [0.0, 0.0, -9.81]",
        ),
        &[],
        Some(8),
        &["physics.gravity_m_s2", "3 components"],
    );
    assert_err(
        &base_with("dimension = 2", "dimension = 3"),
        &[],
        Some(14),
        &[
            "tank.min_m",
            "2 components",
            "3D case (dimension = 3) needs 3",
        ],
    );
}

#[test]
fn unknown_enum_strings_list_the_allowed_ones() {
    assert_err(
        &base_with("dx_m = 0.1", "dx_m = 0.1\nkernel = \"gaussian\""),
        &[],
        Some(5),
        &[
            "particles.kernel = \"gaussian\"",
            "\"cubic_spline\", \"wendland_c2\"",
        ],
    );
    assert_err(
        &base_with("kind = \"pressure\"", "kind = \"velocity\""),
        &[],
        Some(23),
        &["probe[0].kind", "\"pressure\", \"height\", \"front\""],
    );
    assert_err(
        &base_with("max_m = [1.0, 1.0]", "max_m = [1.0, 1.0]\nwall = \"mdbc\""),
        &[],
        Some(16),
        &["tank.wall", "\"dynamic\""],
    );
    assert_err(
        &base_with(
            "sound_speed_coef = 10.0",
            "sound_speed_coef = 10.0\nviscosity = \"sps\"",
        ),
        &[],
        Some(8),
        &["physics.viscosity", "\"artificial\", \"laminar\""],
    );
}

#[test]
fn options_that_do_not_go_together() {
    assert_err(
        &base_with(
            "sound_speed_coef = 10.0",
            "sound_speed_coef = 10.0\nsound_speed_m_s = 20.0",
        ),
        &[],
        Some(7),
        &["both"],
    );
    assert_err(
        &base_with(
            "sound_speed_coef = 10.0",
            "sound_speed_coef = 10.0\nnu_m2_s = 1e-6",
        ),
        &[],
        Some(8),
        &["physics.nu_m2_s", "artificial"],
    );
    assert_err(
        &base_with(
            "sound_speed_coef = 10.0",
            "sound_speed_coef = 10.0\nviscosity = \"laminar\"",
        ),
        &[],
        Some(6),
        &["physics.nu_m2_s", "required"],
    );
    assert_err(
        &base_with(
            "sound_speed_coef = 10.0",
            "sound_speed_coef = 10.0\ngravity_m_s2 = [0.0, 0.0]",
        ),
        &[],
        Some(7),
        &["physics.sound_speed_coef", "sound_speed_m_s"],
    );
    assert_err(
        &base_with(
            "point_m = [0.5, 0.05]",
            "point_m = [0.5, 0.05]\nbase_m = [0.5, 0.0]",
        ),
        &[],
        Some(25),
        &["probe[0].base_m", "not used"],
    );
    assert_err(
        &base_with(
            "kind = \"pressure\"\npoint_m = [0.5, 0.05]",
            "kind = \"front\"\norigin_m = [0.0, 0.0]",
        ),
        &[],
        Some(21),
        &["probe[0].axis", "required"],
    );
    assert_err(
        &base_with(
            "kind = \"pressure\"\npoint_m = [0.5, 0.05]",
            "kind = \"front\"\norigin_m = [0.0, 0.0]\naxis = [0.0, 0.0]",
        ),
        &[],
        Some(25),
        &["probe[0].axis", "non-zero"],
    );
    assert_err(
        &base_with(
            "point_m = [0.5, 0.05]",
            "point_m = [0.5, 0.05]\ncontinuous = true",
        ),
        &[],
        Some(25),
        &["probe[0].continuous", "not used by a \"pressure\" probe"],
    );
    assert_err(
        &base_with("name = \"P1\"", "name = \"P 1\""),
        &[],
        Some(22),
        &["probe[0].name", "letters"],
    );
    assert_err(
        &format!("{BASE}[[probe]]\nname = \"P1\"\nkind = \"height\"\nbase_m = [0.1, 0.0]\n"),
        &[],
        Some(26),
        &["probe[1].name", "probe[0] already"],
    );
    assert_err(
        &base_with("dimension = 2", "dimension = 2\nname = \"\""),
        &[],
        Some(2),
        &["name", "non-empty"],
    );
}

#[test]
fn geometry_errors() {
    // Fluid outside the tank.
    assert_err(
        &base_with("max_m = [0.5, 0.5]", "max_m = [1.5, 0.5]"),
        &[],
        Some(19),
        &["fluid_block[0].max_m", "leaves the tank", "along x"],
    );
    // Tank min above max.
    assert_err(
        &base_with("max_m = [1.0, 1.0]", "max_m = [1.0, -1.0]"),
        &[],
        Some(15),
        &["tank.max_m", "not above min_m[1]"],
    );
    // A block too thin for one particle.
    assert_err(
        &base_with("max_m = [0.5, 0.5]", "max_m = [0.5, 0.04]"),
        &[],
        Some(19),
        &["fluid_block[0].max_m", "too thin", "along y"],
    );
    // Overlapping blocks.
    assert_err(
        &format!("{BASE}[[fluid_block]]\nmin_m = [0.4, 0.0]\nmax_m = [0.8, 0.2]\n"),
        &[],
        Some(25),
        &["fluid_block[1]", "overlaps fluid_block[0]"],
    );
    // Obstacle too thin.
    assert_err(
        &format!("{BASE}[[obstacle]]\nmin_m = [0.61, 0.0]\nmax_m = [0.64, 0.2]\n"),
        &[],
        Some(27),
        &["obstacle[0].max_m", "too thin"],
    );
    // Probe outside the domain.
    assert_err(
        &base_with("point_m = [0.5, 0.05]", "point_m = [0.5, 5.0]"),
        &[],
        Some(24),
        &["probe[0].point_m", "outside the default domain"],
    );
    // Fluid outside a given domain, tank walls outside a given domain.
    let with_domain =
        |min: &str, max: &str| format!("{BASE}[domain]\nmin_m = {min}\nmax_m = {max}\n");
    assert_err(
        &with_domain("[0.1, -1.0]", "[2.0, 2.0]"),
        &[],
        Some(17),
        &["fluid_block[0]", "leaves the domain"],
    );
    assert_err(
        &with_domain("[-0.1, -0.1]", "[2.0, 2.0]"),
        &[],
        Some(13),
        &["tank", "leave the domain"],
    );
    // Too many particles.
    assert_err(
        &base_with("dx_m = 0.1", "dx_m = 1e-5"),
        &[],
        Some(4),
        &["particles.dx_m", "2500000000 fluid", "200 million"],
    );
    assert_err(
        &base_with("max_m = [0.5, 0.5]", "max_m = [0.5, 0.5]\n[tank2]"),
        &[],
        Some(20),
        &["tank2", "unknown field"],
    );
}

#[test]
fn cases_without_tank_and_with_obstacles() {
    let text = "dimension = 3\n[particles]\ndx_m = 0.1\n[physics]\nsound_speed_m_s = 20.0\n\
                [time]\nend_s = 1.0\noutput_every_s = 0.1\n\
                [[fluid_block]]\nmin_m = [0.0, 0.0, 0.0]\nmax_m = [1.0, 0.5, 0.5]\nvelocity_m_s = \
                [1.0, 0.0, 0.0]\n\
                [[obstacle]]\nmin_m = [0.2, 0.0, 0.0]\nmax_m = [0.4, 0.2, 0.2]\n\
                [[obstacle]]\nmin_m = [0.3, 0.0, 0.0]\nmax_m = [0.5, 0.2, 0.2]\n";
    let s = load_str(text, "x.toml", &[]).unwrap();
    assert_eq!(s.physics.c0, 20.0);
    // Obstacle lattice points 0.25..0.45 along x (overlap counted once), 0.05, 0.15 along y, z.
    assert_eq!(s.count(Kind::Wall), 3 * 2 * 2);
    // Fluid removed in and next to the obstacles: x < 0.55 for y, z < 0.25.
    // Fluid on the obstacle's lattice points is removed; its lattice neighbours (dx away) stay.
    assert!(s
        .particles
        .iter()
        .filter(|p| p.kind == Kind::Fluid)
        .all(|p| !(p.pos[0] > 0.2 && p.pos[0] < 0.5 && p.pos[1] < 0.2 && p.pos[2] < 0.2)));
    assert_eq!(s.count(Kind::Fluid), 10 * 5 * 5 - 3 * 2 * 2);
    // Default domain: the fluid's box, raised by its height, plus 2 dx.
    assert!(
        (s.domain.max[2] - (0.5 + 0.5 + 0.2)).abs() < 1e-12
            && (s.domain.min[0] + 0.2).abs() < 1e-12
    );
}

#[test]
fn nothing_panics_on_hostile_values() {
    let numbers = [
        "nan",
        "inf",
        "-inf",
        "0",
        "-1",
        "1e308",
        "-1e308",
        "1e-308",
        "1e15",
        "99999999999999",
        "\"x\"",
        "[]",
        "[nan, nan]",
        "[1e308, -1e308]",
        "true",
        "{}",
    ];
    // Every number (and vector) of BASE, and of a 3D variant, replaced by each hostile value.
    let mut targets: Vec<(String, Vec<(usize, usize)>)> = Vec::new();
    for text in [BASE.to_string(), DAM_3D.to_string()] {
        let mut spans = Vec::new();
        for (start, line) in text
            .match_indices('\n')
            .map(|(i, _)| i + 1)
            .chain([0])
            .map(|s| (s, &text[s..]))
        {
            let line = line.lines().next().unwrap_or("");
            if line.starts_with('#') {
                continue;
            }
            if let Some(eq) = line.find("= ") {
                spans.push((start + eq + 2, start + line.len()));
            }
        }
        targets.push((text, spans));
    }
    let mut n = 0;
    for (text, spans) in &targets {
        for &(a, b) in spans {
            for v in numbers {
                let t = format!("{}{}{}", &text[..a], v, &text[b..]);
                let _ = load_str(&t, "h.toml", &[]);
                n += 1;
            }
        }
    }
    for v in numbers {
        for key in [
            "particles.dx_m",
            "tank.max_m",
            "fluid_block[0].max_m",
            "probe[0].point_m",
            "physics.gravity_m_s2",
            "time.end_s",
            "obstacle.x",
            "x[0].y",
        ] {
            let _ = load_str(BASE, "h.toml", &[format!("{key}={v}")]);
        }
    }
    assert!(n > 100);
}

mod buildings;
mod fill;
mod maps;
mod open_boundaries;
mod shapes;
mod solids;
mod surfaces;
mod terrain;
mod walls;

mod density_filter;

// ---------------------------------------------------------------- bodies and moving tanks

const FLOATING: &str = include_str!("../../cases/floating_box_2d.toml");
const WATER_ENTRY: &str = include_str!("../../cases/water_entry_cylinder_2d.toml");

#[test]
fn body_cases_build_with_bodies_last() {
    for (text, name, mass) in [
        (FLOATING, "box", 500.0 * 0.2 * 0.1),
        (
            WATER_ENTRY,
            "cylinder",
            500.0 * std::f64::consts::PI * 0.055 * 0.055,
        ),
    ] {
        let s = load_str(text, "c.toml", &[]).unwrap();
        check_invariants(&s);
        assert_eq!(s.bodies.len(), 1);
        let b = &s.bodies[0];
        assert_eq!(b.name, name);
        assert_eq!(b.particles.end, s.particles.len());
        assert!((b.mass - mass).abs() < 1e-12 * mass, "{} vs {mass}", b.mass);
        // No fluid within half a spacing of the body's particles' volumes.
        let dx = s.physics.dx;
        for p in s.particles.iter().filter(|p| p.kind == Kind::Fluid) {
            for q in &s.particles[b.particles.clone()] {
                let d2: f64 = (0..2).map(|a| (p.pos[a] - q.pos[a]).powi(2)).sum();
                assert!(
                    d2 > (0.99 * dx).powi(2),
                    "fluid at {:?} too near {:?}",
                    p.pos,
                    q.pos
                );
            }
        }
    }
}

#[test]
fn a_moving_tank_becomes_the_last_body_and_widens_the_domain() {
    let text = format!(
        "{BASE}\n[tank.motion]\nkind = \"sine\"\npivot_m = [0.5, 0.0]\nrotation_deg = 4.0\n\
         period_s = 3.14159\n"
    );
    let moving = load_str(&text, "c.toml", &[]).unwrap();
    let fixed = load_str(BASE, "c.toml", &[]).unwrap();
    assert_eq!(moving.bodies.len(), 1);
    let tank = &moving.bodies[0];
    assert_eq!(tank.name, "tank");
    assert_eq!(tank.particles.len(), fixed.count(Kind::Wall));
    assert!(moving.domain.max[1] > fixed.domain.max[1]);
    assert!(matches!(tank.motion, Motion::Prescribed(_)));
}

/// A body's `wall` makes its particles dynamic, fixed ghosts (with `slip`) or repulsive (the
/// surface layer only); a moving tank may have fixed-ghost or repulsive walls, not mirrors.
#[test]
fn bodies_and_moving_tanks_take_the_particle_wall_treatments() {
    let body = |extra: &str| {
        format!(
            "{BASE}\n[[body]]\nname = \"b\"\nshape = \"box\"\nmin_m = [0.2, 0.6]\n\
             max_m = [0.8, 0.9]\ndensity_kg_m3 = 500.0\n{extra}\n"
        )
    };
    let kinds = |text: &str| -> Vec<Kind> {
        let sc = load_str(text, "c.toml", &[]).unwrap();
        sc.particles[sc.bodies[0].particles.clone()]
            .iter()
            .map(|p| p.kind)
            .collect()
    };
    let dynamic = kinds(&body(""));
    assert!(dynamic.iter().all(|k| *k == Kind::Wall));
    let ghosts = kinds(&body("wall = \"fixed_ghost\"\nslip = \"free_slip\""));
    assert_eq!(ghosts.len(), dynamic.len());
    assert!(ghosts.iter().all(|k| *k == Kind::GhostFreeSlip));
    assert!(kinds(&body("wall = \"fixed_ghost\""))
        .iter()
        .all(|k| *k == Kind::GhostNoSlip));
    let repulsive = kinds(&body("wall = \"repulsive\""));
    let shell = kinds(&body("layers = 1"));
    assert!(repulsive.iter().all(|k| *k == Kind::Repulsive));
    assert_eq!(repulsive.len(), shell.len(), "the surface layer only");
    assert!(repulsive.len() < dynamic.len());
    assert_err(
        &body("slip = \"free_slip\""),
        &[],
        None,
        &["body[0].slip", "fixed_ghost"],
    );

    let motion = "[tank.motion]\nkind = \"sine\"\npivot_m = [0.5, 0.0]\nrotation_deg = 4.0\n\
                  period_s = 3.14159\n";
    let tank = |wall: &str| {
        format!(
            "{}\n{motion}",
            BASE.replace("[tank]", &format!("[tank]\nwall = \"{wall}\""))
        )
    };
    let sc = load_str(&tank("fixed_ghost"), "c.toml", &[]).unwrap();
    let fixed = load_str(BASE, "c.toml", &[]).unwrap();
    assert_eq!(sc.bodies[0].name, "tank");
    assert_eq!(sc.bodies[0].particles.len(), fixed.count(Kind::Wall));
    assert!(sc.particles[sc.bodies[0].particles.clone()]
        .iter()
        .all(|p| p.kind == Kind::GhostNoSlip));
    assert_err(
        &tank("mirror"),
        &[],
        None,
        &["tank.motion", "mirror", "fixed_ghost"],
    );
}

#[test]
fn bad_bodies_and_motions_are_refused() {
    let with_body = |body: &str| format!("{BASE}\n[[body]]\nname = \"b\"\n{body}\n");
    assert_err(
        &with_body(
            "shape = \"sphere\"\ncenter_m = [0.5, 0.5]\nradius_m = 0.05\ndensity_kg_m3 = 500.0",
        ),
        &[],
        None,
        &["body[0].shape", "2D"],
    );
    assert_err(
        &with_body("shape = \"box\"\nmin_m = [0.4, 0.4]\nmax_m = [0.5, 0.5]"),
        &[],
        None,
        &["body[0]", "mass"],
    );
    assert_err(
        &with_body(
            "shape = \"circle\"\ncenter_m = [0.5, 0.5]\nradius_m = 0.05\nmass_kg = 1.0\n\
             wall = \"mirror\"",
        ),
        &[],
        None,
        &["body[0].wall", "dynamic"],
    );
    assert_err(
        &with_body(
            "shape = \"circle\"\ncenter_m = [0.5, 0.5]\nradius_m = 0.05\nmass_kg = 1.0\n\
             [body.motion]\nkind = \"series\"\nfile = \"no_such.csv\"",
        ),
        &[],
        None,
        &["body[0].motion.file", "no_such.csv"],
    );
    assert_err(
        &format!("{BASE}\n[tank.motion]\nkind = \"free\"\n"),
        &[],
        None,
        &["tank.motion.kind", "sine"],
    );
    assert_err(
        &format!("{BASE}\n[tank.motion]\nkind = \"fixed\"\n"),
        &[],
        None,
        &["tank.motion.kind", "without [tank.motion] is fixed"],
    );
    assert_err(
        &with_body(
            "shape = \"box\"\nmin_m = [0.4, 0.4]\nmax_m = [0.5, 0.5]\n[body.motion]\nkind \
             = \"fixed\"\nperiod_s = 1.0",
        ),
        &[],
        None,
        &[
            "body[0].motion.period_s",
            "not used by a fixed motion",
            "no other field",
        ],
    );
    let held = |more: &str| {
        with_body(&format!(
            "shape = \"box\"\nmin_m = [0.4, 0.4]\nmax_m = [0.5, 0.5]\nmass_kg = 1.0\n\
             [body.motion]\nkind = \"free\"\n{more}"
        ))
    };
    assert_err(
        &held("release_s = -1.0"),
        &[],
        None,
        &[
            "body[0].motion.release_s",
            "at least 0 s",
            "release_s = 1.0",
        ],
    );
    assert_err(
        &held("release_s = 1.0\nvelocity_m_s = [0.0, -1.0]"),
        &[],
        None,
        &["body[0].motion.release_s", "initial velocity_m_s", "remove"],
    );
    assert_err(
        &held("release_s = 1.0\nangular_velocity_rad_s = [2.0]"),
        &[],
        None,
        &["body[0].motion.release_s", "angular_velocity_rad_s"],
    );
    assert_err(
        &format!("{BASE}\n[tank.motion]\nkind = \"sine\"\nrelease_s = 1.0\n"),
        &[],
        None,
        &["tank.motion.release_s", "not used by a sine motion"],
    );
    let s = load_str(&held("release_s = 1.5"), "c.toml", &[]).unwrap();
    assert_eq!(
        s.bodies[0].motion,
        Motion::Free {
            velocity: [0.0; 3],
            omega: [0.0; 3],
            release_s: 1.5
        }
    );
}

/// `kind = "fixed"`: a body held where it is, needing no mass; its particles are placed as a
/// box body's and stay at rest.
#[test]
fn a_fixed_body_needs_no_mass_and_stays_at_rest() {
    let text = format!(
        "{BASE}\n[[body]]\nname = \"pier\"\nshape = \"box\"\nmin_m = [0.4, 0.4]\n\
         max_m = [0.5, 0.5]\n[body.motion]\nkind = \"fixed\"\n"
    );
    let s = load_str(&text, "c.toml", &[]).unwrap();
    let b = &s.bodies[0];
    let Motion::Prescribed(p) = &b.motion else {
        panic!("{:?}", b.motion)
    };
    assert_eq!(p.law, crate::scenario::MotionLaw::Fixed);
    for t in [0.0, 0.37, 1e3] {
        let pose = p.pose(glam::DVec3::from_array(b.center), t);
        assert_eq!(pose.center.to_array(), b.center);
        assert_eq!(
            (pose.velocity, pose.omega),
            (glam::DVec3::ZERO, glam::DVec3::ZERO)
        );
    }
    assert!(s.particles[b.particles.clone()]
        .iter()
        .all(|q| q.vel == [0.0; 3] && q.kind == Kind::Wall));
}

// ---------------------------------------------------------------- found by tests/case_fuzz/

mod fuzz_found;

/// A `kind = "point"` probe follows the nearest particle of a rigid body or elastic solid;
/// without one nearby, or with `body`, it is refused with the field named.
#[test]
fn point_probes_choose_the_nearest_body_particle() {
    let body =
        "\n[[body]]\nname = \"b\"\nshape = \"box\"\nmin_m = [0.6, 0.6]\nmax_m = [0.8, 0.8]\n\
                density_kg_m3 = 500.0\n";
    let point = "\n[[probe]]\nname = \"c\"\nkind = \"point\"\npoint_m = [0.81, 0.79]\n";
    let sc = load_str(&format!("{BASE}{body}{point}"), "t.toml", &[]).unwrap();
    assert_eq!(sc.probes.len(), 1, "the point is not a sampled probe");
    assert_eq!(sc.points.len(), 1);
    let k = sc.points[0].particle as usize;
    assert!(sc.bodies[0].particles.contains(&k));
    // The nearest of the body's particles (dx = 0.1: centres at 0.65 and 0.75).
    assert_eq!(sc.particles[k].pos, [0.75, 0.75, 0.0]);

    let no_body = format!("{BASE}{point}");
    assert_err(
        &no_body,
        &[],
        None,
        &["probe[1].kind", "[[solid]] or [[body]]"],
    );
    let far = format!(
        "{BASE}{body}{}",
        point.replace("[0.81, 0.79]", "[0.2, 0.2]")
    );
    assert_err(
        &far,
        &[],
        None,
        &[
            "probe[1].point_m = [0.2000, 0.2000]",
            "2 dx",
            "[0.6500, 0.6500]",
        ],
    );
    let attached = format!("{BASE}{body}{point}body = \"b\"\n");
    assert_err(&attached, &[], None, &["probe[1].body", "remove body"]);
}

#[test]
fn friction_pairs_resolve_names_and_refuse_bad_ones() {
    use crate::scenario::ContactGroup;
    let with = |pairs: &str| format!("{FLOATING}\n{pairs}");
    let sc = load_str(
        &with("[[friction]]\nbetween = [\"walls\", \"box\"]\ncoefficient = 0.7\n"),
        "f.toml",
        &[],
    )
    .unwrap();
    let w = &sc.walls;
    assert_eq!(w.friction_pairs.len(), 1);
    assert_eq!(
        w.friction_between(ContactGroup::Body(0), ContactGroup::Walls),
        0.7
    );
    assert_eq!(
        w.friction_between(ContactGroup::Body(0), ContactGroup::Body(1)),
        0.0
    );
    // A moving tank is a body (index 0) and, for friction, one of the walls.
    let sloshing = format!(
        "{}\n[[body]]\nname = \"float\"\nshape = \"box\"\nmin_m = [0.4, 0.3]\nmax_m = [0.5, 0.4]\n\
         density_kg_m3 = 500.0\n[[friction]]\nbetween = [\"float\", \"walls\"]\ncoefficient = \
         0.4\n",
        include_str!("../../cases/sloshing_2d.toml")
    );
    let sc = load_str(&sloshing, "f.toml", &[]).unwrap();
    for g in [ContactGroup::Walls, ContactGroup::Body(0)] {
        assert_eq!(sc.walls.friction_between(ContactGroup::Body(1), g), 0.4);
    }

    assert!(sc.warnings.is_empty(), "{:?}", sc.warnings);
    // A fixed pier in the moving tank: the pair never acts (one warning, though "walls"
    // stands for both the fixed walls and the tank).
    let pier = sloshing
        .replace("name = \"float\"", "name = \"pier\"")
        .replace("between = [\"float\"", "between = [\"pier\"")
        .replace(
            "density_kg_m3 = 500.0\n",
            "density_kg_m3 = 500.0\n[body.motion]\nkind = \"fixed\"\n",
        );
    let sc = load_str(&pier, "f.toml", &[]).unwrap();
    assert!(sc.bodies[1].motion.is_fixed());
    // It is also left behind by the tank (the second warning).
    assert_eq!(sc.warnings.len(), 2, "{:?}", sc.warnings);
    assert!(
        sc.warnings[1].starts_with("body[0] ('pier') is fixed in the world while the tank moves"),
        "{:?}",
        sc.warnings[1]
    );
    for words in [
        "[[friction]] between \"pier\" and \"walls\"",
        "never acts",
        "fix: remove the table, or make \"pier\" a free body",
    ] {
        assert!(
            sc.warnings[0].contains(words),
            "{words:?} in {:?}",
            sc.warnings[0]
        );
    }

    let bad: &[(&str, &[&str])] = &[
        (
            "between = [\"box\", \"lid\"]\ncoefficient = 0.3",
            &["friction[0].between[1] = \"lid\"", "\"walls\", \"box\""],
        ),
        (
            "between = [\"box\", \"box\"]\ncoefficient = 0.3",
            &["friction[0].between", "same thing twice"],
        ),
        (
            "between = [\"box\"]\ncoefficient = 0.3",
            &["friction[0].between", "a pair is two"],
        ),
        (
            "between = [\"box\", \"walls\"]\ncoefficient = -0.1",
            &["friction[0].coefficient = -0.1"],
        ),
        (
            "between = [\"box\", \"walls\"]\ncoefficient = 0.3\n[[friction]]\n\
             between = [\"walls\", \"box\"]\ncoefficient = 0.5",
            &["friction[1].between", "friction[0] already"],
        ),
    ];
    for (pair, words) in bad {
        let text = with(&format!("[[friction]]\n{pair}\n"));
        let e = load_str(&text, "f.toml", &[]).unwrap_err().to_string();
        for w in *words {
            assert!(e.contains(w), "`{w}` expected in: {e}");
        }
        assert!(e.contains("fix:"), "{e}");
    }
}

/// A built-in case is found by its name and its file together, as a run records them.
#[test]
fn built_in_cases_are_found_by_name_and_file() {
    for b in BUILT_IN {
        let found = built_in(b.name, Path::new(b.file)).unwrap();
        assert_eq!((found.name, found.file), (b.name, b.file));
        assert_eq!(found.text, std::fs::read_to_string(b.file).unwrap());
    }
    let first = &BUILT_IN[0];
    assert!(built_in(first.name, Path::new("cases/elsewhere.toml")).is_none());
    assert!(built_in("another_name", Path::new(first.file)).is_none());
}

/// A case beyond what the host's memory holds (as `sph::run_budget` reckons it) is refused
/// naming the spacing and the memory, before a particle is made (issue 64: 150 million
/// particles, within the engine's limit, aborted the process while they were made).
#[test]
fn a_case_beyond_the_hosts_memory_is_refused_before_it_is_built() {
    let (n, why) = crate::sph::run_budget(None, Some(64 << 20));
    let budget = super::ParticleBudget::at_most(n as f64, why);
    // About 10^6 particles, more than 64 MiB hold at 250 bytes each.
    let text = base_with("dx_m = 0.1", "dx_m = 0.0005");
    let Err(e) = super::load_str_within(&text, "cases/t.toml", &[], &budget) else {
        panic!("built beyond the budget of {n} particles");
    };
    let msg = format!("{e:#}");
    for word in ["particles.dx_m", "host's memory", "0.1 GiB available"] {
        assert!(msg.contains(word), "{word}: {msg}");
    }
    super::load_str_within(BASE, "cases/t.toml", &[], &budget).unwrap();
}

/// What the loader checked field by field in f64 but a run could not take (issue 64), refused
/// naming the field: the time step rounding to nothing in f32 (a Courant number of 1e-50, a
/// sound speed of 1e40 c0's coefficient, a viscosity of 1e40), a density whose square is no
/// f32, a probe interval of 1e-300 s or below a thousandth of the step, a speed of sound below
/// the water's fall, a tank swept faster than sound by a far pivot, an inlet pointing at a
/// wall, a free body placed through a wall.
#[test]
fn cases_a_run_cannot_step_are_refused_naming_the_field() {
    let refused = |case: &str, sets: &[&str], words: &[&str]| {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let Err(e) = super::load(std::path::Path::new(case), &sets) else {
            panic!("{case} {sets:?} was accepted");
        };
        let msg = format!("{e:#}");
        for w in words {
            assert!(msg.contains(w), "{case} {sets:?}: `{w}` in {msg}");
        }
    };
    let tank = "cases/hydrostatic_2d.toml";
    refused(tank, &["time.cfl=1e-50"], &["time.cfl", "steps"]);
    refused(
        tank,
        &["physics.sound_speed_coef=1e40"],
        &["sound_speed_coef", "f32"],
    );
    let laminar = |nu: &str| {
        BASE.to_string().replace(
            "sound_speed_coef = 10.0",
            &format!("sound_speed_coef = 10.0\nviscosity = \"laminar\"\nnu_m2_s = {nu}"),
        )
    };
    assert_err(&laminar("1e40"), &[], None, &["physics.nu_m2_s", "f32"]);
    assert_err(
        &laminar("1e9"),
        &[],
        None,
        &["physics.nu_m2_s", "0.125 h² / ν"],
    );
    refused(tank, &["physics.rho0_kg_m3=1e30"], &["rho0_kg_m3", "f32"]);
    refused(tank, &["physics.rho0_kg_m3=1e-30"], &["rho0_kg_m3", "f32"]);
    refused(
        tank,
        &["time.probe_every_s=1e-300"],
        &["probe_every_s", "samples"],
    );
    refused(
        tank,
        &["time.probe_every_s=5e-8", "time.end_s=0.2"],
        &["probe_every_s", "thousandth"],
    );
    refused(
        tank,
        &["physics.sound_speed_coef=0.5"],
        &["sound_speed_coef", "sqrt(2 |g| H)"],
    );
    refused(
        "cases/sloshing_2d.toml",
        &["tank.motion.pivot_m=[1000.0, 0.0]"],
        &["tank.motion", "speed of sound"],
    );
    refused(
        "cases/water_injection_2d.toml",
        &["inlet[0].direction=[-1.0, 0.0]"],
        &["inlet[0].direction", "tank's wall"],
    );
    refused(
        "cases/floating_box_2d.toml",
        &["body[0].min_m=[-0.1, 0.27]"],
        &["body[0]", "tank's wall"],
    );
    let spinning = |w: &str| {
        let spin = format!("body[0].motion.angular_velocity_rad_s=[{w}]");
        ["body[0].motion.kind=\"free\"".to_string(), spin]
    };
    let box_case = std::path::Path::new("cases/floating_box_2d.toml");
    for w in ["1e308", "1e3"] {
        let Err(e) = super::load(box_case, &spinning(w)) else {
            panic!("a body spinning at {w} rad/s was accepted");
        };
        let msg = format!("{e:#}");
        assert!(
            msg.contains("body[0].motion") && msg.contains("speed of sound"),
            "{msg}"
        );
    }
}

/// The messages that misled a new user (issue 64, item 7) say what is wrong: an integer beyond
/// the field's range ("expected an integer, found an integer"), a case file that is not UTF-8
/// ("check the path and its permissions"), a motion series separated by ';' ("no data
/// rows"), a body shape of no realistic size (blamed on its density).
#[test]
fn messages_that_misled_say_what_is_wrong() {
    assert_err(
        &base_with("[tank]", "[tank]\nlayers = 99999999999999999999"),
        &[],
        None,
        &["tank.layers", "out of range", "1 to 8"],
    );
    let dir = std::env::temp_dir().join(format!("wgsph-misled-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let utf16: Vec<u8> = [0xff, 0xfe]
        .into_iter()
        .chain(BASE.encode_utf16().flat_map(u16::to_le_bytes))
        .collect();
    let file = dir.join("utf16.toml");
    std::fs::write(&file, utf16).unwrap();
    let msg = super::load(&file, &[]).unwrap_err().to_string();
    assert!(
        msg.contains("UTF-8") && !msg.contains("permissions"),
        "{msg}"
    );
    std::fs::write(dir.join("m.csv"), "t;dx;dy;angle\n0;0;0;0\n1;0.1;0;0\n").unwrap();
    let series = format!(
        "{BASE}\n[[body]]\nname = \"b\"\nshape = \"box\"\nmin_m = [0.6, 0.6]\nmax_m = [0.7, 0.7]\
         \n[body.motion]\nkind = \"series\"\nfile = \"m.csv\"\n"
    );
    let case = dir.join("series.toml");
    std::fs::write(&case, series).unwrap();
    let msg = format!("{:#}", super::load(&case, &[]).unwrap_err());
    assert!(
        msg.contains("comma-separated") && msg.contains("line 2"),
        "{msg}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
    let huge = format!(
        "{BASE}\n[[body]]\nname = \"b\"\nshape = \"polygon\"\nvertices_m = [[0.6, 0.6], \
         [1e200, 0.6], [0.6, 0.7]]\ndensity_kg_m3 = 500.0\n"
    );
    assert_err(&huge, &[], None, &["body[0]", "1e200 m across", "units"]);
}

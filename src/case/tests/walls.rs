//! Wall treatments in case files: `[tank] wall`/`slip`, `[[obstacle]] wall`/`slip`, `[walls]`.

use super::*;
use crate::scenario::{GhostCorrection, MirrorPlane};

/// The hydrostatic tank (dx = 0.02, inner box 50 × 30 cells, 3 layers, open top) with overrides.
fn hydrostatic(overrides: &[&str]) -> Scenario {
    load_str(HYDROSTATIC, "cases/hydrostatic_2d.toml", &sets(overrides)).unwrap()
}

/// The case's probes less its floor sensor, which mirror walls (no particles) cannot have.
const WITHOUT_FLOOR_SENSOR: &str =
    "probe=[{name=\"p_bottom\", kind=\"pressure\", point_m=[0.5, 0.05]}]";

/// (position, density) of every boundary particle.
fn boundary(s: &Scenario) -> Vec<([f64; 3], f64)> {
    s.particles
        .iter()
        .filter(|p| !p.kind.is_fluid())
        .map(|p| (p.pos, p.rho))
        .collect()
}

fn plane(point: [f64; 3], normal: [f64; 3], no_slip: bool) -> MirrorPlane {
    MirrorPlane {
        point,
        normal,
        no_slip,
    }
}

#[test]
fn dynamic_is_the_default_wall() {
    let explicit = hydrostatic(&[]);
    let default = load_str(
        &HYDROSTATIC.replace("wall = \"dynamic\"\n", ""),
        "cases/hydrostatic_2d.toml",
        &[],
    )
    .unwrap();
    assert_eq!(explicit, default);
    assert_eq!(default.count(Kind::Wall), 56 * 33 - 50 * 30);
    assert_eq!(default.boundary_count(), default.count(Kind::Wall));
    assert!(default.walls.mirror_planes.is_empty());
}

#[test]
fn fixed_ghost_walls_are_the_dynamic_particles_as_ghosts() {
    let dynamic = hydrostatic(&[]);
    let no_slip = hydrostatic(&["tank.wall=fixed_ghost"]);
    let free_slip = hydrostatic(&["tank.wall=fixed_ghost", "tank.slip=free_slip"]);
    let n = 56 * 33 - 50 * 30;
    assert_eq!(no_slip.count(Kind::GhostNoSlip), n);
    assert_eq!(no_slip.boundary_count(), n);
    assert_eq!(free_slip.count(Kind::GhostFreeSlip), n);
    assert_eq!(free_slip.boundary_count(), n);
    // Same positions and hydrostatic densities as the dynamic wall particles.
    assert_eq!(boundary(&no_slip), boundary(&dynamic));
    assert_eq!(boundary(&free_slip), boundary(&dynamic));
    assert_eq!(no_slip.count(Kind::Fluid), dynamic.count(Kind::Fluid));
    // `slip = "no_slip"` written out is the default.
    let explicit = hydrostatic(&["tank.wall=fixed_ghost", "tank.slip=no_slip"]);
    assert_eq!(explicit, no_slip);
}

#[test]
fn repulsive_walls_are_one_layer_at_half_a_spacing() {
    let s = hydrostatic(&["tank.wall=\"repulsive\""]);
    let dx = 0.02;
    // The outer box grown by one layer (52 × 31, open top) minus the inner 50 × 30 cells.
    assert_eq!(s.count(Kind::Repulsive), 52 * 31 - 50 * 30);
    assert_eq!(s.boundary_count(), s.count(Kind::Repulsive));
    assert_eq!(s.count(Kind::Fluid), 50 * 25);
    for p in s.particles.iter().filter(|p| p.kind == Kind::Repulsive) {
        let on_face = (p.pos[0] + 0.5 * dx).abs() < 1e-9
            || (p.pos[0] - 1.0 - 0.5 * dx).abs() < 1e-9
            || (p.pos[1] + 0.5 * dx).abs() < 1e-9;
        assert!(on_face && p.pos[1] < 0.6, "{p:?}");
        assert_eq!(p.rho, 1000.0);
        assert_eq!(p.vel, [0.0; 3]);
    }
}

#[test]
fn mirror_walls_are_planes_without_particles() {
    let s = hydrostatic(&["tank.wall=mirror", WITHOUT_FLOOR_SENSOR]);
    assert_eq!(s.boundary_count(), 0);
    assert_eq!(s.count(Kind::Fluid), 50 * 25);
    assert_eq!(
        s.walls.mirror_planes,
        vec![
            plane([0.0; 3], [1.0, 0.0, 0.0], true),
            plane([1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], true),
            plane([0.0; 3], [0.0, 1.0, 0.0], true),
        ]
    );
    // The domain still encloses the tank.
    assert!(s.domain.min[0] < 0.0 && s.domain.min[1] < 0.0 && s.domain.max[0] > 1.0);
    assert!(s.domain.max[1] > 0.6);
    // A closed, free-slip tank: the lid too.
    let closed = hydrostatic(&[
        "tank.wall=mirror",
        "tank.slip=free_slip",
        "tank.open_top=false",
        WITHOUT_FLOOR_SENSOR,
    ]);
    let planes = &closed.walls.mirror_planes;
    assert_eq!(planes.len(), 4);
    assert!(planes.iter().all(|p| !p.no_slip));
    assert_eq!(planes[3], plane([0.0, 0.6, 0.0], [0.0, -1.0, 0.0], false));
}

#[test]
fn mirror_walls_in_3d() {
    let text = "dimension = 3\n[particles]\ndx_m = 0.1\n[physics]\nsound_speed_coef = 10.0\n\
                [time]\nend_s = 1.0\noutput_every_s = 0.1\n\
                [tank]\nmin_m = [0.0, 0.0, 0.0]\nmax_m = [1.0, 0.5, 0.6]\nwall = \"mirror\"\n\
                slip = \"free_slip\"\nopen_top = false\n\
                [[fluid_block]]\nmin_m = [0.0, 0.0, 0.0]\nmax_m = [0.5, 0.5, 0.3]\n";
    let s = load_str(text, "m.toml", &[]).unwrap();
    assert_eq!(s.boundary_count(), 0);
    let o = [0.0; 3];
    let planes = &s.walls.mirror_planes;
    let expect = [
        plane(o, [1.0, 0.0, 0.0], false),
        plane([1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], false),
        plane(o, [0.0, 1.0, 0.0], false),
        plane([0.0, 0.5, 0.0], [0.0, -1.0, 0.0], false),
        plane(o, [0.0, 0.0, 1.0], false),
        plane([0.0, 0.0, 0.6], [0.0, 0.0, -1.0], false),
    ];
    assert_eq!(planes.len(), expect.len());
    for (p, e) in planes.iter().zip(&expect) {
        assert_eq!((p.normal, p.no_slip), (e.normal, e.no_slip));
        assert!(
            (0..3).all(|a| (p.point[a] - e.point[a]).abs() < 1e-12),
            "{p:?}"
        );
    }
    let open = load_str(text, "m.toml", &sets(&["tank.open_top=true"])).unwrap();
    assert_eq!(open.walls.mirror_planes[..], s.walls.mirror_planes[..5]);
}

#[test]
fn a_mirror_tank_must_still_lie_in_the_domain() {
    assert_err(
        &format!("{BASE}[domain]\nmin_m = [-0.5, -0.5]\nmax_m = [0.8, 2.0]\n"),
        &["tank.wall=mirror"],
        Some(13),
        &["tank", "leave the domain", "along x"],
    );
}

#[test]
fn obstacle_treatments() {
    // 4 × 4 lattice points (x 0.65..0.95, y 0.05..0.35); 12 of them on the surface.
    let with = |extra: &str| {
        let text = format!("{BASE}[[obstacle]]\nmin_m = [0.6, 0.0]\nmax_m = [1.0, 0.4]\n{extra}");
        load_str(&text, "o.toml", &[]).unwrap()
    };
    let tank = 16 * 13 - 10 * 10;
    let dynamic = with("");
    assert_eq!(dynamic.count(Kind::Wall), tank + 16);
    let repulsive = with("wall = \"repulsive\"\n");
    assert_eq!(repulsive.count(Kind::Repulsive), 12);
    assert_eq!(repulsive.count(Kind::Wall), tank);
    // Only the centre points (0.75, 0.15) … (0.85, 0.25) are left out.
    assert!(repulsive
        .particles
        .iter()
        .filter(|p| p.kind == Kind::Repulsive)
        .all(|p| !(p.pos[0] > 0.7 && p.pos[0] < 0.9 && p.pos[1] > 0.1 && p.pos[1] < 0.3)));
    // The fluid is kept out of the whole box all the same.
    assert_eq!(repulsive.count(Kind::Fluid), dynamic.count(Kind::Fluid));
    let ghost = with("wall = \"fixed_ghost\"\n");
    assert_eq!(ghost.count(Kind::GhostNoSlip), 16);
    let free = with("wall = \"fixed_ghost\"\nslip = \"free_slip\"\n");
    assert_eq!(free.count(Kind::GhostFreeSlip), 16);
    assert_eq!(free.count(Kind::Wall), tank);
    // A repulsive tank with a dynamic obstacle.
    let text = format!("{BASE}[[obstacle]]\nmin_m = [0.6, 0.0]\nmax_m = [1.0, 0.4]\n");
    let s = load_str(&text, "o.toml", &sets(&["tank.wall=repulsive"])).unwrap();
    assert_eq!(s.count(Kind::Repulsive), 12 * 11 - 10 * 10);
    assert_eq!(s.count(Kind::Wall), 16);
}

#[test]
fn walls_table_defaults_and_overrides() {
    let s = hydrostatic(&[]);
    // H = 0.5 m: the fluid's lowest to highest particle plus dx.
    assert_eq!(s.walls.ghost_correction, GhostCorrection::Mls);
    assert!((s.walls.repulsive_d - 5.0 * 9.81 * 0.5).abs() < 1e-9);
    assert!((s.walls.repulsive_r0 - 0.02).abs() < 1e-15);
    let text = format!(
        "{HYDROSTATIC}\n[walls]\nghost_correction = \"shepard\"\nrepulsive_d_m2_s2 = 30.0\n\
         repulsive_r0_m = 0.015\n"
    );
    let s = load_str(&text, "w.toml", &[]).unwrap();
    assert_eq!(s.walls.ghost_correction, GhostCorrection::Shepard);
    assert_eq!(s.walls.repulsive_d, 30.0);
    assert_eq!(s.walls.repulsive_r0, 0.015);
    // An empty table is the defaults; overrides create the table.
    let empty = load_str(&format!("{HYDROSTATIC}\n[walls]\n"), "w.toml", &[]).unwrap();
    assert_eq!(empty.walls, hydrostatic(&[]).walls);
    let s = hydrostatic(&[
        "walls.ghost_correction=shepard",
        "walls.repulsive_d_m2_s2=7",
    ]);
    assert_eq!(s.walls.ghost_correction, GhostCorrection::Shepard);
    assert_eq!(s.walls.repulsive_d, 7.0);
    assert!((s.walls.repulsive_r0 - 0.02).abs() < 1e-15);
}

#[test]
fn monaghan_kajtar_repulsion_settings() {
    use crate::scenario::RepulsiveForm;
    let s = hydrostatic(&[]);
    assert_eq!(s.walls.repulsive_form, RepulsiveForm::LennardJones);
    assert!(
        (s.walls.repulsive_k - 9.81 * 0.5).abs() < 1e-9,
        "default K = |g| H"
    );
    assert_eq!(s.walls.repulsive_beta, 1.0);
    let s = hydrostatic(&[
        "walls.repulsive_form=monaghan_kajtar",
        "walls.repulsive_k_m2_s2=3.5",
        "walls.repulsive_beta=2",
    ]);
    assert_eq!(s.walls.repulsive_form, RepulsiveForm::MonaghanKajtar);
    assert_eq!(s.walls.repulsive_k, 3.5);
    assert_eq!(s.walls.repulsive_beta, 2.0);
    for (set, field) in [
        ("walls.repulsive_k_m2_s2=-1", "walls.repulsive_k_m2_s2"),
        ("walls.repulsive_beta=0", "walls.repulsive_beta"),
        ("walls.repulsive_form=\"soft\"", "walls.repulsive_form"),
    ] {
        let e = crate::case::load_str(HYDROSTATIC, "w.toml", &[set.to_string()])
            .unwrap_err()
            .to_string();
        assert!(e.contains(field), "{set}: {e}");
    }
}

#[test]
fn wall_errors_name_line_and_field() {
    slip_and_mirror_errors();
    unknown_names_and_bad_strengths();
}

/// [`BASE`] with `extra` lines in its `[tank]`.
fn tank_with(extra: &str) -> String {
    base_with(
        "max_m = [1.0, 1.0]",
        &format!("max_m = [1.0, 1.0]\n{extra}"),
    )
}

/// [`BASE`] with an obstacle of `extra` lines.
fn obstacle(extra: &str) -> String {
    format!("{BASE}[[obstacle]]\nmin_m = [0.6, 0.0]\nmax_m = [0.7, 0.1]\n{extra}")
}

/// Slip with a dynamic or repulsive wall, mirror on an obstacle.
fn slip_and_mirror_errors() {
    // slip with a dynamic or repulsive wall.
    assert_err(
        &tank_with("slip = \"free_slip\""),
        &[],
        Some(16),
        &[
            "tank.slip = \"free_slip\"",
            "\"mirror\" or \"fixed_ghost\"",
            "\"dynamic\"",
        ],
    );
    assert_err(
        &tank_with("wall = \"repulsive\"\nslip = \"no_slip\""),
        &[],
        Some(17),
        &["tank.slip", "but the wall is \"repulsive\"", "remove slip"],
    );
    assert_err(
        BASE,
        &["tank.slip=free_slip"],
        None,
        &[
            "tank.slip",
            "(from --set tank.slip=free_slip)",
            "\"dynamic\"",
        ],
    );
    // Mirror on an obstacle; slip on a dynamic obstacle.
    assert_err(
        &obstacle("wall = \"mirror\"\n"),
        &[],
        Some(28),
        &[
            "obstacle[0].wall = \"mirror\"",
            "mirror ghosts are for the tank's straight faces; use fixed_ghost for obstacles",
        ],
    );
    assert_err(
        &obstacle(""),
        &["obstacle[0].wall=mirror"],
        None,
        &[
            "obstacle[0].wall",
            "--set obstacle[0].wall=mirror",
            "fixed_ghost",
        ],
    );
    assert_err(
        &obstacle("slip = \"free_slip\"\n"),
        &[],
        Some(28),
        &["obstacle[0].slip", "\"dynamic\""],
    );
}

/// Unknown enum strings and fields of `[walls]`, non-positive repulsion settings.
fn unknown_names_and_bad_strengths() {
    // Unknown enum strings list the allowed values.
    assert_err(
        &tank_with("wall = \"mdbc\""),
        &[],
        Some(16),
        &[
            "tank.wall = \"mdbc\"",
            "\"dynamic\", \"repulsive\", \"mirror\", \"fixed_ghost\"",
        ],
    );
    assert_err(
        &tank_with("wall = \"fixed_ghost\"\nslip = \"partial\""),
        &[],
        Some(17),
        &["tank.slip = \"partial\"", "\"no_slip\", \"free_slip\""],
    );
    assert_err(
        &obstacle("wall = \"sticky\"\n"),
        &[],
        Some(28),
        &["obstacle[0].wall", "\"fixed_ghost\""],
    );
    assert_err(
        &format!("{BASE}[walls]\nghost_correction = \"kernel\"\n"),
        &[],
        Some(26),
        &[
            "walls.ghost_correction = \"kernel\"",
            "\"shepard\", \"mls\"",
        ],
    );
    assert_err(
        &format!("{BASE}[walls]\nrepulsive_d = 3.0\n"),
        &[],
        Some(26),
        &[
            "walls.repulsive_d",
            "unknown field",
            "ghost_correction, repulsive_d_m2_s2, repulsive_r0_m",
        ],
    );
    // Non-positive D or r0.
    for (field, value) in [
        ("repulsive_d_m2_s2", "0.0"),
        ("repulsive_d_m2_s2", "-5.0"),
        ("repulsive_r0_m", "0"),
        ("repulsive_r0_m", "-0.01"),
        ("repulsive_r0_m", "nan"),
    ] {
        assert_err(
            &format!("{BASE}[walls]\n{field} = {value}\n"),
            &[],
            Some(26),
            &[&format!("walls.{field} = "), "Lennard-Jones"],
        );
    }
    assert_err(
        BASE,
        &["walls.repulsive_r0_m=-1"],
        None,
        &[
            "walls.repulsive_r0_m = -1",
            "> 0",
            "--set walls.repulsive_r0_m=-1",
        ],
    );
}

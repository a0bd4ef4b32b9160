//! `[[solid]]`: the oscillating plate case and the loader's errors.

use super::*;
use crate::scenario::SolidFormulation;

const PLATE: &str = include_str!("../../../cases/oscillating_plate_2d.toml");
const PLATE_TL: &str = include_str!("../../../cases/oscillating_plate_tl_2d.toml");

#[test]
fn oscillating_plate_builds_a_clamped_plate_in_its_first_mode() {
    let s = load_str(PLATE, "cases/oscillating_plate_2d.toml", &[]).unwrap();
    let solids = s.solids.as_ref().expect("solids");
    // 0.26 m × 0.02 m at dx = 0.004: 65 × 5 particles, the first 15 columns clamped.
    assert_eq!(s.particles.len(), 65 * 5);
    assert_eq!(s.count(Kind::SolidClamped), 15 * 5);
    assert_eq!(s.count(Kind::Solid), 50 * 5);
    assert!(solids.body.iter().all(|&b| b == 0));
    assert_eq!(solids.materials.len(), 1);
    let m = &solids.materials[0];
    assert!(
        (m.sound_speed() - 57.0266).abs() < 1e-3,
        "{}",
        m.sound_speed()
    );
    // Velocity: zero on the clamp, V f(s)/f(L) along y, the tip particle (s = L − dx/2) close
    // to V = 0.5703 m/s.
    for p in &s.particles {
        assert_eq!(p.vel[0], 0.0);
        if p.kind == Kind::SolidClamped {
            assert_eq!(p.vel[1], 0.0);
        }
    }
    let tip = s.particles.iter().map(|p| p.vel[1]).fold(0.0, f64::max);
    assert!(tip > 0.55 && tip < 0.5703, "tip velocity {tip}");
    // The whole plate and its swing fit the default domain.
    assert!(s.domain.min[1] < -0.1 && s.domain.max[1] > 0.12);
}

const SOLID: &str = r#"dimension = 2

[particles]
dx_m = 0.01

[physics]
gravity_m_s2 = [0.0, 0.0]

[time]
end_s = 1.0
output_every_s = 0.1

[[solid]]
name = "plate"
min_m = [0.0, 0.0]
max_m = [0.2, 0.04]
density_kg_m3 = 1000.0
youngs_modulus_pa = 2.0e6
poisson_ratio = 0.3975
clamped_min_m = [0.0, 0.0]
clamped_max_m = [0.05, 0.04]
"#;

fn solid_with(from: &str, to: &str) -> String {
    assert!(SOLID.contains(from), "{from}");
    SOLID.replacen(from, to, 1)
}

#[test]
fn solid_errors_name_the_field() {
    load_str(SOLID, "cases/t.toml", &[]).unwrap();
    assert_err(
        &solid_with("poisson_ratio = 0.3975", "poisson_ratio = 0.5"),
        &[],
        Some(19),
        &["solid[0].poisson_ratio", "0.49"],
    );
    // Found by tests/case_fuzz: a positive but subnormal modulus gave a zero sound speed.
    assert_err(
        &solid_with("youngs_modulus_pa = 2.0e6", "youngs_modulus_pa = 5e-324"),
        &[],
        None,
        &["solid[0].youngs_modulus_pa", "sound speed"],
    );
    assert_err(
        &solid_with("clamped_max_m = [0.05, 0.04]\n", ""),
        &[],
        None,
        &["solid[0].clamped_max_m", "both"],
    );
    assert_err(
        &solid_with(
            "clamped_max_m = [0.05, 0.04]",
            "clamped_max_m = [0.0, 0.04]",
        ),
        &[],
        Some(21),
        &["solid[0].clamped_max_m", "empty"],
    );
    assert_err(
        &format!(
            "{SOLID}\n[solid.initial_velocity]\nkind = \"cantilever_mode\"\nroot_m = [0.05, \
             0.02]\naxis = [1.0, 0.0]\ndirection = [0.0, 1.0]\ntip_velocity_m_s = 0.5\n"
        ),
        &[],
        None,
        &["solid[0].initial_velocity.length_m", "required"],
    );
    // No fluid and no solid.
    let no_fluid = SOLID
        .split("[[solid]]")
        .next()
        .unwrap()
        .replace("[physics]\n", "[physics]\nsound_speed_coef = 10.0\n");
    assert_err(&no_fluid, &[], None, &["fluid_block", "[[solid]]"]);
}

/// `[[solid]]` number `i` of Young's modulus `e`, a free block right of SOLID's plate.
fn block_of_modulus(i: usize, e: f64) -> String {
    let x = 0.3 + 0.1 * i as f64;
    format!(
        "\n[[solid]]\nname = \"b{i}\"\nmin_m = [{x}, 0.0]\nmax_m = [{}, 0.04]\n\
         density_kg_m3 = 1000.0\nyoungs_modulus_pa = {e}\npoisson_ratio = 0.3975\n",
        x + 0.05
    )
}

/// Solids of different materials: each body keeps its own, equal materials are stored once on
/// the GPU, and a ninth different one is refused naming the solid. `[walls]` applies to solids
/// alone, and their contact needs a strength where gravity gives none.
#[test]
fn solids_keep_their_own_materials() {
    // Without gravity the contact strength between solids must be given.
    let solid = format!("{SOLID}\n[walls]\nrepulsive_d_m2_s2 = 1.0\n");
    assert_err(
        &(SOLID.to_string() + &block_of_modulus(0, 2.0e6)),
        &[],
        None,
        &[
            "walls.repulsive_d_m2_s2",
            "physics.gravity_m_s2 is zero",
            "repulsive_d_m2_s2 = 1.0",
        ],
    );
    // The plate (E = 2 MPa), then blocks of 3, 2 (the plate's) and 3 MPa.
    let text = [3.0e6, 2.0e6, 3.0e6]
        .iter()
        .enumerate()
        .fold(solid.clone(), |t, (i, &e)| t + &block_of_modulus(i, e));
    let s = load_str(&text, "four.toml", &[]).unwrap();
    assert_eq!(s.walls.repulsive_d, 1.0);
    let solids = s.solids.as_ref().unwrap();
    let e: Vec<f64> = solids.materials.iter().map(|m| m.youngs_modulus).collect();
    assert_eq!(e, [2.0e6, 3.0e6, 2.0e6, 3.0e6]);
    for (i, p) in s.particles.iter().enumerate() {
        let want = if p.pos[0] > 0.25 {
            e[1 + ((p.pos[0] - 0.3) / 0.1) as usize]
        } else {
            2.0e6
        };
        assert_eq!(solids.material_of(i).youngs_modulus, want, "particle {i}");
    }
    let (distinct, index) = solids.distinct_materials();
    assert_eq!(distinct.len(), 2);
    assert_eq!(index, [0, 1, 0, 1]);
    assert_eq!(solids.max_p_wave_speed(), distinct[1].p_wave_speed());

    let eight = (1..=8).fold(solid.clone(), |t, i| {
        t + &block_of_modulus(i - 1, 2.0e6 + 1.0e5 * i as f64)
    });
    assert_err(
        &eight,
        &[],
        None,
        &["solid[8]", "9th material", "at most 8"],
    );
    let seven = (1..=7).fold(solid, |t, i| {
        t + &block_of_modulus(i - 1, 2.0e6 + 1.0e5 * i as f64)
    });
    assert_eq!(
        load_str(&seven, "eight.toml", &[])
            .unwrap()
            .solids
            .unwrap()
            .distinct_materials()
            .0
            .len(),
        8
    );
}

/// A gate of solid particles (2 particles thick: updated Lagrangian, too thin for the
/// total-Lagrangian fit) clamped at its top in a tank of water.
const GATE_IN_WATER: &str = r#"dimension = 2
[particles]
dx_m = 0.01
[physics]
sound_speed_coef = 20.0
[time]
end_s = 0.1
output_every_s = 0.01
[tank]
min_m = [0.0, 0.0]
max_m = [0.6, 0.4]
[[fluid_block]]
min_m = [0.0, 0.0]
max_m = [0.4, 0.2]
[[solid]]
name = "gate"
min_m = [0.2, 0.02]
max_m = [0.22, 0.3]
density_kg_m3 = 1100.0
youngs_modulus_pa = 1.2e7
poisson_ratio = 0.4
formulation = "updated_lagrangian"
clamped_min_m = [0.2, 0.25]
clamped_max_m = [0.22, 0.3]
"#;

/// `formulation`: the default is the total-Lagrangian solid (SOLID gives none); the
/// updated-Lagrangian plate says so; the total-Lagrangian plate reads without α and ε (also in
/// 3D), its refusals (α or ε given, with the formulation given or defaulted) name the field,
/// and it takes fluid like the updated-Lagrangian solid.
#[test]
fn total_lagrangian_formulation_and_its_refusals() {
    let default = load_str(SOLID, "cases/t.toml", &[]).unwrap();
    let md = default.solids.unwrap().materials[0];
    assert_eq!(md.formulation, SolidFormulation::TotalLagrangian);
    assert_eq!((md.alpha, md.artificial_stress), (0.0, 0.0));
    let ul = load_str(PLATE, "cases/oscillating_plate_2d.toml", &[]).unwrap();
    let m = ul.solids.unwrap().materials[0];
    assert_eq!(m.formulation, SolidFormulation::UpdatedLagrangian);
    assert_eq!((m.alpha, m.artificial_stress), (0.1, 0.3));
    let tl = load_str(PLATE_TL, "cases/oscillating_plate_tl_2d.toml", &[]).unwrap();
    let mt = tl.solids.unwrap().materials[0];
    assert_eq!(mt.formulation, SolidFormulation::TotalLagrangian);
    assert_eq!((mt.alpha, mt.artificial_stress), (0.0, 0.0));
    assert_eq!(tl.particles.len(), ul.particles.len());
    let with_tl = |extra: &str| {
        solid_with(
            "poisson_ratio = 0.3975\n",
            &format!("poisson_ratio = 0.3975\nformulation = \"total_lagrangian\"\n{extra}"),
        )
    };
    load_str(&with_tl(""), "cases/t.toml", &[]).unwrap();
    load_str(
        &with_tl("alpha = 0.0\nartificial_stress = 0.0\n"),
        "cases/t.toml",
        &[],
    )
    .unwrap();
    assert_err(
        &with_tl("alpha = 0.1\n"),
        &[],
        None,
        &["solid[0].alpha", "total_lagrangian", "remove alpha"],
    );
    assert_err(
        &with_tl("artificial_stress = 0.3\n"),
        &[],
        None,
        &["solid[0].artificial_stress", "remove artificial_stress"],
    );
    // A stabiliser given without a formulation (a case written for the old default) names the
    // default and the way back to the updated-Lagrangian solid.
    assert_err(
        &solid_with(
            "poisson_ratio = 0.3975\n",
            "poisson_ratio = 0.3975\nalpha = 0.1\n",
        ),
        &[],
        None,
        &[
            "solid[0].alpha",
            "\"total_lagrangian\", the default",
            "formulation = \"updated_lagrangian\"",
        ],
    );
    let three_d = r#"dimension = 3
[particles]
dx_m = 0.01
[physics]
gravity_m_s2 = [0.0, 0.0, 0.0]
[time]
end_s = 1.0
output_every_s = 0.1
[[solid]]
name = "block"
min_m = [0.0, 0.0, 0.0]
max_m = [0.05, 0.05, 0.05]
density_kg_m3 = 1000.0
youngs_modulus_pa = 2.0e6
poisson_ratio = 0.3975
formulation = "total_lagrangian"
"#;
    let s3 = load_str(three_d, "cases/t.toml", &[])
        .unwrap()
        .solids
        .unwrap();
    assert!(
        s3.has(SolidFormulation::TotalLagrangian) && !s3.has(SolidFormulation::UpdatedLagrangian)
    );
    // Two particles thick, the gate is too thin for the total-Lagrangian fit: refused when
    // the case loads, naming the solid, the axis and the way out; three thick it builds.
    let thin = GATE_IN_WATER.replace("\"updated_lagrangian\"", "\"total_lagrangian\"");
    assert_err(
        &thin,
        &[],
        None,
        &[
            "solid[0].max_m",
            "2 particle(s) thick along x",
            "at least 3",
            "formulation = \"updated_lagrangian\"",
        ],
    );
    let fluid = thin.replace("0.22, 0.3]", "0.23, 0.3]");
    let sc = load_str(&fluid, "c.toml", &[]).unwrap();
    assert!(sc.count(Kind::Fluid) > 0 && sc.count(Kind::Solid) > 0);
    let solids = sc.solids.unwrap();
    assert!(
        solids.has(SolidFormulation::TotalLagrangian)
            && !solids.has(SolidFormulation::UpdatedLagrangian)
    );
}

/// Solids of both formulations share a case: each keeps its own (by `[[solid]]` index), and the
/// total-Lagrangian solid's particles are built first, in one run of ids (the solver's TL
/// lists index them so), whatever the order of the `[[solid]]` tables.
#[test]
fn solids_of_both_formulations_share_a_case() {
    let ul = solid_with(
        "poisson_ratio = 0.3975\n",
        "poisson_ratio = 0.3975\nformulation = \"updated_lagrangian\"\n",
    );
    let text = format!(
        "{ul}\n[[solid]]\nname = \"b\"\nmin_m = [0.3, 0.0]\nmax_m = [0.4, 0.04]\n\
         density_kg_m3 = 1000.0\nyoungs_modulus_pa = 3.0e6\npoisson_ratio = 0.3975\n\
         formulation = \"total_lagrangian\"\n[walls]\nrepulsive_d_m2_s2 = 1.0\n"
    );
    let sc = load_str(&text, "cases/t.toml", &[]).unwrap();
    let solids = sc.solids.as_ref().unwrap();
    assert_eq!(
        solids
            .materials
            .iter()
            .map(|m| m.formulation)
            .collect::<Vec<_>>(),
        [
            SolidFormulation::UpdatedLagrangian,
            SolidFormulation::TotalLagrangian
        ]
    );
    let ids: Vec<usize> = (0..sc.particles.len())
        .filter(|&i| sc.particles[i].kind.is_solid())
        .collect();
    let bodies: Vec<u32> = ids.iter().map(|&i| solids.body[i]).collect();
    let n_tl = bodies.iter().filter(|&&b| b == 1).count();
    assert!(n_tl > 0 && n_tl < bodies.len());
    assert!(
        bodies[..n_tl].iter().all(|&b| b == 1) && bodies[n_tl..].iter().all(|&b| b == 0),
        "the total-Lagrangian solid's particles come first"
    );
    // Each particle is where its own solid is: "b" spans x ∈ [0.3, 0.4].
    for &i in &ids {
        let in_b = sc.particles[i].pos[0] > 0.25;
        assert_eq!(in_b, solids.body[i] == 1, "particle {i}");
    }
}

/// A solid in a tank without fluid: the tank's walls on the lattice from its inner corner, the
/// solid's particles, the solid's sound speed as c0 (the fluid's is unused) and the contact
/// strength D = 5 g H from the floor's lowest particle to the solid's highest.
#[test]
fn a_solid_in_an_empty_tank_builds_with_the_walls() {
    let case = format!(
        "{}\n[tank]\nmin_m = [0.0, 0.0]\nmax_m = [0.5, 0.5]\n",
        SOLID
            .replace(
                "[0.0, 0.0]\nmax_m = [0.2, 0.04]",
                "[0.1, 0.1]\nmax_m = [0.3, 0.14]"
            )
            .replace(
                "clamped_min_m = [0.0, 0.0]\nclamped_max_m = [0.05, 0.04]\n",
                ""
            )
            .replace("[0.0, 0.0]", "[0.0, -9.81]")
    );
    let s = load_str(&case, "cases/t.toml", &[]).unwrap();
    assert_eq!(s.count(Kind::Solid), 20 * 4);
    assert_eq!(s.count(Kind::Fluid), 0);
    // 3 layers around a 50 × 50 open box: floor 3 × 56, sides 2 × 3 × 50.
    assert_eq!(s.count(Kind::Wall), 3 * 56 + 2 * 3 * 50);
    let m = s.solids.as_ref().unwrap().materials[0];
    assert_eq!(s.physics.c0, m.sound_speed());
    // Floor's lowest particle at −0.025, the solid's highest at 0.135.
    let d = 5.0 * 9.81 * (0.135 + 0.025 + 0.01);
    assert!(
        (s.walls.repulsive_d - d).abs() < 1e-9,
        "D = {}",
        s.walls.repulsive_d
    );
}

/// A gate of solid particles in a tank of water (the elastic gate's layout): fluid where the
/// solid is not (at least a spacing from its particles), solid particles before the walls'
/// end, a solid state for every particle; a rigid body after the solids; a moving tank and
/// the energy equation are refused beside solids.
#[test]
fn fluid_and_solids_build_together() {
    let case = GATE_IN_WATER;
    let s = load_str(case, "cases/t.toml", &[]).unwrap();
    let solids = s.solids.as_ref().expect("solids");
    assert_eq!(solids.body.len(), s.particles.len());
    assert_eq!(solids.tau0.len(), s.particles.len());
    let gate: Vec<&Particle> = s.particles.iter().filter(|p| p.kind.is_solid()).collect();
    assert_eq!(gate.len(), 2 * 28);
    assert_eq!(s.count(Kind::SolidClamped), 2 * 5);
    assert!(gate.iter().all(|p| p.rho == 1100.0));
    for f in s.particles.iter().filter(|p| p.kind == Kind::Fluid) {
        for g in &gate {
            let d = ((f.pos[0] - g.pos[0]).powi(2) + (f.pos[1] - g.pos[1]).powi(2)).sqrt();
            assert!(
                d > 0.01 - 1e-9,
                "fluid at {:?} within {d} of the gate",
                f.pos
            );
        }
    }
    // 40 × 20 fluid lattice points minus the gate's 2 columns (x = 0.205, 0.215) over the
    // 18 rows from y = 0.025 (the gap under the gate stays fluid, a spacing from it).
    assert_eq!(s.count(Kind::Fluid), 40 * 20 - 2 * 18);
    assert!(
        (s.physics.particle_mass - 0.1).abs() < 1e-12,
        "the fluid's mass"
    );

    let with_body = format!(
        "{case}[[body]]\nname = \"b\"\nshape = \"box\"\nmin_m = [0.5, 0.25]\nmax_m = [0.55, 0.3]\n\
         density_kg_m3 = 500.0\n"
    );
    let b = load_str(&with_body, "cases/t.toml", &[]).unwrap();
    let solids = b.solids.as_ref().expect("solids");
    assert_eq!(b.bodies.len(), 1);
    assert_eq!(solids.body.len(), b.particles.len());
    let first_body = b.bodies[0].particles.start;
    assert!(b.particles[first_body..].iter().all(|p| !p.kind.is_solid()));
    assert_eq!(
        b.particles[..first_body]
            .iter()
            .filter(|p| p.kind.is_solid())
            .count(),
        gate.len()
    );
    assert_err(
        &format!(
            "{case}[tank.motion]\nkind = \"sine\"\nperiod_s = 1.0\ntranslation_m = [0.01, 0.0]\n"
        ),
        &[],
        None,
        &["tank.motion", "clamped"],
    );
    // An obstacle overlapping the gate's free part, or a free gate sunk into the floor, would
    // be thrown off by contact at the start: refused. Touching (a spacing apart) is fine.
    assert_err(
        &format!("{case}[[obstacle]]\nmin_m = [0.21, 0.1]\nmax_m = [0.3, 0.12]\n"),
        &[],
        None,
        &[
            "solid[0]",
            "overlaps a wall, obstacle or body",
            "clamp that part",
        ],
    );
    assert_err(
        &case.replace("min_m = [0.2, 0.02]", "min_m = [0.2, -0.005]"),
        &[],
        None,
        &["solid[0]", "overlaps"],
    );
    load_str(
        &format!("{case}[[obstacle]]\nmin_m = [0.22, 0.1]\nmax_m = [0.3, 0.12]\n"),
        "cases/t.toml",
        &[],
    )
    .unwrap();
    assert_err(
        &case.replace("[tank]\n", "[tank]\nwall = \"mirror\"\n"),
        &[],
        None,
        &["tank.wall", "mirror planes have no particles"],
    );
    assert_err(
        &case.replace("[physics]\n", "[physics]\nenergy = true\n"),
        &[],
        None,
        &["physics.energy", "no solid terms"],
    );
}

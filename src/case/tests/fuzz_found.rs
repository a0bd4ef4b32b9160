//! One test per bug found while fuzzing the loader (`tests/case_fuzz/`), by its properties or
//! by reading the code a property exercises, each with the input that shows it (shrunk by hand
//! to the base case of `super`).

use super::*;

/// `--set probe.0.0.name=x` (an index after an index) reached an `unreachable!` in
/// `overrides::apply` and panicked.
#[test]
fn an_index_after_an_index_in_a_set_is_refused() {
    for arg in ["probe.0.0.name=x", "probe[0].0.name=x", "probe.0[0].name=x"] {
        assert_err(BASE, &[arg], None, &[&format!("--set {arg}"), "index"]);
    }
}

/// A circle smaller than half a spacing built a free body with no particles (which no fluid
/// force would ever reach).
#[test]
fn a_body_too_small_for_one_particle_is_refused() {
    let text = format!(
        "{BASE}\n[[body]]\nname = \"b\"\nshape = \"circle\"\ncenter_m = [0.5, 0.7]\nradius_m = \
         0.04\nmass_kg = 1.0\n"
    );
    assert_err(
        &text,
        &[],
        Some(30),
        &[
            "body[0].radius_m = 0.04",
            "half a particle spacing",
            "no particles",
        ],
    );
    // A radius of a spacing has particles.
    let ok = text.replace("radius_m = 0.04", "radius_m = 0.1");
    let sc = load_str(&ok, "cases/t.toml", &[]).unwrap();
    assert!(!sc.bodies[0].particles.is_empty());
}

/// A body (or an obstacle) covering a whole fluid block left a case with no fluid at all.
#[test]
fn a_block_wholly_inside_a_solid_is_refused() {
    let body = format!(
        "{BASE}\n[[body]]\nname = \"b\"\nshape = \"circle\"\ncenter_m = [0.25, 0.25]\nradius_m = \
         1.0\nmass_kg = 1.0\n"
    );
    assert_err(
        &body,
        &[],
        Some(17),
        &["fluid_block[0]", "inside body[0]", "fix: move body[0]"],
    );
    let obstacle = format!("{BASE}\n[[obstacle]]\nmin_m = [0.0, 0.0]\nmax_m = [0.6, 0.6]\n");
    assert_err(
        &obstacle,
        &[],
        Some(17),
        &["fluid_block[0]", "inside obstacle[0]"],
    );
}

/// `--set` with thousands of dotted parts made as many nested tables, and writing them out
/// overflowed the stack (an abort, found by probing the override path by hand).
#[test]
fn a_set_key_with_thousands_of_parts_is_refused() {
    let deep = format!("{}=1", vec!["a"; 10_000].join("."));
    let e = err_of(BASE, &[&deep]);
    assert!(
        e.starts_with("cases/t.toml: --set a.a.a") && e.contains("parts"),
        "{e}"
    );
    // Deeply nested values in the file itself are the TOML parser's syntax errors.
    for (open, close) in [("[", "]"), ("{a = ", "}")] {
        let text = format!(
            "dimension = {}{}\n",
            open.repeat(10_000),
            close.repeat(10_000)
        );
        assert_err(&text, &[], Some(1), &["TOML syntax error", "recurs"]);
    }
}

/// A series motion read its file whatever it was: `/dev/zero` never ends (memory runs out).
#[cfg(unix)]
#[test]
fn a_series_file_must_be_a_regular_file() {
    let text = format!(
        "{BASE}\n[[body]]\nname = \"b\"\nshape = \"circle\"\ncenter_m = [0.5, 0.7]\nradius_m = \
         0.1\nmass_kg = 1.0\n[body.motion]\nkind = \"series\"\nfile = \"/dev/zero\"\n"
    );
    assert_err(
        &text,
        &[],
        Some(34),
        &["body[0].motion.file", "/dev/zero", "not a regular file"],
    );
}

/// Finite gravity components whose magnitude overflows were blamed on the speed of sound.
#[test]
fn gravity_of_infinite_magnitude_is_refused() {
    let text = base_with("[physics]\n", "[physics]\ngravity_m_s2 = [1.0, 1.7e308]\n");
    assert_err(&text, &[], Some(7), &["physics.gravity_m_s2", "magnitude"]);
}

/// Errors of the speed of sound named `physics.sound_speed_m_s` when the file gives
/// `sound_speed_coef`, and did not say that zero gravity is the cause of c0 = 0.
#[test]
fn sound_speed_errors_name_the_fields_given() {
    let huge = base_with("sound_speed_coef = 10.0", "sound_speed_coef = 1e300");
    let e = err_of(&huge, &[]);
    assert!(
        e.starts_with("cases/t.toml:7: physics.sound_speed_coef = 1e300: gives a Tait stiffness")
            && e.contains("c0 = 2.21472345904e300 m/s, physics.rho0_kg_m3 = 1000"),
        "{e}"
    );
    let weightless = base_with("[physics]\n", "[physics]\ngravity_m_s2 = [0.0, 0.0]\n");
    assert_err(
        &weightless,
        &[],
        Some(8),
        &[
            "physics.sound_speed_coef",
            "|g| = 0 m/s² (physics.gravity_m_s2)",
        ],
    );
}

/// Too many particles: the message names the part with the most, not only `particles.dx_m`
/// (a huge tank read as "increase dx_m"). A box body was counted by its area, so a long thin
/// box (1e10 m by 1e-7 m: area 1000 m², 1e5 particles at dx = 0.1) passed the budget, and its
/// lattice of 1e11 points was walked (found by reading the code while writing the fuzz test).
#[test]
fn the_particle_budget_names_the_largest_part() {
    let tank = base_with("max_m = [1.0, 1.0]", "max_m = [1.0e7, 1.0]");
    assert_err(
        &tank,
        &[],
        Some(4),
        &["particles.dx_m", "in tank", "shrink tank"],
    );
    let thin = format!(
        "{BASE}\n[[body]]\nname = \"b\"\nshape = \"box\"\nmin_m = [0.0, 0.8]\nmax_m = [1e10, \
         0.8000001]\nmass_kg = 1.0\n"
    );
    assert_err(
        &thin,
        &[],
        Some(4),
        &["particles.dx_m", "in body[0]", "shrink body[0]"],
    );
}

/// A domain the neighbour grid cannot cover was accepted (the run failed later, without naming
/// a field): given, or stretched by a 1e300 m mirror tank (whose walls have no particles, so
/// the particle budget let it through).
#[test]
fn a_domain_too_large_for_the_grid_is_refused() {
    let given = format!("{BASE}\n[domain]\nmin_m = [-1.0, -1.0]\nmax_m = [1e300, 2.0]\n");
    assert_err(&given, &[], Some(28), &["domain.max_m", "neighbour grid"]);
    let mirror = |min: &str| {
        base_with(
            "min_m = [0.0, 0.0]\nmax_m = [1.0, 1.0]",
            &format!("min_m = [{min}, 0.0]\nmax_m = [1.0, 1.0]\nwall = \"mirror\""),
        )
    };
    assert_err(
        &mirror("-1e300"),
        &[],
        Some(15),
        &["tank.max_m", "1e301 particle spacings", "neighbour grid"],
    );
    // Short enough to count, too long for the grid: the default domain encloses the tank.
    assert_err(
        &mirror("-5e8"),
        &[],
        Some(13),
        &["tank:", "neighbour grid", "bring tank closer"],
    );
}

/// Fluid leaving a given domain said "enlarge [domain]"; it now names the bound to move.
#[test]
fn fluid_outside_a_given_domain_names_the_bound() {
    let text = format!("{BASE}\n[domain]\nmin_m = [-1.0, -1.0]\nmax_m = [0.3, 2.0]\n");
    assert_err(
        &text,
        &[],
        Some(17),
        &["fluid_block[0]", "raise domain.max_m[0] to 0.5"],
    );
}

/// Deleting a body's [body.motion] makes it free; the error said only "a free body needs its
/// mass". Deleting the tank shrinks the default domain to the fluid; a probe outside it was
/// "outside the domain".
#[test]
fn errors_after_a_deleted_table_say_what_it_changed() {
    let body = format!(
        "{BASE}\n[[body]]\nname = \"b\"\nshape = \"circle\"\ncenter_m = [0.5, 0.7]\nradius_m = \
         0.1\n"
    );
    assert_err(
        &body,
        &[],
        Some(26),
        &["body[0]", "without [body.motion]", "mass"],
    );
    let tankless = BASE
        .replace("[tank]\nmin_m = [0.0, 0.0]\nmax_m = [1.0, 1.0]\n", "")
        .replace("point_m = [0.5, 0.05]", "point_m = [0.9, 0.05]");
    assert_err(
        &tankless,
        &[],
        None,
        &["probe[0].point_m", "there is no tank", "give a [domain]"],
    );
}

/// A NaN in a 2D body's `angular_velocity_rad_s = [w]` was refused naming the list, where every
/// other vector names the component (`...angular_velocity_rad_s[0]`).
#[test]
fn a_nan_rate_of_turn_names_its_component() {
    let text = format!(
        "{BASE}\n[[body]]\nname = \"b\"\nshape = \"circle\"\ncenter_m = [0.5, 0.7]\nradius_m = \
         0.1\nmass_kg = 1.0\n[body.motion]\nkind = \"free\"\nangular_velocity_rad_s = [nan]\n"
    );
    assert_err(
        &text,
        &[],
        Some(34),
        &["body[0].motion.angular_velocity_rad_s[0] = NaN", "finite"],
    );
    let two = text.replace("[nan]", "[1.0, 2.0]");
    assert_err(
        &two,
        &[],
        Some(34),
        &["angular_velocity_rad_s = [1.0, 2.0]", "one number"],
    );
}

/// A free body's mass (density times area) or inertia could overflow to infinity, or a tiny
/// density underflow to 0, and the body was built; its equations of motion divide by both
/// (found by reading `bodies.rs` for the fuzz test's sanity check).
#[test]
fn a_body_mass_or_inertia_out_of_range_is_refused() {
    let body = |fields: &str| {
        format!(
            "{BASE}\n[[body]]\nname = \"b\"\nshape = \"box\"\nmin_m = [0.2, 0.6]\nmax_m = \
             [0.8, 0.9]\n{fields}\n"
        )
    };
    // A 2 m by 0.3 m box of 1.5e308 kg/m³ has 9e307 kg, finite, but an infinite inertia
    // m (w² + h²) / 12; a 2 m by 3.3 m box an infinite mass.
    let wide = body("density_kg_m3 = 1.5e308").replace("max_m = [0.8, 0.9]", "max_m = [2.2, 0.9]");
    assert_err(
        &wide,
        &[],
        Some(31),
        &[
            "body[0].density_kg_m3 = 1.5e308",
            "mass of 9e307 kg",
            "[\"inf\"]",
        ],
    );
    let big = wide.replace("max_m = [2.2, 0.9]", "max_m = [2.2, 3.9]");
    assert_err(
        &big,
        &[],
        Some(31),
        &["body[0].density_kg_m3 = 1.5e308", "mass of inf kg"],
    );
    assert_err(
        &body("density_kg_m3 = 5e-324"),
        &[],
        Some(31),
        &["body[0].density_kg_m3", "mass of 0 kg"],
    );
    // 1e308 kg in a 5 m wide box: m w² / 12 overflows.
    assert_err(
        &body("mass_kg = 1e308").replace("max_m = [0.8, 0.9]", "max_m = [5.2, 0.9]"),
        &[],
        Some(31),
        &["body[0].mass_kg = 1e308", "moments of inertia [\"inf\"]"],
    );
    assert!(load_str(&body("density_kg_m3 = 500.0"), "cases/t.toml", &[]).is_ok());
}

/// serde fills a struct from an array by position: `time = [0.5, 9.0, 1, 5e-324]` was accepted
/// as end_s, output_every_s, probe_every_s and cfl (`CASE_FUZZ_SEED=6823451076234179599`,
/// 20 000 cases, on the seed tests/data/case_fuzz/mirror_2d.toml). A case file names its fields.
#[test]
fn tables_written_as_arrays_are_refused() {
    assert_err(
        &format!(
            "time = [1.0, 0.1]\n{}",
            base_with("[time]\nend_s = 1.0\noutput_every_s = 0.1\n", "")
        ),
        &[],
        Some(1),
        &[
            "time = [1.0, 0.1]",
            "expected a table",
            "found an array",
            "[time] with end_s",
        ],
    );
    assert_err(
        &format!(
            "probe = [[\"P1\", \"pressure\", [0.5, 0.05]]]\n{}",
            base_with(
                "[[probe]]\nname = \"P1\"\nkind = \"pressure\"\npoint_m = [0.5, 0.05]\n",
                ""
            )
        ),
        &[],
        Some(1),
        &[
            "probe[0]",
            "expected a table",
            "found an array",
            "[[probe]]",
        ],
    );
    // The same through an override, and for tables nested in tables and in `[[...]]` elements.
    assert_err(
        BASE,
        &["particles=[0.1, 2.0]"],
        None,
        &[
            "particles",
            "--set particles=[0.1, 2.0]",
            "expected a table",
        ],
    );
    assert_err(
        FLOATING,
        &["body[0].motion=[\"free\"]"],
        None,
        &[
            "body[0].motion",
            "expected a table",
            "[body.motion] with kind",
        ],
    );
    assert_err(
        &format!(
            "{BASE}[[solid]]\nname = \"s\"\nmin_m = [0.6, 0.0]\nmax_m = [0.7, 0.3]\n\
                  density_kg_m3 = 1100.0\nyoungs_modulus_pa = 1e6\npoisson_ratio = 0.4\n\
                  initial_velocity = [\"cantilever_mode\"]\n"
        ),
        &[],
        Some(32),
        &[
            "solid[0].initial_velocity",
            "expected a table",
            "found an array",
        ],
    );
}

/// Deleting the building of `cases/street_flood_mesh_3d.toml` (`body = []`) left its
/// wall-pressure probe on nothing, and the refusal's fix named the tank and obstacles as the
/// walls a probe may sit on but not the bodies it was on.
#[test]
fn a_wall_pressure_probe_on_a_removed_body_names_bodies_in_its_fix() {
    let body = "[[body]]\nname = \"b\"\nshape = \"box\"\nmin_m = [0.2, 0.2]\nmax_m = [0.4, 0.4]\n\
                [body.motion]\nkind = \"fixed\"\n";
    let probe = "[[probe]]\nname = \"w\"\nkind = \"wall_pressure\"\npoint_m = [0.2, 0.3]\n\
                 normal = [-1.0, 0.0]\nradius_m = 0.05\n";
    let with_body = format!("{BASE}\n{probe}\n{body}");
    let sc = load_str(&with_body, "cases/t.toml", &[]).unwrap();
    assert!(sc.bodies[0].motion.is_fixed());
    assert_err(
        &format!("{BASE}\n{probe}"),
        &[],
        None,
        &["probe[1].point_m", "has no wall particle", "[[body]]"],
    );
}

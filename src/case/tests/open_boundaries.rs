//! `[[inlet]]`: the water-injection case's nozzle, and the loader's errors.

use super::*;

const INJECTION: &str = include_str!("../../../cases/water_injection_2d.toml");

#[test]
fn the_injection_nozzle_is_a_buffer_of_layers_behind_its_plane() {
    let s = load_str(INJECTION, "cases/water_injection_2d.toml", &[]).unwrap();
    assert_eq!(s.inlets.len(), 1);
    let inlet = &s.inlets[0];
    // 0.04 m high at dx = 0.005: 8 columns on the plane x = 0.03 m, 6 layers of buffer
    // (0.03 m ≥ 2h = 0.013 m); 1.5 m/s for 1 s is 300 layers.
    assert_eq!(inlet.columns.len(), 8);
    assert!(inlet.columns.iter().all(|c| (c[0] - 0.03).abs() < 1e-12));
    assert!((inlet.columns[0][1] - 0.3025).abs() < 1e-12);
    assert_eq!(inlet.normal, [1.0, 0.0, 0.0]);
    assert!((inlet.thickness - 0.03).abs() < 1e-12);
    assert_eq!(inlet.particles.len(), 8 * 300);
    assert_eq!(s.count(Kind::Inlet), 8 * 300);
    assert_eq!(s.dormant_count(), 8 * 294);
    // Right after the fluid blocks, which are the first particles.
    assert_eq!(inlet.particles.start, s.count(Kind::Fluid));
    // The buffer's front layer half a spacing behind the plane; the waiting layers stacked at
    // the buffer's back.
    let first = s.particles[inlet.particles.start];
    assert!((first.pos[0] - 0.0275).abs() < 1e-12, "{:?}", first.pos);
    assert_eq!(first.vel, [1.5, 0.0, 0.0]);
    assert_eq!(first.rho, 1000.0);
    let last = s.particles[inlet.particles.end - 1];
    assert!((last.pos[0] - 0.0).abs() < 1e-12, "{:?}", last.pos);
    // Stopping earlier makes fewer layers; the inflow sets the speed of sound's scale.
    let short = load_str(INJECTION, "x.toml", &sets(&["inlet[0].stop_s=0.2"])).unwrap();
    assert_eq!(short.inlets[0].particles.len(), 8 * 60);
    let coef = load_str(
        INJECTION,
        "x.toml",
        &sets(&["physics.sound_speed_coef=10", "inlet[0].velocity_m_s=4"]),
    );
    // sound_speed_m_s and sound_speed_coef together are refused; the coefficient alone with
    // a fast inlet gives 10 × 4 m/s.
    assert!(coef.is_err());
    let text = INJECTION.replace("sound_speed_m_s = 30.0", "sound_speed_coef = 10.0");
    let fast = load_str(&text, "x.toml", &sets(&["inlet[0].velocity_m_s=4"])).unwrap();
    assert!((fast.physics.c0 - 40.0).abs() < 1e-9, "{}", fast.physics.c0);
}

#[test]
fn inlet_errors_name_the_field_and_the_fix() {
    assert_err(
        INJECTION,
        &["inlet[0].direction=[1.0, 1.0]"],
        None,
        &[
            "inlet[0].direction",
            "unit vector along an axis",
            "direction = [1.0, 0.0]",
        ],
    );
    assert_err(
        INJECTION,
        &["inlet[0].velocity_m_s=0"],
        None,
        &["inlet[0].velocity_m_s", "> 0"],
    );
    assert_err(
        INJECTION,
        &["inlet[0].max_m=[0.01, 0.34]"],
        None,
        &[
            "inlet[0].max_m",
            "2 layer(s)",
            "2h",
            "at least 0.015 m deep along x",
        ],
    );
    assert_err(
        INJECTION,
        &["inlet[0].min_m=[0.0, 0.05]"],
        None,
        &["inlet[0]", "overlaps fluid_block[0]"],
    );
    assert_err(
        INJECTION,
        &["inlet[0].max_m=[0.03, 0.55]"],
        None,
        &["inlet[0]", "leaves the tank's inner box"],
    );
    let twice = format!(
        "{INJECTION}\n[[inlet]]\nname = \"nozzle\"\nmin_m = [0.2, 0.3]\nmax_m = [0.23, 0.34]\n\
         direction = [1.0, 0.0]\nvelocity_m_s = 1.0\n"
    );
    assert_err(
        &twice,
        &[],
        None,
        &["inlet[1].name", "also the name of inlet[0]"],
    );
    // The whole inflow's particles are made at the start: a long one is refused by the budget.
    assert_err(
        INJECTION,
        &["time.end_s=1e6", "inlet[0].stop_s=1e6"],
        None,
        &[
            "particles.dx_m",
            "in inlet[0]",
            "inlet[0].stop_s, else time.end_s",
        ],
    );
    assert_err(
        INJECTION,
        &["inlet[0].stop_s=-1"],
        None,
        &["inlet[0].stop_s", "> 0"],
    );
}

const OVERFALL: &str = include_str!("../../../cases/free_overfall_2d.toml");

#[test]
fn the_overfall_has_a_critical_inlet_and_a_sump() {
    let s = load_str(OVERFALL, "cases/free_overfall_2d.toml", &[]).unwrap();
    // No fluid block: the inlet alone brings the water (10 columns, 0.04 m at dx = 4 mm).
    assert_eq!(s.count(Kind::Fluid), 0);
    let inlet = &s.inlets[0];
    assert_eq!(inlet.columns.len(), 10);
    assert!((inlet.columns[0][0] - 0.032).abs() < 1e-12);
    // 0.6264 m/s for 2 s is 313 layers (8 of them the buffer).
    assert_eq!(inlet.particles.len(), 10 * 313);
    assert!((inlet.thickness - 0.032).abs() < 1e-12);
    assert_eq!(s.outlets.len(), 1);
    assert_eq!(s.outlets[0].name, "sump");
    assert!(s.outlets[0].contains([0.6, -0.2, 0.0], 2));
    assert!(!s.outlets[0].contains([0.6, -0.05, 0.0], 2));
}

#[test]
fn outlet_errors_name_the_field_and_the_fix() {
    assert_err(
        OVERFALL,
        &["outlet[0].min_m=[1.0, -0.4]", "outlet[0].max_m=[1.2, -0.1]"],
        None,
        &["outlet[0]", "outside the domain", "no fluid could reach it"],
    );
    assert_err(
        OVERFALL,
        &["outlet[0].min_m=[0.0, 0.0]", "outlet[0].max_m=[0.9, 0.1]"],
        None,
        &["outlet[0]", "overlaps inlet[0]"],
    );
    let drain = format!(
        "{INJECTION}\n[[outlet]]\nname = \"drain\"\nmin_m = [0.1, 0.0]\nmax_m = [0.2, 0.05]\n"
    );
    assert_err(&drain, &[], None, &["outlet[0]", "overlaps fluid_block[0]"]);
    let twice = format!(
        "{OVERFALL}\n[[outlet]]\nname = \"sump\"\nmin_m = [0.5, -0.4]\nmax_m = [0.6, -0.3]\n"
    );
    assert_err(
        &twice,
        &[],
        None,
        &["outlet[1].name", "also the name of outlet[0]"],
    );
}

/// The injection case with its nozzle's speed replaced by `inflow` (TOML lines).
fn injection_with(inflow: &str) -> String {
    let text = INJECTION.replace("velocity_m_s = 1.5\n", &format!("{inflow}\n"));
    assert_ne!(text, INJECTION);
    text
}

#[test]
fn a_hydrograph_inlet_makes_the_layers_its_volume_takes() {
    let dir = folder("hydrograph");
    // A triangle: 0 at 0 s, 0.06 m²/s at 0.4 s, 0 at 0.8 s; ∫Q = 0.024 m², over the nozzle's 8
    // columns of 5 mm (0.04 m) a distance of 0.6 m: 120 layers.
    std::fs::write(
        dir.join("q.csv"),
        "# a triangle hydrograph\nt_s,q_m2_s\n0,0\n0.4,0.06\n0.8,0\n",
    )
    .unwrap();
    let s = load_in(&dir, &injection_with("discharge_file = \"q.csv\"")).unwrap();
    let inlet = &s.inlets[0];
    assert_eq!(inlet.particles.len(), 8 * 120);
    assert!((inlet.inflow.speed(0.4) - 1.5).abs() < 1e-12);
    assert!((inlet.inflow.distance(2.0) - 0.6).abs() < 1e-12);
    // The particles start still; a constant discharge is a constant speed.
    assert_eq!(s.particles[inlet.particles.start].vel, [0.0, 0.0, 0.0]);
    let q = load_in(&dir, &injection_with("discharge_m3_s = 0.02")).unwrap();
    assert!((q.inlets[0].inflow.speed(0.3) - 0.5).abs() < 1e-12);
    // A speed in time and the cubic's join.
    std::fs::write(dir.join("u.csv"), "0,0.5\n0.5,1.0\n1.0,0.5\n").unwrap();
    let u = load_in(
        &dir,
        &injection_with("velocity_file = \"u.csv\"\ninterpolation = \"cubic\""),
    )
    .unwrap();
    let h = &u.inlets[0].inflow;
    assert_eq!(h.speed(0.5), 1.0);
    assert!(
        h.speed(0.25) > 0.75,
        "the cubic rounds the rise: {}",
        h.speed(0.25)
    );
}

/// A level-driven nozzle (0.30–0.34 m high, 8 rows at dx = 5 mm, centres from 0.3025 m): its
/// columns flow while the level is above their centres, each carrying its own distance, and the
/// layers are made for the lowest, which flows longest.
#[test]
fn a_level_inlet_wets_the_columns_below_its_level() {
    let dir = folder("level");
    // Up from 0.31 m to 0.35 m over 0.4 s, held there.
    std::fs::write(dir.join("h.csv"), "t_s,level_m\n0,0.31\n0.4,0.35\n").unwrap();
    let s = load_in(
        &dir,
        &injection_with("velocity_m_s = 1.5\nlevel_file = \"h.csv\""),
    )
    .unwrap();
    let inlet = &s.inlets[0];
    let level = inlet.level.as_ref().expect("a level");
    assert_eq!(level.up, [0.0, 1.0, 0.0]);
    // The two lowest rows (0.3025, 0.3075 m) flow from the start; the top row (0.3375 m) from
    // t = 0.4 · 0.0275 / 0.04 = 0.275 s.
    let rows: Vec<usize> = (0..8)
        .map(|c| (inlet.columns[c][1] * 1e4).round() as usize)
        .collect();
    assert_eq!(rows[0], 3025);
    let top = (0..8).max_by_key(|&c| rows[c]).unwrap();
    let low = (0..8).min_by_key(|&c| rows[c]).unwrap();
    assert!(inlet.travel(low, 0.0).flows && !inlet.travel(top, 0.2).flows);
    let w = level.windows.iter().find(|w| w.column == top).unwrap();
    assert!(
        (w.start - 0.275).abs() < 1e-12 && w.end.is_infinite(),
        "{w:?}"
    );
    assert!((inlet.travel(top, 0.5).distance - 1.5 * (0.5 - 0.275)).abs() < 1e-12);
    assert!((inlet.travel(low, 0.5).distance - 0.75).abs() < 1e-12);
    // 1.5 m/s for 1 s at the lowest row: 300 layers; the waiting ones include the columns the
    // level does not reach at t = 0.
    assert_eq!(inlet.particles.len(), 8 * 300);
    let wet = (0..8).filter(|&c| inlet.travel(c, 0.0).flows).count();
    assert_eq!(wet, 2);
    assert_eq!(s.dormant_count(), 8 * 300 - wet * 6);
}

#[test]
fn bad_levels_are_refused_naming_the_field_and_fix() {
    let dir = folder("bad_level");
    std::fs::write(dir.join("h.csv"), "0,0.31\n0.4,0.35\n").unwrap();
    let with = |inflow: &str| injection_with(&format!("{inflow}\nlevel_file = \"h.csv\""));
    let q = with("discharge_m3_s = 0.02");
    assert_refused(
        load_in(&dir, &q),
        &[
            "inlet[0].level_file",
            "discharge_m3_s",
            "velocity_m_s or velocity_file",
        ],
        &q,
    );
    let still = with("velocity_m_s = 1.5").replace("[0.0, -9.81]", "[0.0, 0.0]");
    assert_refused(
        load_in(&dir, &still),
        &[
            "inlet[0].level_file",
            "needs gravity",
            "physics.gravity_m_s2",
        ],
        &still,
    );
    // Above the nozzle only after its stop at 1 s.
    std::fs::write(dir.join("low.csv"), "0,0.2\n0.5,0.3\n1.5,0.3\n3,0.4\n").unwrap();
    let low = injection_with("velocity_m_s = 1.5\nlevel_file = \"low.csv\"");
    assert_refused(
        load_in(&dir, &low),
        &[
            "inlet[0].level_file",
            "never rises above",
            "0.3025 m",
            "brings no water",
        ],
        &low,
    );
    std::fs::write(dir.join("h.csv"), "-1,0.31\n0.4,0.35\n").unwrap();
    let early = with("velocity_m_s = 1.5");
    assert_refused(
        load_in(&dir, &early),
        &["h.csv line 1", "before the run starts", "from 0 s on"],
        &early,
    );
    std::fs::write(dir.join("h.csv"), "0,0.31\n0.4,nan\n").unwrap();
    assert_refused(
        load_in(&dir, &early),
        &["inlet[0].level_file", "h.csv line 2"],
        &early,
    );
}

#[test]
fn bad_hydrographs_are_refused_naming_the_file_line_and_fix() {
    let dir = folder("bad_hydrograph");
    let refused = |rows: &str, words: &[&str]| {
        std::fs::write(dir.join("q.csv"), rows).unwrap();
        let text = injection_with("discharge_file = \"q.csv\"");
        assert_refused(load_in(&dir, &text), words, rows);
    };
    refused(
        "0,0.1\n0.5,0.2\n0.5,0.3\n",
        &[
            "inlet[0].discharge_file",
            "q.csv line 3",
            "does not increase",
        ],
    );
    refused(
        "-1,0.1\n0.5,0.2\n",
        &["q.csv line 1", "before the run starts", "from 0 s on"],
    );
    refused(
        "0,0.1\n0.5,-0.2\n",
        &["q.csv line 2", "q_m3_s = -0.2 is negative", "[[outlet]]"],
    );
    refused("0,0\n1,0\n", &["is 0 at every time", "remove the inlet"]);
    refused("t;q\n0;1\n", &["comma-separated", "t_s, q_m3_s"]);
    refused("# nothing\n", &["no data rows", "add rows t_s, q_m3_s"]);
    // One inflow, and interpolation only with a file.
    let both = injection_with("discharge_m3_s = 0.02\nvelocity_m_s = 1.0");
    assert_refused(
        load_in(&dir, &both),
        &[
            "inlet[0].discharge_m3_s",
            "together with velocity_m_s",
            "keep one",
        ],
        &both,
    );
    let none = injection_with("");
    assert_refused(
        load_in(&dir, &none),
        &["inlet[0].velocity_m_s", "is missing", "discharge_file"],
        &none,
    );
    let lone = injection_with("velocity_m_s = 1.0\ninterpolation = \"cubic\"");
    assert_refused(
        load_in(&dir, &lone),
        &["inlet[0].interpolation", "remove it"],
        &lone,
    );
    let missing = injection_with("velocity_file = \"no_such.csv\"");
    assert_refused(
        load_in(&dir, &missing),
        &[
            "inlet[0].velocity_file",
            "no_such.csv",
            "relative to the case file",
        ],
        &missing,
    );
    // Faster than sound at its peak.
    std::fs::write(dir.join("u.csv"), "0,1\n0.2,45\n0.4,1\n").unwrap();
    let fast = injection_with("velocity_file = \"u.csv\"");
    assert_refused(
        load_in(&dir, &fast),
        &["inlet[0].velocity_file", "45 m/s", "speed of sound"],
        &fast,
    );
}

/// A discharge probe across the injection's lower chamber.
fn with_section(fields: &str) -> String {
    format!("{INJECTION}\n[[probe]]\nname = \"Q\"\nkind = \"discharge\"\n{fields}\n")
}

#[test]
fn discharge_sections_are_read_and_bad_ones_refused() {
    let s = load_str(
        &with_section("from_m = [0.3, 0.0]\nto_m = [0.3, 0.2]"),
        "x.toml",
        &[],
    )
    .unwrap();
    let q = s.probes.iter().find(|p| p.name == "Q").unwrap();
    let ProbeKind::Discharge { from, to } = q.kind else {
        panic!("{:?}", q.kind)
    };
    assert_eq!((from, to), ([0.3, 0.0, 0.0], [0.3, 0.2, 0.0]));
    // Drawn upwards, the section counts flow along +x.
    let (n, length) = ProbeKind::section_normal(from, to);
    assert_eq!((n, length), ([1.0, 0.0, 0.0], 0.2));
    assert_err(
        &with_section("from_m = [0.3, 0.0]"),
        &[],
        None,
        &["probe[", "to_m", "is required for a \"discharge\" probe"],
    );
    assert_err(
        &with_section("from_m = [0.3, 0.1]\nto_m = [0.3, 0.1]"),
        &[],
        None,
        &["to_m", "the section has no length"],
    );
    assert_err(
        &with_section("from_m = [0.3, 0.0]\nto_m = [0.3, 0.2]\nbody = \"tank\""),
        &[],
        None,
        &["body", "its section stays where it is drawn", "remove body"],
    );
    assert_err(
        &with_section("from_m = [0.3, 0.0]\nto_m = [0.3, 9.0]"),
        &[],
        None,
        &["to_m", "lies outside"],
    );
    assert_err(
        &with_section("from_m = [0.3, 0.0]\nto_m = [0.3, 0.2]\npoint_m = [0.1, 0.1]"),
        &[],
        None,
        &["point_m", "is not used by a \"discharge\" probe"],
    );
}

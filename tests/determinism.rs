//! The same input on the same adapter gives bit-identical results (no float atomics; the sort
//! orders each slot by code word: kind, then particle id).

use crate::common::gpu;
use std::path::Path;
use wgsph::sph::Solver;

/// Bit-identical for each cell size (`particles.cell`).
#[test]
fn same_case_twice_is_bit_identical() {
    for cell in ["h", "2h"] {
        let set = vec![
            "particles.dx_m=0.0073".to_string(),
            format!("particles.cell={cell}"),
        ];
        let sc = wgsph::case::load(Path::new("cases/dam_break_2d.toml"), &set).unwrap();
        let run = || {
            let mut s = Solver::new(gpu(), &sc).unwrap();
            s.advance_to(0.08).unwrap();
            (s.steps(), s.read_raw().unwrap(), s.read_rates().unwrap())
        };
        let (steps_a, (pa, va, ca), ra) = run();
        let (steps_b, (pb, vb, cb), rb) = run();
        assert!(steps_a > 100);
        assert_eq!(steps_a, steps_b);
        assert_eq!(ca, cb, "cells of {cell}: particle order differs");
        assert!(pa == pb, "cells of {cell}: positions differ");
        assert_eq!(
            bits(&va),
            bits(&vb),
            "cells of {cell}: velocities/densities differ"
        );
        assert_eq!(bits(&ra), bits(&rb), "cells of {cell}: rates differ");
    }
}

fn bits(v: &[[f32; 4]]) -> Vec<u32> {
    v.iter().flat_map(|x| x.map(f32::to_bits)).collect()
}

/// Cells of h and of 2h find the same neighbours and sum them in another order: from the same
/// state, the first step's rates agree particle by particle within the f32 rounding of the
/// sums (a few hundred terms: 2 × 10⁻⁵ of each rate's largest magnitude), in 2D and in 3D.
#[test]
fn cells_of_h_and_2h_give_the_same_rates_but_for_rounding() {
    let cases = [
        ("cases/dam_break_2d.toml", "particles.dx_m=0.0073"),
        ("cases/bench_spheric2.toml", "particles.dx_m=0.05"),
    ];
    for (case, dx) in cases {
        let rates = |cell: &str| {
            let set = vec![dx.to_string(), format!("particles.cell={cell}")];
            let sc = wgsph::case::load(Path::new(case), &set).unwrap();
            let mut s = Solver::new(gpu(), &sc).unwrap();
            s.run_steps(1).unwrap();
            let (_, _, code) = s.read_raw().unwrap();
            let mut by_id = vec![[f32::NAN; 4]; code.len()];
            for (c, r) in code.iter().zip(s.read_rates().unwrap()) {
                by_id[(c & wgsph::layout::ID_MASK) as usize] = r;
            }
            by_id
        };
        let (h, two_h) = (rates("h"), rates("2h"));
        let scale: [f32; 4] =
            std::array::from_fn(|k| h.iter().map(|r| r[k].abs()).fold(0.0, f32::max));
        let mut worst = 0f32;
        for (a, b) in h.iter().zip(&two_h) {
            for k in 0..4 {
                worst = worst.max((a[k] - b[k]).abs() / scale[k]);
            }
        }
        println!("{case}: largest difference {worst:e} of the rate's scale");
        assert!(worst < 2e-5, "{case}: the cell sizes differ by {worst:e}");
    }
}

/// `bench --stages` records each stage of the step in a timed pass of its own: that must change
/// the timing only. Run with and without profiling, the particles are bit-identical, and every
/// stage of the step is timed, once per step, in the step's order.
#[test]
fn profiling_the_stages_changes_nothing_but_the_timing() {
    let cases: [(&str, &[&str], &[&str]); 2] = [
        (
            "cases/floating_box_2d.toml",
            &["particles.dx_m=0.04"],
            &[
                "predict",
                "body_move",
                "sort_key",
                "sort_scan",
                "sort_scatter",
                "sort_reorder",
                "body_index",
                "ghost",
                "interaction",
                "body_force",
                "correct",
            ],
        ),
        (
            "cases/oscillating_plate_2d.toml",
            &[],
            &[
                "predict",
                "elastic_predict",
                "sort_key",
                "sort_scan",
                "sort_scatter",
                "sort_reorder",
                "ghost",
                "interaction",
                "elastic_rates",
                "elastic_correct",
                "correct",
            ],
        ),
    ];
    for (case, set, stages) in cases {
        let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        let sc = wgsph::case::load(Path::new(case), &set).unwrap();
        let mut plain = Solver::new(gpu(), &sc).unwrap();
        plain.run_steps(12).unwrap();
        let mut profiled = Solver::new(gpu(), &sc).unwrap();
        let times = profiled.profile_steps(12).unwrap();
        assert_eq!(plain.steps(), profiled.steps());
        assert!(
            plain.read_raw().unwrap() == profiled.read_raw().unwrap(),
            "{case}: profiling changed the particles"
        );
        let names: Vec<&str> = times.iter().map(|s| s.name).collect();
        assert_eq!(names, stages, "{case}");
        assert!(
            times
                .iter()
                .all(|s| s.seconds.is_finite() && s.seconds >= 0.0),
            "{case}: {times:?}"
        );
        let interaction = times.iter().find(|s| s.name == "interaction").unwrap();
        assert!(interaction.seconds > 0.0, "{case}: {times:?}");
    }
}

/// Wide particle ids (`particles.id_low_bits`, as a run of 2²⁸ particles or more takes them)
/// give what narrow ids give, bit for bit: forced here with 4 low bits, so that most particles
/// share their code word's id bits with others and only the second word tells them apart; a
/// pass that read the code word's bits as the id would misplace, mismatch or mix them. Each
/// case exercises what looks particles up by id: dynamic walls and the fronts; fixed ghosts, a
/// free body and its probes; an updated- and a total-Lagrangian solid; an inlet's waiting
/// particles; the density filter and the energy equation.
#[test]
fn wide_ids_give_what_narrow_ids_give() {
    let cases: [(&str, &[&str], u64); 6] = [
        ("cases/dam_break_2d.toml", &["particles.dx_m=0.0073"], 150),
        ("cases/floating_box_2d.toml", &["particles.dx_m=0.02"], 150),
        ("cases/oscillating_plate_2d.toml", &[], 100),
        ("cases/oscillating_plate_tl_2d.toml", &[], 100),
        (
            "cases/water_injection_2d.toml",
            &["particles.dx_m=0.01"],
            200,
        ),
        (
            "cases/dam_break_2d.toml",
            &[
                "particles.dx_m=0.0073",
                "physics.density_filter=\"mls\"",
                "physics.density_filter_every=7",
                "physics.energy=true",
            ],
            150,
        ),
    ];
    for (case, set, steps) in cases {
        let run = |wide: bool| {
            let mut set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
            if wide {
                set.push("particles.id_low_bits=4".into());
            }
            let sc = wgsph::case::load(Path::new(case), &set).unwrap();
            let mut s = Solver::new(gpu(), &sc).unwrap();
            assert_eq!(s.ids().wide, wide);
            s.run_steps(steps).unwrap();
            let probes: Vec<u64> = (s.sample_probes().unwrap().iter())
                .map(|v| v.to_bits())
                .collect();
            (s.read_particles().unwrap(), probes)
        };
        let (narrow, wide) = (run(false), run(true));
        assert!(narrow.0.id.len() > 16 * 4, "{case}: too few particles");
        assert!(narrow.0 == wide.0, "{case}: the particles differ");
        assert_eq!(narrow.1, wide.1, "{case}: the probes differ");
    }
}

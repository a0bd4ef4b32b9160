//! The same input on the same adapter gives bit-identical results (no float atomics; the sort
//! orders each cell by previous index).

mod common;
use common::gpu;
use std::path::Path;
use wgsph::sph::Solver;

#[test]
fn same_case_twice_is_bit_identical() {
    let set = vec!["particles.dx_m=0.0073".to_string()];
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
    assert_eq!(ca, cb, "particle order differs");
    assert!(pa == pb, "positions differ");
    let bits = |v: &Vec<[f32; 4]>| {
        v.iter()
            .flat_map(|x| x.map(f32::to_bits))
            .collect::<Vec<u32>>()
    };
    assert_eq!(bits(&va), bits(&vb), "velocities/densities differ");
    assert_eq!(bits(&ra), bits(&rb), "rates differ");
}

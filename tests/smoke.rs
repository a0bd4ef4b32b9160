mod common;
use common::*;
use wgsph::scenario::*;
use wgsph::sph::Solver;

#[test]
fn falling_block_runs() {
    let dx = 0.02;
    let ph = physics(2, dx, 20.0);
    let parts: Vec<Particle> = lattice(2, dx, [0.2, 0.2, 0.0], [0.4, 0.4, 0.0])
        .into_iter()
        .map(|p| Particle { pos: p, vel: [0.0; 3], rho: 1000.0, kind: Kind::Fluid })
        .collect();
    let n = parts.len();
    let sc = scenario(ph, parts, Domain { min: [0.0; 3], max: [1.0, 1.0, 0.0] }, vec![]);
    let mut s = Solver::new(gpu(), &sc).unwrap();
    println!("dt0 {} cells {:?} slots {}", s.dt(), s.grid.cells, s.grid.slots);
    s.advance_to(0.05).unwrap();
    let p = s.read_particles().unwrap();
    println!("t {} steps {} excluded {}", s.time(), s.steps(), s.excluded());
    assert_eq!(p.pos.len(), n);
    let ymean: f64 = p.pos.iter().map(|x| x[1]).sum::<f64>() / n as f64;
    println!("ymean {ymean} v0 {:?}", p.vel[0]);
}

//! Layer 2: a free block of fluid in gravity. Internal forces (pressure, viscosity) are
//! antisymmetric in the pair, so total momentum changes only by gravity: the centroid falls as
//! ½gt² and the mean velocity is gt, whatever the block does internally.

mod common;
use common::*;
use wgsph::scenario::*;
use wgsph::sph::Solver;

#[test]
fn free_block_centroid_follows_gravity() {
    for dim in [2, 3] {
        let dx = 0.02;
        let mut rng = Rng(99);
        let ph = physics(dim, dx, 20.0);
        let max = if dim == 2 {
            [0.4, 0.4, 0.0]
        } else {
            [0.3, 0.3, 0.3]
        };
        let parts: Vec<Particle> =
            lattice(dim, dx, [0.2, 0.2, if dim == 3 { 0.2 } else { 0.0 }], max)
                .into_iter()
                .map(|p| Particle {
                    pos: p,
                    vel: [0.0; 3],
                    // Density noise makes the block oscillate internally.
                    rho: 1000.0 * (1.0 + rng.range(0.0, 0.01)),
                    kind: Kind::Fluid,
                })
                .collect();
        let n = parts.len() as f64;
        let up = dim as usize - 1;
        let c0 = parts.iter().map(|p| p.pos[up]).sum::<f64>() / n;
        let domain = Domain {
            min: [0.0; 3],
            max: if dim == 2 { [1.0, 1.0, 0.0] } else { [1.0; 3] },
        };
        let sc = scenario(ph, parts, domain, vec![]);
        let mut s = Solver::new(gpu(), &sc).unwrap();
        let t = 0.05;
        s.advance_to(t).unwrap();
        let p = s.read_particles().unwrap();
        let c = p.pos.iter().map(|x| x[up]).sum::<f64>() / n;
        let v = p.vel.iter().map(|v| v[up] as f64).sum::<f64>() / n;
        let (c_exact, v_exact) = (c0 - 0.5 * 9.81 * t * t, -9.81 * t);
        println!("{dim}D: centroid {c:.6} (exact {c_exact:.6}), mean v {v:.6} (exact {v_exact:.6}), {} steps", s.steps());
        assert!(
            (v - v_exact).abs() < 1e-4 * v_exact.abs(),
            "mean velocity {v}"
        );
        assert!((c - c_exact).abs() < 1e-3 * (c0 - c_exact), "centroid {c}");
    }
}

//! Layer 2: a free block of fluid in gravity. Internal forces (pressure, viscosity) are
//! antisymmetric in the pair, so total momentum changes only by gravity: the centroid falls as
//! ½gt² and the mean velocity is gt, whatever the block does internally.

use crate::common::*;
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

/// Layer 2 for velocity inlets: a horizontal jet leaves a nozzle (0.02 m, 4 columns of
/// dx = 0.005 m) at U = 1.5 m/s into an empty domain. Each particle crosses the plane at
/// t_c = (layer + ½) dx / U and then flies free: x = x_plane + U (t − t_c), y = y_column −
/// ½ g (t − t_c)². The inflow is exact (every layer whose time has come, no particle lost or
/// made twice); the paths are compared, layer by layer, with that ballistic one. The jet's head
/// (the layers within the kernel support 2h of its front) is held back by the tension of the
/// stretching jet behind it, pulled from one side only: it is reported, the body is asserted.
#[test]
fn a_jet_from_an_inlet_flies_ballistically() {
    let text = r#"dimension = 2
[particles]
dx_m = 0.005
h_over_dx = 1.3
[physics]
gravity_m_s2 = [0.0, -9.81]
sound_speed_m_s = 30.0
[time]
end_s = 0.2
output_every_s = 0.1
[domain]
min_m = [0.0, 0.0]
max_m = [0.5, 0.4]
[[inlet]]
name = "nozzle"
min_m = [0.0, 0.3]
max_m = [0.015, 0.32]
direction = [1.0, 0.0]
velocity_m_s = 1.5
"#;
    let sc = wgsph::case::load_str(text, "jet.toml", &[]).unwrap();
    let inlet = &sc.inlets[0];
    let (u, dx, g) = (1.5, 0.005, 9.81);
    let mut s = Solver::new(gpu(), &sc).unwrap();
    let t = 0.2;
    s.advance_to(t).unwrap();
    let p = s.read_particles().unwrap();
    let n_col = inlet.columns.len();
    assert_eq!(n_col, 4);
    // Fluid by now: the layers with (layer + ½) dx ≤ U t, i.e. 60.
    let fluid: Vec<usize> = inlet
        .particles
        .clone()
        .filter(|&id| p.kind[id] == Kind::Fluid as u32)
        .collect();
    let due = ((u * t / dx + 0.5).floor() as usize) * n_col;
    assert_eq!(fluid.len(), due, "particles injected by t = {t} s");
    assert_eq!(s.excluded(), 0, "no particle left the domain");
    // Per layer: the mean place against the ballistic one, and the error over the distance the
    // layer has flown.
    // Layers more than 2h = 2.6 dx behind the front.
    let head = 4;
    let (mut worst, mut worst_head) = ((0.0f64, 0usize), 0.0f64);
    let mut worst_far = 0.0f64;
    for layer in 0..due / n_col {
        let tc = (layer as f64 + 0.5) * dx / u;
        let tau = t - tc;
        let ids = (0..n_col).map(|c| inlet.particles.start + layer * n_col + c);
        let (mut x, mut y) = (0.0, 0.0);
        for id in ids {
            x += p.pos[id][0] / n_col as f64;
            y += p.pos[id][1] / n_col as f64;
        }
        let y_col = 0.5 * (inlet.columns[0][1] + inlet.columns[n_col - 1][1]);
        let (xe, ye) = (0.015 + u * tau, y_col - 0.5 * g * tau * tau);
        let e = ((x - xe).powi(2) + (y - ye).powi(2)).sqrt();
        if layer < head {
            worst_head = worst_head.max(e);
        } else {
            if e > worst.0 {
                worst = (e, layer);
            }
            let flown = u * tau;
            if flown > 0.1 {
                worst_far = worst_far.max(e / flown);
            }
        }
    }
    println!(
        "jet: {} particles injected; body: worst layer {} off by {:.2e} m ({:.3} dx), beyond \
         0.1 m of flight at most {:.2} % of the distance flown; head: {:.2} dx; {} steps",
        fluid.len(),
        worst.1,
        worst.0,
        worst.0 / dx,
        100.0 * worst_far,
        worst_head / dx,
        s.steps()
    );
    assert!(
        worst.0 < 0.1 * dx,
        "layer {} of the jet's body is {} m off its ballistic place",
        worst.1,
        worst.0
    );
}

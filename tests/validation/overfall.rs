//! Free overfall (`cases/free_overfall_2d.toml`): a horizontal channel fed at its critical
//! depth y_c by a velocity inlet ends in a drop, and an outlet removes the falling nappe. Once
//! the flow is steady the outlet drains what the inlet brings, and the depth at the brink is
//! 0.715 y_c (Rouse 1936; the inviscid potential-flow solutions agree).

use std::path::Path;

use crate::common::gpu;
use wgsph::sph::Solver;

const Y_C: f64 = 0.04;
/// Rouse (1936): brink depth over critical depth, horizontal bed.
const BRINK_RATIO: f64 = 0.715;

struct Overfall {
    /// Drained over injected in the window.
    balance: f64,
    /// Mean depths over y_c in the window: brink, 3 y_c upstream, near the inlet.
    brink: f64,
    upstream: f64,
    inflow: f64,
    escaped: u64,
}

/// Runs the case at `dx` to `end_s`, averaging over its last second.
fn overfall(dx: f64, end_s: f64) -> Overfall {
    let set = [
        format!("particles.dx_m={dx}"),
        format!("time.end_s={end_s}"),
    ];
    let sc = wgsph::case::load(Path::new("cases/free_overfall_2d.toml"), &set).unwrap();
    let inlet = &sc.inlets[0];
    let layers = inlet.particles.len() / inlet.columns.len();
    // Particles through the plane by t: (layer + ½) dx ≤ U t.
    let injected = |t: f64| {
        let crossed = ((inlet.speed * t / dx + 0.5).floor() as usize).min(layers);
        (crossed * inlet.columns.len()) as f64
    };
    let mut s = Solver::new(gpu(), &sc).unwrap();
    let start = end_s - 1.0;
    s.advance_to(start).unwrap();
    let drained0 = s.drained() as f64;
    let mut sums = [0.0; 3];
    let mut n = 0.0;
    let mut t = start;
    while t < end_s - 1e-9 {
        t += 0.01;
        s.advance_to(t).unwrap();
        let p = s.sample_probes().unwrap();
        for k in 0..3 {
            sums[k] += p[k] / Y_C;
        }
        n += 1.0;
    }
    Overfall {
        balance: (s.drained() as f64 - drained0) / (injected(end_s) - injected(start)),
        brink: sums[0] / n,
        upstream: sums[1] / n,
        inflow: sums[2] / n,
        escaped: s.excluded(),
    }
}

fn report(tag: &str, o: &Overfall) {
    println!(
        "overfall {tag}: drained / injected over the last second {:.4}; depth / y_c: brink \
         {:.3} (Rouse {BRINK_RATIO}: {:+.1} %), 3 y_c upstream {:.3}, near the inlet {:.3}; \
         escaped {}",
        o.balance,
        o.brink,
        100.0 * (o.brink / BRINK_RATIO - 1.0),
        o.upstream,
        o.inflow,
        o.escaped
    );
}

/// dx = 10 mm (y_c = 4 dx), 4 s: the flow is steady over the last second, so the outlet takes
/// what the inlet brings (to the discreteness of the nappe: a layer of the inflow is 1.6 % of
/// the second's); the depths are reported.
#[test]
fn overfall_outlet_drains_what_the_inlet_brings_coarse() {
    let o = overfall(0.01, 4.0);
    report("dx = 0.01", &o);
    assert_eq!(o.escaped, 0, "no particle escapes the domain");
    assert!(
        (o.balance - 1.0).abs() < 0.05,
        "outflow / inflow {} over the last second",
        o.balance
    );
}

/// dx = 4 mm (y_c = 10 dx), 4 s: the brink depth against Rouse's 0.715 y_c within 5 %.
#[test]
#[ignore = "fails: 0.800 y_c (+11.9 %) at dx = 4 mm, 0.832 (+16.4 %) at 8 mm as shipped \
            (dynamic bed, hydrostatic buffer); 0.583 at 8 mm on a free-slip fixed-ghost bed; \
            docs/validation.md 'Free overfall'; ~10 min on lavapipe"]
fn overfall_brink_depth_within_5_percent_of_rouse_fine() {
    let o = overfall(0.004, 4.0);
    report("dx = 0.004", &o);
    assert!(
        (o.brink / BRINK_RATIO - 1.0).abs() < 0.05,
        "brink depth {} y_c",
        o.brink
    );
}

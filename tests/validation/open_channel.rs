//! Open channels fed by a velocity inlet and drained by an outlet, each run until its flow is
//! steady; then the outlet drains what the inlet brings, and the depths follow open-channel
//! hydraulics.
//! - Free overfall (`cases/free_overfall_2d.toml`): a horizontal channel fed at its critical
//!   depth y_c ends in a drop; the depth at the brink is 0.715 y_c (Rouse 1936; the inviscid
//!   potential-flow solutions agree).
//! - Broad-crested weir (`cases/broad_crested_weir_2d.toml`): a basin ends in a raised crest;
//!   the flow is critical on it, and the upstream depth follows from the specific energy. The
//!   basin's water stands above the inlet's buffer, whose pressure is extrapolated from it.

use std::path::Path;

use crate::common::gpu;
use wgsph::scenario::Scenario;
use wgsph::sph::Solver;

/// Overfall: the inflow's (critical) depth.
const Y_C: f64 = 0.04;
/// Rouse (1936): brink depth over critical depth, horizontal bed.
const BRINK_RATIO: f64 = 0.715;

/// A steady window of a run.
struct Steady {
    /// Drained over injected in the window.
    balance: f64,
    /// Mean reading of each probe over the window, in the case's order.
    depths: Vec<f64>,
    escaped: u64,
}

/// `case` at `dx`, run to `end_s`.
fn load(case: &str, dx: f64, end_s: f64) -> Scenario {
    let set = [
        format!("particles.dx_m={dx}"),
        format!("time.end_s={end_s}"),
    ];
    wgsph::case::load(Path::new(case), &set).unwrap()
}

/// Runs `sc` to its end and averages its probes over the last `window_s`, sampled every
/// 0.01 s.
fn steady(sc: &Scenario, window_s: f64) -> Steady {
    let end_s = sc.time.end_s;
    let mut s = Solver::new(gpu(), sc).unwrap();
    let start = end_s - window_s;
    s.advance_to(start).unwrap();
    let drained0 = s.drained() as f64;
    let mut sums = vec![0.0; sc.probes.len()];
    let mut n = 0.0;
    let mut t = start;
    while t < end_s - 1e-9 {
        t += 0.01;
        s.advance_to(t).unwrap();
        for (sum, p) in sums.iter_mut().zip(s.sample_probes().unwrap()) {
            *sum += p;
        }
        n += 1.0;
    }
    Steady {
        balance: (s.drained() as f64 - drained0)
            / (injected(sc, end_s) - injected(sc, start)) as f64,
        depths: sums.iter().map(|s| s / n).collect(),
        escaped: s.excluded(),
    }
}

/// The overfall's steady last second: (brink, 3 y_c upstream, near the inlet) over y_c.
fn overfall(dx: f64, end_s: f64) -> (Steady, [f64; 3]) {
    let o = steady(&load("cases/free_overfall_2d.toml", dx, end_s), 1.0);
    let d = [0, 1, 2].map(|k| o.depths[k] / Y_C);
    println!(
        "overfall dx = {dx}: drained / injected over the last second {:.4}; depth / y_c: brink \
         {:.3} (Rouse {BRINK_RATIO}: {:+.1} %), 3 y_c upstream {:.3}, near the inlet {:.3}; \
         escaped {}",
        o.balance,
        d[0],
        100.0 * (d[0] / BRINK_RATIO - 1.0),
        d[1],
        d[2],
        o.escaped
    );
    (o, d)
}

/// dx = 10 mm (y_c = 4 dx), 4 s: the flow is steady over the last second, so the outlet takes
/// what the inlet brings (to the discreteness of the nappe: a layer of the inflow is 1.6 % of
/// the second's); the depths are reported.
#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 2 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn overfall_outlet_drains_what_the_inlet_brings_coarse() {
    let (o, _) = overfall(0.01, 4.0);
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
    let (_, [brink, ..]) = overfall(0.004, 4.0);
    assert!(
        (brink / BRINK_RATIO - 1.0).abs() < 0.05,
        "brink depth {brink} y_c"
    );
}

/// Weir: q = 0.02 m²/s over a crest Δz = 0.04 m high.
const WEIR_Q: f64 = 0.02;
const WEIR_DZ: f64 = 0.04;

/// The loss-free upstream depth of the weir: the subcritical root of
/// y + q²/(2 g y²) = Δz + 3/2 y_c (Henderson 1966, "Open Channel Flow"), by bisection.
fn weir_upstream_depth() -> f64 {
    let g = 9.81;
    let y_c = (WEIR_Q * WEIR_Q / g).cbrt();
    let energy = |y: f64| y + WEIR_Q * WEIR_Q / (2.0 * g * y * y);
    let target = WEIR_DZ + 1.5 * y_c;
    let (mut lo, mut hi) = (y_c, target);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if energy(mid) > target {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The weir's steady last `window_s`: (upstream, crest, near the inlet) depths over the
/// loss-free upstream depth (crest: the depth on the crest over y_c).
fn weir(dx: f64, end_s: f64, window_s: f64) -> (Steady, [f64; 3]) {
    let o = steady(
        &load("cases/broad_crested_weir_2d.toml", dx, end_s),
        window_s,
    );
    let y1 = weir_upstream_depth();
    let y_c = (WEIR_Q * WEIR_Q / 9.81).cbrt();
    let d = [o.depths[0] / y1, o.depths[1] / y_c, o.depths[2] / y1];
    println!(
        "weir dx = {dx}: drained / injected over the last {window_s} s {:.4}; upstream depth \
         {:.4} m against the loss-free {y1:.4} m ({:+.1} %), near the inlet {:+.1} %; crest mid \
         {:.3} y_c; escaped {}",
        o.balance,
        o.depths[0],
        100.0 * (d[0] - 1.0),
        100.0 * (d[2] - 1.0),
        d[1],
        o.escaped
    );
    (o, d)
}

/// The weir at `dx` to 6 s (the pool fills from the crest's height and settles with a time
/// constant near 0.8 s), means over the last second: the outlet drains what the inlet brings
/// and the upstream depth is within `bound` of the loss-free depth.
fn weir_within(dx: f64, bound: f64) {
    let (o, d) = weir(dx, 6.0, 1.0);
    assert_eq!(o.escaped, 0, "no particle escapes the domain");
    assert!(
        (o.balance - 1.0).abs() < 0.05,
        "outflow / inflow {}",
        o.balance
    );
    assert!(
        (d[0] - 1.0).abs() < bound,
        "upstream depth {:+.1} %",
        100.0 * (d[0] - 1.0)
    );
}

/// dx = 10 mm (y_c = 3.4 dx): within 10 %.
#[test]
#[ignore = "met but slow for CI: +8.6 %, about 4 min on lavapipe"]
fn weir_upstream_depth_within_10_percent_coarse() {
    weir_within(0.01, 0.1);
}

/// dx = 5 mm (y_c = 6.9 dx): within 5 %.
#[test]
#[ignore = "fails: +5.3 % at dx = 5 mm (+7.4 % at 8 mm, +8.6 % at 10 mm), converging from \
            above; about 25 min on lavapipe (docs/validation.md 'Broad-crested weir')"]
fn weir_upstream_depth_within_5_percent_fine() {
    weir_within(0.005, 0.05);
}

/// The street flood (`cases/street_flood_3d.toml`) at `dx` to `end_s`, with or without its
/// building (the case's `obstacle[3]`, deleted from the file's table).
fn street(dx: f64, end_s: f64, building: bool) -> Scenario {
    let mut set = vec![
        format!("particles.dx_m={dx}"),
        format!("time.end_s={end_s}"),
    ];
    if !building {
        // The building and the sensor on its front (docs/validation.md, "Street flood").
        set.extend([
            "obstacle[3].enabled=false".into(),
            "probe[5].enabled=false".into(),
        ]);
    }
    let sc = wgsph::case::load(Path::new("cases/street_flood_3d.toml"), &set).unwrap();
    assert_eq!(
        sc.probes.len(),
        if building { 6 } else { 5 },
        "probe[5] is the front"
    );
    sc
}

/// Particles of `sc`'s first inlet through its plane by `t`: (layer + ½) dx ≤ D(t).
fn injected(sc: &Scenario, t: f64) -> usize {
    let inlet = &sc.inlets[0];
    let layers = inlet.particles.len() / inlet.columns.len();
    let travelled = inlet.inflow.distance(t);
    let crossed = ((travelled / sc.physics.dx + 0.5).floor() as usize).min(layers);
    crossed * inlet.columns.len()
}

/// The street flood at dx = 0.04 m (2.5 particles over the inflow's depth) for 1.5 s: the
/// flood runs down the dry street and strikes the building. Every particle the inlet let in is
/// in the street or drained (none escapes), and the building's front feels the water.
#[test]
#[ignore = "slow for CI: about a minute on lavapipe (3 500 wall particles, 1 700 steps)"]
fn street_flood_strikes_the_building_coarse() {
    let sc = street(0.04, 1.5, true);
    let mut s = Solver::new(gpu(), &sc).unwrap();
    let front = sc.probes.iter().position(|p| p.name == "front").unwrap();
    let mut peak: f64 = 0.0;
    let mut t = 0.0;
    while t < 1.5 - 1e-9 {
        t += 0.02;
        s.advance_to(t).unwrap();
        peak = peak.max(s.sample_probes().unwrap()[front]);
    }
    let p = s.read_particles().unwrap();
    let fluid = p.kind.iter().filter(|&&k| k == 0).count();
    println!(
        "street flood dx = 0.04 to 1.5 s: {fluid} fluid, {} drained, {} escaped, injected {}; \
         peak pressure on the building's front {peak:.0} Pa",
        s.drained(),
        s.excluded(),
        injected(&sc, 1.5)
    );
    assert_eq!(s.excluded(), 0, "no particle escapes");
    assert_eq!(fluid + s.drained() as usize, injected(&sc, 1.5));
    assert!(peak > 0.0);
}

/// The street flood with its building read from an STL file and held as a fixed body
/// (`cases/street_flood_mesh_3d.toml`) at dx = 0.04 m to 1.2 s: nothing escapes, and the load
/// written for the building is the water's: along the street, towards the wall it stands
/// against (the chamfer turns the flow away from it), and less than ρ g h_u² b, twice the
/// hydrostatic thrust of the upstream depth h_u over the building's projected width b = 0.2 m.
/// The standing contact with the street's floor and wall, which a fixed body no longer takes,
/// put 2·10⁵ N on it.
#[test]
#[cfg_attr(
    not(feature = "long-tests"),
    ignore = "long: about 3.5 min on lavapipe (2 cores, 2026-12-05), beyond CI's 30 minutes; cargo test --release --features long-tests runs it"
)]
fn a_mesh_building_takes_the_flood_load_not_the_streets() {
    let set = ["particles.dx_m=0.04", "time.end_s=1.2"].map(String::from);
    let sc = wgsph::case::load(Path::new("cases/street_flood_mesh_3d.toml"), &set).unwrap();
    assert!(sc.bodies[0].motion.is_fixed());
    let mut s = Solver::new(gpu(), &sc).unwrap();
    let gauge = sc
        .probes
        .iter()
        .position(|p| p.name == "upstream_blocked")
        .unwrap();
    let (mut force, mut depth, mut n) = ([0.0; 3], 0.0, 0);
    let mut t = 0.0;
    while t < 1.2 - 1e-9 {
        t += 0.02;
        s.advance_to(t).unwrap();
        if t > 1.0 - 1e-9 {
            let f = s.bodies().unwrap().load(0).force;
            force = [force[0] + f.x, force[1] + f.y, force[2] + f.z];
            depth += s.sample_probes().unwrap()[gauge];
            n += 1;
        }
    }
    let force = force.map(|f| f / n as f64);
    let depth = depth / n as f64;
    let bound = 1000.0 * 9.81 * depth * depth * 0.2;
    println!(
        "mesh building, dx = 0.04, t in [1, 1.2] s: load {force:.2?} N, upstream depth \
         {depth:.3} m, bound {bound:.1} N; {} escaped",
        s.excluded()
    );
    assert_eq!(s.excluded(), 0, "no particle escapes");
    assert!(force[0] > 0.0 && force[1] < 0.0, "load {force:?}");
    let size = force.iter().map(|f| f * f).sum::<f64>().sqrt();
    assert!(size < bound, "load {size} N against {bound} N");
}

/// The street's steady flow with and without the building (dx = 0.02 m, 10 s, means over the
/// last 2 s: the gauges move by under 3 mm between [6, 8] and [8, 10] s). The building leaves
/// a gap b = B/2: the flow through it is critical, and the water upstream must stand at the
/// depth whose specific energy is 3/2 of the gap's critical depth, y + q_B²/(2 g y²) =
/// 3/2 (q_b²/g)^(1/3) with q_b = 2 q_B = 0.1 m²/s: 0.145 m, against the street's own critical
/// depth (q_B²/g)^(1/3) = 0.063 m without it (a frictionless horizontal street ending in a
/// drop runs critical). No particle escapes.
#[test]
#[ignore = "a GPU's run: dx = 0.02 m, 10 s (24-28 s each on an H200, hours on lavapipe). The \
            same set-up by the command on an H200, means over [8, 10] s: with the building \
            0.1345 m (-7.3 % of the choke's 0.145 m), without 0.0670 m (ratio 0.50); at \
            dx = 0.04 m the ratio was 0.61 (docs/validation.md 'Street flood')"]
fn street_flood_backs_up_behind_the_building_as_a_choke() {
    let q_b: f64 = 0.5 * 0.1 * 2.0;
    let theory = {
        let (q, e) = (0.05, 1.5 * (q_b * q_b / 9.81).cbrt());
        let (mut lo, mut hi) = ((q * q / 9.81f64).cbrt(), e);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if mid + q * q / (2.0 * 9.81 * mid * mid) > e {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        0.5 * (lo + hi)
    };
    let mut upstream = [0.0; 2];
    for (k, building) in [true, false].into_iter().enumerate() {
        let o = steady(&street(0.02, 10.0, building), 2.0);
        println!(
            "street flood {} the building: drained / injected over the last second {:.3}; \
             depths [m] upstream blocked {:.4}, upstream open {:.4}, gap {:.4}, behind {:.4}, \
             downstream {:.4}; front pressure {:.0} Pa (NaN: no building)",
            if building { "with" } else { "without" },
            o.balance,
            o.depths[0],
            o.depths[1],
            o.depths[2],
            o.depths[3],
            o.depths[4],
            o.depths.get(5).copied().unwrap_or(f64::NAN)
        );
        assert_eq!(o.escaped, 0);
        upstream[k] = 0.5 * (o.depths[0] + o.depths[1]);
    }
    println!(
        "upstream depth with the building {:.4} m (choke {theory:.4} m: {:+.1} %), without \
         {:.4} m",
        upstream[0],
        100.0 * (upstream[0] / theory - 1.0),
        upstream[1]
    );
    assert!((upstream[0] / theory - 1.0).abs() < 0.1);
    assert!(upstream[1] < 0.6 * upstream[0]);
}

//! A run that goes unstable stops with a message naming the step and the time, and keeps the
//! outputs written before (run.json says why it stopped).

mod common;
use common::*;
use wgsph::scenario::*;

#[test]
fn unstable_run_stops_with_step_time_and_keeps_outputs() {
    let dx = 0.02;
    let mut ph = physics(2, dx, 20.0);
    // A Courant number far beyond stability (the case parser refuses cfl > 1; scenarios built in
    // code are not checked) makes the block blow up within a few steps.
    let parts: Vec<Particle> = lattice(2, dx, [0.2, 0.2, 0.0], [0.4, 0.4, 0.0])
        .into_iter()
        .map(|p| Particle {
            pos: p,
            vel: [0.0; 3],
            rho: 1010.0,
            kind: Kind::Fluid,
        })
        .collect();
    ph.delta_sph = 0.0;
    let mut sc = scenario(
        ph,
        parts,
        Domain {
            min: [0.0; 3],
            max: [1.0, 1.0, 0.0],
        },
        vec![],
    );
    sc.time.cfl = 8.0;
    sc.time.end_s = 0.5;
    sc.time.output_every_s = 0.01;
    sc.time.probe_every_s = 0.01;
    let dir = common::Scratch::new("unstable");
    let report = wgsph::run::run(
        gpu(),
        &sc,
        &dir,
        &Default::default(),
        &mut wgsph::progress::LogLines::default(),
    )
    .unwrap();
    let err = report.stopped.expect("the run must stop");
    let msg = format!("{err:#}");
    println!("{msg}");
    assert!(
        msg.contains("unstable at step") && msg.contains("t = "),
        "{msg}"
    );
    assert!(report.summary.status.starts_with("stopped:"));
    let summary = std::fs::read_to_string(dir.join("run.json")).unwrap();
    assert!(summary.contains("stopped"));
    // The snapshot at t = 0 (at least) is there and complete.
    let pvd = std::fs::read_to_string(dir.join("particles.pvd")).unwrap();
    assert!(pvd.contains("particles_000000.vtu"));
    assert!(dir.join("particles/particles_000000.vtu").is_file());
}

//! Criterion benches of the cell-list sort, the interaction pass and a whole step on the
//! SPHERIC Test 2 case at about 10k and 100k particles, on the default adapter
//! (WGSPH_ADAPTER=cpu|gpu to choose). Each iteration waits for the GPU (iter_custom), and
//! throughput is reported in particles.

use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use wgsph::gpu::{AdapterChoice, GpuContext};
use wgsph::sph::{Solver, Stage};

fn benches(c: &mut Criterion) {
    let ctx = GpuContext::new(AdapterChoice::resolve(None).unwrap()).expect("an adapter");
    println!("adapter: {}", ctx.describe());
    // dx for ~10k and ~100k particles (fluid + walls) in cases/dam_break_3d.toml.
    for (label, dx) in [("10k", "0.066"), ("100k", "0.0245")] {
        // Without the case's probes: its wall-pressure sensors need a finer dx than 0.066 (the
        // case is refused), and they would add the walls' reactions to what is timed.
        let set = vec![format!("particles.dx_m={dx}"), "probe=[]".to_string()];
        let sc = wgsph::case::load(Path::new("cases/dam_break_3d.toml"), &set).unwrap();
        let n = sc.particles.len() as u64;
        let mut group = c.benchmark_group(format!("spheric2_{label}"));
        group.throughput(Throughput::Elements(n));
        group.sample_size(10);
        for (name, stage) in [
            ("cell_list", Stage::CellList),
            ("interaction", Stage::Interaction),
            ("step", Stage::Step),
        ] {
            let mut solver = Solver::new(&ctx, &sc).unwrap();
            group.bench_function(format!("{name}/{n}"), |b| {
                b.iter_custom(|iters| solver.time_stage(stage, iters).unwrap())
            });
        }
        group.finish();
    }
}

criterion_group!(kernels, benches);
criterion_main!(kernels);

//! Runs over several ranks under a real `mpirun` (feature `mpi`; CI installs OpenMPI). Each
//! test launches its own binary under `mpirun -np N`, filtered to itself; the launched copies
//! see OpenMPI's `OMPI_COMM_WORLD_SIZE` and play their rank instead.
#![cfg(feature = "mpi")]

mod common;

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use wgsph::decomposition::{cut_axis, layer_load, Slabs};
use wgsph::gpu::{AdapterChoice, GpuContext};
use wgsph::grid::Grid;
use wgsph::ranks::{Mpi, Ranks};
use wgsph::scenario::{Domain, Kind, Particle};

/// Whether this process is one rank of an `mpirun` job.
fn under_mpirun() -> bool {
    std::env::var_os("OMPI_COMM_WORLD_SIZE").is_some()
}

/// Runs `test` of this binary on `ranks` ranks; returns (success, stdout + stderr). Fails the
/// test if the job has not ended after `limit`.
fn mpirun(test: &str, ranks: u32, limit: Duration) -> (bool, String) {
    let exe = std::env::current_exe().unwrap();
    let mut child = Command::new("mpirun")
        .args(["--oversubscribe", "-np", &ranks.to_string()])
        .arg(exe)
        .args(["--exact", test, "--nocapture", "--test-threads=1"])
        // OpenMPI refuses root without these (CI runs as root).
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("mpirun not found: install openmpi-bin (README: building with MPI)");
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            child.kill().ok();
            panic!("the {ranks}-rank job of {test} still runs after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let out = child.wait_with_output().unwrap();
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    (out.status.success(), text)
}

/// A block of fluid in a 3D box whose long axis is x, the same on every rank (fixed seed).
fn particles_and_grid() -> (Vec<Particle>, Grid) {
    let h = 0.05;
    let domain = Domain {
        min: [0.0; 3],
        max: [3.0, 0.8, 0.6],
    };
    let grid = Grid::new(&domain, h, 3, 100_000, [false; 3]).unwrap();
    let mut rng = 7u64;
    let mut uniform = |scale: f64| {
        rng = rng
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        scale * ((rng >> 11) as f64 / (1u64 << 53) as f64)
    };
    let particles = (0..4000)
        .map(|k| Particle {
            // Denser towards x = 0, so the balanced cuts are not evenly spaced.
            pos: [3.0 * uniform(1.0).powi(2), uniform(0.8), uniform(0.6)],
            vel: [0.0; 3],
            rho: 1000.0,
            kind: if k % 5 == 0 { Kind::Wall } else { Kind::Fluid },
        })
        .collect();
    (particles, grid)
}

#[test]
fn ranks_agree_on_the_minimum_the_ordered_sum_and_their_halos() {
    if !under_mpirun() {
        let (ok, log) = mpirun(
            "ranks_agree_on_the_minimum_the_ordered_sum_and_their_halos",
            3,
            Duration::from_secs(120),
        );
        assert!(ok, "the 3-rank job failed:\n{log}");
        for r in 0..3 {
            assert!(log.contains(&format!("rank {r} of 3: adapter")), "{log}");
        }
        return;
    }
    let ranks = Mpi::init().expect("MPI initialised once");
    let (r, n) = (ranks.rank(), ranks.size());
    let gpu = GpuContext::for_rank(AdapterChoice::Cpu, r).unwrap();
    println!("rank {r} of {n}: adapter {}", gpu.describe());

    assert_eq!(ranks.min(1.5 + r as f64), 1.5);
    // Rank order, not arrival order: 1e16 + 1 − 1e16 is 0 left to right (1e16 + 1 rounds to
    // 1e16), 1 added in another order.
    assert_eq!(n, 3);
    let mine = [[1e16, 1.0], [1.0, 2.0], [-1e16, 3.0]][r];
    assert_eq!(ranks.sum_in_rank_order(&mine), vec![0.0, 6.0]);

    // Slabs balanced over the particles' load; each rank owns its slab's particles and swaps
    // its halo layers with its neighbours.
    let (particles, grid) = particles_and_grid();
    let axis = cut_axis(&grid, 3).unwrap();
    let load = layer_load(&grid, axis, &particles);
    let slabs = Slabs::balanced(axis, &load, n, 1).unwrap();
    let layer = |p: &Particle| {
        let (off, b) = grid.to_block(p.pos);
        grid.cell_of(off, b)[axis] as u32
    };
    let ids_in = |range: &std::ops::Range<u32>| -> Vec<u32> {
        (0..particles.len() as u32)
            .filter(|&i| range.contains(&layer(&particles[i as usize])))
            .collect()
    };
    let sends: Vec<(usize, Vec<u8>)> = slabs
        .halo_sends(r, 1)
        .iter()
        .map(|h| (h.to, bytemuck::cast_slice(&ids_in(&h.layers)).to_vec()))
        .collect();
    let from: Vec<usize> = sends.iter().map(|(to, _)| *to).collect();
    let received = ranks.exchange(&sends, &from).unwrap();
    let mut halo: Vec<u32> = received
        .iter()
        .flat_map(|b| bytemuck::pod_collect_to_vec::<u8, u32>(b))
        .collect();
    assert!(!halo.is_empty(), "rank {r} received no halo");
    halo.sort();
    // What this rank holds (its own and the halo) is every particle within the kernel support
    // of its own.
    let own = ids_in(&slabs.range(r));
    let support = 2.0 * 0.05;
    for &i in &own {
        for (j, q) in particles.iter().enumerate() {
            let p = &particles[i as usize];
            let d2: f64 = (0..3).map(|a| (p.pos[a] - q.pos[a]).powi(2)).sum();
            let j = j as u32;
            if d2 <= support * support && slabs.owner(layer(q)) != r {
                assert!(
                    halo.binary_search(&j).is_ok(),
                    "rank {r}: neighbour {j} of {i} missing"
                );
            }
        }
    }
}

#[test]
fn a_failing_rank_ends_the_job_and_says_which() {
    if !under_mpirun() {
        let (ok, log) = mpirun(
            "a_failing_rank_ends_the_job_and_says_which",
            2,
            Duration::from_secs(60),
        );
        assert!(!ok, "the job succeeded although rank 1 failed:\n{log}");
        assert!(
            log.contains("rank 1 of 2: the device was lost (test)"),
            "{log}"
        );
        return;
    }
    let ranks = Mpi::init().expect("MPI initialised once");
    if ranks.rank() == 1 {
        ranks.abort(&anyhow::anyhow!("the device was lost (test)"));
    }
    // Rank 0 waits for a halo that never comes: only the abort ends it.
    let _ = ranks.exchange(&[(1, vec![1, 2, 3])], &[1]);
    unreachable!("rank 0 received from a rank that aborted");
}

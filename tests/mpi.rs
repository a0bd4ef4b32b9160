//! Runs over several ranks under a real `mpirun` (feature `mpi`; CI installs OpenMPI). Each
//! test launches its own binary under `mpirun -np N`, filtered to itself; the launched copies
//! see OpenMPI's `OMPI_COMM_WORLD_SIZE` and play their rank instead.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use wgsph::decomposition::{cut_axis, layer_load, slabs_for, Slabs};
use wgsph::gpu::{AdapterChoice, GpuContext};
use wgsph::grid::Grid;
use wgsph::layout::{unpack_block, KIND_EXCLUDED, KIND_SHIFT};
use wgsph::output::{particle_files, ParticleFile, RunSummary};
use wgsph::ranks::{Mpi, Ranks};
use wgsph::scenario::CellEdge;
use wgsph::scenario::{Domain, Kind, Particle, Scenario};
use wgsph::sph::Solver;

/// Whether this process is one rank of an `mpirun` job.
fn under_mpirun() -> bool {
    std::env::var_os("OMPI_COMM_WORLD_SIZE").is_some()
}

/// Runs `test` of this binary on `ranks` ranks; returns (success, stdout + stderr). Fails the
/// test if the job has not ended after `limit`.
fn mpirun(test: &str, ranks: u32, limit: Duration) -> (bool, String) {
    mpirun_with(test, ranks, limit, &[])
}

/// `mpirun -np RANKS`, to be given the program.
fn mpirun_np(ranks: u32) -> Command {
    crate::common::lavapipe_for_tests();
    let mut command = Command::new("mpirun");
    // Ranks waiting on a message yield their core: OpenMPI spins by default where it counts a
    // core a rank, and the harness runs two jobs at once on CI's two cores (this binary took
    // 504 s instead of 637 s on lavapipe, 2 cores, 2026-12-07).
    command.args(["--oversubscribe", "--mca", "mpi_yield_when_idle", "1"]);
    command.args(["-np", &ranks.to_string()]);
    // OpenMPI refuses root without these (CI runs as root).
    command
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1");
    command
}

/// As [`mpirun`], with environment variables `env` set for every rank.
fn mpirun_with(test: &str, ranks: u32, limit: Duration, env: &[(&str, &str)]) -> (bool, String) {
    let exe = std::env::current_exe().unwrap();
    // The harness's name of the test: its path in this binary (`mpi::name`).
    let (_, module) = module_path!().split_once("::").unwrap();
    let test = &format!("{module}::{test}");
    let mut command = mpirun_np(ranks);
    for (k, v) in env {
        command.args(["-x", &format!("{k}={v}")]);
    }
    let mut child = command
        .arg(exe)
        // (--include-ignored: the ranks run the test also where it is a long one, ignored
        // without `long-tests`, that `--ignored` started.)
        .args([
            "--exact",
            test,
            "--include-ignored",
            "--nocapture",
            "--test-threads=1",
        ])
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
    let grid = Grid::new(&domain, h, 3, 100_000, [false; 3], Some(CellEdge::Support)).unwrap();
    let mut rng = crate::common::Rng(7);
    let mut uniform = |scale: f64| rng.range(0.0, scale);
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

/// Wide particle ids, as runs of 2²⁸ particles or more take them, forced on a small case with
/// 4 of an id's bits in its code word: most particles share those with others, and only the
/// second word tells them apart (tests/determinism.rs: the same results as narrow ids).
const WIDE_IDS: &str = "particles.id_low_bits=4";

/// (id, position words, (v, ρ, e) bits) of every live particle, sorted by id (e = 0 without
/// the energy equation).
type Live = Vec<(u32, [u32; 4], [u32; 5])>;

fn live_particles(solver: &Solver) -> Live {
    let (pos, velrho, code) = solver.read_raw().unwrap();
    let n = pos.len();
    let mut live: Live = (0..n)
        .filter(|&k| code[k] >> KIND_SHIFT != KIND_EXCLUDED)
        .map(|k| {
            let p = pos[k];
            let words = [
                p.off[0].to_bits(),
                p.off[1].to_bits(),
                p.off[2].to_bits(),
                p.block,
            ];
            let [vx, vy, vz, rho] = velrho[k].map(f32::to_bits);
            let id = solver.ids().id_at(&code, n, k);
            (id, words, [vx, vy, vz, rho, 0])
        })
        .collect();
    live.sort_by_key(|l| l.0);
    // The energies, in id order too.
    let read = solver.read_particles().unwrap();
    if let Some(energy) = &read.energy {
        let live_energy = (0..read.id.len())
            .filter(|&k| read.kind[k] != KIND_EXCLUDED)
            .map(|k| energy[k]);
        for (l, e) in live.iter_mut().zip(live_energy) {
            l.2[4] = e.to_bits();
        }
    }
    live
}

/// Every body's pose (centre, rotation, velocity, spin) as the bits of its f64s.
fn body_words(solver: &Solver) -> Vec<u32> {
    let Some(set) = solver.bodies() else {
        return Vec::new();
    };
    (0..set.len())
        .flat_map(|k| {
            let p = set.pose(k);
            let values: Vec<f64> = [
                p.center.to_array(),
                p.velocity.to_array(),
                p.omega.to_array(),
            ]
            .concat()
            .into_iter()
            .chain(p.rotation.to_array())
            .collect();
            values
                .into_iter()
                .flat_map(|x| [x.to_bits() as u32, (x.to_bits() >> 32) as u32])
                .collect::<Vec<_>>()
        })
        .collect()
}

/// A case cut into slabs and stepped on `ranks` ranks under mpirun, against its whole run.
#[derive(Default)]
struct Comparison {
    /// The test function that runs it (what mpirun launches).
    test: &'static str,
    case: &'static str,
    set: &'static [&'static str],
    ranks: u32,
    steps: u64,
    /// Start from cuts at equal numbers of cell layers (not balanced), so that the ranks
    /// move them during the run, which must then have happened.
    uneven: bool,
    /// Save every rank's state after this many steps and take the rest in a new subdomain
    /// restored from it (as `wgsph resume` does), not in the one that saved it.
    restore_at: Option<u64>,
    /// Tables added to the case (written beside the test binary before the ranks start): an
    /// `[[outlet]]` must have drained particles by the end; a `[[body]]` must end with
    /// particles on every rank, and every rank with the whole run's pose of it, bit for bit.
    /// (A case with an elastic solid must end with solid particles on every rank too.)
    tables: &'static str,
    /// The ranks' halo packing buffers must grow during the run (`Halo::reserve`).
    grows: bool,
    /// With `uneven`: a cut must move past a neighbour's slab, so that a particle crosses a
    /// rank on its way to its new owner (`Solver::redistribute` takes two rounds or more).
    far: bool,
}

impl Comparison {
    fn scenario(&self) -> Scenario {
        let mut set: Vec<String> = self.set.iter().map(|s| s.to_string()).collect();
        // The cells a run over ranks takes (`decomposition::ranks_grid`), for the whole run.
        set.push("particles.cell=2h".into());
        wgsph::case::load(&self.case_path(), &set).unwrap()
    }

    /// The case file: `case`, or with `tables` a copy of it with them added.
    fn case_path(&self) -> std::path::PathBuf {
        match self.tables {
            "" => self.case.into(),
            _ => std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
                .join(format!("{}.toml", self.test)),
        }
    }

    /// Writes the case with its added tables ([`Comparison::case_path`]).
    fn write_case(&self) {
        let case = std::fs::read_to_string(self.case).unwrap();
        std::fs::write(self.case_path(), case + "\n" + self.tables).unwrap();
    }

    /// The ranks' live particles, merged, equal the whole run's bit for bit, each on one rank;
    /// every rank sent halos.
    fn check(&self) {
        if under_mpirun() {
            return self.rank();
        }
        if !self.tables.is_empty() {
            self.write_case();
        }
        let out = crate::common::Scratch::new(&format!("mpi-{}", self.test));
        std::fs::create_dir_all(&*out).unwrap();
        let dir = out.to_str().unwrap();
        let limit = Duration::from_secs(600);
        let (ok, log) = mpirun_with(self.test, self.ranks, limit, &[("WGSPH_MPI_OUT", dir)]);
        assert!(ok, "the {}-rank job failed:\n{log}", self.ranks);
        let mut whole = Solver::new(crate::common::gpu(), &self.scenario()).unwrap();
        // In the same calls as the ranks: each rebases the f32 clock (which the inlets read).
        let at = self.restore_at.unwrap_or(0);
        whole.run_steps(at).unwrap();
        whole.run_steps(self.steps - at).unwrap();
        let expected = live_particles(&whole);
        let sc = self.scenario();
        assert!(
            sc.outlets.is_empty() || whole.drained() > 0,
            "the outlet drained nothing: the test tests nothing"
        );
        let live_at_start = sc.particles.len() - sc.dormant_count();
        assert!(
            sc.inlets.is_empty() || expected.len() > live_at_start,
            "no inlet particle joined: the test tests nothing"
        );
        println!("{} particles drained", whole.drained());
        let poses = body_words(&whole);
        let mut merged: Live = Vec::new();
        let mut grown = 0;
        for r in 0..self.ranks {
            let bytes = std::fs::read(out.join(format!("rank{r}.bin"))).unwrap();
            let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
            let (halo, migrants, rebalances, drained) = (words[0], words[1], words[2], words[3]);
            let (held, growths, rounds, words) = (words[4], words[5], words[6], &words[7..]);
            grown += growths;
            let (pose, words) = words.split_at(poses.len());
            assert_eq!(pose, poses, "rank {r}'s bodies differ from the whole run's");
            if !sc.bodies.is_empty() {
                println!("rank {r}: {held} body particles");
                assert!(
                    held > 0,
                    "rank {r} holds no body particle: the body is not cut"
                );
            }
            assert_eq!(
                drained as u64,
                whole.drained(),
                "rank {r}'s count of the drained"
            );
            println!(
                "rank {r}: {halo} halo copies and {migrants} migrants sent, {rebalances} \
                 rebalances, its packing buffer grown {growths} times"
            );
            assert!(halo > 0, "rank {r} sent no halo");
            assert!(!self.uneven || rebalances > 0, "the cuts never moved");
            println!("rank {r}: a move of the cuts took {rounds} rounds at most");
            assert!(
                !self.far || rounds >= 2,
                "no cut moved past a neighbour's slab"
            );
            let mine: Live = (words.chunks(10))
                .map(|c| {
                    (
                        c[0],
                        [c[1], c[2], c[3], c[4]],
                        [c[5], c[6], c[7], c[8], c[9]],
                    )
                })
                .collect();
            if sc.solids.is_some() {
                let solid = (mine.iter())
                    .filter(|l| sc.particles[l.0 as usize].kind.is_solid())
                    .count();
                println!("rank {r}: {solid} solid particles");
                assert!(
                    solid > 0,
                    "rank {r} holds no solid particle: the solid is not cut"
                );
            }
            merged.extend(mine);
        }
        println!("the packing buffers grew {grown} times");
        assert!(!self.grows || grown > 0, "no packing buffer grew");
        merged.sort_by_key(|l| l.0);
        assert_eq!(merged.len(), expected.len(), "particle counts differ");
        let ids: Vec<u32> = merged.iter().map(|l| l.0).collect();
        assert!(
            ids.windows(2).all(|w| w[0] < w[1]),
            "a particle is on two ranks"
        );
        let differ = merged.iter().zip(&expected).filter(|(a, b)| a != b).count();
        assert_eq!(differ, 0, "{differ} particles differ from the whole run");
    }

    /// One rank's part: its subdomain stepped with the others, its live particles written to
    /// `$WGSPH_MPI_OUT/rank<r>.bin` after its counts of halo copies and migrants sent.
    fn rank(&self) {
        let ranks = Mpi::init().expect("MPI initialised once");
        let r = ranks.rank();
        let result = (|| -> anyhow::Result<()> {
            let gpu = GpuContext::for_rank(AdapterChoice::Cpu, r)?;
            let sc = self.scenario();
            let slabs = match self.uneven {
                false => slabs_for(&sc, ranks.size())?,
                true => {
                    let even = slabs_for(&sc, 1)?.range(0).len();
                    let axis = slabs_for(&sc, 1)?.axis;
                    Slabs::balanced(axis, &vec![1.0; even], ranks.size(), 1)?
                }
            };
            let mut solver = Solver::subdomain(&gpu, &sc, &slabs, &ranks)?;
            if let Some(at) = self.restore_at {
                solver.run_steps_ranked(at, &ranks)?;
                let (saved, ranked) = (solver.save_state()?, solver.ranked().unwrap().clone());
                solver = Solver::subdomain(&gpu, &sc, &slabs, &ranks)?;
                solver.restore_state(&saved)?;
                solver.restore_subdomain(&ranked, &ranks)?;
            }
            let left = self.steps - self.restore_at.unwrap_or(0);
            solver.run_steps_ranked(left, &ranks)?;
            // Every rank holds the particles of its slab (the cuts as the ranks last moved
            // them), give or take those that crossed a cut in the last step.
            let grid = wgsph::decomposition::ranks_grid(&sc)?;
            let slabs = solver.ranked().unwrap().slabs.clone().unwrap();
            let mine = slabs.range(r);
            for (_, p, _) in live_particles(&solver) {
                let off = [0, 1, 2].map(|a| f32::from_bits(p[a]));
                let layer = grid.cell_of(off, unpack_block(p[3]))[slabs.axis] as u32;
                anyhow::ensure!(
                    layer + 1 >= mine.start && layer <= mine.end,
                    "rank {r} holds a particle in layer {layer}, its slab is {mine:?}"
                );
            }
            // So do the excluded particles that keep their ids (inlet particles waiting at the
            // place they join from, those drained or gone out of the domain): the cuts move
            // them as they move.
            let (pos, _, code) = solver.read_raw()?;
            let ids = solver.ids();
            for k in 0..pos.len() {
                let id = ids.id_at(&code, pos.len(), k);
                if code[k] >> KIND_SHIFT != KIND_EXCLUDED || id == ids.free_id() {
                    continue;
                }
                let layer = grid.cell_of(pos[k].off, unpack_block(pos[k].block))[slabs.axis];
                anyhow::ensure!(
                    layer as u32 + 1 >= mine.start && layer as u32 <= mine.end,
                    "rank {r} holds the excluded particle {id} in layer {layer}, its slab is \
                     {mine:?}"
                );
            }
            let counts = solver.ranked().unwrap();
            let live = live_particles(&solver);
            let body_ids = (sc.bodies.iter().map(|b| b.particles.start as u32)).min();
            let held = live.iter().filter(|l| body_ids.is_some_and(|b| l.0 >= b));
            let mut words = vec![
                counts.halo_sent as u32,
                counts.migrants_sent as u32,
                counts.rebalances,
                solver.drained() as u32,
                held.count() as u32,
                solver.halo_growths(),
                counts.moving_rounds,
            ];
            words.extend(body_words(&solver));
            for (id, p, v) in live {
                words.push(id);
                words.extend(p);
                words.extend(v);
            }
            let dir = std::env::var("WGSPH_MPI_OUT")?;
            std::fs::write(format!("{dir}/rank{r}.bin"), bytemuck::cast_slice(&words))?;
            Ok(())
        })();
        if let Err(e) = result {
            ranks.abort(&e);
        }
    }
}

/// `wgsph ARGS --adapter cpu` of the 2D dam break (`run` with `end` as time.end_s into `out`
/// when ARGS is empty).
fn dam_break(end: &str, out: &std::path::Path) -> Vec<std::ffi::OsString> {
    let args = ["run", "cases/dam_break_2d.toml", "--set", end, "--quiet"];
    // Twice the shipped spacing (1 100 particles): a quarter of the particles and half the
    // steps; what the tests compare does not depend on the spacing.
    let args = args.into_iter().chain(["--set", "particles.dx_m=0.0073"]);
    let args = args.map(|a| a.into());
    args.chain(["--out".into(), out.as_os_str().to_owned()])
        .collect()
}

/// `wgsph ARGS --resume`-style arguments: `resume DIR --set time.end_s=END`.
fn resume(dir: &std::path::Path, end: &str) -> Vec<std::ffi::OsString> {
    let set = format!("time.end_s={end}");
    vec![
        "resume".into(),
        dir.as_os_str().to_owned(),
        "--set".into(),
        set.into(),
    ]
}

/// One whole run of `args` on lavapipe.
fn on_one_rank(args: Vec<std::ffi::OsString>) {
    crate::common::lavapipe_for_tests();
    let o = Command::new(env!("CARGO_BIN_EXE_wgsph"))
        .args(args)
        .args(["--adapter", "cpu"])
        // The cells a run over ranks takes (`decomposition::ranks_grid`).
        .args(["--set", "particles.cell=2h"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// `mpirun -np 2 wgsph ARGS` on lavapipe with checkpoints every 0.015 s; its log.
fn on_two_ranks(args: Vec<std::ffi::OsString>) -> String {
    let o = mpirun_wgsph(2, args, &[]).output().unwrap();
    let log = String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{log}");
    log
}

/// `mpirun -np RANKS [EXPORT] wgsph ARGS` as [`on_two_ranks`] runs it, `EXPORT` the variables
/// of the test's environment to pass on to the ranks (`-x NAME`).
fn mpirun_wgsph(ranks: u32, args: Vec<std::ffi::OsString>, export: &[&str]) -> Command {
    let mut command = mpirun_np(ranks);
    for name in export {
        command.args(["-x", name]);
    }
    command.arg(env!("CARGO_BIN_EXE_wgsph")).args(args).args([
        "--adapter",
        "cpu",
        "--checkpoint-every",
        "0.015",
    ]);
    command
}

/// The particle outputs and probe tables of the run over ranks in `ranked` equal those of the
/// whole run in `whole`: every output's pieces, read together through its `.pvtu`, hold bit
/// for bit the whole run's particles, each id once, the excluded ones too (waiting behind an
/// inlet, drained, left the domain); every probe table byte for byte. Returns the live
/// particles of the last output and the excluded ones of all outputs.
fn assert_same_outputs(whole: &std::path::Path, ranked: &std::path::Path) -> (usize, usize) {
    let (files_one, files_two) = (
        particle_files(whole).unwrap(),
        particle_files(ranked).unwrap(),
    );
    assert_eq!(files_one.len(), files_two.len());
    assert!(files_two
        .iter()
        .all(|(_, f)| f.extension().unwrap() == "pvtu"));
    let pvd = std::fs::read_to_string(ranked.join("particles.pvd")).unwrap();
    assert!(pvd.contains("particles/particles_000001.pvtu"), "{pvd}");
    let (mut live, mut excluded) = (0, 0);
    for ((_, a), (_, b)) in files_one.iter().zip(&files_two) {
        let (a, b) = (
            ParticleFile::read(a).unwrap(),
            ParticleFile::read(b).unwrap(),
        );
        let whole = a.particles;
        assert!(
            b.particles.id.windows(2).all(|w| w[0] < w[1]),
            "an id twice"
        );
        assert_eq!(whole.id.len(), b.particles.id.len(), "t = {}", a.time_s);
        assert!(
            whole == b.particles,
            "the particles differ at t = {}",
            a.time_s
        );
        assert_eq!(a.time_s.to_bits(), b.time_s.to_bits());
        let out = whole.kind.iter().filter(|&&k| k == KIND_EXCLUDED).count();
        (live, excluded) = (whole.id.len() - out, excluded + out);
    }
    for e in std::fs::read_dir(whole.join("probes")).unwrap() {
        let name = e.unwrap().file_name();
        let (a, b) = (
            std::fs::read(whole.join("probes").join(&name)).unwrap(),
            std::fs::read(ranked.join("probes").join(&name)).unwrap(),
        );
        assert!(a == b, "probes/{name:?} differs");
    }
    (live, excluded)
}

/// `mpirun -np 2 wgsph run` of the floating box (as shipped: fixed ghost walls) writes what one
/// whole run writes: the particles, the gauges, the box's table (pose and load) and the path of
/// its corner (a tracked point), each written once, by rank 0. The cut runs through the box.
#[test]
fn a_floating_body_over_two_ranks_writes_what_one_run_writes() {
    two_ranks_write_what_one_run_writes(
        "body",
        ("cases/floating_box_2d.toml", "0.02"),
        &["time.end_s=0.12"],
        &["body_box.csv", "point_corner.csv"],
    );
}

/// `mpirun -np 2 wgsph run` of the sloshing tank (a body of prescribed motion, its walls
/// dynamic) writes what one whole run writes, the pressure probes and wall sensors that roll
/// with the tank included: no cut goes through the layers of their paths.
#[test]
fn a_rolling_tank_over_two_ranks_writes_what_one_run_writes() {
    two_ranks_write_what_one_run_writes(
        "tank",
        ("cases/sloshing_2d.toml", "0.02"),
        &["time.end_s=0.15"],
        &["body_tank.csv", "p2.csv", "w8.csv"],
    );
}

/// `mpirun -np 2 wgsph run` of the water injection writes what one whole run writes, its
/// excluded particles too: the inlet's particles still waiting behind its buffer (20 at the
/// start), each on the rank that wakes it, as one whole run writes them (kind 15).
#[test]
fn ranks_write_the_waiting_inlet_particles_as_one_run() {
    let (excluded, _) = two_ranks_write_what_one_run_writes(
        "injection",
        ("cases/water_injection_2d.toml", "0.01"),
        &["time.end_s=0.1"],
        &["level_left.csv", "level_right.csv", "p_floor.csv"],
    );
    assert!(excluded > 0, "no excluded particle: the test tests less");
}

/// `mpirun -np 2 wgsph run` of the 2D dam break in an open tank with gravity turned upwards
/// (the water falls out through the top: 14 particles have left the domain at t = 0.29 s)
/// writes what one whole run writes: each particle that left, excluded, in the piece of the
/// rank it left from, as one whole run writes it (kind 15). On its way up most of the water
/// crosses the cut from one rank into the other, and every particle comes through.
#[test]
fn ranks_write_the_particles_that_left_the_domain_as_one_run() {
    let (excluded, two) = two_ranks_write_what_one_run_writes(
        "left",
        ("cases/dam_break_2d.toml", "0.0146"),
        &["time.end_s=0.29", "physics.gravity_m_s2=[0.0, 9.81]"],
        &["p_right_wall.csv"],
    );
    assert!(
        excluded > 0,
        "no particle left the domain: the test tests less"
    );
    // Most of the water crossed from one rank into the other, every particle kept.
    let ranks = two.ranks.unwrap();
    let migrants: f64 = ranks.iter().map(|r| r.migrants_per_step).sum::<f64>() * two.steps as f64;
    println!(
        "{migrants} migrants, {} fluid particles",
        two.particles_fluid
    );
    assert!(migrants > 0.5 * two.particles_fluid as f64);
}

/// A box sinks through the 2D dam break's water column (a free body, 2 000 kg/m³, pushed down
/// at 0.8 m/s) with a pressure probe under it, which crosses where the cut first lies:
/// `mpirun -np 2 wgsph run` to t = 0.1 s, then `resume` from its last checkpoint (0.09 s) to
/// 0.2 s, moves the cuts out of the probe's way as it comes (after the resume), and writes what
/// one whole run writes (the particles, the probe's table, the box's).
#[test]
fn a_probe_on_a_sinking_box_over_two_ranks_reads_what_one_run_reads() {
    let case = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("sinker.toml");
    let tables = "[[body]]\nname = \"sinker\"\nshape = \"box\"\nmin_m = [0.04, 0.30]\n\
                  max_m = [0.10, 0.34]\ndensity_kg_m3 = 2000.0\nwall = \"dynamic\"\n\
                  [body.motion]\nkind = \"free\"\nvelocity_m_s = [0.0, -0.8]\n\
                  [[probe]]\nname = \"under_sinker\"\nkind = \"pressure\"\n\
                  point_m = [0.07, 0.29]\nbody = \"sinker\"\n";
    let dam_break = std::fs::read_to_string("cases/dam_break_2d.toml").unwrap();
    std::fs::write(&case, dam_break + "\n" + tables).unwrap();
    let (one, two) = (
        crate::common::Scratch::new("mpi-sinker-one"),
        crate::common::Scratch::new("mpi-sinker-two"),
    );
    let args = |out: &std::path::Path, end: &str| -> Vec<std::ffi::OsString> {
        let mut args: Vec<std::ffi::OsString> = vec!["run".into(), case.clone().into()];
        for s in ["particles.dx_m=0.01", end, "time.output_every_s=0.05"] {
            args.extend(["--set".into(), s.into()]);
        }
        args.extend(["--out".into(), out.as_os_str().to_owned()]);
        args
    };
    on_one_rank(args(&one, "time.end_s=0.2"));
    on_two_ranks(args(&two, "time.end_s=0.1"));
    let log = on_two_ranks(resume(&two, "0.2"));
    assert!(log.contains("resuming from t = 0.09"), "{log}");
    assert!(
        log.contains("cuts moved out of the way of a probe on a free body"),
        "the probe never neared a cut: the test tests nothing\n{log}"
    );
    assert_same_outputs(&one, &two);
    for table in ["under_sinker.csv", "body_sinker.csv"] {
        let text = std::fs::read_to_string(two.join("probes").join(table)).unwrap();
        assert!(text.lines().count() > 50, "{table}: {text}");
    }
}

/// `case` at dx = `dx` (m) with `sets`, outputs every 0.05 s, on one rank and on two: the same
/// outputs ([`assert_same_outputs`]); each of `tables` (in probes/) has rows. Returns the
/// excluded particles the outputs held.
fn two_ranks_write_what_one_run_writes(
    tag: &str,
    (case, dx): (&str, &str),
    sets: &[&str],
    tables: &[&str],
) -> (usize, RunSummary) {
    let (one, two) = (
        crate::common::Scratch::new(&format!("mpi-{tag}-one")),
        crate::common::Scratch::new(&format!("mpi-{tag}-two")),
    );
    let args = |out: &std::path::Path| -> Vec<std::ffi::OsString> {
        let mut args: Vec<std::ffi::OsString> = vec!["run".into(), case.into()];
        let dx = format!("particles.dx_m={dx}");
        for s in [dx.as_str(), "time.output_every_s=0.05"].iter().chain(sets) {
            args.extend(["--set".into(), s.into()]);
        }
        args.extend(["--quiet".into(), "--out".into(), out.as_os_str().to_owned()]);
        args
    };
    on_one_rank(args(&one));
    on_two_ranks(args(&two));
    let (_, excluded) = assert_same_outputs(&one, &two);
    for table in tables {
        let text = std::fs::read_to_string(two.join("probes").join(table)).unwrap();
        assert!(text.lines().count() > 10, "{table}: {text}");
    }
    (excluded, RunSummary::read(&two).unwrap())
}

/// `mpirun -np 2 wgsph run` of the 2D dam break writes what one whole run writes
/// ([`assert_same_outputs`]: the particles, pressure at the wall, the front and the continuous
/// front). The 2-rank run goes to t = 0.04 s with checkpoints every 0.015 s (both sets of
/// rank files used), then `mpirun -np 2 wgsph resume` takes it from t = 0.032 s to 0.06 s: the
/// outputs before and after the resume are all compared. The cut lies across the water
/// column, which falls through it: particles migrate, and run.json says how much each rank
/// sent. The ranks overlap the exchange with their interior's sums up to the resume, and take
/// the serial step after it (`time.overlap_exchange`): run.json says which.
#[test]
fn a_run_over_two_ranks_writes_what_one_whole_run_writes() {
    let (one, two) = (
        crate::common::Scratch::new("mpi-run-one"),
        crate::common::Scratch::new("mpi-run-two"),
    );
    on_one_rank(dam_break("time.end_s=0.06", &one));
    let mut overlapping = dam_break("time.end_s=0.04", &two);
    overlapping.extend(["--set".into(), "time.overlap_exchange=\"always\"".into()]);
    on_two_ranks(overlapping);
    for set in ["g0", "g1"] {
        assert!(two.join(format!("checkpoint_{set}_p0001.bin")).is_file());
    }
    let overlapped = RunSummary::read(&two).unwrap().ranks.unwrap();
    println!("{overlapped:#?}");
    assert!(overlapped
        .iter()
        .all(|r| r.overlapped == 1.0 && (0.0..=1.0).contains(&r.exchange_hidden)));
    let mut serial = resume(&two, "0.06");
    serial.extend(["--set".into(), "time.overlap_exchange=\"never\"".into()]);
    let log = on_two_ranks(serial);
    assert!(log.contains("resuming from t = 0.032000 s"), "{log}");
    let (live, _) = assert_same_outputs(&one, &two);
    let (a, b) = (
        RunSummary::read(&one).unwrap(),
        RunSummary::read(&two).unwrap(),
    );
    assert_eq!(
        (a.steps, a.particles_excluded),
        (b.steps, b.particles_excluded)
    );
    let ranks = b.ranks.expect("run.json of a run over ranks lists them");
    assert_eq!(ranks.len(), 2);
    println!("{ranks:#?}");
    // Up to the checkpoint resumed from (t = 0.032 s) overlapped, then not.
    assert!(ranks
        .iter()
        .all(|r| 0.0 < r.overlapped && r.overlapped < 1.0));
    let own: u64 = ranks.iter().map(|r| r.own_particles).sum();
    assert_eq!(own, live as u64, "every live particle is own on one rank");
    assert!(ranks.iter().all(|r| r.halo_bytes_per_step > 0.0));
    assert!(
        ranks.iter().map(|r| r.migrants_per_step).sum::<f64>() > 0.0,
        "no particle crossed the cut"
    );
    assert!(ranks.iter().all(|r| r.adapter.contains("llvmpipe")));
    // Each rank's slot table is sized by its own particles or cells (`Grid::for_subdomain`), smaller
    // than the whole run's, and the outputs still equal it bit for bit.
    let sc = wgsph::case::load("cases/dam_break_2d.toml".as_ref(), &[]).unwrap();
    let whole = wgsph::decomposition::ranks_grid(&sc).unwrap().slots as u64;
    assert!(
        ranks.iter().all(|r| r.hash_slots < whole),
        "{whole} slots in one run"
    );
}

/// `time.output_boundary = "first"` and `--snapshots` over two ranks: each rank's later
/// pieces leave out the unmoved walls its first piece holds, and every output, completed from
/// the first (`Particles::completed_from`, as `plot` reads it), equals one whole run's bit for
/// bit, also after `resume` (which reads the first output's pieces back); rank 0 draws each
/// output from the joined pieces, the whole run's pictures byte for byte.
#[test]
fn ranks_write_the_walls_once_and_draw_what_one_run_draws() {
    let (one, two) = (
        crate::common::Scratch::new("mpi-walls-one"),
        crate::common::Scratch::new("mpi-walls-two"),
    );
    let walls_once = |end: &str, out: &std::path::Path| {
        let mut args = dam_break(end, out);
        args.extend(["--set".into(), "time.output_boundary=\"first\"".into()]);
        args.push("--snapshots".into());
        args
    };
    on_one_rank(walls_once("time.end_s=0.05", &one));
    on_two_ranks(walls_once("time.end_s=0.03", &two));
    on_two_ranks(resume(&two, "0.05"));
    let (a, b) = (particle_files(&one).unwrap(), particle_files(&two).unwrap());
    assert_eq!(a.len(), b.len());
    let read = |f: &std::path::Path| ParticleFile::read(f).unwrap();
    let (first_a, first_b) = (read(&a[0].1).particles, read(&b[0].1).particles);
    assert!(first_a == first_b);
    for ((_, fa), (_, fb)) in a.iter().zip(&b).skip(1) {
        let (ra, rb) = (read(fa), read(fb));
        assert!(
            rb.particles.id.len() < first_b.id.len(),
            "{}: the walls were written again",
            fb.display()
        );
        let whole = ra.particles.completed_from(&first_a);
        assert!(
            whole == rb.particles.completed_from(&first_b),
            "the particles differ at t = {}",
            ra.time_s
        );
    }
    for (index, _) in &a {
        let png = |dir: &std::path::Path| {
            std::fs::read(dir.join(format!("snapshots/{index:06}.png"))).unwrap()
        };
        assert!(png(&one) == png(&two), "snapshot {index} differs");
    }
}

/// Three slabs of the 3D SPHERIC dam break at a coarse dx (36 k particles; 3D halos, a middle
/// rank with two neighbours, the box obstacle) with a beam reaching from the air over the dry
/// floor into the water column, across both cuts (dynamic walls, thrown sideways and up: 3D
/// torque, 28 workgroups of body particles, 450 / 1 200 / 100 of its 1 750 on the ranks): the
/// particles and the beam's pose the same, after 20 steps.
#[test]
fn three_ranks_of_the_3d_dam_break_equal_one_run() {
    Comparison {
        test: "three_ranks_of_the_3d_dam_break_equal_one_run",
        case: "cases/dam_break_3d.toml",
        set: &["particles.dx_m=0.04"],
        ranks: 3,
        steps: 20,
        tables: "[[body]]\nname = \"beam\"\nshape = \"box\"\nmin_m = [1.6, 0.3, 0.35]\n\
                 max_m = [3.0, 0.7, 0.55]\ndensity_kg_m3 = 500.0\nwall = \"dynamic\"\n\
                 [body.motion]\nkind = \"free\"\nvelocity_m_s = [0.0, 0.5, 0.3]\n",
        ..Default::default()
    }
    .check();
}

/// Three ranks of the 2D dam break that start from cuts at equal numbers of cell layers (most
/// of the water on one rank): the ranks move the cuts at their first look (step 100), a cut
/// past a neighbour's slab (the move takes two rounds: particles cross a rank on their way;
/// with four ranks it still takes two), and the particles still equal one whole run's bit for
/// bit after 300 steps, the last 100 of them taken by subdomains restored from the state saved
/// at step 200 (with the moved cuts, which differ from the ones the new subdomains are made
/// with).
#[test]
fn ranks_that_move_their_cuts_still_equal_one_run() {
    Comparison {
        test: "ranks_that_move_their_cuts_still_equal_one_run",
        case: "cases/dam_break_2d.toml",
        set: &["particles.dx_m=0.0073"],
        ranks: 3,
        steps: 300,
        uneven: true,
        far: true,
        restore_at: Some(200),
        ..Default::default()
    }
    .check();
}

/// The processes of this test's jobs that play rank `rank` (their environment carries `tag`
/// and OpenMPI's rank).
fn processes_of_rank(tag: &str, rank: usize) -> Vec<u32> {
    let wanted = [tag.to_string(), format!("OMPI_COMM_WORLD_RANK={rank}")];
    let entries = std::fs::read_dir("/proc").unwrap().flatten();
    entries
        .filter_map(|e| {
            let pid: u32 = e.file_name().to_str()?.parse().ok()?;
            let env = std::fs::read(e.path().join("environ")).ok()?;
            let vars: Vec<&[u8]> = env.split(|&b| b == 0).collect();
            let has = |w: &String| vars.contains(&w.as_bytes());
            wanted.iter().all(has).then_some(pid)
        })
        .collect()
}

/// A rank killed mid-run (SIGKILL, as the out-of-memory killer or a lost node would) ends the
/// whole job promptly, with mpirun naming the rank, and the last checkpoint it completed is
/// kept: `mpirun -np 2 wgsph resume` continues from it and writes what one whole run writes.
#[test]
fn killing_a_rank_ends_the_job_and_its_last_checkpoint_resumes() {
    let (one, two) = (
        crate::common::Scratch::new("mpi-kill-one"),
        crate::common::Scratch::new("mpi-kill-two"),
    );
    let (name, value) = ("WGSPH_KILL_TEST", std::process::id().to_string());
    let tag = format!("{name}={value}");
    let mut job = mpirun_wgsph(2, dam_break("time.end_s=0.2", &two), &[name]);
    let mut job = job
        .env(name, &value)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !two.join("checkpoint.bin").is_file() {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no checkpoint written"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    let victims = processes_of_rank(&tag, 1);
    assert_eq!(victims.len(), 1, "rank 1's process: {victims:?}");
    Command::new("kill")
        .args(["-9", &victims[0].to_string()])
        .status()
        .unwrap();
    let killed = Instant::now();
    while job.try_wait().unwrap().is_none() {
        assert!(
            killed.elapsed() < Duration::from_secs(30),
            "the job still runs"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    let o = job.wait_with_output().unwrap();
    let log = String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        log.contains("process rank 1") && log.contains("signal 9"),
        "{log}"
    );
    // Rank 0 was waiting on rank 1: it is gone too.
    while !processes_of_rank(&tag, 0).is_empty() {
        assert!(
            killed.elapsed() < Duration::from_secs(30),
            "rank 0 still runs"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    println!("the job ended {:?} after the kill", killed.elapsed());

    // Resumed on one rank, or quiet on three, the checkpoint of two says how to resume it (on
    // three the message was lost in one job of four before the abort ended it: issue 64).
    let mut alone = Command::new(env!("CARGO_BIN_EXE_wgsph"));
    alone.args(resume(&two, "0.03"));
    let mut three = mpirun_wgsph(3, resume(&two, "0.03"), &[]);
    three.arg("-q");
    for mut command in [alone, three] {
        let o = command.output().unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success());
        assert!(
            stderr.contains("was written by a run over 2 rank(s); resume it on as many"),
            "{stderr}"
        );
    }
    on_two_ranks(resume(&two, "0.03"));
    on_one_rank(dam_break("time.end_s=0.03", &one));
    assert_same_outputs(&one, &two);
}

/// The 2D dam break with the energy equation on: the migrants carry their specific internal
/// energy and its last rate to their new owner, which goes on integrating it; every live
/// particle's energy equals one whole run's bit for bit after 300 steps, with the cuts moved at
/// step 100.
#[test]
fn ranks_integrate_the_energy_equation_as_one_run() {
    Comparison {
        test: "ranks_integrate_the_energy_equation_as_one_run",
        case: "cases/dam_break_2d.toml",
        set: &["particles.dx_m=0.0073", "physics.energy=true"],
        ranks: 2,
        steps: 300,
        uneven: true,
        ..Default::default()
    }
    .check();
}

/// The 2D dam break with an outlet just beyond the foot of the water column, which the column's
/// corner flows into as it starts to fall. The ranks drain the same particles at the same
/// steps as one whole run (the particles bit for bit, every rank's summed count of the drained
/// equal to the whole run's, and not zero).
#[test]
fn ranks_with_an_outlet_drain_what_one_run_drains() {
    Comparison {
        test: "ranks_with_an_outlet_drain_what_one_run_drains",
        case: "cases/dam_break_2d.toml",
        set: &["particles.dx_m=0.0073"],
        ranks: 2,
        steps: 300,
        tables: "[[outlet]]\nname = \"drain\"\nmin_m = [0.1465, -0.1]\nmax_m = [0.3, 0.06]\n",
        ..Default::default()
    }
    .check();
}

/// `mpirun -np 2 wgsph bench`: rank 0 names each rank's adapter and prints the whole run's
/// figures and a line per rank with the halo it sent, where its step time went and how many of
/// its steps overlapped the exchange.
#[test]
fn bench_under_mpirun_reports_every_rank() {
    let o = mpirun_np(2)
        .arg(env!("CARGO_BIN_EXE_wgsph"))
        .args(["bench", "cases/dam_break_2d.toml", "--adapter", "cpu"])
        .args(["--steps", "20", "--warmup", "2"])
        .output()
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert!(o.status.success(), "{stdout}\n{stderr}");
    // Each rank logs its adapter on stderr (mpirun may interleave the lines); rank 0's report
    // names them all.
    for r in 0..2 {
        assert!(
            stdout.contains(&format!("adapter {r:<7} llvmpipe")),
            "{stdout}"
        );
    }
    assert!(
        stdout.contains("ranks           2 (one slab each)"),
        "{stdout}"
    );
    let rows: Vec<Vec<f64>> = stdout
        .lines()
        .skip_while(|l| !l.starts_with("rank  own particles"))
        .skip(1)
        .map(|l| l.split_whitespace().map(|w| w.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 2, "{stdout}");
    let own: f64 = rows.iter().map(|r| r[1]).sum();
    assert_eq!(own, 4274.0, "every particle is own on one rank");
    assert!(rows.iter().all(|r| r[2] > 0.0 && r[4] > 0.0), "{stdout}");
    // `time.overlap_exchange = "auto"` tries both ways in the first steps
    // (`sph::overlap::Choice`).
    assert!(rows.iter().all(|r| r[9] > 0.0 && r[9] < 100.0), "{stdout}");
}

/// A box pushed down through the 2D dam break's water column (dynamic walls, 0.5 m/s down and
/// along), from cuts at equal numbers of cell layers (this case is cut along the vertical): the
/// ranks move the cut into the column at step 100, through the box, whose particles then cross
/// it, migrating from rank to rank, while the load on the box is combined over the ranks. Its
/// pose on every rank and every particle equal one whole run's bit for bit after 300 steps, the
/// last 100 taken by subdomains restored from the state saved at step 200. With wide ids
/// ([`WIDE_IDS`]): halo copies and migrants carry the ids' high bits.
#[test]
fn a_body_crossing_the_cut_moves_as_in_one_run() {
    Comparison {
        test: "a_body_crossing_the_cut_moves_as_in_one_run",
        case: "cases/dam_break_2d.toml",
        // Every step overlapped: "auto"'s first trial comes before the cut reaches the water.
        set: &[
            WIDE_IDS,
            "particles.dx_m=0.0073",
            "time.overlap_exchange=\"always\"",
        ],
        ranks: 2,
        steps: 300,
        uneven: true,
        restore_at: Some(200),
        tables: "[[body]]\nname = \"box\"\nshape = \"box\"\nmin_m = [0.04, 0.10]\n\
                 max_m = [0.10, 0.16]\ndensity_kg_m3 = 500.0\nwall = \"dynamic\"\n\
                 [body.motion]\nkind = \"free\"\nvelocity_m_s = [0.5, -0.5]\n",
        ..Default::default()
    }
    .check();
}

/// The 2D dam break in a tank of fixed ghost walls (the seed's interface, MLS ghosts): a ghost
/// takes its values from the fluid around it earlier in the step, so the halo is two cell layers
/// thick (`decomposition::halo_layers`). From cuts at equal numbers of layers, moved at step 100, every
/// particle equals one whole run's bit for bit after 300 steps. Both ranks' packing buffers,
/// made for their starting halos, grow on the way (`Halo::reserve`). Steps 10 to 19 overlap
/// the exchange (`time.overlap_exchange = "auto"`'s first trial), the ghosts interpolated after
/// both sorts and the first half three layers from the cut.
#[test]
fn ranks_with_fixed_ghost_walls_equal_one_run() {
    Comparison {
        test: "ranks_with_fixed_ghost_walls_equal_one_run",
        case: "cases/dam_break_2d.toml",
        set: &["particles.dx_m=0.0073", "tank.wall=\"fixed_ghost\""],
        ranks: 2,
        steps: 300,
        grows: true,
        uneven: true,
        ..Default::default()
    }
    .check();
}

/// The 2D dam break with the MLS density filter every 7 steps: on those steps the ranks swap
/// their corrected halo particles again and filter with them (`Solver::filter_over_ranks`).
/// From cuts at equal numbers of layers, moved at step 100, every particle equals one whole
/// run's bit for bit after 300 steps, the last 100 taken by subdomains restored at step 200
/// (the filter's last step restored with them). With wide ids ([`WIDE_IDS`]): the filter's
/// records carry the ids' high bits.
#[test]
fn ranks_filter_the_density_as_one_run() {
    Comparison {
        test: "ranks_filter_the_density_as_one_run",
        case: "cases/dam_break_2d.toml",
        set: &[
            WIDE_IDS,
            "particles.dx_m=0.0073",
            "physics.density_filter=\"mls\"",
            "physics.density_filter_every=7",
        ],
        ranks: 2,
        steps: 300,
        uneven: true,
        restore_at: Some(200),
        ..Default::default()
    }
    .check();
}

/// The 2D dam break with a nozzle in its right wall shooting a jet to the left at 1.5 m/s, its
/// buffer's pressure extrapolated from the water at the mirror images (so the halo reaches as
/// far as they do, `decomposition::halo_layers`; with one layer, 890 particles differ). The case is cut
/// along the vertical. From cuts at equal numbers of layers, rank 0 holds every
/// inlet particle waiting to join (ids kept, apart from the free entries the arrivals fill);
/// at step 100 the ranks move the cut through the nozzle, and from then on rank 0 wakes the
/// particles that join above it and sends them on to rank 1. Every particle, the jet's
/// included, equals one whole run's bit for bit after 300 steps, the last 100 taken by
/// subdomains restored at step 200, with the waiting particles.
#[test]
fn ranks_with_an_inlet_inject_what_one_run_injects() {
    Comparison {
        test: "ranks_with_an_inlet_inject_what_one_run_injects",
        case: "cases/dam_break_2d.toml",
        set: &["particles.dx_m=0.0073", "time.overlap_exchange=\"always\""],
        ranks: 2,
        steps: 300,
        uneven: true,
        restore_at: Some(200),
        tables: "[[inlet]]\nname = \"nozzle\"\nmin_m = [0.54, 0.1]\nmax_m = [0.584, 0.16]\n\
                 direction = [-1.0, 0.0]\nvelocity_m_s = 1.5\npressure = \"extrapolated\"\n",
        ..Default::default()
    }
    .check();
}

/// The oscillating plate (an updated-Lagrangian elastic solid, clamped at one end) cut across
/// its length: a solid particle's halo copy and a migrant carry its stress state (τ and the
/// last dτ/dt) to the neighbour, which its own particles' stress rates and artificial stress
/// read (180 and 145 of its 325 particles on the two ranks). From cuts at equal numbers of
/// layers, moved at step 100 (the particles that change owner go with their stress states),
/// every particle equals one whole run's bit for bit after 300 steps, the last 100 taken by
/// subdomains restored at step 200 (with the stresses); without the stress states, 260
/// particles differ. With wide ids ([`WIDE_IDS`]): a stress state finds its particle's entry
/// by the whole id.
#[test]
fn ranks_bend_an_elastic_plate_as_one_run() {
    Comparison {
        test: "ranks_bend_an_elastic_plate_as_one_run",
        case: "cases/oscillating_plate_2d.toml",
        set: &[WIDE_IDS],
        ranks: 2,
        steps: 300,
        uneven: true,
        restore_at: Some(200),
        ..Default::default()
    }
    .check();
}

/// The same plate as a total-Lagrangian solid (`oscillating_plate_tl_2d`), cut across its
/// length: a particle's acceleration reads positions four reference lists away, beyond the
/// halo, so the ranks share every TL particle's predicted position each step and each
/// computes the whole plate's stresses (`Solver::share_tl_positions`). From cuts at equal
/// numbers of layers, moved at step 100, every particle equals one whole run's bit for bit
/// after 300 steps, the last 100 taken by subdomains restored at step 200. With wide ids
/// ([`WIDE_IDS`]).
#[test]
fn ranks_bend_a_total_lagrangian_plate_as_one_run() {
    Comparison {
        test: "ranks_bend_a_total_lagrangian_plate_as_one_run",
        case: "cases/oscillating_plate_tl_2d.toml",
        set: &[WIDE_IDS],
        ranks: 2,
        steps: 300,
        uneven: true,
        restore_at: Some(200),
        ..Default::default()
    }
    .check();
}

/// The elastic gate holding back a water column (the talk's fluid–solid case, its gate updated
/// Lagrangian): the gate's interface pressure comes from the water around it
/// as a ghost's does (a halo of two layers), and its stress crosses the cut with its halo
/// copies (325 and 85 of its particles on the two ranks). Every particle equals one whole run's
/// bit for bit after 100 steps.
#[test]
fn ranks_hold_the_water_with_an_elastic_gate_as_one_run() {
    Comparison {
        test: "ranks_hold_the_water_with_an_elastic_gate_as_one_run",
        case: "cases/elastic_gate_2d.toml",
        set: &[
            "solid[0].formulation=\"updated_lagrangian\"",
            "time.overlap_exchange=\"always\"",
        ],
        ranks: 2,
        steps: 100,
        ..Default::default()
    }
    .check();
}

/// The same gate as the case ships it, total-Lagrangian: the ranks share the gate's predicted
/// positions each step (`Solver::share_tl_positions`), each computes the whole gate's stresses
/// and accelerates its own particles. Every particle equals one whole run's bit for bit after
/// 100 steps.
#[test]
fn ranks_hold_the_water_with_a_total_lagrangian_gate_as_one_run() {
    Comparison {
        test: "ranks_hold_the_water_with_a_total_lagrangian_gate_as_one_run",
        case: "cases/elastic_gate_2d.toml",
        ranks: 2,
        steps: 100,
        ..Default::default()
    }
    .check();
}

/// Sets the run's interrupt flag once the progress it hears has passed `at_steps` steps: every
/// rank hears the same steps (they agree on each), as a signal reaches them at different ones.
struct SignalAt {
    at_steps: u64,
    flag: std::sync::Arc<std::sync::atomic::AtomicBool>,
}

impl wgsph::progress::Progress for SignalAt {
    fn update(&mut self, status: &wgsph::progress::RunStatus) {
        if status.steps >= self.at_steps {
            self.flag.store(true, std::sync::atomic::Ordering::Relaxed);
        }
    }

    fn finish(&mut self, _: &wgsph::progress::RunStatus) {}
}

/// A signal between two probe times stops every rank at the same batch of steps, short of the
/// probe time, with a checkpoint (issue 64: a run answered signals only at probe times); the
/// resumed run over the ranks writes what the uninterrupted one writes, bit for bit (one probe
/// interval: the whole run).
#[test]
fn a_signal_between_probe_times_stops_every_rank_and_resumes_bit_identically() {
    let name = "a_signal_between_probe_times_stops_every_rank_and_resumes_bit_identically";
    if !under_mpirun() {
        let dir = crate::common::Scratch::new("mpi-signal");
        let folder = dir.to_string_lossy().into_owned();
        let (ok, log) = mpirun_with(
            name,
            2,
            Duration::from_secs(300),
            &[("WGSPH_TEST_DIR", &folder)],
        );
        assert!(ok, "the 2-rank job failed:\n{log}");
        assert!(log.contains("stopped between probe times"), "{log}");
        return;
    }
    use wgsph::progress::LogLines;
    use wgsph::run::{resume_on_ranks, run_on_ranks, RunOptions};
    let ranks = Mpi::init().expect("MPI initialised once");
    let ctx = GpuContext::for_rank(AdapterChoice::Cpu, ranks.rank()).unwrap();
    let set: Vec<String> = [
        "particles.dx_m=0.0146",
        "time.end_s=0.08",
        "time.output_every_s=0.08",
        "time.probe_every_s=0.08",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let sc = wgsph::case::load(std::path::Path::new("cases/dam_break_2d.toml"), &set).unwrap();
    let base = std::path::PathBuf::from(std::env::var("WGSPH_TEST_DIR").unwrap());
    let (straight, split) = (base.join("straight"), base.join("split"));
    let plain = RunOptions::default();
    let a = run_on_ranks(
        &ctx,
        &sc,
        &straight,
        &plain,
        &mut LogLines::default(),
        &ranks,
    )
    .unwrap();
    let flag = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let signalled = RunOptions {
        interrupt: Some(flag.clone()),
        ..RunOptions::default()
    };
    let mut signal = SignalAt {
        at_steps: a.summary.steps / 2,
        flag,
    };
    let b = run_on_ranks(&ctx, &sc, &split, &signalled, &mut signal, &ranks).unwrap();
    let t = b.interrupted_at_s.expect("the signal stops the run");
    assert!(0.0 < t && t < 0.08, "stopped at t = {t} s");
    assert!(
        b.summary.steps < signal.at_steps + 64,
        "{}",
        b.summary.steps
    );
    let c = resume_on_ranks(&ctx, &sc, &split, &plain, &mut LogLines::default(), &ranks).unwrap();
    assert_eq!(a.summary.steps, c.summary.steps);
    if ranks.rank() == 0 {
        assert_same_outputs(&straight, &split);
        println!(
            "stopped between probe times at t = {t} s, step {}",
            b.summary.steps
        );
    }
}

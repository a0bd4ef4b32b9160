//! Shared helpers of the GPU tests: one device per test binary, small scenarios built in code.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use wgsph::gpu::{AdapterChoice, GpuContext};
use wgsph::layout::{unpack_block, ID_MASK, KIND_SHIFT};
use wgsph::reference::RefParticle;
use wgsph::scenario::*;
use wgsph::sph::Solver;

/// A test's output folder, `$TMP/wgsph-<name>-<pid>`, emptied when made and removed when the
/// test passes (kept after a failure, to be looked at).
pub struct Scratch(PathBuf);

impl Scratch {
    pub fn new(name: &str) -> Self {
        let d = std::env::temp_dir().join(format!("wgsph-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        Scratch(d)
    }
}

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl Scratch {
    /// The folder, no longer removed (for one shared by several tests of a binary).
    pub fn keep(self) -> PathBuf {
        let d = self.0.clone();
        std::mem::forget(self);
        d
    }
}

impl AsRef<std::ffi::OsStr> for Scratch {
    fn as_ref(&self) -> &std::ffi::OsStr {
        self.0.as_os_str()
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// lavapipe set for the tests, for this process and what it starts (each setting unless it is
/// set already):
/// - one thread per device (`LP_NUM_THREADS=1`): the harness runs a test per core side by side,
///   each on a device of its own ([`gpu`]), and lavapipe gives every device a thread per core,
///   so on 2 cores two tests kept four threads busy. With one each, `wall_treatments` ran in
///   90 s instead of 135 s, `mpi` (two ranks a job) in 182 s instead of 214 s
///   (docs/performance.md, 2026-12-06). A single run is faster with the threads (`wgsph run`
///   keeps lavapipe's default).
/// - shaders compiled for 4-wide vectors (`LP_NATIVE_VECTOR_WIDTH=128`, not the 8 of AVX2):
///   LLVM compiles each pipeline faster, and a clean machine (CI) compiles every shader the
///   tests use once; our kernels, which gather their neighbours, run as fast (the
///   `kernels_vs_reference` tests from an empty shader cache 129 s instead of 172 s, with a
///   full one 84 s against 78 s; the 3D dam break's conservation test 54.6 s against 54.3 s).
/// - a shader cache of the tests' own (`MESA_SHADER_CACHE_DIR` in the target directory), so
///   that shaders of that width never mix with lavapipe's default ones in the user's cache.
///
/// Set once, before this process opens a device (every test opens its own through here or
/// after it called this), so no thread reads the environment from C while it changes.
pub fn lavapipe_for_tests() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let cache = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("mesa_shader_cache");
        let settings = [
            ("LP_NUM_THREADS", "1".into()),
            ("LP_NATIVE_VECTOR_WIDTH", "128".into()),
            ("MESA_SHADER_CACHE_DIR", cache.into_os_string()),
        ];
        for (name, value) in settings {
            if std::env::var_os(name).is_none() {
                std::env::set_var(name, value);
            }
        }
    });
}

/// The adapter for tests: WGSPH_ADAPTER if set, else auto (lavapipe in CI). A missing adapter
/// is a failure, not a skip. One device per test thread: the harness runs tests side by side,
/// and one shared device would put them all on its single queue, one after the other (on
/// lavapipe, two tests on a shared device took 2.8 times as long as on a device each). The
/// device is leaked, a few MB per test.
pub fn gpu() -> &'static GpuContext {
    lavapipe_for_tests();
    thread_local! {
        static CTX: &'static GpuContext = Box::leak(Box::new({
            let choice = AdapterChoice::resolve(None).expect("WGSPH_ADAPTER");
            GpuContext::new(choice)
                .expect("a GPU or software (lavapipe) adapter is required for the tests")
        }));
    }
    CTX.with(|c| *c)
}

pub fn physics(dim: u32, dx: f64, c0: f64) -> Physics {
    let h = 1.3 * dx;
    let mut gravity = [0.0; 3];
    gravity[dim as usize - 1] = -9.81;
    Physics {
        dim,
        dx,
        h,
        kernel: KernelKind::WendlandC2,
        cell: None,
        id_low_bits: None,
        rho0: 1000.0,
        c0,
        gamma: 7.0,
        gravity,
        viscosity: Viscosity::Artificial { alpha: 0.02 },
        delta_sph: 0.1,
        delta_sph_form: Default::default(),
        particle_mass: 1000.0 * dx.powi(dim as i32),
        density_filter: DensityFilter::None,
        energy: false,
    }
}

/// Lattice points min + (i + ½)dx inside [min, max] (3 components, the unused one 0 in 2D).
pub fn lattice(dim: u32, dx: f64, min: [f64; 3], max: [f64; 3]) -> Vec<[f64; 3]> {
    let n: Vec<usize> = (0..3)
        .map(|a| {
            if a < dim as usize {
                ((max[a] - min[a]) / dx).round() as usize
            } else {
                1
            }
        })
        .collect();
    let mut out = Vec::new();
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let idx = [i, j, k];
                let p = [0, 1, 2].map(|a| {
                    if a < dim as usize {
                        min[a] + (idx[a] as f64 + 0.5) * dx
                    } else {
                        0.0
                    }
                });
                out.push(p);
            }
        }
    }
    out
}

pub fn scenario(
    physics: Physics,
    particles: Vec<Particle>,
    domain: Domain,
    probes: Vec<Probe>,
) -> Scenario {
    let physics_dx = physics.dx;
    Scenario {
        name: "test".into(),
        physics,
        time: TimeControl {
            end_s: 1.0,
            output_every_s: 0.1,
            probe_every_s: 0.1,
            cfl: 0.2,
            output_boundary: Default::default(),
            overlap_exchange: Default::default(),
            density_variation_warn: TimeControl::DENSITY_VARIATION_WARN,
            density_variation_stop: TimeControl::DENSITY_VARIATION_STOP,
        },
        walls: WallParams::defaults(physics_dx, 0.5, 9.81),
        periodic: [false; 3],
        bodies: Vec::new(),
        solids: None,
        inlets: Vec::new(),
        outlets: Vec::new(),
        warnings: Vec::new(),
        world_origin_m: [0.0; 3],
        maps: None,
        domain,
        particles,
        probes,
        points: Vec::new(),
    }
}

/// Simple xorshift so tests are reproducible without a dependency.
pub struct Rng(pub u64);

impl Rng {
    /// Lattice point `p` moved by up to ±`jitter`·dx on each of the first `dim` axes, and a
    /// velocity of up to ±0.5 m/s on each: the random particles of the layer-1 tests.
    pub fn jittered(
        &mut self,
        dim: u32,
        p: [f64; 3],
        jitter: f64,
        dx: f64,
    ) -> ([f64; 3], [f64; 3]) {
        let (mut pos, mut vel) = (p, [0.0; 3]);
        for a in 0..dim as usize {
            pos[a] += self.range(-jitter, jitter) * dx;
            vel[a] = self.range(-0.5, 0.5);
        }
        (pos, vel)
    }

    pub fn next_f64(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }
}

/// The GPU arrays (current, cell order) as reference particles in world coordinates, with the
/// code words (kind and id) in the same order.
pub fn gpu_particles_and_codes(s: &Solver) -> (Vec<RefParticle>, Vec<u32>) {
    let (pos, velrho, code) = s.read_raw().unwrap();
    let parts = pos
        .iter()
        .zip(&velrho)
        .zip(&code)
        .map(|((p, v), c)| {
            let pos = s.grid.to_world(p.off, unpack_block(p.block));
            let [wall_vel, wall_acc] = s.wall_motion_of(c & ID_MASK, pos);
            RefParticle {
                pos,
                vel: [v[0] as f64, v[1] as f64, v[2] as f64],
                rho: v[3] as f64,
                kind: c >> KIND_SHIFT,
                body: s.body_of_id(c & ID_MASK),
                body_kinematic: s
                    .body_of_id(c & ID_MASK)
                    .is_some_and(|b| s.body_is_kinematic(b)),
                wall_vel,
                wall_acc,
            }
        })
        .collect();
    (parts, code)
}

/// The GPU arrays as reference particles (see `gpu_particles_and_codes`).
pub fn gpu_particles(s: &Solver) -> Vec<RefParticle> {
    gpu_particles_and_codes(s).0
}

/// Runs the validation case `name` (`wgsph validate`'s table) at the resolution of `resolution`
/// into a temporary folder (the returned `Scratch`, with the outcome's `dir`) and judges it
/// with the bounds of `bounds`; prints its rows.
pub fn validate_case(
    name: &str,
    resolution: wgsph::validation::Mode,
    bounds: wgsph::validation::Mode,
    tag: &str,
) -> (wgsph::validation::CaseOutcome, Scratch) {
    let case = wgsph::validation::find(name).expect("a validation case");
    let dir = Scratch::new(&format!("validate-{name}-{tag}"));
    let overrides = case.overrides(resolution).expect("run in this mode");
    let o = wgsph::validation::run_case(
        &wgsph::validation::Gpu::Given(gpu()),
        case,
        &overrides,
        bounds,
        &dir,
        false,
        &mut wgsph::progress::LogLines::default(),
    );
    println!("{}", rows(&o));
    (o, dir)
}

/// The outcome's table rows and each metric's detail, for messages.
pub fn rows(o: &wgsph::validation::CaseOutcome) -> String {
    let report = wgsph::validation::Report {
        mode: wgsph::validation::Mode::Quick,
        adapter: gpu().describe(),
        cases: vec![o.clone()],
    };
    let mut s = report.table();
    for m in &o.metrics {
        s.push_str(&format!("{}: {}\n", m.name, m.detail));
    }
    s
}

/// Whether f32 and f64 may decide differently if the ghost at `x` uses MLS: its moment
/// matrix's conditioning is within 10 % of the threshold. Such ghosts are left out of
/// comparisons with the reference.
pub fn mls_borderline(sc: &Scenario, parts: &[RefParticle], x: [f64; 3]) -> bool {
    use wgsph::reference::ghost::moment_matrix;
    use wgsph::reference::mls::{min_pivot_ratio, MLS_MIN_PIVOT};
    let a = moment_matrix(&sc.physics, &wgsph::reference::Space::of(sc), parts, x);
    sc.walls.ghost_correction == GhostCorrection::Mls
        && (min_pivot_ratio(sc.physics.dim as usize, a) / MLS_MIN_PIVOT - 1.0).abs() < 0.1
}

/// A case of solids of both formulations: the shipped total-Lagrangian plate
/// (cases/oscillating_plate_tl_2d.toml, probe "tip") and, 0.1 m above it, the shipped
/// updated-Lagrangian one (cases/oscillating_plate_2d.toml; "plate_ul", probe "tip_ul"), each
/// started in its first mode. TOML text.
pub fn both_plates_case() -> String {
    let ul = "cases/oscillating_plate_2d.toml";
    let ul_text = std::fs::read_to_string(ul).unwrap();
    let mut upper = ul_text[ul_text.find("[[solid]]").unwrap()..].to_string();
    for (from, to) in [
        ("name = \"plate\"", "name = \"plate_ul\""),
        ("name = \"tip\"", "name = \"tip_ul\""),
        ("min_m = [0.0, 0.0]", "min_m = [0.0, 0.1]"),
        ("max_m = [0.26, 0.02]", "max_m = [0.26, 0.12]"),
        ("max_m = [0.06, 0.02]", "max_m = [0.06, 0.12]"),
        ("root_m = [0.06, 0.01]", "root_m = [0.06, 0.11]"),
        ("point_m = [0.26, 0.01]", "point_m = [0.26, 0.11]"),
    ] {
        assert!(upper.contains(from), "{ul} no longer has {from}");
        upper = upper.replace(from, to);
    }
    // Without gravity the contact law needs a strength of its own (the plates stay apart).
    format!(
        "{}\n{upper}\n[walls]\nrepulsive_d_m2_s2 = 1.0\n",
        std::fs::read_to_string("cases/oscillating_plate_tl_2d.toml").unwrap()
    )
}

//! The GPU solver: one module per pass, ordered here. A step is
//! predict → cell-list sort → interaction → correct + time step, all on the GPU in one
//! command encoder; the host reads back a 48-byte state once per batch of steps.

pub mod bodies;
pub mod buffers;
pub mod cell_list;
pub mod density_filter;
pub mod elastic;
pub mod ghost;
pub mod grid;
pub mod integrate;
pub mod interaction;
pub mod open_boundaries;
pub mod probes;
pub mod profile;
pub mod state;
pub mod total_lagrangian;

use anyhow::{bail, Context, Result};
use bytemuck::Zeroable;

use crate::body::BodySet;
use crate::gpu::buffers::{map_read, read, readback_buffer};
use crate::gpu::context::GpuFaults;
use crate::gpu::kernel::ShaderModule;
use crate::gpu::shader::{Pass, Present, ShaderConfig};
use crate::gpu::GpuContext;
use crate::layout::{
    pack_block, unpack_block, Params, Pos, SimState, ID_MASK, KIND_EXCLUDED, KIND_SHIFT,
};
use crate::scenario::{
    ContactGroup, DeltaSphForm, GhostCorrection, KernelKind, Kind, ProbeKind, RepulsiveForm,
    Scenario, SolidFormulation, Viscosity,
};
use bodies::Bodies;
use buffers::{CaseTables, InitialParticles, ParticleBuffers};
use cell_list::CellList;
use density_filter::DensityFilter;
use elastic::Elastic;
use ghost::Ghost;
use grid::Grid;
use integrate::Integrate;
use interaction::Interaction;
use open_boundaries::OpenBoundaries;
use probes::{PointTracker, Probes};
use profile::{Profiler, Recorder, StageTime};
use total_lagrangian::TotalLagrangian;

/// Most steps recorded into one submission before the host looks at the state again.
const MAX_BATCH: u32 = 64;

/// A part of the step that benchmarks time on its own.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Key, scan, scatter, rank and reorder.
    CellList,
    /// The neighbour sum.
    Interaction,
    /// A whole step.
    Step,
}

/// Why a run stopped before its end.
#[derive(Debug, thiserror::Error)]
#[error("run unstable at step {step}, t = {time_s:.6} s: {reason}")]
pub struct Unstable {
    pub step: u64,
    pub time_s: f64,
    pub reason: String,
}

pub use crate::output::Particles;

/// (positions, (v, ρ), code words) as stored on the GPU.
pub type RawParticles = (Vec<Pos>, Vec<[f32; 4]>, Vec<u32>);

/// GPU mirror planes in domain coordinates.
fn mirror_planes(sc: &Scenario, origin: [f64; 3]) -> Vec<crate::layout::MirrorPlane> {
    sc.walls
        .mirror_planes
        .iter()
        .map(|m| crate::layout::MirrorPlane {
            point: [0, 1, 2].map(|a| (m.point[a] - origin[a]) as f32),
            no_slip: m.no_slip as u32,
            normal: m.normal.map(|x| x as f32),
            pad: 0,
        })
        .collect()
}

/// The fixed walls' wall-pressure sensors (`WallParams::sensors`) in domain coordinates.
fn wall_sensors(sc: &Scenario, origin: [f64; 3]) -> Vec<crate::layout::WallSensor> {
    (sc.walls.sensors.iter())
        .zip(sc.walls.sensor_faces())
        .map(|(s, face_id)| crate::layout::WallSensor {
            point: [0, 1, 2].map(|a| (s.point[a] - origin[a]) as f32),
            radius: s.radius as f32,
            normal: s.normal.map(|x| x as f32),
            face: s.face as f32,
            over_lo: [0, 1, 2].map(|a| (s.over_lo[a] - origin[a]) as f32),
            face_id,
            over_hi: [0, 1, 2].map(|a| (s.over_hi[a] - origin[a]) as f32),
            pad: 0,
        })
        .collect()
}

/// SPH kernel normalisation α_d (support 2h) of `kernel` in `dim` dimensions.
pub fn kernel_norm(kernel: KernelKind, dim: u32, h: f64) -> f64 {
    use std::f64::consts::PI;
    match (kernel, dim) {
        (KernelKind::CubicSpline, 2) => 10.0 / (7.0 * PI * h * h),
        (KernelKind::CubicSpline, _) => 1.0 / (PI * h * h * h),
        (KernelKind::WendlandC2, 2) => 7.0 / (4.0 * PI * h * h),
        (KernelKind::WendlandC2, _) => 21.0 / (16.0 * PI * h * h * h),
    }
}

/// How many particles fit an adapter, and the limit that binds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Capacity {
    pub particles: u64,
    /// The binding limit: a wgpu limit's name, or the particle id's width.
    pub bound_by: &'static str,
    /// That limit's value (bytes for the wgpu limits).
    pub limit: u64,
}

/// Bytes of the largest per-particle array (positions, (v, ρ), rates: 16 bytes a particle);
/// every other per-particle array is smaller, and the hash grid has at most 2 slots of 4 bytes
/// a particle.
const LARGEST_ARRAY_BYTES_PER_PARTICLE: u64 = 16;

/// The most particles a device with `limits` can run: each per-particle array must fit one
/// storage binding and one buffer, and ids have 28 bits.
pub fn capacity(limits: &wgpu::Limits) -> Capacity {
    let per = LARGEST_ARRAY_BYTES_PER_PARTICLE;
    [
        Capacity {
            particles: limits.max_storage_buffer_binding_size / per,
            bound_by: "max_storage_buffer_binding_size",
            limit: limits.max_storage_buffer_binding_size,
        },
        Capacity {
            particles: limits.max_buffer_size / per,
            bound_by: "max_buffer_size",
            limit: limits.max_buffer_size,
        },
        Capacity {
            particles: ID_MASK as u64,
            bound_by: "the 28-bit particle id",
            limit: ID_MASK as u64,
        },
    ]
    .into_iter()
    .min_by_key(|c| c.particles)
    .expect("three candidates")
}

/// Fails, saying how many fit and which limit binds, when `n` particles do not fit `ctx`'s
/// device. Runs call this before they create anything.
pub fn check_capacity(ctx: &GpuContext, n: usize) -> Result<()> {
    let cap = capacity(&ctx.limits);
    if n as u64 > cap.particles {
        let limit = if cap.bound_by.starts_with("max_") {
            format!("{} = {} MiB", cap.bound_by, cap.limit >> 20)
        } else {
            cap.bound_by.to_string()
        };
        bail!(
            "the case has {n} particles but adapter '{}' fits at most {}: its {limit} holds              {} particles of {LARGEST_ARRAY_BYTES_PER_PARTICLE} bytes per array. Use a coarser              particles.dx_m (the count scales as dx^-dim) or a GPU with larger limits              (`wgsph info` lists them)",
            ctx.info.name,
            cap.particles,
            cap.particles
        );
    }
    Ok(())
}

pub struct Solver {
    device: wgpu::Device,
    queue: wgpu::Queue,
    /// Asynchronous GPU failures (out of memory, device lost), checked after every wait.
    faults: GpuFaults,
    pub grid: Grid,
    pub params: Params,
    buffers: ParticleBuffers,
    cell_list: CellList,
    interaction: Interaction,
    /// Shepard/MLS density re-initialisation, if the case asks for one.
    density_filter: Option<DensityFilter>,
    ghost: Ghost,
    energy: bool,
    integrate: Integrate,
    /// Elastic solid particles, if the case has any (updated-Lagrangian formulation).
    elastic: Option<Elastic>,
    /// Solid particles (the length of the solid arrays).
    n_solid: u32,
    /// Elastic solid particles of the total-Lagrangian formulation.
    total_lagrangian: Option<TotalLagrangian>,
    probes: Probes,
    /// Tracked points of bodies, if the case has any.
    points: Option<PointTracker>,
    /// The case's probes and the bodies' centres at t = 0, when a probe moves with a body.
    attached_probes: Option<(Vec<crate::scenario::Probe>, Vec<[f64; 3]>)>,
    /// Each probe's face on a fixed wall (`probes::probe_faces`).
    probe_faces: Vec<u32>,
    /// Moving bodies: the GPU part, the host dynamics, and the buffer the state and the
    /// per-workgroup loads are read back into after every step.
    bodies: Option<(Bodies, BodySet, wgpu::Buffer)>,
    parity: usize,
    t_base: f64,
    steps: u64,
    state: SimState,
    initial_dt: f32,
    n_fluid: u64,
    /// Inlet particles behind their buffers at t = 0 (excluded until they join).
    dormant_at_start: u32,
    /// Velocity inlets and outlets, if the case has any.
    open_boundaries: Option<OpenBoundaries>,
    /// Stop when more than this fraction of the fluid has been excluded.
    pub max_excluded_fraction: f64,
    /// Per-stage timestamps, while [`Solver::profile_steps`] runs.
    profiler: Option<Profiler>,
}

impl Solver {
    pub fn new(ctx: &GpuContext, sc: &Scenario) -> Result<Self> {
        let ph = &sc.physics;
        let n = sc.particles.len();
        if n == 0 {
            bail!("the case has no particles");
        }
        check_capacity(ctx, n)?;
        let grid = Grid::new(&sc.domain, ph.h, ph.dim, n, sc.periodic)?;
        let body_id_base = body_id_base(sc)?;
        let (alpha, nu, viscosity) = match ph.viscosity {
            Viscosity::Artificial { alpha } => (alpha, 0.0, 0),
            Viscosity::Laminar { nu } => (0.0, nu, 1),
        };
        let mut params = Params {
            grid_cells: grid.cells,
            hash_mask: grid.slots - 1,
            dense_grid: grid.dense() as u32,
            block_size: grid.block_size,
            cells_per_block: grid.cells_per_block,
            inv_cell_size: grid.cell_size.map(|c| (1.0 / c) as f32),
            periodic: (0..3)
                .filter(|&a| grid.periodic[a])
                .map(|a| 1u32 << a)
                .sum(),
            domain_size: grid.extent.map(|e| e as f32),
            n_particles: n as u32,
            h: ph.h as f32,
            kernel_norm: kernel_norm(ph.kernel, ph.dim, ph.h) as f32,
            eta2: (0.01 * ph.h * ph.h) as f32,
            mass: ph.particle_mass as f32,
            rho0: ph.rho0 as f32,
            tait_b: ph.tait_b() as f32,
            gamma: ph.gamma as f32,
            c0: ph.c0 as f32,
            gravity: ph.gravity.map(|g| g as f32),
            alpha: alpha as f32,
            nu: nu as f32,
            delta_coef: (ph.delta_sph * ph.h * ph.c0) as f32,
            cfl: sc.time.cfl as f32,
            n_probes: sc.probes.len() as u32,
            n_mirror_planes: sc.walls.mirror_planes.len() as u32,
            ghost_mls: (sc.walls.ghost_correction == GhostCorrection::Mls) as u32,
            repulsive_d: sc.walls.repulsive_d as f32,
            repulsive_r0: sc.walls.repulsive_r0 as f32,
            repulsive_form: (sc.walls.repulsive_form == RepulsiveForm::MonaghanKajtar) as u32,
            repulsive_k_over_beta: (sc.walls.repulsive_k / sc.walls.repulsive_beta) as f32,
            friction: sc.walls.friction as f32,
            friction_slip: sc.walls.friction_slip as f32,
            body_id_base,
            n_body_particles: n as u32 - body_id_base,
            ..Zeroable::zeroed()
        };
        if !sc.walls.friction_pairs.is_empty() {
            let groups = friction_groups(sc)?;
            params.friction_groups = groups.len() as u32;
            params.friction_first_solid = 1 + sc.bodies.len() as u32;
            let table: &mut [f32] = bytemuck::cast_slice_mut(&mut params.friction_table);
            for (a, ga) in groups.iter().enumerate() {
                for (b, gb) in groups.iter().enumerate() {
                    table[a * groups.len() + b] = sc.walls.friction_between(*ga, *gb) as f32;
                }
            }
        }
        if let Some(solids) = &sc.solids {
            let (distinct, _) = solids.distinct_materials();
            if distinct.len() > crate::layout::MAX_SOLID_MATERIALS {
                bail!(
                    "the solids have {} different materials, more than the {} a case may hold",
                    distinct.len(),
                    crate::layout::MAX_SOLID_MATERIALS
                );
            }
            for (slot, m) in params.solid_materials.iter_mut().zip(&distinct) {
                *slot = solid_material(m, ph);
            }
            params.solid_p_speed = solids.max_p_wave_speed() as f32;
            params.solid_inv_w_dx =
                (1.0 / crate::reference::kernel::w(ph.kernel, ph.dim, ph.h, ph.dx)) as f32;
            params.solid_id_base = solid_range(sc)?.start as u32;
        }
        if let (Some(first), Some(last)) = (sc.inlets.first(), sc.inlets.last()) {
            params.inlet_id_base = first.particles.start as u32;
            params.n_inlet_particles = (last.particles.end - first.particles.start) as u32;
            params.n_inlets = sc.inlets.len() as u32;
        }
        params.n_outlets = sc.outlets.len() as u32;
        let cfg = ShaderConfig {
            dim: ph.dim,
            kernel: match ph.kernel {
                KernelKind::CubicSpline => 0,
                KernelKind::WendlandC2 => 1,
            },
            viscosity,
            energy: ph.energy,
            hydrostatic_diffusion: ph.delta_sph > 0.0
                && ph.delta_sph_form == DeltaSphForm::Fourtakas,
            wall_reactions: sc.walls.reactions,
            present: present(sc, body_id_base),
        };
        let mut pos = Vec::with_capacity(n);
        let mut velrho = Vec::with_capacity(n);
        let mut code = Vec::with_capacity(n);
        for (id, p) in sc.particles.iter().enumerate() {
            let (off, b) = grid.to_block(p.pos);
            pos.push(Pos {
                off,
                block: pack_block(b),
            });
            velrho.push([
                p.vel[0] as f32,
                p.vel[1] as f32,
                p.vel[2] as f32,
                p.rho as f32,
            ]);
            code.push(((p.kind as u32) << KIND_SHIFT) | id as u32);
        }
        // Inlet particles behind their buffers wait excluded (in no cell) until they join.
        for inlet in &sc.inlets {
            for (k, id) in inlet.particles.clone().enumerate() {
                if inlet.dormant(k) {
                    code[id] = (KIND_EXCLUDED << KIND_SHIFT) | id as u32;
                }
            }
        }
        let device = ctx.device.clone();
        for p in &sc.probes {
            if let ProbeKind::WallPressure(patch) = &p.kind {
                if !sc.walls.reactions || patch.area.is_nan() || patch.area <= 0.0 {
                    bail!(
                        "wall-pressure probe {:?} needs walls.reactions and a patch resolved \
                         by WallPatch::resolve",
                        p.name
                    );
                }
            }
        }
        // Allocation failures are caught here to name what was being allocated; later ones
        // reach `faults`.
        let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let probe_faces = probes::probe_faces(&sc.probes, &sc.walls);
        let defs = probes::probe_defs(&sc.probes, grid.origin, &probe_faces);
        let planes = mirror_planes(sc, grid.origin);
        let sensors = wall_sensors(sc, grid.origin);
        let body_particles = bodies::body_particles(sc);
        let body_motions = bodies::initial_motions(sc, body_id_base);
        let solid = solid_states(sc)?;
        let buffers = ParticleBuffers::new(
            &device,
            &params,
            grid.slots,
            &InitialParticles {
                pos: &pos,
                velrho: &velrho,
                code: &code,
                body_particles: &body_particles,
                body_motions: &body_motions,
                solid: &solid,
            },
            &CaseTables {
                probes: &defs,
                mirror_planes: &planes,
                wall_sensors: &sensors,
            },
            ph.energy,
        );
        let module = |pass| ShaderModule::new(&device, pass, cfg);
        let cell_list = CellList::new(
            &device,
            &module(Pass::CellList)?,
            &module(Pass::PrefixScan)?,
            &buffers,
            ph.energy,
        )?;
        let interaction = Interaction::new(&device, &module(Pass::Interaction)?, &buffers)?;
        let has_kind = |k: &[Kind]| sc.particles.iter().any(|p| k.contains(&p.kind));
        let ghost = Ghost::new(
            &device,
            &module(Pass::Ghost)?,
            &buffers,
            has_kind(&[Kind::GhostNoSlip, Kind::GhostFreeSlip]),
            has_kind(&[Kind::Fluid]) && has_kind(&[Kind::Solid, Kind::SolidClamped]),
        )?;
        let density_filter = match ph.density_filter {
            crate::scenario::DensityFilter::None => None,
            mode => DensityFilter::new(&device, &module(Pass::DensityFilter)?, &buffers, mode)?,
        };
        let integrate = Integrate::new(&device, &module(Pass::Integrate)?, &buffers)?;
        let has_formulation = |f| sc.solids.as_ref().is_some_and(|s| s.has(f));
        let elastic = if has_formulation(SolidFormulation::UpdatedLagrangian) {
            Some(Elastic::new(&device, &module(Pass::Elastic)?, &buffers)?)
        } else {
            None
        };
        let total_lagrangian = if has_formulation(SolidFormulation::TotalLagrangian) {
            Some(TotalLagrangian::new(
                &device,
                &module(Pass::TotalLagrangian)?,
                &buffers,
                sc,
            )?)
        } else {
            None
        };
        let open_boundaries = if sc.inlets.is_empty() && sc.outlets.is_empty() {
            None
        } else {
            Some(OpenBoundaries::new(
                &device,
                &module(Pass::OpenBoundaries)?,
                &buffers,
                sc,
                &grid,
            )?)
        };
        let probe_module = module(Pass::Probes)?;
        let probes = Probes::new(
            &device,
            &probe_module,
            &buffers,
            &sc.probes,
            &defs,
            ph.particle_mass,
        )?;
        let points = PointTracker::new(&device, &probe_module, &buffers, &sc.points)?;
        let bodies = if sc.bodies.is_empty() {
            None
        } else {
            let gpu = Bodies::new(
                &device,
                &module(Pass::Bodies)?,
                &buffers,
                body_motions,
                body_id_base,
            )?;
            let staging = readback_buffer(
                &device,
                "state and body loads",
                std::mem::size_of::<SimState>() as u64 + gpu.partials_bytes(),
            );
            let host = BodySet::new(&sc.bodies, ph.gravity, ph.dim);
            Some((gpu, host, staging))
        };
        if let Some(e) = pollster::block_on(oom.pop()) {
            bail!(
                "the GPU ran out of memory allocating the buffers of {n} particles ({} MiB, \
                 {:.0} bytes a particle): use a coarser particles.dx_m or a GPU with more \
                 memory ({e})",
                buffers.bytes() >> 20,
                buffers.bytes() as f64 / n as f64
            );
        }
        let mut solver = Self {
            device,
            queue: ctx.queue.clone(),
            faults: ctx.faults.clone(),
            grid,
            params,
            buffers,
            cell_list,
            interaction,
            density_filter,
            ghost,
            energy: ph.energy,
            integrate,
            elastic,
            n_solid: solid.len() as u32,
            total_lagrangian,
            probes,
            points,
            probe_faces,
            attached_probes: sc.probes.iter().any(|p| p.body.is_some()).then(|| {
                (
                    sc.probes.clone(),
                    sc.bodies.iter().map(|b| b.center).collect(),
                )
            }),
            bodies,
            parity: 0,
            t_base: 0.0,
            steps: 0,
            state: SimState::default(),
            initial_dt: 0.0,
            // Fluid (inlets' included) and free solid particles: the ones that move and can
            // leave the domain.
            n_fluid: (sc.count(Kind::Fluid) + sc.count(Kind::Inlet) + sc.count(Kind::Solid)) as u64,
            dormant_at_start: sc.dormant_count() as u32,
            open_boundaries,
            max_excluded_fraction: 0.05,
            profiler: None,
        };
        // Warm-up: one step with dt = 0 sorts the particles, evaluates the initial rates and
        // chooses the first dt; it moves nothing and is not counted.
        solver.take_steps(1)?;
        solver.initial_dt = solver.state.dt_cfl;
        Ok(solver)
    }

    /// The bodies' host state (poses and last loads), if the case has bodies.
    pub fn bodies(&self) -> Option<&BodySet> {
        self.bodies.as_ref().map(|(_, host, _)| host)
    }

    pub fn time(&self) -> f64 {
        self.t_base + self.state.t_rel as f64
    }

    pub fn steps(&self) -> u64 {
        self.steps
    }

    pub fn dt(&self) -> f64 {
        self.state.dt_cfl as f64
    }

    /// Particles that left the domain or became non-finite (not counting inlet particles that
    /// still wait behind their buffers, nor the fluid outlets removed, which sit in the same
    /// excluded slot).
    pub fn excluded(&self) -> u64 {
        let dormant = self
            .dormant_at_start
            .saturating_sub(self.state.inlet_joined);
        let s = &self.state;
        s.excluded.saturating_sub(dormant).saturating_sub(s.drained) as u64
    }

    /// Fluid particles the outlets have removed.
    pub fn drained(&self) -> u64 {
        self.state.drained as u64
    }

    pub fn particle_count(&self) -> u64 {
        self.buffers.n as u64
    }

    /// GPU memory of the run's buffers, in bytes.
    pub fn gpu_bytes(&self) -> u64 {
        self.buffers.bytes()
            + self.total_lagrangian.as_ref().map_or(0, |t| t.bytes())
            + self.elastic.as_ref().map_or(0, |e| e.bytes())
    }

    fn read_state(&self) -> Result<SimState> {
        let state = read::<SimState>(&self.device, &self.queue, &self.buffers.state, 1);
        // A lost device fails the wait; say why rather than how.
        self.faults.check()?;
        Ok(state?[0])
    }

    /// Test hook: destroys the device, as a driver reset or an unplugged GPU would.
    #[doc(hidden)]
    pub fn lose_device(&self) {
        self.device.destroy();
    }

    /// Takes `count` steps (as the GPU state says: dt 0 once arrived) and reads the state back.
    /// Without bodies the steps go in one submission; with bodies one at a time, each between
    /// the host's predictor and corrector of the bodies.
    fn take_steps(&mut self, count: u32) -> Result<()> {
        if self.bodies.is_none() {
            let encoder = self.encode_steps(count);
            self.queue.submit([encoder.finish()]);
            self.state = self.read_state()?;
            return self.faults.check();
        }
        for _ in 0..count {
            self.step_with_bodies()?;
        }
        Ok(())
    }

    /// One step with bodies: the host predicts every body to t + dt and uploads the poses, the
    /// GPU steps and sums the loads, the host reads back the state and the loads (the only
    /// per-step readback) and corrects the bodies.
    fn step_with_bodies(&mut self) -> Result<()> {
        let dt = self.state.dt as f64;
        let t_next = self.time() + dt;
        let (gpu, host, _) = self.bodies.as_mut().expect("a run with bodies");
        let poses = host.predict(t_next, dt);
        gpu.upload(&self.queue, &self.grid, &poses, &host.accelerations(t_next));
        let mut encoder = self.encode_steps(1);
        let (gpu, _, staging) = self.bodies.as_ref().expect("a run with bodies");
        let state_bytes = std::mem::size_of::<SimState>() as u64;
        encoder.copy_buffer_to_buffer(&self.buffers.state, 0, staging, 0, state_bytes);
        encoder.copy_buffer_to_buffer(&gpu.partials, 0, staging, state_bytes, gpu.partials_bytes());
        self.queue.submit([encoder.finish()]);
        let bytes = map_read(&self.device, staging)?;
        self.state = bytemuck::pod_read_unaligned(&bytes[..state_bytes as usize]);
        let partials: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&bytes[state_bytes as usize..]);
        let loads = gpu.loads(&partials);
        let (_, host, _) = self.bodies.as_mut().expect("a run with bodies");
        host.correct(dt, &loads);
        self.faults.check()
    }

    /// Records `count` steps into one command encoder (with the profiler on, each stage in a
    /// timed pass of its own: one step per encoder).
    fn encode_steps(&mut self, count: u32) -> wgpu::CommandEncoder {
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("steps"),
            });
        let mut profiler = self.profiler.take();
        assert!(
            profiler.is_none() || count == 1,
            "profiling records one step per encoder"
        );
        for _ in 0..count {
            self.cell_list.clear(&mut encoder, &self.buffers);
            let recorder = match profiler.as_mut() {
                Some(profiler) => Recorder::Timed {
                    encoder: &mut encoder,
                    profiler,
                },
                None => {
                    Recorder::Shared(encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: Some("step"),
                        timestamp_writes: None,
                    }))
                }
            };
            self.record_step(recorder);
        }
        if let Some(p) = &profiler {
            p.resolve(&mut encoder);
        }
        self.profiler = profiler;
        encoder
    }

    /// The stages of one step, in order; flips the parity.
    fn record_step(&mut self, mut r: Recorder<'_>) {
        let p = self.parity;
        let q = 1 - p;
        let bodies = self.bodies.as_ref().map(|(gpu, _, _)| gpu);
        r.stage("predict", |pass| self.integrate.encode_predict(pass, p));
        if let Some(e) = &self.elastic {
            r.stage("elastic_predict", |pass| e.encode_predict(pass, p));
        }
        if let Some(b) = bodies {
            r.stage("body_move", |pass| b.encode_move(pass, p));
        }
        if let Some(o) = &self.open_boundaries {
            r.stage("open_boundaries", |pass| o.encode(pass, p));
        }
        let cells = &self.cell_list;
        r.stage("sort_key", |pass| cells.encode_key(pass, p));
        r.stage("sort_scan", |pass| cells.encode_scan(pass));
        r.stage("sort_scatter", |pass| cells.encode_scatter(pass));
        r.stage("sort_reorder", |pass| cells.encode_reorder(pass, p));
        if let Some(t) = &self.total_lagrangian {
            r.stage("total_lagrangian_index", |pass| t.encode_index(pass, q));
        }
        if let Some(b) = bodies {
            r.stage("body_index", |pass| b.encode_index(pass, q));
        }
        r.stage("ghost", |pass| self.ghost.encode(pass, q));
        if let Some(o) = &self.open_boundaries {
            r.stage("inlet_pressure", |pass| o.encode_pressure(pass, q));
        }
        r.stage("interaction", |pass| self.interaction.encode(pass, q));
        if let Some(e) = &self.elastic {
            r.stage("elastic_rates", |pass| e.encode_rates(pass, q));
            r.stage("elastic_correct", |pass| e.encode_correct(pass, q));
        }
        if let Some(t) = &self.total_lagrangian {
            r.stage("total_lagrangian_rates", |pass| t.encode_rates(pass, q));
        }
        if let Some(b) = bodies {
            r.stage("body_force", |pass| b.encode_force(pass, q));
        }
        r.stage("correct", |pass| self.integrate.encode_correct(pass, q));
        if let Some(f) = &self.density_filter {
            r.stage("density_filter", |pass| f.encode(pass, q));
        }
        drop(r);
        self.parity = q;
    }

    /// Re-bases the GPU's f32 clock on the host's f64 one, so that it only ever counts a short
    /// span: the state to upload (with the time to run still to be set).
    fn rebased_state(&mut self) -> SimState {
        self.t_base += self.state.t_rel as f64;
        let mut st = self.state;
        st.t_rel = 0.0;
        st.t_base = self.t_base as f32;
        st
    }

    /// Advances to exactly `t_target` (the last step is shortened to land on it).
    pub fn advance_to(&mut self, t_target: f64) -> Result<()> {
        let mut st = self.rebased_state();
        let remaining = t_target - self.t_base;
        st.t_target_rel = remaining as f32;
        st.dt = if remaining > 1e-4 * st.dt_cfl as f64 {
            st.dt_cfl.min(remaining as f32)
        } else {
            0.0
        };
        self.queue
            .write_buffer(&self.buffers.state, 0, bytemuck::bytes_of(&st));
        self.state = st;
        while self.state.dt > 0.0 {
            let left = (self.state.t_target_rel - self.state.t_rel).max(0.0);
            let batch =
                ((left / self.state.dt_cfl.max(1e-30)).ceil() as u32 + 1).clamp(1, MAX_BATCH);
            let before = self.state.steps;
            self.take_steps(batch)?;
            self.steps += (self.state.steps - before) as u64;
            self.check_stability()?;
        }
        // Arrived: the host clock takes the exact target (the GPU's f32 clock is re-based on
        // the next call anyway).
        self.t_base = self.t_base.max(t_target);
        self.state.t_rel = 0.0;
        Ok(())
    }

    /// Takes exactly `count` steps of CFL size (no target time), for benchmarks; waits for the
    /// GPU at the end and checks stability.
    pub fn run_steps(&mut self, count: u64) -> Result<()> {
        let st = self.start_untargeted();
        let mut left = count;
        while left > 0 {
            let batch = left.min(MAX_BATCH as u64) as u32;
            if self.bodies.is_some() {
                self.take_steps(batch)?;
            } else {
                // Benchmarks: no readback between batches.
                let encoder = self.encode_steps(batch);
                self.queue.submit([encoder.finish()]);
            }
            left -= batch as u64;
        }
        self.state = self.read_state()?;
        self.steps += (self.state.steps - st.steps) as u64;
        self.check_stability()
    }

    /// Sets the GPU state for steps of CFL size with no target time (benchmarks) and returns it.
    fn start_untargeted(&mut self) -> SimState {
        let mut st = self.rebased_state();
        st.t_target_rel = f32::MAX;
        st.dt = st.dt_cfl;
        self.queue
            .write_buffer(&self.buffers.state, 0, bytemuck::bytes_of(&st));
        self.state = st;
        st
    }

    /// Takes `count` steps as [`Solver::run_steps`] does, one submission each, with every stage
    /// in a timed pass of its own, and returns each stage's GPU time summed over the steps (in
    /// the step's order). The particles evolve exactly as without profiling.
    pub fn profile_steps(&mut self, count: u64) -> Result<Vec<StageTime>> {
        if self.profiler.is_none() {
            self.profiler = Some(Profiler::new(&self.device, &self.queue)?);
        }
        self.start_untargeted();
        let result = (0..count).try_for_each(|_| {
            let before = self.state.steps;
            self.take_steps(1)?;
            self.steps += (self.state.steps - before) as u64;
            self.profiler
                .as_mut()
                .expect("profiling")
                .collect(&self.device)
        });
        let profiler = self.profiler.take().expect("profiling");
        result?;
        self.check_stability()?;
        Ok(profiler.totals().to_vec())
    }

    /// Benchmark hook: records `reps` repetitions of `stage`, submits them and waits. After
    /// `CellList` alone the rates no longer match the particle order, so a solver timed that way
    /// is for benchmarking only.
    pub fn time_stage(&mut self, stage: Stage, reps: u64) -> Result<std::time::Duration> {
        if stage == Stage::Step {
            let start = std::time::Instant::now();
            self.run_steps(reps)?;
            return Ok(start.elapsed());
        }
        let start = std::time::Instant::now();
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("stage"),
            });
        for _ in 0..reps {
            if stage == Stage::CellList {
                self.cell_list.clear(&mut encoder, &self.buffers);
            }
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("stage"),
                timestamp_writes: None,
            });
            match stage {
                Stage::CellList => {
                    self.cell_list.encode(&mut pass, self.parity);
                    self.parity = 1 - self.parity;
                }
                Stage::Interaction | Stage::Step => self.interaction.encode(&mut pass, self.parity),
            }
        }
        self.queue.submit([encoder.finish()]);
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| anyhow::anyhow!("GPU wait failed: {e}"))?;
        Ok(start.elapsed())
    }

    fn check_stability(&self) -> Result<()> {
        let s = &self.state;
        let fail = |reason: String| -> Result<()> {
            Err(Unstable {
                step: self.steps,
                time_s: self.time(),
                reason,
            }
            .into())
        };
        if s.nan_count > 0 {
            return fail(format!(
                "{} fluid or solid particle(s) became non-finite; reduce time.cfl or check the case",
                s.nan_count
            ));
        }
        let excluded = self.excluded();
        if excluded as f64 > self.max_excluded_fraction * self.n_fluid as f64 {
            return fail(format!(
                "{} of {} fluid and solid particles left the domain (more than {:.0} %)",
                excluded,
                self.n_fluid,
                100.0 * self.max_excluded_fraction
            ));
        }
        if s.dt_cfl.is_nan() || s.dt_cfl <= 1e-4 * self.initial_dt {
            return fail(format!(
                "the time step collapsed to {:e} s (started at {:e} s)",
                s.dt_cfl, self.initial_dt
            ));
        }
        Ok(())
    }

    /// Samples every probe at the current time.
    pub fn sample_probes(&self) -> Result<Vec<f64>> {
        if self.probes.is_empty() {
            return Ok(Vec::new());
        }
        if let (Some((list, centers)), Some(set)) = (&self.attached_probes, self.bodies()) {
            let placed: Vec<_> = list
                .iter()
                .map(|p| match p.body {
                    Some(k) => probes::moved(p, centers[k], &set.pose(k)),
                    None => p.clone(),
                })
                .collect();
            let defs = probes::probe_defs(&placed, self.grid.origin, &self.probe_faces);
            self.queue
                .write_buffer(&self.buffers.probes, 0, bytemuck::cast_slice(&defs));
        }
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("probes"),
            });
        self.probes.encode(&mut encoder, &self.buffers, self.parity);
        self.queue.submit([encoder.finish()]);
        let raw = read::<u32>(
            &self.device,
            &self.queue,
            &self.buffers.probe_out,
            self.params.n_probes as usize,
        )?;
        Ok(self.probes.decode(&raw))
    }

    /// World positions of the tracked points (`Scenario::points`, in order) at the current
    /// time; empty without points.
    pub fn sample_points(&self) -> Result<Vec<[f64; 3]>> {
        let Some(tracker) = &self.points else {
            return Ok(Vec::new());
        };
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("track points"),
            });
        tracker.encode(&mut encoder, self.parity);
        self.queue.submit([encoder.finish()]);
        let pos = tracker.read(&self.device, &self.queue)?;
        self.faults.check()?;
        Ok(pos
            .iter()
            .map(|p| self.grid.to_world(p.off, unpack_block(p.block)))
            .collect())
    }

    /// Test hook: re-runs the ghost interpolation (fixed ghosts and the solids' interface
    /// pressure, extrapolated inlet buffers' pressure), the interaction pass and, with solids,
    /// the elastic rates on the current arrays
    /// and returns the rates. With `poison`, `rate` (and the stress rates) are first filled with
    /// NaN so an entry the kernel skips cannot pass.
    #[doc(hidden)]
    pub fn rerun_interaction(&self, poison: bool) -> Result<Vec<[f32; 4]>> {
        if poison {
            let nan = vec![f32::NAN; 4 * self.buffers.n as usize];
            self.queue
                .write_buffer(&self.buffers.rate, 0, bytemuck::cast_slice(&nan));
            if let Some(e) = &self.elastic {
                let nan = vec![f32::NAN; 8 * self.n_solid as usize];
                self.queue
                    .write_buffer(&e.stress_rate, 0, bytemuck::cast_slice(&nan));
            }
        }
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("interaction"),
            });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("interaction"),
            timestamp_writes: None,
        });
        self.ghost.encode(&mut pass, self.parity);
        if let Some(o) = &self.open_boundaries {
            o.encode_pressure(&mut pass, self.parity);
        }
        self.interaction.encode(&mut pass, self.parity);
        if let Some(e) = &self.elastic {
            e.encode_rates(&mut pass, self.parity);
        }
        if let Some(t) = &self.total_lagrangian {
            t.encode_rates(&mut pass, self.parity);
        }
        drop(pass);
        self.queue.submit([encoder.finish()]);
        self.read_rates()
    }

    /// The solid state (τ, body, last dτ/dt, interface pressure, material) of every solid
    /// particle, in id order from `solid_id_base` (of a total-Lagrangian solid only its body
    /// and material are in use).
    pub fn read_solid(&self) -> Result<Vec<crate::layout::SolidState>> {
        if self.elastic.is_none() && self.total_lagrangian.is_none() {
            bail!("the case has no solids");
        }
        read(
            &self.device,
            &self.queue,
            &self.buffers.solid,
            self.n_solid as usize,
        )
    }

    /// The first solid particle's id (the index base of `read_solid`).
    pub fn solid_id_base(&self) -> u32 {
        self.params.solid_id_base
    }

    /// Test hook: dτ/dt of the last evaluation, by solid particle as `read_solid`.
    #[doc(hidden)]
    pub fn read_stress_rates(&self) -> Result<Vec<crate::layout::SymRate>> {
        let Some(e) = &self.elastic else {
            bail!("the case has no updated-Lagrangian solids");
        };
        read(
            &self.device,
            &self.queue,
            &e.stress_rate,
            self.n_solid as usize,
        )
    }

    /// Whether body `b` moves as prescribed, whatever its load (`kind = "fixed"`, `"sine"`,
    /// `"series"` or the moving tank; its GPU flag).
    pub fn body_is_kinematic(&self, b: u32) -> bool {
        self.bodies
            .as_ref()
            .is_some_and(|(gpu, _, _)| gpu.is_kinematic(b))
    }

    /// The body particle `id` belongs to, if any.
    pub fn body_of_id(&self, id: u32) -> Option<u32> {
        let (gpu, _, _) = self.bodies.as_ref()?;
        id.checked_sub(self.params.body_id_base)
            .and_then(|k| gpu.body_of(k))
    }

    /// The velocity and acceleration at `x` of the solid particle `id` belongs to, as the GPU
    /// moves it this step: a body's rigid motion (from the last upload); zero for every other
    /// particle.
    pub fn wall_motion_of(&self, id: u32, x: [f64; 3]) -> [[f64; 3]; 2] {
        match (self.body_of_id(id), &self.bodies) {
            (Some(b), Some((gpu, _, _))) => gpu.wall_motion(b, x),
            _ => [[0.0; 3]; 2],
        }
    }

    /// Test hook: re-runs the interaction and the body sums on the current arrays and returns
    /// each body's force and torque (about the centre of mass of the last uploaded pose).
    #[doc(hidden)]
    pub fn rerun_body_loads(&self) -> Result<Vec<crate::body::Load>> {
        let Some((gpu, _, _)) = &self.bodies else {
            bail!("the case has no bodies");
        };
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("body loads"),
            });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("body loads"),
            timestamp_writes: None,
        });
        self.interaction.encode(&mut pass, self.parity);
        gpu.encode_force(&mut pass, self.parity);
        drop(pass);
        self.queue.submit([encoder.finish()]);
        let partials: Vec<[f32; 4]> = read(
            &self.device,
            &self.queue,
            &gpu.partials,
            gpu.partials_bytes() as usize / 16,
        )?;
        Ok(gpu.loads(&partials))
    }

    /// Test hook: applies the density filter of the case once to the current arrays (whatever
    /// the step count). With `poison`, the filter's output buffer is first filled with NaN, so a
    /// fluid particle the filter skips gets a NaN density.
    #[doc(hidden)]
    pub fn run_density_filter(&mut self, poison: bool) -> Result<()> {
        let Some(f) = &self.density_filter else {
            bail!("the case has no density filter");
        };
        if poison {
            let nan = vec![f32::NAN; 4 * self.buffers.n as usize];
            self.queue
                .write_buffer(&self.buffers.rate_sorted, 0, bytemuck::cast_slice(&nan));
        }
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("density filter"),
            });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("density filter"),
            timestamp_writes: None,
        });
        f.encode_now(&mut pass, self.parity);
        drop(pass);
        self.queue.submit([encoder.finish()]);
        Ok(())
    }

    /// Test hook: takes exactly one step of `dt` (no clipping) and returns the new state.
    #[doc(hidden)]
    pub fn single_step(&mut self, dt: f32) -> Result<SimState> {
        let mut st = self.rebased_state();
        st.t_target_rel = f32::MAX;
        st.dt = dt;
        self.queue
            .write_buffer(&self.buffers.state, 0, bytemuck::bytes_of(&st));
        self.state = st;
        self.take_steps(1)?;
        Ok(self.state)
    }

    /// Raw arrays of the current parity, in GPU (cell) order.
    pub fn read_raw(&self) -> Result<RawParticles> {
        let n = self.buffers.n as usize;
        let p = self.parity;
        Ok((
            read(&self.device, &self.queue, &self.buffers.pos[p], n)
                .context("reading positions")?,
            read(&self.device, &self.queue, &self.buffers.velrho[p], n)
                .context("reading velocities")?,
            read(&self.device, &self.queue, &self.buffers.code[p], n).context("reading codes")?,
        ))
    }

    /// Rates (dv/dt, dρ/dt) of the last evaluation, in GPU order.
    pub fn read_rates(&self) -> Result<Vec<[f32; 4]>> {
        read(
            &self.device,
            &self.queue,
            &self.buffers.rate,
            self.buffers.n as usize,
        )
    }

    /// Test hook: de/dt of the last evaluation (energy equation on), in GPU order.
    #[doc(hidden)]
    pub fn read_energy_rates(&self) -> Result<Vec<f32>> {
        read(
            &self.device,
            &self.queue,
            &self.buffers.energy_rate,
            self.buffers.n as usize,
        )
    }

    /// Slot starts of the last sort (slots + 2 entries).
    pub fn read_cell_start(&self) -> Result<Vec<u32>> {
        read(
            &self.device,
            &self.queue,
            &self.buffers.cell_start,
            self.grid.slots as usize + 2,
        )
    }

    /// All particles in world coordinates, sorted by id.
    pub fn read_particles(&self) -> Result<Particles> {
        let (pos, velrho, code) = self.read_raw()?;
        let energy: Option<Vec<[f32; 2]>> = if self.energy {
            Some(read(
                &self.device,
                &self.queue,
                &self.buffers.energy[self.parity],
                pos.len(),
            )?)
        } else {
            None
        };
        // The solid state (τ, material) of either formulation.
        let solid = if self.elastic.is_some() || self.total_lagrangian.is_some() {
            Some(self.read_solid()?)
        } else {
            None
        };
        let tl = match &self.total_lagrangian {
            Some(t) => Some(t.cauchy_stress(&self.device, &self.queue, self.parity)?),
            None => None,
        };
        let mut order: Vec<usize> = (0..pos.len()).collect();
        order.sort_unstable_by_key(|&i| code[i] & ID_MASK);
        let b = self.params.tait_b as f64;
        let (rho0, gamma) = (self.params.rho0 as f64, self.params.gamma as f64);
        let mut out = Particles::default();
        for i in order {
            out.pos
                .push(self.grid.to_world(pos[i].off, unpack_block(pos[i].block)));
            let v = velrho[i];
            out.vel.push([v[0], v[1], v[2]]);
            out.rho.push(v[3]);
            let kind = code[i] >> KIND_SHIFT;
            let id = code[i] & ID_MASK;
            let solid_kind = crate::reference::elastic::is_solid(kind);
            // τ and material of the particle (zeros for the others), when the case has solids.
            let state = solid.as_ref().map(|s| {
                if !solid_kind {
                    return Default::default();
                }
                s[(id - self.params.solid_id_base) as usize]
            });
            let mut tau = state.map(|s| {
                let (a, b) = (s.tau_a, s.tau_b);
                [a[0], a[1], a[2], a[3], b[0], b[1]]
            });
            let mat = state.map_or_else(Default::default, |s| {
                self.params.solid_materials[s.material as usize]
            });
            let tl_stress = tl.as_ref().and_then(|(first, stress)| {
                stress
                    .get(id.checked_sub(*first)? as usize)
                    .filter(|_| solid_kind)
            });
            if let Some(c) = tl_stress {
                // Total-Lagrangian: ρ = ρs/J, p = −tr σ/3 and τ = σ + p I.
                let p = -(c.sigma[0] + c.sigma[1] + c.sigma[2]) / 3.0;
                *out.rho.last_mut().expect("pushed above") = (mat.rho0 as f64 / c.j) as f32;
                out.pressure.push(p as f32);
                let mut t = c.sigma;
                for d in &mut t[..3] {
                    *d += p;
                }
                tau = Some(t.map(|x| x as f32));
            } else if solid_kind {
                // p = c_s² (ρ − ρs).
                out.pressure.push(mat.c2 * (v[3] - mat.rho0));
            } else {
                out.pressure
                    .push((b * ((v[3] as f64 / rho0).powf(gamma) - 1.0)) as f32);
            }
            out.kind.push(kind);
            out.id.push(code[i] & ID_MASK);
            if let Some(e) = &energy {
                out.energy.get_or_insert_with(Vec::new).push(e[i][0]);
            }
            if tl.is_some() || solid.is_some() {
                out.stress
                    .get_or_insert_with(Vec::new)
                    .push(tau.unwrap_or_default());
            }
        }
        Ok(out)
    }
}

/// Which kinds of particle and wall `sc` has, for the composed shaders (`Present`): kinds do
/// not appear during a run (inlet particles become fluid, any particle may become excluded).
fn present(sc: &Scenario, body_id_base: u32) -> Present {
    let has = |kinds: &[Kind]| sc.particles.iter().any(|p| kinds.contains(&p.kind));
    Present {
        solids: has(&[Kind::Solid, Kind::SolidClamped]),
        fixed_ghosts: has(&[Kind::GhostNoSlip, Kind::GhostFreeSlip]),
        repulsive: has(&[Kind::Repulsive]),
        bodies: (body_id_base as usize) < sc.particles.len(),
        mirrors: !sc.walls.mirror_planes.is_empty(),
        lone_solid: sc.solids.as_ref().is_some_and(|s| s.materials.len() == 1)
            && sc.particles.iter().all(|p| p.kind.is_solid()),
    }
}

/// The id of the first body particle: bodies' particles must come last, body after body, in
/// the scenario's order (the case builder puts them there). Without bodies, the particle count.
fn body_id_base(sc: &Scenario) -> Result<u32> {
    let n = sc.particles.len();
    let base = sc.bodies.first().map_or(n, |b| b.particles.start);
    let mut next = base;
    for b in &sc.bodies {
        if b.particles.start != next || b.particles.is_empty() {
            bail!(
                "body '{}' has particles {:?}: bodies need non-empty ranges that follow each \
                 other up to the last particle",
                b.name,
                b.particles
            );
        }
        next = b.particles.end;
    }
    if next != n {
        bail!("the bodies' particles must be the last ones of the scenario");
    }
    Ok(base as u32)
}

/// The contact groups of a case in the GPU's order (`Params::friction_groups`): the walls, the
/// bodies, the solids.
fn friction_groups(sc: &Scenario) -> Result<Vec<ContactGroup>> {
    let solids = sc.solids.as_ref().map_or(0, |s| s.materials.len());
    let groups: Vec<ContactGroup> = std::iter::once(ContactGroup::Walls)
        .chain((0..sc.bodies.len()).map(ContactGroup::Body))
        .chain((0..solids).map(ContactGroup::Solid))
        .collect();
    if groups.len() > crate::layout::MAX_FRICTION_GROUPS {
        bail!(
            "friction by pair needs at most {} walls, bodies and solids together; the case has {}",
            crate::layout::MAX_FRICTION_GROUPS,
            groups.len()
        );
    }
    Ok(groups)
}

/// The solid particles' ids; they must be consecutive (the case loader builds them so), which
/// lets the solid arrays be indexed by id − first id.
pub(crate) fn solid_range(sc: &Scenario) -> Result<std::ops::Range<usize>> {
    let ids: Vec<usize> = (0..sc.particles.len())
        .filter(|&i| sc.particles[i].kind.is_solid())
        .collect();
    consecutive(&ids, "the elastic solids")
}

/// The range that sorted `ids` fill, when they are consecutive (the particles of `what`).
pub(crate) fn consecutive(ids: &[usize], what: &str) -> Result<std::ops::Range<usize>> {
    let (Some(&first), Some(&last)) = (ids.first(), ids.last()) else {
        bail!("{what} have no particles");
    };
    if last - first + 1 != ids.len() {
        bail!("{what}' particles must have consecutive ids");
    }
    Ok(first..last + 1)
}

/// What the kernels use of an elastic material.
fn solid_material(
    m: &crate::scenario::ElasticMaterial,
    ph: &crate::scenario::Physics,
) -> crate::layout::SolidMaterial {
    let c_s = m.sound_speed();
    crate::layout::SolidMaterial {
        rho0: m.density as f32,
        c2: (c_s * c_s) as f32,
        mu: m.shear_modulus() as f32,
        mass: m.particle_mass(ph.dx, ph.dim) as f32,
        alpha: m.alpha as f32,
        eps: m.artificial_stress as f32,
        lambda: crate::reference::total_lagrangian::lame(m).0 as f32,
        total_lagrangian: (m.formulation == SolidFormulation::TotalLagrangian) as u32,
    }
}

/// The initial state (τ0, body, material) of every solid particle, in id order, or nothing
/// without solids.
fn solid_states(sc: &Scenario) -> Result<Vec<crate::layout::SolidState>> {
    let Some(solids) = &sc.solids else {
        return Ok(Vec::new());
    };
    let n = sc.particles.len();
    if solids.body.len() != n || solids.tau0.len() != n {
        bail!(
            "the solids have {} bodies and {} stresses for {n} particles",
            solids.body.len(),
            solids.tau0.len()
        );
    }
    let (_, material) = solids.distinct_materials();
    solid_range(sc)?
        .map(|i| {
            let t = solids.tau0[i].map(|x| x as f32);
            let body = solids.body[i];
            Ok(crate::layout::SolidState {
                tau_a: [t[0], t[1], t[2], t[3]],
                tau_b: [t[4], t[5], 0.0],
                body,
                material: *material.get(body as usize).ok_or_else(|| {
                    anyhow::anyhow!(
                        "solid particle {i} is of body {body}, which has no material ({} given)",
                        solids.materials.len()
                    )
                })?,
                ..Default::default()
            })
        })
        .collect()
}

/// Kind word of an excluded particle, for callers filtering outputs.
pub const EXCLUDED: u32 = KIND_EXCLUDED;

#[cfg(test)]
mod tests {
    use super::*;

    fn present_in(case: &str) -> Present {
        let sc = crate::case::load(std::path::Path::new(case), &[]).unwrap();
        present(&sc, body_id_base(&sc).unwrap())
    }

    /// Only a case of one elastic body and nothing else skips its solids' neighbour search:
    /// with water, walls or a second solid, the solid must be loaded.
    #[test]
    fn a_lone_solid_is_a_case_of_one_elastic_body_alone() {
        assert!(present_in("cases/oscillating_plate_2d.toml").lone_solid);
        assert!(present_in("cases/oscillating_plate_tl_2d.toml").lone_solid);
        assert!(!present_in("cases/elastic_gate_2d.toml").lone_solid);
        assert!(!present_in("cases/dam_break_2d.toml").lone_solid);
        let text = std::fs::read_to_string("cases/oscillating_plate_2d.toml")
            .unwrap()
            .replace("[[solid]]", "[walls]\nrepulsive_d_m2_s2 = 1.0\n[[solid]]")
            + "\n[[solid]]\nname = \"second\"\nmin_m = [0.0, 0.1]\nmax_m = [0.2, 0.12]\n\
               density_kg_m3 = 1000.0\nyoungs_modulus_pa = 2.0e6\npoisson_ratio = 0.3975\n";
        let two = crate::case::load_str(&text, "two.toml", &[]).unwrap();
        assert!(!present(&two, body_id_base(&two).unwrap()).lone_solid);
    }
}

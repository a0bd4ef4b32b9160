//! Moving bodies on the GPU (shaders/bodies.wgsl): places body particles from the poses the
//! host computes (src/body/), tracks where the sort puts them, and sums their force and torque
//! per workgroup for the host to finish in f64.

use anyhow::Result;
use glam::{DMat3, DVec3};

use super::buffers::ParticleBuffers;
use super::shader::WORKGROUP_MAX;
use crate::body::{Load, Pose};
use crate::gpu::buffers::{storage, storage_init};
use crate::gpu::kernel::{ParityKernel, ShaderModule};
use crate::gpu::shader::{Shader, WORKGROUP_SIZE};
use crate::grid::Grid;

pub const SHADER: Shader = Shader {
    name: "bodies",
    source: include_str!("../../shaders/bodies.wgsl"),
    libs: &[WORKGROUP_MAX],
};
use crate::layout::{pack_block, BodyMotion, BodyParticle, BODY_KINEMATIC};
use crate::scenario::Scenario;

/// Body-frame offsets of the bodies' particles (index = id − first body id).
pub fn body_particles(sc: &Scenario) -> Vec<BodyParticle> {
    let mut out = Vec::new();
    for (k, b) in sc.bodies.iter().enumerate() {
        for p in &sc.particles[b.particles.clone()] {
            out.push(BodyParticle {
                r: [0, 1, 2].map(|a| (p.pos[a] - b.center[a]) as f32),
                body: k as u32,
            });
        }
    }
    out
}

/// The per-body table of `bodies`, whose particles have ids from `first_id` on: each body's
/// particle range and first workgroup of `body_force` (the motion comes with each step).
pub fn initial_motions(sc: &Scenario, first_id: u32) -> Vec<BodyMotion> {
    let mut groups = 0;
    sc.bodies
        .iter()
        .map(|body| {
            let count = body.particles.len() as u32;
            let m = BodyMotion {
                first: body.particles.start as u32 - first_id,
                count,
                first_group: groups,
                flags: if body.motion.is_kinematic() {
                    BODY_KINEMATIC
                } else {
                    0
                },
                ..Default::default()
            };
            groups += count.div_ceil(WORKGROUP_SIZE).max(1);
            m
        })
        .collect()
}

pub struct Bodies {
    /// The per-body table (at the start of `ParticleBuffers::tables`); `first`, `count` and
    /// `first_group` never change.
    motions: Vec<BodyMotion>,
    motion_buf: wgpu::Buffer,
    /// The poses and accelerations (linear, angular) of the last upload (what the GPU moves
    /// the bodies with).
    poses: Vec<Pose>,
    accels: Vec<[DVec3; 2]>,
    pub partials: wgpu::Buffer,
    /// Workgroups of `body_force` (each covers particles of one body).
    groups: u32,
    body_move: ParityKernel,
    body_index: ParityKernel,
    body_force: ParityKernel,
    n_body: u32,
    n: u32,
}

impl Bodies {
    /// `motions` is the table the buffers were made with ([`initial_motions`]).
    pub fn new(
        device: &wgpu::Device,
        module: &ShaderModule,
        b: &ParticleBuffers,
        motions: Vec<BodyMotion>,
        first_id: u32,
    ) -> Result<Self> {
        let groups = motions.last().map_or(0, |m| {
            m.first_group + m.count.div_ceil(WORKGROUP_SIZE).max(1)
        });
        let n_body = b.n - first_id;
        // The particles start in id order.
        let slots: Vec<u32> = (first_id..first_id + n_body).collect();
        let body_slot = storage_init(device, "body slots", &slots);
        let partials = storage(device, "body partials", Self::partials_bytes_for(groups));
        let bound = |entry: &str| {
            ParityKernel::new(device, module, entry, |p| {
                b.at(p)
                    .with("body_slot", &body_slot)
                    .with("body_partials", &partials)
            })
        };
        Ok(Self {
            body_move: bound("body_move")?,
            body_index: bound("body_index")?,
            body_force: bound("body_force")?,
            poses: vec![Pose::default(); motions.len()],
            accels: vec![[DVec3::ZERO; 2]; motions.len()],
            motions,
            motion_buf: b.tables.clone(),
            partials,
            groups,
            n_body,
            n: b.n,
        })
    }

    fn partials_bytes_for(groups: u32) -> u64 {
        32 * groups as u64
    }

    /// Size of the per-workgroup (force, torque) array, the only per-step readback.
    pub fn partials_bytes(&self) -> u64 {
        Self::partials_bytes_for(self.groups)
    }

    /// Uploads the poses and accelerations of the step about to be taken (one per body, in
    /// order).
    pub fn upload(
        &mut self,
        queue: &wgpu::Queue,
        grid: &Grid,
        poses: &[Pose],
        accels: &[[DVec3; 2]],
    ) {
        for ((m, pose), [a, alpha]) in self.motions.iter_mut().zip(poses).zip(accels) {
            let (off, block) = grid.to_block(pose.center.to_array());
            let r = DMat3::from_quat(pose.rotation);
            m.center_off = off;
            m.center_block = pack_block(block);
            m.rotation = [r.x_axis, r.y_axis, r.z_axis].map(|c| {
                let c = c.as_vec3();
                [c.x, c.y, c.z, 0.0]
            });
            m.velocity = pose.velocity.as_vec3().to_array();
            m.omega = pose.omega.as_vec3().to_array();
            m.accel = a.as_vec3().to_array();
            m.alpha = alpha.as_vec3().to_array();
        }
        queue.write_buffer(&self.motion_buf, 0, bytemuck::cast_slice(&self.motions));
        self.poses = poses.to_vec();
        self.accels = accels.to_vec();
    }

    /// The rigid velocity and acceleration at `x` of body `b` as last uploaded,
    /// u_c + ω × r and a_c + α × r + ω × (ω × r) with r = x − x_c: how its particles (and the
    /// walls its fixed ghosts stand for) move in the step.
    pub fn wall_motion(&self, b: u32, x: [f64; 3]) -> [[f64; 3]; 2] {
        let (pose, [a, alpha]) = (&self.poses[b as usize], self.accels[b as usize]);
        let r = DVec3::from_array(x) - pose.center;
        let w = pose.omega;
        [
            pose.velocity_at(DVec3::from_array(x)).to_array(),
            (a + alpha.cross(r) + w.cross(w.cross(r))).to_array(),
        ]
    }

    /// Moves the body particles of parity `p` (after the predictor, before the sort).
    pub fn encode_move(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.body_move.dispatch(pass, p, self.n_body);
    }

    /// Records where the sort put each body particle (parity `p`, after the sort).
    pub fn encode_index(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.body_index.dispatch(pass, p, self.n);
    }

    /// Per-workgroup force and torque sums of parity `p` (after the interaction).
    pub fn encode_force(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.body_force.dispatch_groups(pass, p, self.groups);
    }

    /// Whether body `b` moves as prescribed, whatever its load (its `BODY_KINEMATIC` flag).
    pub fn is_kinematic(&self, b: u32) -> bool {
        self.motions[b as usize].flags & BODY_KINEMATIC != 0
    }

    /// The body of body particle `k` (id − first body id).
    pub fn body_of(&self, k: u32) -> Option<u32> {
        self.motions
            .iter()
            .position(|m| (m.first..m.first + m.count).contains(&k))
            .map(|b| b as u32)
    }

    /// Each body's force and torque: its workgroups' partial sums added in f64, in order.
    pub fn loads(&self, partials: &[[f32; 4]]) -> Vec<Load> {
        let mut out = vec![Load::default(); self.motions.len()];
        for (k, m) in self.motions.iter().enumerate() {
            let end = self
                .motions
                .get(k + 1)
                .map_or(self.groups, |next| next.first_group);
            for g in m.first_group..end {
                let (f, t) = (partials[2 * g as usize], partials[2 * g as usize + 1]);
                out[k].force += DVec3::new(f[0] as f64, f[1] as f64, f[2] as f64);
                out[k].torque += DVec3::new(t[0] as f64, t[1] as f64, t[2] as f64);
            }
        }
        out
    }
}

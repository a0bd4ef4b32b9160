//! Moving bodies on the GPU (shaders/bodies.wgsl): places body particles from the poses the
//! host computes (src/body/), tracks where the sort puts them, and sums their force and torque
//! per workgroup for the host to finish in f64. A subdomain of a run over ranks reads back the
//! per-particle loads instead: the ranks combine them ([`owners_values`]) and each sums them
//! with the GPU's own tree ([`workgroup_sums`]), so that every rank moves the bodies as one
//! whole run does.

use anyhow::Result;
use glam::{DMat3, DVec3};

use super::buffers::ParticleBuffers;
use super::shader::PARTICLE_ID;
use super::shader::WORKGROUP_MAX;
use crate::body::{Load, Pose};
use crate::gpu::buffers::storage;
use crate::gpu::kernel::{ParityKernel, ShaderModule};
use crate::gpu::shader::{Shader, WORKGROUP_SIZE};
use crate::grid::Grid;

pub const SHADER: Shader = Shader {
    name: "bodies",
    source: include_str!("../../shaders/bodies.wgsl"),
    libs: &[PARTICLE_ID, WORKGROUP_MAX],
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
    /// Per body particle (force, torque) of `body_load`.
    pub particle_loads: wgpu::Buffer,
    /// Per workgroup (force, torque) of `body_force`.
    pub partials: wgpu::Buffer,
    /// Workgroups of `body_force` (each covers particles of one body).
    groups: u32,
    /// A subdomain's bodies: the host sums the per-particle loads of every rank.
    over_ranks: bool,
    body_move: ParityKernel,
    body_forget: ParityKernel,
    body_index: ParityKernel,
    body_load: ParityKernel,
    body_force: ParityKernel,
    n_body: u32,
    n: u32,
}

impl Bodies {
    /// `motions` is the table the buffers were made with ([`initial_motions`]); `over_ranks`:
    /// of a subdomain ([`Bodies::loads_buffer`]). The slots are unknown until
    /// [`Bodies::encode_index`] runs.
    pub fn new(
        device: &wgpu::Device,
        module: &ShaderModule,
        b: &ParticleBuffers,
        motions: Vec<BodyMotion>,
        over_ranks: bool,
    ) -> Result<Self> {
        let groups = motions.last().map_or(0, |m| {
            m.first_group + m.count.div_ceil(WORKGROUP_SIZE).max(1)
        });
        let n_body = motions.iter().map(|m| m.count).sum::<u32>();
        let body_slot = storage(device, "body slots", 4 * n_body as u64);
        let particle_loads = storage(device, "body particle loads", 32 * n_body as u64);
        let partials = storage(device, "body partials", Self::partials_bytes_for(groups));
        let bound = |entry: &str| {
            ParityKernel::new(device, module, entry, |p| {
                b.at(p)
                    .with("body_slot", &body_slot)
                    .with("body_loads", &particle_loads)
                    .with("body_partials", &partials)
            })
        };
        Ok(Self {
            body_move: bound("body_move")?,
            body_forget: bound("body_forget")?,
            body_index: bound("body_index")?,
            body_load: bound("body_load")?,
            body_force: bound("body_force")?,
            poses: vec![Pose::default(); motions.len()],
            accels: vec![[DVec3::ZERO; 2]; motions.len()],
            motions,
            motion_buf: b.tables.clone(),
            particle_loads,
            partials,
            groups,
            over_ranks,
            n_body,
            n: b.n,
        })
    }

    fn partials_bytes_for(groups: u32) -> u64 {
        32 * groups as u64
    }

    /// Size of the per-workgroup (force, torque) array.
    pub fn partials_bytes(&self) -> u64 {
        Self::partials_bytes_for(self.groups)
    }

    /// What the host reads back after every step, and its size: the per-workgroup sums, or
    /// in a subdomain the per-particle loads.
    pub fn loads_buffer(&self) -> (&wgpu::Buffer, u64) {
        match self.over_ranks {
            true => (&self.particle_loads, 32 * self.n_body as u64),
            false => (&self.partials, self.partials_bytes()),
        }
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

    /// Records where the sort put each live body particle (parity `p`, after the sort).
    pub fn encode_index(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.body_forget.dispatch(pass, p, self.n_body);
        self.body_index.dispatch(pass, p, self.n);
    }

    /// The body particles' loads of parity `p` (after the interaction), and their sums per
    /// workgroup unless the host sums them ([`Bodies::loads_buffer`]).
    pub fn encode_force(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.body_load.dispatch(pass, p, self.n_body);
        if !self.over_ranks {
            self.encode_workgroup_sums(pass, p);
        }
    }

    /// `body_force` alone: the per-workgroup sums of the loads `body_load` left.
    pub fn encode_workgroup_sums(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
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

    /// Each body's force and torque from its particles' loads (`body_load`'s array), summed
    /// as the GPU sums them.
    pub fn loads_of_particles(&self, particle_loads: &[[f32; 4]]) -> Vec<Load> {
        self.loads(&workgroup_sums(&self.motions, self.groups, particle_loads))
    }
}

/// `body_force` on the host: per workgroup of 64 body particles, the same tree of f32 additions
/// (stride 32, 16, …, 1; zeros past a body's last particle), so the same loads give the same
/// bits. IEEE additions only: the products are the GPU's own (`body_load`).
pub fn workgroup_sums(
    motions: &[BodyMotion],
    groups: u32,
    particle_loads: &[[f32; 4]],
) -> Vec<[f32; 4]> {
    let wg = WORKGROUP_SIZE as usize;
    let mut out = vec![[0.0; 4]; 2 * groups as usize];
    for (b, m) in motions.iter().enumerate() {
        let end = motions.get(b + 1).map_or(groups, |next| next.first_group);
        for g in m.first_group..end {
            // Per lane (force, torque).
            let mut lanes = vec![[[0.0f32; 3]; 2]; wg];
            for (li, lane) in lanes.iter_mut().enumerate() {
                let local = (g - m.first_group) as usize * wg + li;
                if local < m.count as usize {
                    let k = m.first as usize + local;
                    for (part, load) in lane.iter_mut().zip(&particle_loads[2 * k..2 * k + 2]) {
                        *part = [load[0], load[1], load[2]];
                    }
                }
            }
            let mut stride = wg / 2;
            while stride > 0 {
                for li in 0..stride {
                    let upper = lanes[li + stride];
                    for (part, add) in lanes[li].iter_mut().zip(upper) {
                        for (x, y) in part.iter_mut().zip(add) {
                            *x += y;
                        }
                    }
                }
                stride /= 2;
            }
            for (part, [x, y, z]) in lanes[0].iter().enumerate() {
                out[2 * g as usize + part] = [*x, *y, *z, 0.0];
            }
        }
    }
    out
}

/// Every rank's per-particle loads combined: each entry is the one rank's that holds the
/// particle, or +0 where none does (as one whole run leaves an excluded particle's). Exact:
/// the ranks add the values' bit patterns as whole numbers, which the others' zeros leave
/// unchanged (adding the values themselves would turn a held −0 into +0).
pub fn owners_values(ranks: &dyn crate::ranks::Ranks, mine: &[[f32; 4]]) -> Vec<[f32; 4]> {
    let bits: Vec<f64> = mine.iter().flatten().map(|x| x.to_bits() as f64).collect();
    let summed = ranks.sum_in_rank_order(&bits);
    summed
        .chunks(4)
        .map(|c| [0, 1, 2, 3].map(|a| f32::from_bits(c[a] as u32)))
        .collect()
}

//! The neighbour sum: continuity, momentum, δ-SPH and viscosity (shaders/interaction.wgsl).

use anyhow::Result;

use super::buffers::ParticleBuffers;
use crate::gpu::kernel::ShaderModule;
use crate::gpu::Kernel;

pub struct Interaction {
    kernel: Kernel,
    bind: [wgpu::BindGroup; 2],
    n: u32,
}

impl Interaction {
    pub fn new(device: &wgpu::Device, module: &ShaderModule, b: &ParticleBuffers) -> Result<Self> {
        let kernel = module.kernel(device, "interaction")?;
        let bufs = |p: usize| {
            [
                (0, &b.params),
                (1, &b.pos[p]),
                (2, &b.velrho[p]),
                (3, &b.code[p]),
                (4, &b.cell_start),
                (5, &b.rate),
                (6, &b.mirror_planes),
                (7, &b.energy_rate),
                (8, &b.body_particles),
                (9, &b.solid),
                (10, &b.body_motions),
                (11, &b.wall_sensors),
            ]
        };
        let bind = [
            kernel.bind(device, &bufs(0))?,
            kernel.bind(device, &bufs(1))?,
        ];
        Ok(Self {
            kernel,
            bind,
            n: b.n,
        })
    }

    /// Evaluates the rates of the (sorted) arrays of parity `p` into `rate`.
    pub fn encode(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.kernel.dispatch(pass, &self.bind[p], self.n);
    }
}

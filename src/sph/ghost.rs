//! Fixed-ghost interpolation (shaders/ghost.wgsl): sets the pressure (through ρ) and velocity
//! of every ghost particle from the fluid, after the sort and before the interaction.

use anyhow::Result;

use super::buffers::ParticleBuffers;
use crate::gpu::kernel::ShaderModule;
use crate::gpu::Kernel;

pub struct Ghost {
    kernel: Kernel,
    bind: [wgpu::BindGroup; 2],
    n: u32,
}

impl Ghost {
    pub fn new(device: &wgpu::Device, module: &ShaderModule, b: &ParticleBuffers) -> Result<Self> {
        let kernel = module.kernel(device, "ghost_interpolate")?;
        let bufs = |p: usize| {
            [
                (0, &b.params),
                (1, &b.pos[p]),
                (2, &b.velrho[p]),
                (3, &b.code[p]),
                (4, &b.cell_start),
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

    pub fn encode(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.kernel.dispatch(pass, &self.bind[p], self.n);
    }
}

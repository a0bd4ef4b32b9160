//! The neighbour sum: continuity, momentum, δ-SPH and viscosity (shaders/interaction.wgsl).

use anyhow::Result;

use super::buffers::ParticleBuffers;
use super::shader::PARTICLE_ID;
use super::shader::{NEIGHBOURS, WALL_PATCH};
use crate::gpu::kernel::{ParityKernel, ShaderModule};
use crate::gpu::shader::Shader;

pub const SHADER: Shader = Shader {
    name: "interaction",
    source: include_str!("../../shaders/interaction.wgsl"),
    libs: &[PARTICLE_ID, NEIGHBOURS, WALL_PATCH],
};

pub struct Interaction {
    kernel: ParityKernel,
    n: u32,
}

impl Interaction {
    pub fn new(device: &wgpu::Device, module: &ShaderModule, b: &ParticleBuffers) -> Result<Self> {
        Ok(Self {
            kernel: ParityKernel::new(device, module, "interaction", |p| b.at(p))?,
            n: b.n,
        })
    }

    /// Evaluates the rates of the (sorted) arrays of parity `p` into `rate`.
    pub fn encode(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.kernel.dispatch(pass, p, self.n);
    }
}

//! Predictor, corrector (with the max-reduction for the time step) and the time-step choice
//! (shaders/integrate.wgsl).

use anyhow::Result;

use super::buffers::ParticleBuffers;
use super::shader::WORKGROUP_MAX;
use crate::gpu::kernel::{ParityKernel, ShaderModule};
use crate::gpu::shader::Shader;
use crate::gpu::Kernel;

pub const SHADER: Shader = Shader {
    name: "integrate",
    source: include_str!("../../shaders/integrate.wgsl"),
    libs: &[WORKGROUP_MAX],
};

pub struct Integrate {
    predict: ParityKernel,
    correct: ParityKernel,
    timestep: Kernel,
    bind_timestep: wgpu::BindGroup,
    n: u32,
}

impl Integrate {
    pub fn new(device: &wgpu::Device, module: &ShaderModule, b: &ParticleBuffers) -> Result<Self> {
        let timestep = module.kernel(device, "timestep")?;
        Ok(Self {
            predict: ParityKernel::new(device, module, "predict", |p| b.at(p))?,
            correct: ParityKernel::new(device, module, "correct", |p| b.at(p))?,
            bind_timestep: timestep.bind(device, &b.unparitied())?,
            timestep,
            n: b.n,
        })
    }

    pub fn encode_predict(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.predict.dispatch(pass, p, self.n);
    }

    /// Corrector on parity `p`, then the time-step choice for the next step.
    pub fn encode_correct(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.correct.dispatch(pass, p, self.n);
        self.timestep.dispatch_groups(pass, &self.bind_timestep, 1);
    }
}

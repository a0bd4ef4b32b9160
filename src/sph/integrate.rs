//! Predictor, corrector (with the max-reduction for the time step) and the time-step choice
//! (shaders/integrate.wgsl).

use anyhow::Result;

use super::buffers::ParticleBuffers;
use crate::gpu::kernel::ShaderModule;
use crate::gpu::Kernel;

pub struct Integrate {
    predict: Kernel,
    correct: Kernel,
    timestep: Kernel,
    bind_predict: [wgpu::BindGroup; 2],
    bind_correct: [wgpu::BindGroup; 2],
    bind_timestep: wgpu::BindGroup,
    n: u32,
}

impl Integrate {
    pub fn new(device: &wgpu::Device, module: &ShaderModule, b: &ParticleBuffers) -> Result<Self> {
        let predict = module.kernel(device, "predict")?;
        let correct = module.kernel(device, "correct")?;
        let timestep = module.kernel(device, "timestep")?;
        let bufs = |p: usize| {
            [
                (0, &b.params),
                (1, &b.pos[p]),
                (2, &b.velrho[p]),
                (3, &b.code[p]),
                (4, &b.rate),
                (5, &b.rate_sorted),
                (6, &b.state),
                (7, &b.cell_start),
                (8, &b.energy[p]),
                (9, &b.energy_rate),
                (10, &b.mirror_planes),
            ]
        };
        Ok(Self {
            bind_predict: [
                predict.bind(device, &bufs(0))?,
                predict.bind(device, &bufs(1))?,
            ],
            bind_correct: [
                correct.bind(device, &bufs(0))?,
                correct.bind(device, &bufs(1))?,
            ],
            bind_timestep: timestep.bind(device, &bufs(0))?,
            predict,
            correct,
            timestep,
            n: b.n,
        })
    }

    pub fn encode_predict(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.predict.dispatch(pass, &self.bind_predict[p], self.n);
    }

    /// Corrector on parity `p`, then the time-step choice for the next step.
    pub fn encode_correct(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.correct.dispatch(pass, &self.bind_correct[p], self.n);
        self.timestep.dispatch_groups(pass, &self.bind_timestep, 1);
    }
}

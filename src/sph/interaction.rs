//! The neighbour sum: continuity, momentum, δ-SPH and viscosity (shaders/interaction.wgsl).

use anyhow::Result;

use super::buffers::ParticleBuffers;
use super::shader::PARTICLE_ID;
use super::shader::{NEIGHBOURS, SLAB, WALL_PATCH};
use crate::gpu::kernel::{ParityKernel, ShaderModule};
use crate::gpu::shader::Shader;

pub const SHADER: Shader = Shader {
    name: "interaction",
    source: include_str!("../../shaders/interaction.wgsl"),
    libs: &[PARTICLE_ID, NEIGHBOURS, WALL_PATCH, SLAB],
};

pub struct Interaction {
    kernel: ParityKernel,
    /// A subdomain whose step overlaps the exchange: (`interaction_interior`,
    /// `interaction_boundary`), its two halves.
    halves: Option<[ParityKernel; 2]>,
    n: u32,
}

impl Interaction {
    /// The pass over `b`; with `slab` (a subdomain's `HaloCtl` uniform), also the two halves
    /// of an overlapped step.
    pub fn new(
        device: &wgpu::Device,
        module: &ShaderModule,
        b: &ParticleBuffers,
        slab: Option<&wgpu::Buffer>,
    ) -> Result<Self> {
        let halves = slab
            .map(|ctl| {
                let half = |entry| {
                    ParityKernel::new(device, module, entry, |p| b.at(p).with("halo_ctl", ctl))
                };
                Ok::<_, anyhow::Error>([
                    half("interaction_interior")?,
                    half("interaction_boundary")?,
                ])
            })
            .transpose()?;
        Ok(Self {
            kernel: ParityKernel::new(device, module, "interaction", |p| b.at(p))?,
            halves,
            n: b.n,
        })
    }

    /// Evaluates the rates of the (sorted) arrays of parity `p` into `rate`.
    pub fn encode(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.kernel.dispatch(pass, p, self.n);
    }

    /// The rates of the particles that read nothing the exchange brings (`reads_no_arrival`,
    /// shaders/lib/slab.wgsl), before it arrives, workgroup by workgroup where all of one's
    /// do; the others' marked left for [`Interaction::encode_boundary`], after the second sort.
    pub fn encode_interior(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.half(0).dispatch(pass, p, self.n);
    }

    pub fn encode_boundary(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.half(1).dispatch(pass, p, self.n);
    }

    fn half(&self, k: usize) -> &ParityKernel {
        &self
            .halves
            .as_ref()
            .expect("an overlapped subdomain's interaction")[k]
    }
}

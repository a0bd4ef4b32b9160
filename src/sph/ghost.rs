//! Ghost interpolation (shaders/ghost.wgsl), after the sort and before the interaction: the
//! pressure (through ρ) and velocity of every fixed ghost particle, and the interface pressure
//! of every elastic solid particle, interpolated from the fluid.

use anyhow::Result;

use super::buffers::ParticleBuffers;
use super::shader::PARTICLE_ID;
use super::shader::{FLUID_AT, MLS, NEIGHBOURS};
use crate::gpu::kernel::{ParityKernel, ShaderModule};
use crate::gpu::shader::Shader;

pub const SHADER: Shader = Shader {
    name: "ghost",
    source: include_str!("../../shaders/ghost.wgsl"),
    libs: &[PARTICLE_ID, NEIGHBOURS, MLS, FLUID_AT],
};

pub struct Ghost {
    /// Fixed ghosts, when the case has any.
    walls: Option<ParityKernel>,
    /// Elastic solid particles in fluid, when the case has both.
    solids: Option<ParityKernel>,
    n: u32,
}

impl Ghost {
    pub fn new(
        device: &wgpu::Device,
        module: &ShaderModule,
        b: &ParticleBuffers,
        fixed_ghosts: bool,
        solids_in_fluid: bool,
    ) -> Result<Self> {
        let bound = |entry: &str| ParityKernel::new(device, module, entry, |p| b.at(p));
        Ok(Self {
            walls: fixed_ghosts
                .then(|| bound("ghost_interpolate"))
                .transpose()?,
            solids: solids_in_fluid
                .then(|| bound("solid_interface_pressure"))
                .transpose()?,
            n: b.n,
        })
    }

    /// Both interpolations, on the arrays of parity `p`.
    pub fn encode(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        for k in [&self.walls, &self.solids].into_iter().flatten() {
            k.dispatch(pass, p, self.n);
        }
    }
}

//! Ghost interpolation (shaders/ghost.wgsl), after the sort and before the interaction: the
//! pressure (through ρ) and velocity of every fixed ghost particle, and the interface pressure
//! of every elastic solid particle, interpolated from the fluid.

use anyhow::Result;

use super::buffers::ParticleBuffers;
use crate::gpu::kernel::{ParityKernel, ShaderModule};

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
        let bound = |entry: &str, with_solid: bool| {
            ParityKernel::new(device, module, entry, |p| {
                let mut bufs = vec![
                    (0, &b.params),
                    (1, &b.pos[p]),
                    (2, &b.velrho[p]),
                    (3, &b.code[p]),
                    (4, &b.cell_start),
                ];
                if with_solid {
                    bufs.push((5, &b.solid));
                } else {
                    bufs.push((6, &b.body_particles));
                    bufs.push((7, &b.body_motions));
                }
                bufs
            })
        };
        Ok(Self {
            walls: fixed_ghosts
                .then(|| bound("ghost_interpolate", false))
                .transpose()?,
            solids: solids_in_fluid
                .then(|| bound("solid_interface_pressure", true))
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

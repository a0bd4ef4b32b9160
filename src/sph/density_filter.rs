//! Density re-initialisation of the fluid, Shepard or MLS (shaders/density_filter.wgsl): every
//! `every` steps (counted on the GPU, steps with dt > 0 only), after the corrector.

use anyhow::{bail, Result};
use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use super::buffers::ParticleBuffers;
use super::shader::{MLS, NEIGHBOURS};
use crate::gpu::buffers::{read, STORAGE};
use crate::gpu::kernel::{fold_groups, ParityKernel, ShaderModule};
use crate::gpu::shader::{Shader, WORKGROUP_SIZE};
use crate::gpu::Kernel;

pub const SHADER: Shader = Shader {
    name: "density_filter",
    source: include_str!("../../shaders/density_filter.wgsl"),
    libs: &[NEIGHBOURS, MLS],
};
use crate::scenario::DensityFilter as Mode;

/// Mirror of `FilterCtl` in shaders/density_filter.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
struct FilterCtl {
    every: u32,
    last: u32,
    groups_x: u32,
    groups_y: u32,
}

pub struct DensityFilter {
    /// Filter every `every` steps.
    every: u32,
    gate: Kernel,
    filter: ParityKernel,
    apply: ParityKernel,
    bind_gate: wgpu::BindGroup,
    /// Indirect dispatch arguments written by the gate.
    args: wgpu::Buffer,
    /// [`FilterCtl`]: its `last` outlives a step, so checkpoints save it.
    ctl: wgpu::Buffer,
    n: u32,
}

/// Byte offset of `FilterCtl::last`.
const LAST_OFFSET: u64 = std::mem::offset_of!(FilterCtl, last) as u64;

impl DensityFilter {
    /// The filter of `mode`, or None for `Mode::None`.
    pub fn new(
        device: &wgpu::Device,
        module: &ShaderModule,
        b: &ParticleBuffers,
        mode: Mode,
    ) -> Result<Option<Self>> {
        let (entry, every) = match mode {
            Mode::None => return Ok(None),
            Mode::Shepard { every } => ("density_filter_shepard", every),
            Mode::Mls { every } => ("density_filter_mls", every),
        };
        if every == 0 {
            bail!("the density filter interval must be at least one step");
        }
        let (groups_x, groups_y) = fold_groups(b.n.div_ceil(WORKGROUP_SIZE).max(1));
        let ctl = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("density filter ctl"),
            contents: bytemuck::bytes_of(&FilterCtl {
                every,
                last: 0,
                groups_x,
                groups_y,
            }),
            usage: STORAGE,
        });
        let args = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("density filter dispatch"),
            contents: bytemuck::cast_slice(&[0u32; 3]),
            usage: STORAGE | wgpu::BufferUsages::INDIRECT,
        });
        let gate = module.kernel(device, "filter_gate")?;
        // The filtered densities go through `rate_sorted`, free after the corrector read it.
        let bufs = |p: usize| {
            b.at(p)
                .with("filtered", &b.rate_sorted)
                .with("ctl", &ctl)
                .with("args", &args)
        };
        Ok(Some(Self {
            bind_gate: gate.bind(
                device,
                &b.unparitied().with("ctl", &ctl).with("args", &args),
            )?,
            filter: ParityKernel::new(device, module, entry, bufs)?,
            apply: ParityKernel::new(device, module, "apply_density", bufs)?,
            every,
            gate,
            args,
            ctl,
            n: b.n,
        }))
    }

    /// Filters the (sorted, corrected) arrays of parity `p` if this step is an `every`-th one;
    /// record after the time-step kernel.
    pub fn encode(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.gate.dispatch_groups(pass, &self.bind_gate, 1);
        for kernel in [&self.filter, &self.apply] {
            let (pipeline, bind) = kernel.bound(p);
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, bind, &[]);
            pass.dispatch_workgroups_indirect(&self.args, 0);
        }
    }

    /// Whether the step that took the GPU's step count from `before` to `after` is one the
    /// gate (`filter_gate`) opens for: a step taken (a step of dt = 0 does not count) whose
    /// count is a multiple of `every` (a count never seen before, so not the last filtered).
    /// A subdomain must know it beforehand, to swap the corrected halo first.
    pub fn fires_after(&self, before: u32, after: u32) -> bool {
        after != before && after.is_multiple_of(self.every)
    }

    /// The GPU step count of the last filtering (0: none yet). Waits for the GPU.
    pub fn last_applied(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<u32> {
        let ctl: Vec<FilterCtl> = read(device, queue, &self.ctl, 1)?;
        Ok(ctl[0].last)
    }

    /// Sets the step count of the last filtering (restoring a checkpoint).
    pub fn set_last_applied(&self, queue: &wgpu::Queue, last: u32) {
        queue.write_buffer(&self.ctl, LAST_OFFSET, bytemuck::bytes_of(&last));
    }

    /// Filters the arrays of parity `p` now, whatever the step (test hook).
    pub fn encode_now(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.filter.dispatch(pass, p, self.n);
        self.apply.dispatch(pass, p, self.n);
    }
}

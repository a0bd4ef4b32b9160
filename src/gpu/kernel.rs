//! A compute kernel: one entry point of a composed shader, its pipeline, and the globals it
//! really uses (reflected with naga) by name, so a bind group is built by asking for each
//! global's buffer by the name the WGSL gives it: a pass never writes a binding number.

use anyhow::{anyhow, Result};
use wgpu::naga;

/// Buffers by the name of the WGSL global they bind to.
pub trait Resolve {
    /// The buffer of the global `name`, or why there is none.
    fn resolve(&self, name: &str) -> Result<&wgpu::Buffer>;
}

/// A parsed and validated shader module, shared by the kernels of one pass.
pub struct ShaderModule {
    /// The pass's shader name (its file's stem).
    pub name: &'static str,
    module: wgpu::ShaderModule,
    naga: naga::Module,
    info: naga::valid::ModuleInfo,
}

/// Parses and validates the composed source with naga (errors come out readable) and creates
/// the wgpu module.
pub fn parse(source: &str, label: &str) -> Result<(naga::Module, naga::valid::ModuleInfo)> {
    let module = naga::front::wgsl::parse_str(source)
        .map_err(|e| anyhow!("{label}: {}", e.emit_to_string(source)))?;
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .map_err(|e| anyhow!("{label}: {}", e.emit_to_string(source)))?;
    Ok((module, info))
}

impl ShaderModule {
    /// The module of the composed `source` of shader `name`.
    pub fn new(device: &wgpu::Device, name: &'static str, source: String) -> Result<Self> {
        let label = format!("{name}.wgsl");
        let (naga, info) = parse(&source, &label)?;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(&label),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        Ok(Self {
            name,
            module,
            naga,
            info,
        })
    }

    pub fn kernel(&self, device: &wgpu::Device, entry: &str) -> Result<Kernel> {
        let index = self
            .naga
            .entry_points
            .iter()
            .position(|e| e.name == entry)
            .ok_or_else(|| anyhow!("{}.wgsl has no entry point {entry}", self.name))?;
        let uses = self.info.get_entry_point(index);
        let mut bindings: Vec<(u32, String)> = self
            .naga
            .global_variables
            .iter()
            .filter(|(h, _)| !uses[*h].is_empty())
            .filter_map(|(_, g)| Some((g.binding.as_ref()?.binding, g.name.clone()?)))
            .collect();
        bindings.sort_unstable();
        let label = format!("{}::{entry}", self.name);
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(&label),
            layout: None,
            module: &self.module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions::default(),
            cache: None,
        });
        Ok(Kernel {
            label,
            pipeline,
            bindings,
        })
    }
}

pub struct Kernel {
    pub label: String,
    pub pipeline: wgpu::ComputePipeline,
    /// (binding number in group 0, global's name) of every global the entry point uses.
    pub bindings: Vec<(u32, String)>,
}

impl Kernel {
    /// A bind group of the buffers `buffers` resolves for the globals the kernel uses; a global
    /// it cannot resolve is an error naming the kernel and the global.
    pub fn bind(&self, device: &wgpu::Device, buffers: &impl Resolve) -> Result<wgpu::BindGroup> {
        let mut entries = Vec::with_capacity(self.bindings.len());
        for (b, name) in &self.bindings {
            let buffer = buffers
                .resolve(name)
                .map_err(|e| anyhow!("kernel {} reads `{name}`: {e}", self.label))?;
            entries.push(wgpu::BindGroupEntry {
                binding: *b,
                resource: buffer.as_entire_binding(),
            });
        }
        Ok(device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(&self.label),
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &entries,
        }))
    }

    /// Records one dispatch covering `invocations` 1D invocations of WORKGROUP_SIZE.
    pub fn dispatch(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        bind: &wgpu::BindGroup,
        invocations: u32,
    ) {
        let groups = invocations.div_ceil(super::shader::WORKGROUP_SIZE).max(1);
        self.dispatch_groups(pass, bind, groups);
    }

    /// Records one dispatch of `groups` workgroups, folded into 2D past 65535.
    pub fn dispatch_groups(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        bind: &wgpu::BindGroup,
        groups: u32,
    ) {
        let (x, y) = fold_groups(groups);
        DISPATCHES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind, &[]);
        pass.dispatch_workgroups(x, y, 1);
    }
}

/// Dispatches recorded by this process (every one goes through `Kernel::dispatch_groups`): what
/// `wgsph bench` counts a step's dispatches with.
static DISPATCHES: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// The dispatches recorded so far by this process.
pub fn dispatches_recorded() -> u64 {
    DISPATCHES.load(std::sync::atomic::Ordering::Relaxed)
}

/// Workgroup grid for `groups` groups: x ≤ 65535, x·y ≥ groups. Kernels recover the linear
/// index as gid.x + gid.y·(nwg.x·WG) and bounds-check it.
pub fn fold_groups(groups: u32) -> (u32, u32) {
    const MAX: u32 = 65535;
    if groups <= MAX {
        (groups, 1)
    } else {
        (MAX, groups.div_ceil(MAX))
    }
}

/// A kernel with its bind groups over the two parities of the particle arrays (the cell sort
/// gathers from one into the other every step).
pub struct ParityKernel {
    kernel: Kernel,
    bind: [wgpu::BindGroup; 2],
}

impl ParityKernel {
    /// Entry point `entry` of `module`, bound to `buffers(p)` for parity p = 0 and 1.
    pub fn new<R: Resolve>(
        device: &wgpu::Device,
        module: &ShaderModule,
        entry: &str,
        buffers: impl Fn(usize) -> R,
    ) -> Result<Self> {
        let kernel = module.kernel(device, entry)?;
        let bind = [
            kernel.bind(device, &buffers(0))?,
            kernel.bind(device, &buffers(1))?,
        ];
        Ok(Self { kernel, bind })
    }

    /// Binds the kernel to `buffers(p)` again (one of them replaced by a larger one).
    pub fn rebind<R: Resolve>(
        &mut self,
        device: &wgpu::Device,
        buffers: impl Fn(usize) -> R,
    ) -> Result<()> {
        self.bind = [
            self.kernel.bind(device, &buffers(0))?,
            self.kernel.bind(device, &buffers(1))?,
        ];
        Ok(())
    }

    /// `invocations` invocations on the arrays of parity `p`.
    pub fn dispatch(&self, pass: &mut wgpu::ComputePass<'_>, p: usize, invocations: u32) {
        self.kernel.dispatch(pass, &self.bind[p], invocations);
    }

    /// `groups` workgroups on the arrays of parity `p`.
    pub fn dispatch_groups(&self, pass: &mut wgpu::ComputePass<'_>, p: usize, groups: u32) {
        self.kernel.dispatch_groups(pass, &self.bind[p], groups);
    }

    /// The pipeline and the bind group of parity `p` (for an indirect dispatch).
    pub fn bound(&self, p: usize) -> (&wgpu::ComputePipeline, &wgpu::BindGroup) {
        (&self.kernel.pipeline, &self.bind[p])
    }
}

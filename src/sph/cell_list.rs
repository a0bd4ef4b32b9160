//! The cell-list sort of every step (shaders/cell_list.wgsl + shaders/prefix_scan.wgsl):
//! key + histogram, exclusive scan of the slot counts, scatter, deterministic rank, reorder.

use anyhow::Result;

use super::buffers::ParticleBuffers;
use super::shader::PARTICLE_ID;
use crate::gpu::kernel::{ParityKernel, Resolve, ShaderModule};
use crate::gpu::shader::Shader;
use crate::gpu::Kernel;

pub const SHADER: Shader = Shader {
    name: "cell_list",
    source: include_str!("../../shaders/cell_list.wgsl"),
    libs: &[PARTICLE_ID],
};

/// The exclusive scan of the slot counts (shaders/prefix_scan.wgsl).
pub const SCAN_SHADER: Shader = Shader {
    name: "prefix_scan",
    source: include_str!("../../shaders/prefix_scan.wgsl"),
    libs: &[],
};

/// One level of the scan: its data and the block sums it writes (and later adds back).
struct ScanLevel<'a> {
    data: &'a wgpu::Buffer,
    block_sums: &'a wgpu::Buffer,
}

impl Resolve for ScanLevel<'_> {
    fn resolve(&self, name: &str) -> Result<&wgpu::Buffer> {
        match name {
            "data" => Ok(self.data),
            "block_sums" => Ok(self.block_sums),
            _ => anyhow::bail!("no buffer of that name in a scan level"),
        }
    }
}

pub struct CellList {
    cell_key: ParityKernel,
    scatter: ParityKernel,
    rank_in_cell: ParityKernel,
    reorder: ParityKernel,
    reorder_motion: ParityKernel,
    reorder_energy: Option<ParityKernel>,
    scan_blocks: Kernel,
    scan_add: Kernel,
    /// (scan_blocks, scan_add) bind group of each level.
    bind_scan: Vec<(wgpu::BindGroup, Option<wgpu::BindGroup>)>,
    scan_sizes: Vec<u32>,
    n: u32,
}

impl CellList {
    pub fn new(
        device: &wgpu::Device,
        cells: &ShaderModule,
        scan: &ShaderModule,
        b: &ParticleBuffers,
        energy: bool,
    ) -> Result<Self> {
        let parity = |entry: &str| ParityKernel::new(device, cells, entry, |p| b.at(p));
        let reorder_energy = energy.then(|| parity("reorder_energy")).transpose()?;
        let scan_blocks = scan.kernel(device, "scan_blocks")?;
        let scan_add = scan.kernel(device, "scan_add")?;
        let mut levels: Vec<&wgpu::Buffer> = vec![&b.cell_start];
        levels.extend(b.scan_levels.iter());
        let mut bind_scan = Vec::new();
        for l in 0..b.scan_sizes.len() - 1 {
            let level = ScanLevel {
                data: levels[l],
                block_sums: levels[l + 1],
            };
            let add = if l + 2 < levels.len() {
                Some(scan_add.bind(device, &level)?)
            } else {
                None
            };
            bind_scan.push((scan_blocks.bind(device, &level)?, add));
        }
        Ok(Self {
            cell_key: parity("cell_key")?,
            scatter: parity("scatter")?,
            rank_in_cell: parity("rank_in_cell")?,
            reorder: parity("reorder")?,
            reorder_motion: parity("reorder_motion")?,
            reorder_energy,
            scan_blocks,
            scan_add,
            bind_scan,
            scan_sizes: b.scan_sizes.clone(),
            n: b.n,
        })
    }

    /// Zeroes the slot histogram; must be recorded outside a compute pass, before `encode`.
    pub fn clear(&self, encoder: &mut wgpu::CommandEncoder, b: &ParticleBuffers) {
        encoder.clear_buffer(&b.cell_start, 0, None);
    }

    /// Sorts the arrays of parity `p` into parity `1 - p` (and `rate` into `rate_sorted`).
    /// The whole sort of parity `p`'s particles: [`CellList::encode_key`], `encode_scan`,
    /// `encode_scatter`, `encode_reorder`, which `Solver::record_step` times one by one.
    pub fn encode(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.encode_key(pass, p);
        self.encode_scan(pass);
        self.encode_scatter(pass, p);
        self.encode_reorder(pass, p);
    }

    /// Each particle's cell key, counted into its slot.
    pub fn encode_key(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.cell_key.dispatch(pass, p, self.n);
    }

    /// Each particle's place in the sorted order: after the slots, then by code word (kind,
    /// then id) within its slot.
    pub fn encode_scatter(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.scatter.dispatch(pass, p, self.n);
        self.rank_in_cell.dispatch(pass, p, self.n);
    }

    /// The particle arrays of parity `p` copied into the other parity in sorted order.
    pub fn encode_reorder(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.reorder.dispatch(pass, p, self.n);
        self.reorder_motion.dispatch(pass, p, self.n);
        if let Some(k) = &self.reorder_energy {
            k.dispatch(pass, p, self.n);
        }
    }

    /// The prefix sum of the slot counts (the slots' starts).
    pub fn encode_scan(&self, pass: &mut wgpu::ComputePass<'_>) {
        let per_group = 2 * crate::gpu::shader::WORKGROUP_SIZE;
        for (l, (blocks, _)) in self.bind_scan.iter().enumerate() {
            self.scan_blocks
                .dispatch_groups(pass, blocks, self.scan_sizes[l].div_ceil(per_group));
        }
        for (l, (_, add)) in self.bind_scan.iter().enumerate().rev() {
            if let Some(add) = add {
                self.scan_add.dispatch(pass, add, self.scan_sizes[l]);
            }
        }
    }
}

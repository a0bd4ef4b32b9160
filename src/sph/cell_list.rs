//! The cell-list sort of every step (shaders/cell_list.wgsl + shaders/prefix_scan.wgsl):
//! key + histogram, exclusive scan of the slot counts, scatter, deterministic rank, reorder.

use anyhow::Result;

use super::buffers::ParticleBuffers;
use crate::gpu::kernel::ShaderModule;
use crate::gpu::Kernel;

pub struct CellList {
    cell_key: Kernel,
    scatter: Kernel,
    rank_in_cell: Kernel,
    reorder: Kernel,
    reorder_energy: Option<(Kernel, [wgpu::BindGroup; 2])>,
    scan_blocks: Kernel,
    scan_add: Kernel,
    bind_key: [wgpu::BindGroup; 2],
    bind_scatter: wgpu::BindGroup,
    bind_rank: wgpu::BindGroup,
    bind_reorder: [wgpu::BindGroup; 2],
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
        let cell_key = cells.kernel(device, "cell_key")?;
        let reorder_energy = if energy {
            let k = cells.kernel(device, "reorder_energy")?;
            let bufs = |p: usize| {
                [
                    (0, &b.params),
                    (8, &b.local_perm),
                    (18, &b.energy[p]),
                    (19, &b.energy[1 - p]),
                ]
            };
            let binds = [k.bind(device, &bufs(0))?, k.bind(device, &bufs(1))?];
            Some((k, binds))
        } else {
            None
        };
        let scatter = cells.kernel(device, "scatter")?;
        let rank_in_cell = cells.kernel(device, "rank_in_cell")?;
        let reorder = cells.kernel(device, "reorder")?;
        let scan_blocks = scan.kernel(device, "scan_blocks")?;
        let scan_add = scan.kernel(device, "scan_add")?;
        let common = |p: usize| {
            vec![
                (0, &b.params),
                (1, &b.pos[p]),
                (2, &b.code[p]),
                (3, &b.keys),
                (4, &b.local_perm),
                (5, &b.cell_start),
                (6, &b.cell_start),
                (7, &b.provisional),
                (8, &b.local_perm),
            ]
        };
        let reorder_bufs = |p: usize| {
            let q = 1 - p;
            let mut v = common(p);
            v.extend([
                (10, &b.pos[p]),
                (11, &b.velrho[p]),
                (12, &b.rate),
                (13, &b.code[p]),
                (14, &b.pos[q]),
                (15, &b.velrho[q]),
                (16, &b.rate_sorted),
                (17, &b.code[q]),
            ]);
            v
        };
        let bind_key = [
            cell_key.bind(device, &common(0))?,
            cell_key.bind(device, &common(1))?,
        ];
        let bind_scatter = scatter.bind(device, &common(0))?;
        let bind_rank = rank_in_cell.bind(device, &common(0))?;
        let bind_reorder = [
            reorder.bind(device, &reorder_bufs(0))?,
            reorder.bind(device, &reorder_bufs(1))?,
        ];
        let mut levels: Vec<&wgpu::Buffer> = vec![&b.cell_start];
        levels.extend(b.scan_levels.iter());
        let mut bind_scan = Vec::new();
        for l in 0..b.scan_sizes.len() - 1 {
            let bufs = [(1, levels[l]), (2, levels[l + 1])];
            let add = if l + 2 < levels.len() {
                Some(scan_add.bind(device, &bufs)?)
            } else {
                None
            };
            bind_scan.push((scan_blocks.bind(device, &bufs)?, add));
        }
        Ok(Self {
            cell_key,
            scatter,
            rank_in_cell,
            reorder,
            reorder_energy,
            scan_blocks,
            scan_add,
            bind_key,
            bind_scatter,
            bind_rank,
            bind_reorder,
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
        self.encode_scatter(pass);
        self.encode_reorder(pass, p);
    }

    /// Each particle's cell key, counted into its slot.
    pub fn encode_key(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.cell_key.dispatch(pass, &self.bind_key[p], self.n);
    }

    /// Each particle's place in the sorted order: after the slots, then within its cell.
    pub fn encode_scatter(&self, pass: &mut wgpu::ComputePass<'_>) {
        self.scatter.dispatch(pass, &self.bind_scatter, self.n);
        self.rank_in_cell.dispatch(pass, &self.bind_rank, self.n);
    }

    /// The particle arrays of parity `p` copied into the other parity in sorted order.
    pub fn encode_reorder(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.reorder.dispatch(pass, &self.bind_reorder[p], self.n);
        if let Some((k, bind)) = &self.reorder_energy {
            k.dispatch(pass, &bind[p], self.n);
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

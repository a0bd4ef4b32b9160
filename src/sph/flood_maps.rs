//! Flood maps on the GPU (shaders/flood_maps.wgsl): each sample finds the surface over every
//! cell of the plan grid and updates the cells' records; only the records are read back, at
//! the end of a run or for a checkpoint.

use anyhow::{ensure, Result};

use super::buffers::ParticleBuffers;
use super::shader::{NEIGHBOURS, WATER_FRACTION};
use crate::gpu::buffers::{read, storage, storage_init};
use crate::gpu::kernel::{ParityKernel, ShaderModule};
use crate::gpu::shader::Shader;
use crate::layout::{MapCell, MapGrid};
use crate::scenario::FloodMaps;

pub const SHADER: Shader = Shader {
    name: "flood_maps",
    source: include_str!("../../shaders/flood_maps.wgsl"),
    libs: &[NEIGHBOURS, WATER_FRACTION],
};

/// The GPU's view of `maps`: its grid in domain coordinates (from `origin`, the domain's min
/// corner), at time 0.
pub fn map_grid(maps: &FloodMaps, origin: [f64; 3]) -> MapGrid {
    MapGrid {
        origin: [0, 1].map(|a| (maps.first_centre[a] - origin[a]) as f32),
        cell: maps.cell as f32,
        nx: maps.nx as u32,
        ny: maps.ny as u32,
        wet_depth: maps.wet_depth as f32,
        time: 0.0,
        pad: 0,
    }
}

pub struct FloodMapPass {
    search: ParityKernel,
    sample: ParityKernel,
    grid: MapGrid,
    grid_buffer: wgpu::Buffer,
    found: wgpu::Buffer,
    cells: wgpu::Buffer,
    n_particles: u32,
}

impl FloodMapPass {
    pub fn new(
        device: &wgpu::Device,
        module: &ShaderModule,
        b: &ParticleBuffers,
        maps: &FloodMaps,
        origin: [f64; 3],
    ) -> Result<Self> {
        let grid = map_grid(maps, origin);
        let n = maps.cells();
        let grid_buffer = storage_init(device, "map grid", &[grid]);
        let ground: Vec<f32> = (maps.ground.iter())
            .map(|z| (z - origin[2]) as f32)
            .collect();
        let ground = storage_init(device, "map ground", &ground);
        let found = storage(device, "map surface found", 4 * n as u64);
        let cells = storage_init(device, "map cells", &vec![MapCell::UNSEEN; n]);
        let kernel = |entry| {
            ParityKernel::new(device, module, entry, |p| {
                (b.at(p))
                    .with("map_grid", &grid_buffer)
                    .with("map_ground", &ground)
                    .with("map_found", &found)
                    .with("map_cells", &cells)
            })
        };
        Ok(Self {
            search: kernel("map_surface_search")?,
            sample: kernel("map_sample")?,
            grid,
            grid_buffer,
            found,
            cells,
            n_particles: b.n,
        })
    }

    fn cell_count(&self) -> usize {
        (self.grid.nx * self.grid.ny) as usize
    }

    /// Records a sample at `time` on the arrays of parity `p` (the cell list current).
    pub fn encode(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        p: usize,
        time: f64,
    ) {
        let grid = MapGrid {
            time: time as f32,
            ..self.grid
        };
        queue.write_buffer(&self.grid_buffer, 0, bytemuck::bytes_of(&grid));
        encoder.clear_buffer(&self.found, 0, None);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("flood maps"),
            timestamp_writes: None,
        });
        // The surface over every cell first: `map_sample` interpolates where it was found.
        self.search.dispatch(&mut pass, p, self.n_particles);
        self.sample.dispatch(&mut pass, p, self.cell_count() as u32);
    }

    /// The cells' records, row by row from the south.
    pub fn read(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Vec<MapCell>> {
        read(device, queue, &self.cells, self.cell_count())
    }

    /// Puts back the records of a checkpoint.
    pub fn restore(&self, queue: &wgpu::Queue, cells: &[MapCell]) -> Result<()> {
        ensure!(
            cells.len() == self.cell_count(),
            "the checkpoint's maps have {} cells, the case's {}",
            cells.len(),
            self.cell_count()
        );
        queue.write_buffer(&self.cells, 0, bytemuck::cast_slice(cells));
        Ok(())
    }

    /// GPU memory of the pass's buffers, in bytes.
    pub fn bytes(&self) -> u64 {
        // The records, the search's words and the ground's.
        self.cells.size() + self.found.size() + 4 * self.cell_count() as u64
    }
}

//! Velocity inlets (shaders/inlet.wgsl): after the predictor, every inlet particle's place,
//! velocity and kind at the time the step moves to. The tables (one entry per inlet and one
//! per column of an inlet's plane) are uploaded once; a particle's layer and column follow from
//! its id, so inlets add no per-particle memory.

use anyhow::{ensure, Result};

use super::buffers::ParticleBuffers;
use super::grid::Grid;
use crate::gpu::buffers::storage_init;
use crate::gpu::kernel::{ParityKernel, ShaderModule};
use crate::layout::{pack_block, InletDef, Pos};
use crate::scenario::Scenario;

pub struct Inlets {
    flow: ParityKernel,
    n: u32,
}

/// The GPU tables of the scenario's inlets: their definitions and their columns' points (as
/// positions in the grid's blocks).
pub fn inlet_tables(sc: &Scenario, grid: &Grid) -> (Vec<InletDef>, Vec<Pos>) {
    let mut defs = Vec::with_capacity(sc.inlets.len());
    let mut columns = Vec::new();
    for inlet in &sc.inlets {
        defs.push(InletDef {
            normal: inlet.normal.map(|c| c as f32),
            speed: inlet.speed as f32,
            thickness: inlet.thickness as f32,
            spacing: inlet.spacing as f32,
            first_id: inlet.particles.start as u32,
            n_columns: inlet.columns.len() as u32,
            first_column: columns.len() as u32,
            n_particles: inlet.particles.len() as u32,
            pad: [0; 2],
        });
        columns.extend(inlet.columns.iter().map(|&c| {
            let (off, b) = grid.to_block(c);
            Pos {
                off,
                block: pack_block(b),
            }
        }));
    }
    (defs, columns)
}

impl Inlets {
    pub fn new(
        device: &wgpu::Device,
        module: &ShaderModule,
        b: &ParticleBuffers,
        sc: &Scenario,
        grid: &Grid,
    ) -> Result<Self> {
        ensure!(!sc.inlets.is_empty(), "the case has no inlets");
        let (defs, columns) = inlet_tables(sc, grid);
        let defs = storage_init(device, "inlets", &defs);
        let columns = storage_init(device, "inlet columns", &columns);
        let flow = ParityKernel::new(device, module, "inlet_flow", |p| {
            vec![
                (0, &b.params),
                (1, &b.pos[p]),
                (2, &b.velrho[p]),
                (3, &b.code[p]),
                (4, &b.state),
                (5, &defs),
                (6, &columns),
            ]
        })?;
        Ok(Self { flow, n: b.n })
    }

    /// Places the inlet particles of the arrays of parity `p` (after the predictor).
    pub fn encode(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.flow.dispatch(pass, p, self.n);
    }
}

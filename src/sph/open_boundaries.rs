//! Open boundaries (shaders/open_boundaries.wgsl), after the predictor: velocity inlets place
//! every inlet particle (its place, velocity and kind at the time the step moves to), outlets
//! remove the fluid that entered them; after the sort, buffers with `pressure =
//! "extrapolated"` take their pressure from the fluid. The tables (one entry per inlet, one
//! per column of an inlet's plane, one per outlet) are uploaded once; an inlet particle's
//! layer and column follow from its id, so inlets add no per-particle memory.

use anyhow::{ensure, Result};

use super::buffers::ParticleBuffers;
use super::shader::PARTICLE_ID;
use super::shader::{FLUID_AT, MLS, NEIGHBOURS};
use crate::gpu::buffers::storage_init;
use crate::gpu::kernel::{ParityKernel, ShaderModule};
use crate::gpu::shader::Shader;
use crate::grid::Grid;

pub const SHADER: Shader = Shader {
    name: "open_boundaries",
    source: include_str!("../../shaders/open_boundaries.wgsl"),
    libs: &[PARTICLE_ID, NEIGHBOURS, MLS, FLUID_AT],
};
use crate::layout::{
    pack_block, FlowWindow, InflowSegment, InletDef, OutletDef, Pos, INLET_EXTRAPOLATED,
    INLET_HYDROSTATIC, INLET_ZERO,
};
use crate::scenario::{InletPressure, Scenario};

pub struct OpenBoundaries {
    inlet_flow: Option<ParityKernel>,
    outlet_drain: Option<ParityKernel>,
    /// Extrapolated buffer pressures, when an inlet has them.
    inlet_pressure: Option<ParityKernel>,
    n: u32,
}

/// The GPU tables of the scenario's inlets: their definitions and their columns' points (as
/// positions in the grid's blocks).
pub fn inlet_tables(sc: &Scenario, grid: &Grid) -> InletTables {
    let mut defs = Vec::with_capacity(sc.inlets.len());
    let mut columns = Vec::new();
    let mut segments = Vec::new();
    let mut windows = Vec::new();
    for inlet in &sc.inlets {
        let inflow = inlet.inflow.segments();
        let level = inlet.level.as_ref();
        let first_window = windows.len() as u32;
        let first_level = (segments.len() + inflow.len()) as u32;
        if let Some(l) = level {
            windows.extend(l.windows.iter().map(|w| FlowWindow {
                column: w.column as u32,
                start: w.start as f32,
                end: w.end.min(f32::MAX as f64) as f32,
                before: w.before as f32,
                after: w.after.min(f32::MAX as f64) as f32,
                pad: [0; 3],
            }));
        }
        defs.push(InletDef {
            normal: inlet.normal.map(|c| c as f32),
            first_segment: segments.len() as u32,
            thickness: inlet.thickness as f32,
            spacing: inlet.spacing as f32,
            first_id: inlet.particles.start as u32,
            n_columns: inlet.columns.len() as u32,
            first_column: columns.len() as u32,
            n_segments: inflow.len() as u32,
            pad: [0; 2],
            surface: match inlet.pressure {
                InletPressure::Hydrostatic { surface } => {
                    [0, 1, 2].map(|a| (surface[a] - grid.origin[a]) as f32)
                }
                _ => [0.0; 3],
            },
            pressure: match inlet.pressure {
                InletPressure::Zero => INLET_ZERO,
                InletPressure::Hydrostatic { .. } => INLET_HYDROSTATIC,
                InletPressure::Extrapolated => INLET_EXTRAPOLATED,
            },
            first_window,
            n_windows: windows.len() as u32 - first_window,
            first_level,
            n_level: level.map_or(0, |l| l.level.segments().len() as u32),
        });
        columns.extend(inlet.columns.iter().map(|&c| {
            let (off, b) = grid.to_block(c);
            Pos {
                off,
                block: pack_block(b),
            }
        }));
        segments.extend(inflow.iter().map(|s| InflowSegment {
            t: s.t as f32,
            distance: s.distance as f32,
            pad: [0; 2],
            speed: s.speed.map(|c| c as f32),
            moved: s.distance_coefficients().map(|c| c as f32),
        }));
        // A level's pieces: its height from the grid's origin in `speed` (their integral is
        // never read).
        if let Some(l) = level {
            let origin: f64 = (0..3).map(|a| l.up[a] * grid.origin[a]).sum();
            segments.extend(l.level.segments().iter().map(|s| InflowSegment {
                t: s.t as f32,
                distance: 0.0,
                pad: [0; 2],
                speed: [s.speed[0] - origin, s.speed[1], s.speed[2], s.speed[3]].map(|c| c as f32),
                moved: [0.0; 4],
            }));
        }
    }
    InletTables {
        defs,
        columns,
        segments,
        windows,
    }
}

/// The GPU tables of a scenario's inlets ([`inlet_tables`]).
pub struct InletTables {
    pub defs: Vec<InletDef>,
    /// Each column's point on its inlet's plane, as a position in the grid's blocks.
    pub columns: Vec<Pos>,
    /// The inlets' hydrographs, piece after piece (an inlet's inflow, then its level).
    pub segments: Vec<InflowSegment>,
    /// The level-driven inlets' windows.
    pub windows: Vec<FlowWindow>,
}

/// The outlets' boxes in domain coordinates (from the grid's origin); in 2D z spans [−1, 1].
pub fn outlet_table(sc: &Scenario, grid: &Grid) -> Vec<OutletDef> {
    let dim = sc.physics.dim as usize;
    sc.outlets
        .iter()
        .map(|o| {
            let rel = |x: [f64; 3], z: f32| {
                [0, 1, 2].map(|a| {
                    if a < dim {
                        (x[a] - grid.origin[a]) as f32
                    } else {
                        z
                    }
                })
            };
            OutletDef {
                min: rel(o.min, -1.0),
                pad0: 0,
                max: rel(o.max, 1.0),
                pad1: 0,
            }
        })
        .collect()
}

impl OpenBoundaries {
    pub fn new(
        device: &wgpu::Device,
        module: &ShaderModule,
        b: &ParticleBuffers,
        sc: &Scenario,
        grid: &Grid,
    ) -> Result<Self> {
        ensure!(
            !sc.inlets.is_empty() || !sc.outlets.is_empty(),
            "the case has no inlets or outlets"
        );
        let mut tables = inlet_tables(sc, grid);
        let mut outlets = outlet_table(sc, grid);
        // A binding cannot be empty.
        if tables.defs.is_empty() {
            tables.defs.push(InletDef::default());
            tables.columns.push(Pos::default());
            tables.segments.push(InflowSegment::default());
        }
        if tables.windows.is_empty() {
            tables.windows.push(FlowWindow::default());
        }
        if outlets.is_empty() {
            outlets.push(OutletDef::default());
        }
        let defs = storage_init(device, "inlets", &tables.defs);
        let columns = storage_init(device, "inlet columns", &tables.columns);
        let segments = storage_init(device, "inflow segments", &tables.segments);
        let windows = storage_init(device, "flow windows", &tables.windows);
        let outlets = storage_init(device, "outlets", &outlets);
        let bufs = |p: usize| {
            b.at(p)
                .with("inlets", &defs)
                .with("inlet_columns", &columns)
                .with("inflow_segments", &segments)
                .with("flow_windows", &windows)
                .with("outlets", &outlets)
        };
        let kernel = |entry: &str| ParityKernel::new(device, module, entry, bufs);
        let extrapolated = sc
            .inlets
            .iter()
            .any(|i| i.pressure == InletPressure::Extrapolated);
        Ok(Self {
            inlet_flow: (!sc.inlets.is_empty())
                .then(|| kernel("inlet_flow"))
                .transpose()?,
            outlet_drain: (!sc.outlets.is_empty())
                .then(|| kernel("outlet_drain"))
                .transpose()?,
            inlet_pressure: extrapolated.then(|| kernel("inlet_pressure")).transpose()?,
            n: b.n,
        })
    }

    /// Places the inlet particles, then drains the outlets, on the arrays of parity `p` (after
    /// the predictor).
    pub fn encode(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        for k in [&self.inlet_flow, &self.outlet_drain].into_iter().flatten() {
            k.dispatch(pass, p, self.n);
        }
    }

    /// Takes the extrapolated buffers' pressures from the fluid, on the sorted arrays of parity
    /// `p` (after the cell-list sort, before the interaction).
    pub fn encode_pressure(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        if let Some(k) = &self.inlet_pressure {
            k.dispatch(pass, p, self.n);
        }
    }
}

//! What a run needs to continue exactly where it was: the particle arrays of the current parity
//! in their GPU (cell) order, the last rates (the predictor uses them), the time-step state, the
//! host clock, the density filter's last step, the elastic solids' stress and the bodies' host
//! state. Restoring these into
//! a solver built from the same case continues bit-identically on the same adapter: every other
//! GPU buffer (cell starts, sorted rates, ghost values, body partials) is rebuilt by the
//! step before it is read.
//!
//! The file format is the checkpoint's business (`crate::checkpoint`); this module only gathers
//! and scatters.

use anyhow::{bail, Context, Result};

use super::Solver;
use crate::gpu::buffers::read;
use crate::layout::{Pos, SimState, SolidState};

/// The state of a [`Solver`] between two steps.
#[derive(Clone, Debug, PartialEq)]
pub struct SolverState {
    /// Which of the two particle-array parities is current.
    pub parity: u32,
    /// Host clock: the GPU's f32 clock counts from here.
    pub t_base: f64,
    /// Steps taken (host count).
    pub steps: u64,
    /// dt of the warm-up evaluation (the collapse check compares against it).
    pub initial_dt: f32,
    pub sim: SimState,
    /// The density peaks of the probe interval so far (a run stopped between two probe times
    /// goes on with them).
    pub peaks: super::DensityPeaks,
    /// `state.steps` at the density filter's last application (0 without a filter).
    pub filter_last: u32,
    pub pos: Vec<Pos>,
    /// (v, ρ)
    pub velrho: Vec<[f32; 4]>,
    /// kind << 28 | id
    pub code: Vec<u32>,
    /// (dv/dt, dρ/dt) of the last evaluation.
    pub rate: Vec<[f32; 4]>,
    /// (e, de/dt), with the energy equation on.
    pub energy: Option<Vec<[f32; 2]>>,
    /// τ, body and last dτ/dt of every solid particle (id order), with updated-Lagrangian
    /// solids.
    pub solid: Option<Vec<SolidState>>,
    /// [`crate::body::BodySet::save`], empty without bodies.
    pub bodies: Vec<f64>,
    /// The flood maps' cell records (`[maps]`), when the case has maps.
    pub maps: Option<Vec<crate::layout::MapCell>>,
}

impl Solver {
    /// Reads back everything [`restore_state`](Self::restore_state) needs. Waits for the GPU.
    pub fn save_state(&self) -> Result<SolverState> {
        let (pos, velrho, code) = self.read_raw()?;
        let n = pos.len();
        let energy = if self.energy {
            Some(read(
                &self.device,
                &self.queue,
                &self.buffers.energy[self.parity],
                n,
            )?)
        } else {
            None
        };
        let filter_last = match &self.passes.density_filter {
            Some(f) => f.last_applied(&self.device, &self.queue)?,
            None => 0,
        };
        Ok(SolverState {
            parity: self.parity as u32,
            t_base: self.t_base,
            steps: self.steps,
            initial_dt: self.initial_dt,
            sim: self.state,
            peaks: self.peaks,
            filter_last,
            pos,
            velrho,
            code,
            rate: self.read_rates().context("reading rates")?,
            energy,
            solid: match &self.passes.elastic {
                Some(_) => Some(self.read_solid()?),
                None => None,
            },
            bodies: self.bodies().map(|b| b.save()).unwrap_or_default(),
            maps: self.map_cells()?,
        })
    }

    /// Puts a saved state back into this solver, which must have been built from the same case
    /// (same particle count, energy equation, bodies).
    pub fn restore_state(&mut self, s: &SolverState) -> Result<()> {
        let n = self.buffers.n as usize;
        let lens = [
            ("positions", s.pos.len()),
            ("velocities", s.velrho.len()),
            ("rates", s.rate.len()),
        ];
        for (what, len) in lens {
            if len != n {
                bail!("the saved state has {len} {what}; this case has {n} particles");
            }
        }
        if s.code.len() != n * self.ids.words() {
            bail!(
                "the saved state has {} code words for {n} particles; this case takes {} a \
                 particle (particles.id_low_bits differs?)",
                s.code.len(),
                self.ids.words()
            );
        }
        if s.energy.is_some() != self.energy {
            bail!("the saved state and this case disagree on the energy equation");
        }
        if s.parity > 1 {
            bail!("the saved state has parity {}", s.parity);
        }
        let p = s.parity as usize;
        let q = &self.queue;
        q.write_buffer(&self.buffers.pos[p], 0, bytemuck::cast_slice(&s.pos));
        q.write_buffer(&self.buffers.velrho[p], 0, bytemuck::cast_slice(&s.velrho));
        q.write_buffer(&self.buffers.code[p], 0, bytemuck::cast_slice(&s.code));
        q.write_buffer(&self.buffers.rate, 0, bytemuck::cast_slice(&s.rate));
        if let Some(e) = &s.energy {
            if e.len() != n {
                bail!("the saved state has {} energies for {n} particles", e.len());
            }
            q.write_buffer(&self.buffers.energy[p], 0, bytemuck::cast_slice(e));
        }
        if s.solid.is_some() != self.passes.elastic.is_some() {
            bail!("the saved state and this case disagree on elastic solids");
        }
        if let Some(solid) = &s.solid {
            let n_solid = self.n_solid as usize;
            if solid.len() != n_solid {
                bail!(
                    "the saved state has {} solid states for {n_solid} solid particles",
                    solid.len()
                );
            }
            q.write_buffer(&self.buffers.solid, 0, bytemuck::cast_slice(solid));
        }
        q.write_buffer(&self.buffers.state, 0, bytemuck::bytes_of(&s.sim));
        if let Some(f) = &self.passes.density_filter {
            f.set_last_applied(q, s.filter_last);
        }
        match (&s.maps, &self.passes.flood_maps) {
            (Some(cells), _) => self.restore_map_cells(cells)?,
            (None, Some(_)) => bail!("the saved state has no flood maps; this case has [maps]"),
            (None, None) => {}
        }
        match &mut self.bodies {
            Some(host) => host.set.restore(&s.bodies)?,
            None if !s.bodies.is_empty() => bail!("the saved state has bodies; this case has none"),
            None => {}
        }
        self.parity = p;
        // The restored arrays are in the saved order, not the warm-up's.
        self.index_bodies();
        self.t_base = s.t_base;
        self.steps = s.steps;
        self.initial_dt = s.initial_dt;
        self.state = s.sim;
        self.peaks = s.peaks;
        self.faults.check()
    }
}

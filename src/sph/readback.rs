//! Reading the particles back from the GPU: raw arrays in cell order, and the particles in id
//! order and world coordinates with their pressure from the one equation of state.

use anyhow::{bail, Context, Result};

use super::{Particles, RawParticles, Solver};
use crate::eos::{solid_pressure, Tait};
use crate::gpu::buffers::read;
use crate::layout::{unpack_block, IdSplit, SolidState, KIND_SHIFT};
use crate::scenario::Kind;

impl Solver {
    /// How the particles' ids are stored (the code buffer's words: [`Solver::read_raw`]).
    pub fn ids(&self) -> IdSplit {
        self.ids
    }

    /// Raw arrays of the current parity, in GPU (cell) order.
    pub fn read_raw(&self) -> Result<RawParticles> {
        let n = self.buffers.n as usize;
        let words = n * self.ids.words();
        let p = self.parity;
        Ok((
            read(&self.device, &self.queue, &self.buffers.pos[p], n)
                .context("reading positions")?,
            read(&self.device, &self.queue, &self.buffers.velrho[p], n)
                .context("reading velocities")?,
            read(&self.device, &self.queue, &self.buffers.code[p], words)
                .context("reading codes")?,
        ))
    }

    /// Rates (dv/dt, dρ/dt) of the last evaluation, in GPU order.
    pub fn read_rates(&self) -> Result<Vec<[f32; 4]>> {
        read(
            &self.device,
            &self.queue,
            &self.buffers.rate,
            self.buffers.n as usize,
        )
    }

    /// Slot starts of the last sort (slots + 3 entries).
    pub fn read_cell_start(&self) -> Result<Vec<u32>> {
        read(
            &self.device,
            &self.queue,
            &self.buffers.cell_start,
            self.grid.slots as usize + 3,
        )
    }

    /// The solid state (τ, body, last dτ/dt, interface pressure, material) of every solid
    /// particle, in id order from `solid_id_base` (of a total-Lagrangian solid only its body
    /// and material are in use).
    pub fn read_solid(&self) -> Result<Vec<SolidState>> {
        if self.passes.elastic.is_none() && self.passes.total_lagrangian.is_none() {
            bail!("the case has no solids");
        }
        read(
            &self.device,
            &self.queue,
            &self.buffers.solid,
            self.n_solid as usize,
        )
    }

    /// All particles in world coordinates, sorted by id.
    pub fn read_particles(&self) -> Result<Particles> {
        let (pos, velrho, code) = self.read_raw()?;
        let energy: Option<Vec<[f32; 2]>> = if self.energy {
            Some(read(
                &self.device,
                &self.queue,
                &self.buffers.energy[self.parity],
                pos.len(),
            )?)
        } else {
            None
        };
        // The solid state (τ, material) of either formulation.
        let solid = if self.passes.elastic.is_some() || self.passes.total_lagrangian.is_some() {
            Some(self.read_solid()?)
        } else {
            None
        };
        let tl = match &self.passes.total_lagrangian {
            Some(t) => Some(t.cauchy_stress(&self.device, &self.queue, self.parity)?),
            None => None,
        };
        let n = pos.len();
        let id_of = |i: usize| self.ids.id_at(&code, n, i);
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_unstable_by_key(|&i| id_of(i));
        let eos = Tait {
            b: self.params.tait_b as f64,
            rho0: self.params.rho0 as f64,
            gamma: self.params.gamma as f64,
        };
        let mut out = Particles::default();
        for i in order {
            out.pos
                .push(self.grid.to_world(pos[i].off, unpack_block(pos[i].block)));
            let v = velrho[i];
            out.vel.push([v[0], v[1], v[2]]);
            out.rho.push(v[3]);
            let kind = code[i] >> KIND_SHIFT;
            let id = id_of(i);
            let solid_kind = Kind::code_is_solid(kind);
            // τ and material of the particle (zeros for the others), when the case has solids.
            let state = solid.as_ref().map(|s| {
                if !solid_kind {
                    return Default::default();
                }
                s[(id - self.params.solid_id_base) as usize]
            });
            let mut tau = state.map(|s| {
                let (a, b) = (s.tau_a, s.tau_b);
                [a[0], a[1], a[2], a[3], b[0], b[1]]
            });
            let mat = state.map_or_else(Default::default, |s| {
                self.params.solid_materials[s.material as usize]
            });
            let tl_stress = tl.as_ref().and_then(|(first, stress)| {
                stress
                    .get(id.checked_sub(*first)? as usize)
                    .filter(|_| solid_kind)
            });
            if let Some(c) = tl_stress {
                // Total-Lagrangian: ρ = ρs/J, p = −tr σ/3 and τ = σ + p I.
                let p = -(c.sigma[0] + c.sigma[1] + c.sigma[2]) / 3.0;
                *out.rho.last_mut().expect("pushed above") = (mat.rho0 as f64 / c.j) as f32;
                out.pressure.push(p as f32);
                let mut t = c.sigma;
                for d in &mut t[..3] {
                    *d += p;
                }
                tau = Some(t.map(|x| x as f32));
            } else if solid_kind {
                out.pressure.push(solid_pressure(mat.c2, v[3], mat.rho0));
            } else {
                out.pressure.push(eos.pressure(v[3] as f64) as f32);
            }
            out.kind.push(kind);
            out.id.push(id);
            if let Some(e) = &energy {
                out.energy.get_or_insert_with(Vec::new).push(e[i][0]);
            }
            if tl.is_some() || solid.is_some() {
                out.stress
                    .get_or_insert_with(Vec::new)
                    .push(tau.unwrap_or_default());
            }
        }
        Ok(out)
    }
}

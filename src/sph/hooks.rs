//! Test hooks (feature `test-hooks`, which the crate's own tests turn on): re-running one pass
//! on the current arrays, reading what only the tests compare, breaking the device. Not part of
//! the public API of a default build.

use anyhow::{bail, Result};

use super::Solver;
use crate::gpu::buffers::read;
use crate::layout::{SimState, SymRate};

impl Solver {
    /// Test hook: how many times a subdomain's halo packing buffer grew (`Halo::reserve`).
    pub fn halo_growths(&self) -> u32 {
        self.passes.halo.as_ref().map_or(0, |h| h.growths)
    }

    /// Test hook: destroys the device, as a driver reset or an unplugged GPU would.
    pub fn lose_device(&self) {
        self.device.destroy();
    }

    /// Test hook: re-runs the ghost interpolation (fixed ghosts and the solids' interface
    /// pressure, extrapolated inlet buffers' pressure), the interaction pass and, with solids,
    /// the elastic rates on the current arrays
    /// and returns the rates. With `poison`, `rate` (and the stress rates) are first filled with
    /// NaN so an entry the kernel skips cannot pass.
    pub fn rerun_interaction(&self, poison: bool) -> Result<Vec<[f32; 4]>> {
        if poison {
            self.fill_nan(&self.buffers.rate, 4 * self.buffers.n as usize);
            if let Some(e) = &self.passes.elastic {
                self.fill_nan(&e.stress_rate, 8 * self.n_solid as usize);
            }
        }
        self.submit_pass("interaction", |pass| {
            self.passes.ghost.encode(pass, self.parity);
            if let Some(o) = &self.passes.open_boundaries {
                o.encode_pressure(pass, self.parity);
            }
            self.passes.interaction.encode(pass, self.parity);
            if let Some(e) = &self.passes.elastic {
                e.encode_rates(pass, self.parity);
            }
            if let Some(t) = &self.passes.total_lagrangian {
                t.encode_rates(pass, self.parity);
            }
        });
        self.read_rates()
    }

    /// Test hook: dτ/dt of the last evaluation, by solid particle as `read_solid`.
    pub fn read_stress_rates(&self) -> Result<Vec<SymRate>> {
        let Some(e) = &self.passes.elastic else {
            bail!("the case has no updated-Lagrangian solids");
        };
        read(
            &self.device,
            &self.queue,
            &e.stress_rate,
            self.n_solid as usize,
        )
    }

    /// Test hook: re-runs the interaction and the body sums on the current arrays and returns
    /// each body's force and torque (about the centre of mass of the last uploaded pose): as
    /// the GPU sums them per workgroup, and as the host sums the GPU's per-particle loads
    /// (`bodies::workgroup_sums`, what a subdomain does).
    pub fn rerun_body_loads(&self) -> Result<[Vec<crate::body::Load>; 2]> {
        let Some(gpu) = &self.passes.bodies else {
            bail!("the case has no bodies");
        };
        self.submit_pass("body loads", |pass| {
            self.passes.interaction.encode(pass, self.parity);
            gpu.encode_force(pass, self.parity);
        });
        let read_all = |buffer: &wgpu::Buffer| -> Result<Vec<[f32; 4]>> {
            read(
                &self.device,
                &self.queue,
                buffer,
                buffer.size() as usize / 16,
            )
        };
        Ok([
            gpu.loads(&read_all(&gpu.partials)?),
            gpu.loads_of_particles(&read_all(&gpu.particle_loads)?),
        ])
    }

    /// Test hook: applies the density filter of the case once to the current arrays (whatever
    /// the step count). With `poison`, the filter's output buffer is first filled with NaN, so a
    /// fluid particle the filter skips gets a NaN density.
    pub fn run_density_filter(&mut self, poison: bool) -> Result<()> {
        let Some(f) = &self.passes.density_filter else {
            bail!("the case has no density filter");
        };
        if poison {
            self.fill_nan(&self.buffers.rate_sorted, 4 * self.buffers.n as usize);
        }
        self.submit_pass("density filter", |pass| {
            f.encode_now(pass, self.parity);
        });
        Ok(())
    }

    /// Test hook: takes exactly one step of `dt` (no clipping) and returns the new state.
    pub fn single_step(&mut self, dt: f32) -> Result<SimState> {
        let mut st = self.rebased_state();
        st.t_target_rel = f32::MAX;
        st.dt = dt;
        self.queue
            .write_buffer(&self.buffers.state, 0, bytemuck::bytes_of(&st));
        self.state = st;
        self.take_steps(1)?;
        Ok(self.state)
    }

    /// Test hook: de/dt of the last evaluation (energy equation on), in GPU order.
    pub fn read_energy_rates(&self) -> Result<Vec<f32>> {
        read(
            &self.device,
            &self.queue,
            &self.buffers.energy_rate,
            self.buffers.n as usize,
        )
    }

    /// Writes NaN into the first `floats` f32 of `buffer`, so that an entry a kernel skips
    /// cannot pass a comparison.
    fn fill_nan(&self, buffer: &wgpu::Buffer, floats: usize) {
        let nan = vec![f32::NAN; floats];
        self.queue
            .write_buffer(buffer, 0, bytemuck::cast_slice(&nan));
    }
}

//! The probes of a run over several ranks (issue 32), each rank sampling its own particles.
//!
//! A point probe, a gauge or a wall patch reads only the cell layers `probe_layers` names, and
//! the cuts never split them (`Slabs::balanced_keeping`): the rank that owns those layers holds
//! every particle the probe reads, in the order one whole run holds them, and gives its value
//! bit for bit (a probe on a moving tank: the layers of its whole path; one on a free body: the
//! layers where it stands, which the cuts move out of the way of). A front is the
//! largest reach over the fluid: the ranks' words combine by their
//! maximum, and a continuous front's wet bins by their union before the walk — exact too.

use anyhow::{bail, ensure, Result};

use super::Solver;
use crate::decomposition::layers_read;
use crate::gpu::buffers::read;
use crate::ranks::Ranks;

impl Solver {
    /// Samples every probe at the current time, every rank together; each rank gets the
    /// values one whole run would give.
    pub fn sample_probes_ranked(&self, ranks: &dyn Ranks) -> Result<Vec<f64>> {
        let probes = &self.passes.probes;
        if probes.is_empty() {
            return Ok(Vec::new());
        }
        let ranked = self.ranked.as_ref().expect("a subdomain");
        let slabs = ranked.slabs.as_ref().expect("a subdomain's cuts");
        // The layers each probe reads: those `probe_layers` planned, or for one on a free body
        // those where it stands now (which `keep_probes_whole` kept whole).
        let mut layers = ranked.probe_layers.clone();
        if let Some(placed) = self.place_attached_probes() {
            for &k in &ranked.moving_probes {
                let here = layers_read(&placed[k], self.params.h as f64, &self.grid, slabs.axis);
                if let Some(l) = here.clone().filter(|l| slabs.splits(l)) {
                    bail!(
                        "probe '{}' on a free body reads cell layers {l:?} at t = {:.4} s, \
                         which the cuts {slabs:?} split (it moved further in a step than the \
                         cuts allow for); run the case on one rank",
                        placed[k].name,
                        self.time()
                    );
                }
                layers[k] = here;
            }
            // A probe on a moving tank stays within the layers of its path the cuts keep whole
            // (`probe_layers`), unless the run goes on past the end they were planned for.
            let planned = (placed.iter().zip(&ranked.probe_layers).enumerate())
                .filter(|(k, _)| !ranked.moving_probes.contains(k));
            for (_, (p, planned)) in planned {
                let here = layers_read(p, self.params.h as f64, &self.grid, slabs.axis);
                if let (Some(here), Some(planned)) = (here, planned) {
                    ensure!(
                        planned.start <= here.start && here.end <= planned.end,
                        "probe '{}' reads cell layers {here:?} at t = {:.4} s, outside the \
                         layers {planned:?} its path was planned to read when the run \
                         started (did a resume extend time.end_s?); resume it on one rank",
                        p.name,
                        self.time()
                    );
                }
            }
        }
        let mut encoder = self.device.create_command_encoder(&Default::default());
        probes.encode_particles(&mut encoder, &self.buffers, self.parity);
        self.queue.submit([encoder.finish()]);
        if probes.has_continuous() {
            self.unite_front_bins(ranks)?;
            let mut encoder = self.device.create_command_encoder(&Default::default());
            probes.encode_continuous(&mut encoder, self.parity);
            self.queue.submit([encoder.finish()]);
        }
        let mine: Vec<f64> = self.probe_words()?.iter().map(|&w| w as f64).collect();
        let all = ranks.gather(&mine);
        let words: Vec<u32> = (0..mine.len())
            .map(|k| match &layers[k] {
                _ if probes.is_front(k) => all.iter().map(|w| w[k] as u32).max().unwrap_or(0),
                Some(layers) => all[slabs.owner(layers.start)][k] as u32,
                None => unreachable!("every probe but a front reads some layers"),
            })
            .collect();
        Ok(probes.decode(&words))
    }

    /// Replaces every rank's wet bins of the continuous fronts by the union of all ranks'.
    fn unite_front_bins(&self, ranks: &dyn Ranks) -> Result<()> {
        let buffer = self.passes.probes.front_bins();
        let n = (buffer.size() / 4) as usize;
        let mine = read::<u32>(&self.device, &self.queue, buffer, n)?;
        let mine: Vec<f64> = mine.iter().map(|&w| w as f64).collect();
        let all = ranks.gather(&mine);
        let union: Vec<u32> = (0..n)
            .map(|w| all.iter().fold(0, |u, r| u | r[w] as u32))
            .collect();
        self.queue
            .write_buffer(buffer, 0, bytemuck::cast_slice(&union));
        Ok(())
    }
}

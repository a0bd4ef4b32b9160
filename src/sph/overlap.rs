//! A subdomain's step that overlaps the exchange with the sums of the particles that read
//! nothing it brings (shaders/overlap.wgsl; issue 32, docs/scaling.md): the second sort's two
//! rates a particle. Every case can: what a pass writes between the sort and the sums (the
//! fixed ghosts' and the solids' values, the extrapolated inlet buffers' pressure) it writes
//! after each sort, and the first half keeps a layer further from the cuts than those read;
//! what comes after the sums (the solids' stress rates, the bodies' loads) runs after the
//! second; the bodies and the solids' stress are read by id, which no sort moves.

use anyhow::Result;

use super::buffers::ParticleBuffers;
use crate::gpu::buffers::storage;
use crate::gpu::kernel::ShaderModule;
use crate::gpu::shader::Shader;
use crate::gpu::Kernel;
use crate::layout::HaloCtl;
use crate::scenario::OverlapExchange;

pub const SHADER: Shader = Shader {
    name: "overlap",
    source: include_str!("../../shaders/overlap.wgsl"),
    libs: &[],
};

/// Whether a particle in cell layer `layer` of the subdomain `ctl` reads nothing the exchange
/// brings, so that its sums run before it arrives: a layer more than the halo is thick inside
/// every cut that has a neighbour (mirrors `reads_no_arrival` in shaders/lib/slab.wgsl, which
/// says why).
pub fn reads_no_arrival(layer: u32, ctl: &HaloCtl) -> bool {
    let margin = ctl.layers + 1;
    layer >= ctl.own_lo + margin * ctl.lower && layer + margin * ctl.upper < ctl.own_hi
}

/// Steps taken each way in a trial of `time.overlap_exchange = "auto"`, and steps from the
/// start of one trial to the next.
pub const TRIAL_STEPS: u64 = 10;
pub const TRIAL_EVERY: u64 = 1000;

/// A subdomain's choice, step by step, of whether to overlap (`time.overlap_exchange`). With
/// "auto" it times [`TRIAL_STEPS`] steps of each way every [`TRIAL_EVERY`] steps and takes the
/// faster until the next trial: which is faster depends on the device (on a CPU adapter the
/// sums and the exchange share the cores), the network and the slabs' thickness (how much of
/// a slab is interior), which change as the run goes. Each rank chooses for itself: the
/// results and the messages are the same either way.
#[derive(Clone, Debug)]
pub struct Choice {
    policy: OverlapExchange,
    /// Seconds of the present trial's serial and overlapped steps.
    trial: [f64; 2],
    chosen: bool,
}

impl Choice {
    pub fn new(policy: OverlapExchange) -> Self {
        Self {
            policy,
            trial: [0.0; 2],
            chosen: false,
        }
    }

    /// Whether the subdomain's step `k` (counted from its first) overlaps.
    pub fn overlaps(&self, k: u64) -> bool {
        match self.policy {
            OverlapExchange::Always => true,
            OverlapExchange::Never => false,
            OverlapExchange::Auto => match k % TRIAL_EVERY {
                t if t < TRIAL_STEPS => false,
                t if t < 2 * TRIAL_STEPS => true,
                _ => self.chosen,
            },
        }
    }

    /// Step `k` took `seconds` of this rank's (its packing, exchange and sums; not the wait
    /// for the other ranks' time step, which their choices move).
    pub fn record(&mut self, k: u64, seconds: f64) {
        if self.policy != OverlapExchange::Auto {
            return;
        }
        let t = k % TRIAL_EVERY;
        if t < 2 * TRIAL_STEPS {
            self.trial[self.overlaps(k) as usize] += seconds;
        }
        if t == 2 * TRIAL_STEPS - 1 {
            let [serial, overlapped] = self.trial.map(|s| s / TRIAL_STEPS as f64);
            self.chosen = overlapped < serial;
            log::debug!(
                "exchange: {:.2} ms a step serial, {:.2} ms overlapped; {} from step {k}",
                1e3 * serial,
                1e3 * overlapped,
                if self.chosen { "overlapping" } else { "serial" }
            );
            self.trial = [0.0; 2];
        }
    }
}

pub struct Overlap {
    /// Whether each step overlaps.
    pub choice: Choice,
    hold: Kernel,
    settle: Kernel,
    bind: [wgpu::BindGroup; 2],
    /// The last rates during the second sort (16 bytes a particle), and this step's de/dt
    /// with the energy equation (4 more).
    held: wgpu::Buffer,
    energy_held: wgpu::Buffer,
    n: u32,
}

impl Overlap {
    pub fn new(
        device: &wgpu::Device,
        module: &ShaderModule,
        b: &ParticleBuffers,
        policy: OverlapExchange,
    ) -> Result<Self> {
        let held = storage(device, "rate held", 16 * b.n as u64);
        let energy_held = storage(device, "energy rate held", b.energy_rate.size());
        let hold = module.kernel(device, "hold_old_rates")?;
        let settle = module.kernel(device, "settle_rates")?;
        let bindings = || {
            (b.unparitied())
                .with("rate_held", &held)
                .with("energy_rate_held", &energy_held)
        };
        let bind = [
            hold.bind(device, &bindings())?,
            settle.bind(device, &bindings())?,
        ];
        Ok(Self {
            choice: Choice::new(policy),
            hold,
            settle,
            bind,
            held,
            energy_held,
            n: b.n,
        })
    }

    /// Before the second sort's gather (after its scatter): the last rates in its order.
    pub fn encode_hold(&self, pass: &mut wgpu::ComputePass<'_>) {
        self.hold.dispatch(pass, &self.bind[0], self.n);
    }

    /// After the gather: this step's rates and the last ones each in its place.
    pub fn encode_settle(&self, pass: &mut wgpu::ComputePass<'_>) {
        self.settle.dispatch(pass, &self.bind[1], self.n);
    }

    /// GPU memory of the pass's own buffer, in bytes.
    pub fn bytes(&self) -> u64 {
        self.held.size() + self.energy_held.size()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decomposition::{cut_axis, layer_load, random_fluid, Slabs};
    use crate::grid::Grid;
    use crate::scenario::CellEdge;
    use crate::scenario::{Domain, Particle};

    /// No particle that [`reads_no_arrival`] says may be summed early reads, directly (within
    /// the support 2h, the cell edge) or through a fixed ghost (within 4h, with the two-layer
    /// halo of such cases), a place where the exchange writes: a halo layer, or the first own
    /// layer by a cut with a neighbour, where migrants land (brute force over random particles
    /// in 3 slabs). A rule of a layer less fails it.
    #[test]
    fn the_interior_reads_nothing_the_exchange_brings() {
        let h = 0.05;
        let g = Grid::new(
            &Domain {
                min: [0.0; 3],
                max: [3.0, 0.8, 0.6],
            },
            h,
            3,
            3000,
            [false; 3],
            Some(CellEdge::Support),
        )
        .unwrap();
        let axis = cut_axis(&g, 3).unwrap();
        let particles = random_fluid(&g, 3000, 7);
        let layer = |p: &Particle| {
            let (off, b) = g.to_block(p.pos);
            g.cell_of(off, b)[axis] as u32
        };
        for thickness in [1, 2] {
            let load = layer_load(&g, axis, &particles);
            let s = Slabs::balanced(axis, &load, 3, thickness).unwrap();
            let reach = thickness as f64 * 2.0 * h;
            let early_reads_arrival = |rule: &dyn Fn(u32, &HaloCtl) -> bool| {
                let (mut early, mut wrong) = (0, 0);
                for r in 0..3 {
                    let ctl = crate::sph::halo::control(&s, r, thickness);
                    let arrives = |l: u32| {
                        (ctl.lower != 0 && l + thickness >= ctl.own_lo && l <= ctl.own_lo)
                            || (ctl.upper != 0 && l + 1 >= ctl.own_hi && l < ctl.own_hi + thickness)
                    };
                    for i in particles.iter().filter(|p| s.owner(layer(p)) == r) {
                        if !rule(layer(i), &ctl) {
                            continue;
                        }
                        early += 1;
                        wrong += particles
                            .iter()
                            .filter(|j| {
                                let d2: f64 = (0..3).map(|a| (i.pos[a] - j.pos[a]).powi(2)).sum();
                                d2 < reach * reach && arrives(layer(j))
                            })
                            .count();
                    }
                }
                (early, wrong)
            };
            let (early, wrong) = early_reads_arrival(&reads_no_arrival);
            assert!(early > 800, "only {early} particles summed early");
            assert_eq!(
                wrong, 0,
                "an early particle reads an arrival ({thickness} layers)"
            );
            let a_layer_less = |l: u32, c: &HaloCtl| {
                l >= c.own_lo + c.layers * c.lower && l + c.layers * c.upper < c.own_hi
            };
            assert!(
                early_reads_arrival(&a_layer_less).1 > 0,
                "the test cannot fail ({thickness} layers)"
            );
        }
    }
}

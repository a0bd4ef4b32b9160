//! Hypoelastic solid particles (shaders/elastic.wgsl): continuity, momentum with the total
//! stress and the artificial stress, and the Jaumann stress rate, plus the predictor and
//! corrector of the stress. Only built when the case has updated-Lagrangian solids (the
//! total-Lagrangian ones are src/sph/total_lagrangian.rs's).

use anyhow::Result;

use super::buffers::ParticleBuffers;
use super::shader::NEIGHBOURS;
use super::shader::PARTICLE_ID;
use crate::gpu::buffers::storage;
use crate::gpu::kernel::{ParityKernel, ShaderModule};
use crate::gpu::shader::Shader;

pub const SHADER: Shader = Shader {
    name: "elastic",
    source: include_str!("../../shaders/elastic.wgsl"),
    libs: &[PARTICLE_ID, NEIGHBOURS],
};

/// Bytes of `SolidTerms` (shaders/elastic.wgsl) per solid particle: σ/ρ², R and the body.
pub(crate) const TERMS_BYTES: u64 = 64;

/// The updated-Lagrangian solid's passes and their own buffers: the new dτ/dt (`SymRate`) and
/// the per-evaluation stress terms of every solid particle (a total-Lagrangian case has
/// neither).
pub struct Elastic {
    terms: ParityKernel,
    rates: ParityKernel,
    predict: ParityKernel,
    correct: ParityKernel,
    n: u32,
    /// dτ/dt of the last evaluation, by solid slot (read by tests).
    pub stress_rate: wgpu::Buffer,
    /// GPU memory of the pass's buffers.
    bytes: u64,
}

impl Elastic {
    pub fn new(device: &wgpu::Device, module: &ShaderModule, b: &ParticleBuffers) -> Result<Self> {
        let n_solid = b.solid.size() / std::mem::size_of::<crate::layout::SolidState>() as u64;
        let terms = storage(device, "solid stress terms", TERMS_BYTES * n_solid.max(1));
        let sym_rate = std::mem::size_of::<crate::layout::SymRate>() as u64;
        let stress_rate = storage(device, "stress rate", sym_rate * n_solid.max(1));
        let bufs = |p: usize| {
            b.at(p)
                .with("stress_rate", &stress_rate)
                .with("terms", &terms)
        };
        let bound = |entry: &str| ParityKernel::new(device, module, entry, bufs);
        Ok(Self {
            terms: bound("solid_stress_terms")?,
            rates: bound("elastic_rates")?,
            predict: bound("stress_predict")?,
            correct: bound("stress_correct")?,
            n: b.n,
            bytes: terms.size() + stress_rate.size(),
            stress_rate,
        })
    }

    /// GPU memory of the pass's own buffer, in bytes.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// τ* = τ_n + dt (dτ/dt)_n of the solid particles of parity `p`'s arrays (before the sort).
    pub fn encode_predict(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.predict.dispatch(pass, p, self.n);
    }

    /// dρ/dt, dv/dt (into `rate`) and dτ/dt (into `stress_rate`) of the solid particles of the
    /// sorted arrays of parity `p`; after the interaction pass. First σ/ρ² and R of every solid
    /// particle, then the pair sums that read them.
    pub fn encode_rates(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.terms.dispatch(pass, p, self.n);
        self.rates.dispatch(pass, p, self.n);
    }

    /// The corrector of τ on parity `p`.
    pub fn encode_correct(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.correct.dispatch(pass, p, self.n);
    }
}

//! Total-Lagrangian elastic solid (shaders/total_lagrangian.wgsl): the reference neighbour
//! lists and gradient weights, computed once in f64 (src/reference/total_lagrangian.rs) and
//! uploaded; per step the slot of every solid particle after the sort, then F, the strain
//! gradient's stress T, the first Piola–Kirchhoff stress P and the accelerations. Takes the
//! place of the hypoelastic pass (src/sph/elastic.rs) for the solids of `formulation =
//! "total_lagrangian"`; there is no stress or density to integrate, integrate.wgsl moves the
//! particles (velocity Verlet).
//! GPU memory only for the solid particles: the lists (48 bytes a pair) and 5 matrices a
//! particle.

use anyhow::Result;

use super::buffers::ParticleBuffers;
use super::shader::PARTICLE_ID;
use crate::gpu::buffers::{map_read, read, readback_buffer, storage, storage_init, uniform_init};
use crate::gpu::kernel::{ParityKernel, ShaderModule};
use crate::gpu::shader::Shader;

pub const SHADER: Shader = Shader {
    name: "total_lagrangian",
    source: include_str!("../../shaders/total_lagrangian.wgsl"),
    libs: &[PARTICLE_ID],
};
use crate::lagrangian::{cauchy_of, TlSetup};
use crate::layout::{Pos, TlPair, TlParams};
use crate::scenario::{Scenario, SolidFormulation};

pub struct TotalLagrangian {
    index: ParityKernel,
    gather: ParityKernel,
    deform: ParityKernel,
    gradient: ParityKernel,
    stress: ParityKernel,
    accel: ParityKernel,
    /// H = F − I and the first Piola–Kirchhoff stress P of the last evaluation, by TL index.
    tl_h: wgpu::Buffer,
    tl_p: wgpu::Buffer,
    /// Every TL particle's position, and whether the arrays hold it (`tl_gather`).
    tl_pos: wgpu::Buffer,
    tl_held: wgpu::Buffer,
    /// Where a subdomain's step copies `tl_pos` and then `tl_held` for the host (`copy_held`).
    held_staging: wgpu::Buffer,
    /// The first TL particle's id.
    first_id: u32,
    /// Particles (all kinds) and TL particles.
    n: u32,
    n_tl: u32,
    /// GPU memory of the TL buffers.
    bytes: u64,
}

/// The ids of the total-Lagrangian solids' particles and their f64 setup (TL index = id − the
/// range's start).
pub fn setup(sc: &Scenario) -> Result<(std::ops::Range<usize>, TlSetup)> {
    let range = tl_range(sc)?;
    let solids = sc.solids.as_ref().expect("a case with solids");
    let x0: Vec<[f64; 3]> = sc.particles[range.clone()].iter().map(|p| p.pos).collect();
    let setup =
        TlSetup::new(&sc.physics, &x0, &solids.body[range.clone()]).map_err(anyhow::Error::msg)?;
    Ok((range, setup))
}

/// The ids of the particles of the total-Lagrangian solids: one run of consecutive ids (the case
/// loader builds these solids before the updated-Lagrangian ones), which the kernels index as
/// TL index + first id.
fn tl_range(sc: &Scenario) -> Result<std::ops::Range<usize>> {
    let solids = sc.solids.as_ref().expect("a case with solids");
    let solid = super::initial::solid_range(sc)?;
    let ids: Vec<usize> = solid
        .filter(|&i| solids.material_of(i).formulation == SolidFormulation::TotalLagrangian)
        .collect();
    super::initial::consecutive(&ids, "the total-Lagrangian solids")
}

impl TotalLagrangian {
    pub fn new(
        device: &wgpu::Device,
        module: &ShaderModule,
        b: &ParticleBuffers,
        sc: &Scenario,
    ) -> Result<Self> {
        let (range, setup) = setup(sc)?;
        let n_tl = setup.len() as u32;
        let params = TlParams {
            n: n_tl,
            first_id: range.start as u32,
            k2: (sc.physics.dx * sc.physics.dx / 12.0) as f32,
            pad: 0,
        };
        let start: Vec<u32> = setup.start.iter().map(|&s| s as u32).collect();
        let f3 = |v: [f64; 3]| v.map(|x| x as f32);
        let mut pairs: Vec<TlPair> = setup
            .pairs
            .iter()
            .map(|p| TlPair {
                w_ij: f3(p.w_ij),
                j: p.j as u32,
                w_ji: f3(p.w_ji),
                pad0: 0,
                d0: f3(p.d0),
                pad1: 0,
            })
            .collect();
        if pairs.is_empty() {
            // A binding cannot be empty.
            pairs.push(TlPair::default());
        }
        let tl_params = uniform_init(device, "tl params", &params);
        let tl_start = storage_init(device, "tl start", &start);
        let tl_pairs = storage_init(device, "tl pairs", &pairs);
        // The particles start in id order.
        let slots: Vec<u32> = (range.start as u32..range.end as u32).collect();
        let tl_slot = storage_init(device, "tl slots", &slots);
        let mat = 48u64; // mat3x3<f32> in a storage array
        let tl_h = storage(device, "tl H", mat * n_tl as u64);
        let tl_t = storage(device, "tl T", 3 * mat * n_tl as u64);
        let tl_p = storage(device, "tl P", mat * n_tl as u64);
        let tl_pos = storage(device, "tl positions", 16 * n_tl as u64);
        let tl_held = storage(device, "tl held", 4 * n_tl as u64);
        let held_staging = readback_buffer(device, "tl held positions", 20 * n_tl as u64);
        let bytes = [
            &tl_params,
            &tl_start,
            &tl_pairs,
            &tl_slot,
            &tl_h,
            &tl_t,
            &tl_p,
            &tl_pos,
            &tl_held,
            &held_staging,
        ]
        .iter()
        .map(|b| b.size())
        .sum();
        let bufs = |p: usize| {
            b.at(p)
                .with("tlp", &tl_params)
                .with("tl_start", &tl_start)
                .with("tl_pairs", &tl_pairs)
                .with("tl_slot", &tl_slot)
                .with("tl_h", &tl_h)
                .with("tl_t", &tl_t)
                .with("tl_p", &tl_p)
                .with("tl_pos", &tl_pos)
                .with("tl_held", &tl_held)
        };
        let bound = |entry: &str| ParityKernel::new(device, module, entry, bufs);
        Ok(Self {
            index: bound("tl_index")?,
            gather: bound("tl_gather")?,
            deform: bound("tl_deform")?,
            gradient: bound("tl_gradient")?,
            stress: bound("tl_stress")?,
            accel: bound("tl_accel")?,
            tl_h,
            tl_p,
            tl_pos,
            tl_held,
            held_staging,
            first_id: range.start as u32,
            n: b.n,
            n_tl,
            bytes,
        })
    }

    /// The first TL particle's id (TL index 0).
    pub fn first_id(&self) -> u32 {
        self.first_id
    }

    /// GPU memory of the lists and per-particle matrices, in bytes.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// Records where every TL particle the arrays of parity `p` hold is, and its position
    /// (after the sort, and in a subdomain after the predictor too, before the ranks share
    /// the positions).
    pub fn encode_index(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.index.dispatch(pass, p, self.n);
        self.gather.dispatch(pass, p, self.n_tl);
    }

    /// Copies the positions `encode_index` gathered and which of them the arrays hold for
    /// [`TotalLagrangian::read_held`], in the submission that gathered them.
    pub fn copy_held(&self, encoder: &mut wgpu::CommandEncoder) {
        let pos_bytes = 16 * self.n_tl as u64;
        encoder.copy_buffer_to_buffer(&self.tl_pos, 0, &self.held_staging, 0, pos_bytes);
        let held_bytes = 4 * self.n_tl as u64;
        encoder.copy_buffer_to_buffer(&self.tl_held, 0, &self.held_staging, pos_bytes, held_bytes);
    }

    /// The positions of the TL particles this process holds, by TL index (`None` for the
    /// others), as the last [`TotalLagrangian::copy_held`] copied them. Waits for the GPU.
    pub fn read_held(&self, device: &wgpu::Device) -> Result<Vec<Option<Pos>>> {
        let bytes = map_read::<u8>(device, &self.held_staging)?;
        let (pos, held) = bytes.split_at(16 * self.n_tl as usize);
        let pos: Vec<Pos> = bytemuck::pod_collect_to_vec(pos);
        let held: Vec<u32> = bytemuck::pod_collect_to_vec(&held[..4 * self.n_tl as usize]);
        Ok(pos
            .into_iter()
            .zip(held)
            .map(|(p, h)| (h != 0).then_some(p))
            .collect())
    }

    /// Every TL particle's position, by TL index (what the ranks shared); `encode_index`
    /// rewrites those the arrays hold with the same values after the sort.
    pub fn write_positions(&self, queue: &wgpu::Queue, pos: &[Pos]) {
        queue.write_buffer(&self.tl_pos, 0, bytemuck::cast_slice(pos));
    }

    /// The four passes: dv/dt of the TL particles added to `rate` (after the interaction
    /// pass, which initialises it), on the arrays of parity `p`.
    pub fn encode_rates(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        for b in [&self.deform, &self.gradient, &self.stress, &self.accel] {
            b.dispatch(pass, p, self.n_tl);
        }
    }

    /// The Cauchy stress σ = J⁻¹ P Fᵀ and J = det F of every TL particle at the positions of
    /// the arrays of parity `p`, by TL index (id − `first_id`), for the particle outputs.
    /// A step evaluates P at its predicted positions, so this re-runs the three stress passes
    /// (not the acceleration, which would add to `rate` again) at the current ones; the next
    /// step recomputes them before use, so outputs do not change the run.
    pub fn cauchy_stress(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        p: usize,
    ) -> Result<(u32, Vec<CauchyStress>)> {
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("tl stress output"),
        });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("tl stress output"),
                timestamp_writes: None,
            });
            // The positions of the arrays held now (those of the step's evaluation: the
            // corrector moves no particle).
            self.gather.dispatch(&mut pass, p, self.n_tl);
            for b in [&self.deform, &self.gradient, &self.stress] {
                b.dispatch(&mut pass, p, self.n_tl);
            }
        }
        queue.submit([encoder.finish()]);
        // mat3x3<f32> in storage: three columns of vec3 padded to 16 bytes.
        type Mat = [[f32; 4]; 3];
        let h: Vec<Mat> = read(device, queue, &self.tl_h, self.n_tl as usize)?;
        let pk: Vec<Mat> = read(device, queue, &self.tl_p, self.n_tl as usize)?;
        // Row r, column c of a matrix read back.
        let m3 = |m: &Mat| [0, 1, 2].map(|r| [0, 1, 2].map(|c| m[c][r] as f64));
        let out = h
            .iter()
            .zip(&pk)
            .map(|(h, pk)| {
                let (s, j) = cauchy_of(&m3(h), &m3(pk));
                CauchyStress {
                    sigma: [s[0][0], s[1][1], s[2][2], s[0][1], s[0][2], s[1][2]],
                    j,
                }
            })
            .collect();
        Ok((self.first_id, out))
    }
}

/// The Cauchy stress (xx, yy, zz, xy, xz, yz) [Pa] of a TL particle and its volume ratio J.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CauchyStress {
    pub sigma: [f64; 6],
    pub j: f64,
}

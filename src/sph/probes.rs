//! Probes sampled on the GPU (shaders/probes.wgsl); only one f32 per probe, and one position
//! per tracked point, is read back.

use anyhow::{bail, Result};

use super::buffers::ParticleBuffers;
use super::shader::PARTICLE_ID;
use super::shader::{NEIGHBOURS, WALL_PATCH, WATER_FRACTION, WORKGROUP_MAX};
use crate::body::Pose;
use crate::gpu::buffers::{read, storage, storage_init};
use crate::gpu::kernel::{ParityKernel, ShaderModule};
use crate::gpu::shader::{Shader, WORKGROUP_SIZE};

pub const SHADER: Shader = Shader {
    name: "probes",
    source: include_str!("../../shaders/probes.wgsl"),
    libs: &[
        PARTICLE_ID,
        NEIGHBOURS,
        WORKGROUP_MAX,
        WALL_PATCH,
        WATER_FRACTION,
    ],
};
use super::shader::WgslEnum;
use crate::layout::{Pos, ProbeCode, ProbeDef, NO_FACE};
use crate::ranks::Ranks;
use crate::scenario::{GaugeSurface, Probe, ProbeKind, TrackedPoint, WallParams, WallPatch};
use glam::DVec3;

/// Bins along a continuous front's axis (probes.wgsl, `probe_front_walk`): the kernel support
/// 2h wide, enough of them to cover the domain's diagonal from anywhere in it.
#[derive(Clone, Copy, Debug)]
pub struct FrontBins {
    pub width: f64,
    pub words: u32,
}

/// lavapipe ends an invocation's loops after 65 535 iterations in all (probes.wgsl): the
/// walk over a front's words must stay below that.
const MAX_FRONT_WORDS: f64 = 60_000.0;

impl FrontBins {
    /// The bins for `probes` (an error only where one of them is a continuous front).
    pub fn new(grid: &crate::grid::Grid, h: f64, probes: &[Probe]) -> Result<Self> {
        let width = 2.0 * h;
        let diagonal = grid.extent.iter().map(|e| e * e).sum::<f64>().sqrt();
        let words = (diagonal / width / 32.0).ceil() + 1.0;
        let continuous = (probes.iter()).any(|p| {
            matches!(
                p.kind,
                ProbeKind::Front {
                    continuous: true,
                    ..
                }
            )
        });
        if continuous && words > MAX_FRONT_WORDS {
            anyhow::bail!(
                "a continuous front probe needs {words} words of bins ({diagonal} m of domain \
                 diagonal in bins of 2h = {width} m), more than {MAX_FRONT_WORDS}: use a \
                 smaller domain or `continuous = false`"
            );
        }
        Ok(Self {
            width,
            words: words.min(MAX_FRONT_WORDS) as u32,
        })
    }
}

/// The words of `front_bins` the probes `defs` use (at least one, so the buffer exists).
pub fn front_bin_words(defs: &[ProbeDef]) -> usize {
    (defs.iter())
        .filter(|d| d.kind == ProbeCode::FrontContinuous.code())
        .map(|d| (d.bins + d.words + 1) as usize)
        .max()
        .unwrap_or(1)
}

/// Each probe's face: for a wall-pressure probe on a fixed wall (one of `walls.sensors`), its
/// sensor's face (`WallParams::sensor_faces`); `NO_FACE` for every other probe.
pub fn probe_faces(probes: &[Probe], walls: &WallParams) -> Vec<u32> {
    let faces = walls.sensor_faces();
    probes
        .iter()
        .map(|p| match &p.kind {
            ProbeKind::WallPressure(patch) if p.body.is_none() => (walls.sensors.iter())
                .position(|s| s == patch)
                .map_or(NO_FACE, |k| faces[k]),
            _ => NO_FACE,
        })
        .collect()
}

/// A wall-pressure probe needs the walls' reactions and a resolved patch.
pub fn check_wall_pressure(sc: &crate::scenario::Scenario) -> Result<()> {
    for p in &sc.probes {
        if let ProbeKind::WallPressure(patch) = &p.kind {
            if !sc.walls.reactions || patch.area.is_nan() || patch.area <= 0.0 {
                anyhow::bail!(
                    "wall-pressure probe {:?} needs walls.reactions and a patch resolved \
                     by WallPatch::resolve",
                    p.name
                );
            }
        }
    }
    Ok(())
}

/// GPU definitions of the probes, in domain coordinates (from the domain's min corner);
/// `faces` from [`probe_faces`]; each continuous front gets `bins.words` words of bits and
/// one for its end, in probe order.
pub fn probe_defs(
    probes: &[Probe],
    origin: [f64; 3],
    faces: &[u32],
    bins: FrontBins,
) -> Vec<ProbeDef> {
    let rel = |p: &[f64; 3]| [0, 1, 2].map(|a| (p[a] - origin[a]) as f32);
    let mut next_word = 0;
    let discharges = discharge_count(probes) as u32;
    let mut next_discharge = 0;
    (probes.iter().zip(faces))
        .map(|(p, &face)| match &p.kind {
            ProbeKind::Pressure { point } => ProbeDef {
                point: rel(point),
                kind: ProbeCode::Pressure.code(),
                face,
                ..Default::default()
            },
            ProbeKind::Height { base, surface } => ProbeDef {
                point: rel(base),
                kind: match surface {
                    GaugeSurface::FluidHalf => ProbeCode::Height,
                    GaugeSurface::WaterFraction => ProbeCode::Depth,
                }
                .code(),
                face,
                ..Default::default()
            },
            ProbeKind::Front {
                origin: o,
                axis,
                continuous,
            } => {
                let norm = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
                let def = ProbeDef {
                    point: rel(o),
                    kind: ProbeCode::Front.code(),
                    axis: axis.map(|a| (a / norm) as f32),
                    face,
                    ..Default::default()
                };
                if !continuous {
                    return def;
                }
                let first = next_word;
                next_word += bins.words + 1;
                ProbeDef {
                    kind: ProbeCode::FrontContinuous.code(),
                    bins: first,
                    words: bins.words,
                    bin_width: bins.width as f32,
                    ..def
                }
            }
            ProbeKind::WallPressure(patch) => ProbeDef {
                point: rel(&patch.point),
                kind: ProbeCode::WallPressure.code(),
                axis: patch.normal.map(|a| a as f32),
                radius: patch.radius as f32,
                face,
                ..Default::default()
            },
            ProbeKind::Discharge { from, to } => {
                let (normal, length) = ProbeKind::section_normal(*from, *to);
                next_discharge += 1;
                ProbeDef {
                    point: rel(from),
                    kind: ProbeCode::Discharge.code(),
                    axis: normal.map(|a| a as f32),
                    radius: length as f32,
                    face,
                    bins: next_discharge - 1,
                    words: discharges,
                    ..Default::default()
                }
            }
        })
        .collect()
}

/// The probe kind of a `ProbeDef::kind` code.
fn probe_code(code: u32) -> ProbeCode {
    ProbeCode::VARIANTS[code as usize].0
}

/// How many of `probes` are discharge probes.
pub fn discharge_count(probes: &[Probe]) -> usize {
    (probes.iter())
        .filter(|p| matches!(p.kind, ProbeKind::Discharge { .. }))
        .count()
}

/// `probe` where its body has taken it: a point given at t = 0 goes to x_c + R (x0 − x_c0)
/// (x_c0 the body's centre at t = 0, `pose` its current one) and a front's axis and a wall
/// patch's normal turn with R.
/// A height gauge's line stays vertical in the world frame.
pub fn moved(probe: &Probe, center0: [f64; 3], pose: &Pose) -> Probe {
    let c0 = DVec3::from_array(center0);
    let place =
        |x: &[f64; 3]| (pose.center + pose.rotation * (DVec3::from_array(*x) - c0)).to_array();
    let kind = match &probe.kind {
        ProbeKind::Pressure { point } => ProbeKind::Pressure {
            point: place(point),
        },
        ProbeKind::Height { base, surface } => ProbeKind::Height {
            base: place(base),
            surface: *surface,
        },
        ProbeKind::Front {
            origin,
            axis,
            continuous,
        } => ProbeKind::Front {
            origin: place(origin),
            axis: (pose.rotation * DVec3::from_array(*axis)).to_array(),
            continuous: *continuous,
        },
        ProbeKind::WallPressure(patch) => ProbeKind::WallPressure(WallPatch {
            point: place(&patch.point),
            normal: (pose.rotation * DVec3::from_array(patch.normal)).to_array(),
            ..*patch
        }),
        // A section is not attached to a body (the case reader refuses it).
        ProbeKind::Discharge { .. } => probe.kind.clone(),
    };
    Probe {
        kind,
        ..probe.clone()
    }
}

/// Inverse of `ordered_bits` in probes.wgsl; 0 (no fluid at all) gives NaN.
pub fn decode_ordered(bits: u32) -> f32 {
    if bits == 0 {
        f32::NAN
    } else if bits & 0x8000_0000 != 0 {
        f32::from_bits(bits & 0x7FFF_FFFF)
    } else {
        f32::from_bits(!bits)
    }
}

pub struct Probes {
    points: ParityKernel,
    front: ParityKernel,
    front_walk: ParityKernel,
    front_continuous: ParityKernel,
    height: ParityKernel,
    discharge_sums: ParityKernel,
    discharge_total: ParityKernel,
    /// The continuous fronts' bits of wet bins and ends (`probe_front_walk`).
    front_bins: wgpu::Buffer,
    kinds: Vec<ProbeCode>,
    /// What a probe's word is multiplied by: −m/area for wall pressures (the GPU sums the
    /// boundary particles' rates along the normal), 1 otherwise.
    scales: Vec<f64>,
    /// The probes that cannot measure ([`crate::probe_reach::unmeasurable`]): they read NaN.
    blind: Vec<bool>,
    n: u32,
}

impl Probes {
    pub fn new(
        device: &wgpu::Device,
        module: &ShaderModule,
        b: &ParticleBuffers,
        probes: &[Probe],
        defs: &[ProbeDef],
        particle_mass: f64,
        blind: Vec<bool>,
    ) -> Result<Self> {
        let front_bins = storage(device, "front bins", 4 * front_bin_words(defs) as u64);
        // A sum per workgroup of the particle arrays and discharge probe (one word at least).
        let groups = b.n.div_ceil(WORKGROUP_SIZE) as u64;
        let sums = (groups * discharge_count(probes) as u64).max(1);
        let discharge_sums = storage(device, "discharge sums", 4 * sums);
        let kernel = |entry| {
            ParityKernel::new(device, module, entry, |p| {
                (b.at(p))
                    .with("front_bins", &front_bins)
                    .with("discharge_sums", &discharge_sums)
            })
        };
        Ok(Self {
            points: kernel("probe_points")?,
            front: kernel("probe_front")?,
            front_walk: kernel("probe_front_walk")?,
            front_continuous: kernel("probe_front_continuous")?,
            height: kernel("probe_height_search")?,
            discharge_sums: kernel("probe_discharge_sums")?,
            discharge_total: kernel("probe_discharge_total")?,
            kinds: defs.iter().map(|d| probe_code(d.kind)).collect(),
            scales: probes
                .iter()
                .map(|p| match &p.kind {
                    ProbeKind::WallPressure(patch) => -particle_mass / patch.area,
                    _ => 1.0,
                })
                .collect(),
            blind,
            n: b.n,
            front_bins,
        })
    }

    pub fn is_empty(&self) -> bool {
        self.kinds.is_empty()
    }

    /// Records the probe evaluation on the arrays of parity `p` (cell list must be current).
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, b: &ParticleBuffers, p: usize) {
        self.encode_particles(encoder, b, p);
        self.encode_continuous(encoder, p);
    }

    /// What each probe reads from the particles: the gauges, the points and wall patches, the
    /// fronts and the continuous fronts' wet bins. Of a subdomain, its own particles' share.
    pub fn encode_particles(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        b: &ParticleBuffers,
        p: usize,
    ) {
        encoder.clear_buffer(&b.probe_out, 0, None);
        if self.has_continuous() {
            encoder.clear_buffer(&self.front_bins, 0, None);
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("probes"),
            timestamp_writes: None,
        });
        // The gauges' search over the particles first: `probe_points` interpolates where it
        // found the surface (probes.wgsl).
        if self.kinds.contains(&ProbeCode::Height) || self.kinds.contains(&ProbeCode::Depth) {
            self.height.dispatch(&mut pass, p, self.n);
        }
        self.points.dispatch(&mut pass, p, self.kinds.len() as u32);
        if self.has_continuous() || self.kinds.contains(&ProbeCode::Front) {
            self.front.dispatch(&mut pass, p, self.n);
        }
        if self.kinds.contains(&ProbeCode::Discharge) {
            self.discharge_sums.dispatch(&mut pass, p, self.n);
            self.discharge_total
                .dispatch(&mut pass, p, self.kinds.len() as u32);
        }
    }

    /// The continuous fronts from their wet bins (all of them: of a subdomain, the ranks'
    /// bins together, [`Probes::front_bins`]).
    pub fn encode_continuous(&self, encoder: &mut wgpu::CommandEncoder, p: usize) {
        if !self.has_continuous() {
            return;
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("continuous fronts"),
            timestamp_writes: None,
        });
        self.front_walk
            .dispatch(&mut pass, p, self.kinds.len() as u32);
        self.front_continuous.dispatch(&mut pass, p, self.n);
    }

    pub fn has_continuous(&self) -> bool {
        self.kinds.contains(&ProbeCode::FrontContinuous)
    }

    /// The continuous fronts' bits of wet bins.
    pub fn front_bins(&self) -> &wgpu::Buffer {
        &self.front_bins
    }

    /// Whether probe `k` is a front: a maximum over the fluid, whose words combine over ranks
    /// by their maximum (`ordered_bits` keeps the order of the values).
    pub fn is_front(&self, k: usize) -> bool {
        matches!(self.kinds[k], ProbeCode::Front | ProbeCode::FrontContinuous)
    }

    /// Values from the raw words read back.
    pub fn decode(&self, raw: &[u32]) -> Vec<f64> {
        self.kinds
            .iter()
            .zip(&self.scales)
            .zip(raw)
            .zip(&self.blind)
            .map(|(((&k, &scale), &w), &blind)| {
                if blind {
                    f64::NAN
                } else if matches!(k, ProbeCode::Front | ProbeCode::FrontContinuous) {
                    decode_ordered(w) as f64
                } else {
                    scale * f32::from_bits(w) as f64
                }
            })
            .collect()
    }
}

/// Tracked points on the GPU (`track_points` in probes.wgsl): the followed ids in ascending
/// order (each once) and, for every point of the scenario, its slot in that list.
pub struct PointTracker {
    kernel: ParityKernel,
    out: wgpu::Buffer,
    /// 1 where the arrays hold the point's particle live.
    held: wgpu::Buffer,
    slot_of_point: Vec<usize>,
    slots: usize,
    n: u32,
}

impl PointTracker {
    /// `None` when the case tracks no point.
    pub fn new(
        device: &wgpu::Device,
        module: &ShaderModule,
        b: &ParticleBuffers,
        points: &[TrackedPoint],
    ) -> Result<Option<Self>> {
        if points.is_empty() {
            return Ok(None);
        }
        let mut ids: Vec<u32> = points.iter().map(|p| p.particle).collect();
        ids.sort_unstable();
        ids.dedup();
        let slot_of_point = points
            .iter()
            .map(|p| {
                ids.binary_search(&p.particle)
                    .expect("every id is in the list")
            })
            .collect();
        let tracked = storage_init(device, "tracked ids", &ids);
        let out = storage(
            device,
            "tracked positions",
            (ids.len() * std::mem::size_of::<Pos>()) as u64,
        );
        let held = storage(device, "tracked held", 4 * ids.len() as u64);
        let kernel = ParityKernel::new(device, module, "track_points", |p| {
            b.at(p)
                .with("tracked", &tracked)
                .with("tracked_pos", &out)
                .with("tracked_held", &held)
        })?;
        Ok(Some(Self {
            kernel,
            out,
            held,
            slot_of_point,
            slots: ids.len(),
            n: b.n,
        }))
    }

    /// Copies the followed particles' positions (arrays of parity `p`) into the output buffer.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, p: usize) {
        encoder.clear_buffer(&self.held, 0, None);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("track points"),
            timestamp_writes: None,
        });
        self.kernel.dispatch(&mut pass, p, self.n);
    }

    /// The positions, in the scenario's point order (after [`encode`](Self::encode) was
    /// submitted); None where the arrays do not hold the particle live. Over `ranks`, every
    /// rank together, each from the rank that holds it (the position's words, exact).
    pub fn read(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        ranks: Option<&dyn Ranks>,
    ) -> Result<Vec<Option<Pos>>> {
        let raw: Vec<Pos> = read(device, queue, &self.out, self.slots)?;
        let held: Vec<u32> = read(device, queue, &self.held, self.slots)?;
        // Per slot (held, the position's four words), zeros where not held.
        let mut words: Vec<f64> = (raw.iter().zip(&held))
            .flat_map(|(p, &h)| {
                let w = [
                    h,
                    p.off[0].to_bits(),
                    p.off[1].to_bits(),
                    p.off[2].to_bits(),
                    p.block,
                ];
                w.map(|x| if h == 0 { 0.0 } else { x as f64 })
            })
            .collect();
        if let Some(ranks) = ranks {
            words = ranks.sum_in_rank_order(&words);
        }
        let slots: Vec<Option<Pos>> = words
            .chunks(5)
            .map(|w| match w[0] as u32 {
                0 => Ok(None),
                1 => Ok(Some(Pos {
                    off: [1, 2, 3].map(|a| f32::from_bits(w[a] as u32)),
                    block: w[4] as u32,
                })),
                n => bail!("a tracked particle is held by {n} ranks"),
            })
            .collect::<Result<_>>()?;
        Ok(self.slot_of_point.iter().map(|&s| slots[s]).collect())
    }
}

//! Every GPU buffer of a run. Particle arrays come in two parities (the cell sort gathers
//! from one into the other); everything else is single.

use anyhow::{anyhow, Result};

use crate::gpu::buffers::{storage, storage_init, uniform_init};
use crate::gpu::kernel::Resolve;
use crate::layout::Packed;
use crate::layout::{
    BodyMotion, BodyParticle, MirrorPlane, Params, Pos, ProbeDef, SimState, SolidState, WallSensor,
};

pub struct ParticleBuffers {
    pub n: u32,
    pub params: wgpu::Buffer,
    pub state: wgpu::Buffer,
    pub pos: [wgpu::Buffer; 2],
    /// (v, ρ)
    pub velrho: [wgpu::Buffer; 2],
    /// kind << 28 | id
    pub code: [wgpu::Buffer; 2],
    /// (dv/dt, dρ/dt) of the last evaluation, in the current order.
    pub rate: wgpu::Buffer,
    /// The previous rates gathered into the new order by the sort.
    pub rate_sorted: wgpu::Buffer,
    /// Atomic rank within the slot, then (reused) the final permutation.
    pub local_perm: wgpu::Buffer,
    pub provisional: wgpu::Buffer,
    /// Slot histogram, scanned in place into slot starts: slots + 3 entries (the extra slots
    /// hold the excluded particles and a subdomain's free entries; the last entry ends up = n).
    pub cell_start: wgpu::Buffer,
    /// Block sums of the prefix scan, one buffer per level (the last has one element).
    pub scan_levels: Vec<wgpu::Buffer>,
    pub scan_sizes: Vec<u32>,
    pub probes: wgpu::Buffer,
    pub probe_out: wgpu::Buffer,
    /// (e, de/dt) per particle, 2 parities, and the new de/dt: one element each when the
    /// energy equation is off.
    pub energy: [wgpu::Buffer; 2],
    pub energy_rate: wgpu::Buffer,
    /// The case's small read-only tables in one binding (`CaseTables` in common.wgsl, laid
    /// out by [`TableSizes`]): each body's rigid motion for the step (the host uploads it at
    /// offset 0 every step), the mirror planes, the wall-pressure probes' patches on fixed
    /// walls (`WallParams::sensors`), and the body-frame offset and body of every body particle
    /// (by id − body_id_base); a stand-in of each where the case has none.
    pub tables: wgpu::Buffer,
    /// Deviatoric stress, body, last dτ/dt, interface pressure and material of the solid
    /// particles, indexed by id − `Params::solid_id_base`: the sort leaves them in place, and
    /// fluid and wall particles take no room in it (one element when there are no solids).
    /// The updated-Lagrangian pass (`Elastic`) owns the new dτ/dt.
    pub solid: wgpu::Buffer,
}

/// Stand-in so a run without probes still binds a valid buffer.
const EMPTY_PROBES: [ProbeDef; 1] = [ProbeDef {
    point: [0.0; 3],
    kind: 0,
    axis: [0.0; 3],
    radius: 0.0,
    face: crate::layout::NO_FACE,
    bins: 0,
    words: 0,
    bin_width: 0.0,
}];

/// How many entries each fixed table of `CaseTables` (shaders/lib/common.wgsl) has: the case's
/// count, at least one (a stand-in where it has none). Composed into the shaders as N_BODIES,
/// N_MIRROR_PLANES and N_WALL_SENSORS; the body particles follow, as many as the case has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TableSizes {
    pub bodies: u32,
    pub mirror_planes: u32,
    pub wall_sensors: u32,
}

impl TableSizes {
    /// The sizes of `sc`'s tables.
    pub fn of(sc: &crate::scenario::Scenario) -> TableSizes {
        let at_least_one = |n: usize| n.max(1) as u32;
        TableSizes {
            bodies: at_least_one(sc.bodies.len()),
            mirror_planes: at_least_one(sc.walls.mirror_planes.len()),
            wall_sensors: at_least_one(sc.walls.sensors.len()),
        }
    }

    /// Byte offset of the mirror planes (the bodies' motions start at 0).
    pub fn mirror_planes_offset(&self) -> usize {
        self.bodies as usize * std::mem::size_of::<BodyMotion>()
    }

    pub fn wall_sensors_offset(&self) -> usize {
        self.mirror_planes_offset()
            + self.mirror_planes as usize * std::mem::size_of::<MirrorPlane>()
    }

    pub fn body_particles_offset(&self) -> usize {
        self.wall_sensors_offset() + self.wall_sensors as usize * std::mem::size_of::<WallSensor>()
    }

    /// The tables' bytes; an empty table takes its stand-in (zeros; a sensor of radius 0).
    pub fn pack(
        &self,
        motions: &[BodyMotion],
        planes: &[MirrorPlane],
        sensors: &[WallSensor],
        body_particles: &[BodyParticle],
    ) -> Vec<u8> {
        assert!(
            motions.len() <= self.bodies as usize
                && planes.len() <= self.mirror_planes as usize
                && sensors.len() <= self.wall_sensors as usize,
            "tables larger than their sizes"
        );
        let sensors: &[WallSensor] = if sensors.is_empty() {
            &[NO_SENSOR]
        } else {
            sensors
        };
        let n_body = body_particles.len().max(1);
        let mut out =
            vec![0u8; self.body_particles_offset() + n_body * std::mem::size_of::<BodyParticle>()];
        let mut put = |offset: usize, bytes: &[u8]| {
            out[offset..offset + bytes.len()].copy_from_slice(bytes);
        };
        put(0, bytemuck::cast_slice(motions));
        put(self.mirror_planes_offset(), bytemuck::cast_slice(planes));
        put(self.wall_sensors_offset(), bytemuck::cast_slice(sensors));
        put(
            self.body_particles_offset(),
            bytemuck::cast_slice(body_particles),
        );
        out
    }
}

/// Stand-in for a run without wall sensors: a patch of radius 0 holds no particle.
const NO_SENSOR: WallSensor = WallSensor {
    point: [0.0; 3],
    radius: 0.0,
    normal: [0.0; 3],
    face: 0.0,
    over_lo: [0.0; 3],
    face_id: 0,
    over_hi: [0.0; 3],
    pad: 0,
};

pub struct InitialParticles<'a> {
    /// The particles the arrays hold (a subdomain's entries, free ones included). The arrays
    /// start zeroed: [`ParticleBuffers::write_particles`] writes them.
    pub capacity: u32,
    /// Whether ids are wide: the code buffer then holds each id's high word after the code
    /// words (`IdSplit`).
    pub wide_ids: bool,
    pub body_particles: &'a [BodyParticle],
    /// One per body (its particle range and workgroups; the motion comes with each step).
    pub body_motions: &'a [BodyMotion],
    /// One per solid particle, in id order (from `Params::solid_id_base`), else empty.
    pub solid: &'a [SolidState],
}

/// The case's fixed tables, in domain coordinates.
pub struct CaseTables<'a> {
    pub probes: &'a [ProbeDef],
    pub mirror_planes: &'a [MirrorPlane],
    /// The wall-pressure probes' patches on fixed walls.
    pub wall_sensors: &'a [WallSensor],
}

impl ParticleBuffers {
    pub fn new(
        device: &wgpu::Device,
        params: &Params,
        slots: u32,
        init: &InitialParticles,
        tables: &CaseTables,
        sizes: TableSizes,
        energy: bool,
    ) -> Self {
        let CaseTables {
            probes,
            mirror_planes: planes,
            wall_sensors: sensors,
        } = *tables;
        let n = init.capacity;
        let vec4 = 16 * n as u64;
        let words = 4 * n as u64;
        let code_bytes = words * (1 + init.wide_ids as u64);
        let mut scan_sizes = vec![slots + 3];
        let block = 2 * crate::gpu::shader::WORKGROUP_SIZE;
        while *scan_sizes.last().unwrap() > block {
            let last = *scan_sizes.last().unwrap();
            scan_sizes.push(last.div_ceil(block));
        }
        scan_sizes.push(1);
        let scan_levels = scan_sizes[1..]
            .iter()
            .enumerate()
            .map(|(l, &s)| storage(device, &format!("scan level {}", l + 1), 4 * s as u64))
            .collect();
        Self {
            n,
            params: uniform_init(device, "params", params),
            state: storage_init(device, "sim state", &[SimState::default()]),
            pos: ["pos A", "pos B"].map(|l| storage(device, l, vec4)),
            velrho: ["velrho A", "velrho B"].map(|l| storage(device, l, vec4)),
            code: ["code A", "code B"].map(|l| storage(device, l, code_bytes)),
            // The first step's predictor reads the last rates: zero (wgpu zeroes a buffer).
            rate: storage(device, "rate", vec4),
            rate_sorted: storage(device, "rate sorted", vec4),
            local_perm: storage(device, "local rank / perm", words),
            provisional: storage(device, "provisional", words),
            cell_start: storage(device, "cell start", 4 * (slots as u64 + 3)),
            scan_levels,
            scan_sizes,
            probes: storage_init(
                device,
                "probe defs",
                if probes.is_empty() {
                    &EMPTY_PROBES
                } else {
                    probes
                },
            ),
            probe_out: storage(device, "probe out", 4 * probes.len().max(1) as u64),
            energy: [0, 1].map(|k| {
                storage(
                    device,
                    &format!("energy {k}"),
                    if energy { 8 * n as u64 } else { 8 },
                )
            }),
            energy_rate: storage(device, "energy rate", if energy { 4 * n as u64 } else { 4 }),
            solid: if init.solid.is_empty() {
                storage(device, "solid", std::mem::size_of::<SolidState>() as u64)
            } else {
                storage_init(device, "solid", init.solid)
            },
            tables: storage_init(
                device,
                "case tables",
                &sizes.pack(init.body_motions, planes, sensors, init.body_particles),
            ),
        }
    }

    /// Writes `packed`, the entries from `first` on in the arrays' order, into the arrays a
    /// run starts from (parity 0). The queue holds a staging copy of the bytes until its next
    /// submission: a large case is written in pieces (`Solver::build`).
    pub fn write_particles(&self, queue: &wgpu::Queue, first: u32, packed: &Packed) {
        let at = |bytes: usize| first as u64 * bytes as u64;
        let write = |buffer: &wgpu::Buffer, offset: u64, bytes: &[u8]| {
            if !bytes.is_empty() {
                queue.write_buffer(buffer, offset, bytes);
            }
        };
        let pos: &[u8] = bytemuck::cast_slice(&packed.pos);
        write(&self.pos[0], at(std::mem::size_of::<Pos>()), pos);
        write(
            &self.velrho[0],
            at(16),
            bytemuck::cast_slice(&packed.velrho),
        );
        write(&self.code[0], at(4), bytemuck::cast_slice(&packed.code));
        let high = packed.high_words();
        let high_at = 4 * self.n as u64 + at(4);
        write(&self.code[0], high_at, bytemuck::cast_slice(&high));
    }

    /// The buffers a pass binds, by WGSL name, with the particle arrays of parity `p`.
    pub fn at(&self, p: usize) -> Bindings<'_> {
        Bindings {
            shared: self,
            parity: Some(p),
            own: Vec::new(),
        }
    }

    /// The buffers a kernel that reads no particle array binds (asking for one is an error).
    pub fn unparitied(&self) -> Bindings<'_> {
        Bindings {
            shared: self,
            parity: None,
            own: Vec::new(),
        }
    }

    /// The shared buffer of the WGSL global `name` (`Ok(None)`: no shared buffer has that
    /// name). Where a name is not the buffer's own it says why the passes call it so.
    fn named(&self, name: &str, parity: Option<usize>) -> Result<Option<&wgpu::Buffer>> {
        let single = match name {
            "params" => Some(&self.params),
            "state" => Some(&self.state),
            // The slot histogram, counted atomically, then scanned into the slots' starts.
            "cell_start" | "counts" => Some(&self.cell_start),
            // The rank within the slot, then the permutation it becomes.
            "local_rank" | "perm" => Some(&self.local_perm),
            "provisional" => Some(&self.provisional),
            // The sort reads the last rates and writes them in the new order, where the
            // predictor of the next step reads them as the old rates.
            "rate" | "rate_in" => Some(&self.rate),
            "rate_out" | "rate_old" => Some(&self.rate_sorted),
            "probes" => Some(&self.probes),
            "probe_out" => Some(&self.probe_out),
            "tables" => Some(&self.tables),
            "energy_rate" => Some(&self.energy_rate),
            "solid" => Some(&self.solid),
            _ => None,
        };
        if single.is_some() {
            return Ok(single);
        }
        // The particle arrays: `x` and `x_in` of the current parity, `x_out` the other (the
        // sort gathers from one into the other).
        let (stem, other) = match name.strip_suffix("_out") {
            Some(stem) => (stem, true),
            None => (name.strip_suffix("_in").unwrap_or(name), false),
        };
        let pair = match stem {
            "pos" => &self.pos,
            "velrho" => &self.velrho,
            "code" => &self.code,
            "energy" => &self.energy,
            _ => return Ok(None),
        };
        let p = parity.ok_or_else(|| anyhow!("a particle array, bound without a parity"))?;
        Ok(Some(&pair[if other { 1 - p } else { p }]))
    }

    /// GPU memory of everything that scales with the run (all buffers above).
    pub fn bytes(&self) -> u64 {
        let mut all: Vec<&wgpu::Buffer> = vec![
            &self.params,
            &self.state,
            &self.rate,
            &self.rate_sorted,
            &self.local_perm,
            &self.provisional,
            &self.cell_start,
            &self.probes,
            &self.probe_out,
            &self.tables,
            &self.energy_rate,
            &self.solid,
        ];
        all.extend(self.energy.iter());
        all.extend(
            self.pos
                .iter()
                .chain(&self.velrho)
                .chain(&self.code)
                .chain(&self.scan_levels),
        );
        all.iter().map(|b| b.size()).sum()
    }
}

/// The buffers of one bind group: the shared ones by their WGSL names, with the particle arrays
/// of one parity (or none), and the pass's own buffers.
pub struct Bindings<'a> {
    shared: &'a ParticleBuffers,
    parity: Option<usize>,
    own: Vec<(&'static str, &'a wgpu::Buffer)>,
}

impl<'a> Bindings<'a> {
    /// Adds a buffer of the pass's own under the WGSL name `name`, which must not be a shared
    /// buffer's (a pass cannot rebind one).
    pub fn with(mut self, name: &'static str, buffer: &'a wgpu::Buffer) -> Self {
        assert!(
            matches!(self.shared.named(name, Some(0)), Ok(None)),
            "`{name}` is a shared buffer's name"
        );
        self.own.push((name, buffer));
        self
    }
}

impl Resolve for Bindings<'_> {
    fn resolve(&self, name: &str) -> Result<&wgpu::Buffer> {
        if let Some((_, b)) = self.own.iter().find(|(n, _)| *n == name) {
            return Ok(b);
        }
        self.shared
            .named(name, self.parity)?
            .ok_or_else(|| anyhow!("no buffer of that name"))
    }
}

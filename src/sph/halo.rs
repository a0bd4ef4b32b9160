//! A subdomain's halo and migrants (shaders/halo.wgsl; issue 32): `halo_pack` after the
//! predictor, `halo_drop` after the interaction. The solver's `ranked_step` swaps the packed
//! records with the neighbours between the two.

use anyhow::{anyhow, ensure, Result};

use super::buffers::{Bindings, ParticleBuffers};
use super::shader::{PARTICLE_ID, SLAB};
use crate::decomposition::Slabs;
use crate::gpu::buffers::{map_read, read, readback_buffer, storage, uniform_init};
use crate::gpu::kernel::{ParityKernel, ShaderModule};
use crate::gpu::shader::Shader;
use crate::layout::{HaloArrivals, HaloCounts, HaloCtl, HaloRecord, Pos};
use crate::scenario::Scenario;
use bytemuck::{Pod, Zeroable};

pub const SHADER: Shader = Shader {
    name: "halo",
    source: include_str!("../../shaders/halo.wgsl"),
    libs: &[PARTICLE_ID, SLAB],
};

/// Records the packing buffer of `sc`'s subdomains holds per particle of the arrays: a
/// particle packs at most two (a halo copy each way from a slab as thin as its halo, or one
/// migrant), a solid particle twice as many (each with its stress state).
pub fn records_per_particle(sc: &Scenario) -> u32 {
    match sc.solids.is_some() {
        true => 4,
        false => 2,
    }
}

/// The most records the packing buffer can need for arrays of `n` entries: `per_particle`
/// each, but no more than one storage binding of `max_binding` bytes holds. Only a slab as
/// thin as its halo, or a rebalance that moves most of a rank's particles, packs every
/// particle; the cap binds only ranks of millions of particles (128 B an entry would reach an
/// H200's 2 047 MiB binding at 1.7 × 10⁷ entries), and a step that packs more stops with a
/// message. The buffer starts far smaller ([`Halo::new`]) and grows to this at most.
pub fn records_capacity(per_particle: u32, n: u32, max_binding: u64) -> u32 {
    let fit = max_binding / std::mem::size_of::<HaloRecord>() as u64;
    (per_particle as u64 * n as u64)
        .min(fit)
        .min(u32::MAX as u64) as u32
}

/// A packing buffer of `capacity` records.
fn records_buffer(device: &wgpu::Device, capacity: u32) -> wgpu::Buffer {
    let bytes = capacity as u64 * std::mem::size_of::<HaloRecord>() as u64;
    storage(device, "halo records", bytes)
}

/// The halo kernels' buffers on the arrays of parity `p`: the particle arrays, the pass's own
/// (its control, counters, messages, layer loads and arrivals) and where the arrivals' last
/// rates go.
fn bindings<'a>(
    b: &'a ParticleBuffers,
    p: usize,
    own: [&'a wgpu::Buffer; 6],
    arrival_rate: &'a wgpu::Buffer,
) -> Bindings<'a> {
    let [ctl, counts, records, layer_load, arrivals, restore_index] = own;
    b.at(p)
        .with("halo_ctl", ctl)
        .with("halo_counts", counts)
        .with("halo_out", records)
        .with("layer_load", layer_load)
        .with("halo_arrivals", arrivals)
        .with("arrival_rate", arrival_rate)
        .with("restore_index", restore_index)
}

/// Rank `rank`'s part of `slabs` with a halo of `layers` ([`halo_layers`](crate::decomposition::halo_layers)): what `halo_pack`
/// needs to know (the records' capacity is the pass's own, set by [`Halo::new`]).
pub fn control(slabs: &Slabs, rank: usize, layers: u32) -> HaloCtl {
    let own = slabs.range(rank);
    HaloCtl {
        axis: slabs.axis as u32,
        own_lo: own.start,
        own_hi: own.end,
        layers,
        lower: (rank > 0) as u32,
        upper: (rank + 1 < slabs.ranks()) as u32,
        capacity: 0,
        lean: 0,
        moving: 0,
        pad: [0; 3],
    }
}

pub struct Halo {
    tail: ParityKernel,
    count: ParityKernel,
    layout: ParityKernel,
    pack: ParityKernel,
    /// `halo_unpack` with the arrivals' last rates into `rate`, and into `rate_sorted` (after
    /// an overlapped step's first sort).
    unpack: [ParityKernel; 2],
    drop: ParityKernel,
    index: ParityKernel,
    restore: ParityKernel,
    forget: ParityKernel,
    count_layers: ParityKernel,
    ctl: wgpu::Buffer,
    counts: wgpu::Buffer,
    /// Where the counts are copied in the packing's own submission.
    counts_staging: wgpu::Buffer,
    records: wgpu::Buffer,
    layer_load: wgpu::Buffer,
    /// The messages received ([`HaloArrivals`]), and their particles and states.
    arrivals: wgpu::Buffer,
    arrived: u32,
    /// The density filter's index of the copies received (`halo_index`), grown to their
    /// number by [`Halo::upload_restoring`].
    restore_index: wgpu::Buffer,
    /// Cell layers along the cut axis.
    layers: u32,
    /// Cell layers of halo.
    pub thickness: u32,
    /// How the next packing writes its copies ([`Halo::set_lean`]).
    copies: Copies,
    /// Records `halo_out` holds.
    capacity: u32,
    /// Records it may grow to ([`records_capacity`]).
    max_capacity: u32,
    /// Times it grew ([`Halo::reserve`]).
    pub growths: u32,
    n: u32,
}

/// What a halo copy carries to the neighbour: what the neighbour's passes read of it (its
/// place, (v, ρ) and code word) and its `id_high`; not the last rates nor the energy, which only a
/// migrant goes on integrating (a copy is excluded before the corrector): 40 bytes where a
/// record is 64.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct HaloCopy {
    pub pos: Pos,
    pub velrho: [f32; 4],
    pub code: u32,
    pub id_high: u32,
}

/// Words of a message's header: its sections' counts.
pub const HEADER_WORDS: u32 = 3;
const RECORD_BYTES: usize = std::mem::size_of::<HaloRecord>();

/// How a message carries its halo copies: as [`HaloCopy`]s (40 bytes), or `lean` as the
/// density filter's exchange needs them (halo.wgsl `LEAN_WORDS`: its owner's code word and
/// corrected ρ, all `halo_restore` gives a copy back, with wide ids the id's high bits too: 8
/// or 12 bytes) and with no stress states.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Copies {
    pub lean: bool,
    pub wide_ids: bool,
}

impl Copies {
    /// Bytes of a copy.
    pub fn bytes(self) -> usize {
        match self.lean {
            true => 4 * (2 + self.wide_ids as usize),
            false => std::mem::size_of::<HaloCopy>(),
        }
    }
}

/// The sections' counts in the header of a message to a neighbour, which must be whole. A
/// message travels as `halo_pack` writes it on the GPU: a header of three counts, then three
/// sections: the migrants (whole [`HaloRecord`]s), the solid particles' stress states (records
/// too, one for each solid migrant or copy), the halo copies ([`HaloCopy`]s). The receiver
/// uploads it as it came, and `halo_unpack` (or, for the density filter, `halo_restore`) reads
/// it there: the host reads no record.
pub fn message_header(bytes: &[u8], copies: Copies) -> Result<[u32; 3]> {
    let malformed = || {
        anyhow!(
            "a neighbour's halo message of {} bytes is malformed",
            bytes.len()
        )
    };
    let head = bytes
        .get(..4 * HEADER_WORDS as usize)
        .ok_or_else(malformed)?;
    let counts: [u32; 3] = bytemuck::pod_read_unaligned(head);
    ensure!(
        bytes.len() as u64 == 4 * message_words(&counts, copies),
        malformed()
    );
    Ok(counts)
}

/// What one `halo_pack` found: the messages to the neighbours, the rank's own live particles,
/// and where the free tail of the arrays starts.
#[derive(Default)]
pub struct Packed {
    /// To the neighbour below and above, as they travel ([`message_header`]).
    pub messages: [Vec<u8>; 2],
    /// The records of each section of each ([`HaloCounts::sizes`]).
    pub sizes: [u32; 6],
    pub owned: u32,
    pub tail: u32,
    /// The records the packing needed where they did not fit the buffer (then no message is
    /// read): [`Halo::reserve`] them and pack again.
    pub needed: Option<u32>,
}

impl Packed {
    /// Particles that left the rank's own layers, sent to their new owners.
    pub fn migrants(&self) -> u32 {
        self.sizes[0] + self.sizes[3]
    }

    /// Halo copies sent.
    pub fn copies(&self) -> u32 {
        self.sizes[2] + self.sizes[5]
    }
}

/// Words of the message with section sizes `sizes` (as `message_words` in halo.wgsl).
fn message_words(sizes: &[u32], copies: Copies) -> u64 {
    let records = (sizes[0] as u64 + sizes[1] as u64) * (RECORD_BYTES / 4) as u64;
    HEADER_WORDS as u64 + records + sizes[2] as u64 * (copies.bytes() / 4) as u64
}

impl Halo {
    /// The pass of a subdomain `ctl` on a grid of `layers` cell layers along its cut axis, its
    /// packing buffer of `ctl.capacity` records to start with (`subdomain::starting_records`),
    /// grown as the steps need ([`Halo::reserve`]) up to [`records_capacity`].
    pub fn new(
        device: &wgpu::Device,
        module: &ShaderModule,
        b: &ParticleBuffers,
        ctl: HaloCtl,
        layers: u32,
        records_per_particle: u32,
        wide_ids: bool,
    ) -> Result<Self> {
        let max_binding = device.limits().max_storage_buffer_binding_size;
        let max_capacity = records_capacity(records_per_particle, b.n, max_binding);
        let ctl = HaloCtl {
            capacity: ctl.capacity.clamp(1, max_capacity),
            ..ctl
        };
        let ctl_buffer = uniform_init(device, "halo ctl", &ctl);
        let layer_load = storage(device, "layer load", 4 * layers as u64);
        let counts = storage(
            device,
            "halo counts",
            std::mem::size_of::<HaloCounts>() as u64,
        );
        let records = records_buffer(device, ctl.capacity);
        let arrivals = uniform_init(device, "halo arrivals", &HaloArrivals::default());
        let restore_index = storage(device, "restore index", 4);
        let own = [
            &ctl_buffer,
            &counts,
            &records,
            &layer_load,
            &arrivals,
            &restore_index,
        ];
        let bufs = |p: usize| bindings(b, p, own, &b.rate);
        let kernel = |entry: &str| ParityKernel::new(device, module, entry, bufs);
        let sorted = |p: usize| bindings(b, p, own, &b.rate_sorted);
        Ok(Self {
            tail: kernel("halo_tail")?,
            count: kernel("halo_count")?,
            layout: kernel("halo_layout")?,
            pack: kernel("halo_pack")?,
            unpack: [
                kernel("halo_unpack")?,
                ParityKernel::new(device, module, "halo_unpack", sorted)?,
            ],
            drop: kernel("halo_drop")?,
            index: kernel("halo_index")?,
            restore: kernel("halo_restore")?,
            forget: kernel("halo_forget")?,
            count_layers: kernel("count_layers")?,
            ctl: ctl_buffer,
            counts_staging: readback_buffer(
                device,
                "halo counts",
                std::mem::size_of::<HaloCounts>() as u64,
            ),
            counts,
            records,
            layer_load,
            arrivals,
            arrived: 0,
            restore_index,
            layers,
            thickness: ctl.layers,
            copies: Copies {
                lean: false,
                wide_ids,
            },
            capacity: ctl.capacity,
            max_capacity,
            growths: 0,
            n: b.n,
        })
    }

    /// Makes the packing buffer hold at least `needed` records (half as many again, or twice
    /// its size, whichever is more, up to [`records_capacity`]); an error past that. The
    /// buffer's records are not kept: call it before packing or uploading.
    pub fn reserve(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        b: &ParticleBuffers,
        needed: usize,
    ) -> Result<()> {
        if needed <= self.capacity as usize {
            return Ok(());
        }
        ensure!(
            needed <= self.max_capacity as usize,
            "{needed} halo and migrant records, more than the subdomain's {} fit (one storage \
             binding, or two a particle of its arrays): more particles near the cuts than \
             its buffers were made for",
            self.max_capacity
        );
        let grown = (needed as u64 * 3 / 2).max(2 * self.capacity as u64);
        self.capacity = grown.min(self.max_capacity as u64) as u32;
        self.growths += 1;
        self.records = records_buffer(device, self.capacity);
        self.rebind(device, b)?;
        let at = std::mem::offset_of!(HaloCtl, capacity) as u64;
        queue.write_buffer(&self.ctl, at, bytemuck::bytes_of(&self.capacity));
        log::debug!("halo records: room for {} now", self.capacity);
        Ok(())
    }

    /// Binds the kernels to the pass's buffers again, one of them new.
    fn rebind(&mut self, device: &wgpu::Device, b: &ParticleBuffers) -> Result<()> {
        let own = [
            &self.ctl,
            &self.counts,
            &self.records,
            &self.layer_load,
            &self.arrivals,
            &self.restore_index,
        ];
        let bufs = |p: usize| bindings(b, p, own, &b.rate);
        let [unpack, unpack_sorted] = &mut self.unpack;
        unpack_sorted.rebind(device, |p| bindings(b, p, own, &b.rate_sorted))?;
        for kernel in [
            &mut self.tail,
            &mut self.count,
            &mut self.layout,
            &mut self.pack,
            unpack,
            &mut self.drop,
            &mut self.index,
            &mut self.restore,
            &mut self.forget,
            &mut self.count_layers,
        ] {
            kernel.rebind(device, bufs)?;
        }
        Ok(())
    }

    /// The subdomain's `HaloCtl` uniform, which an overlapped step's interaction reads too.
    pub fn slab(&self) -> &wgpu::Buffer {
        &self.ctl
    }

    /// GPU memory of the pass's own buffers, in bytes: the packing buffer's records as it
    /// stands ([`Halo::reserve`] grows it) and the layer loads.
    pub fn bytes(&self) -> u64 {
        self.records.size() + self.layer_load.size()
    }

    /// The subdomain of rank `rank` under `slabs` from now on; `moving`: while the cuts move to
    /// `slabs`, whose packings take what lies outside the slab only (no halo), the excluded
    /// particles that keep their ids too.
    pub fn set_cuts(&self, queue: &wgpu::Queue, slabs: &Slabs, rank: usize, moving: bool) {
        let mut ctl = HaloCtl {
            capacity: self.capacity,
            lean: self.copies.lean as u32,
            ..control(slabs, rank, self.thickness)
        };
        if moving {
            (ctl.lower, ctl.upper, ctl.moving) = (0, 0, 1);
        }
        queue.write_buffer(&self.ctl, 0, bytemuck::bytes_of(&ctl));
    }

    /// Packs the copies of the next packings lean ([`Copies`]: for the density filter's
    /// exchange), or as a step's exchange needs them.
    pub fn set_lean(&mut self, queue: &wgpu::Queue, lean: bool) {
        self.copies.lean = lean;
        let at = std::mem::offset_of!(HaloCtl, lean) as u64;
        queue.write_buffer(&self.ctl, at, bytemuck::bytes_of(&(lean as u32)));
    }

    /// The rank's own particles per cell layer along the cut axis, weighted as
    /// `decomposition::weight` (2 for a moving particle, 1 for a boundary one: doubled), from
    /// the arrays of parity `p`. Waits for the GPU.
    pub fn layer_load(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        p: usize,
    ) -> Result<Vec<f64>> {
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.clear_buffer(&self.layer_load, 0, None);
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            self.count_layers.dispatch(&mut pass, p, self.n);
        }
        queue.submit([encoder.finish()]);
        let load = read::<u32>(device, queue, &self.layer_load, self.layers as usize)?;
        Ok(load.iter().map(|&w| 0.5 * w as f64).collect())
    }

    /// Zeroes the counters; record outside a compute pass, before `encode_pack`.
    pub fn clear(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.counts, 0, None);
    }

    /// Copies the counters for [`Halo::read`]; record after the pass that packed.
    pub fn copy_counts(&self, encoder: &mut wgpu::CommandEncoder) {
        let bytes = std::mem::size_of::<HaloCounts>() as u64;
        encoder.copy_buffer_to_buffer(&self.counts, 0, &self.counts_staging, 0, bytes);
    }

    /// Packs the migrants and the halo copies of the arrays of parity `p` into the messages to
    /// the neighbours (after the predictor, before the sort); the migrants stay until
    /// `encode_drop`, as halo copies.
    pub fn encode_pack(&self, pass: &mut wgpu::ComputePass<'_>, p: usize) {
        self.tail.dispatch_groups(pass, p, 1);
        self.count.dispatch(pass, p, self.n);
        self.layout.dispatch_groups(pass, p, 1);
        self.pack.dispatch(pass, p, self.n);
    }

    /// Where the free tail of the arrays of parity `q` starts, sorted into them just now (an
    /// overlapped step's first sort), for `encode_unpack`.
    pub fn encode_tail(&self, pass: &mut wgpu::ComputePass<'_>, q: usize) {
        self.tail.dispatch_groups(pass, q, 1);
    }

    /// Sets where the arrivals go in place of the last sort's free tail (the first step's:
    /// no sort has run).
    pub fn set_tail(&self, queue: &wgpu::Queue, tail: u32) {
        let at = std::mem::offset_of!(HaloCounts, tail) as u64;
        queue.write_buffer(&self.counts, at, bytemuck::bytes_of(&tail));
    }

    /// Uploads the messages the neighbours sent ([`message_header`], at most two; with `lean`,
    /// the density filter's: [`Copies`]), as they came, for the next `encode_unpack`; grows the
    /// buffer where they need it. Returns their particles (migrants and copies), which go after
    /// the free tail.
    pub fn upload_arrivals(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        b: &ParticleBuffers,
        messages: &[Vec<u8>],
        lean: bool,
    ) -> Result<u32> {
        let copies = Copies {
            lean,
            ..self.copies
        };
        ensure!(
            messages.len() <= 2,
            "{} halo messages arrived where a subdomain has two neighbours",
            messages.len()
        );
        let mut arrivals = HaloArrivals {
            copy_words: copies.bytes() as u32 / 4,
            ..Default::default()
        };
        let mut words = 0u64;
        for (m, bytes) in messages.iter().enumerate() {
            let [migrants, states, n_copies] = message_header(bytes, copies)?;
            arrivals.messages[m] = [words as u32, migrants, states, n_copies];
            arrivals.particles += migrants + n_copies;
            arrivals.states += states;
            words += bytes.len() as u64 / 4;
        }
        self.reserve(
            device,
            queue,
            b,
            words.div_ceil(RECORD_BYTES as u64 / 4) as usize,
        )?;
        for (bytes, m) in messages.iter().zip(arrivals.messages) {
            queue.write_buffer(&self.records, 4 * m[0] as u64, bytes);
        }
        queue.write_buffer(&self.arrivals, 0, bytemuck::bytes_of(&arrivals));
        self.arrived = arrivals.particles + arrivals.states;
        Ok(arrivals.particles)
    }

    /// Writes the arrivals [`Halo::upload_arrivals`] uploaded last into the arrays of parity
    /// `p` after their free tail, their last rates into `rate`, or with `sorted_rates` into
    /// `rate_sorted` (after an overlapped step's first sort).
    pub fn encode_unpack(&self, pass: &mut wgpu::ComputePass<'_>, p: usize, sorted_rates: bool) {
        if self.arrived > 0 {
            self.unpack[sorted_rates as usize].dispatch(pass, p, self.arrived);
        }
    }

    /// Excludes the halo copies and the migrants sent from the arrays of parity `q` (after the
    /// interaction).
    pub fn encode_drop(&self, pass: &mut wgpu::ComputePass<'_>, q: usize) {
        self.drop.dispatch(pass, q, self.n);
    }

    /// Uploads the lean copies the neighbours sent for the density filter (as
    /// [`Halo::upload_arrivals`]) and makes the index `encode_restore` builds of them room for
    /// them all: a power of two of entries at least twice their number, so that its probes
    /// stay short.
    pub fn upload_restoring(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        b: &ParticleBuffers,
        messages: &[Vec<u8>],
    ) -> Result<()> {
        let copies = self.upload_arrivals(device, queue, b, messages, true)?;
        let entries = (2 * copies as u64).next_power_of_two();
        if 4 * entries > self.restore_index.size() {
            self.restore_index = storage(device, "restore index", 4 * entries);
            self.rebind(device, b)?;
        }
        Ok(())
    }

    /// Empties the index of the copies received; record outside a compute pass, before
    /// `encode_restore`.
    pub fn clear_index(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.restore_index, 0, None);
    }

    /// Gives the halo copies of the arrays of parity `q`, excluded by `encode_drop`, their
    /// owners' code word and corrected density among the copies [`Halo::upload_restoring`]
    /// uploaded (for the density filter), found by id in the index it builds first.
    pub fn encode_restore(&self, pass: &mut wgpu::ComputePass<'_>, q: usize) {
        self.index.dispatch(pass, q, self.arrived);
        self.restore.dispatch(pass, q, self.n);
    }

    /// Frees the entries of the arrays of parity `q` excluded since the last sort (at the end
    /// of a step, after the last pass that reads them by id).
    pub fn encode_forget(&self, pass: &mut wgpu::ComputePass<'_>, q: usize) {
        self.forget.dispatch(pass, q, self.n);
    }

    /// Reads what the last `halo_pack` packed, once its submission (with `copy_counts`) is
    /// made: the counts, then the two messages, as they travel. Waits for the GPU.
    pub fn read(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Packed> {
        let counts: HaloCounts =
            bytemuck::pod_read_unaligned(&map_read::<u8>(device, &self.counts_staging)?);
        let lower = message_words(&counts.sizes[..3], self.copies) as usize;
        let words = lower + message_words(&counts.sizes[3..], self.copies) as usize;
        if counts.fits == 0 {
            return Ok(Packed {
                needed: Some(words.div_ceil(RECORD_BYTES / 4) as u32),
                ..Default::default()
            });
        }
        let mut messages = read::<u8>(device, queue, &self.records, 4 * words)?;
        let upper = messages.split_off(4 * lower);
        Ok(Packed {
            messages: [messages, upper],
            sizes: counts.sizes,
            owned: counts.owned,
            tail: counts.tail,
            needed: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A message as the tests build it ([`message_header`]).
    #[derive(Debug, Default, PartialEq)]
    struct Message {
        migrants: Vec<HaloRecord>,
        states: Vec<HaloRecord>,
        copies: Vec<HaloCopy>,
    }

    impl Message {
        fn to_wire(&self) -> Vec<u8> {
            let counts = [self.migrants.len(), self.states.len(), self.copies.len()];
            let mut bytes = bytemuck::cast_slice(&counts.map(|c| c as u32)).to_vec();
            bytes.extend_from_slice(bytemuck::cast_slice(&self.migrants));
            bytes.extend_from_slice(bytemuck::cast_slice(&self.states));
            bytes.extend_from_slice(bytemuck::cast_slice(&self.copies));
            bytes
        }
    }

    /// What `halo_pack` writes of `r` as a halo copy.
    fn copy_of(r: &HaloRecord) -> HaloCopy {
        HaloCopy {
            pos: r.pos,
            velrho: r.velrho,
            code: r.code,
            id_high: r.id_high,
        }
    }

    /// The packing buffer holds two records an entry (four with solids), but never more than
    /// one storage binding: on lavapipe's 128 MiB, 2²¹ records of 64 bytes.
    #[test]
    fn the_packing_buffer_fits_one_binding() {
        assert_eq!(records_capacity(2, 1000, 128 << 20), 2000);
        assert_eq!(records_capacity(4, 1000, 128 << 20), 4000);
        assert_eq!(records_capacity(2, 10_000_000, 128 << 20), 1 << 21);
        assert_eq!(records_capacity(2, u32::MAX, u64::MAX), u32::MAX);
    }

    /// A halo message carries migrants and solid states whole and copies lean (40 bytes), in
    /// sections after a header of their counts, which the receiver reads back and checks
    /// against the message's length; a message that is not whole is refused.
    #[test]
    fn a_halo_message_sends_copies_lean_and_the_rest_whole() {
        let record = |k: u32| HaloRecord {
            pos: Pos {
                off: [0.1 * k as f32, 0.2, 0.3],
                block: k,
            },
            velrho: [k as f32, -2.0, 0.5, 1000.0 + k as f32],
            rate: [4.0 + k as f32; 4],
            code: 0x1000_0000 | k,
            id_high: k % 2,
            energy: [5.0, 6.0 + k as f32],
        };
        let sent = Message {
            migrants: vec![record(2)],
            states: vec![record(3)],
            copies: [record(1), record(4), record(5)]
                .iter()
                .map(copy_of)
                .collect(),
        };
        let bytes = sent.to_wire();
        assert_eq!(std::mem::size_of::<HaloCopy>(), 40);
        assert_eq!(bytes.len(), 12 + 2 * 64 + 3 * 40);
        let whole = Copies {
            lean: false,
            wide_ids: false,
        };
        assert_eq!(message_header(&bytes, whole).unwrap(), [1, 1, 3]);
        assert_eq!(message_words(&[1, 1, 3], whole) * 4, bytes.len() as u64);
        assert!(message_header(&bytes[..bytes.len() - 4], whole).is_err());
        assert!(message_header(&bytes[..8], whole).is_err());
        let empty = Message::default().to_wire();
        assert_eq!(message_header(&empty, whole).unwrap(), [0; 3]);
        // The density filter's copies: 8 bytes, 12 with wide ids, and no states.
        let lean = Copies {
            lean: true,
            wide_ids: false,
        };
        let wide = Copies {
            wide_ids: true,
            ..lean
        };
        let mut filter = bytemuck::cast_slice(&[0u32, 0, 3]).to_vec();
        filter.extend_from_slice(&[0; 3 * 8]);
        assert_eq!(message_header(&filter, lean).unwrap(), [0, 0, 3]);
        assert!(message_header(&filter, wide).is_err());
        filter.extend_from_slice(&[0; 3 * 4]);
        assert_eq!(message_header(&filter, wide).unwrap(), [0, 0, 3]);
        assert_eq!(message_words(&[0, 0, 3], wide) * 4, filter.len() as u64);
    }
}

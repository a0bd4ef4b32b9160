//! Per-stage GPU time of a step (`wgsph bench --stages`): each stage of the step recorded in a
//! compute pass of its own, between two timestamp queries. Only for profiling: splitting the
//! step into passes changes its timing a little (not its results), and the timestamps need the
//! adapter's optional `TIMESTAMP_QUERY` feature.

use anyhow::{bail, Result};

use crate::gpu::buffers::{map_read, readback_buffer};

/// Most stages one step records (two queries each).
const MAX_STAGES: u32 = 32;

/// The GPU time of one stage, summed over the profiled steps.
#[derive(Clone, Debug, PartialEq)]
pub struct StageTime {
    pub name: &'static str,
    pub seconds: f64,
}

/// Where a step's stages are recorded: all in one compute pass (a run), or each in its own
/// pass between two timestamps (profiling). One lives on the stack per step, so the size
/// difference of its variants costs nothing.
#[allow(clippy::large_enum_variant)]
pub(super) enum Recorder<'e> {
    Shared(wgpu::ComputePass<'e>),
    Timed {
        encoder: &'e mut wgpu::CommandEncoder,
        profiler: &'e mut Profiler,
    },
    /// Only the stages' names, in order (the bytes each moves: `traffic`); records nothing.
    Names(&'e mut Vec<&'static str>),
}

impl Recorder<'_> {
    /// Records the dispatches of stage `name`.
    pub(super) fn stage(
        &mut self,
        name: &'static str,
        record: impl FnOnce(&mut wgpu::ComputePass<'_>),
    ) {
        match self {
            Recorder::Shared(pass) => record(pass),
            Recorder::Names(names) => names.push(name),
            Recorder::Timed { encoder, profiler } => {
                let first = profiler.open(name);
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(name),
                    timestamp_writes: Some(wgpu::ComputePassTimestampWrites {
                        query_set: &profiler.queries,
                        beginning_of_pass_write_index: Some(first),
                        end_of_pass_write_index: Some(first + 1),
                    }),
                });
                record(&mut pass);
            }
        }
    }
}

/// Timestamp queries for one step's stages, and the times summed so far.
pub(super) struct Profiler {
    queries: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    staging: wgpu::Buffer,
    /// Nanoseconds per timestamp tick.
    period_ns: f64,
    /// The stages recorded since the last [`Profiler::collect`], in order.
    open: Vec<&'static str>,
    totals: Vec<StageTime>,
}

impl Profiler {
    pub(super) fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Profiler> {
        if !device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            bail!(
                "the adapter has no timestamp queries (wgpu feature TIMESTAMP_QUERY), which \
                 timing the stages needs; bench without --stages"
            );
        }
        let bytes = 2 * MAX_STAGES as u64 * 8;
        Ok(Profiler {
            queries: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("stage timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * MAX_STAGES,
            }),
            resolved: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("stage timestamps resolved"),
                size: bytes,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            staging: readback_buffer(device, "stage timestamps readback", bytes),
            period_ns: queue.get_timestamp_period() as f64,
            open: Vec::new(),
            totals: Vec::new(),
        })
    }

    /// The first of the two queries of a new stage.
    fn open(&mut self, name: &'static str) -> u32 {
        assert!(
            (self.open.len() as u32) < MAX_STAGES,
            "a profiled step records at most {MAX_STAGES} stages"
        );
        self.open.push(name);
        2 * (self.open.len() as u32 - 1)
    }

    /// Copies the recorded stages' timestamps where [`Profiler::collect`] reads them, at the
    /// end of the step's encoder.
    pub(super) fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        let n = 2 * self.open.len() as u32;
        if n > 0 {
            encoder.resolve_query_set(&self.queries, 0..n, &self.resolved, 0);
            encoder.copy_buffer_to_buffer(&self.resolved, 0, &self.staging, 0, n as u64 * 8);
        }
    }

    /// After the step's submission: adds each stage's time to its total.
    pub(super) fn collect(&mut self, device: &wgpu::Device) -> Result<()> {
        if self.open.is_empty() {
            return Ok(());
        }
        let bytes = map_read::<u8>(device, &self.staging)?;
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&bytes[..self.open.len() * 16]);
        for (k, name) in self.open.drain(..).enumerate() {
            // A timer that wraps or runs backwards between passes counts as zero, not as years.
            let seconds =
                ticks[2 * k + 1].saturating_sub(ticks[2 * k]) as f64 * self.period_ns * 1e-9;
            match self.totals.iter_mut().find(|s| s.name == name) {
                Some(s) => s.seconds += seconds,
                None => self.totals.push(StageTime { name, seconds }),
            }
        }
        Ok(())
    }

    pub(super) fn totals(&self) -> &[StageTime] {
        &self.totals
    }
}

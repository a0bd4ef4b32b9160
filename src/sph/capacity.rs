//! How many particles an adapter can run, and the check runs make before they allocate.

use anyhow::{bail, Result};

use crate::gpu::GpuContext;

/// How many particles fit an adapter, and the limit that binds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Capacity {
    pub particles: u64,
    /// The binding limit: a wgpu limit's name, or the particle id's width.
    pub bound_by: &'static str,
    /// That limit's value (bytes for the wgpu limits).
    pub limit: u64,
}

/// Bytes of the largest per-particle array (positions, (v, ρ), rates: 16 bytes a particle);
/// every other per-particle array is smaller, and the hash grid has at most 2 slots of 4 bytes
/// a particle.
const LARGEST_ARRAY_BYTES_PER_PARTICLE: u64 = 16;

/// The most particles a device with `limits` can run: each per-particle array must fit one
/// storage binding and one buffer, and ids have 32 bits (wide ids, `layout::IdSplit`, past
/// 2^28).
pub fn capacity(limits: &wgpu::Limits) -> Capacity {
    let per = LARGEST_ARRAY_BYTES_PER_PARTICLE;
    [
        Capacity {
            particles: limits.max_storage_buffer_binding_size / per,
            bound_by: "max_storage_buffer_binding_size",
            limit: limits.max_storage_buffer_binding_size,
        },
        Capacity {
            particles: limits.max_buffer_size / per,
            bound_by: "max_buffer_size",
            limit: limits.max_buffer_size,
        },
        Capacity {
            particles: MAX_PARTICLES,
            bound_by: "the 32-bit particle id",
            limit: MAX_PARTICLES,
        },
    ]
    .into_iter()
    .min_by_key(|c| c.particles)
    .expect("three candidates")
}

/// The most particles a run can have, over all its ranks: one id is the free entries'.
pub const MAX_PARTICLES: u64 = u32::MAX as u64 - 1;

/// Fails, naming the limit, when a run of `n` particles (all its ranks') has more than ids
/// can number.
pub fn check_ids(n: usize) -> Result<()> {
    if n as u64 > MAX_PARTICLES {
        bail!(
            "the case has {n} particles, more than the {MAX_PARTICLES} that 32-bit particle \
             ids number: use a coarser particles.dx_m"
        );
    }
    Ok(())
}

/// Host memory a particle takes while a case is built and run: the case's particle (64 bytes),
/// the packed arrays uploaded from (36), the upload's staging copy, and an output's read-back
/// and file buffers (about 60), with room to spare. Measured peak resident memory of a run of
/// 10^6 particles on lavapipe: 447 MB, device memory included (docs/performance.md, "On the
/// host").
pub const HOST_BYTES_PER_PARTICLE: u64 = 250;

/// What a CPU adapter's device memory adds on the host (the run's GPU buffers, about 120 bytes
/// a particle, and the driver's copies).
const CPU_ADAPTER_BYTES_PER_PARTICLE: u64 = 200;

/// The host memory this process may still take: the system's available memory
/// (`MemAvailable`), or less where a control group (a batch job's) limits it; None where
/// neither can be read.
pub fn host_memory_available() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok();
    let available = meminfo.as_deref().and_then(mem_available);
    let cgroup = |f: &str| -> Option<u64> {
        std::fs::read_to_string(format!("/sys/fs/cgroup/{f}"))
            .ok()?
            .trim()
            .parse()
            .ok()
    };
    let in_group =
        cgroup("memory.max").map(|max| max.saturating_sub(cgroup("memory.current").unwrap_or(0)));
    [available, in_group].into_iter().flatten().min()
}

/// `MemAvailable` of a /proc/meminfo text, in bytes.
fn mem_available(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

/// The most particles a run on `ctx` can build and run, and why: the adapter's limits
/// ([`capacity`]), and the host's memory at [`HOST_BYTES_PER_PARTICLE`] (more on a CPU
/// adapter, whose device memory is the host's) when `host_bytes` is known. Checked before
/// the case's particles are made (issue 64: 150 million particles exhausted the host's memory
/// before the adapter's limit was looked at).
///
/// Without `ctx` (a run over several ranks, each on its own slab), the host's memory alone:
/// every rank builds the whole case.
pub fn run_budget(ctx: Option<&GpuContext>, host_bytes: Option<u64>) -> (u64, String) {
    let adapter = ctx.map(|ctx| {
        let cap = capacity(&ctx.limits);
        (
            cap.particles,
            format!("the adapter '{}''s {}", ctx.info.name, cap.bound_by),
        )
    });
    let on_cpu = ctx.is_some_and(|c| c.info.device_type == wgpu::DeviceType::Cpu);
    let per = HOST_BYTES_PER_PARTICLE + on_cpu as u64 * CPU_ADAPTER_BYTES_PER_PARTICLE;
    let host = host_bytes.map(|b| {
        (
            b / per,
            format!(
                "the host's memory: {:.1} GiB available, at about {per} bytes a particle,",
                b as f64 / (1u64 << 30) as f64
            ),
        )
    });
    (adapter.into_iter().chain(host))
        .min_by_key(|(n, _)| *n)
        .unwrap_or((MAX_PARTICLES, "the 32-bit particle id's".into()))
}

/// Fails, saying how many fit and which limit binds, when `n` particles do not fit `ctx`'s
/// device (a whole run's, or a subdomain's arrays). Runs call this before they create anything.
pub fn check_capacity(ctx: &GpuContext, n: usize) -> Result<()> {
    let cap = capacity(&ctx.limits);
    if n as u64 > cap.particles {
        let limit = if cap.bound_by.starts_with("max_") {
            format!("{} = {} MiB", cap.bound_by, cap.limit >> 20)
        } else {
            cap.bound_by.to_string()
        };
        bail!(
            "the case has {n} particles but adapter '{}' fits at most {}: its {limit} holds \
             {} particles of {LARGEST_ARRAY_BYTES_PER_PARTICLE} bytes per array. Use a coarser \
             particles.dx_m (the count scales as dx^-dim) or a GPU with larger limits \
             (`wgsph info` lists them)",
            ctx.info.name,
            cap.particles,
            cap.particles
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn available_memory_is_read_from_meminfo() {
        let text = "MemTotal:       24576000 kB\nMemFree: 1 kB\nMemAvailable:   1024 kB\n";
        assert_eq!(mem_available(text), Some(1 << 20));
        assert_eq!(mem_available("MemTotal: 5 kB\n"), None);
        assert_eq!(mem_available("MemAvailable: lots\n"), None);
    }

    /// Without an adapter (a run over ranks), the host's memory binds; with neither known,
    /// the particle id.
    #[test]
    fn the_host_memory_bounds_a_run() {
        let (n, why) = run_budget(None, Some(1 << 30));
        assert_eq!(n, (1 << 30) / HOST_BYTES_PER_PARTICLE);
        assert!(
            why.contains("host's memory") && why.contains("1.0 GiB"),
            "{why}"
        );
        assert_eq!(run_budget(None, None).0, MAX_PARTICLES);
    }
}

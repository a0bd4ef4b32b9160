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

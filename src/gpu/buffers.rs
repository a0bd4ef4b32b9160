//! Buffer creation and (rare) readback. Readback happens only for outputs, probes and the
//! per-batch time-step state; never per particle per step.

use anyhow::{anyhow, Result};
use bytemuck::Pod;
use wgpu::util::DeviceExt;

pub const STORAGE: wgpu::BufferUsages = wgpu::BufferUsages::STORAGE
    .union(wgpu::BufferUsages::COPY_SRC)
    .union(wgpu::BufferUsages::COPY_DST);

/// A storage buffer holding `data` (at least 4 bytes, as wgpu binds no empty buffers).
pub fn storage_init<T: Pod>(device: &wgpu::Device, label: &str, data: &[T]) -> wgpu::Buffer {
    let bytes: &[u8] = bytemuck::cast_slice(data);
    let padded;
    let contents = if bytes.len() < 4 {
        padded = [0u8; 4];
        &padded[..]
    } else {
        bytes
    };
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage: STORAGE,
    })
}

/// An uninitialised (zeroed by wgpu) storage buffer of `bytes` (at least 4).
pub fn storage(device: &wgpu::Device, label: &str, bytes: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(4),
        usage: STORAGE,
        mapped_at_creation: false,
    })
}

pub fn uniform_init<T: Pod>(device: &wgpu::Device, label: &str, value: &T) -> wgpu::Buffer {
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytemuck::bytes_of(value),
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
    })
}

/// Copies `buffer` (the first `len` elements) back to the host. Waits for the GPU.
pub fn read<T: Pod>(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    len: usize,
) -> Result<Vec<T>> {
    let bytes = (len * std::mem::size_of::<T>()) as u64;
    if bytes == 0 {
        return Ok(Vec::new());
    }
    let staging = readback_buffer(device, "readback", bytes);
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("readback"),
    });
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, bytes);
    queue.submit([encoder.finish()]);
    map_read(device, &staging)
}

/// A host-mappable buffer that copies are made into, for [`map_read`].
pub fn readback_buffer(device: &wgpu::Device, label: &str, bytes: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(4),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Waits for the GPU and returns the contents of `staging` (a [`readback_buffer`] whose copies
/// have been submitted) as elements of `T`, copied once from the mapping; leaves it unmapped
/// for reuse.
pub fn map_read<T: Pod>(device: &wgpu::Device, staging: &wgpu::Buffer) -> Result<Vec<T>> {
    let (tx, rx) = std::sync::mpsc::channel();
    staging.slice(..).map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| anyhow!("GPU wait failed during readback: {e}"))?;
    rx.recv()
        .map_err(|_| anyhow!("readback callback dropped"))?
        .map_err(|e| anyhow!("mapping the readback buffer failed: {e}"))?;
    let view = staging
        .slice(..)
        .get_mapped_range()
        .map_err(|e| anyhow!("reading the mapped buffer failed: {e}"))?;
    let out = bytemuck::pod_collect_to_vec(&view);
    drop(view);
    staging.unmap();
    Ok(out)
}

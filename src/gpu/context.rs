//! Adapter choice and device creation.
//!
//! Prefers a hardware GPU and falls back to a software/CPU adapter (Mesa lavapipe) so that
//! everything runs headless; `--adapter` or `WGSPH_ADAPTER` (auto|gpu|cpu) override.

use std::fmt;
use std::str::FromStr;
use std::sync::{Arc, Mutex};

use anyhow::{anyhow, bail, Context, Result};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum AdapterChoice {
    /// Best hardware GPU, else a CPU adapter.
    #[default]
    Auto,
    /// A hardware GPU or nothing.
    Gpu,
    /// A CPU (software) adapter or nothing.
    Cpu,
}

impl FromStr for AdapterChoice {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(Self::Auto),
            "gpu" => Ok(Self::Gpu),
            "cpu" => Ok(Self::Cpu),
            other => bail!("unknown adapter choice '{other}': use auto, gpu or cpu"),
        }
    }
}

impl fmt::Display for AdapterChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Auto => "auto",
            Self::Gpu => "gpu",
            Self::Cpu => "cpu",
        })
    }
}

impl AdapterChoice {
    /// The command-line choice if given, else `WGSPH_ADAPTER`, else auto.
    pub fn resolve(cli: Option<AdapterChoice>) -> Result<Self> {
        if let Some(c) = cli {
            return Ok(c);
        }
        match std::env::var("WGSPH_ADAPTER") {
            Ok(v) if !v.trim().is_empty() => v
                .parse()
                .with_context(|| format!("environment variable WGSPH_ADAPTER={v}")),
            _ => Ok(Self::Auto),
        }
    }
}

/// Rank of an adapter for `auto`: lower is preferred.
fn preference(t: wgpu::DeviceType) -> u8 {
    match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    }
}

fn is_hardware(t: wgpu::DeviceType) -> bool {
    preference(t) <= 2
}

pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub limits: wgpu::Limits,
    /// The first error the device reported outside an error scope (out of memory, device
    /// lost, validation); see [`GpuFaults`].
    pub faults: GpuFaults,
}

/// The first asynchronous GPU failure of a device: out-of-memory and validation errors that no
/// error scope caught, and device loss. wgpu's default handler panics on these; a run must
/// instead stop with a message and keep its last checkpoint, so the handlers only record the
/// failure here and the solver checks it after every submission it waits for.
#[derive(Clone, Default)]
pub struct GpuFaults(Arc<Mutex<Faults>>);

#[derive(Default)]
struct Faults {
    /// Why the device was lost, if it was: the root cause of whatever failed around it.
    lost: Option<String>,
    /// The first error no scope caught.
    first: Option<String>,
}

impl GpuFaults {
    /// Installs the recording handlers on `device`.
    fn watch(&self, device: &wgpu::Device) {
        let errors = self.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            let what = match &e {
                wgpu::Error::OutOfMemory { .. } => "the GPU ran out of memory",
                wgpu::Error::Validation { .. } => "a GPU command was rejected",
                wgpu::Error::Internal { .. } => "the GPU driver failed",
            };
            errors.record(format!("{what}: {e}"));
        }));
        let lost = self.clone();
        device.set_device_lost_callback(move |reason, message| {
            let what = format!("the GPU device was lost ({reason:?}): {message}");
            log::error!("{what}");
            lost.lock().lost.get_or_insert(what);
        });
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Faults> {
        self.0.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Keeps the first failure (later ones are usually consequences of it).
    pub fn record(&self, what: String) {
        let mut f = self.lock();
        if f.first.is_none() {
            log::error!("{what}");
            f.first = Some(what);
        }
    }

    /// The failure to report, if any: the device loss when there was one (commands on a lost
    /// device fail first, but the loss is the cause), else the first error.
    pub fn first(&self) -> Option<String> {
        let f = self.lock();
        f.lost.clone().or_else(|| f.first.clone())
    }

    /// Err with the failure to report, if any.
    pub fn check(&self) -> Result<()> {
        match self.first() {
            Some(what) => Err(GpuFailure(what).into()),
            None => Ok(()),
        }
    }
}

/// A run cannot go on because the GPU failed (out of memory, device lost); the message says
/// what the driver reported.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct GpuFailure(pub String);

/// Storage buffers one kernel binds at most: WebGPU's default, which every adapter wgpu
/// supports gives (tests/shader_backends.rs checks every entry point of every shipped variant).
pub const STORAGE_BUFFERS_PER_STAGE: u32 = 8;

/// Switches off Mesa's implicit Vulkan layer `VK_LAYER_MESA_device_select` for this process,
/// unless the user steers it (`MESA_VK_DEVICE_SELECT`) or set `NODEVICE_SELECT` already. The
/// layer only moves the default device first for programs that take the first one; wgsph
/// chooses its adapter itself (`--adapter`), and to pick a default the layer connects to a
/// Wayland display, which on a headless machine prints "error: XDG_RUNTIME_DIR is invalid or
/// not set in the environment." twice on every command. Call at the start of `main`, before
/// any thread starts (it sets an environment variable).
pub fn without_mesa_device_select() {
    if std::env::var_os("MESA_VK_DEVICE_SELECT").is_none()
        && std::env::var_os("NODEVICE_SELECT").is_none()
    {
        std::env::set_var("NODEVICE_SELECT", "1");
    }
}

fn instance() -> wgpu::Instance {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = wgpu::Backends::PRIMARY;
    wgpu::Instance::new(desc)
}

/// Every adapter wgpu can see (for `wgsph info`).
pub fn list_adapters() -> Vec<(wgpu::AdapterInfo, wgpu::Limits)> {
    let adapters = pollster::block_on(instance().enumerate_adapters(wgpu::Backends::PRIMARY));
    adapters
        .iter()
        .map(|a| (a.get_info(), a.limits()))
        .collect()
}

impl GpuContext {
    pub fn new(choice: AdapterChoice) -> Result<Self> {
        Self::with_limits(choice, |_| {})
    }

    /// As [`new`](Self::new), with the device's limits lowered by `restrict` (tests use this to
    /// stand for a smaller GPU).
    pub fn with_limits(
        choice: AdapterChoice,
        restrict: impl FnOnce(&mut wgpu::Limits),
    ) -> Result<Self> {
        Self::open(choice, 0, restrict)
    }

    /// The device of rank `rank` of a run over several ranks: adapter `rank mod n` of the n
    /// adapters of the most preferred type that `choice` allows (ranks beyond n share them).
    pub fn for_rank(choice: AdapterChoice, rank: usize) -> Result<Self> {
        Self::open(choice, rank, |_| {})
    }

    fn open(
        choice: AdapterChoice,
        rank: usize,
        restrict: impl FnOnce(&mut wgpu::Limits),
    ) -> Result<Self> {
        let instance = instance();
        let mut adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::PRIMARY));
        adapters.retain(|a| match choice {
            AdapterChoice::Auto => true,
            AdapterChoice::Gpu => is_hardware(a.get_info().device_type),
            AdapterChoice::Cpu => a.get_info().device_type == wgpu::DeviceType::Cpu,
        });
        adapters.sort_by_key(|a| preference(a.get_info().device_type));
        if let Some(best) = adapters
            .first()
            .map(|a| preference(a.get_info().device_type))
        {
            adapters.retain(|a| preference(a.get_info().device_type) == best);
        }
        let n = adapters.len().max(1);
        let adapter = adapters.into_iter().nth(rank % n).ok_or_else(|| {
            anyhow!(
                "no {} adapter found (adapter choice '{choice}'). For a software adapter install \
                 Mesa's lavapipe: apt-get install mesa-vulkan-drivers libvulkan1",
                match choice {
                    AdapterChoice::Cpu => "CPU (software)",
                    AdapterChoice::Gpu => "hardware GPU",
                    AdapterChoice::Auto => "Vulkan/Metal/DX12",
                }
            )
        })?;
        let info = adapter.get_info();
        let have = adapter.limits();
        if have.max_storage_buffers_per_shader_stage < STORAGE_BUFFERS_PER_STAGE {
            bail!(
                "adapter '{}' allows {} storage buffers per shader stage; wgsph needs {}",
                info.name,
                have.max_storage_buffers_per_shader_stage,
                STORAGE_BUFFERS_PER_STAGE
            );
        }
        // Ask for what the adapter can give: particle arrays are as large as the binding and
        // buffer limits allow; the solver checks its own needs against these.
        let mut limits = wgpu::Limits {
            max_storage_buffers_per_shader_stage: STORAGE_BUFFERS_PER_STAGE,
            max_storage_buffer_binding_size: have.max_storage_buffer_binding_size,
            max_buffer_size: have.max_buffer_size,
            max_compute_workgroups_per_dimension: have.max_compute_workgroups_per_dimension,
            ..wgpu::Limits::default()
        };
        restrict(&mut limits);
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("wgsph"),
            // Optional: only `bench --stages` uses timestamps.
            required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
            required_limits: limits.clone(),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .with_context(|| format!("requesting a device from adapter '{}'", info.name))?;
        let faults = GpuFaults::default();
        faults.watch(&device);
        Ok(Self {
            device,
            queue,
            info,
            limits,
            faults,
        })
    }

    /// "name (backend, device type)", as the run log and run.json name the adapter.
    pub fn describe(&self) -> String {
        format!(
            "{} ({:?}, {:?})",
            self.info.name, self.info.backend, self.info.device_type
        )
    }

    /// Blocks until all submitted work is done.
    pub fn wait(&self) -> Result<()> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| anyhow!("GPU wait failed: {e}"))
    }
}

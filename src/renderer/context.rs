//! Adapter and device creation, shared by the GUI (through eframe) and the headless commands.
//!
//! The workbench needs a native backend (Vulkan, Metal or DX12): the GL backend lacks
//! `Rgba32Float` render targets and int64, so it is never picked silently.

use std::sync::{Arc, Mutex};

use thiserror::Error;

/// Backends the workbench accepts. GL is left out on purpose (see the module docs).
pub const BACKENDS: wgpu::Backends = wgpu::Backends::PRIMARY;

/// What to tell a user who has no usable adapter.
pub const NO_ADAPTER_HELP: &str = "no Vulkan/Metal/DX12 GPU adapter found. Install a Vulkan \
driver; on Linux without a GPU use Mesa's software Vulkan: \
`apt-get install mesa-vulkan-drivers libvulkan1`";

#[derive(Debug, Error)]
pub enum GpuError {
    #[error("{NO_ADAPTER_HELP}")]
    NoAdapter,
    #[error("could not create a GPU device on '{adapter}': {source}")]
    Device {
        adapter: String,
        source: wgpu::RequestDeviceError,
    },
    #[error("GPU readback failed: {0}")]
    Readback(String),
    #[error("{0}")]
    Limit(String),
}

/// The optional features the workbench uses when the adapter has them.
pub fn wanted_features(adapter: &wgpu::Adapter) -> wgpu::Features {
    let wanted = wgpu::Features::TIMESTAMP_QUERY
        | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS
        | wgpu::Features::SHADER_INT64
        | wgpu::Features::SUBGROUP;
    adapter.features() & wanted
}

/// Limits requested from the adapter: the defaults, raised where the adapter allows and the
/// renderer benefits (large storage buffers for BVHs and light trees).
pub fn wanted_limits(adapter: &wgpu::Adapter) -> wgpu::Limits {
    let a = adapter.limits();
    wgpu::Limits {
        max_texture_dimension_2d: a.max_texture_dimension_2d.min(16384),
        max_storage_buffer_binding_size: a.max_storage_buffer_binding_size.min(1 << 30),
        max_buffer_size: a.max_buffer_size.min(1 << 31),
        max_storage_buffers_per_shader_stage: a.max_storage_buffers_per_shader_stage.min(16),
        max_storage_textures_per_shader_stage: a.max_storage_textures_per_shader_stage.min(8),
        max_texture_array_layers: a.max_texture_array_layers.min(2048),
        ..wgpu::Limits::default()
    }
}

pub fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
    wgpu::DeviceDescriptor {
        label: Some("lightcut::device"),
        required_features: wanted_features(adapter),
        required_limits: wanted_limits(adapter),
        ..Default::default()
    }
}

/// One-line description of an adapter: name and backend (and driver when known).
pub fn describe_adapter(info: &wgpu::AdapterInfo) -> String {
    let mut s = format!("{} ({:?}", info.name, info.backend);
    if !info.driver.is_empty() {
        s.push_str(&format!(", {}", info.driver));
    }
    if info.device_type == wgpu::DeviceType::Cpu {
        s.push_str(", software");
    }
    s.push(')');
    s
}

/// Collects GPU validation errors so each is shown once instead of panicking.
#[derive(Clone, Default)]
pub struct ErrorSink {
    inner: Arc<Mutex<Vec<String>>>,
}

impl ErrorSink {
    pub fn install(&self, device: &wgpu::Device) {
        let sink = self.inner.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            let msg = e.to_string();
            log::error!("GPU error: {msg}");
            if let Ok(mut v) = sink.lock()
                && !v.iter().any(|m| m == &msg)
            {
                v.push(msg);
            }
        }));
    }
    /// Records a message (shown like a GPU error, once).
    pub fn report(&self, msg: String) {
        if let Ok(mut v) = self.inner.lock()
            && !v.contains(&msg)
        {
            v.push(msg);
        }
    }

    /// Takes the errors gathered since the last call.
    pub fn take(&self) -> Vec<String> {
        self.inner
            .lock()
            .map(|mut v| std::mem::take(&mut *v))
            .unwrap_or_default()
    }
}

/// Device, queue and what we know about the adapter.
#[derive(Clone)]
pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub adapter_info: wgpu::AdapterInfo,
    pub errors: ErrorSink,
}

impl GpuContext {
    /// Creates a headless context (CLI, tests, benchmarks) on the best native adapter.
    pub fn new_headless() -> Result<Self, GpuError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::from_env().unwrap_or(BACKENDS),
            flags: wgpu::InstanceFlags::from_build_config().with_env(),
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            ..Default::default()
        }))
        .map_err(|_| GpuError::NoAdapter)?;
        Self::from_adapter(&adapter)
    }

    /// The adapter a headless context would use, without creating a device.
    pub fn probe_adapter() -> Result<wgpu::AdapterInfo, GpuError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::from_env().unwrap_or(BACKENDS),
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))
            .map(|a| a.get_info())
            .map_err(|_| GpuError::NoAdapter)
    }

    pub fn from_adapter(adapter: &wgpu::Adapter) -> Result<Self, GpuError> {
        let info = adapter.get_info();
        let (device, queue) = pollster::block_on(adapter.request_device(&device_descriptor(adapter)))
            .map_err(|source| GpuError::Device {
                adapter: describe_adapter(&info),
                source,
            })?;
        Ok(Self::from_parts(device, queue, info))
    }

    /// Wraps a device created elsewhere (eframe's).
    pub fn from_parts(device: wgpu::Device, queue: wgpu::Queue, adapter_info: wgpu::AdapterInfo) -> Self {
        let errors = ErrorSink::default();
        errors.install(&device);
        log::info!("GPU adapter: {}", describe_adapter(&adapter_info));
        Self {
            device,
            queue,
            adapter_info,
            errors,
        }
    }

    pub fn describe(&self) -> String {
        describe_adapter(&self.adapter_info)
    }

    pub fn has_timestamps(&self) -> bool {
        self.device.features().contains(wgpu::Features::TIMESTAMP_QUERY)
    }

    /// Blocks until all submitted work is done.
    pub fn wait_idle(&self) -> Result<(), GpuError> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| GpuError::Readback(e.to_string()))
    }
}

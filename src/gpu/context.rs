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
        max_storage_buffers_per_shader_stage: a.max_storage_buffers_per_shader_stage.min(32),
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
    lost: Arc<std::sync::atomic::AtomicBool>,
}

/// The first GPU error of this process (validation, out of memory, device lost), for the CLI's
/// exit status: a command that met one exits non-zero even where its own loop did not look.
static FIRST_ERROR: Mutex<Option<String>> = Mutex::new(None);

fn set_first_error(msg: &str) {
    if let Ok(mut first) = FIRST_ERROR.lock()
        && first.is_none()
    {
        *first = Some(msg.to_string());
    }
}

/// The first GPU error (validation, out of memory, device lost) wgpu reported to any
/// [`ErrorSink`] of this process.
pub fn first_gpu_error() -> Option<String> {
    FIRST_ERROR.lock().ok().and_then(|e| e.clone())
}

/// A wgpu error as one line naming the failing pass: our labels are `pass::object`, and wgpu
/// says which labelled object the failing call was on ("In Device::create_bind_group, label =
/// 'sst_build::bind_group'"); the pass is the label's first part. Errors inside a pass are
/// raised when the frame's encoder finishes, on the encoder ('frame::encoder'), or at the
/// submit: then the first other `pass::thing` the cause names ("RenderPipeline with
/// 'rsm::pipeline' label is invalid") says which pass failed.
pub fn describe_gpu_error(kind: &str, text: &str) -> String {
    let lines: Vec<&str> = text.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    let on = text
        .split("label = '")
        .nth(1)
        .and_then(|r| r.split('\'').next())
        .filter(|l| !l.is_empty());
    let named: Vec<&str> = text
        .split('\'')
        .skip(1)
        .step_by(2)
        .filter(|l| l.contains("::") && !l.contains(' ') && Some(*l) != on)
        .collect();
    let call = lines.iter().find(|l| l.starts_with("In ")).map(|l| {
        l.trim_start_matches("In ")
            .split(',')
            .next()
            .unwrap_or("")
            .to_string()
    });
    let frame_level = call
        .as_deref()
        .is_none_or(|c| c.contains("CommandEncoder") || c.contains("Queue::submit"));
    let pass_label = match (on, named.first()) {
        (_, Some(n)) if frame_level => Some(*n),
        (Some(l), _) => Some(l),
        (None, n) => n.copied(),
    };
    // The cause: what follows the "In ..." line, else every line but the headings.
    let cause: Vec<&str> = match lines.iter().position(|l| l.starts_with("In ")) {
        Some(i) => lines[i + 1..].to_vec(),
        None => lines
            .iter()
            .copied()
            .filter(|l| *l != "Caused by:" && !l.ends_with("Error"))
            .collect(),
    };
    let cause = if cause.is_empty() {
        lines.join(" ")
    } else {
        cause.join(" ")
    };
    let object = match (call, on) {
        (Some(c), Some(l)) => format!(" ({c}, label '{l}')"),
        (Some(c), None) => format!(" ({c})"),
        (None, Some(l)) => format!(" (label '{l}')"),
        (None, None) => String::new(),
    };
    match pass_label {
        Some(l) => format!(
            "GPU {kind} in pass '{}'{object}: {cause}",
            l.split("::").next().unwrap_or(l)
        ),
        None => format!("GPU {kind}{object}: {cause}"),
    }
}

impl ErrorSink {
    pub fn install(&self, device: &wgpu::Device) {
        let sink = self.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            let kind = match &e {
                wgpu::Error::OutOfMemory { .. } => "out of memory",
                wgpu::Error::Validation { .. } => "validation error",
                wgpu::Error::Internal { .. } => "internal error",
            };
            // wgpu's Display of out-of-memory is the bare kind; its sources say where.
            let mut text = e.to_string();
            let mut src = std::error::Error::source(&e);
            while let Some(s) = src {
                let t = s.to_string();
                if !text.contains(&t) {
                    text.push('\n');
                    text.push_str(&t);
                }
                src = s.source();
            }
            let msg = describe_gpu_error(kind, &text);
            log::error!("{msg}");
            set_first_error(&msg);
            sink.report(msg);
        }));
        let sink = self.clone();
        device.set_device_lost_callback(move |reason, message| {
            // (Dropping a device does not call this; `destroy` does, with `Destroyed`.)
            sink.lost.store(true, std::sync::atomic::Ordering::SeqCst);
            let message: Vec<&str> = message.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
            let msg = if message.is_empty() {
                format!("GPU device lost ({reason:?})")
            } else {
                format!("GPU device lost ({reason:?}): {}", message.join(" "))
            };
            log::error!("{msg}");
            set_first_error(&msg);
            sink.report(msg);
        });
    }
    /// Records a message (shown like a GPU error, once): GPU errors, and the renderer's
    /// refusals and fallbacks (which do not fail a command: [`first_gpu_error`] holds only
    /// what wgpu reported).
    pub fn report(&self, msg: String) {
        if let Ok(mut v) = self.inner.lock()
            && !v.contains(&msg)
        {
            v.push(msg);
        }
    }

    /// Whether the device was lost (everything made on it is gone).
    pub fn device_lost(&self) -> bool {
        self.lost.load(std::sync::atomic::Ordering::SeqCst)
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

    /// The live GPU objects of each kind and the GPU memory held, from wgpu's internal
    /// counters (the `counters` feature). A frame that allocates and frees the same objects
    /// leaves these flat; a leak shows as a kind that grows from frame to frame.
    pub fn live_objects(&self) -> LiveObjects {
        let hal = self.device.get_internal_counters().hal;
        LiveObjects {
            buffers: hal.buffers.read(),
            textures: hal.textures.read(),
            texture_views: hal.texture_views.read(),
            bind_groups: hal.bind_groups.read(),
            bind_group_layouts: hal.bind_group_layouts.read(),
            pipelines: hal.render_pipelines.read() + hal.compute_pipelines.read(),
            pipeline_layouts: hal.pipeline_layouts.read(),
            samplers: hal.samplers.read(),
            command_encoders: hal.command_encoders.read(),
            shader_modules: hal.shader_modules.read(),
            query_sets: hal.query_sets.read(),
            buffer_bytes: hal.buffer_memory.read(),
            texture_bytes: hal.texture_memory.read(),
            memory_allocations: hal.memory_allocations.read(),
        }
    }

    /// Blocks until all submitted work is done.
    pub fn wait_idle(&self) -> Result<(), GpuError> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| GpuError::Readback(e.to_string()))
    }
}

/// Live GPU objects per kind (see [`GpuContext::live_objects`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct LiveObjects {
    pub buffers: isize,
    pub textures: isize,
    pub texture_views: isize,
    pub bind_groups: isize,
    pub bind_group_layouts: isize,
    pub pipelines: isize,
    pub pipeline_layouts: isize,
    pub samplers: isize,
    pub command_encoders: isize,
    pub shader_modules: isize,
    pub query_sets: isize,
    pub buffer_bytes: isize,
    pub texture_bytes: isize,
    pub memory_allocations: isize,
}

impl LiveObjects {
    /// The counts that must not grow once a run is warm (memory sizes excluded: a pool
    /// may keep its blocks; command encoders too: wgpu keeps finished ones in a pool that
    /// holds the most ever in flight at once).
    pub fn objects(&self) -> [(&'static str, isize); 10] {
        [
            ("buffers", self.buffers),
            ("textures", self.textures),
            ("texture views", self.texture_views),
            ("bind groups", self.bind_groups),
            ("bind group layouts", self.bind_group_layouts),
            ("pipelines", self.pipelines),
            ("pipeline layouts", self.pipeline_layouts),
            ("samplers", self.samplers),
            ("shader modules", self.shader_modules),
            ("query sets", self.query_sets),
        ]
    }

    /// One line: every kind's count and the GPU memory in MiB.
    pub fn summary(&self) -> String {
        let mut s: Vec<String> = self.objects().iter().map(|(k, v)| format!("{v} {k}")).collect();
        s.push(format!(
            "{:.1} MiB buffers, {:.1} MiB textures",
            self.buffer_bytes as f64 / 1048576.0,
            self.texture_bytes as f64 / 1048576.0
        ));
        s.join(", ")
    }
}

#[cfg(test)]
mod error_text_tests {
    use super::describe_gpu_error;

    #[test]
    fn an_error_raised_at_the_encoder_names_the_pass_of_the_object_it_blames() {
        let text = "Validation Error\n\nCaused by:\n  In a CommandEncoder, label = 'frame::encoder'\n    In a set_pipeline command\n      RenderPipeline with 'rsm::pipeline' label is invalid\n";
        let m = describe_gpu_error("validation error", text);
        assert!(
            m.starts_with("GPU validation error in pass 'rsm' (a CommandEncoder, label 'frame::encoder'): "),
            "{m}"
        );
        assert!(!m.contains('\n'), "{m}");
        let direct = "Validation Error\n\nCaused by:\n  In Device::create_bind_group, label = 'sst_build::bind_group'\n    Usage flags of Buffer with 'sst_build::params' label do not contain STORAGE\n";
        let m = describe_gpu_error("validation error", direct);
        assert!(m.starts_with("GPU validation error in pass 'sst_build' (Device::create_bind_group, label 'sst_build::bind_group'): Usage"), "{m}");
        assert_eq!(
            describe_gpu_error("out of memory", "Out of Memory"),
            "GPU out of memory: Out of Memory"
        );
    }
}

//! One module per pass. Each pass owns its long-lived pipelines and layouts (`new`), declares
//! what it reads and writes in its `record` signature (typed inputs, no global lookups), and
//! builds its per-frame bind groups when it records.

pub mod compare;
pub mod composite;
pub mod direct;
pub mod display;
pub mod gbuffer;
pub mod interleave_filter;
pub mod ism;
pub mod lbvh;
pub mod light_paths;
pub mod rsm;
pub mod sst_build;
pub mod sst_overlay;
pub mod sst_sort;
pub mod temporal;
pub mod val_cluster;
pub mod visualise;
pub mod vpl_gen;
pub mod vpl_splat;

/// Workgroup edge of the 2D image kernels (`@workgroup_size(8, 8, 1)` in their WGSL; checked
/// by `tests::workgroup_sizes_match_wgsl`).
pub const WG_2D: u32 = 8;
/// Workgroup size of the 1D kernels (`@workgroup_size(64, 1, 1)`).
pub const WG_1D: u32 = 64;

/// Workgroup counts (x, y, 1) covering a `w` x `h` image.
pub fn groups_image(w: u32, h: u32) -> (u32, u32, u32) {
    (w.div_ceil(WG_2D), h.div_ceil(WG_2D), 1)
}

/// Number of workgroups covering a `w` x `h` image.
pub fn groups_2d(w: u32, h: u32) -> (u32, u32) {
    (w.div_ceil(WG_2D), h.div_ceil(WG_2D))
}

/// Whether this device reads the `var<uniform>` parameter blocks as read-only storage
/// buffers instead. True on CPU adapters (Mesa's lavapipe): lavapipe 22.3 inlines the values
/// of uniforms that steer control flow into a freshly compiled shader at every pipeline bind
/// (`update_inline_shader_state`), never frees it, and so grew ~2 MB and ~11 LLVM modules per
/// frame (issue 42); it never inlines storage buffers. The layout of a struct is the same in
/// both address spaces (WGSL's one layout algorithm), so the shaders read the same bytes.
/// `LIGHTCUT_UNIFORMS=uniform` or `=storage` overrides the choice (to reproduce the growth, or
/// to try storage on a GPU).
pub fn uniforms_as_storage(device: &wgpu::Device) -> bool {
    match std::env::var("LIGHTCUT_UNIFORMS").ok().as_deref() {
        Some("uniform") => false,
        Some("storage") => true,
        _ => device.adapter_info().device_type == wgpu::DeviceType::Cpu,
    }
}

/// Creates a bind group layout: every layout of the renderer and the methods goes through
/// here, so that uniform bindings become read-only storage where [`uniforms_as_storage`]
/// says so (the shaders are rewritten to match in `shaders::module_from_text`).
pub fn bind_group_layout(
    device: &wgpu::Device,
    desc: &wgpu::BindGroupLayoutDescriptor<'_>,
) -> wgpu::BindGroupLayout {
    if !uniforms_as_storage(device) {
        return device.create_bind_group_layout(desc);
    }
    let entries: Vec<wgpu::BindGroupLayoutEntry> = desc
        .entries
        .iter()
        .map(|e| {
            let mut e = *e;
            if let wgpu::BindingType::Buffer {
                ty: ty @ wgpu::BufferBindingType::Uniform,
                ..
            } = &mut e.ty
            {
                *ty = wgpu::BufferBindingType::Storage { read_only: true };
            }
            e
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: desc.label,
        entries: &entries,
    })
}

/// The usage of a parameter (`var<uniform>`) buffer: uniform, and storage for the devices
/// that read parameters as storage ([`uniforms_as_storage`]).
pub const PARAMS_USAGE: wgpu::BufferUsages = wgpu::BufferUsages::UNIFORM.union(wgpu::BufferUsages::STORAGE);

pub fn storage_entry(binding: u32, vis: wgpu::ShaderStages, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: vis,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A storage buffer of `size` bytes (at least 16) that copies can read and write (readbacks,
/// clears).
pub(crate) fn storage_buffer(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Dynamic-offset stride of [`StridedUniforms`] (the largest `minUniformBufferOffsetAlignment`).
pub(crate) const UNIFORM_STRIDE: u64 = 256;

/// Per-dispatch uniforms of type `T`, `UNIFORM_STRIDE` bytes apart in one buffer (bound with a
/// dynamic offset `i * UNIFORM_STRIDE` for dispatch i); the buffer grows as needed.
pub(crate) struct StridedUniforms<T> {
    buffer: wgpu::Buffer,
    label: &'static str,
    _t: std::marker::PhantomData<T>,
}

impl<T: bytemuck::Pod> StridedUniforms<T> {
    pub fn new(device: &wgpu::Device, label: &'static str, count: u32) -> Self {
        Self {
            buffer: Self::create(device, label, count),
            label,
            _t: std::marker::PhantomData,
        }
    }
    fn create(device: &wgpu::Device, label: &str, count: u32) -> wgpu::Buffer {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: count.max(1) as u64 * UNIFORM_STRIDE,
            usage: crate::gpu::passes::PARAMS_USAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    }
    /// Writes `items` (item i at offset i * UNIFORM_STRIDE), growing the buffer first.
    pub fn write(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, items: &[T]) {
        let n = items.len() as u32;
        if self.buffer.size() < n as u64 * UNIFORM_STRIDE {
            self.buffer = Self::create(device, self.label, n);
        }
        let mut all = Vec::with_capacity(items.len() * UNIFORM_STRIDE as usize);
        for it in items {
            let start = all.len();
            all.extend_from_slice(bytemuck::bytes_of(it));
            all.resize(start + UNIFORM_STRIDE as usize, 0);
        }
        queue.write_buffer(&self.buffer, 0, &all);
    }
    /// The binding (one `T` at the dynamic offset).
    pub fn binding(&self) -> wgpu::BindingResource<'_> {
        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: &self.buffer,
            offset: 0,
            size: wgpu::BufferSize::new(std::mem::size_of::<T>() as u64),
        })
    }
    /// Dynamic offset of item `i`.
    pub fn offset(i: u32) -> u32 {
        (i as u64 * UNIFORM_STRIDE) as u32
    }
}

/// A uniform buffer sized for `T`, written with `queue.write_buffer` before use.
pub(crate) fn uniform_buffer<T>(device: &wgpu::Device, label: &str) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: std::mem::size_of::<T>() as u64,
        usage: crate::gpu::passes::PARAMS_USAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Records one timed compute pass `name` (inside a debug group of the same name) that
/// dispatches `pipeline` once over `groups` with `bind` at group 0.
pub(crate) fn run_compute(
    encoder: &mut wgpu::CommandEncoder,
    timer: &mut crate::gpu::timing::GpuTimer,
    name: &str,
    pipeline: &wgpu::ComputePipeline,
    bind: &wgpu::BindGroup,
    groups: (u32, u32, u32),
) {
    encoder.push_debug_group(name);
    {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(name),
            timestamp_writes: timer.compute_pass(name),
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind, &[]);
        pass.dispatch_workgroups(groups.0, groups.1, groups.2);
    }
    encoder.pop_debug_group();
}

/// A kernel dispatched with a workgroup size of its own (not `WG_2D` x `WG_2D` or `WG_1D`):
/// declared beside the pass that dispatches it, checked against its WGSL by
/// [`check_workgroup_sizes`].
pub struct OwnWorkgroup {
    /// The WGSL file (under `shaders/`).
    pub file: &'static str,
    /// Its entry points of that size (empty: every entry point of the file).
    pub entries: &'static [&'static str],
    pub size: [u32; 3],
}

/// Every compute entry point of `files` has the standard sizes or one `own` declares; the
/// message names the first that has neither.
pub fn check_workgroup_sizes(files: &[&str], own: &[OwnWorkgroup]) -> Result<(), String> {
    use crate::gpu::shaders::{Embedded, preprocess, validate};
    for file in files {
        let text = preprocess(&Embedded, file).map_err(|e| e.to_string())?;
        let module = validate(file, &text).map_err(|e| e.to_string())?;
        for ep in &module.entry_points {
            if ep.stage != naga::ShaderStage::Compute {
                continue;
            }
            let ws = ep.workgroup_size;
            let declared = own.iter().any(|o| {
                o.file == *file
                    && (o.entries.is_empty() || o.entries.contains(&ep.name.as_str()))
                    && o.size == ws
            });
            if !(declared || ws == [WG_2D, WG_2D, 1] || ws == [WG_1D, 1, 1]) {
                return Err(format!("{file}::{} has workgroup size {ws:?}", ep.name));
            }
        }
    }
    Ok(())
}

/// The shared passes' own workgroup sizes: the parallel sort's kernels (the pass dispatches
/// with it) and the VAL clustering's fallback list (one workgroup of 256 scans it).
pub static OWN_WORKGROUPS: &[OwnWorkgroup] = &[
    OwnWorkgroup {
        file: "sst_sort.wgsl",
        entries: &sst_sort::SORT_WG_ENTRIES,
        size: [sst_sort::SORT_WG, 1, 1],
    },
    OwnWorkgroup {
        file: "val_cluster.wgsl",
        entries: &["list_main"],
        size: [256, 1, 1],
    },
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn workgroup_sizes_match_wgsl() {
        if let Err(e) = check_workgroup_sizes(crate::gpu::shaders::ENTRY_SHADERS, OWN_WORKGROUPS) {
            panic!("{e}");
        }
    }
}

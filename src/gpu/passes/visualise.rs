//! Visualise: maps any non-radiance buffer (normals, albedo, positions, depth, ids, shadow-map
//! depth, integer buffers) to a viewable image in the `Rgba8Unorm` view texture.

use crate::gpu::gpu_data::VisParams;
use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;

use super::groups_2d;

/// Twin of the mode table at the top of `shaders/visualise.wgsl`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VisMode {
    Normal = 0,
    Albedo = 1,
    Position = 2,
    Depth = 3,
    IdFromW = 4,
    DepthTexture = 5,
    UintIds = 6,
    UintHeat = 7,
    ArrayColor = 8,
    ArrayNormal = 9,
    ScalarLogHeat = 10,
    ArrayPosition = 11,
}

/// One visualisation: `src` drawn in `mode` into `dst` (of `size`). `range_min`/`range_max`
/// depend on the mode (see `shaders/visualise.wgsl`).
pub struct VisInputs<'a> {
    pub mode: VisMode,
    pub src: VisSource<'a>,
    pub range_min: [f32; 4],
    pub range_max: [f32; 4],
    pub dst: &'a wgpu::TextureView,
    pub size: (u32, u32),
}

/// What to visualise.
pub enum VisSource<'a> {
    /// A float buffer with mode Normal/Albedo/Position/Depth/IdFromW.
    Float(&'a wgpu::TextureView),
    /// A layer of a depth texture array.
    Depth(&'a wgpu::TextureView, u32),
    /// An unsigned-integer buffer (mode UintIds or UintHeat).
    Uint(&'a wgpu::TextureView),
    /// A layer of a float array texture (mode ArrayColor / ArrayNormal).
    Array(&'a wgpu::TextureView, u32),
    /// A square map of f32 in a buffer (mode ScalarLogHeat) and the pyramid whose top holds
    /// its sum (index in the pyramid buffer given in range_min.y by the caller).
    Scalar(&'a wgpu::Buffer, &'a wgpu::Buffer),
}

pub struct VisualisePass {
    /// One kernel per source kind (each entry point binds its source in its own group).
    float: (Kernel, wgpu::ComputePipeline),
    depth: (Kernel, wgpu::ComputePipeline),
    uint: (Kernel, wgpu::ComputePipeline),
    array: (Kernel, wgpu::ComputePipeline),
    scalar: (Kernel, wgpu::ComputePipeline),
    params: wgpu::Buffer,
}

impl VisualisePass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        // One kernel per entry point (one parse, one module): each binds its source kind at
        // the same slots.
        let entries = ["vis_float", "vis_depth", "vis_uint", "vis_array", "vis_scalar"];
        let kernels = Kernel::per_entry(device, "visualise.wgsl", &entries, KernelOptions::default())?;
        let mut pipes = entries.iter().zip(kernels).map(|(entry, k)| {
            let label = format!("visualise::{}_pipeline", entry.trim_start_matches("vis_"));
            let p = k.compute(device, &label, entry);
            (k, p)
        });
        let mut kernel = || pipes.next().expect("one kernel per entry point");
        Ok(Self {
            float: kernel(),
            depth: kernel(),
            uint: kernel(),
            array: kernel(),
            scalar: kernel(),
            params: super::uniform_buffer::<VisParams>(device, "visualise::params"),
        })
    }

    /// Records the visualisation `v` (its `src` into its `dst`).
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        v: VisInputs<'_>,
    ) {
        let VisInputs {
            mode,
            src,
            range_min,
            range_max,
            dst,
            size,
        } = v;
        let layer = match src {
            VisSource::Depth(_, l) | VisSource::Array(_, l) => l,
            _ => 0,
        };
        let p = VisParams {
            mode: mode as u32,
            layer,
            _pad: [0; 2],
            range_min,
            range_max,
        };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let ((kernel, pipeline), group, source) = match &src {
            VisSource::Float(view) => (&self.float, 1, vec![("src_float", tex(view))]),
            VisSource::Depth(view, _) => (&self.depth, 2, vec![("src_depth", tex(view))]),
            VisSource::Array(view, _) => (&self.array, 1, vec![("src_array", tex(view))]),
            VisSource::Scalar(values, pyramid) => (
                &self.scalar,
                1,
                vec![("src_scalar", buf(values)), ("src_pyramid", buf(pyramid))],
            ),
            VisSource::Uint(view) => (&self.uint, 3, vec![("src_uint", tex(view))]),
        };
        let common = kernel.bind(device, 0, &[("params", buf(&self.params)), ("dst", tex(dst))]);
        let source = kernel.bind(device, group, &source);
        encoder.push_debug_group("visualise");
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("visualise::pass"),
                timestamp_writes: timer.compute_pass("visualise"),
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &common, &[]);
            pass.set_bind_group(group, &source, &[]);
            let (gx, gy) = groups_2d(size.0, size.1);
            pass.dispatch_workgroups(gx, gy, 1);
        }
        encoder.pop_debug_group();
    }
}

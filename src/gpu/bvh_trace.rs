//! Traces batches of rays through the scene BVH on the GPU (`shaders/bvh_rays.wgsl`): used by
//! the GPU-vs-CPU tests and the shadow-ray benchmark. Frame passes use the same WGSL traversal
//! (`shaders/common/bvh.wgsl`, the layout of `scene_gpu::BvhLayout`) inline.

use wgpu::util::DeviceExt;

use super::{
    context::{GpuContext, GpuError},
    gpu_data::{GpuHit, GpuRay},
    kernel::{Kernel, KernelOptions, buf, tex},
    passes::WG_1D,
    readback, shaders,
    timing::GpuTimer,
};
use crate::scene::bvh::Ray;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TraceMode {
    /// Occlusion only: `GpuHit::triangle` is 1 when something lies strictly between tmin and tmax.
    AnyHit,
    /// Nearest intersection.
    ClosestHit,
}

pub struct BvhTracer {
    any: wgpu::ComputePipeline,
    closest: wgpu::ComputePipeline,
    kernel: Kernel,
}

/// Most rays per dispatch row (dispatches are split in 2D when larger).
const MAX_GROUPS_X: u32 = 65535;

pub fn to_gpu_ray(r: &Ray) -> GpuRay {
    GpuRay {
        origin: r.origin.extend(r.tmin).to_array(),
        dir: r.dir.extend(r.tmax).to_array(),
    }
}

impl BvhTracer {
    /// Traces through the binary BVH (`common/bvh_binary.wgsl`, the frames' default; buffers
    /// from `scene_gpu::upload_bvh`).
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        Self::with_shader(device, "bvh_rays.wgsl")
    }

    /// Traces through the compressed 8-wide BVH (`common/bvh_wide.wgsl`; buffers from
    /// `scene_gpu::upload_wide_bvh`).
    pub fn new_wide(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        Self::with_shader(device, "bvh_rays_wide.wgsl")
    }

    fn with_shader(device: &wgpu::Device, file: &str) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(
            device,
            file,
            &["any_hit_main", "closest_hit_main"],
            KernelOptions::default(),
        )?;
        Ok(Self {
            any: kernel.compute(device, "bvh_rays::any_hit", "any_hit_main"),
            closest: kernel.compute(device, "bvh_rays::closest_hit", "closest_hit_main"),
            kernel,
        })
    }

    /// Traces `rays` `repeat` times (the results of the last repetition are returned), timing
    /// each repetition with timestamps when available. Returns (hits, per-repetition ms).
    pub fn trace(
        &self,
        ctx: &GpuContext,
        nodes: &wgpu::Buffer,
        triangles: &wgpu::Buffer,
        rays: &[GpuRay],
        mode: TraceMode,
        repeat: u32,
    ) -> Result<(Vec<GpuHit>, Vec<f64>), GpuError> {
        let device = &ctx.device;
        if rays.is_empty() {
            return Ok((Vec::new(), Vec::new()));
        }
        let ray_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("bvh_rays::rays"),
            contents: bytemuck::cast_slice(rays),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let hit_buf = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("bvh_rays::hits"),
            size: (rays.len() * std::mem::size_of::<GpuHit>()) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let bind = self.kernel.bind(
            device,
            0,
            &[
                ("bvh_nodes", buf(nodes)),
                ("bvh_triangles", buf(triangles)),
                ("rays", buf(&ray_buf)),
                ("hits", buf(&hit_buf)),
            ],
        );
        let pipeline = match mode {
            TraceMode::AnyHit => &self.any,
            TraceMode::ClosestHit => &self.closest,
        };
        let groups = (rays.len() as u32).div_ceil(WG_1D);
        if groups > MAX_GROUPS_X {
            return Err(GpuError::Limit(format!(
                "{} rays exceed one dispatch ({} max)",
                rays.len(),
                MAX_GROUPS_X as u64 * WG_1D as u64
            )));
        }
        let mut times = Vec::new();
        let mut timer = GpuTimer::new(device, &ctx.queue);
        for _ in 0..repeat.max(1) {
            let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("bvh_rays::encoder"),
            });
            timer.begin_frame(true);
            {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("bvh_rays::pass"),
                    timestamp_writes: timer.compute_pass("trace"),
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &bind, &[]);
                pass.dispatch_workgroups(groups, 1, 1);
            }
            timer.resolve(&mut enc);
            ctx.queue.submit([enc.finish()]);
            timer.after_submit();
            if let Some(t) = timer.collect_blocking(device).and_then(|t| t.get("trace")) {
                times.push(t);
            }
        }
        let bytes = readback::read_storage_buffer(ctx, &hit_buf)?;
        Ok((bytemuck::cast_slice(&bytes).to_vec(), times))
    }
}

/// One ray's hit surface as `shaders/surface_rays.wgsl` writes it (twin: `Surface` in
/// `shaders/common/surface.wgsl`, `reference::surface::Surface`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuSurface {
    pub position: [f32; 3],
    /// u32::MAX on a miss.
    pub material: u32,
    pub normal: [f32; 3],
    /// 1 on a hit of a non-degenerate triangle.
    pub valid: u32,
    pub geometric_normal: [f32; 3],
    pub _pad: u32,
    pub albedo: [f32; 3],
    pub _pad1: u32,
    pub uv: [f32; 2],
    pub _pad2: [u32; 2],
}

/// Traces rays and describes the surfaces they hit (`shaders/surface_rays.wgsl` over
/// `common/surface.wgsl`): the GPU side of the light paths' hit surfaces, for the tests.
pub struct SurfaceProbe {
    pipeline: wgpu::ComputePipeline,
    kernel: Kernel,
}

impl SurfaceProbe {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(device, "surface_rays.wgsl", &["main"], KernelOptions::default())?;
        Ok(Self {
            pipeline: kernel.compute(device, "surface_rays", "main"),
            kernel,
        })
    }

    /// The surfaces `rays` hit in `scene`, albedo at mip level `lod`.
    pub fn run(
        &self,
        ctx: &GpuContext,
        scene: &super::scene_gpu::SceneGpu,
        rays: &[GpuRay],
        lod: u32,
    ) -> Result<Vec<GpuSurface>, GpuError> {
        let device = &ctx.device;
        if rays.is_empty() {
            return Ok(Vec::new());
        }
        if (rays.len() as u32).div_ceil(WG_1D) > MAX_GROUPS_X {
            return Err(GpuError::Limit(format!(
                "{} rays exceed one dispatch",
                rays.len()
            )));
        }
        let ray_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("surface_rays::rays"),
            contents: bytemuck::cast_slice(rays),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let out = super::passes::storage_buffer(
            device,
            "surface_rays::out",
            (rays.len() * std::mem::size_of::<GpuSurface>()) as u64,
        );
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("surface_rays::params"),
            contents: bytemuck::cast_slice(&[lod, 0, 0, 0]),
            usage: crate::gpu::passes::PARAMS_USAGE,
        });
        let bind = self.kernel.bind(
            device,
            0,
            &[
                ("bvh_nodes", buf(&scene.bvh_nodes)),
                ("bvh_triangles", buf(&scene.bvh_triangles)),
                ("rays", buf(&ray_buf)),
                ("out", buf(&out)),
                ("scene_vertices", buf(&scene.vertices)),
                ("scene_indices", buf(&scene.indices)),
                ("materials", buf(&scene.materials)),
                ("textures", tex(&scene.textures_view)),
                ("pp", buf(&params)),
            ],
        );
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("surface_rays::encoder"),
        });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("surface_rays"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups((rays.len() as u32).div_ceil(WG_1D), 1, 1);
        }
        ctx.queue.submit([enc.finish()]);
        let bytes = readback::read_storage_buffer(ctx, &out)?;
        Ok(bytemuck::pod_collect_to_vec(
            &bytes[..rays.len() * std::mem::size_of::<GpuSurface>()],
        ))
    }
}

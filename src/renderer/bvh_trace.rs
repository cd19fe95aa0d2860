//! Traces batches of rays through the scene BVH on the GPU (`shaders/bvh_rays.wgsl`): used by
//! the GPU-vs-CPU tests and the shadow-ray benchmark. Frame passes use the same WGSL traversal
//! (`shaders/common/bvh.wgsl`) inline.

use wgpu::util::DeviceExt;

use super::{
    context::{GpuContext, GpuError},
    gpu_data::{GpuHit, GpuRay},
    passes::{WG_1D, compute_pipeline, storage_entry},
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
    layout: wgpu::BindGroupLayout,
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
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let module = shaders::create_module(device, "bvh_rays.wgsl")?;
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bvh_rays::layout"),
            entries: &[
                storage_entry(0, c, true),
                storage_entry(1, c, true),
                storage_entry(2, c, true),
                storage_entry(3, c, false),
            ],
        });
        Ok(Self {
            any: compute_pipeline(
                device,
                "bvh_rays::any_hit",
                &[Some(&layout)],
                &module,
                "any_hit_main",
            ),
            closest: compute_pipeline(
                device,
                "bvh_rays::closest_hit",
                &[Some(&layout)],
                &module,
                "closest_hit_main",
            ),
            layout,
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
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bvh_rays::bind_group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: nodes.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: triangles.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: ray_buf.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: hit_buf.as_entire_binding(),
                },
            ],
        });
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

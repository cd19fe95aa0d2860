//! Ground truth (thesis chapter 7): every VPL at every pixel with a BVH shadow ray, run in
//! VPL batches so no dispatch is long; the caller accumulates batches over frames.
//! Reads: BVH, a VPL array, G-buffer. Writes: an accumulation buffer (rgb sum per pixel).

use crate::renderer::{
    frame::GbufferTargets, gpu_data::GpuGtParams, scene_gpu::SceneGpu, shaders, timing::GpuTimer,
};

use crate::renderer::passes::{
    compute_pipeline, dynamic_uniform_entry, float_texture_entry, groups_2d, storage_entry,
};

/// Dynamic-offset stride of the per-batch uniforms; most batches per recorded call.
const STRIDE: u64 = 256;
pub const MAX_BATCHES: u32 = 64;

pub struct GroundTruthPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
}

impl GroundTruthPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let module = shaders::create_module(device, "methods/ground_truth/ground_truth.wgsl")?;
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = crate::renderer::passes::bind_group_layout(
            device,
            &wgpu::BindGroupLayoutDescriptor {
                label: Some("ground_truth::layout"),
                entries: &[
                    dynamic_uniform_entry(0, c, std::mem::size_of::<GpuGtParams>() as u64),
                    storage_entry(1, c, true),
                    storage_entry(2, c, true),
                    storage_entry(3, c, true),
                    float_texture_entry(4),
                    float_texture_entry(5),
                    float_texture_entry(6),
                    storage_entry(7, c, false),
                ],
            },
        );
        let pipeline = compute_pipeline(
            device,
            "ground_truth::pipeline",
            &[Some(&layout)],
            &module,
            "main",
        );
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ground_truth::params"),
            size: STRIDE * MAX_BATCHES as u64,
            usage: crate::renderer::passes::PARAMS_USAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(Self {
            pipeline,
            layout,
            params,
        })
    }

    /// Records dispatches for VPLs `[begin, end)` in batches of `batch` VPLs (at most
    /// MAX_BATCHES batches; returns the end actually reached).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        base: GpuGtParams,
        batch: u32,
        scene: &SceneGpu,
        vpls: &wgpu::Buffer,
        gbuffer: &GbufferTargets,
        accum: &wgpu::Buffer,
    ) -> u32 {
        let batch = batch.max(1);
        let mut b = base.begin;
        let mut n = 0u64;
        while b < base.end && n < MAX_BATCHES as u64 {
            let e = (b + batch).min(base.end);
            let p = GpuGtParams {
                begin: b,
                end: e,
                ..base
            };
            queue.write_buffer(&self.params, n * STRIDE, bytemuck::bytes_of(&p));
            b = e;
            n += 1;
        }
        let tv = wgpu::BindingResource::TextureView;
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("ground_truth::bind_group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &self.params,
                        offset: 0,
                        size: wgpu::BufferSize::new(std::mem::size_of::<GpuGtParams>() as u64),
                    }),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: scene.bvh_nodes.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: scene.bvh_triangles.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: vpls.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: tv(&gbuffer.position_view),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: tv(&gbuffer.normal_view),
                },
                wgpu::BindGroupEntry {
                    binding: 6,
                    resource: tv(&gbuffer.albedo_view),
                },
                wgpu::BindGroupEntry {
                    binding: 7,
                    resource: accum.as_entire_binding(),
                },
            ],
        });
        encoder.push_debug_group("ground_truth");
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("ground_truth::pass"),
                timestamp_writes: timer.compute_pass("ground_truth"),
            });
            pass.set_pipeline(&self.pipeline);
            let (gx, gy) = groups_2d(base.width, base.height);
            for i in 0..n {
                pass.set_bind_group(0, &bind, &[(i * STRIDE) as u32]);
                pass.dispatch_workgroups(gx, gy, 1);
            }
        }
        encoder.pop_debug_group();
        b
    }
}

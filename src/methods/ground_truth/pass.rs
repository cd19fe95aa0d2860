//! Ground truth (thesis chapter 7): every VPL at every pixel with a BVH shadow ray, run in
//! VPL batches so no dispatch is long; the caller accumulates batches over frames.
//! Reads: BVH, a VPL array, G-buffer. Writes: an accumulation buffer (rgb sum per pixel).

use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use crate::gpu::shaders;
use crate::methods::FrameCx;
use bytemuck::{Pod, Zeroable};

use crate::gpu::passes::groups_2d;

/// Dynamic-offset stride of the per-batch uniforms; most batches per recorded call.
const STRIDE: u64 = 256;
pub const MAX_BATCHES: u32 = 64;

pub struct GroundTruthPass {
    kernel: Kernel,
    pipeline: wgpu::ComputePipeline,
    params: wgpu::Buffer,
}

impl GroundTruthPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(
            device,
            "methods/ground_truth/ground_truth.wgsl",
            &["main"],
            KernelOptions { dynamic: &["params"] },
        )?;
        let pipeline = kernel.compute(device, "ground_truth::pipeline", "main");
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ground_truth::params"),
            size: STRIDE * MAX_BATCHES as u64,
            usage: crate::gpu::passes::PARAMS_USAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(Self {
            kernel,
            pipeline,
            params,
        })
    }

    /// Records dispatches for VPLs `[begin, end)` of `vpls` in batches of `batch` VPLs (at
    /// most MAX_BATCHES batches; returns the end actually reached), shading the frame's
    /// G-buffer against its scene into `cx.gi_accum`.
    pub fn record(
        &self,
        cx: &mut FrameCx<'_>,
        encoder: &mut wgpu::CommandEncoder,
        base: GpuGtParams,
        batch: u32,
        vpls: &wgpu::Buffer,
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
            cx.queue
                .write_buffer(&self.params, n * STRIDE, bytemuck::bytes_of(&p));
            b = e;
            n += 1;
        }
        let bind = self.kernel.bind(
            cx.device,
            0,
            &[
                (
                    "params",
                    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &self.params,
                        offset: 0,
                        size: wgpu::BufferSize::new(std::mem::size_of::<GpuGtParams>() as u64),
                    }),
                ),
                ("bvh_nodes", buf(&cx.scene.bvh_nodes)),
                ("bvh_triangles", buf(&cx.scene.bvh_triangles)),
                ("vpls", buf(vpls)),
                ("gb_position", tex(&cx.targets.gbuffer.position_view)),
                ("gb_normal", tex(&cx.targets.gbuffer.normal_view)),
                ("gb_albedo", tex(&cx.targets.gbuffer.albedo_view)),
                ("accum", buf(cx.gi_accum)),
            ],
        );
        encoder.push_debug_group("ground_truth");
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("ground_truth::pass"),
                timestamp_writes: cx.timer.compute_pass("ground_truth"),
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

/// Twin: `GtParams` in `shaders/methods/ground_truth/ground_truth.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuGtParams {
    pub begin: u32,
    pub end: u32,
    pub width: u32,
    pub height: u32,
    pub epsilon: f32,
    pub ray_offset: f32,
    /// 1: shadow rays, 0: every VPL visible (`GiSettings::shadow_rays`).
    pub shadow_rays: u32,
    /// The BRDF model (`Brdf::gpu`).
    pub brdf: u32,
    /// xyz the camera's position (the view direction of glossy shading).
    pub eye: [f32; 4],
    /// The order the VPLs are summed in: step i evaluates VPL (i x order[0]) mod order[1]
    /// (a stride coprime with the count, [`crate::methods::ground_truth::visit_stride`]), so
    /// that every partial sum is spread over the whole set.
    pub order: [u32; 4],
}

/// The structs this method shares with WGSL (its `Module::wgsl_twins`: the registry test
/// checks them against naga's layout).
pub static WGSL_TWINS: &[crate::gpu::gpu_data::WgslTwin] = &[crate::wgsl_twin!(
    GpuGtParams,
    "methods/ground_truth/ground_truth.wgsl",
    "GtParams",
    [
        begin,
        end,
        width,
        height,
        epsilon,
        ray_offset,
        shadow_rays,
        brdf,
        eye,
        order
    ]
)];

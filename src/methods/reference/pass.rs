//! Converged reference (stage 19): every RSM texel as a VPL, estimated per pixel by Monte
//! Carlo through the RSM pyramids and accumulated over frames (see `shaders/methods/reference/reference.wgsl`).
//! Reads: VPL-stage pyramids and parameters, RSM, G-buffer, BVH. Writes: the GI accumulation.

use bytemuck::{Pod, Zeroable};

use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use crate::gpu::shaders;
use crate::methods::FrameCx;

use crate::gpu::passes::{groups_image, run_compute, uniform_buffer};

/// Twin: `RefParams` in `shaders/methods/reference/reference.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuRefParams {
    pub width: u32,
    pub height: u32,
    pub samples: u32,
    pub first_sample: u32,
    pub epsilon: f32,
    pub ray_offset: f32,
    pub flux_mix: f32,
    pub seed: u32,
    /// The BRDF model (`Brdf::gpu`).
    pub brdf: u32,
    pub _pad: [u32; 3],
    /// xyz the camera's position.
    pub eye: [f32; 4],
}

pub struct ReferencePass {
    kernel: Kernel,
    pipeline: wgpu::ComputePipeline,
    params: wgpu::Buffer,
}

impl ReferencePass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(
            device,
            "methods/reference/reference.wgsl",
            &["main"],
            KernelOptions::default(),
        )?;
        let pipeline = kernel.compute(device, "reference::pipeline", "main");
        let params = uniform_buffer::<GpuRefParams>(device, "reference::params");
        Ok(Self {
            kernel,
            pipeline,
            params,
        })
    }

    /// Records `p.samples` more samples per pixel into `cx.gi_accum` (from the frame's VPL
    /// pyramids, RSM, G-buffer and scene).
    pub fn record(&self, cx: &mut FrameCx<'_>, encoder: &mut wgpu::CommandEncoder, p: GpuRefParams) {
        let (vpl, rsm, gbuffer, scene) = (cx.vpl_buffers, &cx.targets.shadow, &cx.targets.gbuffer, cx.scene);
        cx.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let bind = self.kernel.bind(
            cx.device,
            0,
            &[
                ("params", buf(cx.vpl_params)),
                ("rp", buf(&self.params)),
                ("rsm_position", tex(&rsm.position_array)),
                ("rsm_normal", tex(&rsm.normal_array)),
                ("rsm_flux", tex(&rsm.flux_array)),
                ("gb_position", tex(&gbuffer.position_view)),
                ("gb_normal", tex(&gbuffer.normal_view)),
                ("gb_albedo", tex(&gbuffer.albedo_view)),
                ("importance_pyramid", buf(&vpl.importance_pyramid)),
                ("flux_pyramid", buf(&vpl.flux_pyramid)),
                ("bounds_pyramid", buf(&vpl.bounds_pyramid)),
                ("bvh_nodes", buf(&scene.bvh_nodes)),
                ("bvh_triangles", buf(&scene.bvh_triangles)),
                ("accum", buf(cx.gi_accum)),
            ],
        );
        run_compute(
            encoder,
            cx.timer,
            "reference",
            &self.pipeline,
            &bind,
            groups_image(p.width, p.height),
        );
    }
}

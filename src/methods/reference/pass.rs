//! Converged reference (stage 19): every RSM texel as a VPL, estimated per pixel by Monte
//! Carlo through the RSM pyramids and accumulated over frames (see `shaders/methods/reference/reference.wgsl`).
//! Reads: VPL-stage pyramids and parameters, RSM, G-buffer, BVH. Writes: the GI accumulation.

use bytemuck::{Pod, Zeroable};

use crate::gpu::frame::{GbufferTargets, ShadowTargets};
use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use crate::gpu::scene_gpu::SceneGpu;
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;

use crate::gpu::passes::{groups_image, run_compute, uniform_buffer, vpl_gen::VplBuffers};

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

    /// Records `p.samples` more samples per pixel into `accum`.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        p: GpuRefParams,
        vpl_params: &wgpu::Buffer,
        vpl: &VplBuffers,
        rsm: &ShadowTargets,
        gbuffer: &GbufferTargets,
        scene: &SceneGpu,
        accum: &wgpu::Buffer,
    ) {
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let bind = self.kernel.bind(
            device,
            0,
            &[
                ("params", buf(vpl_params)),
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
                ("accum", buf(accum)),
            ],
        );
        run_compute(
            encoder,
            timer,
            "reference",
            &self.pipeline,
            &bind,
            groups_image(p.width, p.height),
        );
    }
}

//! Direct light: rho/pi * E * max(0, n.l) * shadow-map visibility per directional light.
//! Reads: camera, lights, shadow maps, G-buffer. Writes: the `direct` radiance buffer.

use crate::gpu::frame::{GbufferTargets, ShadowTargets};
use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;

use super::{groups_image, run_compute};

pub const RADIANCE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

pub struct DirectPass {
    kernel: Kernel,
    pipeline: wgpu::ComputePipeline,
    /// `DirectParams`: x = the BRDF model (`Brdf::gpu`).
    params: wgpu::Buffer,
}

/// What the direct pass reads and writes.
pub struct DirectInputs<'a> {
    /// The BRDF model (`Brdf::gpu`).
    pub brdf: u32,
    pub camera: &'a wgpu::Buffer,
    pub lights: &'a wgpu::Buffer,
    pub shadow: &'a ShadowTargets,
    pub gbuffer: &'a GbufferTargets,
    pub out: &'a wgpu::TextureView,
    pub size: (u32, u32),
}

impl DirectPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(device, "direct.wgsl", &["main"], KernelOptions::default())?;
        let pipeline = kernel.compute(device, "direct::pipeline", "main");
        let params = super::uniform_buffer::<[u32; 4]>(device, "direct::params");
        Ok(Self {
            kernel,
            pipeline,
            params,
        })
    }

    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        i: &DirectInputs<'_>,
    ) {
        queue.write_buffer(&self.params, 0, bytemuck::cast_slice(&[i.brdf, 0u32, 0, 0]));
        let bind = self.kernel.bind(
            device,
            0,
            &[
                ("camera", buf(i.camera)),
                ("lights", buf(i.lights)),
                ("shadow_maps", tex(&i.shadow.array_view)),
                ("gb_position", tex(&i.gbuffer.position_view)),
                ("gb_normal", tex(&i.gbuffer.normal_view)),
                ("gb_albedo", tex(&i.gbuffer.albedo_view)),
                ("out_direct", tex(i.out)),
                ("dp", buf(&self.params)),
            ],
        );
        run_compute(
            encoder,
            timer,
            "direct",
            &self.pipeline,
            &bind,
            groups_image(i.size.0, i.size.1),
        );
    }
}

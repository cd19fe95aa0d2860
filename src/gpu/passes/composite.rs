//! Composite: indirect = accumulated GI x scale, final = direct + indirect.
//! Reads: the direct buffer, a GI accumulation buffer. Writes: the indirect and final buffers.

use bytemuck::{Pod, Zeroable};

use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;

use super::{groups_image, run_compute, uniform_buffer};

/// Twin: `CompositeParams` in `shaders/composite.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuCompositeParams {
    pub width: u32,
    pub height: u32,
    pub indirect_scale: f32,
    pub _pad: u32,
}

/// What the composite reads and writes: the direct image and the GI accumulation (times
/// `indirect_scale`) in, the indirect and final images out, all of `size`.
#[derive(Clone, Copy)]
pub struct CompositeInputs<'a> {
    pub size: (u32, u32),
    pub indirect_scale: f32,
    pub direct: &'a wgpu::TextureView,
    pub accum: &'a wgpu::Buffer,
    pub out_indirect: &'a wgpu::TextureView,
    pub out_final: &'a wgpu::TextureView,
}

pub struct CompositePass {
    kernel: Kernel,
    pipeline: wgpu::ComputePipeline,
    params: wgpu::Buffer,
}

impl CompositePass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(device, "composite.wgsl", &["main"], KernelOptions::default())?;
        let pipeline = kernel.compute(device, "composite::pipeline", "main");
        let params = uniform_buffer::<GpuCompositeParams>(device, "composite::params");
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
        c: &CompositeInputs<'_>,
    ) {
        let CompositeInputs {
            size,
            indirect_scale,
            direct,
            accum,
            out_indirect,
            out_final,
        } = *c;
        let p = GpuCompositeParams {
            width: size.0,
            height: size.1,
            indirect_scale,
            _pad: 0,
        };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let bind = self.kernel.bind(
            device,
            0,
            &[
                ("params", buf(&self.params)),
                ("direct", tex(direct)),
                ("accum", buf(accum)),
                ("out_indirect", tex(out_indirect)),
                ("out_final", tex(out_final)),
            ],
        );
        run_compute(
            encoder,
            timer,
            "composite",
            &self.pipeline,
            &bind,
            groups_image(size.0, size.1),
        );
    }
}

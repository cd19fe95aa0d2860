//! Display: exposure (2^EV), tonemap and sRGB encoding of a linear-radiance buffer into the
//! `Rgba8Unorm` view texture, with the view's look (channel, false colour, NaN highlight). Reads: one radiance buffer. Writes: the view texture.

use crate::gpu::gpu_data::DisplayParams;
use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;
use crate::gpu::views::ViewLook;

use super::{groups_image, run_compute, uniform_buffer};

pub const VIEW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// What one display dispatch reads and writes: the linear-radiance `src` shown with `look`
/// into the view texture `dst` of `size`.
#[derive(Clone, Copy)]
pub struct DisplayInputs<'a> {
    pub look: &'a ViewLook,
    pub src: &'a wgpu::TextureView,
    pub dst: &'a wgpu::TextureView,
    pub size: (u32, u32),
}

pub struct DisplayPass {
    kernel: Kernel,
    pipeline: wgpu::ComputePipeline,
    params: wgpu::Buffer,
}

impl DisplayPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(device, "display.wgsl", &["main"], KernelOptions::default())?;
        let pipeline = kernel.compute(device, "display::pipeline", "main");
        let params = uniform_buffer::<DisplayParams>(device, "display::params");
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
        i: &DisplayInputs<'_>,
    ) {
        let DisplayInputs { look, src, dst, size } = *i;
        let p = DisplayParams::new(look);
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let bind = self.kernel.bind(
            device,
            0,
            &[
                ("params", buf(&self.params)),
                ("src", tex(src)),
                ("dst", tex(dst)),
            ],
        );
        run_compute(
            encoder,
            timer,
            "display",
            &self.pipeline,
            &bind,
            groups_image(size.0, size.1),
        );
    }
}

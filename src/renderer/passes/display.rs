//! Display: exposure (2^EV), tonemap and sRGB encoding of a linear-radiance buffer into the
//! `Rgba8Unorm` view texture, with the view's look (channel, false colour, NaN highlight). Reads: one radiance buffer. Writes: the view texture.

use crate::renderer::{gpu_data::DisplayParams, shaders, timing::GpuTimer, views::ViewLook};

use super::{
    compute_pipeline, float_texture_entry, groups_image, run_compute, storage_texture_entry, uniform_buffer,
    uniform_entry,
};

pub const VIEW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

pub struct DisplayPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
}

impl DisplayPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let module = shaders::create_module(device, "display.wgsl")?;
        let layout = crate::renderer::passes::bind_group_layout(
            device,
            &wgpu::BindGroupLayoutDescriptor {
                label: Some("display::layout"),
                entries: &[
                    uniform_entry(0, wgpu::ShaderStages::COMPUTE),
                    float_texture_entry(1),
                    storage_texture_entry(2, VIEW_FORMAT),
                ],
            },
        );
        let pipeline = compute_pipeline(device, "display::pipeline", &[Some(&layout)], &module, "main");
        let params = uniform_buffer::<DisplayParams>(device, "display::params");
        Ok(Self {
            pipeline,
            layout,
            params,
        })
    }

    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        look: &ViewLook,
        src: &wgpu::TextureView,
        dst: &wgpu::TextureView,
        size: (u32, u32),
    ) {
        let p = DisplayParams::new(look);
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("display::bind_group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(src),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(dst),
                },
            ],
        });
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

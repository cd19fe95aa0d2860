//! Display: exposure (2^EV), tonemap and sRGB encoding of a linear-radiance buffer into the
//! `Rgba8Unorm` view texture. Reads: one radiance buffer. Writes: the view texture.

use crate::renderer::{gpu_data::DisplayParams, settings::DisplaySettings, shaders, timing::GpuTimer};

use super::{compute_pipeline, float_texture_entry, groups_2d, storage_texture_entry, uniform_entry};

pub const VIEW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

pub struct DisplayPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
}

impl DisplayPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let module = shaders::create_module(device, "display.wgsl")?;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("display::layout"),
            entries: &[
                uniform_entry(0, wgpu::ShaderStages::COMPUTE),
                float_texture_entry(1),
                storage_texture_entry(2, VIEW_FORMAT),
            ],
        });
        let pipeline = compute_pipeline(device, "display::pipeline", &[Some(&layout)], &module, "main");
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("display::params"),
            size: std::mem::size_of::<DisplayParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
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
        settings: &DisplaySettings,
        src: &wgpu::TextureView,
        dst: &wgpu::TextureView,
        size: (u32, u32),
    ) {
        let p = DisplayParams {
            exposure: settings.exposure_ev.exp2(),
            tonemap: settings.tonemap.gpu_id(),
            _pad: [0; 2],
        };
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
        encoder.push_debug_group("display");
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("display::pass"),
                timestamp_writes: timer.compute_pass("display"),
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind, &[]);
            let (gx, gy) = groups_2d(size.0, size.1);
            pass.dispatch_workgroups(gx, gy, 1);
        }
        encoder.pop_debug_group();
    }
}

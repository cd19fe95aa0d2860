//! Direct light: rho/pi * E * max(0, n.l) * shadow-map visibility per directional light.
//! Reads: camera, lights, shadow maps, G-buffer. Writes: the `direct` radiance buffer.

use crate::renderer::{
    frame::{GbufferTargets, ShadowTargets},
    shaders,
    timing::GpuTimer,
};

use super::{
    compute_pipeline, float_texture_entry, groups_image, run_compute, storage_texture_entry, texture_entry,
    uniform_entry,
};

pub const RADIANCE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

pub struct DirectPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    /// `DirectParams`: x = the BRDF model (`Brdf::gpu`).
    params: wgpu::Buffer,
}

impl DirectPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let module = shaders::create_module(device, "direct.wgsl")?;
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = crate::renderer::passes::bind_group_layout(
            device,
            &wgpu::BindGroupLayoutDescriptor {
                label: Some("direct::layout"),
                entries: &[
                    uniform_entry(0, c),
                    uniform_entry(1, c),
                    texture_entry(
                        2,
                        c,
                        wgpu::TextureSampleType::Depth,
                        wgpu::TextureViewDimension::D2Array,
                    ),
                    float_texture_entry(3),
                    float_texture_entry(4),
                    float_texture_entry(5),
                    storage_texture_entry(6, RADIANCE_FORMAT),
                    uniform_entry(7, c),
                ],
            },
        );
        let pipeline = compute_pipeline(device, "direct::pipeline", &[Some(&layout)], &module, "main");
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("direct::params"),
            size: 16,
            usage: crate::renderer::passes::PARAMS_USAGE | wgpu::BufferUsages::COPY_DST,
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
        brdf: u32,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        camera: &wgpu::Buffer,
        lights: &wgpu::Buffer,
        shadow: &ShadowTargets,
        gbuffer: &GbufferTargets,
        out: &wgpu::TextureView,
        size: (u32, u32),
    ) {
        queue.write_buffer(&self.params, 0, bytemuck::cast_slice(&[brdf, 0u32, 0, 0]));
        let tv = wgpu::BindingResource::TextureView;
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("direct::bind_group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: camera.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: lights.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: tv(&shadow.array_view),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: tv(&gbuffer.position_view),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: tv(&gbuffer.normal_view),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: tv(&gbuffer.albedo_view),
                },
                wgpu::BindGroupEntry {
                    binding: 6,
                    resource: tv(out),
                },
                wgpu::BindGroupEntry {
                    binding: 7,
                    resource: self.params.as_entire_binding(),
                },
            ],
        });
        run_compute(
            encoder,
            timer,
            "direct",
            &self.pipeline,
            &bind,
            groups_image(size.0, size.1),
        );
    }
}

//! Composite: indirect = accumulated GI x scale, final = direct + indirect.
//! Reads: the direct buffer, a GI accumulation buffer. Writes: the indirect and final buffers.

use bytemuck::{Pod, Zeroable};

use crate::renderer::{shaders, timing::GpuTimer};

use super::{
    compute_pipeline, direct::RADIANCE_FORMAT, float_texture_entry, groups_image, run_compute, storage_entry,
    storage_texture_entry, uniform_buffer, uniform_entry,
};

/// Twin: `CompositeParams` in `shaders/composite.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuCompositeParams {
    pub width: u32,
    pub height: u32,
    pub indirect_scale: f32,
    pub _pad: u32,
}

pub struct CompositePass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
}

impl CompositePass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let module = shaders::create_module(device, "composite.wgsl")?;
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = crate::renderer::passes::bind_group_layout(
            device,
            &wgpu::BindGroupLayoutDescriptor {
                label: Some("composite::layout"),
                entries: &[
                    uniform_entry(0, c),
                    float_texture_entry(1),
                    storage_entry(2, c, true),
                    storage_texture_entry(3, RADIANCE_FORMAT),
                    storage_texture_entry(4, RADIANCE_FORMAT),
                ],
            },
        );
        let pipeline = compute_pipeline(device, "composite::pipeline", &[Some(&layout)], &module, "main");
        let params = uniform_buffer::<GpuCompositeParams>(device, "composite::params");
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
        size: (u32, u32),
        indirect_scale: f32,
        direct: &wgpu::TextureView,
        accum: &wgpu::Buffer,
        out_indirect: &wgpu::TextureView,
        out_final: &wgpu::TextureView,
    ) {
        let p = GpuCompositeParams {
            width: size.0,
            height: size.1,
            indirect_scale,
            _pad: 0,
        };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let tv = wgpu::BindingResource::TextureView;
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("composite::bind_group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: tv(direct),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: accum.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: tv(out_indirect),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: tv(out_final),
                },
            ],
        });
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

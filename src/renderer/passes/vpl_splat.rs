//! VPL overlay: the frame's VPLs as discs over the view texture, coloured by flux (log scale
//! around the mean VPL flux). Reads: VPLs, camera, G-buffer. Writes: the view texture.

use bytemuck::{Pod, Zeroable};

use crate::renderer::{shaders, timing::GpuTimer};

use super::{
    WG_1D, compute_pipeline, display::VIEW_FORMAT, float_texture_entry, run_compute, storage_entry,
    storage_texture_entry, uniform_buffer, uniform_entry,
};

/// Twin: `SplatParams` in `shaders/vpl_splat.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuSplatParams {
    pub count: u32,
    /// 0 = camera view, 1 = RSM texel space.
    pub space: u32,
    pub radius: u32,
    pub layer: u32,
    pub rsm_res: u32,
    pub light_count: u32,
    pub per_layer: u32,
    pub top_offset: u32,
    /// 0 = flux, 1 = bounce.
    pub color_mode: u32,
    pub _pad: [u32; 3],
}

pub struct VplSplatPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
}

impl VplSplatPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let module = shaders::create_module(device, "vpl_splat.wgsl")?;
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = crate::renderer::passes::bind_group_layout(
            device,
            &wgpu::BindGroupLayoutDescriptor {
                label: Some("vpl_splat::layout"),
                entries: &[
                    uniform_entry(0, c),
                    uniform_entry(1, c),
                    storage_entry(2, c, true),
                    float_texture_entry(3),
                    storage_texture_entry(4, VIEW_FORMAT),
                    storage_entry(5, c, true),
                ],
            },
        );
        let pipeline = compute_pipeline(device, "vpl_splat::pipeline", &[Some(&layout)], &module, "main");
        let params = uniform_buffer::<GpuSplatParams>(device, "vpl_splat::params");
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
        p: GpuSplatParams,
        camera: &wgpu::Buffer,
        vpls: &wgpu::Buffer,
        flux_pyramid: &wgpu::Buffer,
        gb_position: &wgpu::TextureView,
        dst: &wgpu::TextureView,
    ) {
        if p.count == 0 {
            return;
        }
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("vpl_splat::bind_group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: camera.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: vpls.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(gb_position),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::TextureView(dst),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: flux_pyramid.as_entire_binding(),
                },
            ],
        });
        run_compute(
            encoder,
            timer,
            "vpl_splat",
            &self.pipeline,
            &bind,
            (p.count.div_ceil(WG_1D), 1, 1),
        );
    }
}

//! A/B comparison views of two radiance images (a tree sampler against the ground truth of the
//! same VPLs, snapshots, live buffers): split, side by side, A, B, difference x N, relative
//! error in log false colour. Reads: the two images, G-buffer positions. Writes: the view
//! texture.

use bytemuck::{Pod, Zeroable};

use crate::renderer::{shaders, timing::GpuTimer};

use super::{
    bind_group_seq, compute_pipeline, display::VIEW_FORMAT, float_texture_entry, groups_image, run_compute,
    storage_texture_entry, uniform_buffer, uniform_entry,
};

/// Twin: `CmpParams` in `shaders/compare_views.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuCmpParams {
    /// `views::AbMode::gpu_id`: 0 split, 1 relative error, 2 side by side (twice as wide),
    /// 3 difference x diff_scale, 4 A, 5 B.
    pub mode: u32,
    pub split_x: u32,
    pub exposure: f32,
    pub tonemap: u32,
    pub diff_scale: f32,
    pub _pad: [u32; 3],
}

pub struct CompareViewsPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
}

impl CompareViewsPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let module = shaders::create_module(device, "compare_views.wgsl")?;
        let layout = crate::renderer::passes::bind_group_layout(
            device,
            &wgpu::BindGroupLayoutDescriptor {
                label: Some("compare_views::layout"),
                entries: &[
                    uniform_entry(0, wgpu::ShaderStages::COMPUTE),
                    float_texture_entry(1),
                    float_texture_entry(2),
                    float_texture_entry(3),
                    storage_texture_entry(4, VIEW_FORMAT),
                ],
            },
        );
        Ok(Self {
            pipeline: compute_pipeline(device, "compare_views", &[Some(&layout)], &module, "main"),
            params: uniform_buffer::<GpuCmpParams>(device, "compare_views::params"),
            layout,
        })
    }

    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        p: GpuCmpParams,
        method_image: &wgpu::TextureView,
        reference_image: &wgpu::TextureView,
        gb_position: &wgpu::TextureView,
        dst: &wgpu::TextureView,
        size: (u32, u32),
    ) {
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let entries = [
            self.params.as_entire_binding(),
            wgpu::BindingResource::TextureView(method_image),
            wgpu::BindingResource::TextureView(reference_image),
            wgpu::BindingResource::TextureView(gb_position),
            wgpu::BindingResource::TextureView(dst),
        ];
        let bind = bind_group_seq(device, "compare_views::bind_group", &self.layout, &entries);
        run_compute(
            encoder,
            timer,
            "compare_views",
            &self.pipeline,
            &bind,
            groups_image(size.0, size.1),
        );
    }
}

//! A/B comparison views of two radiance images (a tree sampler against the ground truth of the
//! same VPLs, snapshots, live buffers): split, side by side, A, B, difference x N, relative
//! error in log false colour. Reads: the two images, G-buffer positions. Writes: the view
//! texture.

use bytemuck::{Pod, Zeroable};

use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;

use super::{groups_image, run_compute, uniform_buffer};

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

/// What one comparison dispatch reads and writes: the method's and the reference's images,
/// the G-buffer's positions, and the view texture `dst` of `size`.
#[derive(Clone, Copy)]
pub struct CompareInputs<'a> {
    pub method_image: &'a wgpu::TextureView,
    pub reference_image: &'a wgpu::TextureView,
    pub gb_position: &'a wgpu::TextureView,
    pub dst: &'a wgpu::TextureView,
    pub size: (u32, u32),
}

pub struct CompareViewsPass {
    kernel: Kernel,
    pipeline: wgpu::ComputePipeline,
    params: wgpu::Buffer,
}

impl CompareViewsPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(device, "compare_views.wgsl", &["main"], KernelOptions::default())?;
        Ok(Self {
            pipeline: kernel.compute(device, "compare_views", "main"),
            params: uniform_buffer::<GpuCmpParams>(device, "compare_views::params"),
            kernel,
        })
    }

    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        p: GpuCmpParams,
        i: &CompareInputs<'_>,
    ) {
        let CompareInputs {
            method_image,
            reference_image,
            gb_position,
            dst,
            size,
        } = *i;
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let bind = self.kernel.bind(
            device,
            0,
            &[
                ("cp", buf(&self.params)),
                ("image_a", tex(method_image)),
                ("image_b", tex(reference_image)),
                ("gb_position", tex(gb_position)),
                ("dst", tex(dst)),
            ],
        );
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

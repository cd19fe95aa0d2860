//! VPL overlay: the frame's VPLs as discs over the view texture, coloured by flux (log scale
//! around the mean VPL flux). Reads: VPLs, camera, G-buffer. Writes: the view texture.

use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use bytemuck::{Pod, Zeroable};

use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;

use super::{WG_1D, run_compute, uniform_buffer};

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

/// What the splat reads and draws into: the camera, the VPLs and their flux pyramid, the
/// G-buffer's positions and the view texture `dst`.
#[derive(Clone, Copy)]
pub struct SplatInputs<'a> {
    pub camera: &'a wgpu::Buffer,
    pub vpls: &'a wgpu::Buffer,
    pub flux_pyramid: &'a wgpu::Buffer,
    pub gb_position: &'a wgpu::TextureView,
    pub dst: &'a wgpu::TextureView,
}

pub struct VplSplatPass {
    pipeline: wgpu::ComputePipeline,
    kernel: Kernel,
    params: wgpu::Buffer,
}

impl VplSplatPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(device, "vpl_splat.wgsl", &["main"], KernelOptions::default())?;
        let pipeline = kernel.compute(device, "vpl_splat::pipeline", "main");
        let params = uniform_buffer::<GpuSplatParams>(device, "vpl_splat::params");
        Ok(Self {
            pipeline,
            kernel,
            params,
        })
    }

    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        p: GpuSplatParams,
        i: &SplatInputs<'_>,
    ) {
        let SplatInputs {
            camera,
            vpls,
            flux_pyramid,
            gb_position,
            dst,
        } = *i;
        if p.count == 0 {
            return;
        }
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let bind = self.kernel.bind(
            device,
            0,
            &[
                ("sp", buf(&self.params)),
                ("camera", buf(camera)),
                ("vpls", buf(vpls)),
                ("gb_position", tex(gb_position)),
                ("dst", tex(dst)),
                ("flux_pyramid", buf(flux_pyramid)),
            ],
        );
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

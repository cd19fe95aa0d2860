//! Evaluates the shaders' BRDF (`shaders/common/brdf.wgsl`) for a batch of cases on the GPU
//! (`shaders/brdf_eval.wgsl`): the test of the BRDF against its CPU twin `reference::brdf`.

use crate::gpu::kernel::{Kernel, KernelOptions, buf};
use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use super::{
    context::{GpuContext, GpuError},
    passes::{WG_1D, storage_buffer},
    readback, shaders,
};

/// Twin: `BrdfCase` in `shaders/brdf_eval.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuBrdfCase {
    /// xyz normal, w = model (0 Lambert, 1 GGX).
    pub n: [f32; 4],
    /// xyz view direction, w = metallic.
    pub v: [f32; 4],
    /// xyz light direction, w = roughness.
    pub l: [f32; 4],
    /// rgb base colour.
    pub base: [f32; 4],
}

/// One case's (diffuse, specular) rgb.
pub type BrdfParts = ([f32; 3], [f32; 3]);

pub struct BrdfProbe {
    pipeline: wgpu::ComputePipeline,
    kernel: Kernel,
}

impl BrdfProbe {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(device, "brdf_eval.wgsl", &["main"], KernelOptions::default())?;
        Ok(Self {
            pipeline: kernel.compute(device, "brdf_eval", "main"),
            kernel,
        })
    }

    /// (diffuse, specular) rgb of each case.
    pub fn run(&self, ctx: &GpuContext, cases: &[GpuBrdfCase]) -> Result<Vec<BrdfParts>, GpuError> {
        let device = &ctx.device;
        if cases.is_empty() {
            return Ok(Vec::new());
        }
        let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("brdf_eval::cases"),
            contents: bytemuck::cast_slice(cases),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let out = storage_buffer(device, "brdf_eval::out", 32 * cases.len() as u64);
        let bind = self
            .kernel
            .bind(device, 0, &[("cases", buf(&input)), ("out", buf(&out))]);
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("brdf_eval::encoder"),
        });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("brdf_eval"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups((cases.len() as u32).div_ceil(WG_1D), 1, 1);
        }
        ctx.queue.submit([enc.finish()]);
        let bytes = readback::read_storage_buffer(ctx, &out)?;
        let v: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&bytes[..32 * cases.len()]);
        Ok(v.chunks(2)
            .map(|p| ([p[0][0], p[0][1], p[0][2]], [p[1][0], p[1][1], p[1][2]]))
            .collect())
    }
}

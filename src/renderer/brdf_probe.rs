//! Evaluates the shaders' BRDF (`shaders/common/brdf.wgsl`) for a batch of cases on the GPU
//! (`shaders/brdf_eval.wgsl`): the test of the BRDF against its CPU twin `reference::brdf`.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use super::{
    context::{GpuContext, GpuError},
    passes::{WG_1D, bind_group_seq, compute_pipeline, storage_buffer, storage_entry},
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
    layout: wgpu::BindGroupLayout,
}

impl BrdfProbe {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let module = shaders::create_module(device, "brdf_eval.wgsl")?;
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = crate::renderer::passes::bind_group_layout(
            device,
            &wgpu::BindGroupLayoutDescriptor {
                label: Some("brdf_eval::layout"),
                entries: &[storage_entry(0, c, true), storage_entry(1, c, false)],
            },
        );
        Ok(Self {
            pipeline: compute_pipeline(device, "brdf_eval", &[Some(&layout)], &module, "main"),
            layout,
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
        let bind = bind_group_seq(
            device,
            "brdf_eval::bind_group",
            &self.layout,
            &[input.as_entire_binding(), out.as_entire_binding()],
        );
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

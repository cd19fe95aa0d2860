//! Converged reference (stage 19): every RSM texel as a VPL, estimated per pixel by Monte
//! Carlo through the RSM pyramids and accumulated over frames (see `shaders/methods/reference/reference.wgsl`).
//! Reads: VPL-stage pyramids and parameters, RSM, G-buffer, BVH. Writes: the GI accumulation.

use bytemuck::{Pod, Zeroable};

use crate::renderer::{
    frame::{GbufferTargets, ShadowTargets},
    scene_gpu::SceneGpu,
    shaders,
    timing::GpuTimer,
};

use crate::renderer::passes::{
    compute_pipeline, float_array_texture_entry, float_texture_entry, groups_image, run_compute,
    storage_entry, uniform_buffer, uniform_entry, vpl_gen::VplBuffers,
};

/// Twin: `RefParams` in `shaders/methods/reference/reference.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuRefParams {
    pub width: u32,
    pub height: u32,
    pub samples: u32,
    pub first_sample: u32,
    pub epsilon: f32,
    pub ray_offset: f32,
    pub flux_mix: f32,
    pub seed: u32,
    /// The BRDF model (`Brdf::gpu`).
    pub brdf: u32,
    pub _pad: [u32; 3],
    /// xyz the camera's position.
    pub eye: [f32; 4],
}

pub struct ReferencePass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
}

impl ReferencePass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let module = shaders::create_module(device, "methods/reference/reference.wgsl")?;
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = crate::renderer::passes::bind_group_layout(
            device,
            &wgpu::BindGroupLayoutDescriptor {
                label: Some("reference::layout"),
                entries: &[
                    uniform_entry(0, c),
                    uniform_entry(1, c),
                    float_array_texture_entry(2),
                    float_array_texture_entry(3),
                    float_array_texture_entry(4),
                    float_texture_entry(5),
                    float_texture_entry(6),
                    float_texture_entry(7),
                    storage_entry(8, c, true),
                    storage_entry(9, c, true),
                    storage_entry(10, c, true),
                    storage_entry(11, c, true),
                    storage_entry(12, c, true),
                    storage_entry(13, c, false),
                ],
            },
        );
        let pipeline = compute_pipeline(device, "reference::pipeline", &[Some(&layout)], &module, "main");
        let params = uniform_buffer::<GpuRefParams>(device, "reference::params");
        Ok(Self {
            pipeline,
            layout,
            params,
        })
    }

    /// Records `p.samples` more samples per pixel into `accum`.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        p: GpuRefParams,
        vpl_params: &wgpu::Buffer,
        vpl: &VplBuffers,
        rsm: &ShadowTargets,
        gbuffer: &GbufferTargets,
        scene: &SceneGpu,
        accum: &wgpu::Buffer,
    ) {
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let tv = wgpu::BindingResource::TextureView;
        let entries = [
            vpl_params.as_entire_binding(),
            self.params.as_entire_binding(),
            tv(&rsm.position_array),
            tv(&rsm.normal_array),
            tv(&rsm.flux_array),
            tv(&gbuffer.position_view),
            tv(&gbuffer.normal_view),
            tv(&gbuffer.albedo_view),
            vpl.importance_pyramid.as_entire_binding(),
            vpl.flux_pyramid.as_entire_binding(),
            vpl.bounds_pyramid.as_entire_binding(),
            scene.bvh_nodes.as_entire_binding(),
            scene.bvh_triangles.as_entire_binding(),
            accum.as_entire_binding(),
        ];
        let entries: Vec<wgpu::BindGroupEntry<'_>> = entries
            .into_iter()
            .enumerate()
            .map(|(i, resource)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource,
            })
            .collect();
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("reference::bind_group"),
            layout: &self.layout,
            entries: &entries,
        });
        run_compute(
            encoder,
            timer,
            "reference",
            &self.pipeline,
            &bind,
            groups_image(p.width, p.height),
        );
    }
}

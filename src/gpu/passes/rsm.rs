//! Reflective shadow map: an orthographic raster per directional light into one layer of
//! [`ShadowTargets`]: depth (the shadow map), world position, normal and reflected flux per
//! texel. Reads: scene vertices, materials, textures, the lights' view-projections.

use bytemuck::{Pod, Zeroable};

use crate::gpu::frame::{RSM_FLUX_FORMAT, RSM_NORMAL_FORMAT, RSM_POSITION_FORMAT, ShadowTargets};
use crate::gpu::gpu_data::{GpuLights, MAX_LIGHTS};
use crate::gpu::kernel::{Kernel, KernelOptions, buf, sampler, tex};
use crate::gpu::scene_gpu::SceneGpu;
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;

use super::gbuffer::{DEPTH_FORMAT, vertex_layout};

/// Uniform stride per light (dynamic offsets must be 256-byte aligned).
const STRIDE: u64 = 256;

/// Twin: `RsmLight` in `shaders/rsm.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuRsmLight {
    pub view_proj: [[f32; 4]; 4],
    /// rgb = irradiance E (W/m^2), w = texel area perpendicular to the light (m^2).
    pub irradiance: [f32; 4],
}

/// What the RSM pass renders: the frame's lights (one layer each), the scene, and the
/// shadow targets it draws into.
#[derive(Clone, Copy)]
pub struct RsmInputs<'a> {
    pub lights: &'a GpuLights,
    pub scene: &'a SceneGpu,
    pub out: &'a ShadowTargets,
}

pub struct RsmPass {
    pipeline: wgpu::RenderPipeline,
    kernel: Kernel,
    uniforms: wgpu::Buffer,
}

impl RsmPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(
            device,
            "rsm.wgsl",
            &["vs_main", "fs_main"],
            KernelOptions { dynamic: &["light"] },
        )?;
        let pl = kernel.pipeline_layout(device, &["vs_main", "fs_main"]);
        let targets = [RSM_POSITION_FORMAT, RSM_NORMAL_FORMAT, RSM_FLUX_FORMAT].map(|format| {
            Some(wgpu::ColorTargetState {
                format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("rsm::pipeline"),
            layout: Some(&pl),
            vertex: wgpu::VertexState {
                module: &kernel.module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(vertex_layout())],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                front_face: wgpu::FrontFace::Ccw,
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &kernel.module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        });
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("rsm::lights"),
            size: STRIDE * MAX_LIGHTS as u64,
            usage: crate::gpu::passes::PARAMS_USAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(Self {
            pipeline,
            kernel,
            uniforms,
        })
    }

    /// Renders one layer per light of `r.lights` (its first `count` entries).
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        r: &RsmInputs<'_>,
    ) {
        let RsmInputs { lights, scene, out } = *r;
        let count = (lights.count[0] as usize).min(MAX_LIGHTS);
        for (i, l) in lights.lights.iter().take(count).enumerate() {
            let texel = l.shadow[0];
            let u = GpuRsmLight {
                view_proj: l.view_proj,
                irradiance: [l.irradiance[0], l.irradiance[1], l.irradiance[2], texel * texel],
            };
            queue.write_buffer(&self.uniforms, i as u64 * STRIDE, bytemuck::bytes_of(&u));
        }
        let bind = self.kernel.bind(
            device,
            0,
            &[
                (
                    "light",
                    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &self.uniforms,
                        offset: 0,
                        size: wgpu::BufferSize::new(std::mem::size_of::<GpuRsmLight>() as u64),
                    }),
                ),
                ("materials", buf(&scene.materials)),
                ("textures", tex(&scene.textures_view)),
                ("tex_sampler", sampler(&scene.sampler)),
            ],
        );
        encoder.push_debug_group("rsm");
        let clear = |view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        for i in 0..out.layers() as usize {
            let name = if i == 0 {
                "rsm".to_string()
            } else {
                format!("rsm[{i}]")
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("rsm::pass"),
                color_attachments: &[
                    clear(&out.position_layers[i]),
                    clear(&out.normal_layers[i]),
                    clear(&out.flux_layers[i]),
                ],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &out.layer_views[i],
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: timer.render_pass(&name),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if i < count && scene.index_count > 0 {
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &bind, &[(i as u64 * STRIDE) as u32]);
                pass.set_vertex_buffer(0, scene.vertices.slice(..));
                pass.set_index_buffer(scene.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..scene.index_count, 0, 0..1);
            }
        }
        encoder.pop_debug_group();
    }
}

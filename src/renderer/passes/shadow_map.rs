//! Directional shadow map: a depth-only orthographic raster per light into one layer of
//! [`ShadowTargets`]. Reads: scene vertices, the lights' view-projections.

use glam::Mat4;

use crate::renderer::{
    frame::ShadowTargets, gpu_data::MAX_LIGHTS, scene_gpu::SceneGpu, shaders, timing::GpuTimer,
};

use super::gbuffer::{DEPTH_FORMAT, vertex_layout};

/// Uniform stride per light (dynamic offsets must be 256-byte aligned).
const STRIDE: u64 = 256;

pub struct ShadowMapPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    uniforms: wgpu::Buffer,
}

impl ShadowMapPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let module = shaders::create_module(device, "shadow_map.wgsl")?;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow_map::layout"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(64),
                },
                count: None,
            }],
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow_map::pipeline_layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("shadow_map::pipeline"),
            layout: Some(&pl),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(vertex_layout())],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
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
            fragment: None,
            multiview_mask: None,
            cache: None,
        });
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("shadow_map::light_matrices"),
            size: STRIDE * MAX_LIGHTS as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(Self {
            pipeline,
            layout,
            uniforms,
        })
    }

    /// Renders one layer per light matrix in `light_view_proj` (at most MAX_LIGHTS).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        light_view_proj: &[Mat4],
        scene: &SceneGpu,
        out: &ShadowTargets,
    ) {
        for (i, m) in light_view_proj.iter().take(MAX_LIGHTS).enumerate() {
            queue.write_buffer(
                &self.uniforms,
                i as u64 * STRIDE,
                bytemuck::cast_slice(&m.to_cols_array()),
            );
        }
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow_map::bind_group"),
            layout: &self.layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &self.uniforms,
                    offset: 0,
                    size: wgpu::BufferSize::new(64),
                }),
            }],
        });
        encoder.push_debug_group("shadow_map");
        for (i, layer_view) in out.layer_views.iter().enumerate() {
            let name = if i == 0 {
                "shadow_map".to_string()
            } else {
                format!("shadow_map[{i}]")
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow_map::pass"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: layer_view,
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
            if i < light_view_proj.len() && scene.index_count > 0 {
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

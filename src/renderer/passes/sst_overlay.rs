//! Light-tree overlay: the nodes of one SST level over the camera view, as substitute
//! distributions (ellipses in each node's plane at 1 and 2 sigma) or bounding boxes, coloured
//! by flux, usable flag or node. Reads: the tree, its flags, camera, G-buffer positions (to
//! dim what is hidden). Writes: the view texture (alpha-blended raster).

use bytemuck::{Pod, Zeroable};

use crate::renderer::{
    settings::{TreeColor, TreeOverlay},
    shaders,
    timing::GpuTimer,
};

use super::{
    bind_group_seq, display::VIEW_FORMAT, sst_build::TreeBuffers, storage_entry, texture_entry, uniform_entry,
};

/// Twin: `OverlayParams` in `shaders/sst_overlay.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuOverlayParams {
    pub level: u32,
    pub color_mode: u32,
    pub min_radius: f32,
    pub _pad: u32,
}

pub struct SstOverlayPass {
    ellipses: wgpu::RenderPipeline,
    boxes: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
}

impl SstOverlayPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let module = shaders::create_module(device, "sst_overlay.wgsl")?;
        let vf = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sst_overlay::layout"),
            entries: &[
                uniform_entry(0, vf),
                uniform_entry(1, vf),
                storage_entry(2, wgpu::ShaderStages::VERTEX, true),
                storage_entry(3, wgpu::ShaderStages::VERTEX, true),
                texture_entry(
                    4,
                    wgpu::ShaderStages::FRAGMENT,
                    wgpu::TextureSampleType::Float { filterable: false },
                    wgpu::TextureViewDimension::D2,
                ),
            ],
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("sst_overlay::pipeline_layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let targets = [Some(wgpu::ColorTargetState {
            format: VIEW_FORMAT,
            blend: Some(wgpu::BlendState::ALPHA_BLENDING),
            write_mask: wgpu::ColorWrites::COLOR,
        })];
        let pipeline = |label: &str, vs: &str, fs: &str, topology| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&pl),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(vs),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState {
                    topology,
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        Ok(Self {
            ellipses: pipeline(
                "sst_overlay::ellipses",
                "vs_ellipse",
                "fs_ellipse",
                wgpu::PrimitiveTopology::TriangleList,
            ),
            boxes: pipeline(
                "sst_overlay::boxes",
                "vs_box",
                "fs_box",
                wgpu::PrimitiveTopology::LineList,
            ),
            params: super::uniform_buffer::<GpuOverlayParams>(device, "sst_overlay::params"),
            layout,
        })
    }

    /// Draws level `level` (clamped to the leaves) of `tree` over `dst`. `min_radius`
    /// (metres) is the smallest drawn semi-axis.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        mode: TreeOverlay,
        color: TreeColor,
        level: u32,
        min_radius: f32,
        camera: &wgpu::Buffer,
        tree: &TreeBuffers,
        gb_position: &wgpu::TextureView,
        dst: &wgpu::TextureView,
    ) {
        let (pipeline, verts) = match mode {
            TreeOverlay::Off => return,
            TreeOverlay::Distributions => (&self.ellipses, 6),
            TreeOverlay::Boxes => (&self.boxes, 24),
        };
        let level = level.min(tree.levels() - 1);
        let p = GpuOverlayParams {
            level,
            color_mode: match color {
                TreeColor::Intensity => 0,
                TreeColor::Usable => 1,
                TreeColor::Node => 2,
            },
            min_radius,
            _pad: 0,
        };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let entries = [
            self.params.as_entire_binding(),
            camera.as_entire_binding(),
            tree.nodes.as_entire_binding(),
            tree.flags.as_entire_binding(),
            wgpu::BindingResource::TextureView(gb_position),
        ];
        let bind = bind_group_seq(device, "sst_overlay::bind_group", &self.layout, &entries);
        encoder.push_debug_group("sst_overlay");
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("sst_overlay"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: dst,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: timer.render_pass("sst_overlay"),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.draw(0..verts, 0..(1u32 << level));
        }
        encoder.pop_debug_group();
    }
}

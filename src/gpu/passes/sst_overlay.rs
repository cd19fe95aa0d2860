//! Light-tree overlay: the nodes of one SST level over the camera view, as substitute
//! distributions (ellipses in each node's plane at 1 and 2 sigma) or bounding boxes, coloured
//! by flux, usable flag or node; on the radix tree a level is the cut at that depth (its
//! shallower leaves included). With `display.tree_compare`, both trees side by side (perfect
//! left, radix right). Reads: the tree(s), flags, parents, camera, G-buffer positions (to dim
//! what is hidden). Writes: the view texture (alpha-blended raster).

use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use bytemuck::{Pod, Zeroable};

use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;
use crate::settings::{TreeColor, TreeKind, TreeOverlay};

use super::{display::VIEW_FORMAT, sst_build::TreeBuffers};

/// Twin: `OverlayParams` in `shaders/sst_overlay.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuOverlayParams {
    pub level: u32,
    pub color_mode: u32,
    pub min_radius: f32,
    pub radix: u32,
    pub leaves: u32,
    pub _pad: [u32; 3],
}

/// How the overlay draws: `mode` (distributions or boxes), the colouring, the tree level
/// (clamped to the leaves) and the smallest drawn semi-axis `min_radius` (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OverlayLook {
    pub mode: TreeOverlay,
    pub color: TreeColor,
    pub level: u32,
    pub min_radius: f32,
}

/// What the overlay draws and over what: the camera, the frame's tree with, optionally, the
/// other kind of tree over the same VPLs, the G-buffer's positions, and `dst` of `size`.
#[derive(Clone, Copy)]
pub struct OverlayInputs<'a> {
    pub camera: &'a wgpu::Buffer,
    pub trees: (&'a TreeBuffers, Option<&'a TreeBuffers>),
    pub gb_position: &'a wgpu::TextureView,
    pub dst: &'a wgpu::TextureView,
    pub size: (u32, u32),
}

pub struct SstOverlayPass {
    ellipses: wgpu::RenderPipeline,
    boxes: wgpu::RenderPipeline,
    kernel: Kernel,
    params: wgpu::Buffer,
    params_b: wgpu::Buffer,
}

impl SstOverlayPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let entries = ["vs_ellipse", "fs_ellipse", "vs_box", "fs_box"];
        let kernel = Kernel::new(device, "sst_overlay.wgsl", &entries, KernelOptions::default())?;
        let pl = kernel.pipeline_layout(device, &entries);
        let module = &kernel.module;
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
                    module,
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
                    module,
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
            params_b: super::uniform_buffer::<GpuOverlayParams>(device, "sst_overlay::params_b"),
            kernel,
        })
    }

    /// Draws level `look.level` (clamped to the leaves) of the tree over `dst`. With the
    /// other tree (`trees.1`), the two side by side: the perfect tree in the left half of
    /// `dst`, the radix tree in the right half (`size`: dst's).
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        look: OverlayLook,
        i: &OverlayInputs<'_>,
    ) {
        let OverlayLook {
            mode,
            color,
            level,
            min_radius,
        } = look;
        let OverlayInputs {
            camera,
            trees,
            gb_position,
            dst,
            size,
        } = *i;
        let (pipeline, verts) = match mode {
            TreeOverlay::Off => return,
            TreeOverlay::Distributions => (&self.ellipses, 6),
            TreeOverlay::Boxes => (&self.boxes, 24),
        };
        let mut halves: Vec<(&TreeBuffers, Option<(u32, u32)>)> = vec![(trees.0, None)];
        if let Some(other) = trees.1 {
            let half = size.0 / 2;
            halves = [trees.0, other]
                .into_iter()
                .map(|t| match t.kind {
                    TreeKind::Perfect => (t, Some((0, half))),
                    TreeKind::Lbvh => (t, Some((half, size.0 - half))),
                })
                .collect();
        }
        let params: Vec<GpuOverlayParams> = halves
            .iter()
            .map(|(tree, _)| {
                let radix = tree.kind == TreeKind::Lbvh;
                GpuOverlayParams {
                    level: if radix {
                        level
                    } else {
                        level.min(tree.levels() - 1)
                    },
                    color_mode: match color {
                        TreeColor::Intensity => 0,
                        TreeColor::Usable => 1,
                        TreeColor::Node => 2,
                    },
                    min_radius,
                    radix: radix as u32,
                    leaves: tree.leaves,
                    _pad: [0; 3],
                }
            })
            .collect();
        // One uniform slot per half (dynamic offsets would need another layout): the second
        // half's parameters go to their own buffer.
        let bufs = [&self.params, &self.params_b];
        for (k, p) in params.iter().enumerate() {
            queue.write_buffer(bufs[k], 0, bytemuck::bytes_of(p));
        }
        encoder.push_debug_group("sst_overlay");
        for (k, ((tree, scissor), p)) in halves.iter().zip(&params).enumerate() {
            let bind = self.kernel.bind(
                device,
                0,
                &[
                    ("op", buf(bufs[k])),
                    ("camera", buf(camera)),
                    ("tree", buf(&tree.nodes)),
                    ("flags", buf(&tree.flags)),
                    ("gb_position", tex(gb_position)),
                    ("parents", buf(&tree.parents)),
                    ("tree_links", buf(&tree.links)),
                ],
            );
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
                timestamp_writes: timer.render_pass(if k == 0 { "sst_overlay" } else { "sst_overlay_b" }),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind, &[]);
            if let Some((x, w)) = scissor {
                if *w == 0 || size.1 == 0 {
                    continue;
                }
                pass.set_scissor_rect(*x, 0, *w, size.1);
            }
            let instances = if p.radix != 0 {
                2 * tree.leaves - 1
            } else {
                1u32 << p.level
            };
            pass.draw(0..verts, 0..instances);
        }
        encoder.pop_debug_group();
    }
}

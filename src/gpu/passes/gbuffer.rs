//! G-buffer pass: raster from the camera into position / normal / albedo (+ depth).
//! Reads: scene vertices, materials, textures, camera. Writes: [`GbufferTargets`].
//!
//! With the depth pre-pass (the default, [`GbufferPass::prepass`]) a depth-only pass
//! (`gbuffer_depth`) rasterises the scene first and the shading pass (`gbuffer`) tests depth
//! Equal without writing it, so every covered pixel is shaded and written once instead of
//! once per fragment that passes the depth test in draw order (Sponza's single draw in file
//! order). The shading pass draws the triangles in reverse order, so that at exact depth ties
//! the first triangle in file order wins as with Less: the values written are the same.
//! [`OverdrawCounter`] counts the fragments of
//! each way (machine-independent: rasterisation rules and draw order), for `bench gbuffer`.

use crate::gpu::frame::GbufferTargets;
use crate::gpu::gpu_data::GpuVertex;
use crate::gpu::kernel::{Kernel, KernelOptions, buf, sampler, tex};
use crate::gpu::scene_gpu::SceneGpu;
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;

pub const POSITION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
pub const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const ALBEDO_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

pub const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 4] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Uint32];

pub fn vertex_layout() -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<GpuVertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &VERTEX_ATTRIBUTES,
    }
}

/// Bytes a shaded fragment writes to the colour targets (position 16, normal 8, albedo 8).
pub const COLOR_BYTES_PER_FRAGMENT: u32 = 32;
/// Bytes of a depth write.
pub const DEPTH_BYTES: u32 = 4;

pub struct GbufferPass {
    /// Shading with depth test Less and depth writes (no pre-pass).
    pipeline: wgpu::RenderPipeline,
    /// Depth only (the pre-pass).
    depth_only: wgpu::RenderPipeline,
    /// Shading after the pre-pass: depth test Equal, no depth writes.
    pipeline_equal: wgpu::RenderPipeline,
    kernel: Kernel,
    /// Depth pre-pass on (the frame's default); off is the single pass of before issue 18,
    /// which `bench gbuffer` measures beside it.
    pub prepass: bool,
}

/// The depth state of the G-buffer raster: test `compare`, writes on or off.
fn depth_state(compare: wgpu::CompareFunction, write: bool) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(write),
        depth_compare: Some(compare),
        stencil: Default::default(),
        bias: Default::default(),
    }
}

/// The G-buffer's primitive state (two-sided: no culling).
fn primitive() -> wgpu::PrimitiveState {
    wgpu::PrimitiveState {
        topology: wgpu::PrimitiveTopology::TriangleList,
        front_face: wgpu::FrontFace::Ccw,
        cull_mode: None,
        ..Default::default()
    }
}

impl GbufferPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(
            device,
            "gbuffer.wgsl",
            &["vs_main", "fs_main"],
            KernelOptions::default(),
        )?;
        let pl = kernel.pipeline_layout(device, &["vs_main", "fs_main"]);
        let module = &kernel.module;
        let targets = [POSITION_FORMAT, NORMAL_FORMAT, ALBEDO_FORMAT].map(|format| {
            Some(wgpu::ColorTargetState {
                format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })
        });
        let shading = |label, depth| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&pl),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[Some(vertex_layout())],
                },
                primitive: primitive(),
                depth_stencil: Some(depth),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let pipeline = shading(
            "gbuffer::pipeline",
            depth_state(wgpu::CompareFunction::Less, true),
        );
        let pipeline_equal = shading(
            "gbuffer::pipeline_equal",
            depth_state(wgpu::CompareFunction::Equal, false),
        );
        let depth_only = depth_only_pipeline(device, "gbuffer::depth_only", &pl, module);
        Ok(Self {
            pipeline,
            depth_only,
            pipeline_equal,
            kernel,
            prepass: true,
        })
    }

    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        camera: &wgpu::Buffer,
        scene: &SceneGpu,
        out: &GbufferTargets,
    ) {
        let bind = self.kernel.bind(
            device,
            0,
            &[
                ("camera", buf(camera)),
                ("materials", buf(&scene.materials)),
                ("textures", tex(&scene.textures_view)),
                ("tex_sampler", sampler(&scene.sampler)),
            ],
        );
        encoder.push_debug_group("gbuffer");
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
        let draw =
            |pass: &mut wgpu::RenderPass<'_>, pipeline: &wgpu::RenderPipeline, indices: &wgpu::Buffer| {
                if scene.index_count > 0 {
                    pass.set_pipeline(pipeline);
                    pass.set_bind_group(0, &bind, &[]);
                    pass.set_vertex_buffer(0, scene.vertices.slice(..));
                    pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
                    pass.draw_indexed(0..scene.index_count, 0, 0..1);
                }
            };
        if self.prepass {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("gbuffer_depth::pass"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &out.depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: timer.render_pass("gbuffer_depth"),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            draw(&mut pass, &self.depth_only, &scene.indices);
        }
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("gbuffer::pass"),
                color_attachments: &[
                    clear(&out.position_view),
                    clear(&out.normal_view),
                    clear(&out.albedo_view),
                ],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &out.depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: if self.prepass {
                            wgpu::LoadOp::Load
                        } else {
                            wgpu::LoadOp::Clear(1.0)
                        },
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: timer.render_pass("gbuffer"),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            // After the pre-pass every triangle at a pixel's nearest depth passes Equal and
            // the last drawn stays: drawn in reverse, that is the first in file order, the
            // one a single pass with Less keeps. The G-buffer is the same either way.
            if self.prepass {
                draw(&mut pass, &self.pipeline_equal, &scene.indices_reversed);
            } else {
                draw(&mut pass, &self.pipeline, &scene.indices);
            }
        }
        encoder.pop_debug_group();
    }
}

/// A depth-only pipeline of the scene's vertex format (`vs_main` of `module`).
fn depth_only_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[Some(vertex_layout())],
        },
        primitive: primitive(),
        depth_stencil: Some(depth_state(wgpu::CompareFunction::Less, true)),
        multisample: Default::default(),
        fragment: None,
        multiview_mask: None,
        cache: None,
    })
}

/// Fragments of the G-buffer raster of one view, per way of drawing it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OverdrawCounts {
    /// Pixels covered by geometry.
    pub covered: u64,
    /// Every rasterised fragment (the depth complexity: what a GPU shades without early depth
    /// testing).
    pub rasterised: u64,
    /// Fragments that pass the depth test Less in draw order (shaded and written with early
    /// depth testing; the G-buffer without the pre-pass).
    pub written_single_pass: u64,
    /// Fragments that pass the depth test Equal after the depth pre-pass (1 per covered pixel
    /// unless coplanar duplicates tie).
    pub written_after_prepass: u64,
    pub pixels: u64,
}

impl OverdrawCounts {
    /// G-buffer bytes written per frame pixel without the pre-pass (colour + depth per
    /// written fragment).
    pub fn bytes_per_pixel_single_pass(&self) -> f64 {
        self.written_single_pass as f64 * (COLOR_BYTES_PER_FRAGMENT + DEPTH_BYTES) as f64
            / self.pixels.max(1) as f64
    }
    /// ... with the pre-pass (colour per written fragment, depth once per covered pixel's
    /// fragments that pass Less in the pre-pass).
    pub fn bytes_per_pixel_prepass(&self) -> f64 {
        (self.written_after_prepass as f64 * COLOR_BYTES_PER_FRAGMENT as f64
            + self.written_single_pass as f64 * DEPTH_BYTES as f64)
            / self.pixels.max(1) as f64
    }
}

/// Counts the G-buffer's fragments: the scene drawn as the G-buffer draws it (same vertex
/// stage, same order, same depth states) into an additive `Rgba16Float` counter (exact to
/// 2048 per pixel), read back and summed.
pub struct OverdrawCounter {
    count: wgpu::RenderPipeline,
    count_less: wgpu::RenderPipeline,
    count_equal: wgpu::RenderPipeline,
    depth_only: wgpu::RenderPipeline,
    kernel: Kernel,
}

const COUNT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

impl OverdrawCounter {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(
            device,
            "gbuffer_overdraw.wgsl",
            &["vs_main", "fs_count"],
            KernelOptions::default(),
        )?;
        let pl = kernel.pipeline_layout(device, &["vs_main", "fs_count"]);
        let module = &kernel.module;
        let add = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        let targets = [Some(wgpu::ColorTargetState {
            format: COUNT_FORMAT,
            blend: Some(wgpu::BlendState {
                color: add,
                alpha: add,
            }),
            write_mask: wgpu::ColorWrites::ALL,
        })];
        let counting = |label, depth| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&pl),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[Some(vertex_layout())],
                },
                primitive: primitive(),
                depth_stencil: depth,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some("fs_count"),
                    compilation_options: Default::default(),
                    targets: &targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        Ok(Self {
            count: counting("overdraw::all", None),
            count_less: counting(
                "overdraw::less",
                Some(depth_state(wgpu::CompareFunction::Less, true)),
            ),
            count_equal: counting(
                "overdraw::equal",
                Some(depth_state(wgpu::CompareFunction::Equal, false)),
            ),
            depth_only: depth_only_pipeline(device, "overdraw::depth_only", &pl, module),
            kernel,
        })
    }

    /// Counts the fragments of `scene` seen through `camera` (a `GpuCamera` uniform) at
    /// `size`.
    pub fn count(
        &self,
        ctx: &crate::gpu::context::GpuContext,
        camera: &wgpu::Buffer,
        scene: &SceneGpu,
        size: (u32, u32),
    ) -> Result<OverdrawCounts, crate::gpu::context::GpuError> {
        let device = &ctx.device;
        let texture = |label, format, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: size.0,
                    height: size.1,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let counter = texture(
            "overdraw::counter",
            COUNT_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let depth = texture(
            "overdraw::depth",
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let cv = counter.create_view(&Default::default());
        let dv = depth.create_view(&Default::default());
        let bind = self.kernel.bind(device, 0, &[("camera", buf(camera))]);
        // One count: optionally the depth pre-pass (its own pass, no colour target), then
        // `pipeline` into the cleared counter (depth cleared, or loaded after the pre-pass).
        let run = |pipeline: &wgpu::RenderPipeline, with_depth: bool, prepass: bool| {
            let mut enc = device.create_command_encoder(&Default::default());
            let depth_attachment = |load| wgpu::RenderPassDepthStencilAttachment {
                view: &dv,
                depth_ops: Some(wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            };
            let draw = |pass: &mut wgpu::RenderPass<'_>, p: &wgpu::RenderPipeline| {
                if scene.index_count > 0 {
                    pass.set_pipeline(p);
                    pass.set_bind_group(0, &bind, &[]);
                    pass.set_vertex_buffer(0, scene.vertices.slice(..));
                    pass.set_index_buffer(scene.indices.slice(..), wgpu::IndexFormat::Uint32);
                    pass.draw_indexed(0..scene.index_count, 0, 0..1);
                }
            };
            if prepass {
                let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("overdraw::depth_pass"),
                    color_attachments: &[],
                    depth_stencil_attachment: Some(depth_attachment(wgpu::LoadOp::Clear(1.0))),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                draw(&mut pass, &self.depth_only);
            }
            {
                let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("overdraw::pass"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &cv,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: with_depth.then(|| {
                        depth_attachment(if prepass {
                            wgpu::LoadOp::Load
                        } else {
                            wgpu::LoadOp::Clear(1.0)
                        })
                    }),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                draw(&mut pass, pipeline);
            }
            ctx.queue.submit([enc.finish()]);
            crate::gpu::readback::read_texture_f32(ctx, &counter, 0)
        };
        let sum = |img: &crate::base::image::ImageF32| -> (u64, u64) {
            img.pixels.iter().fold((0, 0), |(n, c), p| {
                let k = p[0].round() as u64;
                (n + k, c + (k > 0) as u64)
            })
        };
        let (rasterised, covered) = sum(&run(&self.count, false, false)?);
        let (written_single_pass, _) = sum(&run(&self.count_less, true, false)?);
        let (written_after_prepass, _) = sum(&run(&self.count_equal, true, true)?);
        Ok(OverdrawCounts {
            covered,
            rasterised,
            written_single_pass,
            written_after_prepass,
            pixels: size.0 as u64 * size.1 as u64,
        })
    }
}

//! Lightcuts' GPU passes: `lightcuts_build` (normal cones and representatives per node, one
//! dispatch per tree level, bottom-up), `lightcuts` (the per-pixel cut), `lightcuts_views`.
//! Reads: the light tree (nodes, VPLs in leaf order), BVH, G-buffer. Writes: the GI
//! accumulation, per-pixel diagnostics, counters and the pinned pixel's cut.

use bytemuck::{Pod, Zeroable};

use crate::reference::lightcuts::{Cone, LcTree, MAX_CUT};
use crate::renderer::{
    context::{GpuContext, GpuError},
    frame::GbufferTargets,
    passes::sst_build::TreeBuffers,
    passes::{
        WG_1D, bind_group_seq, compute_pipeline_with, dynamic_uniform_entry, float_texture_entry,
        groups_image, run_compute, storage_entry, storage_texture_entry, uniform_buffer, uniform_entry,
    },
    readback::{self, AsyncReadback},
    scene_gpu::SceneGpu,
    shaders,
    timing::GpuTimer,
};

/// Twin: `LcBuildParams` in `lc_build.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuLcBuildParams {
    pub first: u32,
    pub count: u32,
    pub leaves: u32,
    pub seed: u32,
}

/// Twin: `LcParams` in `lightcuts.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuLcParams {
    pub width: u32,
    pub height: u32,
    pub leaves: u32,
    pub max_cut: u32,
    pub relative_error: f32,
    pub epsilon: f32,
    pub ray_offset: f32,
    pub shadow_rays: u32,
    pub accumulate: u32,
    /// x | y << 16, or u32::MAX.
    pub trace_pixel: u32,
    /// This slice's first pixel (row-major; set per dispatch).
    pub first_pixel: u32,
    /// Pixels per slice: threads per dispatch and the scratch's stride.
    pub slice: u32,
    /// 1 when the dispatch starts the slice's cuts, 1 when it finishes them (set per dispatch).
    pub first: u32,
    pub last: u32,
    /// Refinements per dispatch at most ([`steps_per_dispatch`]).
    pub steps: u32,
    pub _pad: u32,
}

/// Refinements per dispatch: all of them on a GPU; 16 on a CPU adapter, where lavapipe
/// ends a shader invocation after 65535 loop iterations in total (gallivm's loop limiter,
/// which counts the shadow rays' BVH traversal steps too), so a long refinement is split
/// over dispatches that carry each pixel's state. The cuts are the same either way.
pub fn steps_per_dispatch(device_type: wgpu::DeviceType) -> u32 {
    if device_type == wgpu::DeviceType::Cpu {
        16
    } else {
        u32::MAX
    }
}

/// Dispatches per slice for cuts of `max_cut` nodes in a tree of `levels` levels with
/// `steps` refinements each: a refinement adds a node unless a child is empty, which only
/// the padded right spine has (at most `levels` such nodes).
pub fn dispatches_per_slice(max_cut: u32, levels: u32, steps: u32) -> u32 {
    ((max_cut as u64 + levels as u64).div_ceil(steps.max(1) as u64)).clamp(1, 4096) as u32
}

/// Twin: `LcViewParams` in `lc_views.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuLcViewParams {
    pub mode: u32,
    /// The top of the log scales (a power of ten).
    pub scale_top: u32,
    pub relative_error: f32,
    pub exposure: f32,
    pub tonemap: u32,
    pub _pad: [u32; 3],
}

/// Dynamic-offset stride of the per-level build and per-slice uniforms; levels at most.
const STRIDE: u64 = 256;
/// Bytes of the heaps' scratch at most (slice x max_cut entries of 8 bytes).
pub const SCRATCH_BUDGET: u64 = 128 << 20;
const MAX_LEVELS: u64 = 32;
/// Counter words: pixels, pixels at max_cut, cut nodes, refinements, shadow rays (64 bit each).
const STATS: usize = 8;
const TRACE_WORDS: u64 = 8 + 8 * MAX_CUT as u64;

/// The frame's counters (diagnostic frames).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LcStats {
    pub pixels: u32,
    pub at_max_cut: u32,
    pub cut_nodes: u64,
    pub refinements: u64,
    pub shadow_rays: u64,
}

impl LcStats {
    pub fn from_words(w: &[u32]) -> Self {
        let w64 = |i: usize| w[i] as u64 | (w[i + 1] as u64) << 32;
        Self {
            pixels: w[0],
            at_max_cut: w[1],
            cut_nodes: w64(2),
            refinements: w64(4),
            shadow_rays: w64(6),
        }
    }
    fn per_pixel(&self, v: u64) -> f64 {
        v as f64 / self.pixels.max(1) as f64
    }
    pub fn mean_cut(&self) -> f64 {
        self.per_pixel(self.cut_nodes)
    }
    pub fn rays_per_pixel(&self) -> f64 {
        self.per_pixel(self.shadow_rays)
    }
    pub fn max_cut_fraction(&self) -> f64 {
        self.at_max_cut as f64 / self.pixels.max(1) as f64
    }
}

/// One node of the pinned pixel's cut.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TracedNode {
    pub node: u32,
    /// Its representative (leaf index).
    pub rep: u32,
    pub bound: f32,
    /// Its estimate (flux / pi x G x V, without the receiver's rho / pi).
    pub estimate: [f32; 3],
}

/// The pinned pixel's lightcut in the last diagnostic frame.
#[derive(Clone, Debug, PartialEq)]
pub struct TracedCut {
    pub pixel: u32,
    pub refinements: u32,
    pub relative_bound: f32,
    pub shadow_rays: u32,
    pub nodes: Vec<TracedNode>,
}

impl TracedCut {
    pub fn parse(w: &[u32]) -> Option<TracedCut> {
        if w.len() < 8 || w[4] == 0 {
            return None;
        }
        let n = (w[0] as usize).min(MAX_CUT as usize);
        let nodes = (0..n)
            .filter_map(|i| {
                let r = w.get(8 + 8 * i..16 + 8 * i)?;
                Some(TracedNode {
                    node: r[0],
                    rep: r[1],
                    bound: f32::from_bits(r[2]),
                    estimate: [f32::from_bits(r[3]), f32::from_bits(r[4]), f32::from_bits(r[5])],
                })
            })
            .collect();
        Some(TracedCut {
            pixel: w[4] - 1,
            refinements: w[1],
            relative_bound: f32::from_bits(w[2]),
            shadow_rays: w[3],
            nodes,
        })
    }
}

/// Per-node and per-pixel buffers (resized with the tree and the frame).
pub struct LcBuffers {
    pub cones: wgpu::Buffer,
    pub reps: wgpu::Buffer,
    pub leaves: u32,
    pub diag: wgpu::Buffer,
    pub stats: wgpu::Buffer,
    pub trace: wgpu::Buffer,
    pub size: (u32, u32),
    /// The heaps (slice x max_cut entries) and the pixels per slice.
    pub scratch: wgpu::Buffer,
    /// Each pixel's refinement state between dispatches (32 bytes per slice pixel).
    pub state: wgpu::Buffer,
    pub slice: u32,
    pub max_cut: u32,
}

/// Pixels per slice for `pixels` pixels and cuts of `max_cut` within `budget` bytes: a
/// multiple of the workgroup size, at least one workgroup.
pub fn slice_pixels(pixels: u32, max_cut: u32, budget: u64) -> u32 {
    let fit = (budget / (8 * max_cut.max(1) as u64)).min(u32::MAX as u64) as u32;
    let fit = (fit / WG_1D * WG_1D).max(WG_1D);
    fit.min(pixels.div_ceil(WG_1D) * WG_1D).max(WG_1D)
}

fn storage(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

impl LcBuffers {
    pub fn new(device: &wgpu::Device, leaves: u32, size: (u32, u32), max_cut: u32, budget: u64) -> Self {
        let nodes = 2 * leaves as u64;
        let slice = slice_pixels(size.0 * size.1, max_cut, budget);
        Self {
            scratch: storage(device, "lightcuts::scratch", 8 * slice as u64 * max_cut as u64),
            state: storage(device, "lightcuts::state", 32 * slice as u64),
            slice,
            max_cut,
            cones: storage(device, "lightcuts::cones", 16 * nodes),
            reps: storage(device, "lightcuts::reps", 4 * nodes),
            leaves,
            diag: storage(device, "lightcuts::diag", 16 * size.0 as u64 * size.1 as u64),
            stats: storage(device, "lightcuts::stats", 4 * STATS as u64),
            trace: storage(device, "lightcuts::trace", 4 * TRACE_WORDS),
            size,
        }
    }

    /// Bytes of the largest binding for `leaves` leaves at `size` (the scratch stays within
    /// its budget).
    pub fn largest_binding(leaves: u32, size: (u32, u32)) -> u64 {
        (32 * leaves as u64).max(16 * size.0 as u64 * size.1 as u64)
    }

    pub fn matches(&self, leaves: u32, size: (u32, u32), max_cut: u32) -> bool {
        self.leaves == leaves && self.size == size && self.max_cut == max_cut
    }
}

pub struct LightcutsPass {
    build: wgpu::ComputePipeline,
    build_layout: wgpu::BindGroupLayout,
    build_params: wgpu::Buffer,
    cut: wgpu::ComputePipeline,
    cut_timed: wgpu::ComputePipeline,
    cut_layout: wgpu::BindGroupLayout,
    /// Per-slice uniforms (grown as needed).
    params: wgpu::Buffer,
    views: wgpu::ComputePipeline,
    views_layout: wgpu::BindGroupLayout,
    view_params: wgpu::Buffer,
    stats_readback: AsyncReadback,
    last_stats: Option<LcStats>,
}

impl LightcutsPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let c = wgpu::ShaderStages::COMPUTE;
        let bmod = shaders::create_module(device, "methods/lightcuts/lc_build.wgsl")?;
        let cmod = shaders::create_module(device, "methods/lightcuts/lightcuts.wgsl")?;
        let vmod = shaders::create_module(device, "methods/lightcuts/lc_views.wgsl")?;
        let build_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lightcuts_build::layout"),
            entries: &[
                dynamic_uniform_entry(0, c, std::mem::size_of::<GpuLcBuildParams>() as u64),
                storage_entry(1, c, true),
                storage_entry(2, c, true),
                storage_entry(3, c, false),
                storage_entry(4, c, false),
            ],
        });
        let cut_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lightcuts::layout"),
            entries: &[
                dynamic_uniform_entry(0, c, std::mem::size_of::<GpuLcParams>() as u64),
                storage_entry(1, c, true),
                storage_entry(2, c, true),
                storage_entry(3, c, true),
                storage_entry(4, c, true),
                storage_entry(5, c, true),
                storage_entry(6, c, true),
                float_texture_entry(7),
                float_texture_entry(8),
                float_texture_entry(9),
                storage_entry(10, c, false),
                storage_entry(11, c, false),
                storage_entry(12, c, false),
                storage_entry(13, c, false),
                storage_entry(14, c, false),
                storage_entry(15, c, false),
            ],
        });
        let views_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lightcuts_views::layout"),
            entries: &[
                uniform_entry(0, c),
                float_texture_entry(1),
                float_texture_entry(2),
                storage_entry(3, c, true),
                storage_texture_entry(4, wgpu::TextureFormat::Rgba8Unorm),
            ],
        });
        let pipe =
            |label: &str, layout: &wgpu::BindGroupLayout, module: &wgpu::ShaderModule, k: &[(&str, f64)]| {
                compute_pipeline_with(device, label, &[Some(layout)], module, "main", k)
            };
        Ok(Self {
            build: pipe("lightcuts_build", &build_layout, &bmod, &[]),
            build_params: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("lightcuts_build::params"),
                size: STRIDE * MAX_LEVELS,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            build_layout,
            cut: pipe("lightcuts", &cut_layout, &cmod, &[]),
            cut_timed: pipe("lightcuts_timed", &cut_layout, &cmod, &[("DIAGNOSTICS", 0.0)]),
            cut_layout,
            params: slice_params(device, 1),
            views: pipe("lightcuts_views", &views_layout, &vmod, &[]),
            views_layout,
            view_params: uniform_buffer::<GpuLcViewParams>(device, "lightcuts_views::params"),
            stats_readback: AsyncReadback::new(device, "lightcuts::stats_readback", (STATS * 4) as u64),
            last_stats: None,
        })
    }

    /// Records `lightcuts_build` (every level, one compute pass) and `lightcuts`.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &mut self,
        diagnostics: bool,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        p: GpuLcParams,
        seed: u32,
        tree: &TreeBuffers,
        scene: &SceneGpu,
        gbuffer: &GbufferTargets,
        accum: &wgpu::Buffer,
        out: &LcBuffers,
    ) {
        // Levels bottom-up: leaves (level L-1) first, the root last.
        let levels = tree.levels();
        let mut dispatches = Vec::new();
        for (i, level) in (0..levels).rev().enumerate() {
            let bp = GpuLcBuildParams {
                first: 1 << level,
                count: 1 << level,
                leaves: tree.leaves,
                seed,
            };
            queue.write_buffer(&self.build_params, i as u64 * STRIDE, bytemuck::bytes_of(&bp));
            dispatches.push((i as u64 * STRIDE, bp.count.div_ceil(WG_1D)));
        }
        let build_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("lightcuts_build::bind_group"),
            layout: &self.build_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &self.build_params,
                        offset: 0,
                        size: wgpu::BufferSize::new(std::mem::size_of::<GpuLcBuildParams>() as u64),
                    }),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: tree.nodes.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: tree.sorted_vpls.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: out.cones.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: out.reps.as_entire_binding(),
                },
            ],
        });
        encoder.push_debug_group("lightcuts_build");
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("lightcuts_build"),
                timestamp_writes: timer.compute_pass("lightcuts_build"),
            });
            pass.set_pipeline(&self.build);
            for (offset, groups) in dispatches.into_iter().take(MAX_LEVELS as usize) {
                pass.set_bind_group(0, &build_bind, &[offset as u32]);
                pass.dispatch_workgroups(groups, 1, 1);
            }
        }
        encoder.pop_debug_group();

        let pixels = p.width * p.height;
        let slices = pixels.div_ceil(out.slice).max(1);
        let per_slice = dispatches_per_slice(p.max_cut, tree.levels(), p.steps);
        let n = slices * per_slice;
        if self.params.size() < n as u64 * STRIDE {
            self.params = slice_params(device, n);
        }
        let mut all = Vec::with_capacity(n as usize * STRIDE as usize);
        for i in 0..slices {
            for j in 0..per_slice {
                let sp = GpuLcParams {
                    first_pixel: i * out.slice,
                    slice: out.slice,
                    first: (j == 0) as u32,
                    last: (j + 1 == per_slice) as u32,
                    ..p
                };
                let mut bytes = bytemuck::bytes_of(&sp).to_vec();
                bytes.resize(STRIDE as usize, 0);
                all.extend_from_slice(&bytes);
            }
        }
        queue.write_buffer(&self.params, 0, &all);
        let tv = wgpu::BindingResource::TextureView;
        let entries = [
            wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: &self.params,
                offset: 0,
                size: wgpu::BufferSize::new(std::mem::size_of::<GpuLcParams>() as u64),
            }),
            tree.nodes.as_entire_binding(),
            tree.sorted_vpls.as_entire_binding(),
            out.cones.as_entire_binding(),
            out.reps.as_entire_binding(),
            scene.bvh_nodes.as_entire_binding(),
            scene.bvh_triangles.as_entire_binding(),
            tv(&gbuffer.position_view),
            tv(&gbuffer.normal_view),
            tv(&gbuffer.albedo_view),
            accum.as_entire_binding(),
            out.diag.as_entire_binding(),
            out.stats.as_entire_binding(),
            out.trace.as_entire_binding(),
            out.scratch.as_entire_binding(),
            out.state.as_entire_binding(),
        ];
        let bind = bind_group_seq(device, "lightcuts::bind_group", &self.cut_layout, &entries);
        if diagnostics {
            encoder.clear_buffer(&out.stats, 0, None);
            encoder.clear_buffer(&out.trace, 0, None);
        }
        // One compute pass (one timestamp pair): per slice, its dispatches in order.
        encoder.push_debug_group("lightcuts");
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("lightcuts"),
                timestamp_writes: timer.compute_pass("lightcuts"),
            });
            pass.set_pipeline(if diagnostics { &self.cut } else { &self.cut_timed });
            for i in 0..n {
                pass.set_bind_group(0, &bind, &[(i as u64 * STRIDE) as u32]);
                pass.dispatch_workgroups(out.slice / WG_1D, 1, 1);
            }
        }
        encoder.pop_debug_group();
        if diagnostics {
            self.stats_readback
                .record(encoder, &[(&out.stats, 0, 0, (STATS * 4) as u64)]);
        }
    }

    #[allow(clippy::too_many_arguments)]
    pub fn record_view(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        p: GpuLcViewParams,
        final_image: &wgpu::TextureView,
        gb_position: &wgpu::TextureView,
        out: &LcBuffers,
        dst: &wgpu::TextureView,
    ) {
        queue.write_buffer(&self.view_params, 0, bytemuck::bytes_of(&p));
        let entries = [
            self.view_params.as_entire_binding(),
            wgpu::BindingResource::TextureView(final_image),
            wgpu::BindingResource::TextureView(gb_position),
            out.diag.as_entire_binding(),
            wgpu::BindingResource::TextureView(dst),
        ];
        let bind = bind_group_seq(
            device,
            "lightcuts_views::bind_group",
            &self.views_layout,
            &entries,
        );
        run_compute(
            encoder,
            timer,
            "lightcuts_views",
            &self.views,
            &bind,
            groups_image(out.size.0, out.size.1),
        );
    }

    pub fn after_submit(&self) {
        self.stats_readback.after_submit();
    }

    pub fn last_stats(&self) -> Option<LcStats> {
        self.last_stats
    }

    /// The counters of the latest diagnostic frame read back (non-blocking).
    pub fn poll_stats(&mut self) -> Option<LcStats> {
        if let Some(bytes) = self.stats_readback.try_take() {
            self.last_stats = Some(LcStats::from_words(bytemuck::cast_slice(&bytes)));
        }
        self.last_stats
    }
}

fn slice_params(device: &wgpu::Device, slices: u32) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("lightcuts::params"),
        size: slices.max(1) as u64 * STRIDE,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Reads the last build's cones and representatives (node 0 unused).
pub fn read_build(ctx: &GpuContext, out: &LcBuffers) -> Result<LcTree, GpuError> {
    let cones: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&readback::read_storage_buffer(ctx, &out.cones)?);
    let reps: Vec<u32> = bytemuck::pod_collect_to_vec(&readback::read_storage_buffer(ctx, &out.reps)?);
    let n = 2 * out.leaves as usize;
    Ok(LcTree {
        cones: cones.into_iter().take(n).map(Cone::from_gpu).collect(),
        reps: reps.into_iter().take(n).collect(),
    })
}

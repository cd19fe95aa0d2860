//! Lightcuts' GPU passes: `lightcuts_build` (normal cones and representatives per node, one
//! dispatch per tree level, bottom-up), `lightcuts` (the per-pixel cut), `lightcuts_views`.
//! Reads: the light tree (nodes, VPLs in leaf order), BVH, G-buffer. Writes: the GI
//! accumulation, per-pixel diagnostics, counters and the pinned pixel's cut.

use crate::methods::{FrameCx, ViewCx};
use bytemuck::{Pod, Zeroable};

use crate::gpu::context::{GpuContext, GpuError};
use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use crate::gpu::passes::{WG_1D, groups_image, run_compute, storage_buffer, uniform_buffer};
use crate::gpu::readback::{self, CounterReadback};
use crate::gpu::shaders;
use crate::reference::lightcuts::{Cone, LcTree, MAX_CUT};

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
    /// 1: the radix tree (children from its links; Lightcuts only), 0: the perfect tree.
    pub radix: u32,
    /// The BRDF (`Brdf::gpu`; Lightcuts only, Lightcut Interpolation shades Lambert).
    pub brdf: u32,
    pub _pad: [u32; 3],
    /// xyz the camera's position (the glossy BRDF's view direction).
    pub eye: [f32; 4],
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

/// Bytes of the heaps' scratch at most (slice x max_cut entries of 8 bytes).
pub const SCRATCH_BUDGET: u64 = 128 << 20;
/// Tree levels the build's uniforms start with (they grow).
pub(super) const MAX_LEVELS: u32 = 32;
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
    /// Bound where a mode does not use a binding (Lightcut Interpolation's lanes, records).
    pub dummy: wgpu::Buffer,
    /// The same for the read-write bindings (one usage per buffer and dispatch).
    pub dummy_rw: wgpu::Buffer,
}

/// Pixels per slice for `pixels` pixels and cuts of `max_cut` within `budget` bytes: a
/// multiple of the workgroup size, at least one workgroup.
pub fn slice_pixels(pixels: u32, max_cut: u32, budget: u64) -> u32 {
    // At most 65535 workgroups per dispatch (one dispatch per slice).
    let fit = (budget / (8 * max_cut.max(1) as u64)).min(65535 * WG_1D as u64) as u32;
    let fit = (fit / WG_1D * WG_1D).max(WG_1D);
    fit.min(pixels.div_ceil(WG_1D) * WG_1D).max(WG_1D)
}

impl LcBuffers {
    pub fn new(device: &wgpu::Device, leaves: u32, size: (u32, u32), max_cut: u32, budget: u64) -> Self {
        let nodes = 2 * leaves as u64;
        let slice = slice_pixels(size.0 * size.1, max_cut, budget);
        Self {
            scratch: storage_buffer(device, "lightcuts::scratch", 8 * slice as u64 * max_cut as u64),
            state: storage_buffer(device, "lightcuts::state", 32 * slice as u64),
            slice,
            max_cut,
            cones: storage_buffer(device, "lightcuts::cones", 16 * nodes),
            reps: storage_buffer(device, "lightcuts::reps", 4 * nodes),
            leaves,
            diag: storage_buffer(device, "lightcuts::diag", 16 * size.0 as u64 * size.1 as u64),
            stats: storage_buffer(device, "lightcuts::stats", 4 * STATS as u64),
            trace: storage_buffer(device, "lightcuts::trace", 4 * TRACE_WORDS),
            size,
            dummy: storage_buffer(device, "lightcuts::dummy", 16),
            dummy_rw: storage_buffer(device, "lightcuts::dummy_rw", 16),
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

pub use super::kernels::{BuildKernel, BuildRun, CutBindings, CutKernel, CutRun};

pub struct LightcutsPass {
    build: BuildKernel,
    cut: CutKernel,
    views: wgpu::ComputePipeline,
    views_kernel: Kernel,
    view_params: wgpu::Buffer,
    /// The frame counters (diagnostic frames).
    pub stats: CounterReadback<LcStats>,
}

impl LightcutsPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let views_kernel = Kernel::new(
            device,
            "methods/lightcuts/lc_views.wgsl",
            &["main"],
            KernelOptions::default(),
        )?;
        Ok(Self {
            build: BuildKernel::new(device)?,
            cut: CutKernel::new(device, 0, 0)?,
            views: views_kernel.compute(device, "lightcuts_views", "main"),
            views_kernel,
            view_params: uniform_buffer::<GpuLcViewParams>(device, "lightcuts_views::params"),
            stats: CounterReadback::new(
                device,
                "lightcuts::stats_readback",
                (STATS * 4) as u64,
                LcStats::from_words,
            ),
        })
    }

    /// Records `lightcuts_build` (every level, one compute pass) and `lightcuts` over the
    /// frame's tree, scene and G-buffer into `cx.gi_accum`.
    pub fn record(
        &mut self,
        cx: &mut FrameCx<'_>,
        encoder: &mut wgpu::CommandEncoder,
        p: GpuLcParams,
        seed: u32,
        out: &LcBuffers,
    ) {
        let diagnostics = cx.diagnostics;
        let (device, queue, tree, scene, targets) = (cx.device, cx.queue, cx.tree, cx.scene, cx.targets);
        let (gbuffer, accum) = (&targets.gbuffer, cx.gi_accum);
        let build = BuildRun {
            name: "lightcuts_build",
            seed,
            tree,
            cones: &out.cones,
            reps: &out.reps,
        };
        self.build.record(device, queue, encoder, cx.timer, build);
        if diagnostics {
            encoder.clear_buffer(&out.stats, 0, None);
            encoder.clear_buffer(&out.trace, 0, None);
        }
        let b = CutBindings {
            tree,
            scene,
            gbuffer,
            cones: &out.cones,
            reps: &out.reps,
            accum,
            diag: &out.diag,
            stats: &out.stats,
            trace: &out.trace,
            scratch: &out.scratch,
            state: &out.state,
            lanes: &out.dummy,
            record_cuts: &out.dummy_rw,
            rec_meta: &out.dummy_rw,
        };
        let items = p.width * p.height;
        let run = CutRun {
            name: "lightcuts",
            params: p,
            items,
            slice: out.slice,
            diagnostics,
        };
        self.cut.record(device, queue, encoder, cx.timer, run, &b);
        if diagnostics {
            self.stats
                .record(encoder, &[(&out.stats, 0, 0, (STATS * 4) as u64)]);
        }
    }

    /// Draws one of the diagnostic views (`p.mode`) into `cx.dst`.
    pub fn record_view(
        &self,
        cx: &mut ViewCx<'_>,
        encoder: &mut wgpu::CommandEncoder,
        p: GpuLcViewParams,
        out: &LcBuffers,
    ) {
        let final_image = &cx.targets.lighting.final_view;
        let gb_position = &cx.targets.gbuffer.position_view;
        let dst = cx.dst;
        cx.queue
            .write_buffer(&self.view_params, 0, bytemuck::bytes_of(&p));
        let bind = self.views_kernel.bind(
            cx.device,
            0,
            &[
                ("vp", buf(&self.view_params)),
                ("final_image", tex(final_image)),
                ("gb_position", tex(gb_position)),
                ("diag", buf(&out.diag)),
                ("dst", tex(dst)),
            ],
        );
        run_compute(
            encoder,
            cx.timer,
            "lightcuts_views",
            &self.views,
            &bind,
            groups_image(out.size.0, out.size.1),
        );
    }
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

/// The structs this method shares with WGSL (its `Module::wgsl_twins`: the registry test
/// checks them against naga's layout).
pub static WGSL_TWINS: &[crate::gpu::gpu_data::WgslTwin] = &[
    crate::wgsl_twin!(
        crate::methods::lightcuts::pass::GpuLcBuildParams,
        "methods/lightcuts/lc_build.wgsl",
        "LcBuildParams",
        [first, count, leaves, seed]
    ),
    crate::wgsl_twin!(
        crate::methods::lightcuts::pass::GpuLcParams,
        "methods/lightcuts/lightcuts.wgsl",
        "LcParams",
        [
            width,
            height,
            leaves,
            max_cut,
            relative_error,
            epsilon,
            ray_offset,
            shadow_rays,
            accumulate,
            trace_pixel,
            first_pixel,
            slice,
            first,
            last,
            steps,
            radix,
            brdf,
            _pad,
            _pad + 4,
            _pad + 8,
            eye
        ]
    ),
    crate::wgsl_twin!(
        crate::methods::lightcuts::pass::GpuLcViewParams,
        "methods/lightcuts/lc_views.wgsl",
        "LcViewParams",
        [
            mode,
            scale_top,
            relative_error,
            exposure,
            tonemap,
            _pad,
            _pad + 4,
            _pad + 8
        ]
    ),
];

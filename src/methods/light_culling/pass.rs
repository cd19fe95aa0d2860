//! Stochastic Light Culling's GPU passes, in frame order (Algorithm 1 of the paper):
//! `lcull_ranges` (per VPL: fall-off and range; with ISM visibility also its map's light),
//! `lcull_ism` (with ISM visibility: the VPLs' imperfect shadow maps, the shared
//! `passes::ism`), `lcull_tiles` (per tile: depth bounds and the light list), `lcull_shade`
//! (per pixel: the list's VPLs, demodulated), `lcull_filter` (the
//! interleaving's geometry-aware filter, x albedo / pi, into the GI accumulation: the shared
//! `passes::interleave_filter`), and the views.
//! Reads: the VPLs, G-buffer, camera, BVH. CPU twins: `crate::reference::light_culling`.

mod record;

use bytemuck::{Pod, Zeroable};

use super::settings::{IsmAdaptive, IsmSettings};
use crate::gpu::frame::GbufferTargets;
use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use crate::gpu::passes::{
    WG_1D, groups_image,
    interleave_filter::{FilterDispatch, FilterInputs, FilterUniform, GpuFilterParams, InterleaveFilter},
    ism::{GpuIsmParams, IsmBuild, IsmPass, IsmPoints, IsmTargets},
    run_compute, storage_buffer, uniform_buffer,
};
use crate::gpu::readback::CounterReadback;
use crate::gpu::scene_gpu::SceneGpu;
use crate::gpu::shaders;
use crate::methods::lightcut_interpolation::pass::groups_1d_as_2d;

/// Workgroup size of `lcull_tiles.wgsl` (one tile per workgroup).
pub const TILE_WG: u32 = 256;

/// Twin: `LcullParams` in `lcull_common.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuLcullParams {
    pub width: u32,
    pub height: u32,
    pub tile: u32,
    pub n: u32,
    pub tiles_x: u32,
    pub tiles_y: u32,
    pub tiles: u32,
    pub cap: u32,
    pub count: u32,
    pub offset: u32,
    pub seed: u32,
    /// 0 stochastic, 1 clamped, 2 the tree variant (stochastic ranges).
    pub mode: u32,
    pub epsilon_max: f32,
    pub exposure: f32,
    pub eps: f32,
    pub ray_offset: f32,
    /// Visibility: 0 none, 1 BVH shadow rays, 2 imperfect shadow maps.
    pub shadow_rays: u32,
    pub stride: u32,
    /// The tree variant: leaves of the light tree.
    pub leaves: u32,
    /// Bit 0: the ranges pass writes the VPLs' ISM lights (the maps are built: ISM
    /// visibility, or the atlas view); bit 1: a map leaves out the points beyond its VPL's
    /// range (section 4.3).
    pub ism_flags: u32,
    /// The shading's BRDF (`Brdf::gpu`): with GGX `raw` is radiance (no albedo / pi after).
    pub brdf: u32,
    pub _pad: [u32; 3],
    /// xyz the camera's position (the glossy BRDF's view direction).
    pub eye: [f32; 4],
}

/// `GpuLcullParams::shadow_rays` of ISM visibility.
pub const VISIBILITY_ISM: u32 = 2;

/// Twin: `LcullViewParams` in `lcull_views.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuLcullViewParams {
    pub mode: u32,
    pub scale_top: u32,
    pub exposure: f32,
    pub tonemap: u32,
    pub n: u32,
    pub cap: u32,
    /// The difference view: 1 / frames of the method's own accumulation and of the
    /// companion's (0: none yet), and 1 when the method itself is the clamped variant.
    pub own_scale: f32,
    pub companion_scale: f32,
    pub own_is_clamped: u32,
    /// The difference view's colour scale: relative differences +-range map to its ends.
    pub range: f32,
    pub _pad: [u32; 2],
}

pub const STATS_WORDS: usize = 16;

/// A frame's counters (diagnostic frames).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LcullStats {
    /// Sum of the tiles' list lengths (true counts, over the cap included).
    pub list_entries: u64,
    pub tiles_with_geometry: u32,
    pub overflow_tiles: u32,
    pub longest_list: u32,
    pub pixels: u32,
    /// VPLs whose fall-off was evaluated (list entries, or the subset in overflowing tiles).
    pub tested: u64,
    /// VPLs in range of their pixel (non-zero fall-off).
    pub in_range: u64,
    pub shadow_rays: u64,
    /// The tree variant: tree nodes visited by the pixels' traversals.
    pub nodes_visited: u64,
}

impl LcullStats {
    pub fn from_words(w: &[u32]) -> Self {
        let w64 = |i: usize| w[i] as u64 | (w[i + 1] as u64) << 32;
        Self {
            list_entries: w64(0),
            tiles_with_geometry: w[2],
            overflow_tiles: w[3],
            longest_list: w[4],
            pixels: w[5],
            tested: w64(6),
            in_range: w64(8),
            shadow_rays: w64(10),
            nodes_visited: w64(12),
        }
    }
    fn per_pixel(&self, v: u64) -> f64 {
        v as f64 / self.pixels.max(1) as f64
    }
    pub fn tested_per_pixel(&self) -> f64 {
        self.per_pixel(self.tested)
    }
    pub fn in_range_per_pixel(&self) -> f64 {
        self.per_pixel(self.in_range)
    }
    pub fn rays_per_pixel(&self) -> f64 {
        self.per_pixel(self.shadow_rays)
    }
    pub fn visited_per_pixel(&self) -> f64 {
        self.per_pixel(self.nodes_visited)
    }
    pub fn mean_list(&self) -> f64 {
        self.list_entries as f64 / self.tiles_with_geometry.max(1) as f64
    }
}

/// Per-VPL, per-tile and per-pixel buffers (resized with the VPL capacity, the frame size and
/// the tile layout).
pub struct LcullBuffers {
    pub size: (u32, u32),
    pub vpl_capacity: u32,
    pub tiles: u32,
    pub cap: u32,
    /// Two vec4 per VPL: (position, range), (threshold, floor, 0, 0).
    pub lights: wgpu::Buffer,
    pub tile_count: wgpu::Buffer,
    pub tile_lists: wgpu::Buffer,
    pub raw: wgpu::Buffer,
    pub diag: wgpu::Buffer,
    pub stats: wgpu::Buffer,
    /// The difference view's buffers (allocated when it is first drawn or kept).
    pub companion: Option<CompanionBuffers>,
    /// Bound in their place before then (16 bytes each, never touched; two, as one buffer
    /// may not be both read-only and read-write in a dispatch).
    pub dummy: [wgpu::Buffer; 2],
}

/// The clamped-vs-stochastic view's: the other variant's GI accumulation and the view's
/// linear data as last drawn (`Method::read_view`).
pub struct CompanionBuffers {
    pub accum: wgpu::Buffer,
    pub difference: wgpu::Buffer,
}

impl LcullBuffers {
    pub fn new(device: &wgpu::Device, vpl_capacity: u32, size: (u32, u32), tiles: u32, cap: u32) -> Self {
        let px = size.0 as u64 * size.1 as u64;
        Self {
            size,
            vpl_capacity,
            tiles,
            cap,
            lights: storage_buffer(device, "lcull::lights", 32 * vpl_capacity as u64),
            tile_count: storage_buffer(device, "lcull::tile_count", 4 * tiles as u64),
            tile_lists: storage_buffer(device, "lcull::tile_lists", 4 * tiles as u64 * cap as u64),
            raw: storage_buffer(device, "lcull::raw", 16 * px),
            diag: storage_buffer(device, "lcull::diag", 16 * px),
            stats: storage_buffer(device, "lcull::stats", 4 * STATS_WORDS as u64),
            companion: None,
            dummy: [
                storage_buffer(device, "lcull::dummy_accum", 16),
                storage_buffer(device, "lcull::dummy_difference", 16),
            ],
        }
    }
    /// The difference view's buffers, allocated on first use.
    pub fn ensure_companion(&mut self, device: &wgpu::Device) {
        if self.companion.is_none() {
            let px = self.size.0 as u64 * self.size.1 as u64;
            self.companion = Some(CompanionBuffers {
                accum: storage_buffer(device, "lcull::companion_accum", 16 * px),
                difference: storage_buffer(device, "lcull::difference", 16 * px),
            });
        }
    }
    /// Bytes of the tile lists for this layout (the largest binding).
    pub fn list_bytes(tiles: u32, cap: u32) -> u64 {
        4 * tiles as u64 * cap as u64
    }
    pub fn matches(&self, vpl_capacity: u32, size: (u32, u32), tiles: u32, cap: u32) -> bool {
        self.vpl_capacity == vpl_capacity && self.size == size && self.tiles == tiles && self.cap == cap
    }
}

/// The tree variant's buffers (section 5): per leaf its range, per node the largest range
/// below it, per pixel its k-entry light list and (m, nodes visited).
pub struct TreeCullBuffers {
    pub size: (u32, u32),
    pub leaves: u32,
    pub k: u32,
    /// Two vec4 per leaf: (position, range), (threshold, floor, 0, 0).
    pub lights: wgpu::Buffer,
    pub max_range: wgpu::Buffer,
    pub list: wgpu::Buffer,
    pub m: wgpu::Buffer,
}

impl TreeCullBuffers {
    pub fn new(device: &wgpu::Device, size: (u32, u32), leaves: u32, k: u32) -> Self {
        let px = size.0 as u64 * size.1 as u64;
        Self {
            size,
            leaves,
            k,
            lights: storage_buffer(device, "lcull_tree::lights", 32 * leaves as u64),
            max_range: storage_buffer(device, "lcull_tree::max_range", 8 * leaves as u64),
            list: storage_buffer(device, "lcull_tree::list", Self::list_bytes(size, k)),
            m: storage_buffer(device, "lcull_tree::m", 8 * px),
        }
    }
    /// Bytes of the per-pixel lists (the largest binding).
    pub fn list_bytes(size: (u32, u32), k: u32) -> u64 {
        4 * size.0 as u64 * size.1 as u64 * k as u64
    }
    pub fn matches(&self, size: (u32, u32), leaves: u32, k: u32) -> bool {
        self.size == size && self.leaves == leaves && self.k == k
    }
}

/// The light tree the tree variant walks (`TreeBuffers`: nodes and VPLs in leaf order).
pub struct TreeInputs<'a> {
    pub nodes: &'a wgpu::Buffer,
    pub sorted_vpls: &'a wgpu::Buffer,
}

/// Everything a frame of the method binds from the renderer.
pub struct FrameInputs<'a> {
    pub scene: &'a SceneGpu,
    pub gbuffer: &'a GbufferTargets,
    pub camera: &'a wgpu::Buffer,
    pub vpls: &'a wgpu::Buffer,
    pub accum: &'a wgpu::Buffer,
    /// The frame's imperfect shadow maps (None: no maps this frame).
    pub ism: Option<IsmFrame<'a>>,
}

/// A frame's GPU parameters: the culling's and the interleave filter's.
#[derive(Clone, Copy)]
pub struct LcullFrameParams {
    pub cull: GpuLcullParams,
    pub filter: GpuFilterParams,
}

impl FrameInputs<'_> {
    /// The filter's: `raw` of `b` into `accum`.
    fn filter_inputs<'b>(&'b self, b: &'b LcullBuffers) -> FilterInputs<'b> {
        FilterInputs {
            gbuffer: self.gbuffer,
            camera: self.camera,
            raw: &b.raw,
            accum: self.accum,
        }
    }
}

/// The frame's imperfect shadow maps (ISM visibility, or drawn by the atlas view): built
/// after the ranges from the lights they wrote, one map per VPL (the tree: per leaf).
pub struct IsmFrame<'a> {
    pub settings: &'a IsmSettings<IsmAdaptive>,
    pub points: &'a IsmPoints,
    pub targets: &'a IsmTargets,
    /// Maps to build (the frame's VPLs or leaves; at most the atlas's capacity).
    pub maps: u32,
}

/// Timer names of a run's passes: the method's own, and the difference view's companion
/// (diagnostic frames only, so never in a timed frame's GI cost).
const OWN_PASSES: [&str; 5] = [
    "lcull_ranges",
    "lcull_tiles",
    "lcull_shade",
    "lcull_filter",
    "lcull_ism",
];
const COMPANION_PASSES: [&str; 5] = [
    "lcull_companion_ranges",
    "lcull_companion_tiles",
    "lcull_companion_shade",
    "lcull_companion_filter",
    "lcull_companion_ism",
];

pub struct LcullPass {
    params: wgpu::Buffer,
    companion_params: wgpu::Buffer,
    ranges_kernel: Kernel,
    ranges: wgpu::ComputePipeline,
    tiles_kernel: Kernel,
    tiles: wgpu::ComputePipeline,
    tiles_timed: wgpu::ComputePipeline,
    shade_kernel: Kernel,
    shade: wgpu::ComputePipeline,
    shade_timed: wgpu::ComputePipeline,
    filter: InterleaveFilter,
    filter_params: FilterUniform,
    companion_filter_params: FilterUniform,
    tree_kernel: Kernel,
    tree_leaves: wgpu::ComputePipeline,
    tree_traverse: wgpu::ComputePipeline,
    tree_traverse_timed: wgpu::ComputePipeline,
    tree_shade: wgpu::ComputePipeline,
    tree_shade_timed: wgpu::ComputePipeline,
    views_kernel: Kernel,
    views: wgpu::ComputePipeline,
    view_params: wgpu::Buffer,
    pub stats: CounterReadback<LcullStats>,
    /// The imperfect shadow maps' build (and the atlas view).
    pub ism: IsmPass,
    /// The lookups' parameters (`GpuIsmParams`, level 0).
    ism_params: wgpu::Buffer,
    /// Bound in the maps' place without ISM visibility: depth (read) and lights (written).
    ism_dummy: [wgpu::Buffer; 2],
}

/// The structs this method shares with WGSL (its `Module::wgsl_twins`: the registry test
/// checks them against naga's layout).
pub static WGSL_TWINS: &[crate::gpu::gpu_data::WgslTwin] = &[
    crate::wgsl_twin!(
        crate::methods::light_culling::pass::GpuLcullParams,
        "methods/light_culling/lcull_ranges.wgsl",
        "LcullParams",
        [
            width,
            height,
            tile,
            n,
            tiles_x,
            tiles_y,
            tiles,
            cap,
            count,
            offset,
            seed,
            mode,
            epsilon_max,
            exposure,
            eps,
            ray_offset,
            shadow_rays,
            stride,
            leaves,
            ism_flags,
            brdf,
            _pad,
            _pad + 4,
            _pad + 8,
            eye
        ]
    ),
    crate::wgsl_twin!(
        crate::methods::light_culling::pass::GpuLcullViewParams,
        "methods/light_culling/lcull_views.wgsl",
        "LcullViewParams",
        [
            mode,
            scale_top,
            exposure,
            tonemap,
            n,
            cap,
            own_scale,
            companion_scale,
            own_is_clamped,
            range,
            _pad,
            _pad + 4
        ]
    ),
];

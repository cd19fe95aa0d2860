//! Lightcut Interpolation's GPU passes, in frame order: `li_build` (Lightcuts' cones and
//! representatives), `li_radius`, `li_place`, `li_compact` (the cache records,
//! `li_records.wgsl`), `li_record_cuts` (the records' lightcuts: `lightcuts.wgsl` MODE 1),
//! `li_select` (each pixel's records and weights), `li_interp` (interpolated cuts, shaded),
//! `li_fallback` (full lightcuts where no record fits: `lightcuts.wgsl` MODE 2), and the
//! views. Reads: the light tree, BVH, G-buffer, camera. Writes: the GI accumulation, per-pixel
//! diagnostics, counters and the pinned pixel's interpolation.

mod record;

use bytemuck::{Pod, Zeroable};

use crate::gpu::frame::GbufferTargets;
use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use crate::gpu::passes::sst_build::TreeBuffers;
use crate::gpu::passes::{StridedUniforms, WG_1D, groups_image, run_compute, storage_buffer, uniform_buffer};
use crate::gpu::readback::CounterReadback;
use crate::gpu::scene_gpu::SceneGpu;
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;
use crate::methods::lightcuts::pass::{
    BuildKernel, BuildRun, CutBindings, CutKernel, CutRun, GpuLcParams, slice_pixels,
};
use crate::reference::lightcut_interpolation::{TILE, TILE_CAP};

/// Workgroup size of `li_records.wgsl`'s tile kernels (`TILE_WG_ENTRIES`): a 16 x 16 tile
/// per workgroup (`place_main`; `compact_main` runs one such group).
pub const TILE_WG: u32 = TILE * TILE;
pub const TILE_WG_ENTRIES: &[&str] = &["place_main", "compact_main"];

/// Twin: `LiParams` in `li_common.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuLiParams {
    pub width: u32,
    pub height: u32,
    pub tiles_x: u32,
    pub tiles_y: u32,
    pub leaves: u32,
    pub levels: u32,
    pub max_cut: u32,
    pub capacity: u32,
    pub r_min_px: f32,
    pub r_max_px: f32,
    pub one_minus_cos_max: f32,
    pub epsilon: f32,
    pub coverage: f32,
    pub radius_rays: u32,
    pub ray_offset: f32,
    pub shadow_rays: u32,
    pub interp_visibility: u32,
    pub accumulate: u32,
    /// x | y << 16, or u32::MAX.
    pub trace_pixel: u32,
    /// Walk units per dispatch ([`walk_steps_per_dispatch`]).
    pub steps: u32,
    pub first: u32,
    pub last: u32,
    pub distance_epsilon: f32,
    pub _pad: u32,
}

/// Twin: `LiViewParams` in `li_views.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuLiViewParams {
    pub mode: u32,
    pub scale_top: u32,
    pub r_min_px: f32,
    pub r_max_px: f32,
    pub exposure: f32,
    pub tonemap: u32,
    pub tiles_x: u32,
    pub tiles_y: u32,
    /// The pinned pixel (row-major index), or u32::MAX.
    pub pinned: u32,
    pub _pad: [u32; 3],
}

/// Walk units (lowest-edge steps and emitted nodes) per `li_interp` dispatch: all on a GPU,
/// 32 on a CPU adapter (lavapipe's loop limit; docs/lightcuts.md).
pub fn walk_steps_per_dispatch(device_type: wgpu::DeviceType) -> u32 {
    if device_type == wgpu::DeviceType::Cpu {
        32
    } else {
        u32::MAX
    }
}

/// `li_interp` dispatches for cuts of `max_cut` nodes in a tree of `levels` levels: three
/// input cuts and their gaps, and as many emitted nodes. Walks left unfinished are counted
/// (`LiStats::unfinished`), never silently cut.
pub fn walk_dispatches(max_cut: u32, levels: u32, steps: u32) -> u32 {
    if steps == u32::MAX {
        return 1;
    }
    let units = 6 * (max_cut as u64 + levels as u64 + 1);
    units.div_ceil(steps.max(1) as u64).clamp(1, 4096) as u32
}

/// Counter words: the interpolation's (8), the records' lightcuts (8), the fallback's (8),
/// and the records' metadata (8: records, dropped, tiles at their cap).
pub const STATS_WORDS: usize = 32;
const TRACE_WORDS: u64 = 16 + 2 * 4096;

/// The frame's counters (diagnostic frames).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LiStats {
    pub interpolated: u32,
    pub unfinished: u32,
    pub cut_nodes: u64,
    pub shadow_rays: u64,
    pub walk_steps: u64,
    pub records: u32,
    pub records_at_max_cut: u32,
    pub record_cut_nodes: u64,
    pub record_rays: u64,
    pub fallback: u32,
    pub fallback_cut_nodes: u64,
    pub fallback_rays: u64,
    pub dropped_records: u32,
    pub capped_tiles: u32,
}

impl LiStats {
    pub fn from_words(w: &[u32]) -> Self {
        let w64 = |i: usize| w[i] as u64 | (w[i + 1] as u64) << 32;
        Self {
            interpolated: w[0],
            unfinished: w[1],
            cut_nodes: w64(2),
            shadow_rays: w64(4),
            walk_steps: w64(6),
            records: w[8],
            records_at_max_cut: w[9],
            record_cut_nodes: w64(10),
            record_rays: w64(14),
            fallback: w[16],
            fallback_cut_nodes: w64(18),
            fallback_rays: w64(22),
            dropped_records: w[25],
            capped_tiles: w[26],
        }
    }
    /// Pixels shaded (interpolated or fallback).
    pub fn pixels(&self) -> u32 {
        self.interpolated + self.fallback
    }
    pub fn fallback_fraction(&self) -> f64 {
        self.fallback as f64 / self.pixels().max(1) as f64
    }
    /// Mean cut size over shaded pixels (interpolated and fallback cuts).
    pub fn mean_cut(&self) -> f64 {
        (self.cut_nodes + self.fallback_cut_nodes) as f64 / self.pixels().max(1) as f64
    }
    /// Shadow rays per shaded pixel, the records' included.
    pub fn rays_per_pixel(&self) -> f64 {
        (self.shadow_rays + self.record_rays + self.fallback_rays) as f64 / self.pixels().max(1) as f64
    }
    pub fn records_per_pixel(&self) -> f64 {
        self.records as f64 / self.pixels().max(1) as f64
    }
    pub fn mean_record_cut(&self) -> f64 {
        self.record_cut_nodes as f64 / self.records.max(1) as f64
    }
}

/// The pinned pixel's interpolation in the last diagnostic frame.
#[derive(Clone, Debug, PartialEq)]
pub struct TracedInterpolation {
    pub pixel: u32,
    pub records: Vec<u32>,
    pub weights: Vec<f32>,
    pub level_spread: f32,
    pub shadow_rays: u32,
    pub walk_steps: u32,
    /// (node, interpolated visibility), left to right.
    pub nodes: Vec<(u32, f32)>,
}

impl TracedInterpolation {
    pub fn parse(w: &[u32]) -> Option<Self> {
        if w.len() < 16 || w[8] == 0 {
            return None;
        }
        let m = (w[1] as usize).min(3);
        let n = (w[0] as usize).min(4096);
        Some(Self {
            pixel: w[8] - 1,
            records: w[2..2 + m].to_vec(),
            weights: w[5..5 + m].iter().map(|&b| f32::from_bits(b)).collect(),
            level_spread: f32::from_bits(w[9]),
            shadow_rays: w[10],
            walk_steps: w[11],
            nodes: (0..n)
                .filter_map(|i| Some((*w.get(16 + 2 * i)?, f32::from_bits(*w.get(17 + 2 * i)?))))
                .collect(),
        })
    }
}

/// Records at most in `tiles` tiles with cuts of `max_cut`: every record the tiles can place
/// (detailed geometry at a low resolution places one for every 5 or 6 pixels: Sponza at
/// 192 x 108), unless their cuts would not fit a binding of `limit` bytes; records past the
/// capacity are dropped and counted (`dropped_records`), their pixels fall back.
pub fn record_capacity(tiles: u32, max_cut: u32, limit: u64) -> u32 {
    let fit = limit / (4 * max_cut.max(1) as u64);
    (tiles as u64 * TILE_CAP as u64)
        .min(fit)
        .clamp(1, u32::MAX as u64) as u32
}

/// Per-node, per-record and per-pixel buffers (resized with the tree, frame and settings).
pub struct LiBuffers {
    pub size: (u32, u32),
    pub leaves: u32,
    pub max_cut: u32,
    pub tiles: (u32, u32),
    pub capacity: u32,
    /// Whether `li_interp` carries its walk between dispatches (CPU adapters).
    pub split_walk: bool,
    pub cones: wgpu::Buffer,
    pub reps: wgpu::Buffer,
    pub radius: wgpu::Buffer,
    pub tile_count: wgpu::Buffer,
    pub tile_recs: wgpu::Buffer,
    pub tile_offset: wgpu::Buffer,
    pub records: wgpu::Buffer,
    pub rec_meta: wgpu::Buffer,
    pub record_cuts: wgpu::Buffer,
    pub sel: wgpu::Buffer,
    pub diag: wgpu::Buffer,
    pub stats: wgpu::Buffer,
    pub trace: wgpu::Buffer,
    pub walk_state: wgpu::Buffer,
    /// The lightcut kernel's heaps and state (records' and fallback slices).
    pub scratch: wgpu::Buffer,
    pub lc_state: wgpu::Buffer,
    pub record_slice: u32,
    pub fallback_slice: u32,
}

impl LiBuffers {
    pub fn new(
        device: &wgpu::Device,
        leaves: u32,
        size: (u32, u32),
        max_cut: u32,
        budget: u64,
        binding_limit: u64,
        split_walk: bool,
    ) -> Self {
        let pixels = size.0 * size.1;
        let tiles = (size.0.div_ceil(TILE), size.1.div_ceil(TILE));
        let nt = tiles.0 * tiles.1;
        let capacity = record_capacity(nt, max_cut, binding_limit);
        let record_slice = slice_pixels(capacity, max_cut, budget);
        let fallback_slice = slice_pixels(pixels, max_cut, budget);
        let slice = record_slice.max(fallback_slice) as u64;
        let px = pixels as u64;
        let nodes = 2 * leaves as u64;
        Self {
            size,
            leaves,
            max_cut,
            tiles,
            capacity,
            split_walk,
            cones: storage_buffer(device, "li::cones", 16 * nodes),
            reps: storage_buffer(device, "li::reps", 4 * nodes),
            radius: storage_buffer(device, "li::radius", 8 * px),
            tile_count: storage_buffer(device, "li::tile_count", 4 * nt as u64),
            tile_recs: storage_buffer(device, "li::tile_recs", 4 * (nt * TILE_CAP) as u64),
            tile_offset: storage_buffer(device, "li::tile_offset", 4 * nt as u64),
            records: storage_buffer(device, "li::records", 4 * capacity as u64),
            rec_meta: storage_buffer(device, "li::rec_meta", 4 * (8 + capacity as u64)),
            record_cuts: storage_buffer(device, "li::record_cuts", 4 * capacity as u64 * max_cut as u64),
            sel: storage_buffer(device, "li::sel", 32 * px),
            diag: storage_buffer(device, "li::diag", 16 * px),
            stats: storage_buffer(device, "li::stats", 4 * STATS_WORDS as u64),
            trace: storage_buffer(device, "li::trace", 4 * TRACE_WORDS),
            // One LiState (96 bytes, li_interp.wgsl) at least: a binding smaller than the
            // struct is rejected at dispatch.
            walk_state: storage_buffer(device, "li::walk_state", if split_walk { 96 * px } else { 96 }),
            scratch: storage_buffer(device, "li::scratch", 8 * slice * max_cut as u64),
            lc_state: storage_buffer(device, "li::lc_state", 32 * slice),
            record_slice,
            fallback_slice,
        }
    }

    /// Bytes of the largest binding for these sizes (the scratch stays within its budget).
    /// (The records' cuts fit by construction: [`record_capacity`].)
    pub fn largest_binding(leaves: u32, size: (u32, u32), split_walk: bool) -> u64 {
        let px = size.0 as u64 * size.1 as u64;
        [32 * leaves as u64, 32 * px, if split_walk { 96 * px } else { 0 }]
            .into_iter()
            .max()
            .unwrap_or(0)
    }

    pub fn matches(&self, leaves: u32, size: (u32, u32), max_cut: u32, split_walk: bool) -> bool {
        self.leaves == leaves && self.size == size && self.max_cut == max_cut && self.split_walk == split_walk
    }
}

/// Everything a frame of the method binds from the renderer.
pub struct FrameInputs<'a> {
    pub tree: &'a TreeBuffers,
    pub scene: &'a SceneGpu,
    pub gbuffer: &'a GbufferTargets,
    pub camera: &'a wgpu::Buffer,
    pub accum: &'a wgpu::Buffer,
}

pub struct LiPass {
    build: BuildKernel,
    record_cuts: CutKernel,
    fallback: CutKernel,
    records_kernel: Kernel,
    radius: wgpu::ComputePipeline,
    place: wgpu::ComputePipeline,
    compact: wgpu::ComputePipeline,
    select_kernel: Kernel,
    select: wgpu::ComputePipeline,
    interp_kernel: Kernel,
    interp: wgpu::ComputePipeline,
    interp_timed: wgpu::ComputePipeline,
    /// Uniforms: 0 the records' and selection's; 1.. the walk's dispatches.
    params: StridedUniforms<GpuLiParams>,
    views_kernel: Kernel,
    views: wgpu::ComputePipeline,
    view_params: wgpu::Buffer,
    /// The frame counters (diagnostic frames).
    pub stats: CounterReadback<LiStats>,
}

/// `n` workgroups of a 1D kernel as (x, y) within the 65535-per-dimension limit (the kernel
/// numbers them `x + y * num_workgroups.x`).
pub fn groups_1d_as_2d(n: u32) -> (u32, u32) {
    let x = n.clamp(1, 65535);
    (x, n.div_ceil(x).max(1))
}

/// The structs this method shares with WGSL (its `Module::wgsl_twins`: the registry test
/// checks them against naga's layout).
pub static WGSL_TWINS: &[crate::gpu::gpu_data::WgslTwin] = &[
    crate::wgsl_twin!(
        crate::methods::lightcut_interpolation::pass::GpuLiParams,
        "methods/lightcut_interpolation/li_interp.wgsl",
        "LiParams",
        [
            width,
            height,
            tiles_x,
            tiles_y,
            leaves,
            levels,
            max_cut,
            capacity,
            r_min_px,
            r_max_px,
            one_minus_cos_max,
            epsilon,
            coverage,
            radius_rays,
            ray_offset,
            shadow_rays,
            interp_visibility,
            accumulate,
            trace_pixel,
            steps,
            first,
            last,
            distance_epsilon,
            _pad
        ]
    ),
    crate::wgsl_twin!(
        crate::methods::lightcut_interpolation::pass::GpuLiViewParams,
        "methods/lightcut_interpolation/li_views.wgsl",
        "LiViewParams",
        [
            mode,
            scale_top,
            r_min_px,
            r_max_px,
            exposure,
            tonemap,
            tiles_x,
            tiles_y,
            pinned,
            _pad,
            _pad + 4,
            _pad + 8
        ]
    ),
];

//! Stages 11-15 (thesis chapter 5) and the SST / RTSLC baselines: `slc_cuts` builds one
//! shallow light cut per k x k block at the block centre's G-buffer sample; `slc_sample`
//! blends the cuts per pixel (or falls back), traverses the tree from each chosen node and
//! evaluates one cluster per slot with a shadow ray.
//! Reads: the tree, its flags, the VPLs in leaf order, BVH, G-buffer. Writes: the GI
//! accumulation buffer and, in diagnostic frames only, per-pixel diagnostics, frame counters
//! and the pixel story ([`SlcBuffers`]). Timed frames run the sampling shader compiled with
//! `DIAGNOSTICS = false` (same estimate, none of that work, no readback).

use crate::gpu::frame::GbufferTargets;
use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use crate::gpu::readback::CounterReadback;
use crate::gpu::scene_gpu::SceneGpu;
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;
use crate::methods::ViewCx;
use bytemuck::{Pod, Zeroable};

use crate::gpu::passes::{
    WG_1D, groups_image,
    ism::{GpuIsmParams, IsmBuild, IsmPass, IsmPoints, IsmTargets},
    run_compute,
    sst_build::TreeBuffers,
};

/// Frame counter words written by `slc_sample`: two 32-bit counters, then four 64-bit ones
/// as (low, high) pairs.
pub const STATS: usize = 10;

pub use crate::base::traversal::TraversalStats as SamplingStats;

pub use crate::base::story::{PixelTrace, SampleVisibility, StopReason, TraceSample};

/// Layout of the pixel story (twin of the constants in `shaders/methods/tree_samplers/slc_sample.wgsl`).
pub const TRACE_HEADER: usize = 32;
pub const TRACE_RECORD: usize = 64;
pub const TRACE_SAMPLES: usize = 64;
pub const TRACE_PATH: usize = 24;
pub const TRACE_WORDS: usize = TRACE_HEADER + TRACE_RECORD * TRACE_SAMPLES;

/// Parses `slc_sample`'s trace buffer (None: the pixel was not traced this frame).
pub fn parse_trace(w: &[u32]) -> Option<PixelTrace> {
    if w.len() < TRACE_WORDS || w[0] != 1 {
        return None;
    }
    let f = |i: usize| f32::from_bits(w[i]);
    let taken = w[16];
    let samples = (0..(taken as usize).min(TRACE_SAMPLES))
        .map(|i| {
            let b = TRACE_HEADER + i * TRACE_RECORD;
            let stop = match w[b + 4] {
                0 => StopReason::Usable,
                1 => StopReason::Leaf,
                2 => StopReason::Dead,
                _ => StopReason::EmptySlot,
            };
            let steps = w[b + 3];
            let path = (0..(steps as usize).min(TRACE_PATH))
                .map(|k| (w[b + 16 + 2 * k], f(b + 17 + 2 * k)))
                .collect();
            let end = w[b + 2];
            let evaluated = matches!(stop, StopReason::Usable | StopReason::Leaf);
            let point = evaluated.then(|| {
                let vis = match w[b + 9] {
                    0 => SampleVisibility::FacingAway,
                    1 => SampleVisibility::Blocked,
                    _ => SampleVisibility::Visible,
                };
                (glam::Vec3::new(f(b + 6), f(b + 7), f(b + 8)), vis)
            });
            TraceSample {
                slot: (w[b] < 4).then_some(w[b] as usize),
                cut_slot: w[b + 13],
                start: w[b + 1],
                end,
                steps,
                stop,
                prob: f(b + 5),
                path,
                point,
                contribution: glam::Vec3::new(f(b + 10), f(b + 11), f(b + 12)),
                ism_map: w[b + 14].checked_sub(1),
            }
        })
        .collect();
    Some(PixelTrace {
        mode: w[1],
        fell_back: w[2] != 0,
        blocks: [w[3], w[4], w[5], w[6]],
        bilinear: [f(7), f(8), f(9), f(10)],
        weights: [f(11), f(12), f(13), f(14)],
        weight_sum: f(15),
        taken,
        cells: w[17].max(1),
        subset: w[18],
        filtered: false,
        samples,
    })
}

/// Per-frame buffers: the cuts (cut_size node ids per block, 0 = empty slot; then the radix
/// tree's mock cut, cut_size slots), per-pixel
/// diagnostics (vec4: steps per traversal, fell back, samples evaluated, 1 + block of slot
/// 0's cut) and the frame counters.
pub struct SlcBuffers {
    pub cuts: wgpu::Buffer,
    pub diag: wgpu::Buffer,
    pub stats: wgpu::Buffer,
    /// The pixel story ([`PixelTrace`]), cleared every frame.
    pub trace: wgpu::Buffer,
    pub size: (u32, u32),
    pub block: u32,
    pub grid: (u32, u32),
    pub cut_size: u32,
}

impl SlcBuffers {
    pub fn grid(size: (u32, u32), block: u32) -> (u32, u32) {
        (size.0.div_ceil(block.max(1)), size.1.div_ceil(block.max(1)))
    }

    /// Bytes of the largest binding (the cuts or the diagnostics).
    pub fn largest_binding(size: (u32, u32), block: u32, cut_size: u32) -> u64 {
        let (gx, gy) = Self::grid(size, block);
        ((gx as u64 * gy as u64 + 1) * cut_size as u64 * 4).max(size.0 as u64 * size.1 as u64 * 16)
    }

    pub fn new(device: &wgpu::Device, size: (u32, u32), block: u32, cut_size: u32) -> Self {
        let grid = Self::grid(size, block);
        let buf = |label: &str, bytes: u64| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(16),
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        Self {
            cuts: buf(
                "slc::cuts",
                (grid.0 as u64 * grid.1 as u64 + 1) * cut_size as u64 * 4,
            ),
            diag: buf("slc::diag", size.0 as u64 * size.1 as u64 * 16),
            stats: buf("slc::stats", (STATS * 4) as u64),
            trace: buf("slc::trace", TRACE_WORDS as u64 * 4),
            size,
            block,
            grid,
            cut_size,
        }
    }

    pub fn matches(&self, size: (u32, u32), block: u32, cut_size: u32) -> bool {
        self.size == size && self.block == block && self.cut_size == cut_size
    }
}

/// Twin: `ViewParams` in `shaders/methods/tree_samplers/slc_views.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuSlcViewParams {
    /// 0 steps, 1 fallback mask, 2 cut colours, 3 cut depth.
    pub mode: u32,
    pub grid_x: u32,
    pub block: u32,
    pub cut_size: u32,
    /// Linear exposure multiplier.
    pub exposure: f32,
    pub tonemap: u32,
    pub max_steps: f32,
    pub levels: u32,
    /// 1 + the selected block, 0 = none.
    pub selected: u32,
    /// Full-resolution pixels per GI pixel (2 with half-resolution GI).
    pub final_scale: u32,
    /// 1: the radix tree (cut depths along its links).
    pub radix: u32,
    pub leaves: u32,
}

/// What one sampling frame reads and writes: its parameters, the frame's light tree, scene
/// and G-buffer, the buffer it adds its estimate to, its own buffers, and the leaves' maps
/// with ISM visibility; `diagnostics` also writes the per-pixel diagnostics, counters and story.
pub struct SlcInputs<'a> {
    pub diagnostics: bool,
    pub params: GpuSlcParams,
    pub tree: &'a TreeBuffers,
    pub scene: &'a SceneGpu,
    pub gbuffer: &'a GbufferTargets,
    pub accum: &'a wgpu::Buffer,
    pub out: &'a SlcBuffers,
    pub ism: Option<&'a SlcIsm<'a>>,
}

/// The leaves' maps of a frame with ISM visibility.
pub struct SlcIsm<'a> {
    pub settings: &'a super::settings::IsmSettings<super::settings::IsmAdaptive>,
    pub points: &'a IsmPoints,
    pub targets: &'a IsmTargets,
    /// Maps: the tree's leaves.
    pub maps: u32,
}

pub struct SlcPass {
    views: wgpu::ComputePipeline,
    /// Per leaf its map's light (`ism_leaves_main`).
    ism_leaves: wgpu::ComputePipeline,
    /// The maps' build (the shared ISM component).
    pub ism: IsmPass,
    ism_params: wgpu::Buffer,
    /// Bound in the maps' place without ISM visibility: depth (read), lights (written).
    ism_dummy: [wgpu::Buffer; 2],
    views_kernel: Kernel,
    view_params: wgpu::Buffer,
    cuts: wgpu::ComputePipeline,
    cuts_kernel: Kernel,
    /// The sampling pass with diagnostics (counters, per-pixel diagnostics, story) and
    /// without (timed frames).
    sample: wgpu::ComputePipeline,
    sample_timed: wgpu::ComputePipeline,
    sample_kernel: Kernel,
    params: wgpu::Buffer,
    /// The counters of a recent frame, read back without blocking.
    /// The frame counters (diagnostic frames).
    pub stats: CounterReadback<SamplingStats>,
}

impl SlcPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let cuts_kernel = Kernel::new(
            device,
            "methods/tree_samplers/slc_cuts.wgsl",
            &["build_cuts"],
            KernelOptions::default(),
        )?;
        let sample_kernel = Kernel::new(
            device,
            "methods/tree_samplers/slc_sample.wgsl",
            &["main", "ism_leaves_main"],
            KernelOptions::default(),
        )?;
        let views_kernel = Kernel::new(
            device,
            "methods/tree_samplers/slc_views.wgsl",
            &["main"],
            KernelOptions::default(),
        )?;
        Ok(Self {
            views: views_kernel.compute(device, "slc_views", "main"),
            views_kernel,
            view_params: crate::gpu::passes::uniform_buffer::<GpuSlcViewParams>(device, "slc_views::params"),
            cuts: cuts_kernel.compute(device, "slc_cuts", "build_cuts"),
            sample: sample_kernel.compute(device, "slc_sample", "main"),
            ism_leaves: sample_kernel.compute(device, "slc_ism_lights", "ism_leaves_main"),
            ism: IsmPass::new(device)?,
            ism_params: crate::gpu::passes::uniform_buffer::<GpuIsmParams>(device, "slc::ism_params"),
            ism_dummy: [
                crate::gpu::passes::storage_buffer(device, "slc::ism_dummy_depth", 16),
                crate::gpu::passes::storage_buffer(device, "slc::ism_dummy_lights", 32),
            ],
            sample_timed: sample_kernel.compute_with(
                device,
                "slc_sample::timed",
                "main",
                &[("DIAGNOSTICS", 0.0)],
            ),
            params: crate::gpu::passes::uniform_buffer::<GpuSlcParams>(device, "slc::params"),
            stats: CounterReadback::new(
                device,
                "slc::stats_readback",
                (STATS * 4) as u64,
                SamplingStats::from_words,
            ),
            cuts_kernel,
            sample_kernel,
        })
    }

    /// Records the cuts (skipped for SST, which starts at the root) and the sampling; with
    /// `diagnostics` the sampling also writes the per-pixel diagnostics, the counters (read
    /// back after the frame) and the story, otherwise it touches none of them.
    pub fn record(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        inputs: SlcInputs<'_>,
    ) {
        let SlcInputs {
            diagnostics,
            params: p,
            tree,
            scene,
            gbuffer,
            accum,
            out,
            ism,
        } = inputs;
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let (ism_depth, ism_lights) = match ism {
            Some(m) => {
                let ip = GpuIsmParams::new(m.targets, m.settings, m.maps, m.points.count);
                queue.write_buffer(&self.ism_params, 0, bytemuck::bytes_of(&ip));
                (&m.targets.depth, &m.targets.lights)
            }
            None => (&self.ism_dummy[0], &self.ism_dummy[1]),
        };
        if p.method != 1 {
            let bind = self.cuts_kernel.bind(
                device,
                0,
                &[
                    ("sp", buf(&self.params)),
                    ("tree", buf(&tree.nodes)),
                    ("gb_position", tex(&gbuffer.position_view)),
                    ("gb_normal", tex(&gbuffer.normal_view)),
                    ("cuts", buf(&out.cuts)),
                    ("tree_links", buf(&tree.links)),
                ],
            );
            run_compute(
                encoder,
                timer,
                "slc_cuts",
                &self.cuts,
                &bind,
                ((p.grid_x * p.grid_y).div_ceil(WG_1D), 1, 1),
            );
        }
        let bind = self.sample_kernel.bind(
            device,
            0,
            &[
                ("sp", buf(&self.params)),
                ("tree", buf(&tree.nodes)),
                ("flags", buf(&tree.flags)),
                ("sorted_vpls", buf(&tree.sorted_vpls)),
                ("cuts", buf(&out.cuts)),
                ("bvh_nodes", buf(&scene.bvh_nodes)),
                ("bvh_triangles", buf(&scene.bvh_triangles)),
                ("gb_position", tex(&gbuffer.position_view)),
                ("gb_normal", tex(&gbuffer.normal_view)),
                ("gb_albedo", tex(&gbuffer.albedo_view)),
                ("accum", buf(accum)),
                ("diag", buf(&out.diag)),
                ("stats", buf(&out.stats)),
                ("trace", buf(&out.trace)),
                ("ism", buf(&self.ism_params)),
                ("ism_depth", buf(ism_depth)),
                ("ism_lights", buf(ism_lights)),
                ("tree_links", buf(&tree.links)),
            ],
        );
        if let Some(m) = ism {
            // The leaves' map lights, then the maps (the shared component).
            run_compute(
                encoder,
                timer,
                "slc_ism_lights",
                &self.ism_leaves,
                &bind,
                (m.maps.div_ceil(WG_1D).max(1), 1, 1),
            );
            let b = IsmBuild {
                name: "slc_ism",
                settings: m.settings,
                points: m.points,
                targets: m.targets,
            };
            self.ism.record_maps(device, queue, encoder, timer, &b, m.maps);
        }
        if diagnostics {
            encoder.clear_buffer(&out.stats, 0, None);
            encoder.clear_buffer(&out.trace, 0, None);
        }
        let name = match p.method {
            1 => "sst_sample",
            2 => "rtslc_sample",
            _ => "slc_sample",
        };
        run_compute(
            encoder,
            timer,
            name,
            if diagnostics {
                &self.sample
            } else {
                &self.sample_timed
            },
            &bind,
            groups_image(p.width, p.height),
        );
        if diagnostics {
            self.stats
                .record(encoder, &[(&out.stats, 0, 0, (STATS * 4) as u64)]);
        }
    }

    /// Draws one of the diagnostic views (`p.mode`) into `cx.dst` (the GI resolution).
    pub fn record_view(
        &self,
        cx: &mut ViewCx<'_>,
        encoder: &mut wgpu::CommandEncoder,
        p: GpuSlcViewParams,
        out: &SlcBuffers,
        tree_links: &wgpu::Buffer,
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
                ("cuts", buf(&out.cuts)),
                ("dst", tex(dst)),
                ("tree_links", buf(tree_links)),
            ],
        );
        run_compute(
            encoder,
            cx.timer,
            "slc_views",
            &self.views,
            &bind,
            groups_image(out.size.0, out.size.1),
        );
    }
}

/// Twin: `SlcParams` in `shaders/common/slc_params.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuSlcParams {
    pub width: u32,
    pub height: u32,
    pub block: u32,
    pub grid_x: u32,
    pub grid_y: u32,
    pub cut_size: u32,
    pub leaves: u32,
    pub levels: u32,
    /// 0 SLC, 1 SST, 2 RTSLC.
    pub method: u32,
    /// 0 stochastic, 1 off.
    pub blending: u32,
    /// 0 mock cut, 1 average, 2 root, 3 recompute.
    pub fallback: u32,
    pub cull: u32,
    pub seed: u32,
    pub accumulate: u32,
    pub epsilon: f32,
    pub ray_offset: f32,
    pub n_min: f32,
    pub d_max: f32,
    /// 1: the estimate without the albedo (half-resolution GI, upsampled at full resolution;
    /// interleaving, whose filter applies it).
    pub demodulate: u32,
    /// x | y << 16 of the pixel whose samples are recorded (`base::story::PixelTrace`);
    /// `u32::MAX` = none.
    pub trace_pixel: u32,
    /// Near-field refinement factor (`SamplingSettings::near_field`; 0 = off).
    pub near_field: f32,
    /// 1: shadow rays, 0: every sample visible (`GiSettings::shadow_rays`).
    pub shadow_rays: u32,
    /// Metres by which substitute samples' shadow rays stop short of the drawn point
    /// (`SamplingSettings::substitute_offset`).
    pub substitute_offset: f32,
    /// 0 mean position (eq. 5.5), 1 min-max box distance, 2 defensive (`ChildProbability`).
    pub child_probability: u32,
    /// Interleaving pattern edge n (1 = off) and the frame's subset offset
    /// (`reference::interleave::Interleave::offset_of`).
    pub interleave: u32,
    pub interleave_offset: u32,
    /// 1: the radix tree (children from its links; `TreeKind::Lbvh`), 0: the perfect tree.
    pub radix: u32,
    /// The BRDF model (`Brdf::gpu`).
    pub brdf: u32,
    /// How glossy walks weigh the children: 0 geometric, 1 the SST paper's material term,
    /// 2 defensive (`GlossyWeights::gpu`).
    pub glossy_material: u32,
    pub _pad: [u32; 3],
    /// xyz the camera's position.
    pub eye: [f32; 4],
}

/// The structs this method shares with WGSL (its `Module::wgsl_twins`: the registry test
/// checks them against naga's layout).
pub static WGSL_TWINS: &[crate::gpu::gpu_data::WgslTwin] = &[crate::wgsl_twin!(
    GpuSlcParams,
    "methods/tree_samplers/slc_sample.wgsl",
    "SlcParams",
    [
        width,
        height,
        block,
        grid_x,
        grid_y,
        cut_size,
        leaves,
        levels,
        method,
        blending,
        fallback,
        cull,
        seed,
        accumulate,
        epsilon,
        ray_offset,
        n_min,
        d_max,
        demodulate,
        trace_pixel,
        near_field,
        shadow_rays,
        substitute_offset,
        child_probability,
        interleave,
        interleave_offset,
        radix,
        brdf,
        glossy_material,
        _pad,
        _pad + 4,
        _pad + 8,
        eye
    ]
)];

#[cfg(test)]
mod tests {
    use super::SamplingStats;

    #[test]
    fn counters_are_64_bit_from_the_gpu_words_and_when_summed() {
        // 6e8 steps a frame (SST, 64 spp, 1280x720): the low word and a carried high word.
        let steps: u64 = 600_000_000 + (3 << 32);
        let words = [
            900_000,
            12,
            steps as u32,
            (steps >> 32) as u32,
            58_000_000,
            0,
            7,
            0,
            u32::MAX,
            1,
        ];
        let s = SamplingStats::from_words(&words);
        assert_eq!(s.steps, steps);
        assert_eq!(s.traversals, 58_000_000);
        assert_eq!(s.rays, (1 << 32) + u32::MAX as u64);
        // Eight frames of 6e8 steps pass 2^32: the sum keeps them (a u32 sum wrapped to
        // 0.85 steps per traversal at 64 spp on the H100).
        let frame = SamplingStats {
            pixels: 921_600,
            steps: 600_000_000,
            traversals: 58_982_400,
            ..Default::default()
        };
        let sum = (1..8).fold(frame, |a, _| a + frame);
        assert_eq!(sum.steps, 4_800_000_000);
        assert!((sum.steps_per_traversal() - frame.steps_per_traversal()).abs() < 1e-12);
    }
}

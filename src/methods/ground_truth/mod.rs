//! The thesis's ground truth (chapter 7): every VPL of the frame at every pixel with a BVH
//! shadow ray, in VPL batches, accumulated over frames (progressive; restarts when anything
//! it depends on changes). It is also the comparison's truth: the renderer runs a second
//! instance beside a per-frame method, on the same VPLs, into its own buffers.

pub mod pass;
mod ui;

use super::{FrameCx, Kind, Method, MethodId, MethodInfo, Module, Resource};
use crate::renderer::{
    GiProgress, gpu_data::GpuGtParams, gpu_data::GpuVpl, settings::RenderSettings, shaders::ShaderError,
};
use pass::GroundTruthPass;

pub const ID: MethodId = MethodId::new("ground-truth");

pub static MODULE: Module = Module {
    name: "ground_truth",
    create,
    shaders: &[(
        "methods/ground_truth/ground_truth.wgsl",
        include_str!("../../../shaders/methods/ground_truth/ground_truth.wgsl"),
    )],
    entry_shaders: &["methods/ground_truth/ground_truth.wgsl"],
};

pub static INFO: MethodInfo = MethodInfo {
    id: ID,
    aliases: &["gt"],
    label: "ground truth (all VPLs)",
    short: "ground truth",
    about: "Thesis chapter 7: every VPL at every pixel with a shadow ray (progressive).",
    progress_unit: "VPLs",
    kind: Kind::Progressive,
    module: &MODULE,
    reads: &[Resource::Gbuffer, Resource::Vpls, Resource::Bvh],
    views: &[],
    timed_passes: &["ground_truth"],
    story: false,
    shadow_ray_switch: true,
    truth_of_vpls: true,
    one_bounce: false,
    glossy: true,
    validate,
    invalid_example: Some(|s| {
        s.gi.rays_per_frame = 0;
        "gi.rays_per_frame"
    }),
    ui: ui::settings_ui,
    tests: &[
        "vpl::ground_truth_on_the_gpu_equals_a_cpu_evaluation_of_the_same_vpls",
        "slc::the_comparison_ground_truth_equals_the_ground_truth_method",
        "vpl::ground_truth_with_ggx_equals_a_cpu_evaluation_with_the_brdf",
    ],
    sweep: None,
    bias: |_| super::Bias::NotCompared,
    unbiased: None,
};

fn validate(s: &RenderSettings) -> Result<(), String> {
    if s.gi.rays_per_frame == 0 {
        return Err("gi.rays_per_frame must be at least 1".into());
    }
    Ok(())
}

/// State between frames: a snapshot of the VPLs it evaluates, and how far it got. Any change
/// of `FrameCx::key` restarts it.
struct GtState {
    key: u64,
    progress: GiProgress,
    snapshot: wgpu::Buffer,
}

pub struct GroundTruth {
    pass: GroundTruthPass,
    state: Option<GtState>,
}

fn create(device: &wgpu::Device) -> Result<Box<dyn Method>, ShaderError> {
    Ok(Box::new(GroundTruth {
        pass: GroundTruthPass::new(device)?,
        state: None,
    }))
}

impl Method for GroundTruth {
    /// Starts (when the key changed: snapshot of the frame's VPLs, accumulation cleared) or
    /// continues, adding at most `gi.rays_per_frame` shadow rays' worth of VPL batches.
    fn record(&mut self, cx: &mut FrameCx<'_>, enc: &mut wgpu::CommandEncoder) -> f32 {
        let total = cx.vpl_frame.count;
        if self.state.as_ref().is_none_or(|g| g.key != cx.key) {
            let bytes = (std::mem::size_of::<GpuVpl>() as u64) * cx.vpl_buffers.capacity as u64;
            let snapshot = match self.state.take() {
                Some(g) if g.snapshot.size() == bytes => g.snapshot,
                _ => cx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("ground_truth::vpl_snapshot"),
                    size: bytes,
                    usage: wgpu::BufferUsages::STORAGE
                        | wgpu::BufferUsages::COPY_DST
                        | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                }),
            };
            enc.copy_buffer_to_buffer(&cx.vpl_buffers.vpls, 0, &snapshot, 0, bytes);
            enc.clear_buffer(cx.gi_accum, 0, None);
            self.state = Some(GtState {
                key: cx.key,
                progress: GiProgress { done: 0, total },
                snapshot,
            });
        }
        let Some(gt) = self.state.as_mut() else { return 1.0 };
        if gt.progress.finished() {
            return 1.0;
        }
        let g = &cx.settings.gi;
        let pixels = (cx.size.0 as u64 * cx.size.1 as u64).max(1);
        let budget_vpls = (g.rays_per_frame as u64 / pixels).max(1);
        let batch = budget_vpls.div_ceil(pass::MAX_BATCHES as u64).max(1) as u32;
        let end = (gt.progress.done as u64 + budget_vpls).min(gt.progress.total as u64) as u32;
        let base = GpuGtParams {
            begin: gt.progress.done,
            end,
            width: cx.size.0,
            height: cx.size.1,
            epsilon: g.distance_epsilon,
            ray_offset: g.ray_offset,
            shadow_rays: g.shadow_rays as u32,
            brdf: cx.brdf.gpu(),
            eye: cx.eye.extend(0.0).to_array(),
        };
        gt.progress.done = self.pass.record(
            cx.device,
            cx.queue,
            enc,
            cx.timer,
            base,
            batch,
            cx.scene,
            &gt.snapshot,
            &cx.targets.gbuffer,
            cx.gi_accum,
        );
        1.0
    }

    fn progress(&self) -> Option<GiProgress> {
        self.state.as_ref().map(|g| g.progress)
    }

    fn reset(&mut self) {
        self.state = None;
    }
}

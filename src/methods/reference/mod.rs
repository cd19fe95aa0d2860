//! Converged reference (stage 19): every RSM texel as a VPL, estimated per pixel by Monte
//! Carlo through the RSM pyramids and accumulated over frames until `gi.reference_samples`
//! per pixel (checked against Mitsuba 3, docs/mitsuba_check.md). With `vpl.bounces` N > 1
//! each frame also traces `gi.reference_paths_per_sample` fresh light paths per sample
//! (`passes::light_paths`, new seeds every frame) and shades their bounce 2..=N VPLs at every
//! pixel with shadow rays (the ground truth's kernel): the mean over frames converges to the
//! N-bounce light, not to one frame's VPLs.

pub mod pass;
mod ui;

use super::{FrameCx, Kind, Method, MethodId, MethodInfo, Module, Resource};
use crate::base::field::Field;
use crate::base::progress::GiProgress;
use crate::gpu::gpu_data::GpuVpl;
use crate::gpu::passes::light_paths::{LightPathPass, PathInputs, PathJob};
use crate::gpu::shaders::ShaderError;
use crate::methods::ground_truth::pass::GpuGtParams;
use crate::methods::ground_truth::pass::{GroundTruthPass, MAX_BATCHES};
use crate::settings::GiSettings;
use crate::settings::RenderSettings;
use pass::{GpuRefParams, ReferencePass};

pub const ID: MethodId = MethodId::new("reference");

/// Its WGSL files (paths under `shaders/`), embedded; the GPU layer finds them through
/// `gpu::shaders::ShaderTable` without naming the method.
const SHADERS: &[(&str, &str)] = &[(
    "methods/reference/reference.wgsl",
    include_str!("../../../shaders/methods/reference/reference.wgsl"),
)];

/// Those of its files that are entry points.
const ENTRY_SHADERS: &[&str] = &["methods/reference/reference.wgsl"];

inventory::submit! {
    crate::gpu::shaders::ShaderTable {
        files: SHADERS,
        entries: ENTRY_SHADERS,
    }
}

pub static MODULE: Module = Module {
    name: "reference",
    create,
    shaders: SHADERS,
    entry_shaders: ENTRY_SHADERS,
    wgsl_twins: &[],
    own_workgroups: &[],
    flags: &[],
};

pub static INFO: MethodInfo = MethodInfo {
    id: ID,
    aliases: &["converged-reference"],
    label: "converged reference (all texels)",
    short: "reference",
    about: "Every RSM texel as a VPL, per-pixel Monte Carlo over the RSM pyramids (progressive).",
    progress_unit: "samples per pixel",
    kind: Kind::Progressive,
    module: &MODULE,
    reads: &[Resource::Gbuffer, Resource::ShadowMaps, Resource::Bvh],
    views: &[],
    timed_passes: &["reference", "light_path_starts", "light_paths", "ground_truth"],
    story: false,
    shadow_ray_switch: false,
    visibility: None,
    truth_of_vpls: false,
    one_bounce: false,
    glossy: true,
    validate,
    fields,
    invalid_example: Some(|s| {
        s.gi.reference_flux_mix = 0.0;
        "gi.reference_flux_mix"
    }),
    ui: ui::settings_ui,
    tests: &[
        "vpl::converged_reference_converges_to_the_exact_sum_over_all_texels",
        "vpl::raising_the_reference_target_continues_and_a_view_change_restarts",
        "light_paths::the_n_bounce_reference_converges_to_the_mean_ground_truth_of_fresh_vpls",
        "vpl::converged_reference_with_ggx_converges_to_the_exact_brdf_sum",
    ],
    sweep: None,
    bias: |_| super::Bias::NotCompared,
    unbiased: None,
};

/// Its numeric settings (in `[gi]`), declared once (validation, the GUI's sliders, `--set`).
pub static FIELDS: &[Field<GiSettings>] = &[
    crate::field!(
        GiSettings,
        reference_samples: u32,
        "samples per pixel",
        "",
        1,
        u32::MAX,
        Log,
        "the target: the reference stops when every pixel has this many samples"
    ),
    crate::field!(
        GiSettings,
        reference_spp_per_frame: u32,
        "samples / frame",
        "",
        1,
        4096,
        Log,
        "samples per pixel added each frame"
    ),
    crate::field!(
        GiSettings,
        reference_flux_mix: f32,
        "reference flux mix",
        "",
        0.0,
        1.0,
        Linear,
        "share of the texel PDF that follows flux (> 0 keeps it unbiased)",
        open
    ),
    crate::field!(
        GiSettings,
        reference_paths_per_sample: u32,
        "light paths / sample",
        "",
        1,
        256,
        Log,
        "fresh light paths per sample for bounces 2..N, shaded at every pixel"
    ),
];

fn validate(s: &RenderSettings) -> Result<(), String> {
    crate::base::field::check("gi", FIELDS, &s.gi)
}

pub struct Reference {
    pass: ReferencePass,
    /// Bounces 2..=N: fresh light paths each frame ...
    paths: LightPathPass,
    /// ... their VPLs ...
    path_vpls: Option<(u32, wgpu::Buffer)>,
    /// ... shaded at every pixel with shadow rays.
    shade: GroundTruthPass,
    /// (key, samples per pixel so far / target).
    state: Option<(u64, GiProgress)>,
}

fn create(device: &wgpu::Device) -> Result<Box<dyn Method>, ShaderError> {
    Ok(Box::new(Reference {
        pass: ReferencePass::new(device)?,
        paths: LightPathPass::new(device)?,
        path_vpls: None,
        shade: GroundTruthPass::new(device)?,
        state: None,
    }))
}

impl Method for Reference {
    /// Restart on any change (clear the sums), then add `reference_spp_per_frame` samples
    /// per pixel up to `reference_samples`; the scale is 1 / samples so far.
    fn record(&mut self, cx: &mut FrameCx<'_>, enc: &mut wgpu::CommandEncoder) -> f32 {
        let g = &cx.settings.gi;
        let total = g.reference_samples;
        if self.state.is_none_or(|(k, _)| k != cx.key) {
            enc.clear_buffer(cx.gi_accum, 0, None);
            self.state = Some((cx.key, GiProgress { done: 0, total }));
        }
        let Some((_, progress)) = self.state.as_mut() else {
            return 0.0;
        };
        // The target may change without restarting (more samples continue the same sums).
        progress.total = total;
        let n = g
            .reference_spp_per_frame
            .min(progress.total - progress.done.min(progress.total));
        if n > 0 {
            let p = GpuRefParams {
                width: cx.size.0,
                height: cx.size.1,
                samples: n,
                first_sample: progress.done,
                epsilon: g.distance_epsilon,
                ray_offset: g.ray_offset,
                flux_mix: g.reference_flux_mix,
                seed: cx.settings.vpl.seed,
                brdf: cx.brdf.gpu(),
                _pad: [0; 3],
                eye: cx.eye.extend(0.0).to_array(),
            };
            self.pass.record(cx, enc, p);
            let bounces = cx.settings.vpl.bounces;
            if bounces > 1 {
                // This frame's n samples of bounce 1 come with n x paths_per_sample light
                // paths, their flux x n: the sum over frames divided by the samples so far
                // is the mean of the frames' path estimates.
                let paths = n * g.reference_paths_per_sample;
                let count = (bounces - 1) * paths;
                if self.path_vpls.as_ref().is_none_or(|(c, _)| *c < count) {
                    self.path_vpls = Some((
                        count,
                        cx.device.create_buffer(&wgpu::BufferDescriptor {
                            label: Some("reference::path_vpls"),
                            size: count as u64 * std::mem::size_of::<GpuVpl>() as u64,
                            usage: wgpu::BufferUsages::STORAGE,
                            mapped_at_creation: false,
                        }),
                    ));
                }
                if let Some((_, vpls)) = &self.path_vpls {
                    let job = PathJob {
                        paths,
                        first: 0,
                        bounces,
                        roulette: cx.settings.vpl.roulette,
                        seed: cx.settings.vpl.seed.wrapping_mul(0x9e37_79b9)
                            ^ progress.done.wrapping_mul(0x85eb_ca6b).wrapping_add(0x27d4_eb2f),
                        ray_offset: g.ray_offset,
                        lod: 0,
                        flux_scale: n as f32,
                        flux_mix: g.reference_flux_mix,
                    };
                    let inputs = PathInputs {
                        lights: cx.lights,
                        vpl_params: cx.vpl_params,
                        rsm: &cx.targets.shadow,
                        pyramids: cx.vpl_buffers,
                        scene: cx.scene,
                        out: vpls,
                    };
                    self.paths
                        .record(cx.device, cx.queue, enc, cx.timer, &job, &inputs);
                    let base = GpuGtParams {
                        begin: 0,
                        end: count,
                        width: cx.size.0,
                        height: cx.size.1,
                        epsilon: g.distance_epsilon,
                        ray_offset: g.ray_offset,
                        shadow_rays: 1,
                        brdf: cx.brdf.gpu(),
                        eye: cx.eye.extend(0.0).to_array(),
                        // In order: each chunk is summed whole within the frame.
                        order: [0; 4],
                    };
                    self.shade
                        .record(cx, enc, base, count.div_ceil(MAX_BATCHES).max(1), vpls);
                }
            }
            progress.done += n;
        }
        if progress.done == 0 {
            0.0
        } else {
            1.0 / progress.done as f32
        }
    }

    fn progress(&self) -> Option<GiProgress> {
        self.state.map(|(_, p)| p)
    }

    fn reset(&mut self) {
        self.state = None;
    }
}

/// `MethodInfo::fields`.
fn fields() -> Vec<super::FieldSection> {
    vec![super::FieldSection::of("gi", FIELDS, false)]
}

//! Converged one-bounce reference (stage 19): every RSM texel as a VPL, estimated per pixel by
//! Monte Carlo through the RSM pyramids and accumulated over frames until
//! `gi.reference_samples` per pixel (checked against Mitsuba 3, docs/mitsuba_check.md).

pub mod pass;
mod ui;

use super::{FrameCx, Kind, Method, MethodId, MethodInfo, Module, Resource};
use crate::renderer::{GiProgress, settings::RenderSettings, shaders::ShaderError};
use pass::{GpuRefParams, ReferencePass};

pub const ID: MethodId = MethodId::new("reference");

pub static MODULE: Module = Module {
    name: "reference",
    create,
    shaders: &[(
        "methods/reference/reference.wgsl",
        include_str!("../../../shaders/methods/reference/reference.wgsl"),
    )],
    entry_shaders: &["methods/reference/reference.wgsl"],
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
    timed_passes: &["reference"],
    story: false,
    shadow_ray_switch: false,
    truth_of_vpls: false,
    validate,
    invalid_example: Some(|s| {
        s.gi.reference_flux_mix = 0.0;
        "gi.reference_flux_mix"
    }),
    ui: ui::settings_ui,
    tests: &[
        "vpl::converged_reference_converges_to_the_exact_sum_over_all_texels",
        "vpl::raising_the_reference_target_continues_and_a_view_change_restarts",
    ],
    sweep: None,
};

fn validate(s: &RenderSettings) -> Result<(), String> {
    let g = &s.gi;
    if !(g.reference_flux_mix > 0.0 && g.reference_flux_mix <= 1.0) {
        return Err(format!(
            "gi.reference_flux_mix {} is out of range (0..=1, > 0)",
            g.reference_flux_mix
        ));
    }
    if g.reference_samples == 0 {
        return Err("gi.reference_samples must be at least 1".into());
    }
    if !(1..=4096).contains(&g.reference_spp_per_frame) {
        return Err(format!(
            "gi.reference_spp_per_frame {} is out of range (1..=4096)",
            g.reference_spp_per_frame
        ));
    }
    Ok(())
}

pub struct Reference {
    pass: ReferencePass,
    /// (key, samples per pixel so far / target).
    state: Option<(u64, GiProgress)>,
}

fn create(device: &wgpu::Device) -> Result<Box<dyn Method>, ShaderError> {
    Ok(Box::new(Reference {
        pass: ReferencePass::new(device)?,
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
            };
            self.pass.record(
                cx.device,
                cx.queue,
                enc,
                cx.timer,
                p,
                cx.vpl_params,
                cx.vpl_buffers,
                &cx.targets.shadow,
                &cx.targets.gbuffer,
                cx.scene,
                cx.gi_accum,
            );
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

//! The frame graph: what one frame records and submits, in pass order (ARCHITECTURE.md,
//! *Frame pass order*): shadow maps / RSMs, G-buffer, direct light, VPLs, light tree, the GI
//! method (through `crate::methods`) and the comparison's truth beside it, composite, and
//! each docked view with its overlays.

use super::*;

/// What a method's `record` sees of the renderer: the frame's shared resources by disjoint
/// field borrows of `$r` (a macro, so that the method instance, another field, stays
/// borrowable), writing into `$accum`.
macro_rules! frame_cx {
    ($r:ident, $method:expr, $accum:expr, $size:expr, $key:expr, $trace:expr, $diag:expr) => {
        frame_cx!($r, $method, $accum, $size, $key, $trace, $diag, timer)
    };
    // The same with another timer field of `$r` (the comparison truth: `quiet_timer`).
    ($r:ident, $method:expr, $accum:expr, $size:expr, $key:expr, $trace:expr, $diag:expr, $timer:ident) => {
        FrameCx {
            method: $method,
            device: &$r.ctx.device,
            adapter_type: $r.ctx.adapter_info.device_type,
            queue: &$r.ctx.queue,
            errors: &$r.ctx.errors,
            timer: &mut $r.$timer,
            settings: &$r.settings,
            scene: &$r.scene,
            scene_radius: $r.scene.bounds.radius().max(1e-30),
            targets: &$r.targets,
            camera: &$r.camera_buf,
            vpl_buffers: &$r.vpl_buffers,
            vpl_frame: &$r.vpl_frame,
            lights: &$r.frame_lights,
            brdf: $r.frame_brdf,
            eye: $r.frame_eye,
            vpl_params: $r.vpl_gen.params_buffer(),
            tree: &$r.tree,
            gi_accum: $accum,
            size: $size,
            key: $key,
            frame_index: $r.frames,
            trace_pixel: $trace,
            diagnostics: $diag,
            views: &$r.frame_views,
            rsm: $r.rsm_raster,
        }
    };
}

impl Renderer {
    /// Records and submits one frame, ending with the selected view (with the global display
    /// look) in the view texture.
    pub fn render(&mut self, input: &FrameInput<'_>) {
        let spec = ViewSpec::new(input.view, &self.settings.display);
        self.render_views(input, &[spec]);
    }

    /// Records and submits one frame and draws every view of `views` (at least one; the
    /// first into [`Renderer::view_texture`], the others into [`Renderer::view_texture_at`]).
    /// `input.view` is ignored. Each extra view is its own submission (the view passes share
    /// their parameter buffers).
    pub fn render_views(&mut self, input: &FrameInput<'_>, views: &[ViewSpec]) {
        let first = views.first().copied().unwrap_or_default();
        self.frame_views.clone_from(&self.kept_views);
        for v in views {
            if let ViewBuffer::Method(m) = v.buffer
                && !self.frame_views.contains(&m)
            {
                self.frame_views.push(m);
            }
        }
        let device = self.ctx.device.clone();
        let queue = self.ctx.queue.clone();
        let size = self.targets.size;
        let s = self.settings.clone();

        let lights = &input.lights[..input.lights.len().min(MAX_LIGHTS)];
        let setup = self.upload_frame_uniforms(input.camera, lights, size, &s);

        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("frame::encoder"),
        });
        // A diagnostic frame or a timed one (FrameMode). A frame that advances a converging
        // comparison truth stays timed: the truth's passes record with the quiet timer, so
        // its timings are the method's from the first frames on (issue 41).
        let diagnostic = self.next_frame_diagnostic();
        let compare_due = self.compare_on
            && s.gi.method.per_frame()
            && (diagnostic || !self.compare_settled(input, lights, size));
        self.timer.begin_frame(!diagnostic);
        self.record_raster(&mut enc, &setup, size);
        let vpl_ok = self.vpl_resources_ok(&s, setup.layers);
        self.record_vpls_and_tree(&mut enc, &s, lights, vpl_ok, diagnostic);
        let indirect_scale = if vpl_ok {
            let key = self.gt_key(input, lights, size);
            let scale = self.record_method(&mut enc, s.gi.method, key, size, diagnostic);
            if compare_due {
                self.step_compare(&mut enc, input, lights, size);
            }
            scale
        } else {
            0.0
        };
        self.record_temporal_and_composite(&mut enc, &s, setup.gpu_camera, indirect_scale, vpl_ok);
        self.record_view_with_overlays(&mut enc, &first, input.camera, vpl_ok);
        queue.submit([enc.finish()]);
        self.submit_extra_views(views, input.camera, vpl_ok);
        self.finish_frame(diagnostic, vpl_ok);
    }

    /// Draws `input.view` (with its overlays) from the last frame's buffers without rendering
    /// a new frame: an accumulating method keeps its frame count, a view shows exactly what
    /// was read back. Untimed.
    pub fn redraw_view(&mut self, input: &FrameInput<'_>) {
        let spec = ViewSpec::new(input.view, &self.settings.display);
        let mut enc = self
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("frame::redraw_encoder"),
            });
        self.timer.begin_frame(false);
        let vpl_ok = self.last_vpl_ok;
        self.record_view_with_overlays(&mut enc, &spec, input.camera, vpl_ok);
        self.ctx.queue.submit([enc.finish()]);
    }

    /// Whether the comparison's truth is finished for this frame's view and settings (a timed
    /// frame then leaves it out).
    fn compare_settled(&self, input: &FrameInput<'_>, lights: &[DirectionalLight], size: (u32, u32)) -> bool {
        self.compare.as_ref().is_some_and(|c| {
            c.targets_size == size
                && c.key == self.compare_key(input, lights, size)
                && c.truth.progress().is_some_and(|p| p.finished())
        })
    }

    /// One view into `targets.view`, then the overlays that apply to it.
    pub(super) fn record_view_with_overlays(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        spec: &ViewSpec,
        camera: &Camera,
        vpl_ok: bool,
    ) {
        let device = self.ctx.device.clone();
        let queue = self.ctx.queue.clone();
        self.record_view(enc, spec, camera);
        if self.settings.display.vpl_overlay && vpl_ok {
            self.record_vpl_overlay(enc, spec.buffer);
        }
        let d = &self.settings.display;
        if d.tree_overlay != TreeOverlay::Off
            && vpl_ok
            && !spec.buffer.is_rsm_space()
            && spec.effective_ab().is_none()
        {
            let look = passes::sst_overlay::OverlayLook {
                mode: d.tree_overlay,
                color: d.tree_color,
                level: d.tree_level,
                min_radius: 0.003 * self.scene.bounds.radius().max(1e-30),
            };
            let inputs = passes::sst_overlay::OverlayInputs {
                camera: &self.camera_buf,
                trees: (&self.tree, self.tree_other.as_ref().filter(|_| d.tree_compare)),
                gb_position: &self.targets.gbuffer.position_view,
                dst: &self.targets.view.view,
                size: self.targets.view.size,
            };
            self.sst_overlay
                .record(&device, &queue, enc, &mut self.timer, look, &inputs);
        }
    }

    /// Fingerprint of everything the ground truth depends on (not the animated seed).
    pub(super) fn gt_key(
        &self,
        input: &FrameInput<'_>,
        lights: &[DirectionalLight],
        size: (u32, u32),
    ) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        hash_view(&mut h, input, lights, size);
        let mut s = self.settings.clone();
        s.display = Default::default();
        s.gi.rays_per_frame = 0;
        s.gi.reference_samples = 0;
        s.gi.reference_spp_per_frame = 0;
        s.vpl.animate = false;
        format!("{s:?}").hash(&mut h);
        h.finish()
    }

    /// Records the passes of `method` (its module's instance) for this frame into the GI
    /// accumulation; returns the composite's scale.
    pub(super) fn record_method(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        method: MethodId,
        key: u64,
        size: (u32, u32),
        diagnostic: bool,
    ) -> f32 {
        let module = method.info().module.name;
        let Some((_, m)) = self.methods.iter_mut().find(|(n, _)| *n == module) else {
            return 0.0;
        };
        if self.accum_owner != Some(method) {
            m.reset();
            self.accum_owner = Some(method);
        }
        let mut cx = frame_cx!(
            self,
            method,
            &self.targets.lighting.gi_accum,
            size,
            key,
            if diagnostic { self.trace_pixel } else { None },
            diagnostic
        );
        m.record(&mut cx, enc)
    }

    /// Key of the comparison ground truth: what its image depends on (view, lights, size,
    /// VPL and shading settings), not the sampler's settings.
    pub(super) fn compare_key(
        &self,
        input: &FrameInput<'_>,
        lights: &[DirectionalLight],
        size: (u32, u32),
    ) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        hash_view(&mut h, input, lights, size);
        let s = &self.settings;
        let mut v = s.vpl.clone();
        v.animate = false;
        format!(
            "{:?}{:?}{}{}",
            s.shadow, v, s.gi.distance_epsilon, s.gi.ray_offset
        )
        .hash(&mut h);
        // Animated or unfrozen-but-changing VPLs: a new set each frame never converges.
        if s.vpl.animate && self.freeze.is_none() {
            self.frames.hash(&mut h);
        }
        h.finish()
    }

    /// The ground truth of the same VPLs beside a tree sampler (progressive, into its own
    /// buffers), then its composite.
    pub(super) fn step_compare(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        input: &FrameInput<'_>,
        lights: &[DirectionalLight],
        size: (u32, u32),
    ) {
        let device = self.ctx.device.clone();
        let queue = self.ctx.queue.clone();
        let key = self.compare_key(input, lights, size);
        let truth = methods::comparison_truth();
        let mut cmp = match self.compare.take() {
            // A new size: new targets, the same pipelines, the sum restarts.
            Some(mut c) => {
                if c.targets_size != size {
                    c.targets = frame::LightingTargets::new(&device, size);
                    c.targets_size = size;
                    c.truth.reset();
                }
                c
            }
            None => match (truth.info().module.create)(&device) {
                Ok(m) => CompareState {
                    truth: m,
                    key,
                    targets: frame::LightingTargets::new(&device, size),
                    targets_size: size,
                },
                Err(e) => {
                    self.ctx.errors.report(format!("comparison ground truth: {e}"));
                    return;
                }
            },
        };
        // Untimed: the frame's timings are the method's, not its ground truth's.
        let mut cx = frame_cx!(
            self,
            truth,
            &cmp.targets.gi_accum,
            size,
            key,
            None,
            true,
            quiet_timer
        );
        // While it converges, the truth's views show the VPLs so far scaled to all of them.
        let scale = cmp.truth.record(&mut cx, enc);
        cmp.key = key;
        let inputs = CompositeInputs {
            size,
            indirect_scale: scale,
            direct: &self.targets.lighting.direct_view,
            accum: &cmp.targets.gi_accum,
            out_indirect: &cmp.targets.indirect_view,
            out_final: &cmp.targets.final_view,
        };
        self.compare_composite
            .record(&device, &queue, enc, &mut self.quiet_timer, &inputs);
        self.compare = Some(cmp);
    }

    /// Runs the ground truth of the same VPLs beside a tree sampler (SLC, SST, RTSLC), for the
    /// comparison views and metrics; off frees its buffers.
    pub fn set_compare_ground_truth(&mut self, on: bool) {
        self.compare_on = on;
        if !on {
            self.compare = None;
        }
    }

    /// Progress of the comparison ground truth (None when off or not started).
    pub fn compare_progress(&self) -> Option<GiProgress> {
        self.compare.as_ref().and_then(|c| c.truth.progress())
    }
}

/// Clears a view texture to black (a render pass: `clear_texture` needs a device feature).
/// One GPU instance per method module.
pub(super) fn create_methods(device: &wgpu::Device) -> Result<Vec<MethodInstance>, RenderError> {
    methods::modules()
        .into_iter()
        .map(|m| Ok((m.name, (m.create)(device)?)))
        .collect()
}

/// What the temporal history belongs to: the method and the stage's mode and history
/// parameters (not the filter's, which act on each frame anew).
pub(super) fn temporal_key(method: MethodId, t: &TemporalSettings) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    method.cli().hash(&mut h);
    format!(
        "{:?}{}{}{}{}",
        t.mode, t.max_history, t.normal_cos, t.depth_tolerance, t.feedback_iteration
    )
    .hash(&mut h);
    h.finish()
}

/// Hashes what a frame's image depends on besides the settings: camera, lights, size.
pub(super) fn hash_view(
    h: &mut impl std::hash::Hasher,
    input: &FrameInput<'_>,
    lights: &[DirectionalLight],
    size: (u32, u32),
) {
    use std::hash::Hash;
    let c = input.camera;
    for v in [c.position, c.forward, c.up] {
        v.to_array().map(f32::to_bits).hash(h);
    }
    c.yfov.to_bits().hash(h);
    for l in lights {
        l.direction.to_array().map(f32::to_bits).hash(h);
        l.irradiance.to_array().map(f32::to_bits).hash(h);
    }
    size.hash(h);
}

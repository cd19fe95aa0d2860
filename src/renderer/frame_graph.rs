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
        self.frame_lights.clear();
        self.frame_lights.extend_from_slice(lights);
        self.frame_brdf = s.gi.method.brdf(s.gi.brdf);
        self.frame_eye = input.camera.position;
        let layers = lights.len().max(1) as u32;
        if layers != self.targets.shadow.layers() {
            self.targets.shadow = ShadowTargets::new(&device, s.shadow.resolution, layers);
        }
        let gpu_lights = GpuLights::new(
            lights,
            &self.scene.bounds,
            s.shadow.resolution,
            s.shadow.depth_bias,
            s.shadow.normal_offset,
            s.shadow.slope_bias,
            s.shadow.pcf_radius,
        );
        let gpu_camera = GpuCamera::new(input.camera, size.0, size.1);
        queue.write_buffer(&self.camera_buf, 0, bytemuck::bytes_of(&gpu_camera));
        queue.write_buffer(&self.lights_buf, 0, bytemuck::bytes_of(&gpu_lights));
        self.light0_lum = lights
            .first()
            .map(|l| l.irradiance.dot(Vec3::new(0.2126, 0.7152, 0.0722)))
            .unwrap_or(1.0);
        self.lights_texel = gpu_lights.lights[0].shadow[0];
        self.rsm_raster = lights.first().map(|l| {
            let (view_proj, texel, _) =
                crate::gpu::gpu_data::light_frustum(l.direction, &self.scene.bounds, s.shadow.resolution);
            crate::gpu::gpu_data::RsmRaster {
                view_proj,
                direction: l.direction.normalize_or(glam::Vec3::NEG_Y),
                texel,
                res: s.shadow.resolution,
                lights: lights.len() as u32,
            }
        });

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
        let t = &self.targets;
        let rsm = RsmInputs {
            lights: &gpu_lights,
            scene: &self.scene,
            out: &t.shadow,
        };
        self.rsm.record(&device, &queue, &mut enc, &mut self.timer, &rsm);
        self.gbuffer.record(
            &device,
            &mut enc,
            &mut self.timer,
            &self.camera_buf,
            &self.scene,
            &t.gbuffer,
        );
        self.direct.record(
            &device,
            &queue,
            &mut enc,
            &mut self.timer,
            &crate::gpu::passes::direct::DirectInputs {
                brdf: self.frame_brdf.gpu(),
                camera: &self.camera_buf,
                lights: &self.lights_buf,
                shadow: &t.shadow,
                gbuffer: &t.gbuffer,
                out: &t.lighting.direct_view,
                size,
            },
        );
        // VPLs (thesis 4.1): resources follow the RSM resolution, light count and VPL budget.
        let vb = &self.vpl_buffers;
        let mut vpl_ok = true;
        if vb.res != s.shadow.resolution || vb.layers != layers || vb.capacity != s.vpl.count {
            match check_device_limits(&device, &s, layers) {
                // More lights than the buffers fit: say so and keep the frame direct-only.
                Err(e) => {
                    self.ctx.errors.report(e.to_string());
                    vpl_ok = false;
                }
                Ok(()) => {
                    self.vpl_buffers = VplBuffers::new(&device, s.shadow.resolution, layers, s.vpl.count);
                    for (_, m) in &mut self.methods {
                        m.reset();
                    }
                    self.compare = None;
                }
            }
        }
        let seed = s
            .vpl
            .seed
            .wrapping_add(if s.vpl.animate { self.frames as u32 } else { 0 });
        // The tree the method runs on: `tree.kind` where it follows links, else the perfect one.
        let tree_kind = s.gi.method.tree_kind(s.tree.kind);
        let frozen = self.freeze.is_some() && vpl_ok && self.tree.matches(self.vpl_frame.count, tree_kind);
        if frozen {
            // Frozen VPLs and tree (debugging): only the flags follow new thresholds.
            let th = (s.tree.v_min, s.tree.sigma_max);
            if self.freeze != Some(th) {
                let usable = UsableThresholds {
                    v_min: th.0,
                    sigma_max: th.1,
                };
                self.sst_build.record_classify(
                    &device,
                    &queue,
                    &mut enc,
                    &mut self.timer,
                    &self.tree,
                    usable,
                );
                self.freeze = Some(th);
            }
        } else if vpl_ok {
            if self.freeze.is_some() {
                self.freeze = Some((s.tree.v_min, s.tree.sigma_max));
            }
            let t = &self.targets;
            let inputs = passes::vpl_gen::VplGenInputs {
                settings: &s.vpl,
                gi: &s.gi,
                seed,
                scene_radius: self.scene.bounds.radius().max(1e-30),
                lights,
                camera: &self.camera_buf,
                rsm: &t.shadow,
                gbuffer: &t.gbuffer,
                out: &self.vpl_buffers,
            };
            self.vpl_frame = self
                .vpl_gen
                .record(&device, &queue, &mut enc, &mut self.timer, &inputs);
            // Bounces 2..=N (`vpl.bounces`): light paths from RSM texels drawn by flux.
            let vf = &self.vpl_frame;
            if vf.paths > 0 {
                let job = passes::light_paths::PathJob {
                    paths: vf.paths,
                    first: vf.first_bounce,
                    bounces: vf.bounces,
                    roulette: s.vpl.roulette,
                    seed,
                    ray_offset: s.gi.ray_offset,
                    lod: 0,
                    flux_scale: 1.0,
                    flux_mix: s.vpl.path_flux_mix,
                };
                let inputs = passes::light_paths::PathInputs {
                    lights,
                    vpl_params: self.vpl_gen.params_buffer(),
                    rsm: &self.targets.shadow,
                    pyramids: &self.vpl_buffers,
                    scene: &self.scene,
                    out: &self.vpl_buffers.vpls,
                };
                self.light_paths
                    .record(&device, &queue, &mut enc, &mut self.timer, &job, &inputs);
            }
            // SST stages 8-9: sort keys and the bitonic sort of (key, index) pairs.
            if self.sort_buffers.count != self.vpl_frame.count {
                self.sort_buffers = SortBuffers::new(&device, self.vpl_frame.count);
            }
            self.sst_sort.record(
                &device,
                &queue,
                &mut enc,
                &mut self.timer,
                &self.vpl_buffers.vpls,
                &self.sort_buffers,
            );
            // SST stage 10: the tree over the sorted VPLs (the perfect tree or the radix tree,
            // `tree.kind`), then its usable flags.
            if !self.tree.matches(self.vpl_frame.count, tree_kind) {
                self.tree = TreeBuffers::new(&device, self.vpl_frame.count, tree_kind);
            }
            let usable = UsableThresholds {
                v_min: s.tree.v_min,
                sigma_max: s.tree.sigma_max,
            };
            let build = BuildInputs {
                vpls: &self.vpl_buffers.vpls,
                sort: &self.sort_buffers,
                tree: &self.tree,
                usable,
            };
            self.sst_build
                .record(&device, &queue, &mut enc, &mut self.timer, &build);
            // The overlay's comparison: the other tree over the same keys, untimed.
            let d = &s.display;
            if d.tree_compare && d.tree_overlay != TreeOverlay::Off {
                let other = match tree_kind {
                    TreeKind::Perfect => TreeKind::Lbvh,
                    TreeKind::Lbvh => TreeKind::Perfect,
                };
                let count = self.vpl_frame.count;
                if !self.tree_other.as_ref().is_some_and(|t| t.matches(count, other)) {
                    self.tree_other = Some(TreeBuffers::new(&device, count, other));
                }
                if let Some(t) = &self.tree_other {
                    let other = BuildInputs {
                        vpls: &self.vpl_buffers.vpls,
                        sort: &self.sort_buffers,
                        tree: t,
                        usable,
                    };
                    self.sst_build
                        .record(&device, &queue, &mut enc, &mut self.quiet_timer, &other);
                }
            } else {
                self.tree_other = None;
            }
            // The flux-pyramid tops (one float per light), read back on a later frame: a
            // readback, so in diagnostic frames only.
            let (per_layer, offsets) = passes::vpl_gen::pyramid_layout(self.vpl_buffers.res);
            let top = *offsets.last().unwrap_or(&0) as u64;
            let fp = &self.vpl_buffers.flux_pyramid;
            let copies: Vec<(&wgpu::Buffer, u64, u64, u64)> = (0..self.vpl_frame.ranges.len() as u64)
                .map(|l| (fp, 4 * (l * per_layer as u64 + top), 4 * l, 4))
                .collect();
            if diagnostic {
                self.flux_readback.record(&mut enc, &copies);
            }
        }
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
        // The temporal stage after a per-frame method (reprojection, history, SVGF): the
        // composite then reads its result at scale 1.
        let temporal_on = vpl_ok && s.temporal.mode != TemporalMode::Off && s.gi.method.per_frame();
        // Off frees its buffers; a frame of a progressive method (the ground truth of the
        // same view, say) leaves the history as it was: the next per-frame frame reprojects
        // from the last frame the stage ran (its camera and G-buffer are kept with it).
        if s.temporal.mode == TemporalMode::Off {
            self.temporal.release();
        } else if !temporal_on {
            self.temporal.skipped();
        }
        let t = &self.targets;
        let filtered = if temporal_on {
            let inputs = passes::temporal::TemporalInputs {
                gbuffer: &t.gbuffer,
                camera_buf: &self.camera_buf,
                camera: gpu_camera,
                accum: &t.lighting.gi_accum,
                scale: indirect_scale,
                size,
                key: temporal_key(s.gi.method, &s.temporal),
            };
            self.temporal
                .record(&device, &queue, &mut enc, &mut self.timer, &s.temporal, &inputs)
        } else {
            None
        };
        let (accum, scale) = match filtered {
            Some(b) => (b, 1.0),
            None => (&t.lighting.gi_accum, indirect_scale),
        };
        let inputs = CompositeInputs {
            size,
            indirect_scale: scale,
            direct: &t.lighting.direct_view,
            accum,
            out_indirect: &t.lighting.indirect_view,
            out_final: &t.lighting.final_view,
        };
        self.composite
            .record(&device, &queue, &mut enc, &mut self.timer, &inputs);
        self.record_view_with_overlays(&mut enc, &first, input.camera, vpl_ok);
        queue.submit([enc.finish()]);
        // The other views, each into its own texture.
        self.extra_views.truncate(views.len().saturating_sub(1));
        for (i, spec) in views.iter().enumerate().skip(1) {
            if self.extra_views.len() < i {
                self.view_generation += 1;
                self.extra_views
                    .push(ViewTarget::new(&device, (1, 1), self.view_generation));
            }
            let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("frame::view_encoder"),
            });
            std::mem::swap(&mut self.targets.view, &mut self.extra_views[i - 1]);
            self.record_view_with_overlays(&mut enc, spec, input.camera, vpl_ok);
            std::mem::swap(&mut self.targets.view, &mut self.extra_views[i - 1]);
            queue.submit([enc.finish()]);
        }
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("frame::resolve_encoder"),
        });
        self.timer.resolve(&mut enc);
        queue.submit([enc.finish()]);
        self.timer.after_submit();
        self.flux_readback.after_submit();
        for (_, m) in &mut self.methods {
            m.after_submit();
        }
        self.frames += 1;
        self.last_diagnostic = diagnostic;
        if diagnostic {
            self.diagnostic_requested = false;
        }
        self.last_vpl_ok = vpl_ok;
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
fn temporal_key(method: MethodId, t: &TemporalSettings) -> u64 {
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

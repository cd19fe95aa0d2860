//! The frame's stages as [`Renderer::render_views`] calls them, in pass order: uniforms,
//! rasters, VPLs and the light tree, (the GI method), the temporal stage and composite, the
//! extra views, the frame's end.

use super::*;

/// What stage 0 uploaded and later stages read: the light and camera uniforms and the
/// number of light layers (shadow maps / RSMs).
pub(super) struct FrameSetup {
    pub gpu_lights: GpuLights,
    pub gpu_camera: GpuCamera,
    pub layers: u32,
}

impl Renderer {
    /// Stage 0: the frame's lights (at most `MAX_LIGHTS`), BRDF and eye kept for the
    /// methods; the shadow targets sized to the light count; the camera and light uniforms
    /// uploaded; the first light's luminance, texel and RSM raster kept.
    pub(super) fn upload_frame_uniforms(
        &mut self,
        camera: &Camera,
        lights: &[DirectionalLight],
        size: (u32, u32),
        s: &RenderSettings,
    ) -> FrameSetup {
        let queue = self.ctx.queue.clone();
        self.frame_lights.clear();
        self.frame_lights.extend_from_slice(lights);
        self.frame_brdf = s.gi.method.brdf(s.gi.brdf);
        self.frame_eye = camera.position;
        let layers = lights.len().max(1) as u32;
        if layers != self.targets.shadow.layers() {
            self.targets.shadow = ShadowTargets::new(&self.ctx.device, s.shadow.resolution, layers);
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
        let gpu_camera = GpuCamera::new(camera, size.0, size.1);
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
        FrameSetup {
            gpu_lights,
            gpu_camera,
            layers,
        }
    }

    /// Stage 1, the rasters: shadow maps / RSMs, the G-buffer, direct light.
    pub(super) fn record_raster(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        setup: &FrameSetup,
        size: (u32, u32),
    ) {
        let (device, queue) = (self.ctx.device.clone(), self.ctx.queue.clone());
        let t = &self.targets;
        let rsm = RsmInputs {
            lights: &setup.gpu_lights,
            scene: &self.scene,
            out: &t.shadow,
        };
        self.rsm.record(&device, &queue, enc, &mut self.timer, &rsm);
        self.gbuffer.record(
            &device,
            enc,
            &mut self.timer,
            &self.camera_buf,
            &self.scene,
            &t.gbuffer,
        );
        self.direct.record(
            &device,
            &queue,
            enc,
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
    }

    /// VPL resources follow the RSM resolution, light count and VPL budget (thesis 4.1):
    /// rebuilt when they change (the methods reset, the comparison dropped). False when the
    /// device cannot hold them: the error is reported and the frame stays direct-only.
    pub(super) fn vpl_resources_ok(&mut self, s: &RenderSettings, layers: u32) -> bool {
        let device = self.ctx.device.clone();
        let vb = &self.vpl_buffers;
        let mut vpl_ok = true;
        if vb.res != s.shadow.resolution || vb.layers != layers || vb.capacity != s.vpl.count {
            match check_device_limits(&device, s, layers) {
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
        vpl_ok
    }

    /// Stage 2, VPLs and the light tree: the VPLs (bounces 2..=N as light paths), the sort
    /// keys and their sort (SST stages 8-9), the tree over them and its usable flags (stage
    /// 10), the overlay's other tree, the flux-pyramid tops' readback (diagnostic frames).
    /// Frozen (debugging): only the usable flags follow new thresholds.
    pub(super) fn record_vpls_and_tree(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        s: &RenderSettings,
        lights: &[DirectionalLight],
        vpl_ok: bool,
        diagnostic: bool,
    ) {
        let (device, queue) = (self.ctx.device.clone(), self.ctx.queue.clone());
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
                self.sst_build
                    .record_classify(&device, &queue, enc, &mut self.timer, &self.tree, usable);
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
                .record(&device, &queue, enc, &mut self.timer, &inputs);
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
                    .record(&device, &queue, enc, &mut self.timer, &job, &inputs);
            }
            // SST stages 8-9: sort keys and the bitonic sort of (key, index) pairs.
            if self.sort_buffers.count != self.vpl_frame.count {
                self.sort_buffers = SortBuffers::new(&device, self.vpl_frame.count);
            }
            self.sst_sort.record(
                &device,
                &queue,
                enc,
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
                .record(&device, &queue, enc, &mut self.timer, &build);
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
                        .record(&device, &queue, enc, &mut self.quiet_timer, &other);
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
                self.flux_readback.record(enc, &copies);
            }
        }
    }

    /// Stage 4: the temporal stage after a per-frame method (reprojection, history, SVGF;
    /// the composite then reads its result at scale 1), and the composite of direct and
    /// indirect light.
    pub(super) fn record_temporal_and_composite(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        s: &RenderSettings,
        gpu_camera: GpuCamera,
        indirect_scale: f32,
        vpl_ok: bool,
    ) {
        let (device, queue) = (self.ctx.device.clone(), self.ctx.queue.clone());
        let size = self.targets.size;
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
                key: frame_graph::temporal_key(s.gi.method, &s.temporal),
            };
            self.temporal
                .record(&device, &queue, enc, &mut self.timer, &s.temporal, &inputs)
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
            .record(&device, &queue, enc, &mut self.timer, &inputs);
    }

    /// The frame's other views, each into its own texture and its own submission.
    pub(super) fn submit_extra_views(&mut self, views: &[ViewSpec], camera: &Camera, vpl_ok: bool) {
        let device = self.ctx.device.clone();
        let queue = self.ctx.queue.clone();
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
            self.record_view_with_overlays(&mut enc, spec, camera, vpl_ok);
            std::mem::swap(&mut self.targets.view, &mut self.extra_views[i - 1]);
            queue.submit([enc.finish()]);
        }
    }

    /// The frame's end: the timestamps resolved and submitted, every readback and method told
    /// of the submission, the frame counted.
    pub(super) fn finish_frame(&mut self, diagnostic: bool, vpl_ok: bool) {
        let device = self.ctx.device.clone();
        let queue = self.ctx.queue.clone();
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
}

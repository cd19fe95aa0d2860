//! The tree samplers' frame: `Method` for [`TreeSamplers`] (traversal and shading at full or half
//! resolution, the diagnostics, views, pixel story, overlay and statistics).

use super::settings::SamplingSettings;
use super::*;

impl Method for TreeSamplers {
    /// One frame; returns 1 / the frames summed in the accumulation (1 unless
    /// `frame.accumulate` and nothing changed).
    fn record(&mut self, cx: &mut FrameCx<'_>, enc: &mut wgpu::CommandEncoder) -> f32 {
        let s = cx.settings;
        let sm = &SamplingSettings::of(s);
        let device = cx.device;
        let size = cx.size;
        // Half-resolution GI: the sampler runs on every other G-buffer sample (demodulated)
        // and is upsampled into the full-resolution accumulation afterwards.
        let half = sm.half_resolution;
        let gi_size = if half { HalfTargets::half_size(size) } else { size };
        if !self.fit_buffers(cx, enc, gi_size) {
            return 1.0;
        }
        let d_max = s.vpl.d_max * cx.scene_radius;
        let half_targets = self.record_downsample(cx, enc, gi_size, d_max);
        // Accumulate while nothing changes (the key also covers the method and its settings);
        // a frozen tree keeps its VPLs, otherwise new VPLs average in too.
        let key = cx.key;
        if half && self.state.is_none_or(|(k, _)| k != key || !s.frame.accumulate) {
            // The half-resolution sum restarts with the accumulation.
            if let Some(h) = &half_targets {
                enc.clear_buffer(&h.accum, 0, None);
            }
        }
        let frames = match self.state {
            Some((k, n)) if s.frame.accumulate && k == key => n + 1,
            _ => 1,
        };
        self.state = Some((key, frames));
        // Interleaved sampling: the sampler writes its frame's demodulated estimate into
        // `raw`, the filter then averages the pattern into the accumulation.
        let il = &sm.interleave;
        let filtered = il.filters();
        self.fit_raw(device, filtered, gi_size);
        let seed = if s.frame.fixed_seed {
            s.vpl.seed
        } else {
            s.vpl.seed ^ (cx.frame_index as u32).wrapping_mul(0x9e37_79b9)
        };
        let grid = self.buffers.grid;
        let ism_maps = self.plan_ism(cx);
        let p = GpuSlcParams {
            width: gi_size.0,
            height: gi_size.1,
            block: sm.block_size,
            grid_x: grid.0,
            grid_y: grid.1,
            cut_size: sm.cut_size,
            leaves: cx.tree.leaves,
            levels: cx.tree.levels(),
            method: if cx.method == SST {
                1
            } else if cx.method == RTSLC {
                2
            } else {
                0
            },
            blending: match sm.blending {
                CutBlending::Stochastic => 0,
                CutBlending::Off => 1,
            },
            fallback: match sm.fallback {
                CutFallback::MockCut => 0,
                CutFallback::Average => 1,
                CutFallback::Root => 2,
                CutFallback::Recompute => 3,
            },
            cull: sm.cull_behind as u32,
            seed,
            accumulate: (frames > 1 && !filtered) as u32,
            epsilon: s.gi.distance_epsilon,
            ray_offset: s.gi.ray_offset,
            n_min: s.vpl.n_min,
            d_max,
            demodulate: (half || filtered) as u32,
            trace_pixel: match cx.trace_pixel {
                // In GI pixels (half resolution: the GI pixel covering it).
                Some((x, y)) if half => (x / 2) | (y / 2) << 16,
                Some((x, y)) => x | y << 16,
                None => u32::MAX,
            },
            near_field: sm.near_field,
            shadow_rays: if ism_maps.is_some() {
                2
            } else {
                s.gi.shadow_rays as u32
            },
            substitute_offset: sm.substitute_offset,
            child_probability: match sm.child_probability {
                ChildProbability::Mean => 0,
                ChildProbability::MinMax => 1,
                ChildProbability::Defensive => 2,
            },
            interleave: il.n,
            interleave_offset: Interleave::offset_of(il.n, seed),
            radix: (cx.tree.kind == TreeKind::Lbvh) as u32,
            brdf: cx.brdf.gpu(),
            glossy_material: sm.glossy_weights.gpu(),
            _pad: [0; 3],
            eye: cx.eye.extend(0.0).to_array(),
        };
        // A timed frame leaves the last diagnostic frame's story (and statistics) in place.
        if cx.diagnostics {
            self.traced = cx.trace_pixel.is_some();
        }
        let (gbuffer, accum) = match &half_targets {
            Some(h) => (&h.gbuffer, &h.accum),
            None => (&cx.targets.gbuffer, cx.gi_accum),
        };
        let raw = self.raw.as_ref().map(|(b, _)| b);
        let ism = match (ism_maps, self.ism_points.as_ref(), self.ism_targets.as_ref()) {
            (Some(maps), Some((_, points)), Some(targets)) => Some(pass::SlcIsm {
                settings: &SamplingSettings::of(s).ism,
                points,
                targets,
                maps,
            }),
            _ => None,
        };
        let inputs = pass::SlcInputs {
            diagnostics: cx.diagnostics,
            params: p,
            tree: cx.tree,
            scene: cx.scene,
            gbuffer,
            accum: raw.unwrap_or(accum),
            out: &self.buffers,
            ism: ism.as_ref(),
        };
        self.pass.record(device, cx.queue, enc, cx.timer, inputs);
        if let Some(raw) = raw {
            self.record_filter(cx, enc, half_targets.as_ref(), gi_size, frames, raw);
        }
        if let Some(h) = half_targets {
            self.half_pass.record_upsample(cx, enc, &h);
            self.half = Some(h);
        }
        1.0 / frames.max(1) as f32
    }

    fn after_submit(&mut self) {
        self.pass.stats.after_submit();
    }

    fn frames_averaged(&self) -> Option<u32> {
        Some(self.frames())
    }

    /// The diagnostics are drawn at the GI resolution (full or half).
    fn view_size(&self, _view: MethodView, frame: (u32, u32)) -> Option<(u32, u32)> {
        let b = &self.buffers;
        let scale = frame.0.div_ceil(b.size.0.max(1));
        // No tree-sampling frame at this size yet: nothing to show.
        (scale != 0 && b.size.0 * scale >= frame.0 && scale <= 2).then_some(b.size)
    }

    fn record_view(&mut self, view: MethodView, cx: &mut ViewCx<'_>, enc: &mut wgpu::CommandEncoder) {
        let b = &self.buffers;
        let scale = cx.targets.size.0.div_ceil(b.size.0.max(1));
        let p = GpuSlcViewParams {
            mode: if view == STEPS {
                0
            } else if view == FALLBACK {
                1
            } else if view == CUT_BLOCKS {
                2
            } else {
                3
            },
            grid_x: b.grid.0,
            block: b.block,
            cut_size: b.cut_size,
            exposure: cx.look.exposure_ev.exp2(),
            tonemap: cx.look.tonemap.gpu_id(),
            max_steps: steps_scale(cx.tree.levels()),
            levels: cx.tree.levels(),
            selected: cx.selected_block.map_or(0, |b| b + 1),
            final_scale: scale,
            radix: (cx.tree.kind == TreeKind::Lbvh) as u32,
            leaves: cx.tree.leaves,
        };
        let tree = cx.tree;
        self.pass.record_view(cx, enc, p, b, &tree.links);
    }

    /// The per-pixel diagnostics (steps per traversal, fell back, samples, 1 + block) at the
    /// GI resolution, whichever of the views asks.
    fn read_view(&self, ctx: &GpuContext, _view: MethodView) -> Result<Option<ImageF32>, GpuError> {
        readback::read_vec4_image(ctx, &self.buffers.diag, self.buffers.size)
    }

    fn read_story(&self, ctx: &GpuContext) -> Result<Option<Story>, GpuError> {
        if !self.traced {
            return Ok(None);
        }
        let bytes = readback::read_storage_buffer(ctx, &self.buffers.trace)?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        Ok(pass::parse_trace(&words).map(|t| {
            Story::Samples(PixelTrace {
                filtered: self.raw.is_some(),
                ..t
            })
        }))
    }

    fn pixel_rows(
        &self,
        ctx: &GpuContext,
        x: u32,
        y: u32,
        frame: (u32, u32),
    ) -> Result<Vec<(&'static str, [f32; 4])>, GpuError> {
        let b = &self.buffers;
        let scale = frame.0.div_ceil(b.size.0.max(1)).max(1);
        let (dx, dy) = (x / scale, y / scale);
        if dx >= b.size.0 || dy >= b.size.1 {
            return Ok(Vec::new());
        }
        let d = readback::read_vec4_pixel(ctx, &b.diag, b.size.0, dx, dy)?;
        Ok(vec![("sampling (steps, fallback, samples, 1 + block)", d)])
    }

    fn legend(&self, view: MethodView, tree_levels: u32) -> Option<Legend> {
        let hi = steps_scale(tree_levels);
        if view == STEPS {
            let title = match self.pass.stats.last() {
                Some(st) => format!(
                    "traversal steps per traversal (image mean {:.2})",
                    st.steps_per_traversal()
                ),
                None => "traversal steps per traversal".to_string(),
            };
            Some(Legend {
                title,
                lo: 0.0,
                hi,
                log: false,
            })
        } else if view == CUT_DEPTH {
            Some(Legend {
                title: "mean cut node depth (root = 0)".into(),
                lo: 0.0,
                hi,
                log: false,
            })
        } else {
            None
        }
    }

    fn traversal_stats(&mut self) -> Option<crate::base::traversal::TraversalStats> {
        self.poll_stats()
    }

    /// The diagnostics buffer's steps (word 0) and fallback flag (word 1) per pixel.
    fn read_traversal_pixels(
        &self,
        ctx: &GpuContext,
    ) -> Result<Option<crate::base::traversal::TraversalPixels>, GpuError> {
        let bytes = crate::gpu::readback::read_storage_buffer(ctx, &self.buffers.diag)?;
        let diag: &[f32] = bytemuck::cast_slice(&bytes);
        let steps = diag.chunks_exact(4).map(|d| d[0]).collect();
        let fallback = diag.chunks_exact(4).map(|d| d[1] > 0.5).collect();
        Ok(Some(crate::base::traversal::TraversalPixels { steps, fallback }))
    }

    /// The cut views show the blocks: a texel's block and its cut.
    fn pick_block(
        &self,
        ctx: &GpuContext,
        view: MethodView,
        (px, py): (u32, u32),
    ) -> Result<Option<crate::base::story::BlockCut>, GpuError> {
        if view != CUT_BLOCKS && view != CUT_DEPTH {
            return Ok(None);
        }
        let b = &self.buffers;
        let k = b.block.max(1);
        let (bx, by) = (px / k, py / k);
        let index = by * b.grid.0 + bx;
        Ok(Some(crate::base::story::BlockCut {
            index,
            block: (bx, by),
            nodes: self.read_cut(ctx, index)?,
        }))
    }

    fn status(&mut self) -> Option<String> {
        let st = self.pass.stats.poll()?;
        Some(format!(
            "{:.2} steps per traversal · {:.1} per pixel · {:.2}% pixels without a similar cut · {} dead branches",
            st.steps_per_traversal(),
            st.steps_per_pixel(),
            100.0 * st.fallback_fraction(),
            st.dead
        ))
    }
}

impl TreeSamplers {
    /// Sizes the sampler's buffers for the GI resolution `gi_size`. False (reported, the
    /// accumulation cleared, the history dropped) when they exceed the device's binding size.
    fn fit_buffers(
        &mut self,
        cx: &mut FrameCx<'_>,
        enc: &mut wgpu::CommandEncoder,
        gi_size: (u32, u32),
    ) -> bool {
        let sm = &SamplingSettings::of(cx.settings);
        let device = cx.device;
        if self.buffers.matches(gi_size, sm.block_size, sm.cut_size) {
            return true;
        }
        let need = SlcBuffers::largest_binding(gi_size, sm.block_size, sm.cut_size);
        let limit = device.limits().max_storage_buffer_binding_size;
        if need > limit {
            // Refuse (once per change) rather than fail validation; GI stays black.
            cx.errors.report(format!(
                "sampling: {}x{} pixels with {}x{} blocks and cuts of {} need a {} MiB buffer; \
                 this device binds at most {} MiB (raise methods.slc.block_size or lower cut_size)",
                gi_size.0,
                gi_size.1,
                sm.block_size,
                sm.block_size,
                sm.cut_size,
                need >> 20,
                limit >> 20
            ));
            enc.clear_buffer(cx.gi_accum, 0, None);
            self.state = None;
            return false;
        }
        self.buffers = SlcBuffers::new(device, gi_size, sm.block_size, sm.cut_size);
        true
    }

    /// Half-resolution GI: the half-resolution targets of the frame (kept from the last frame
    /// at the same size), with the G-buffer downsampled into them; None at full resolution.
    fn record_downsample(
        &mut self,
        cx: &mut FrameCx<'_>,
        enc: &mut wgpu::CommandEncoder,
        gi_size: (u32, u32),
        d_max: f32,
    ) -> Option<HalfTargets> {
        let s = cx.settings;
        let device = cx.device;
        let size = cx.size;
        if SamplingSettings::of(s).half_resolution {
            let h = match self.half.take() {
                Some(h) if h.size == gi_size => h,
                _ => HalfTargets::new(device, size),
            };
            self.half_pass.record_downsample(cx, enc, &h, s.vpl.n_min, d_max);
            Some(h)
        } else {
            self.half = None;
            None
        }
    }

    /// The interleaved sampler's per-frame estimate (`raw`) at the GI resolution while the
    /// interleave pattern is filtered.
    fn fit_raw(&mut self, device: &wgpu::Device, filtered: bool, gi_size: (u32, u32)) {
        if !filtered {
            self.raw = None;
        } else if self.raw.as_ref().is_none_or(|(_, sz)| *sz != gi_size) {
            let bytes = 16 * gi_size.0 as u64 * gi_size.1 as u64;
            self.raw = Some((
                crate::gpu::passes::storage_buffer(device, "slc::interleaved_raw", bytes),
                gi_size,
            ));
        }
    }

    /// The interleave filter: the demodulated estimate `raw`'s mean over the pattern, x albedo
    /// (at half resolution it stays demodulated: the upsampler applies the full-resolution
    /// albedo), into the accumulation (`half`'s at half resolution).
    fn record_filter(
        &self,
        cx: &mut FrameCx<'_>,
        enc: &mut wgpu::CommandEncoder,
        half: Option<&HalfTargets>,
        gi_size: (u32, u32),
        frames: u32,
        raw: &wgpu::Buffer,
    ) {
        let (gbuffer, accum) = match half {
            Some(h) => (&h.gbuffer, &h.accum),
            None => (&cx.targets.gbuffer, cx.gi_accum),
        };
        let fp = GpuFilterParams {
            accumulate: (frames > 1) as u32,
            modulate: half.is_none() as u32,
            ..GpuFilterParams::new(gi_size, &SamplingSettings::of(cx.settings).interleave)
        };
        let inputs = FilterInputs {
            gbuffer,
            camera: cx.camera,
            raw,
            accum,
        };
        self.filter.record(
            cx.device,
            cx.queue,
            enc,
            cx.timer,
            FilterDispatch {
                name: "slc_filter",
                uniform: &self.filter_params,
                params: fp,
            },
            &inputs,
        );
    }
}

//! Lightcut Interpolation's frame: `Method` for [`LightcutInterpolation`] (the cuts at the tile
//! corners, interpolation and its refinements, the views, pixel rows, story and statistics).

use super::*;

impl Method for LightcutInterpolation {
    fn record(&mut self, cx: &mut FrameCx<'_>, enc: &mut wgpu::CommandEncoder) -> f32 {
        let s = cx.settings;
        let li: LightcutInterpolationSettings = s.method(cx.method).unwrap_or_default();
        if self.pass.is_none() {
            match LiPass::new(cx.device) {
                Ok(p) => self.pass = Some(p),
                Err(e) => {
                    cx.errors.report(format!("lightcut interpolation: {e}"));
                    enc.clear_buffer(cx.gi_accum, 0, None);
                    return 1.0;
                }
            }
            self.steps = (
                steps_per_dispatch(cx.adapter_type),
                walk_steps_per_dispatch(cx.adapter_type),
            );
        }
        let leaves = cx.tree.leaves;
        let max_cut = li.max_cut.clamp(1, MAX_CUT);
        let split = self.steps.1 != u32::MAX;
        if !self
            .buffers
            .as_ref()
            .is_some_and(|b| b.matches(leaves, cx.size, max_cut, split))
        {
            let need = LiBuffers::largest_binding(leaves, cx.size, split);
            let limit = cx.device.limits().max_storage_buffer_binding_size;
            if need > limit {
                cx.errors.report(format!(
                    "lightcut interpolation: {}x{} pixels and {leaves} leaves need a {} MiB \
                     buffer; this device binds at most {} MiB",
                    cx.size.0,
                    cx.size.1,
                    need >> 20,
                    limit >> 20
                ));
                enc.clear_buffer(cx.gi_accum, 0, None);
                self.state = None;
                return 1.0;
            }
            self.buffers = Some(LiBuffers::new(
                cx.device,
                leaves,
                cx.size,
                max_cut,
                SCRATCH_BUDGET.min(limit),
                limit,
                split,
            ));
        }
        let (Some(pass), Some(b)) = (self.pass.as_mut(), self.buffers.as_ref()) else {
            return 1.0;
        };
        let frames = match self.state {
            Some((k, n)) if s.frame.accumulate && k == cx.key => n + 1,
            _ => 1,
        };
        self.state = Some((cx.key, frames));
        let trace_pixel = match cx.trace_pixel {
            Some((x, y)) => x | y << 16,
            None => u32::MAX,
        };
        let p = GpuLiParams {
            width: cx.size.0,
            height: cx.size.1,
            tiles_x: b.tiles.0,
            tiles_y: b.tiles.1,
            leaves,
            levels: leaves.trailing_zeros(),
            max_cut,
            capacity: b.capacity,
            r_min_px: li.r_min_px,
            r_max_px: li.r_max_px,
            one_minus_cos_max: 1.0 - li.max_angle_deg.to_radians().cos(),
            epsilon: li.epsilon,
            coverage: li.coverage,
            radius_rays: li.radius_rays,
            ray_offset: s.gi.ray_offset,
            shadow_rays: s.gi.shadow_rays as u32,
            interp_visibility: (li.visibility == LiVisibility::Interpolated) as u32,
            accumulate: (frames > 1) as u32,
            trace_pixel,
            steps: self.steps.1,
            first: 1,
            last: 1,
            distance_epsilon: s.gi.distance_epsilon,
            _pad: 0,
        };
        let lc = GpuLcParams {
            width: cx.size.0,
            height: cx.size.1,
            leaves,
            max_cut,
            relative_error: li.relative_error,
            epsilon: s.gi.distance_epsilon,
            ray_offset: s.gi.ray_offset,
            shadow_rays: s.gi.shadow_rays as u32,
            accumulate: (frames > 1) as u32,
            trace_pixel: u32::MAX,
            first_pixel: 0,
            slice: 0,
            first: 1,
            last: 1,
            steps: self.steps.0,
            radix: 0,
            brdf: 0,
            _pad: [0; 3],
            eye: [0.0; 4],
        };
        if cx.diagnostics {
            self.traced = cx.trace_pixel.is_some();
        }
        if cx.diagnostics {
            // (Timed frames trace nothing: the view keeps the last diagnostic frame's pin.)
            self.pinned = cx
                .trace_pixel
                .filter(|&(x, y)| x < cx.size.0 && y < cx.size.1)
                .map(|(x, y)| y * cx.size.0 + x);
        }
        if li != self.settings {
            pass.stats.clear();
        }
        self.settings = li;
        let seed = Lightcuts::seed(s, cx.frame_index);
        pass.record(cx, enc, p, lc, seed, b);
        1.0 / frames as f32
    }

    fn after_submit(&mut self) {
        if let Some(p) = &self.pass {
            p.stats.after_submit();
        }
    }

    fn frames_averaged(&self) -> Option<u32> {
        Some(self.state.map_or(0, |(_, n)| n))
    }

    fn reset(&mut self) {
        self.state = None;
    }

    fn view_size(&self, _view: MethodView, frame: (u32, u32)) -> Option<(u32, u32)> {
        (self.buffers.as_ref()?.size == frame && self.state.is_some()).then_some(frame)
    }

    fn record_view(&mut self, view: MethodView, cx: &mut ViewCx<'_>, enc: &mut wgpu::CommandEncoder) {
        let (Some(pass), Some(b)) = (self.pass.as_ref(), self.buffers.as_ref()) else {
            return;
        };
        let mode = [RECORDS, WEIGHTS, FALLBACK, CUT_SIZE, LEVEL_SPREAD]
            .iter()
            .position(|v| *v == view)
            .unwrap_or(0) as u32;
        let p = GpuLiViewParams {
            mode,
            scale_top: 10u32.pow(decades(self.settings.max_cut)),
            r_min_px: self.settings.r_min_px,
            r_max_px: self.settings.r_max_px,
            exposure: cx.look.exposure_ev.exp2(),
            tonemap: cx.look.tonemap.gpu_id(),
            tiles_x: b.tiles.0,
            tiles_y: b.tiles.1,
            pinned: self.pinned.unwrap_or(u32::MAX),
            _pad: [0; 3],
        };
        pass.record_view(cx, enc, p, b);
    }

    /// The pinned pixel: its records (pixel, weight, cut), the interpolated cut, and where
    /// the records' cuts disagree.
    fn read_story(&self, ctx: &GpuContext) -> Result<Option<Story>, GpuError> {
        let Some(b) = &self.buffers else { return Ok(None) };
        let Some(t) = self.read_traced(ctx)? else {
            return Ok(None);
        };
        let word = |buf: &wgpu::Buffer, i: u64| -> Result<u32, GpuError> {
            let bytes = readback::read_buffer_range(ctx, buf, 4 * i, 4)?;
            Ok(bytemuck::pod_read_unaligned(&bytes[..4]))
        };
        let levels = b.leaves.trailing_zeros();
        let mut story = CutStory::default();
        let px = |k: u32| (k % b.size.0, k / b.size.0);
        let (x, y) = px(t.pixel);
        story.rows.push(("pixel".into(), format!("({x}, {y})")));
        let mut cuts = Vec::new();
        for (i, (&r, &w)) in t.records.iter().zip(&t.weights).enumerate() {
            let pixel = word(&b.records, r as u64)?;
            let len = word(&b.rec_meta, 8 + r as u64)?.min(b.max_cut);
            let bytes = readback::read_buffer_range(
                ctx,
                &b.record_cuts,
                4 * r as u64 * b.max_cut as u64,
                4 * len.max(1) as u64,
            )?;
            let cut: Vec<u32> = bytemuck::pod_collect_to_vec::<u8, u32>(&bytes)
                .into_iter()
                .take(len as usize)
                .collect();
            let (rx, ry) = px(pixel);
            let visible = cut
                .iter()
                .filter(|&&e| e & crate::reference::lightcut_interpolation::VISIBLE != 0)
                .count();
            story.rows.push((
                format!("record {}", i + 1),
                format!("#{r} at ({rx}, {ry}), weight {w:.3}, cut {len} nodes ({visible} visible)"),
            ));
            story.inputs.push(StoryCut {
                label: format!("record #{r} (w {w:.2})"),
                nodes: cut
                    .iter()
                    .map(|e| e & !crate::reference::lightcut_interpolation::VISIBLE)
                    .collect(),
            });
            cuts.push(cut);
        }
        let refs: Vec<&[u32]> = cuts.iter().map(|c| c.as_slice()).collect();
        story.disagreements = crate::reference::lightcut_interpolation::disagreements(&refs, levels);
        let span: u32 = story.disagreements.iter().map(|(s, e)| e - s).sum();
        story.rows.push((
            "inputs disagree".into(),
            format!(
                "on {span} of {} leaves (level spread {:.2})",
                b.leaves, t.level_spread
            ),
        ));
        story.rows.push((
            "interpolated cut".into(),
            format!(
                "{} nodes, {} walk steps, {} shadow rays ({})",
                t.nodes.len(),
                t.walk_steps,
                t.shadow_rays,
                self.settings.visibility.label()
            ),
        ));
        story.cut = Some(StoryCut {
            label: format!("interpolated ({} nodes)", t.nodes.len()),
            nodes: t.nodes.iter().map(|n| n.0).collect(),
        });
        Ok(Some(Story::Cuts(story)))
    }

    /// Per pixel: cut size, level spread (-1: fallback), records used, shadow rays.
    fn read_view(&self, ctx: &GpuContext, _view: MethodView) -> Result<Option<ImageF32>, GpuError> {
        let Some(b) = &self.buffers else { return Ok(None) };
        if self.state.is_none() {
            return Ok(None);
        }
        readback::read_vec4_image(ctx, &b.diag, b.size)
    }

    fn pixel_rows(
        &self,
        ctx: &GpuContext,
        x: u32,
        y: u32,
        frame: (u32, u32),
    ) -> Result<Vec<(&'static str, [f32; 4])>, GpuError> {
        let Some(b) = &self.buffers else {
            return Ok(Vec::new());
        };
        if b.size != frame || x >= frame.0 || y >= frame.1 || self.state.is_none() {
            return Ok(Vec::new());
        }
        let k = y as u64 * b.size.0 as u64 + x as u64;
        let d = readback::read_vec4_pixel(ctx, &b.diag, b.size.0, x, y)?;
        let sel: [u32; 8] =
            bytemuck::pod_read_unaligned(&readback::read_buffer_range(ctx, &b.sel, k * 32, 32)?[..32]);
        let w = |i: usize| f32::from_bits(sel[i]);
        Ok(vec![
            (
                "LI cut (size, level spread or -1 = fallback, records, shadow rays)",
                d,
            ),
            (
                "LI records (ids)",
                [sel[0] as f32, sel[1] as f32, sel[2] as f32, sel[3] as f32],
            ),
            ("LI weights (3, best raw)", [w(4), w(5), w(6), w(7)]),
        ])
    }

    fn legend(&self, view: MethodView, _tree_levels: u32) -> Option<Legend> {
        let st = self.pass.as_ref()?.stats.last();
        if view == CUT_SIZE {
            Some(Legend {
                title: match st {
                    Some(st) => format!("cut size (image mean {:.1})", st.mean_cut()),
                    None => "cut size".into(),
                },
                lo: 0.0,
                hi: decades(self.settings.max_cut) as f32,
                log: true,
            })
        } else if view == LEVEL_SPREAD {
            Some(Legend {
                title: "input cut level spread (levels)".into(),
                lo: 0.0,
                hi: 4.0,
                log: false,
            })
        } else if view == FALLBACK {
            st.map(|st| Legend {
                title: format!("fallback {:.2}% of pixels", 100.0 * st.fallback_fraction()),
                lo: 0.0,
                hi: 1.0,
                log: false,
            })
        } else {
            None
        }
    }

    fn stats(&mut self) -> Vec<(&'static str, f64)> {
        match self.poll_stats() {
            Some(st) => vec![
                ("records", st.records as f64),
                ("records_per_pixel", st.records_per_pixel()),
                ("mean_record_cut_size", st.mean_record_cut()),
                ("mean_cut_size", st.mean_cut()),
                ("shadow_rays_per_pixel", st.rays_per_pixel()),
                (
                    "interpolation_rays_per_pixel",
                    st.shadow_rays as f64 / st.pixels().max(1) as f64,
                ),
                ("fallback_pixel_fraction", st.fallback_fraction()),
                ("dropped_records", st.dropped_records as f64),
                ("unfinished_walks", st.unfinished as f64),
                ("relative_error", self.settings.relative_error as f64),
                ("r_max_px", self.settings.r_max_px as f64),
                (
                    "interpolated_visibility",
                    (self.settings.visibility == LiVisibility::Interpolated) as u32 as f64,
                ),
            ],
            None => Vec::new(),
        }
    }

    fn status(&mut self) -> Option<String> {
        let st = self.poll_stats()?;
        let dropped = if st.dropped_records > 0 {
            format!(" · {} records dropped (memory)", st.dropped_records)
        } else {
            String::new()
        };
        Some(format!(
            "{} records ({:.2}% of pixels, cuts of {:.0}) · cut {:.1} nodes per pixel · {:.1} shadow rays per pixel · fallback {:.2}%{dropped}",
            st.records,
            100.0 * st.records_per_pixel(),
            st.mean_record_cut(),
            st.mean_cut(),
            st.rays_per_pixel(),
            100.0 * st.fallback_fraction()
        ))
    }
}

//! The VAL methods' frame: `Method` for [`Vals`] (clustering, the ISMs, the VALs' shading, its
//! views, pixel rows, overlay, legends and statistics).

use super::*;

impl Method for Vals {
    fn record(&mut self, cx: &mut FrameCx<'_>, enc: &mut wgpu::CommandEncoder) -> f32 {
        let s = cx.settings;
        let vs: ValSettings = s.method(ID).unwrap_or_default();
        self.scene_radius = cx.scene_radius;
        self.ray_offset = s.gi.ray_offset;
        // Without a light there is no RSM and no indirect light.
        let Some(rsm) = cx.rsm else {
            return self.fail(cx, enc, None);
        };
        // The clustering RSM: light 0's summed down by `factor`.
        let res = vs.resolution.min(rsm.res).max(1);
        let factor = (rsm.res / res).max(1);
        self.fit_targets(cx, &vs, res);
        let frames = match self.state {
            Some((k, m, n)) if s.frame.accumulate && k == cx.key && m == cx.method => n + 1,
            _ => 1,
        };
        let visibility = visibility_of(s, &vs);
        let maps_shown = cx.diagnostics && (cx.views.contains(&ISM_ATLAS) || cx.views.contains(&ISM_TRUE));
        let build = visibility == VIS_ISM || visibility == VIS_PCSS || maps_shown;
        self.ism_maps = 0;
        if build && let Err(e) = self.ensure_ism(cx, &vs) {
            return self.fail(cx, enc, Some(e));
        }
        let n = vs.interleave.n.max(1);
        let p = GpuValShadeParams {
            width: cx.size.0,
            height: cx.size.1,
            n,
            offset: Self::offset(s, n, cx.frame_index),
            clusters: vs.clusters,
            as_point: (cx.method == VPL) as u32,
            visibility,
            count: cx.vpl_frame.count.min(cx.vpl_buffers.capacity),
            eps: s.gi.distance_epsilon,
            ray_offset: s.gi.ray_offset,
            blocker_samples: vs.pcss.blocker_samples,
            pcf_samples: vs.pcss.pcf_samples,
            max_radius: vs.pcss.max_radius,
            res: rsm.res,
            layer: 0,
            inspect: vs.inspect.min(vs.clusters.saturating_sub(1)),
            factor,
            _pad: [0; 3],
        };
        let cp = GpuValParams {
            area_mode: 1,
            ..GpuValParams::new(
                rsm.view_proj,
                rsm.direction,
                rsm.texel * factor as f32,
                res,
                0,
                &vs.cluster_params(),
            )
        };
        let down = GpuDownParams {
            res,
            factor,
            layer: 0,
            _pad: 0,
            light_dir: rsm.direction.to_array(),
            texel_area: rsm.texel * rsm.texel,
        };
        let fp = GpuFilterParams {
            accumulate: (frames > 1) as u32,
            scale: std::f32::consts::FRAC_1_PI,
            period: if vs.paper_filter { n } else { 0 },
            ..GpuFilterParams::new(cx.size, &vs.interleave)
        };
        let (frame_targets, vpl_buffers) = (cx.targets, cx.vpl_buffers);
        let shadow = &frame_targets.shadow;
        let (Some(coarse), Some((_, seed_list))) = (self.coarse.as_ref(), self.seed_list.as_ref()) else {
            return 0.0;
        };
        let ism = match (build, self.ism_points.as_ref(), self.ism_targets.as_ref()) {
            (true, Some((_, points)), Some(targets)) => Some(ValIsm {
                settings: &vs.ism,
                points,
                targets,
            }),
            _ => None,
        };
        let f = ValFrame {
            coarse,
            seed_list,
            down,
            scene: cx.scene,
            gbuffer: &frame_targets.gbuffer,
            camera: cx.camera,
            vpls: &vpl_buffers.vpls,
            accum: cx.gi_accum,
            rsm: [&shadow.position_array, &shadow.normal_array, &shadow.flux_array],
            ism: ism.as_ref(),
        };
        let Some(t) = self.targets.as_mut() else {
            return 0.0;
        };
        let built = ism.is_some();
        let frame = ValRecordParams {
            shade: p,
            cluster: cp,
            iterations: vs.iterations,
            carry: vs.carry_over,
            filter: fp,
        };
        let r = self.pass.record(cx, enc, frame, &f, &self.buffers, t);
        if let Err(e) = r {
            return self.fail(cx, enc, Some(e));
        }
        if cx.diagnostics
            && let Some(st) = self.stats.as_mut()
        {
            let bytes = t.clusters as u64 * std::mem::size_of::<GpuVal>() as u64;
            st.record(enc, &[(t.vals(), 0, 0, bytes)]);
        }
        self.ism_maps = if built { vs.clusters } else { 0 };
        self.visibility = visibility;
        self.state = Some((cx.key, cx.method, frames));
        self.settings = vs;
        1.0 / frames as f32
    }

    fn after_submit(&mut self) {
        if let Some(st) = self.stats.as_ref() {
            st.after_submit();
        }
    }

    fn frames_averaged(&self) -> Option<u32> {
        Some(self.state.map_or(0, |(_, _, n)| n))
    }

    fn reset(&mut self) {
        self.state = None;
        if let Some(t) = self.targets.as_mut() {
            t.unprime();
        }
    }

    fn view_size(&self, view: MethodView, frame: (u32, u32)) -> Option<(u32, u32)> {
        self.state?;
        if view == CLUSTERS {
            return self.targets.as_ref().map(|t| (t.res, t.res));
        }
        if view == ISM_ATLAS || view == ISM_TRUE {
            let (t, _) = self.ism()?;
            if view == ISM_TRUE {
                return Some((2 * t.layout.tile + GAP, t.layout.tile));
            }
        }
        (self.buffers.size == frame).then_some(frame)
    }

    fn record_view(&mut self, view: MethodView, cx: &mut ViewCx<'_>, enc: &mut wgpu::CommandEncoder) {
        let Some(size) = self.view_size(view, self.buffers.size) else {
            return;
        };
        self.data_buffer(cx.device, view, size);
        let Some((_, data)) = self.view_data.get(view.name()) else {
            return;
        };
        let ism = self.ism_targets.as_ref().filter(|_| self.ism_maps > 0);
        if view == ISM_ATLAS {
            if let Some(t) = ism {
                let v = crate::gpu::passes::ism::IsmView {
                    maps: self.ism_maps,
                    range: self.depth_range(),
                    size,
                    dst: cx.dst,
                    data,
                };
                self.pass
                    .ism
                    .record_view(cx.device, cx.queue, enc, cx.timer, t, &v);
            }
            return;
        }
        let Some(t) = self.targets.as_ref() else {
            return;
        };
        let (lo, hi) = if view == PENUMBRA {
            self.penumbra_range()
        } else {
            self.depth_range()
        };
        let p = GpuValViewParams {
            mode: if view == CLUSTERS {
                0
            } else if view == DISKS {
                1
            } else if view == PENUMBRA {
                2
            } else {
                3
            },
            clusters: self.settings.clusters.min(t.clusters),
            exposure: cx.look.exposure_ev.exp2(),
            tonemap: cx.look.tonemap.gpu_id(),
            lo,
            hi,
            inspect: self.settings.inspect.min(t.clusters.saturating_sub(1)),
            gap: GAP,
            ray_offset: self.ray_offset,
            res: t.res,
            _pad: [0; 2],
        };
        let inputs = pass::ValViewInputs {
            params: p,
            size,
            buffers: &self.buffers,
            targets: t,
            ism: ism.map(|it| (it, &self.settings.ism, self.ism_maps)),
            data,
        };
        self.pass.record_view(cx, enc, inputs);
    }

    fn read_view(&self, ctx: &GpuContext, view: MethodView) -> Result<Option<ImageF32>, GpuError> {
        if self.state.is_none() {
            return Ok(None);
        }
        match self.view_data.get(view.name()) {
            Some((size, data)) => readback::read_vec4_image(ctx, data, *size),
            None => Ok(None),
        }
    }

    fn legend(&self, view: MethodView, _tree_levels: u32) -> Option<Legend> {
        if view == ISM_ATLAS || view == ISM_TRUE {
            let (lo, hi) = self.depth_range();
            let tile = self.ism_targets.as_ref().map_or(0, |t| t.layout.tile);
            let title = if self.ism_maps == 0 {
                "no maps this frame (visibility by rays or none and the view not drawn yet, or \
                 refused: see the problems window)"
                    .to_string()
            } else if view == ISM_TRUE {
                format!(
                    "distance from VAL {} (m): its {tile}^2 map (left) and the traced one (right); \
                     black: hole / nothing hit",
                    self.settings
                        .inspect
                        .min(self.settings.clusters.saturating_sub(1))
                )
            } else {
                format!(
                    "distance from the VAL (m; {} maps of {tile}^2; dim: filled by pull-push; black: hole)",
                    self.ism_maps
                )
            };
            return Some(Legend {
                title,
                lo: lo.log10(),
                hi: hi.log10(),
                log: true,
            });
        }
        if view == PENUMBRA {
            let (lo, hi) = self.penumbra_range();
            return Some(Legend {
                title: if self.visibility == VIS_PCSS {
                    "PCSS penumbra width on the receiver (m, eq. 3)".into()
                } else {
                    "no PCSS lookups this frame (visibility is not pcss)".into()
                },
                lo: lo.log10(),
                hi: hi.log10(),
                log: true,
            });
        }
        None
    }

    fn pixel_rows(
        &self,
        ctx: &GpuContext,
        x: u32,
        y: u32,
        frame: (u32, u32),
    ) -> Result<Vec<(&'static str, [f32; 4])>, GpuError> {
        let b = &self.buffers;
        if b.size != frame || x >= frame.0 || y >= frame.1 || self.state.is_none() {
            return Ok(Vec::new());
        }
        let d = readback::read_vec4_pixel(ctx, &b.diag, b.size.0, x, y)?;
        Ok(vec![(
            "VAL (penumbra width m, lookups with blockers, VALs lighting it, -)",
            d,
        )])
    }

    fn status(&mut self) -> Option<String> {
        let st = self.stats.as_ref()?.last()?;
        let vis = match self.visibility {
            VIS_RAYS => "shadow rays",
            VIS_ISM => "ISM lookups",
            VIS_PCSS => "PCSS lookups",
            VIS_DISK => "rays to the disks",
            _ => "no visibility",
        };
        Some(format!(
            "{} of {} VALs lit · mean disk radius {:.3} m · {:.3} W · {vis}",
            st.lit, st.clusters, st.mean_radius, st.flux
        ))
    }

    fn stats(&mut self) -> Vec<(&'static str, f64)> {
        let Some(st) = self.stats.as_mut().and_then(|s| s.poll()) else {
            return Vec::new();
        };
        vec![
            ("vals", st.clusters as f64),
            ("vals_lit", st.lit as f64),
            ("val_rsm_texels", st.pixels as f64),
            ("val_flux_w", st.flux),
            ("val_mean_radius_m", st.mean_radius),
            ("ism_maps", self.ism_maps as f64),
            ("visibility", self.visibility as f64),
        ]
    }
}

impl Vals {
    /// Sizes the frame's buffers, the clustering RSM (`res` texels a side), the seed list and
    /// the cluster targets for `cx` and `vs`; clusters carried over from another scene are
    /// dropped.
    fn fit_targets(&mut self, cx: &FrameCx<'_>, vs: &ValSettings, res: u32) {
        if self.buffers.size != cx.size {
            self.buffers = ValBuffers::new(cx.device, cx.size);
        }
        if self.coarse.as_ref().is_none_or(|c| c.res != res) {
            self.coarse = Some(ValRsm::new(cx.device, res));
        }
        let capacity = cx.vpl_buffers.capacity;
        if self.seed_list.as_ref().is_none_or(|(c, _)| *c != capacity) {
            let b = cx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("val::seed_list"),
                size: pass::seed_list_bytes(capacity),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            self.seed_list = Some((capacity, b));
        }
        if !self.targets.as_ref().is_some_and(|t| t.matches(vs.clusters, res)) {
            let t = ValTargets::new(cx.device, vs.clusters, res);
            self.stats = Some(CounterReadback::new(
                cx.device,
                "val::stats_readback",
                (t.clusters as usize * std::mem::size_of::<GpuVal>()) as u64,
                ValStats::from_words,
            ));
            self.targets = Some(t);
        }
        // Clusters carried over belong to one scene.
        if self.scene_generation != cx.scene.generation {
            self.scene_generation = cx.scene.generation;
            if let Some(t) = self.targets.as_mut() {
                t.unprime();
            }
        }
    }
}

/// The frame's visibility (`VIS_*`): none without shadow rays, else `vs.visibility`'s.
fn visibility_of(s: &RenderSettings, vs: &ValSettings) -> u32 {
    if !s.gi.shadow_rays {
        VIS_NONE
    } else {
        match vs.visibility {
            ValVisibility::Rays => VIS_RAYS,
            ValVisibility::Ism => VIS_ISM,
            ValVisibility::Pcss => VIS_PCSS,
            ValVisibility::Disk => VIS_DISK,
        }
    }
}

//! One UI frame of the workbench: settings to the renderer, camera input, the frame and its
//! docked views, A/B metrics, the sheet job, exports, the status line, exit handling.

use super::*;

impl WorkbenchApp {
    pub(super) fn viewport(&mut self, ui: &mut egui::Ui) {
        let (Some(rs), Some(_)) = (self.render_state.clone(), self.open.as_ref()) else {
            ui.centered_and_justified(|ui| ui.label("No scene is open."));
            return;
        };
        if self.renderer.is_none() || self.device_lost_notice(ui) {
            return;
        }
        self.sync_renderer(ui);
        let job_running = self.sheet_job.is_some();
        let render_now = self.camera_and_animation(ui, job_running);
        let comparing = self.compare_gt && self.settings.gi.method.per_frame() && !job_running;
        self.render_frame(render_now, comparing);
        let now = ui.input(|i| i.time);
        self.after_frame(now, comparing);
        let mut events = self.draw_views(ui, &rs);
        self.update_ab_metrics(now);
        self.pointer_and_story(ui, &events, now);
        self.pick_cut(&events);
        let Some(renderer) = self.renderer.as_mut() else {
            return;
        };
        if let Some(src) = events.snapshot {
            let label = format!(
                "{} · {} · frame {}",
                self.settings.gi.method.name(),
                src.name(),
                renderer.sampling_frames()
            );
            if let Err(e) = renderer.take_snapshot(src, label) {
                self.errors.push(format!("snapshot: {e}"));
            }
        }
        self.pending_export = events.export.take();
        self.events = events;
        self.frames += 1;
    }

    /// A lost device the app has no next window for (`recovery.rs`: an app without a
    /// handover, as in a test harness): rendering stops and says why (true).
    fn device_lost_notice(&mut self, ui: &mut egui::Ui) -> bool {
        let Some(renderer) = self.renderer.as_mut() else {
            return false;
        };
        if renderer.ctx.errors.device_lost() {
            for e in renderer.ctx.errors.take() {
                if !self.errors.contains(&e) {
                    self.errors.push(e);
                }
            }
            ui.centered_and_justified(|ui| {
                ui.colored_label(
                    ui.visuals().error_fg_color,
                    format!(
                        "The GPU device was lost (see the status line){}. Rendering has \
                         stopped; restart the workbench (its layout is saved on exit).",
                        if self.recoveries > 0 {
                            format!(" after {} recoveries", self.recoveries)
                        } else {
                            String::new()
                        }
                    ),
                )
            });
            return true;
        }
        false
    }

    /// The render size (the largest view at the render scale) and the settings to the
    /// renderer (not while a sheet drives it).
    fn sync_renderer(&mut self, ui: &egui::Ui) {
        let avail = ui.available_size();
        let ppp = ui.ctx().pixels_per_point();
        let Some(renderer) = self.renderer.as_mut() else {
            return;
        };
        // Render resolution: the largest view's image area (last layout) at the render scale.
        let px = self.layout.largest_view_px().unwrap_or(avail * ppp);
        let w = ((px.x * self.render_scale) as u32).clamp(16, 8192);
        let h = ((px.y * self.render_scale) as u32).clamp(16, 8192);
        if let Err(e) = renderer.resize(w, h) {
            self.errors.push(e.to_string());
        }
        let job_running = self.sheet_job.is_some();
        if !job_running
            && renderer.settings() != &self.settings
            && let Err(e) = renderer.set_settings(self.settings.clone())
        {
            self.errors.push(e.to_string());
            self.settings = renderer.settings().clone();
        }
        if self.settings.gi.method.kind() != crate::methods::Kind::Progressive {
            self.last_fast_method = self.settings.gi.method;
        }
    }

    /// The views' input of the last frame to the camera, and the dynamic scene's step (sun
    /// sweep, orbit, camera path); true when this UI frame renders.
    fn camera_and_animation(&mut self, ui: &egui::Ui, job_running: bool) -> bool {
        let Some(open) = self.open.as_mut() else {
            return false;
        };
        let ev = std::mem::take(&mut self.events);
        let dt = ui.input(|i| i.stable_dt).min(0.1);
        if let Some((d, primary)) = ev.camera_drag {
            open.controller.on_drag(d, primary);
            open.camera_index = None;
        }
        if ev.scroll != 0.0 {
            open.controller.on_scroll(ev.scroll);
            open.camera_index = None;
        }
        if open.controller.mode == CameraMode::Fly && ev.hovered {
            let mv = ui.input(|i| {
                let k = |key| if i.key_down(key) { 1.0 } else { 0.0 };
                let fast = if i.modifiers.shift { 4.0 } else { 1.0 };
                Vec3::new(
                    k(egui::Key::D) - k(egui::Key::A),
                    k(egui::Key::E) - k(egui::Key::Q),
                    k(egui::Key::W) - k(egui::Key::S),
                ) * fast
            });
            if mv != Vec3::ZERO {
                open.controller.on_move(mv, dt);
                open.camera_index = None;
            }
        }
        // The dynamic scene: sun sweep and camera orbit, one step per rendered frame.
        let render_now = !self.anim.paused || self.anim.step;
        self.anim.step = false;
        if render_now && !job_running {
            if self.anim.sun_deg_per_frame != 0.0
                && let Some(sun) = &mut self.sun
            {
                sun.azimuth_deg =
                    (sun.azimuth_deg + self.anim.sun_deg_per_frame + 180.0).rem_euclid(360.0) - 180.0;
            }
            if self.anim.orbit_deg_per_frame != 0.0 {
                open.controller.yaw += self.anim.orbit_deg_per_frame.to_radians();
                open.camera_index = None;
            }
            if let Some(cam) = self.anim.path.step(&open.scene) {
                open.camera = cam;
                open.controller = CameraController::from_camera(&open.camera, &open.scene.bounds);
                open.camera_index = None;
            }
        }
        if open.camera_index.is_none() {
            open.controller.apply(&mut open.camera);
        }
        render_now
    }

    /// One frame: a comparison sheet's step while one runs, else the docked views' frame.
    fn render_frame(&mut self, render_now: bool, comparing: bool) {
        let (Some(renderer), Some(open)) = (self.renderer.as_mut(), self.open.as_mut()) else {
            return;
        };
        let lights = lights_with_sun(&open.scene, self.sun.as_ref());
        let specs = self.layout.assign_slots(self.hover_view);
        if self.cancel_sheet {
            self.cancel_sheet = false;
            if let Some(job) = self.sheet_job.take() {
                job.restore(renderer);
                self.sheet_status = None;
                let _ = renderer.set_settings(self.settings.clone());
            }
        }
        if let Some(job) = &mut self.sheet_job {
            // A comparison sheet drives the renderer (one frame per UI frame; cancellable).
            renderer.set_compare_ground_truth(false);
            match job.step(renderer, &open.camera, &lights) {
                Ok(crate::sheet::Step::Running { fraction, label }) => {
                    self.sheet_status = Some((fraction, label));
                }
                Ok(crate::sheet::Step::Done(sheet)) => {
                    self.sheet_job = None;
                    self.sheet_status = None;
                    match write_sheet(&sheet, std::path::Path::new(&self.export_dir)) {
                        Ok((png, json)) => {
                            self.last_export = format!("{}, {}", png.display(), json.display());
                            let (c, s) = super::exports::capture_of(renderer, open, &lights, "sheet");
                            if let Err(e) = super::exports::write_capture_records(c, &s, &[png, json]) {
                                self.errors.push(format!("capture record: {e}"));
                            }
                        }
                        Err(e) => self.errors.push(format!("comparison sheet: {e}")),
                    }
                    let _ = renderer.set_settings(self.settings.clone());
                }
                Err(e) => {
                    job.restore(renderer);
                    self.sheet_job = None;
                    self.sheet_status = None;
                    self.errors.push(format!("comparison sheet: {e}"));
                }
            }
        } else if render_now {
            renderer.set_freeze_tree(self.tree_panel.freeze);
            renderer.set_compare_ground_truth(comparing);
            renderer.render_views(
                &FrameInput {
                    camera: &open.camera,
                    lights: &lights,
                    view: specs[0].buffer,
                },
                &specs,
            );
        }
    }

    /// After the frame: live metrics against the comparison's truth, the tree panel, the
    /// timings, the method's statistics and the GPU's errors.
    fn after_frame(&mut self, now: f64, comparing: bool) {
        let Some(renderer) = self.renderer.as_mut() else {
            return;
        };
        // Live metrics against the finished comparison ground truth (twice a second).
        if comparing
            && now - self.last_metrics_time > 0.5
            && renderer.compare_progress().is_some_and(|p| p.finished())
        {
            self.last_metrics_time = now;
            let look = crate::gpu::views::ViewLook::from_display(&self.settings.display);
            match ab_metrics(
                renderer,
                AbSource::Indirect,
                AbSource::GroundTruthIndirect,
                &look,
                None,
            ) {
                Ok(m) => self.compare_metrics = m.map(|m| m.0),
                Err(e) => self.errors.push(format!("comparison readback: {e}")),
            }
        } else if !comparing {
            self.compare_metrics = None;
        }
        if let Err(e) = self.tree_panel.refresh(renderer, now) {
            self.errors.push(format!("light tree statistics: {e}"));
        }
        if let Some(t) = renderer.poll_timings() {
            self.timings_panel.push(&t);
            self.timings = Some(t);
        }
        self.sampling_stats = renderer.sampling_stats();
        self.method_status = renderer.method_status();
        for e in renderer.ctx.errors.take() {
            if !self.errors.contains(&e) {
                self.errors.push(e);
            }
        }
    }

    /// The docked views; returns their input events.
    fn draw_views(&mut self, ui: &mut egui::Ui, rs: &egui_wgpu::RenderState) -> ViewEvents {
        let (Some(renderer), Some(open)) = (self.renderer.as_mut(), self.open.as_mut()) else {
            return ViewEvents::default();
        };
        let mut tree = std::mem::replace(
            &mut self.layout.tree,
            egui_tiles::Tree::empty(egui::Id::unique("image_views_swap")),
        );
        let mut events = ViewEvents::default();
        let overlay = self.story.overlay();
        {
            let snapshots = renderer.snapshot_labels();
            let mut cx = PaneContext {
                renderer: &*renderer,
                render_state: rs,
                transform: &mut self.layout.transform,
                events: &mut events,
                linear_filter: self.render_scale < 1.0,
                stats: self.sampling_stats,
                display: &self.settings.display,
                snapshots: &snapshots,
                pinned: if self.pixel.pinned { self.pixel.pixel } else { None },
                overlay: &overlay,
                view_proj: open
                    .camera
                    .view_projection(renderer.size().0 as f32 / renderer.size().1.max(1) as f32),
            };
            tree.ui(&mut cx, ui);
        }
        self.layout.tree = tree;
        events
    }

    /// A/B metrics (whole pair and rectangle), twice a second per view.
    fn update_ab_metrics(&mut self, now: f64) {
        let Some(renderer) = self.renderer.as_mut() else {
            return;
        };
        for p in self.layout.panes_mut() {
            let Some(ab) = p.spec.effective_ab() else {
                p.rt.metrics = None;
                continue;
            };
            if p.rt.slot.is_none() || now - p.rt.metrics_at < 0.5 {
                continue;
            }
            p.rt.metrics_at = now;
            p.rt.metrics_note = None;
            let gt = |s: AbSource| matches!(s, AbSource::GroundTruthIndirect | AbSource::GroundTruthFinal);
            if gt(ab.a) || gt(ab.b) {
                match renderer.compare_progress() {
                    Some(pr) if !pr.finished() => {
                        p.rt.metrics = None;
                        p.rt.metrics_note = Some(format!(
                            "metrics when the ground truth is done ({:.0}%)",
                            100.0 * pr.fraction()
                        ));
                        continue;
                    }
                    None => {
                        p.rt.metrics = None;
                        p.rt.metrics_note =
                            Some("no ground truth: turn on \"compare with the ground truth\"".into());
                        continue;
                    }
                    _ => {}
                }
            }
            p.rt.metrics = match ab_metrics(renderer, ab.a, ab.b, &p.spec.look, p.rect) {
                Ok(None) => {
                    p.rt.metrics_note = Some("no metrics: A or B is missing, or their sizes differ".into());
                    None
                }
                Ok(m) => m,
                Err(e) => {
                    self.errors.push(format!("A/B readback: {e}"));
                    None
                }
            };
        }
    }

    /// Pixel values under the pointer (camera-space views; P pins / unpins, a click pins) and
    /// the pinned pixel's story.
    fn pointer_and_story(&mut self, ui: &egui::Ui, events: &ViewEvents, now: f64) {
        let Some(renderer) = self.renderer.as_mut() else {
            return;
        };
        if self.pixel.show || self.story.show {
            if events.hovered && ui.input(|i| i.key_pressed(egui::Key::P)) {
                self.pixel.pinned = !self.pixel.pinned;
            }
            if let Some(c) = events.click
                && let Some(p) = c.pixel
            {
                self.pixel.pixel = Some(p);
                self.pixel.pinned = true;
            } else if !self.pixel.pinned && events.hover_pixel.is_some() {
                self.pixel.pixel = events.hover_pixel;
            }
            if let Some((x, y)) = self.pixel.pixel
                && self.pixel.show
                && self.pixel.read.is_none_or(|(p, t)| p != (x, y) || now - t > 0.25)
            {
                self.pixel.read = Some(((x, y), now));
                match renderer.read_pixel(x, y) {
                    Ok(rows) => self.pixel.rows = rows,
                    Err(e) => self.errors.push(format!("pixel values: {e}")),
                }
            }
        }
        // The story of the pinned pixel (tree samplers).
        let story_pixel = if self.pixel.pinned { self.pixel.pixel } else { None };
        if let Err(e) = self.story.refresh(renderer, story_pixel, now) {
            self.errors.push(format!("pixel story: {e}"));
        }
    }

    /// Clicking a block in a view of a method's cut blocks lists its cut.
    fn pick_cut(&mut self, events: &ViewEvents) {
        let Some(renderer) = self.renderer.as_mut() else {
            return;
        };
        if let Some(c) = events.click
            && let ViewBuffer::Method(v) = c.buffer
        {
            match renderer.pick_block(v, c.texel) {
                Ok(None) => {}
                Ok(Some(picked)) => match (renderer.read_tree(), renderer.read_tree_links()) {
                    (Ok((nodes, flags)), Ok(links)) => {
                        let topo = crate::base::sst_node::Topology::of((nodes.len() / 2) as u32, &links);
                        let cut = &picked.nodes;
                        self.cut_inspect = Some(CutInspect {
                            depths: cut.iter().map(|&n| topo.depth(n.max(1))).collect(),
                            block: picked.block,
                            rows: cut
                                .iter()
                                .map(|&n| {
                                    let node = nodes.get(n as usize).copied().unwrap_or(SstNode::EMPTY);
                                    (n, node, crate::base::sst_node::flag(&flags, n as usize))
                                })
                                .collect(),
                            leaves: (nodes.len() / 2) as u32,
                            root_flux: nodes.get(1).map_or(0.0, |r| luminance(r.intensity)),
                        })
                    }
                    (Err(e), _) | (_, Err(e)) => self.errors.push(format!("reading the cut: {e}")),
                },
                Err(e) => self.errors.push(format!("reading the cut: {e}")),
            }
        }
    }

    /// One line of fixed height (so the layout never jumps with the length of the timings):
    /// the adapter, resolution, VPLs and frame time first, then the per-pass GPU times,
    /// truncated to the window; hovering shows every pass.
    pub(super) fn status_bar(&self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.label(format!("GPU: {}", self.adapter));
            let Some(r) = &self.renderer else { return };
            ui.separator();
            let (w, h) = r.size();
            ui.label(format!("{w}x{h}"));
            ui.separator();
            match r.flux_total() {
                Some(f) => ui.label(format!(
                    "VPLs {} · reflected flux {:.4} W (lum.)",
                    r.vpl_frame().count,
                    f
                )),
                None => ui.label(format!("VPLs {}", r.vpl_frame().count)),
            };
            ui.separator();
            ui.label(format!("frame {:.1} ms (wall)", self.frame_ms_smoothed));
            ui.separator();
            if !r.timestamps_supported() {
                ui.label("timestamps not supported");
            } else if let Some(t) = &self.timings {
                let lines: Vec<String> = t
                    .passes
                    .iter()
                    .map(|(n, ms)| format!("{n:<16} {ms:>9.3} ms"))
                    .collect();
                ui.add(egui::Label::new(t.summary()).truncate())
                    .on_hover_ui(|ui| {
                        ui.label(egui::RichText::new(lines.join("\n")).monospace());
                        ui.label(format!(
                            "total {:.3} ms (GPU timestamps of the last timed frame, no diagnostics)",
                            t.total_ms()
                        ));
                    });
            } else {
                ui.label("GPU timings: no timed frame yet");
            }
            // GPU errors (validation, out of memory, device lost) and refused settings: the
            // latest, with the pass it names; all of them on hover.
            if let Some(last) = self.errors.last() {
                ui.separator();
                let text = if self.errors.len() > 1 {
                    format!("{} errors; last: {last}", self.errors.len())
                } else {
                    last.clone()
                };
                ui.add(
                    egui::Label::new(egui::RichText::new(text).color(ui.visuals().error_fg_color)).truncate(),
                )
                .on_hover_ui(|ui| {
                    for e in &self.errors {
                        ui.label(e);
                    }
                });
            }
        });
    }

    /// Writes a view as displayed (PNG) or the linear buffer behind it (EXR; A and B of an
    /// A/B view) into the export folder; the files written, or the problem, are reported.
    pub fn export_view(
        &mut self,
        slot: usize,
        spec: &crate::gpu::views::ViewSpec,
        kind: ExportKind,
    ) -> Vec<PathBuf> {
        let Some(r) = &self.renderer else {
            return Vec::new();
        };
        match export_view_files(r, slot, spec, kind, std::path::Path::new(&self.export_dir)) {
            Ok(files) => {
                self.last_export = files
                    .iter()
                    .map(|f| f.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", ");
                self.record_captures("view export", &files);
                files
            }
            Err(e) => {
                self.errors.push(format!("export: {e}"));
                Vec::new()
            }
        }
    }

    pub(super) fn handle_exit(&mut self, ctx: &egui::Context) {
        let Some(n) = self.options.exit_after_frames else {
            return;
        };
        if self.frames < n {
            return;
        }
        match &self.options.screenshot {
            Some(path) if !self.screenshot_done.load(Ordering::Acquire) => {
                if !self.screenshot_requested {
                    self.screenshot_requested = true;
                    let path = path.clone();
                    self.record_captures("screenshot", std::slice::from_ref(&path));
                    let done = self.screenshot_done.clone();
                    let ctx2 = ctx.clone();
                    ctx.request_screenshot(move |img| {
                        let [w, h] = img.size;
                        let bytes: Vec<u8> = img.pixels.iter().flat_map(|c| c.to_array()).collect();
                        match crate::export::write_png(&path, w as u32, h as u32, &bytes) {
                            Ok(()) => log::info!("screenshot written to {}", path.display()),
                            Err(e) => log::error!("{e}"),
                        }
                        done.store(true, Ordering::Release);
                        ctx2.request_repaint();
                    });
                }
            }
            _ => ctx.send_viewport_cmd(egui::ViewportCommand::Close),
        }
    }
}

pub(super) fn lights_with_sun(scene: &Scene, sun: Option<&SunControls>) -> Vec<DirectionalLight> {
    let mut lights = scene.lights.clone();
    if let (Some(sun), Some(l0)) = (sun, lights.first_mut()) {
        *l0 = sun.to_light(&l0.name);
    }
    lights
}

pub(super) fn ab_metrics(
    r: &Renderer,
    a: AbSource,
    b: AbSource,
    look: &crate::gpu::views::ViewLook,
    rect: Option<[u32; 4]>,
) -> Result<Option<AbMetrics>, crate::gpu::context::GpuError> {
    let (Some(a), Some(b)) = (r.read_ab_source(a)?, r.read_ab_source(b)?) else {
        return Ok(None);
    };
    if (a.width, a.height) != (b.width, b.height) {
        return Ok(None);
    }
    let m = |a: &_, b: &_| crate::metrics::compare(a, b, look.exposure_ev, look.tonemap);
    let part = rect
        .filter(|r| r[2] > r[0] && r[3] > r[1])
        .map(|r| m(&crate::metrics::crop(&a, r), &crate::metrics::crop(&b, r)));
    Ok(Some((m(&a, &b), part)))
}

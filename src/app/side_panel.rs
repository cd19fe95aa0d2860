//! The side panel: scene and presets, camera and bookmarks, view, sun, animation, the GI
//! method (its settings UI from `crate::methods`) and the VPLs, the light tree, exports and
//! comparison sheets, the shadow map.

use super::*;

impl WorkbenchApp {
    pub(super) fn side_panel(&mut self, ui: &mut egui::Ui) {
        egui::ScrollArea::vertical().show(ui, |ui| {
            self.scene_section(ui);
            self.view_section(ui);
            self.sun_and_animation_section(ui);
            self.method_section(ui);
            self.shading_and_vpl_section(ui);
            self.export_section(ui);
            self.shadow_section(ui);
        });
    }

    /// The scene: open a file, built-in scenes and presets, what was loaded, and the camera with its bookmarks.
    fn scene_section(&mut self, ui: &mut egui::Ui) {
        ui.heading("Scene");
        ui.horizontal(|ui| {
            ui.add(
                egui::TextEdit::singleline(&mut self.scene_path_input)
                    .hint_text(".gltf / .glb / preset .toml")
                    .desired_width(150.0),
            );
            if ui.button("Open").clicked() {
                let s = self.scene_path_input.trim().to_string();
                let s = if s.is_empty() { "default".to_string() } else { s };
                if let Err(e) = self.open_scene(&s, None) {
                    self.errors.push(e);
                }
            }
        });
        ui.horizontal_wrapped(|ui| {
            let mut choice = None;
            for b in crate::scene::test_scenes::BUILTIN {
                if ui.button(b.name).on_hover_text(b.about).clicked() {
                    choice = Some(b.name.to_string());
                }
            }
            for p in preset_files() {
                let label = p
                    .file_stem()
                    .map(|s| s.to_string_lossy().to_string())
                    .unwrap_or_default();
                if ui.button(label).on_hover_text(p.display().to_string()).clicked() {
                    choice = Some(p.display().to_string());
                }
            }
            if let Some(c) = choice {
                self.scene_path_input = if c == "default" { String::new() } else { c.clone() };
                if let Err(e) = self.open_scene(&c, None) {
                    self.errors.push(e);
                }
            }
        });
        if let Some(open) = &mut self.open {
            ui.label(format!(
                "{}: {} triangles, {} materials, {} textures",
                open.scene.name,
                open.scene.triangle_count(),
                open.scene.materials.len(),
                open.scene.textures.len()
            ));
            for note in &open.scene.load_notes {
                ui.label(format!("decoded: {note}"));
            }
            if !open.scene.warnings.is_empty() {
                ui.collapsing(format!("{} load warnings", open.scene.warnings.len()), |ui| {
                    for w in &open.scene.warnings {
                        ui.label(w);
                    }
                });
            }
            ui.separator();
            ui.heading("Camera");
            let names: Vec<String> = open.scene.cameras.iter().map(|c| c.name.clone()).collect();
            let current = open
                .camera_index
                .and_then(|i| names.get(i).cloned())
                .unwrap_or_else(|| "(free)".into());
            egui::ComboBox::from_label("camera")
                .selected_text(current)
                .show_ui(ui, |ui| {
                    for (i, n) in names.iter().enumerate() {
                        if ui.selectable_label(open.camera_index == Some(i), n).clicked() {
                            open.camera_index = Some(i);
                            open.camera = open.scene.cameras[i].clone();
                            open.controller = CameraController::from_camera(&open.camera, &open.scene.bounds);
                        }
                    }
                });
            ui.horizontal(|ui| {
                ui.radio_value(&mut open.controller.mode, CameraMode::Orbit, "orbit")
                    .on_hover_text("left drag: orbit, right drag: pan, wheel: zoom");
                ui.radio_value(&mut open.controller.mode, CameraMode::Fly, "fly")
                    .on_hover_text("drag: look, W/A/S/D/Q/E: move (Shift: faster), wheel: speed");
            });
            let mut fov = open.camera.yfov.to_degrees();
            if ui
                .add(egui::Slider::new(&mut fov, 10.0..=120.0).text("vertical fov (deg)"))
                .changed()
            {
                open.camera.yfov = fov.to_radians();
            }
            ui.horizontal(|ui| {
                let l = ui.label("bookmark");
                ui.add(egui::TextEdit::singleline(&mut self.bookmark_name).desired_width(100.0))
                    .labelled_by(l.id);
                if ui
                    .button("save")
                    .on_hover_text("adds this camera to the list; a preset scene keeps it in its .toml")
                    .clicked()
                {
                    let mut cam = open.camera.clone();
                    cam.name = self.bookmark_name.trim().to_string();
                    if cam.name.is_empty() {
                        cam.name = format!("bookmark {}", open.scene.cameras.len() + 1);
                    }
                    open.scene.cameras.retain(|c| c.name != cam.name);
                    open.scene.cameras.push(cam.clone());
                    open.camera_index = Some(open.scene.cameras.len() - 1);
                    let path = std::path::Path::new(&open.source);
                    self.bookmark_note = if path.extension().is_some_and(|e| e == "toml") {
                        match crate::scene::preset::append_bookmark(path, &cam) {
                            Ok(()) => format!("saved '{}' in {}", cam.name, path.display()),
                            Err(e) => e,
                        }
                    } else {
                        format!(
                            "'{}' is kept for this session (the scene has no preset file to store it in)",
                            cam.name
                        )
                    };
                    self.bookmark_name = format!("bookmark {}", open.scene.cameras.len() + 1);
                }
            });
            if !self.bookmark_note.is_empty() {
                ui.label(egui::RichText::new(&self.bookmark_note).small());
            }
        }
    }

    /// The main view's buffer and look, overlays, the global exposure and tonemap, texture filtering, render scale.
    fn view_section(&mut self, ui: &mut egui::Ui) {
        ui.separator();
        ui.heading("View");
        let mut main = self.view();
        egui::ComboBox::from_label("buffer")
            .height(600.0)
            .selected_text(main.name())
            .show_ui(ui, |ui| {
                for v in ViewBuffer::all() {
                    ui.selectable_value(&mut main, v, v.name());
                }
            })
            .response
            .on_hover_text("the buffer of view 1; every view has its own selector");
        if main != self.view() {
            self.set_view(main);
        }
        ui.horizontal(|ui| {
            if ui
                .button("+ view")
                .on_hover_text("another image view (drag its :: handle to dock it elsewhere)")
                .clicked()
            {
                let spec = crate::gpu::views::ViewSpec::new(ViewBuffer::Indirect, &self.settings.display);
                self.layout.add_view(spec);
            }
            if ui
                .button("+ A/B view")
                .on_hover_text("compare two images: live buffers or snapshots")
                .clicked()
            {
                let spec = crate::gpu::views::ViewSpec::new(ViewBuffer::AbCompare, &self.settings.display);
                self.layout.add_view(spec);
            }
            if ui
                .button("reset layout")
                .on_hover_text("one view of the final image; zoom to fit")
                .clicked()
            {
                self.reset_layout(&[ViewBuffer::Final]);
            }
        });
        let before = (self.settings.display.exposure_ev, self.settings.display.tonemap);
        ui.add(
            egui::Slider::new(&mut self.settings.display.exposure_ev, -10.0..=10.0)
                .text("exposure (EV, all views)"),
        );
        if self.view() == ViewBuffer::PdfPyramid {
            ui.add(egui::Slider::new(&mut self.settings.display.pyramid_level, 0..=12).text("pyramid level"));
        }
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.settings.display.vpl_overlay, "show VPLs");
            ui.add(egui::Slider::new(&mut self.settings.display.vpl_point_size, 0..=6).text("point size"));
        });
        if self.settings.display.vpl_overlay {
            ui.horizontal(|ui| {
                let d = &mut self.settings.display;
                egui::ComboBox::from_label("VPL colour")
                    .selected_text(d.vpl_color.name())
                    .show_ui(ui, |ui| {
                        for c in crate::settings::VplColor::ALL {
                            ui.selectable_value(&mut d.vpl_color, c, c.name());
                        }
                    });
                if d.vpl_color == crate::settings::VplColor::Bounce {
                    // The legend: one swatch per bounce of the frame.
                    for b in 1..=self.settings.vpl.bounces {
                        let [r, g, bl] = crate::base::colormap::bounce_color(b);
                        let c =
                            egui::Color32::from_rgb((r * 255.0) as u8, (g * 255.0) as u8, (bl * 255.0) as u8);
                        ui.label(
                            egui::RichText::new(format!("bounce {b}"))
                                .background_color(c)
                                .color(egui::Color32::BLACK),
                        );
                    }
                }
            });
        }
        egui::ComboBox::from_label("tonemap")
            .selected_text(self.settings.display.tonemap.name())
            .show_ui(ui, |ui| {
                for t in Tonemap::ALL {
                    ui.selectable_value(&mut self.settings.display.tonemap, t, t.name());
                }
            });
        // The global exposure and tonemap set every view's (each view's "look" menu
        // overrides its own).
        if before != (self.settings.display.exposure_ev, self.settings.display.tonemap) {
            let d = self.settings.display.clone();
            for p in self.layout.panes_mut() {
                p.spec.look.exposure_ev = d.exposure_ev;
                p.spec.look.tonemap = d.tonemap;
            }
        }
        ui.checkbox(&mut self.pixel.show, "pixel values window")
            .on_hover_text("every buffer at the pixel under the pointer (camera views); P pins it");
        ui.checkbox(&mut self.story.show, "pixel story window").on_hover_text(
        "click a camera view: the pinned pixel's cuts, blend weights and every sample's path (tree samplers)",
    );
        ui.checkbox(&mut self.timings_panel.show, "GPU timings window")
            .on_hover_text("per-pass GPU times: last frame and history; hover a pass to see its output");
        let hint = if crate::gpu::shaders::ShaderSourceDisk::reload_from_disk() {
            "rebuild the pipelines from shaders/ on disk (the last good ones stay on error)"
        } else {
            "release build: rebuilds the pipelines from the embedded shaders"
        };
        if ui.button("Reload shaders").on_hover_text(hint).clicked()
            && let Some(r) = &mut self.renderer
            && let Err(e) = r.reload_shaders()
        {
            self.errors.push(e.to_string());
        }
        ui.add(egui::Slider::new(&mut self.settings.textures.anisotropy, 1..=16).text("anisotropy"))
            .on_hover_text("anisotropic texture filtering (1 = trilinear)");
        ui.add(egui::Slider::new(&mut self.render_scale, 0.25..=1.0).text("render scale"))
            .on_hover_text("render resolution relative to the viewport's pixels");
    }

    /// The sun (direction, irradiance, colour) and the animation (sun sweep, camera orbit or path, pause and step, fixed seed).
    fn sun_and_animation_section(&mut self, ui: &mut egui::Ui) {
        if let Some(sun) = &mut self.sun {
            ui.separator();
            ui.heading("Sun");
            ui.add(egui::Slider::new(&mut sun.azimuth_deg, -180.0..=180.0).text("azimuth (deg)"));
            ui.add(egui::Slider::new(&mut sun.elevation_deg, -10.0..=90.0).text("elevation (deg)"));
            ui.add(
                egui::Slider::new(&mut sun.irradiance, 0.0..=100.0)
                    .logarithmic(true)
                    .text("irradiance (W/m²)"),
            )
            .on_hover_text("E on a surface perpendicular to the sun");
            ui.horizontal(|ui| {
                ui.label("colour");
                ui.color_edit_button_rgb(&mut sun.color);
            });
        }
        ui.separator();
        ui.heading("Animation");
        ui.add(
            egui::Slider::new(&mut self.anim.sun_deg_per_frame, -10.0..=10.0)
                .text("sun azimuth sweep (deg/frame)"),
        )
        .on_hover_text("the sun turns every frame: RSM, VPLs and tree are rebuilt each frame");
        ui.add(
            egui::Slider::new(&mut self.anim.orbit_deg_per_frame, -10.0..=10.0)
                .text("camera orbit (deg/frame)"),
        )
        .on_hover_text("the camera circles its orbit target");
        if let Some(open) = &self.open {
            self.anim.path.ui(ui, &open.scene);
        }
        ui.horizontal(|ui| {
            let label = if self.anim.paused { "resume" } else { "pause" };
            if ui.button(label).clicked() {
                self.anim.paused = !self.anim.paused;
            }
            if ui
                .add_enabled(self.anim.paused, egui::Button::new("step frame"))
                .clicked()
            {
                self.anim.step = true;
            }
            ui.checkbox(&mut self.settings.frame.fixed_seed, "fixed seed")
                .on_hover_text("the samplers draw the same random numbers every frame");
        });
    }

    /// The GI method: its combo from the registry, its settings UI and status line.
    fn method_section(&mut self, ui: &mut egui::Ui) {
        ui.separator();
        ui.heading("Global illumination");
        let method = self.settings.gi.method;
        egui::ComboBox::from_label("method")
            .selected_text(method.name())
            .show_ui(ui, |ui| {
                for m in crate::methods::REGISTRY {
                    ui.selectable_value(&mut self.settings.gi.method, m.id, m.label)
                        .on_hover_text(m.about);
                }
            });
        let info = method.info();
        if let Some(p) = self.renderer.as_ref().and_then(|r| r.gi_progress()) {
            ui.horizontal(|ui| {
                ui.add(
                    egui::ProgressBar::new(p.fraction())
                        .desired_width(200.0)
                        .text(format!("{} / {} {}", p.done, p.total, info.progress_unit))
                        .show_percentage(),
                );
                if !p.finished()
                    && ui
                        .button("stop")
                        .on_hover_text(format!("back to {}", self.last_fast_method.name()))
                        .clicked()
                {
                    self.settings.gi.method = self.last_fast_method;
                }
            });
        }
        if info.shadow_ray_switch {
            ui.checkbox(&mut self.settings.gi.shadow_rays, "shadow rays")
                .on_hover_text(
                    "off: every VPL and cluster sample counts as visible (unshadowed GI: light \
             through walls; the GPU timings then show the cost without visibility)",
                );
        }
        (info.ui)(ui, method, &mut self.settings);
        super::temporal_panel::temporal_ui(ui, &mut self.settings.temporal, method.per_frame());
        if method.per_frame() {
            ui.checkbox(&mut self.compare_gt, "compare with the ground truth")
                .on_hover_text(
                    "runs the ground truth of the same VPLs beside the method (progressive; \
                 keep the camera still); views: ground truth, split, relative error",
                );
            if self.compare_gt {
                if let Some(p) = self.renderer.as_ref().and_then(|r| r.compare_progress()) {
                    ui.horizontal(|ui| {
                        ui.add(
                            egui::ProgressBar::new(p.fraction())
                                .desired_width(200.0)
                                .text(format!("ground truth {} / {} VPLs", p.done, p.total))
                                .show_percentage(),
                        );
                        if !p.finished() && ui.button("stop").clicked() {
                            self.compare_gt = false;
                        }
                    });
                    if p.finished()
                        && let Some(m) = &self.compare_metrics
                    {
                        ui.label(format!(
                            "vs ground truth: RMSE {:.2e} (relative {:.3}) · SSIM {:.4} · mean ratio {:.3}",
                            m.rmse, m.relative_rmse, m.ssim, m.mean_ratio
                        ))
                        .on_hover_text(
                            "RMSE on linear radiance; SSIM on the displayed luminance (exposure, tonemap)",
                        );
                    }
                }
                if let Some(p) = self.layout.main_pane_mut()
                    && p.spec.buffer == ViewBuffer::SplitIndirect
                {
                    ui.add(egui::Slider::new(&mut p.spec.ab.split, 0.0..=1.0).text("split"));
                }
            }
        }
        if let Some(line) = &self.method_status {
            ui.label(line);
        }
    }

    /// The BRDF, the distance bound, the VPLs (count, selection, bounces) and the light tree's controls.
    fn shading_and_vpl_section(&mut self, ui: &mut egui::Ui) {
        let g = &mut self.settings.gi;
        egui::ComboBox::from_label("BRDF")
            .selected_text(g.brdf.name())
            .show_ui(ui, |ui| {
                for b in crate::settings::Brdf::ALL {
                    ui.selectable_value(&mut g.brdf, b, b.name());
                }
            })
            .response
            .on_hover_text("the BRDF of every shading point; the VPLs stay diffuse emitters (docs/brdf.md)");
        if let Some(msg) = g.method.refuses_brdf(g.brdf) {
            ui.colored_label(ui.visuals().warn_fg_color, msg);
        }
        let g = &mut self.settings.gi;
        ui.add(
            egui::Slider::new(&mut g.distance_epsilon, 0.001..=1.0)
                .logarithmic(true)
                .text("distance bound ε (m)"),
        )
        .on_hover_text("1/d² is bounded by 1/max(d², ε²)");
        let v = &mut self.settings.vpl;
        ui.add(
            egui::Slider::new(&mut v.count, 16..=65536)
                .logarithmic(true)
                .text("VPLs"),
        );
        egui::ComboBox::from_label("VPL selection")
            .selected_text(v.mode.name())
            .show_ui(ui, |ui| {
                for m in VplMode::ALL {
                    ui.selectable_value(&mut v.mode, m, m.name());
                }
            });
        ui.add(egui::Slider::new(&mut v.samples_per_texel, 1..=32).text("BRSM samples / texel"));
        ui.add(
            egui::Slider::new(&mut v.sample_radius, 0.005..=1.0)
                .logarithmic(true)
                .text("sample radius (× scene)"),
        );
        ui.add(egui::Slider::new(&mut v.filter_radius, 0..=8).text("filter radius (texels)"));
        ui.add(egui::Slider::new(&mut v.n_min, -1.0..=1.0).text("n_min"));
        ui.add(
            egui::Slider::new(&mut v.d_max, 0.001..=1.0)
                .logarithmic(true)
                .text("d_max (× scene)"),
        );
        ui.add(egui::Slider::new(&mut v.flux_mix, 0.0..=1.0).text("flux mix"))
            .on_hover_text("share of the PDF that follows flux: > 0 keeps the VPLs unbiased");
        ui.horizontal(|ui| {
            ui.add(egui::DragValue::new(&mut v.seed).prefix("seed "));
            ui.checkbox(&mut v.animate, "new VPLs every frame");
        });
        // Multi-bounce VPLs (instant radiosity): light paths from the RSM through the BVH.
        let max_bounces = crate::gpu::passes::light_paths::MAX_BOUNCES;
        ui.add(egui::Slider::new(&mut v.bounces, 1..=max_bounces).text("bounces"))
            .on_hover_text(
                "1: the RSM's VPLs (one bounce, the thesis). N: light paths traced through the \
             BVH add VPLs at bounces 2..N, each bounce a 1/N share of the VPL budget",
            );
        if v.bounces > 1 {
            let (first, paths) = crate::gpu::passes::light_paths::split_bounces(v.count, v.bounces);
            ui.label(
                egui::RichText::new(format!(
                    "bounce 1: {first} RSM VPLs · bounces 2..{}: {paths} light paths",
                    v.bounces
                ))
                .small(),
            );
            ui.checkbox(&mut v.roulette, "Russian roulette")
                .on_hover_text("continue with probability max(albedo), flux / that (the SST paper)");
            ui.add(egui::Slider::new(&mut v.path_flux_mix, 0.01..=1.0).text("path start flux mix"))
                .on_hover_text(
                    "1: paths start at RSM texels drawn by flux (the SST paper); lower mixes in \
                 bounce 1's BRSM importance, so fewer paths start where their light leaves unseen",
                );
            if let Some(msg) = self.settings.gi.method.refuses_bounces(self.settings.vpl.bounces) {
                ui.colored_label(ui.visuals().warn_fg_color, msg);
            }
        }
        ui.separator();
        // Rows of the level slider: the perfect tree's levels; the radix tree is deeper
        // (its depth per leaf varies: the statistics window shows it), up to 48 here.
        let levels = self.renderer.as_ref().map(|r| {
            let t = r.tree_buffers().1;
            match t.kind {
                crate::settings::TreeKind::Perfect => t.levels(),
                crate::settings::TreeKind::Lbvh => t.depth_bound().min(48),
            }
        });
        self.tree_panel.controls(ui, &mut self.settings, levels);
    }

    /// Exports and the comparison sheet.
    fn export_section(&mut self, ui: &mut egui::Ui) {
        ui.separator();
        ui.heading("Export");
        ui.horizontal(|ui| {
            let l = ui.label("folder");
            ui.add(egui::TextEdit::singleline(&mut self.export_dir).desired_width(170.0))
                .labelled_by(l.id);
        });
        ui.label(egui::RichText::new("each view: export menu (PNG as displayed, EXR of its buffer)").small());
        ui.label("comparison sheet (same VPLs, vs their ground truth):");
        ui.horizontal_wrapped(|ui| {
            for (i, m) in crate::methods::sheet_columns().into_iter().enumerate() {
                if let Some(on) = self.sheet_methods.get_mut(i) {
                    ui.checkbox(on, m.name());
                }
            }
        });
        ui.add(egui::Slider::new(&mut self.sheet_frames, 1..=256).text("frames per method"));
        if let Some((f, label)) = &self.sheet_status {
            ui.add(egui::ProgressBar::new(*f).text(label.clone()).show_percentage());
            if ui.button("cancel sheet").clicked() {
                self.cancel_sheet = true;
            }
        } else if ui
            .button("make comparison sheet")
            .on_hover_text("ground truth of the frame's VPLs, then each method; one PNG + JSON in the folder")
            .clicked()
        {
            let methods: Vec<MethodId> = crate::methods::sheet_columns()
                .into_iter()
                .zip(self.sheet_methods.iter().copied())
                .filter_map(|(m, on)| on.then_some(m))
                .collect();
            self.start_sheet(methods, self.sheet_frames);
        }
        if !self.last_export.is_empty() {
            ui.label(egui::RichText::new(format!("wrote {}", self.last_export)).small());
        }
    }

    /// The shadow map's resolution and biases.
    fn shadow_section(&mut self, ui: &mut egui::Ui) {
        ui.separator();
        ui.heading("Shadow map");
        let s = &mut self.settings.shadow;
        egui::ComboBox::from_label("resolution")
            .selected_text(format!("{0}x{0}", s.resolution))
            .show_ui(ui, |ui| {
                for r in [128, 256, 512, 1024, 2048, 4096] {
                    ui.selectable_value(&mut s.resolution, r, format!("{r}x{r}"));
                }
            });
        ui.add(egui::Slider::new(&mut s.depth_bias, 0.0..=8.0).text("depth bias (texels)"));
        ui.add(egui::Slider::new(&mut s.normal_offset, 0.0..=8.0).text("normal offset (texels)"));
        ui.add(egui::Slider::new(&mut s.slope_bias, 0.0..=4.0).text("slope bias"));
        ui.add(egui::Slider::new(&mut s.pcf_radius, 0..=4).text("PCF radius"));
    }
}

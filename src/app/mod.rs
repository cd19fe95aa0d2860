//! The eframe/egui workbench: viewport with camera controls, buffer selector, sun, shadow and
//! display settings, status line. Only [`viewport_texture`] touches `egui_wgpu`'s textures.

pub mod camera_control;
pub mod image_views;
pub mod story_panel;
pub mod timings_panel;
pub mod tree_panel;
pub mod viewport_texture;

use std::{
    path::PathBuf,
    sync::{
        Arc,
        atomic::{AtomicBool, Ordering},
    },
};

use glam::Vec3;

use crate::reference::sst_tree::{SstNode, luminance};
use crate::renderer::views::AbSource;
use crate::{
    renderer::{
        FrameInput, Renderer,
        context::{GpuContext, describe_adapter},
        settings::{
            ChildProbability, CutBlending, CutFallback, GiMethod, RenderSettings, Tonemap, ViewBuffer,
            VplMode,
        },
        timing::PassTimings,
    },
    scene::{
        Camera, DirectionalLight, Scene,
        preset::{SceneSource, open_scene},
    },
};
use camera_control::{CameraController, CameraMode};
use image_views::{ExportKind, Layout, PaneContext, ViewEvents};
use timings_panel::TimingsPanel;
use tree_panel::TreePanel;

/// How the app was started.
#[derive(Clone, Debug, Default)]
pub struct AppOptions {
    /// What `--scene` said (`default`, a glTF file or a preset).
    pub scene: String,
    pub camera: Option<String>,
    /// Exit after this many rendered frames.
    pub exit_after_frames: Option<u64>,
    /// Save a window screenshot before exiting.
    pub screenshot: Option<PathBuf>,
    /// Start-up settings (from `--settings`); None = defaults with the preset's exposure.
    pub settings: Option<RenderSettings>,
    /// Open the light-tree statistics window at start.
    pub tree_stats: bool,
    /// The buffer shown at start (default: final).
    pub view: Option<ViewBuffer>,
    /// Start with the ground-truth comparison on.
    pub compare_gt: bool,
    /// Open the GPU timings window at start.
    pub timings: bool,
    /// Start with these views (docked in a grid) instead of the saved layout.
    pub views: Vec<ViewBuffer>,
    /// Ignore the saved layout.
    pub reset_layout: bool,
    /// Pin this frame pixel and open the pixel story window.
    pub pin: Option<(u32, u32)>,
}

/// The sun as the UI edits it (light 0 of the scene).
#[derive(Clone, Debug, PartialEq)]
pub struct SunControls {
    pub azimuth_deg: f32,
    pub elevation_deg: f32,
    /// Irradiance E in W/m^2 on a perpendicular surface (of the brightest channel).
    pub irradiance: f32,
    /// Colour, brightest channel = 1.
    pub color: [f32; 3],
}

impl SunControls {
    pub fn from_light(l: &DirectionalLight) -> Self {
        let (az, el) = l.angles_deg();
        let e = l.irradiance.max_element().max(0.0);
        let color = if e > 0.0 {
            (l.irradiance / e).to_array()
        } else {
            [1.0; 3]
        };
        Self {
            azimuth_deg: az,
            elevation_deg: el,
            irradiance: e,
            color,
        }
    }
    pub fn to_light(&self, name: &str) -> DirectionalLight {
        DirectionalLight::from_angles(
            name,
            self.azimuth_deg,
            self.elevation_deg,
            Vec3::from(self.color) * self.irradiance,
        )
    }
}

/// Everything about the open scene.
pub struct OpenScene {
    pub scene: Scene,
    pub source: String,
    pub camera: Camera,
    pub controller: CameraController,
    pub camera_index: Option<usize>,
}

impl OpenScene {
    fn new(scene: Scene, source: String, camera_name: Option<&str>) -> Result<Self, String> {
        let camera = scene.camera_or_default(camera_name)?;
        let camera_index = scene.cameras.iter().position(|c| c.name == camera.name);
        let controller = CameraController::from_camera(&camera, &scene.bounds);
        Ok(Self {
            scene,
            source,
            camera,
            controller,
            camera_index,
        })
    }
}

pub struct WorkbenchApp {
    render_state: Option<egui_wgpu::RenderState>,
    renderer: Option<Renderer>,
    open: Option<OpenScene>,
    settings: RenderSettings,
    /// The docked image views and their shared zoom / pan (saved with the app state).
    layout: Layout,
    /// What the user did in the views last frame (applied at the next frame).
    events: ViewEvents,
    /// A view export asked for this frame: (slot, spec, kind).
    pending_export: Option<(usize, crate::renderer::views::ViewSpec, ExportKind)>,
    /// Folder of exports and comparison sheets.
    export_dir: String,
    /// The files the last export wrote (shown in the side panel).
    last_export: String,
    sun: Option<SunControls>,
    /// Render resolution = largest view's pixels x this.
    render_scale: f32,
    timings: Option<PassTimings>,
    /// Messages shown in the error window until dismissed (each once).
    errors: Vec<String>,
    scene_path_input: String,
    options: AppOptions,
    frames: u64,
    screenshot_done: Arc<AtomicBool>,
    screenshot_requested: bool,
    last_frame_time: Option<f64>,
    frame_ms_smoothed: f64,
    adapter: String,
    tree_panel: TreePanel,
    sampling_stats: Option<crate::renderer::passes::slc::SamplingStats>,
    cut_inspect: Option<CutInspect>,
    /// Run the ground truth of the same VPLs beside a tree sampler.
    compare_gt: bool,
    compare_metrics: Option<crate::metrics::Metrics>,
    last_metrics_time: f64,
    timings_panel: TimingsPanel,
    /// A view shown while a pass is hovered in the timings window.
    hover_view: Option<ViewBuffer>,
    pixel: PixelInspect,
    story: story_panel::StoryPanel,
    anim: Animation,
    /// The comparison sheet being made (one frame per UI frame), its progress, and its setup.
    sheet_job: Option<crate::sheet::SheetJob>,
    sheet_status: Option<(f32, String)>,
    cancel_sheet: bool,
    sheet_methods: [bool; 4],
    sheet_frames: u32,
    bookmark_name: String,
    bookmark_note: String,
    /// The GI method to return to when a progressive one (ground truth, reference) is stopped.
    last_fast_method: GiMethod,
}

/// The dynamic scene: the sun's azimuth sweep and the camera's orbit path, per rendered frame;
/// pause and single steps.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Animation {
    /// Degrees the sun's azimuth advances per frame (0 = still).
    pub sun_deg_per_frame: f32,
    /// Degrees the orbit camera turns about its target per frame (0 = still).
    pub orbit_deg_per_frame: f32,
    /// No new frames (the views keep the last one) until unpaused or stepped.
    pub paused: bool,
    /// Render one frame while paused.
    pub step: bool,
}

/// Values of every buffer at the hovered (or pinned) frame pixel.
#[derive(Default)]
struct PixelInspect {
    show: bool,
    pinned: bool,
    pixel: Option<(u32, u32)>,
    rows: Vec<(&'static str, [f32; 4])>,
    /// The pixel and time of the last readback (it blocks: at most 4 per second for one pixel).
    read: Option<((u32, u32), f64)>,
}

/// The cut listed after a click in the cut views.
struct CutInspect {
    block: (u32, u32),
    /// (node id, node, usable).
    rows: Vec<(u32, SstNode, bool)>,
    leaves: u32,
    /// Luminance of the root's flux (every VPL).
    root_flux: f32,
}

impl WorkbenchApp {
    pub fn new(cc: &eframe::CreationContext<'_>, options: AppOptions) -> Self {
        let tree_stats = options.tree_stats;
        let start_compare = options.compare_gt;
        let start_timings = options.timings;
        let settings: RenderSettings = options.settings.clone().unwrap_or_default();
        let mut layout = None;
        if !options.reset_layout
            && options.views.is_empty()
            && options.view.is_none()
            && let Some(storage) = cc.storage
        {
            layout = eframe::get_value::<Layout>(storage, LAYOUT_KEY);
        }
        let layout = layout.unwrap_or_else(|| {
            let mut views = options.views.clone();
            if let Some(v) = options.view {
                views.insert(0, v);
            }
            Layout::new(&views, &settings.display)
        });
        let mut app = Self {
            render_state: cc.wgpu_render_state.clone(),
            renderer: None,
            open: None,
            settings,
            layout,
            events: ViewEvents::default(),
            pending_export: None,
            export_dir: "screenshots".to_string(),
            last_export: String::new(),
            sun: None,
            render_scale: 1.0,
            timings: None,
            errors: Vec::new(),
            scene_path_input: if options.scene == "default" {
                String::new()
            } else {
                options.scene.clone()
            },
            options,
            frames: 0,
            screenshot_done: Arc::new(AtomicBool::new(false)),
            screenshot_requested: false,
            last_frame_time: None,
            frame_ms_smoothed: 0.0,
            adapter: String::new(),
            tree_panel: TreePanel::new(tree_stats),
            sampling_stats: None,
            cut_inspect: None,
            compare_gt: start_compare,
            compare_metrics: None,
            last_metrics_time: 0.0,
            timings_panel: TimingsPanel::new(start_timings),
            hover_view: None,
            pixel: PixelInspect::default(),
            story: story_panel::StoryPanel::new(),
            anim: Animation::default(),
            sheet_job: None,
            sheet_status: None,
            cancel_sheet: false,
            sheet_methods: [true, true, true, false],
            sheet_frames: 8,
            bookmark_name: "bookmark 1".into(),
            bookmark_note: String::new(),
            last_fast_method: GiMethod::Off,
        };
        let Some(rs) = app.render_state.clone() else {
            app.errors.push(format!(
                "The workbench needs the wgpu renderer and got none: {}",
                crate::renderer::context::NO_ADAPTER_HELP
            ));
            return app;
        };
        let info = rs.adapter.get_info();
        app.adapter = describe_adapter(&info);
        if info.device_type == wgpu::DeviceType::Cpu {
            // Software rasterisers: keep the viewport interactive.
            app.render_scale = 0.5;
        }
        if let Some(p) = app.options.pin {
            app.pin_pixel(p.0, p.1);
        }
        let source = app.options.scene.clone();
        let camera = app.options.camera.clone();
        if let Err(e) = app.open_scene(&source, camera.as_deref()) {
            app.errors.push(e);
            if source != "default"
                && let Err(e) = app.open_scene("default", None)
            {
                app.errors.push(e);
            }
        }
        app
    }

    /// Opens a scene; on failure the previous scene stays and the message is returned.
    pub fn open_scene(&mut self, source: &str, camera: Option<&str>) -> Result<(), String> {
        let Some(rs) = self.render_state.clone() else {
            return Err("no GPU renderer".into());
        };
        let opened = open_scene(&SceneSource::from_arg(source))
            .map_err(|e| format!("Could not open '{source}': {e}"))?;
        let camera = camera.map(str::to_string).or(opened.camera_name.clone());
        let open = OpenScene::new(opened.scene, source.to_string(), camera.as_deref())
            .map_err(|e| format!("Could not open '{source}': {e}"))?;
        if self.options.settings.is_none() {
            self.settings.display.exposure_ev = opened.exposure_ev;
        }
        match &mut self.renderer {
            Some(r) => {
                r.load_scene(&open.scene);
                let _ = r.set_settings(self.settings.clone());
            }
            None => {
                let ctx = GpuContext::from_parts(rs.device.clone(), rs.queue.clone(), rs.adapter.get_info());
                let r = Renderer::new(ctx, &open.scene, (64, 64), self.settings.clone())
                    .map_err(|e| e.to_string())?;
                self.renderer = Some(r);
            }
        }
        self.sun = open.scene.lights.first().map(SunControls::from_light);
        self.open = Some(open);
        Ok(())
    }

    /// The buffer of the main view (the lowest-numbered one).
    pub fn view(&self) -> ViewBuffer {
        self.layout
            .main_pane()
            .map_or(ViewBuffer::Final, |p| p.spec.buffer)
    }
    pub fn set_view(&mut self, v: ViewBuffer) {
        if let Some(p) = self.layout.main_pane_mut() {
            p.spec.buffer = v;
        }
    }
    /// The animation state (sun sweep, camera orbit, pause).
    pub fn animation_mut(&mut self) -> &mut Animation {
        &mut self.anim
    }
    /// Starts a comparison sheet of `methods` (`frames` accumulated each) on the current view;
    /// it runs one frame per UI frame and is written to the export folder.
    pub fn start_sheet(&mut self, methods: Vec<GiMethod>, frames: u32) {
        let title = self
            .open
            .as_ref()
            .map(|o| format!("{} · camera {}", o.source, o.camera.name))
            .unwrap_or_default();
        match crate::sheet::SheetJob::new(self.settings.clone(), methods, frames, None, title) {
            Ok(job) => {
                self.sheet_job = Some(job);
                self.sheet_status = Some((0.0, "starting".into()));
            }
            Err(e) => self.errors.push(format!("comparison sheet: {e}")),
        }
    }
    /// Progress of the running comparison sheet (None: none runs).
    pub fn sheet_progress(&self) -> Option<&(f32, String)> {
        self.sheet_status.as_ref()
    }
    /// Cancels the running comparison sheet (at the next frame).
    pub fn cancel_sheet(&mut self) {
        self.cancel_sheet = true;
    }
    /// What the last export wrote.
    pub fn last_export(&self) -> &str {
        &self.last_export
    }
    /// The settings the next frame renders with.
    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }
    /// Replaces the settings (as the side panel's controls do).
    pub fn set_settings(&mut self, s: RenderSettings) {
        self.settings = s;
    }
    /// Pins frame pixel (x, y) and opens the pixel story (as a click on a camera view does).
    pub fn pin_pixel(&mut self, x: u32, y: u32) {
        self.pixel.pixel = Some((x, y));
        self.pixel.pinned = true;
        self.story.show = true;
    }
    /// The pixel story of the pinned pixel (last read).
    pub fn story(&self) -> &story_panel::StoryPanel {
        &self.story
    }
    /// The docked views.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }
    pub fn layout_mut(&mut self) -> &mut Layout {
        &mut self.layout
    }
    pub fn renderer(&self) -> Option<&Renderer> {
        self.renderer.as_ref()
    }
    pub fn open(&self) -> Option<&OpenScene> {
        self.open.as_ref()
    }
    pub fn errors(&self) -> &[String] {
        &self.errors
    }
    pub fn frames(&self) -> u64 {
        self.frames
    }

    fn side_panel(&mut self, ui: &mut egui::Ui) {
        egui::ScrollArea::vertical().show(ui, |ui| {
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
                if ui.button("default").clicked() {
                    choice = Some("default".to_string());
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
                                open.controller =
                                    CameraController::from_camera(&open.camera, &open.scene.bounds);
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
            ui.separator();
            ui.heading("View");
            let mut main = self.view();
            egui::ComboBox::from_label("buffer")
                .height(600.0)
                .selected_text(main.name())
                .show_ui(ui, |ui| {
                    for v in ViewBuffer::ALL {
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
                    let spec = crate::renderer::views::ViewSpec::new(ViewBuffer::Indirect, &self.settings.display);
                    self.layout.add_view(spec);
                }
                if ui
                    .button("+ A/B view")
                    .on_hover_text("compare two images: live buffers or snapshots")
                    .clicked()
                {
                    let spec =
                        crate::renderer::views::ViewSpec::new(ViewBuffer::AbCompare, &self.settings.display);
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
                ui.add(
                    egui::Slider::new(&mut self.settings.display.pyramid_level, 0..=12).text("pyramid level"),
                );
            }
            ui.horizontal(|ui| {
                ui.checkbox(&mut self.settings.display.vpl_overlay, "show VPLs");
                ui.add(
                    egui::Slider::new(&mut self.settings.display.vpl_point_size, 0..=6).text("point size"),
                );
            });
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
            let hint = if crate::renderer::shaders::ShaderSourceDisk::reload_from_disk() {
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
                ui.checkbox(&mut self.settings.sampling.fixed_seed, "fixed seed")
                    .on_hover_text("the samplers draw the same random numbers every frame");
            });
            ui.separator();
            ui.heading("Global illumination");
            let g = &mut self.settings.gi;
            egui::ComboBox::from_label("method")
                .selected_text(g.method.name())
                .show_ui(ui, |ui| {
                    for m in GiMethod::ALL {
                        ui.selectable_value(&mut g.method, m, m.name());
                    }
                });
            if let Some(p) = self.renderer.as_ref().and_then(|r| r.gi_progress()) {
                ui.horizontal(|ui| {
                    ui.add(
                        egui::ProgressBar::new(p.fraction())
                            .desired_width(200.0)
                            .text(match g.method {
                                GiMethod::Reference => format!("{} / {} samples per pixel", p.done, p.total),
                                _ => format!("{} / {} VPLs", p.done, p.total),
                            })
                            .show_percentage(),
                    );
                    if !p.finished()
                        && ui
                            .button("stop")
                            .on_hover_text(format!("back to {}", self.last_fast_method.name()))
                            .clicked()
                    {
                        g.method = self.last_fast_method;
                    }
                });
            }
            if matches!(
                g.method,
                GiMethod::GroundTruth | GiMethod::Slc | GiMethod::Sst | GiMethod::Rtslc
            ) {
                ui.checkbox(&mut g.shadow_rays, "shadow rays").on_hover_text(
                    "off: every VPL and cluster sample counts as visible (unshadowed GI: light \
                     through walls; the GPU timings then show the cost without visibility)",
                );
            }
            match g.method {
                GiMethod::GroundTruth => {
                    ui.add(
                        egui::Slider::new(&mut g.rays_per_frame, 1 << 14..=1 << 26)
                            .logarithmic(true)
                            .text("shadow rays / frame"),
                    )
                    .on_hover_text("more finishes sooner, but each frame takes longer");
                }
                GiMethod::Reference => {
                    ui.add(
                        egui::Slider::new(&mut g.reference_samples, 16..=65536)
                            .logarithmic(true)
                            .text("samples per pixel"),
                    );
                    ui.add(egui::Slider::new(&mut g.reference_spp_per_frame, 1..=64).text("samples / frame"));
                    ui.add(
                        egui::Slider::new(&mut g.reference_flux_mix, 0.01..=1.0).text("reference flux mix"),
                    )
                    .on_hover_text("share of the texel PDF that follows flux (> 0 keeps it unbiased)");
                }
                GiMethod::Slc | GiMethod::Sst | GiMethod::Rtslc => {
                    let sm = &mut self.settings.sampling;
                    let cut_label = if g.method == GiMethod::Sst {
                        "samples per pixel"
                    } else {
                        "cut size (samples per pixel)"
                    };
                    ui.add(egui::Slider::new(&mut sm.cut_size, 1..=64).text(cut_label));
                    if g.method != GiMethod::Sst {
                        ui.add(egui::Slider::new(&mut sm.block_size, 1..=64).text("cut block k (pixels)"))
                            .on_hover_text("one shallow light cut per k x k block (1 = per pixel)");
                        egui::ComboBox::from_label("cut blending")
                            .selected_text(sm.blending.name())
                            .show_ui(ui, |ui| {
                                for b in CutBlending::ALL {
                                    ui.selectable_value(&mut sm.blending, b, b.name());
                                }
                            });
                        egui::ComboBox::from_label("no similar cut")
                            .selected_text(sm.fallback.name())
                            .show_ui(ui, |ui| {
                                for f in CutFallback::ALL {
                                    ui.selectable_value(&mut sm.fallback, f, f.name());
                                }
                            });
                        ui.checkbox(&mut sm.cull_behind, "cull nodes behind the block centre")
                            .on_hover_text("thesis 5.1; off keeps every cut complete (unbiased)");
                    }
                    if g.method != GiMethod::Rtslc {
                        ui.add(egui::Slider::new(&mut sm.near_field, 0.0..=4.0).text("near-field refinement"))
                            .on_hover_text(
                                "stop at a usable node only when the point is at least this many box \
                                 diagonals from its box (0 = the thesis's rule): substitute samples \
                                 next to the point turn into fireflies",
                            );
                        ui.add(
                            egui::Slider::new(&mut sm.substitute_offset, 0.0..=0.3)
                                .suffix(" m")
                                .text("substitute ray offset"),
                        )
                        .on_hover_text(
                            "substitute samples' shadow rays end this far short of the drawn point \
                             (the SST paper's scene-size epsilon; 0 = the thesis): drawn points land \
                             slightly inside geometry; too large leaks light through thin walls",
                        );
                    }
                    egui::ComboBox::from_label("child probability")
                        .selected_text(sm.child_probability.name())
                        .show_ui(ui, |ui| {
                            for c in ChildProbability::ALL {
                                ui.selectable_value(&mut sm.child_probability, c, c.name());
                            }
                        })
                        .response
                        .on_hover_text(
                            "how a traversal step picks a child: eq. 5.5's weights with the distance to \
                             each child's mean (thesis); RTSLC's average of the closest- and \
                             farthest-point box distances; or (default) the thesis's mixed with 20% \
                             of the closest-point one, which keeps VPLs next to the point from being \
                             drawn rarely (fireflies)",
                        );
                    ui.checkbox(&mut sm.half_resolution, "half-resolution GI (bilateral upsampling)");
                    ui.checkbox(&mut sm.accumulate, "accumulate frames while static");
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
                    if let Some(st) = self.sampling_stats {
                        ui.label(format!(
                            "{:.2} steps per traversal · {:.1} per pixel · {:.2}% pixels without a similar cut · {} dead branches",
                            st.steps_per_traversal(),
                            st.steps_per_pixel(),
                            100.0 * st.fallback_fraction(),
                            st.dead
                        ));
                    }
                }
                GiMethod::Off => {}
            }
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
            ui.separator();
            let levels = self.renderer.as_ref().map(|r| r.tree_buffers().1.levels());
            self.tree_panel.controls(ui, &mut self.settings, levels);
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
                for (i, m) in [GiMethod::Slc, GiMethod::Rtslc, GiMethod::Sst, GiMethod::Reference]
                    .into_iter()
                    .enumerate()
                {
                    ui.checkbox(&mut self.sheet_methods[i], m.name());
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
                let methods: Vec<GiMethod> = [GiMethod::Slc, GiMethod::Rtslc, GiMethod::Sst, GiMethod::Reference]
                    .into_iter()
                    .zip(self.sheet_methods)
                    .filter_map(|(m, on)| on.then_some(m))
                    .collect();
                self.start_sheet(methods, self.sheet_frames);
            }
            if !self.last_export.is_empty() {
                ui.label(egui::RichText::new(format!("wrote {}", self.last_export)).small());
            }
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
        });
    }

    /// One line of fixed height (so the layout never jumps with the length of the timings):
    /// the adapter, resolution, VPLs and frame time first, then the per-pass GPU times,
    /// truncated to the window; hovering shows every pass.
    fn status_bar(&self, ui: &mut egui::Ui) {
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
            ui.label(format!("frame {:.1} ms", self.frame_ms_smoothed));
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
                        ui.label(format!("total {:.3} ms", t.total_ms()));
                    });
            } else {
                ui.label("GPU timings pending");
            }
        });
    }

    fn viewport(&mut self, ui: &mut egui::Ui) {
        let avail = ui.available_size();
        let ppp = ui.ctx().pixels_per_point();
        let (Some(rs), Some(open)) = (self.render_state.clone(), self.open.as_mut()) else {
            ui.centered_and_justified(|ui| ui.label("No scene is open."));
            return;
        };
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
        if !matches!(
            self.settings.gi.method,
            GiMethod::GroundTruth | GiMethod::Reference
        ) {
            self.last_fast_method = self.settings.gi.method;
        }

        // The views' input of the last frame -> camera.
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
        }
        if open.camera_index.is_none() {
            open.controller.apply(&mut open.camera);
        }

        let lights = lights_with_sun(&open.scene, self.sun.as_ref());
        let comparing = self.compare_gt && self.settings.gi.method.samples_tree() && !job_running;
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
                        Ok(files) => self.last_export = files,
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
        let now = ui.input(|i| i.time);
        // Live metrics against the finished comparison ground truth (twice a second).
        if comparing
            && now - self.last_metrics_time > 0.5
            && renderer.compare_progress().is_some_and(|p| p.finished())
        {
            self.last_metrics_time = now;
            let look = crate::renderer::views::ViewLook::from_display(&self.settings.display);
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
        if self.settings.gi.method.samples_tree() {
            self.sampling_stats = renderer.sampling_stats();
        }
        for e in renderer.ctx.errors.take() {
            if !self.errors.contains(&e) {
                self.errors.push(e);
            }
        }

        // The docked views.
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
                render_state: &rs,
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

        // A/B metrics (whole pair and rectangle), twice a second per view.
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
        // Pixel values under the pointer (camera-space views; P pins / unpins, a click pins).
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
        // Clicking a block in the cut views lists its cut.
        if let Some(c) = events.click
            && matches!(c.buffer, ViewBuffer::CutBlocks | ViewBuffer::CutDepth)
        {
            let (px, py) = c.texel;
            let b = renderer.slc_buffers();
            let block = (py / b.block) * b.grid.0 + px / b.block;
            let (bx, by) = (px / b.block, py / b.block);
            renderer.select_block(Some(block));
            match (renderer.read_cut(block), renderer.read_tree()) {
                (Ok(cut), Ok((nodes, flags))) => {
                    self.cut_inspect = Some(CutInspect {
                        block: (bx, by),
                        rows: cut
                            .iter()
                            .map(|&n| {
                                let node = nodes.get(n as usize).copied().unwrap_or(SstNode::EMPTY);
                                (n, node, crate::reference::sst_tree::flag(&flags, n as usize))
                            })
                            .collect(),
                        leaves: (nodes.len() / 2) as u32,
                        root_flux: nodes.get(1).map_or(0.0, |r| luminance(r.intensity)),
                    })
                }
                (Err(e), _) | (_, Err(e)) => self.errors.push(format!("reading the cut: {e}")),
            }
        }
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

    /// Replaces the views by a grid of `buffers` (zoom to fit).
    pub fn reset_layout(&mut self, buffers: &[ViewBuffer]) {
        if let Some(rs) = &self.render_state {
            for p in self.layout.panes_mut() {
                p.rt.texture.free(rs);
            }
        }
        self.layout = Layout::new(buffers, &self.settings.display);
    }

    /// Folder of exports (created on first use).
    pub fn set_export_dir(&mut self, dir: &str) {
        self.export_dir = dir.to_string();
    }

    /// Writes a view as displayed (PNG) or the linear buffer behind it (EXR; A and B of an
    /// A/B view) into the export folder; the files written, or the problem, are reported.
    pub fn export_view(
        &mut self,
        slot: usize,
        spec: &crate::renderer::views::ViewSpec,
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
                files
            }
            Err(e) => {
                self.errors.push(format!("export: {e}"));
                Vec::new()
            }
        }
    }

    /// The values of every buffer at the inspected pixel.
    fn pixel_window(&mut self, ctx: &egui::Context) {
        if !self.pixel.show {
            return;
        }
        let mut open = true;
        let p = &mut self.pixel;
        let title = match p.pixel {
            Some((x, y)) => format!("Pixel ({x}, {y}){}", if p.pinned { " · pinned" } else { "" }),
            None => "Pixel values".to_string(),
        };
        egui::Window::new("Pixel values")
            .open(&mut open)
            .default_width(430.0)
            .show(ctx, |ui| {
                ui.label(title);
                ui.checkbox(&mut p.pinned, "pinned (P)");
                if p.rows.is_empty() {
                    ui.label("hover the image (camera-space views)");
                    return;
                }
                egui::Grid::new("pixel_grid").striped(true).show(ui, |ui| {
                    for h in ["buffer", "r / x", "g / y", "b / z", "a / w"] {
                        ui.strong(h);
                    }
                    ui.end_row();
                    for (name, v) in &p.rows {
                        ui.label(*name);
                        for c in v {
                            ui.label(egui::RichText::new(format!("{c:.5e}")).monospace());
                        }
                        ui.end_row();
                    }
                });
            });
        if !open {
            self.pixel.show = false;
        }
    }

    /// The nodes of the clicked block's cut.
    fn cut_window(&mut self, ctx: &egui::Context) {
        let Some(ci) = &self.cut_inspect else { return };
        let mut open = true;
        egui::Window::new(format!("Cut of block ({}, {})", ci.block.0, ci.block.1))
            .open(&mut open)
            .default_width(420.0)
            .show(ctx, |ui| {
                if ci.rows.is_empty() {
                    ui.label("empty: the block centre sees no geometry, or no node can light it");
                    return;
                }
                let total: f32 = ci.rows.iter().map(|r| luminance(r.1.intensity)).sum();
                ui.label(format!(
                    "{} nodes; share of the root's flux: {:.1}%",
                    ci.rows.len(),
                    100.0 * total / ci.root_flux.max(1e-30)
                ));
                egui::ScrollArea::vertical().max_height(360.0).show(ui, |ui| {
                    egui::Grid::new("cut_grid").striped(true).show(ui, |ui| {
                        for h in [
                            "slot",
                            "node",
                            "level",
                            "flux (lum., W)",
                            "v",
                            "σ_z (m)",
                            "usable",
                        ] {
                            ui.strong(h);
                        }
                        ui.end_row();
                        for (i, (n, node, usable)) in ci.rows.iter().enumerate() {
                            ui.label(i.to_string());
                            ui.label(n.to_string());
                            let level = n.ilog2();
                            let leaf = *n >= ci.leaves;
                            ui.label(if leaf {
                                format!("{level} (leaf)")
                            } else {
                                level.to_string()
                            });
                            ui.label(format!("{:.5}", luminance(node.intensity)));
                            ui.label(format!("{:.3}", node.v));
                            ui.label(format!("{:.4}", node.sigma_z()));
                            ui.label(if *usable { "yes" } else { "no" });
                            ui.end_row();
                        }
                    });
                });
            });
        if !open {
            self.cut_inspect = None;
            if let Some(r) = &mut self.renderer {
                r.select_block(None);
            }
        }
    }

    fn error_window(&mut self, ctx: &egui::Context) {
        if self.errors.is_empty() {
            return;
        }
        let mut dismiss = false;
        egui::Window::new("Problems")
            .collapsible(false)
            .default_width(420.0)
            .show(ctx, |ui| {
                for e in &self.errors {
                    ui.label(egui::RichText::new(e).color(ui.visuals().warn_fg_color));
                }
                if ui.button("Dismiss").clicked() {
                    dismiss = true;
                }
            });
        if dismiss {
            self.errors.clear();
        }
    }

    fn handle_exit(&mut self, ctx: &egui::Context) {
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

/// A false-colour scale bar in the lower left of `rect`, labelled in powers of ten.
#[derive(Clone, Copy, PartialEq)]
enum Scale {
    /// Labels 10^lo .. 10^hi, one per decade.
    Log10,
    /// Labels lo .. hi, evenly (at most 7 ticks).
    Linear,
}

/// A false-colour legend in the bottom-left corner of `rect`.
fn legend_with(painter: &egui::Painter, rect: egui::Rect, title: &str, lo: f32, hi: f32, scale: Scale) {
    let w = 220.0;
    let bar = egui::Rect::from_min_size(rect.left_bottom() + egui::vec2(12.0, -34.0), egui::vec2(w, 12.0));
    painter.rect_filled(
        bar.expand2(egui::vec2(6.0, 22.0))
            .translate(egui::vec2(0.0, -8.0)),
        4.0,
        egui::Color32::from_black_alpha(170),
    );
    let steps = 64;
    for k in 0..steps {
        let t = (k as f32 + 0.5) / steps as f32;
        let c = crate::reference::visualise::false_color(t);
        let [r, g, b] = c.map(|v| (v * 255.0) as u8);
        let x0 = bar.left() + w * k as f32 / steps as f32;
        painter.rect_filled(
            egui::Rect::from_min_max(
                egui::pos2(x0, bar.top()),
                egui::pos2(x0 + w / steps as f32 + 0.5, bar.bottom()),
            ),
            0.0,
            egui::Color32::from_rgb(r, g, b),
        );
    }
    let font = egui::FontId::proportional(11.0);
    let text = egui::Color32::from_gray(230);
    painter.text(
        bar.left_top() - egui::vec2(0.0, 3.0),
        egui::Align2::LEFT_BOTTOM,
        title,
        font.clone(),
        text,
    );
    let ticks = match scale {
        Scale::Log10 => (hi - lo).round().max(1.0) as i32,
        Scale::Linear => {
            let span = (hi - lo).max(1e-6);
            let mut n = span.round().max(1.0) as i32;
            while n > 6 {
                n = (n + 1) / 2;
            }
            n
        }
    };
    for d in 0..=ticks {
        let x = bar.left() + w * d as f32 / ticks as f32;
        let label = match scale {
            Scale::Log10 => match lo as i32 + d {
                0 => "1".to_string(),
                e if e > 0 => format!("{}", 10i64.pow(e as u32)),
                e => format!("1e{e}"),
            },
            Scale::Linear => {
                let v = lo + (hi - lo) * d as f32 / ticks as f32;
                if (v - v.round()).abs() < 1e-3 {
                    format!("{}", v.round() as i64)
                } else {
                    format!("{v:.1}")
                }
            }
        };
        painter.text(
            egui::pos2(x, bar.bottom() + 2.0),
            egui::Align2::CENTER_TOP,
            label,
            font.clone(),
            text,
        );
    }
}

fn lights_with_sun(scene: &Scene, sun: Option<&SunControls>) -> Vec<DirectionalLight> {
    let mut lights = scene.lights.clone();
    if let (Some(sun), Some(l0)) = (sun, lights.first_mut()) {
        *l0 = sun.to_light(&l0.name);
    }
    lights
}

/// Metrics of A against B (the display transform of `look` for SSIM and FLIP), and of the
/// rectangle [x0, y0, x1, y1] when one is given; None when either image does not exist now.
type AbMetrics = (crate::metrics::Metrics, Option<crate::metrics::Metrics>);
fn ab_metrics(
    r: &Renderer,
    a: AbSource,
    b: AbSource,
    look: &crate::renderer::views::ViewLook,
    rect: Option<[u32; 4]>,
) -> Result<Option<AbMetrics>, crate::renderer::context::GpuError> {
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

/// A file name in `dir` that does not exist yet: `stem_NNN.ext`.
fn fresh_path(dir: &std::path::Path, stem: &str, ext: &str) -> PathBuf {
    let slug: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    let mut n = 0;
    loop {
        let p = dir.join(format!("{slug}_{n:03}.{ext}"));
        if !p.exists() {
            return p;
        }
        n += 1;
    }
}

/// Writes a comparison sheet (PNG + JSON of its metrics) into `dir`; returns the paths.
pub fn write_sheet(sheet: &crate::sheet::Sheet, dir: &std::path::Path) -> Result<String, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let canvas = crate::sheet::compose(sheet)?;
    let png = fresh_path(dir, "comparison sheet", "png");
    crate::export::write_png(&png, canvas.width, canvas.height, &canvas.rgba).map_err(|e| e.to_string())?;
    let json = png.with_extension("json");
    std::fs::write(&json, crate::sheet::metrics_json(sheet))
        .map_err(|e| format!("cannot write {}: {e}", json.display()))?;
    Ok(format!("{}, {}", png.display(), json.display()))
}

/// The files of one view export (see [`WorkbenchApp::export_view`]).
pub fn export_view_files(
    r: &Renderer,
    slot: usize,
    spec: &crate::renderer::views::ViewSpec,
    kind: ExportKind,
    dir: &std::path::Path,
) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let name = spec.buffer.name();
    match kind {
        ExportKind::Png => {
            let (w, h, bytes) = r.read_view_rgba8_at(slot).map_err(|e| e.to_string())?;
            let path = fresh_path(dir, name, "png");
            crate::export::write_png(&path, w, h, &bytes).map_err(|e| e.to_string())?;
            Ok(vec![path])
        }
        ExportKind::Exr => {
            let images = match spec.effective_ab() {
                Some(ab) => vec![
                    (format!("{name} A {}", ab.a.name()), r.read_ab_source(ab.a)),
                    (format!("{name} B {}", ab.b.name()), r.read_ab_source(ab.b)),
                ],
                None => vec![(name.to_string(), r.read_view_buffer(spec.buffer))],
            };
            let mut files = Vec::new();
            for (stem, img) in images {
                let img = img.map_err(|e| e.to_string())?.ok_or_else(|| {
                    format!("'{stem}' has no linear image now (PNG export shows it as displayed)")
                })?;
                let path = fresh_path(dir, &stem, "exr");
                crate::export::write_exr(&path, &img).map_err(|e| e.to_string())?;
                files.push(path);
            }
            Ok(files)
        }
    }
}

/// Preset files shipped under `scenes/` (next to the executable's working directory).
pub fn preset_files() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir("scenes")
        .map(|rd| {
            rd.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "toml"))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// Storage key of the saved view layout.
const LAYOUT_KEY: &str = "lightcut_view_layout";

impl eframe::App for WorkbenchApp {
    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, LAYOUT_KEY, &self.layout);
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        let now = ctx.input(|i| i.time);
        if let Some(prev) = self.last_frame_time {
            let ms = (now - prev) * 1e3;
            self.frame_ms_smoothed = if self.frame_ms_smoothed == 0.0 {
                ms
            } else {
                0.9 * self.frame_ms_smoothed + 0.1 * ms
            };
        }
        self.last_frame_time = Some(now);
        egui::Panel::bottom("status").show(ui, |ui| self.status_bar(ui));
        egui::Panel::left("controls")
            .default_size(290.0)
            .show(ui, |ui| self.side_panel(ui));
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| self.viewport(ui));
        if let Some((slot, spec, kind)) = self.pending_export.take() {
            self.export_view(slot, &spec, kind);
        }
        self.cut_window(&ctx);
        self.pixel_window(&ctx);
        self.story.window(&ctx);
        self.hover_view = if self.timings_panel.show {
            self.timings_panel.window(&ctx)
        } else {
            None
        };
        if self.tree_panel.show_stats {
            self.tree_panel
                .window(&ctx, &self.settings, self.timings.as_ref());
        }
        self.error_window(&ctx);
        self.handle_exit(&ctx);
        ctx.request_repaint();
    }
}

/// Runs the GUI (blocking). Fails with one clear message when no GPU adapter is usable.
pub fn run_gui(options: AppOptions) -> anyhow::Result<()> {
    // Fail early with the fix named, rather than with eframe's surface error.
    let info = GpuContext::probe_adapter()?;
    log::info!("GPU adapter: {}", describe_adapter(&info));
    let mut wgpu_setup = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    wgpu_setup.instance_descriptor.backends =
        wgpu::Backends::from_env().unwrap_or(crate::renderer::context::BACKENDS);
    wgpu_setup.device_descriptor = Arc::new(|adapter| {
        let mut d = crate::renderer::context::device_descriptor(adapter);
        // The window surface may need large textures.
        d.required_limits.max_texture_dimension_2d = d
            .required_limits
            .max_texture_dimension_2d
            .max(8192)
            .min(adapter.limits().max_texture_dimension_2d);
        d
    });
    let native = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("lightcut-workbench")
            .with_inner_size([1280.0, 760.0]),
        renderer: eframe::Renderer::Wgpu,
        wgpu_options: egui_wgpu::WgpuConfiguration {
            wgpu_setup: egui_wgpu::WgpuSetup::CreateNew(wgpu_setup),
            ..Default::default()
        },
        ..Default::default()
    };
    eframe::run_native(
        "lightcut-workbench",
        native,
        Box::new(move |cc| Ok(Box::new(WorkbenchApp::new(cc, options)))),
    )
    .map_err(|e| {
        let msg = e.to_string();
        if msg.to_lowercase().contains("adapter") {
            anyhow::anyhow!("{}", crate::renderer::context::NO_ADAPTER_HELP)
        } else {
            anyhow::anyhow!("could not start the window: {msg}")
        }
    })
}

//! The eframe/egui workbench: viewport with camera controls, buffer selector, sun, shadow and
//! display settings, status line. Only [`viewport_texture`] touches `egui_wgpu`'s textures.

pub mod camera_control;
pub mod cut_story;
pub mod image_views;
pub mod story_panel;
pub mod temporal_panel;
pub mod timings_panel;
pub mod tree_panel;
pub mod viewport_texture;

mod exports;
mod frame;
mod recovery;
mod settings_ui;
mod side_panel;
mod tool_dock;

pub use tool_dock::Tool;
mod windows;

pub use exports::{export_view_files, preset_files, write_sheet};
use windows::{bounce_legend, legend_with};

use std::{
    path::PathBuf,
    sync::{
        Arc,
        atomic::{AtomicBool, Ordering},
    },
};

use glam::Vec3;

use crate::base::sst_node::{SstNode, luminance};
use crate::gpu::views::AbSource;
use crate::{
    renderer::{
        FrameInput, Renderer,
        context::{GpuContext, describe_adapter},
        settings::{MethodId, RenderSettings, Tonemap, ViewBuffer, VplMode},
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

/// In the GUI every n-th frame is a diagnostic (untimed) frame ([`crate::renderer::FrameMode`]).
pub const GUI_DIAGNOSTICS_EVERY: u32 = 4;

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
    /// The views when neither `views`, `view` nor a saved layout give them (the binary:
    /// [`first_screen`]; empty: one view of the final image).
    pub default_views: Vec<ViewBuffer>,
    /// Ignore the saved layout.
    pub reset_layout: bool,
    /// Pin this frame pixel and open the pixel story window.
    pub pin: Option<(u32, u32)>,
    /// Destroy the GPU device after this many frames of each window (tests the recovery from
    /// a lost device, [`WorkbenchApp::resume`], and its stop after [`MAX_DEVICE_RECOVERIES`]).
    pub lose_device_at_frame: Option<u64>,
}

/// The workbench's first screen: the final image, the method's GI, the ground truth of the
/// same VPLs (progressive) and the traversal steps. A layout with a ground-truth view starts
/// the comparison.
/// The fourth is the default method's first view (SLC's traversal steps).
pub fn first_screen() -> Vec<ViewBuffer> {
    let mut v = vec![
        ViewBuffer::Final,
        ViewBuffer::Indirect,
        ViewBuffer::GroundTruthIndirect,
    ];
    if let Some(first) = crate::methods::MethodId::default().info().views.first() {
        v.push(ViewBuffer::Method(crate::methods::MethodView::new(first.name)));
    }
    v
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
    /// The glTF file it was loaded from (capture records hash it).
    pub file: Option<PathBuf>,
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
            file: None,
            camera,
            controller,
            camera_index,
        })
    }
}

pub struct WorkbenchApp {
    /// The pixel story, pixel values, cut inspector and timings: docked or floating.
    tools: tool_dock::ToolDock,
    render_state: Option<egui_wgpu::RenderState>,
    renderer: Option<Renderer>,
    open: Option<OpenScene>,
    settings: RenderSettings,
    /// The docked image views and their shared zoom / pan (saved with the app state).
    layout: Layout,
    /// What the user did in the views last frame (applied at the next frame).
    events: ViewEvents,
    /// A view export asked for this frame: (slot, spec, kind).
    pending_export: Option<(usize, crate::gpu::views::ViewSpec, ExportKind)>,
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
    sampling_stats: Option<crate::base::traversal::TraversalStats>,
    /// The current method's statistics line (`Method::status`).
    method_status: Option<String>,
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
    /// Per method of [`sheet_candidates`]: on the comparison sheet.
    sheet_methods: Vec<bool>,
    sheet_frames: u32,
    bookmark_name: String,
    bookmark_note: String,
    /// The GI method to return to when a progressive one (ground truth, reference) is stopped.
    last_fast_method: MethodId,
    /// Where the app goes when its GPU device is lost: [`run_gui`] opens a new window with a
    /// new device and resumes it there ([`WorkbenchApp::resume`]). None: rendering stops.
    handover: Option<Handover>,
    /// Lost devices recovered from so far (at most [`MAX_DEVICE_RECOVERIES`]).
    recoveries: u32,
    /// This is the empty app left in a window whose state went to the handover.
    handed_over: bool,
    /// `frames` when this window opened (`--lose-device-at-frame` counts from it).
    window_start_frame: u64,
}

/// The slot a window whose GPU device was lost leaves its app in for the next window
/// (`Ok`), or why no next window opens (`Err`: the device was lost once more than
/// [`MAX_DEVICE_RECOVERIES`] allows).
pub type Handover = std::rc::Rc<std::cell::RefCell<Option<Result<WorkbenchApp, String>>>>;

/// How many lost devices the GUI recreates; the next loss stops it with an error (a device
/// that keeps being lost would otherwise loop).
pub const MAX_DEVICE_RECOVERIES: u32 = 3;

/// The dynamic scene: the sun's azimuth sweep and the camera's orbit path, per rendered frame;
/// pause and single steps.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Animation {
    /// Degrees the sun's azimuth advances per frame (0 = still).
    pub sun_deg_per_frame: f32,
    /// Degrees the orbit camera turns about its target per frame (0 = still).
    pub orbit_deg_per_frame: f32,
    /// The camera path through the bookmarks, played one step per rendered frame.
    pub path: temporal_panel::PathPlayer,
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
    /// Each row's depth (root 0: the perfect tree's level; the radix tree's depth).
    depths: Vec<u32>,
    /// Luminance of the root's flux (every VPL).
    root_flux: f32,
}

impl WorkbenchApp {
    pub fn new(cc: &eframe::CreationContext<'_>, options: AppOptions) -> Self {
        let start_compare = options.compare_gt;
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
            if views.is_empty() {
                views = options.default_views.clone();
            }
            Layout::new(&views, &settings.display)
        });
        // Views of the ground truth show nothing without the comparison: start it.
        let start_compare = start_compare || layout.panes().iter().any(|p| p.spec.buffer.is_compare_view());
        let mut app = Self::unbound(options, settings, layout, start_compare);
        app.render_state = cc.wgpu_render_state.clone();
        let Some(rs) = app.render_state.clone() else {
            app.errors.push(format!(
                "The workbench needs the wgpu renderer and got none: {}",
                crate::gpu::context::NO_ADAPTER_HELP
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

    /// The app's state without a GPU (no render state, renderer or scene yet).
    fn unbound(options: AppOptions, settings: RenderSettings, layout: Layout, compare_gt: bool) -> Self {
        let (tree_stats, start_timings) = (options.tree_stats, options.timings);
        Self {
            tools: tool_dock::ToolDock::default(),
            render_state: None,
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
            method_status: None,
            cut_inspect: None,
            compare_gt,
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
            sheet_methods: crate::methods::sheet_columns()
                .iter()
                .map(|m| m.per_frame())
                .collect(),
            sheet_frames: 8,
            bookmark_name: "bookmark 1".into(),
            bookmark_note: String::new(),
            last_fast_method: MethodId::default(),
            handover: None,
            recoveries: 0,
            handed_over: false,
            window_start_frame: 0,
        }
    }

    /// Opens a scene; on failure the previous scene stays and the message is returned.
    pub fn open_scene(&mut self, source: &str, camera: Option<&str>) -> Result<(), String> {
        let Some(rs) = self.render_state.clone() else {
            return Err("no GPU renderer".into());
        };
        let opened = open_scene(&SceneSource::from_arg(source))
            .map_err(|e| format!("Could not open '{source}': {e}"))?;
        let camera = camera.map(str::to_string).or(opened.camera_name.clone());
        let mut open = OpenScene::new(opened.scene, source.to_string(), camera.as_deref())
            .map_err(|e| format!("Could not open '{source}': {e}"))?;
        open.file = opened.file;
        if self.options.settings.is_none() {
            self.settings.display.exposure_ev = opened.exposure_ev;
        }
        match &mut self.renderer {
            Some(r) => {
                r.load_scene(&open.scene);
                let _ = r.set_settings(self.settings.clone());
            }
            None => self.renderer = Some(self.make_renderer(&rs, &open.scene)?),
        }
        self.sun = open.scene.lights.first().map(SunControls::from_light);
        self.open = Some(open);
        Ok(())
    }

    /// A renderer of `scene` on the window's device, with the app's settings.
    fn make_renderer(&self, rs: &egui_wgpu::RenderState, scene: &Scene) -> Result<Renderer, String> {
        let ctx = GpuContext::from_parts(rs.device.clone(), rs.queue.clone(), rs.adapter.get_info());
        let mut r = Renderer::new(ctx, scene, (64, 64), self.settings.clone()).map_err(|e| e.to_string())?;
        // Every 4th frame records the diagnostics (statistics, method views, the pixel story)
        // untimed; the GPU timings come from the other frames.
        r.set_frame_mode(crate::renderer::FrameMode::Interleaved(GUI_DIAGNOSTICS_EVERY));
        Ok(r)
    }

    /// The buffer of the main view (the lowest-numbered one).
    pub fn view(&self) -> ViewBuffer {
        self.layout
            .main_pane()
            .map_or(ViewBuffer::Final, |p| p.spec.buffer)
    }
    /// The render resolution as a fraction of the view's pixels (the side panel's slider).
    pub fn render_scale(&self) -> f32 {
        self.render_scale
    }
    /// Sets the render scale, clamped to the slider's 0.25..=1.
    pub fn set_render_scale(&mut self, scale: f32) {
        self.render_scale = if scale.is_finite() {
            scale.clamp(0.25, 1.0)
        } else {
            1.0
        };
    }
    pub fn set_view(&mut self, v: ViewBuffer) {
        if let Some(p) = self.layout.main_pane_mut() {
            p.spec.buffer = v;
        }
    }
    /// The animation state (sun sweep, camera orbit, camera path, pause).
    pub fn animation(&self) -> &Animation {
        &self.anim
    }
    /// The animation state (sun sweep, camera orbit, camera path, pause).
    pub fn animation_mut(&mut self) -> &mut Animation {
        &mut self.anim
    }
    /// Starts a comparison sheet of `methods` (`frames` accumulated each) on the current view;
    /// it runs one frame per UI frame and is written to the export folder.
    pub fn start_sheet(&mut self, methods: Vec<MethodId>, frames: u32) {
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
    /// The tools docked beside the views (the others float or are closed).
    pub fn docked_tools(&self) -> Vec<Tool> {
        self.tools.docked()
    }
    /// Whether the light-tree statistics window is open.
    pub fn tree_stats_shown(&self) -> bool {
        self.tree_panel.show_stats
    }
    pub fn frames(&self) -> u64 {
        self.frames
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
}

/// A false-colour scale bar in the lower left of `rect`, labelled in powers of ten.
#[derive(Clone, Copy, PartialEq)]
enum Scale {
    /// Labels 10^lo .. 10^hi, one per decade.
    Log10,
    /// Labels lo .. hi, evenly (at most 7 ticks).
    Linear,
}

/// Metrics of A against B (the display transform of `look` for SSIM and FLIP), and of the
/// rectangle [x0, y0, x1, y1] when one is given; None when either image does not exist now.
type AbMetrics = (crate::metrics::Metrics, Option<crate::metrics::Metrics>);
/// Storage key of the saved view layout.
const LAYOUT_KEY: &str = "lightcut_view_layout";

impl eframe::App for WorkbenchApp {
    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        // The empty app of a window whose device was lost: the layout went on with the app.
        if !(self.handed_over && self.renderer.is_none()) {
            eframe::set_value(storage, LAYOUT_KEY, &self.layout);
        }
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.lose_device_if_asked();
        // Nothing is drawn in a window whose device is lost: egui-wgpu 0.37 panics when it
        // cannot upload a frame's vertices to a lost device, and an empty frame has none.
        if self.hand_over_if_lost(&ctx) {
            return;
        }
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
        let dock_hover = self.tool_dock(ui);
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| self.viewport(ui));
        if let Some((slot, spec, kind)) = self.pending_export.take() {
            self.export_view(slot, &spec, kind);
        }
        let float_hover = self.tool_windows(&ctx);
        self.hover_view = if self.timings_panel.show {
            dock_hover.or(float_hover)
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
        // A loss met during this frame's work: its shapes are dropped before they are painted.
        self.hand_over_if_lost(&ctx);
    }
}

/// Runs the GUI (blocking). Fails with one clear message when no GPU adapter is usable.
pub fn run_gui(options: AppOptions) -> anyhow::Result<()> {
    // Fail early with the fix named, rather than with eframe's surface error.
    let info = GpuContext::probe_adapter()?;
    log::info!("GPU adapter: {}", describe_adapter(&info));
    let mut wgpu_setup = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    wgpu_setup.instance_descriptor.backends =
        wgpu::Backends::from_env().unwrap_or(crate::gpu::context::BACKENDS);
    wgpu_setup.device_descriptor = Arc::new(|adapter| {
        let mut d = crate::gpu::context::device_descriptor(adapter);
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
            .with_inner_size([1440.0, 900.0]),
        renderer: eframe::Renderer::Wgpu,
        wgpu_options: egui_wgpu::WgpuConfiguration {
            wgpu_setup: egui_wgpu::WgpuSetup::CreateNew(wgpu_setup),
            ..Default::default()
        },
        ..Default::default()
    };
    // Windows one after the other: a window whose device is lost leaves its app in the
    // handover, and the next window (a new instance, adapter and device) resumes it.
    let handover = Handover::default();
    let mut first = Some(options);
    let mut resumed: Option<WorkbenchApp> = None;
    loop {
        let h = handover.clone();
        let create: eframe::AppCreator<'_> = match (first.take(), resumed.take()) {
            (Some(options), _) => {
                Box::new(move |cc| Ok(Box::new(WorkbenchApp::new(cc, options).with_handover(h))))
            }
            (None, Some(app)) => Box::new(move |cc| Ok(Box::new(app.resume(cc)))),
            (None, None) => return Ok(()),
        };
        eframe::run_native("lightcut-workbench", native.clone(), create).map_err(|e| {
            let msg = e.to_string();
            if msg.to_lowercase().contains("adapter") {
                anyhow::anyhow!("{}", crate::gpu::context::NO_ADAPTER_HELP)
            } else {
                anyhow::anyhow!("could not start the window: {msg}")
            }
        })?;
        match handover.borrow_mut().take() {
            None => return Ok(()),
            Some(Ok(app)) => resumed = Some(app),
            Some(Err(stop)) => anyhow::bail!("{stop}"),
        }
    }
}

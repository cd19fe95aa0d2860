//! The frame's orchestration: [`Renderer`] runs the shared passes of [`crate::gpu`] and the
//! registered methods of [`crate::methods`] in the frame's order, and holds the frame graph,
//! the inspection readbacks and the view recording; it sits above both. Knows nothing of egui:
//! the app shows [`Renderer::view_texture`] through the one bridge module
//! `app::viewport_texture`.
//!
//! Frame order (see ARCHITECTURE.md): shadow_map -> gbuffer -> direct -> display | visualise.

// The GPU layer and the settings, below the methods, as they were reached before they moved
// out of this module (the orchestration here sits above both and the methods).
pub use crate::gpu::{
    brdf_probe, bvh_trace, context, frame, gpu_data, kernel, passes, readback, scene_gpu, shaders, soak,
    timing, views,
};
pub use crate::settings;
pub use crate::settings::temporal as temporal_settings;

mod frame_graph;
mod inspect;
mod stages;
mod view_data;
mod view_record;

use frame_graph::create_methods;
pub use view_record::depth_range;

use glam::Vec3;
use thiserror::Error;

use crate::base::sst_node::SstNode;
use crate::base::story::PixelTrace;
use crate::base::traversal::TraversalStats;
use crate::methods::{self, FrameCx, Method, MethodId, MethodView, ViewCx};
use crate::scene::{Camera, DirectionalLight, Scene};
use context::{GpuContext, GpuError};
use frame::{FrameTargets, ShadowTargets, ViewTarget};
use gpu_data::{GpuCamera, GpuLights, GpuVpl, MAX_LIGHTS};
use passes::{
    composite::{CompositeInputs, CompositePass},
    direct::DirectPass,
    display::{DisplayInputs, DisplayPass},
    gbuffer::GbufferPass,
    rsm::{RsmInputs, RsmPass},
    sst_build::{BuildInputs, BuildPass, TreeBuffers, UsableThresholds},
    sst_overlay::SstOverlayPass,
    sst_sort::{SortBuffers, SortPass},
    visualise::{VisInputs, VisMode, VisSource, VisualisePass},
    vpl_gen::{VplBuffers, VplFrame, VplGenPass},
    vpl_splat::{GpuSplatParams, VplSplatPass},
};
use readback::ImageF32;
use scene_gpu::SceneGpu;
use settings::{
    RenderSettings, TemporalMode, TemporalSettings, TemporalView, TreeKind, TreeOverlay, ViewBuffer,
};
use timing::{GpuTimer, PassTimings};
use views::{AbMode, AbSource, AbSpec, ViewLook, ViewSpec};

#[derive(Debug, Error)]
pub enum RenderError {
    #[error(transparent)]
    Shader(#[from] shaders::ShaderError),
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error("invalid setting: {0}")]
    Settings(String),
    #[error("{0}")]
    Pipeline(String),
    #[error("invalid frame size {0}x{1} (1..=8192 each)")]
    Size(u32, u32),
}

/// What a frame needs beyond the settings: the camera, the lights and the buffer to show.
pub struct FrameInput<'a> {
    pub camera: &'a Camera,
    pub lights: &'a [DirectionalLight],
    pub view: ViewBuffer,
}

/// The HDR/G-buffer buffers that can be exported or read back.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Buffer {
    Final,
    Direct,
    Indirect,
    Position,
    Normal,
    Albedo,
    Depth,
    ShadowMap(u32),
    RsmPosition(u32),
    RsmNormal(u32),
    RsmFlux(u32),
    /// The comparison ground truth's GI (empty 0x0 image when no comparison runs).
    GroundTruthIndirect,
}

pub use crate::base::progress::GiProgress;

/// Which frames record diagnostics and which are timed. A frame is one or the other, so the
/// GPU timestamps of a timed frame never include diagnostics work: the samplers' counters,
/// per-pixel statistics and pixel story, readbacks, or the comparison's ground truth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameMode {
    /// Every frame records diagnostics, untimed (the default: every statistic, story and
    /// method view read after a frame is that frame's).
    Diagnostic,
    /// Every frame timed, without diagnostics (the harness's and `render`'s timed frames).
    /// The comparison's ground truth, while it converges, records beside it untimed.
    Timed,
    /// Every `n`-th frame diagnostic (untimed), the others timed (the GUI).
    Interleaved(u32),
}

/// The comparison's truth kept beside a per-frame method (an instance of
/// [`methods::comparison_truth`]): its own accumulation and composite targets.
struct CompareState {
    truth: Box<dyn Method>,
    /// The key its image was last recorded for (a timed frame skips a finished truth whose
    /// key did not change).
    key: u64,
    targets: frame::LightingTargets,
    targets_size: (u32, u32),
}

/// A method module's GPU instance, by the module's name.
type MethodInstance = (&'static str, Box<dyn Method>);

pub struct Renderer {
    pub ctx: GpuContext,
    settings: RenderSettings,
    scene: SceneGpu,
    targets: FrameTargets,
    gbuffer: GbufferPass,
    rsm: RsmPass,
    direct: DirectPass,
    display: DisplayPass,
    visualise: VisualisePass,
    vpl_gen: VplGenPass,
    /// Bounces 2..=N of `vpl.bounces` (light paths through the BVH).
    light_paths: passes::light_paths::LightPathPass,
    composite: CompositePass,
    vpl_splat: VplSplatPass,
    sst_sort: SortPass,
    sort_buffers: SortBuffers,
    sst_build: BuildPass,
    tree: TreeBuffers,
    /// The other kind of tree over the same VPLs, for the overlay's side-by-side comparison
    /// (`display.tree_compare`), built untimed (`quiet_timer`).
    tree_other: Option<TreeBuffers>,
    /// A timer that never times (begun untimed once): passes recorded with it take no
    /// timestamps.
    quiet_timer: GpuTimer,
    sst_overlay: SstOverlayPass,
    /// One GPU instance per method module (`methods::modules()`), by module name.
    methods: Vec<MethodInstance>,
    /// Block outlined in the cut views (set by the UI).
    selected_block: Option<u32>,
    compare_on: bool,
    compare: Option<CompareState>,
    compare_views: passes::compare::CompareViewsPass,
    /// The comparison ground truth's composite: its own pass (and parameter buffer), since the
    /// sampler's composite with scale 1/frames is recorded in the same encoder.
    compare_composite: CompositePass,
    /// Temporal reuse and SVGF after a per-frame method (`settings.temporal`).
    temporal: passes::temporal::TemporalPass,
    vpl_buffers: VplBuffers,
    vpl_frame: VplFrame,
    /// The frame's lights (at most MAX_LIGHTS), for the methods.
    frame_lights: Vec<crate::scene::DirectionalLight>,
    /// The frame's BRDF (`MethodId::brdf`: Lambert where the method refuses GGX).
    frame_brdf: settings::Brdf,
    /// The frame's camera position.
    frame_eye: Vec3,
    /// Luminance of light 0's irradiance and its shadow texel size, last frame (RSM flux view).
    light0_lum: f32,
    lights_texel: f32,
    /// Light 0's RSM raster this frame (None without lights).
    rsm_raster: Option<gpu_data::RsmRaster>,
    /// The RSMs' total reflected flux (flux-pyramid tops), read back without blocking.
    flux_readback: readback::AsyncReadback,
    flux_total: Option<f32>,
    camera_buf: wgpu::Buffer,
    lights_buf: wgpu::Buffer,
    timer: GpuTimer,
    frames: u64,
    /// The method whose passes wrote the GI accumulation last: a method taking it over is
    /// reset first (a finished progressive method would otherwise keep showing, and report
    /// as its result, what another method wrote there).
    accum_owner: Option<crate::methods::MethodId>,
    frame_mode: FrameMode,
    /// Whether the last frame recorded diagnostics (else it was timed).
    last_diagnostic: bool,
    /// In `FrameMode::Interleaved`: the next frame records diagnostics whatever its number
    /// (a new pinned pixel or new settings show at once).
    diagnostic_requested: bool,
    /// Whether the last frame had VPLs (redrawing its views without a new frame).
    last_vpl_ok: bool,
    /// While frozen: the thresholds the flags were last classified with.
    freeze: Option<(f32, f32)>,
    /// View textures of the views after the first (`render_views`); the first is
    /// `targets.view`.
    extra_views: Vec<ViewTarget>,
    /// Source of unique view-texture generations (the UI re-registers a texture on change).
    view_generation: u64,
    /// Radiance buffers kept for A/B comparison.
    snapshots: Vec<views::Snapshot>,
    /// Frame pixel whose tree samples `slc_sample` records (the pixel story).
    trace_pixel: Option<(u32, u32)>,
    /// Method views drawn after the frames (`render`'s PNGs) besides the frame's own specs:
    /// a view that needs extra work in the frame (light culling's difference) gets it.
    kept_views: Vec<methods::MethodView>,
    /// The method views of this frame (`kept_views` and the specs of `render_views`).
    frame_views: Vec<methods::MethodView>,
}

/// Refuses settings whose buffers the device cannot bind (instead of failing every frame).
fn check_device_limits(device: &wgpu::Device, s: &RenderSettings, layers: u32) -> Result<(), RenderError> {
    let limit = device.limits().max_storage_buffer_binding_size;
    let need = VplBuffers::largest_binding(s.shadow.resolution, layers.max(1), s.vpl.count)
        .max(TreeBuffers::largest_binding(s.vpl.count));
    if need > limit {
        return Err(RenderError::Settings(format!(
            "shadow.resolution {} with {} VPLs needs a {} MiB storage buffer; this device binds at most {} MiB",
            s.shadow.resolution,
            s.vpl.count,
            need >> 20,
            limit >> 20
        )));
    }
    Ok(())
}

fn check_size(w: u32, h: u32) -> Result<(), RenderError> {
    if (1..=8192).contains(&w) && (1..=8192).contains(&h) {
        Ok(())
    } else {
        Err(RenderError::Size(w, h))
    }
}

impl Renderer {
    pub fn new(
        ctx: GpuContext,
        scene: &Scene,
        size: (u32, u32),
        settings: RenderSettings,
    ) -> Result<Self, RenderError> {
        settings.validate().map_err(RenderError::Settings)?;
        check_size(size.0, size.1)?;
        check_device_limits(
            &ctx.device,
            &settings,
            scene.lights.len().clamp(1, MAX_LIGHTS) as u32,
        )?;
        let device = &ctx.device;
        let uniform = |label, size: usize| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size as u64,
                usage: wgpu::BufferUsages::UNIFORM
                    | wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let lights = scene.lights.len().clamp(1, MAX_LIGHTS) as u32;
        Ok(Self {
            scene: SceneGpu::new(
                device,
                &ctx.queue,
                scene,
                settings.textures.max_size,
                settings.textures.anisotropy,
            ),
            targets: FrameTargets::new(device, size, settings.shadow.resolution, lights),
            gbuffer: GbufferPass::new(device)?,
            rsm: RsmPass::new(device)?,
            direct: DirectPass::new(device)?,
            display: DisplayPass::new(device)?,
            visualise: VisualisePass::new(device)?,
            vpl_gen: VplGenPass::new(device)?,
            light_paths: passes::light_paths::LightPathPass::new(device)?,
            composite: CompositePass::new(device)?,
            vpl_splat: VplSplatPass::new(device)?,
            sst_sort: SortPass::new(device)?,
            sort_buffers: SortBuffers::new(device, settings.vpl.count),
            sst_build: BuildPass::new(device)?,
            tree: TreeBuffers::new(device, settings.vpl.count, settings.tree.kind),
            tree_other: None,
            quiet_timer: {
                let mut t = GpuTimer::new(device, &ctx.queue);
                // Never timed: its passes write no timestamps.
                t.begin_frame(false);
                t
            },
            sst_overlay: SstOverlayPass::new(device)?,
            methods: create_methods(device)?,
            selected_block: None,
            compare_on: false,
            compare: None,
            compare_views: passes::compare::CompareViewsPass::new(device)?,
            compare_composite: CompositePass::new(device)?,
            temporal: passes::temporal::TemporalPass::new(device)?,
            vpl_buffers: VplBuffers::new(device, settings.shadow.resolution, lights, settings.vpl.count),
            vpl_frame: VplFrame::default(),
            frame_lights: Vec::new(),
            frame_brdf: settings::Brdf::Lambert,
            frame_eye: Vec3::ZERO,
            light0_lum: 0.0,
            lights_texel: 0.0,
            rsm_raster: None,
            flux_readback: readback::AsyncReadback::new(
                device,
                "vpl::flux_total_readback",
                4 * MAX_LIGHTS as u64,
            ),
            flux_total: None,
            camera_buf: uniform("frame::camera", std::mem::size_of::<GpuCamera>()),
            lights_buf: uniform("frame::lights", std::mem::size_of::<GpuLights>()),
            timer: GpuTimer::new(device, &ctx.queue),
            settings,
            frames: 0,
            accum_owner: None,
            frame_mode: FrameMode::Diagnostic,
            last_diagnostic: false,
            diagnostic_requested: false,
            last_vpl_ok: false,
            freeze: None,
            extra_views: Vec::new(),
            view_generation: 0,
            snapshots: Vec::new(),
            trace_pixel: None,
            kept_views: Vec::new(),
            frame_views: Vec::new(),
            ctx,
        })
    }

    /// Rebuilds every pass's pipelines from the shader sources (from `shaders/` on disk in
    /// debug builds: edit WGSL while the workbench runs). If any shader fails to compile, the
    /// error is returned and the last good pipelines stay in use.
    pub fn reload_shaders(&mut self) -> Result<(), RenderError> {
        let device = &self.ctx.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let passes = (
            GbufferPass::new(device),
            RsmPass::new(device),
            DirectPass::new(device),
            DisplayPass::new(device),
            VisualisePass::new(device),
            (
                VplGenPass::new(device),
                CompositePass::new(device),
                VplSplatPass::new(device),
                SortPass::new(device),
                BuildPass::new(device),
                SstOverlayPass::new(device),
                passes::compare::CompareViewsPass::new(device),
                CompositePass::new(device),
            ),
            create_methods(device),
            passes::temporal::TemporalPass::new(device),
            passes::light_paths::LightPathPass::new(device),
        );
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RenderError::Pipeline(format!("shader reload failed: {e}")));
        }
        let (g, s, d, disp, v, (vg, c, sp, so, b, ov, cv, cc), m, tp, lp) = passes;
        let new = (
            g?, s?, d?, disp?, v?, vg?, c?, sp?, so?, b?, ov?, cv?, cc?, m?, tp?, lp?,
        );
        (
            self.gbuffer,
            self.rsm,
            self.direct,
            self.display,
            self.visualise,
            self.vpl_gen,
            self.composite,
            self.vpl_splat,
            self.sst_sort,
            self.sst_build,
            self.sst_overlay,
            self.compare_views,
            self.compare_composite,
            self.methods,
            self.temporal,
            self.light_paths,
        ) = new;
        // The comparison's truth restarts with new pipelines.
        self.compare = None;
        Ok(())
    }

    /// Replaces the scene (geometry, materials, textures, BVH).
    pub fn load_scene(&mut self, scene: &Scene) {
        self.scene = SceneGpu::new(
            &self.ctx.device,
            &self.ctx.queue,
            scene,
            self.settings.textures.max_size,
            self.settings.textures.anisotropy,
        );
        // The history belongs to the old scene.
        self.temporal.invalidate();
    }

    pub fn scene_gpu(&self) -> &SceneGpu {
        &self.scene
    }

    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// Applies new settings; resources that depend on them are recreated. Out-of-range values
    /// are refused with a message and the previous settings stay.
    pub fn set_settings(&mut self, settings: RenderSettings) -> Result<(), RenderError> {
        settings.validate().map_err(RenderError::Settings)?;
        check_device_limits(&self.ctx.device, &settings, self.targets.shadow.layers())?;
        if settings.shadow.resolution != self.targets.shadow.resolution {
            self.targets.shadow = ShadowTargets::new(
                &self.ctx.device,
                settings.shadow.resolution,
                self.targets.shadow.layers(),
            );
        }
        if settings.textures.anisotropy != self.settings.textures.anisotropy {
            self.scene.sampler = scene_gpu::texture_sampler(&self.ctx.device, settings.textures.anisotropy);
        }
        if settings != self.settings {
            self.diagnostic_requested = true;
        }
        self.settings = settings;
        Ok(())
    }

    pub fn size(&self) -> (u32, u32) {
        self.targets.size
    }

    /// Which frames are timed and which record diagnostics ([`FrameMode`]).
    pub fn set_frame_mode(&mut self, mode: FrameMode) {
        self.frame_mode = match mode {
            FrameMode::Interleaved(0) => FrameMode::Timed,
            m => m,
        };
    }

    pub fn frame_mode(&self) -> FrameMode {
        self.frame_mode
    }

    /// Whether the next frame records diagnostics (and is untimed).
    fn next_frame_diagnostic(&self) -> bool {
        match self.frame_mode {
            FrameMode::Diagnostic => true,
            FrameMode::Timed => false,
            FrameMode::Interleaved(n) => {
                self.diagnostic_requested || self.frames.is_multiple_of(n.max(1) as u64)
            }
        }
    }

    /// Whether the last frame recorded diagnostics (statistics, per-pixel diagnostics and the
    /// story are that frame's; a timed frame leaves the previous diagnostic frame's).
    pub fn last_frame_diagnostic(&self) -> bool {
        self.last_diagnostic
    }

    pub fn resize(&mut self, w: u32, h: u32) -> Result<(), RenderError> {
        check_size(w, h)?;
        if (w, h) != self.targets.size {
            self.view_generation += 1;
            let gen_ = self.view_generation;
            self.targets = FrameTargets::new(
                &self.ctx.device,
                (w, h),
                self.settings.shadow.resolution,
                self.targets.shadow.layers(),
            );
            self.targets.view.generation = gen_;
        }
        Ok(())
    }
}

//! The GPU pipeline. Knows nothing of egui: the app shows [`Renderer::view_texture`] through
//! the one bridge module `app::viewport_texture`.
//!
//! Frame order (see ARCHITECTURE.md): shadow_map -> gbuffer -> direct -> display | visualise.

pub mod bvh_trace;
pub mod context;
pub mod frame;
pub mod gpu_data;
pub mod passes;
pub mod readback;
pub mod scene_gpu;
pub mod settings;
pub mod shaders;
pub mod timing;
pub mod views;

use glam::Vec3;
use thiserror::Error;

use crate::reference::sst_tree::SstNode;
use crate::scene::{Camera, DirectionalLight, Scene};
use context::{GpuContext, GpuError};
use frame::{FrameTargets, ShadowTargets, ViewTarget};
use gpu_data::{GpuCamera, GpuGtParams, GpuLights, GpuVpl, MAX_LIGHTS};
use passes::{
    composite::CompositePass,
    direct::DirectPass,
    display::DisplayPass,
    gbuffer::GbufferPass,
    ground_truth::GroundTruthPass,
    reference::{GpuRefParams, ReferencePass},
    rsm::RsmPass,
    slc::{SamplingStats, SlcBuffers, SlcPass},
    sst_build::{BuildPass, TreeBuffers},
    sst_overlay::SstOverlayPass,
    sst_sort::{SortBuffers, SortPass},
    visualise::{VisMode, VisSource, VisualisePass},
    vpl_gen::{VplBuffers, VplFrame, VplGenPass},
    vpl_splat::{GpuSplatParams, VplSplatPass},
};
use readback::ImageF32;
use scene_gpu::SceneGpu;
use settings::{GiMethod, RenderSettings, TreeOverlay, ViewBuffer};
use timing::{GpuTimer, PassTimings};
use views::{AbMode, AbSource, ViewSpec};

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

/// Progress of the progressive GI method (ground truth).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GiProgress {
    /// VPLs evaluated at every pixel so far.
    pub done: u32,
    pub total: u32,
}

impl GiProgress {
    pub fn fraction(&self) -> f32 {
        if self.total == 0 {
            1.0
        } else {
            self.done as f32 / self.total as f32
        }
    }
    pub fn finished(&self) -> bool {
        self.done >= self.total
    }
}

/// State of the ground truth between frames: a snapshot of the VPLs it evaluates, and how far
/// it got. Any change of view, lights or settings (`key`) restarts it.
struct GtState {
    key: u64,
    progress: GiProgress,
    snapshot: wgpu::Buffer,
}

/// Half-resolution G-buffer position and normal, and the sampler's demodulated sums there.
pub type HalfReadback = (ImageF32, ImageF32, Vec<[f32; 4]>);

/// The ground truth kept beside a tree sampler for comparison: its own accumulation and
/// composite targets.
struct CompareState {
    gt: Option<GtState>,
    targets: frame::LightingTargets,
    targets_size: (u32, u32),
}

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
    ground_truth: GroundTruthPass,
    composite: CompositePass,
    reference: ReferencePass,
    vpl_splat: VplSplatPass,
    sst_sort: SortPass,
    sort_buffers: SortBuffers,
    sst_build: BuildPass,
    tree: TreeBuffers,
    sst_overlay: SstOverlayPass,
    slc: SlcPass,
    slc_buffers: SlcBuffers,
    /// Accumulation of the tree samplers: (key, frames summed).
    slc_state: Option<(u64, u32)>,
    /// Block outlined in the cut views (set by the UI).
    selected_block: Option<u32>,
    compare_on: bool,
    compare: Option<CompareState>,
    compare_views: passes::compare::CompareViewsPass,
    /// The comparison ground truth's composite: its own pass (and parameter buffer), since the
    /// sampler's composite with scale 1/frames is recorded in the same encoder.
    compare_composite: CompositePass,
    slc_half: passes::slc_half::HalfPass,
    half: Option<passes::slc_half::HalfTargets>,
    vpl_buffers: VplBuffers,
    vpl_frame: VplFrame,
    gt: Option<GtState>,
    reference_state: Option<(u64, GiProgress)>,
    /// Luminance of light 0's irradiance and its shadow texel size, last frame (RSM flux view).
    light0_lum: f32,
    lights_texel: f32,
    /// The RSMs' total reflected flux (flux-pyramid tops), read back without blocking.
    flux_readback: readback::AsyncReadback,
    flux_total: Option<f32>,
    camera_buf: wgpu::Buffer,
    lights_buf: wgpu::Buffer,
    timer: GpuTimer,
    frames: u64,
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
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
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
            ground_truth: GroundTruthPass::new(device)?,
            composite: CompositePass::new(device)?,
            reference: ReferencePass::new(device)?,
            vpl_splat: VplSplatPass::new(device)?,
            sst_sort: SortPass::new(device)?,
            sort_buffers: SortBuffers::new(device, settings.vpl.count),
            sst_build: BuildPass::new(device)?,
            tree: TreeBuffers::new(device, settings.vpl.count),
            sst_overlay: SstOverlayPass::new(device)?,
            slc: SlcPass::new(device)?,
            // Sized at the first tree-sampling frame (after the device-limit check).
            slc_buffers: SlcBuffers::new(device, (1, 1), 1, 1),
            slc_state: None,
            selected_block: None,
            compare_on: false,
            compare: None,
            compare_views: passes::compare::CompareViewsPass::new(device)?,
            compare_composite: CompositePass::new(device)?,
            slc_half: passes::slc_half::HalfPass::new(device)?,
            half: None,
            vpl_buffers: VplBuffers::new(device, settings.shadow.resolution, lights, settings.vpl.count),
            vpl_frame: VplFrame::default(),
            gt: None,
            reference_state: None,
            light0_lum: 0.0,
            lights_texel: 0.0,
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
            freeze: None,
            extra_views: Vec::new(),
            view_generation: 0,
            snapshots: Vec::new(),
            trace_pixel: None,
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
                GroundTruthPass::new(device),
                CompositePass::new(device),
                ReferencePass::new(device),
                VplSplatPass::new(device),
                SortPass::new(device),
                BuildPass::new(device),
                SstOverlayPass::new(device),
                SlcPass::new(device),
                passes::compare::CompareViewsPass::new(device),
                passes::slc_half::HalfPass::new(device),
                CompositePass::new(device),
            ),
        );
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RenderError::Pipeline(format!("shader reload failed: {e}")));
        }
        let (g, s, d, disp, v, (vg, gt, c, rf, sp, so, b, ov, sl, cv, hp, cc)) = passes;
        let new = (
            g?, s?, d?, disp?, v?, vg?, gt?, c?, rf?, sp?, so?, b?, ov?, sl?, cv?, hp?, cc?,
        );
        (
            self.gbuffer,
            self.rsm,
            self.direct,
            self.display,
            self.visualise,
            self.vpl_gen,
            self.ground_truth,
            self.composite,
            self.reference,
            self.vpl_splat,
            self.sst_sort,
            self.sst_build,
            self.sst_overlay,
            self.slc,
            self.compare_views,
            self.slc_half,
            self.compare_composite,
        ) = new;
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
        self.settings = settings;
        Ok(())
    }

    pub fn size(&self) -> (u32, u32) {
        self.targets.size
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
        let device = self.ctx.device.clone();
        let queue = self.ctx.queue.clone();
        let size = self.targets.size;
        let s = self.settings.clone();

        let lights = &input.lights[..input.lights.len().min(MAX_LIGHTS)];
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
        queue.write_buffer(
            &self.camera_buf,
            0,
            bytemuck::bytes_of(&GpuCamera::new(input.camera, size.0, size.1)),
        );
        queue.write_buffer(&self.lights_buf, 0, bytemuck::bytes_of(&gpu_lights));
        self.light0_lum = lights
            .first()
            .map(|l| l.irradiance.dot(Vec3::new(0.2126, 0.7152, 0.0722)))
            .unwrap_or(1.0);
        self.lights_texel = gpu_lights.lights[0].shadow[0];

        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("frame::encoder"),
        });
        self.timer.begin_frame();
        let t = &self.targets;
        self.rsm.record(
            &device,
            &queue,
            &mut enc,
            &mut self.timer,
            &gpu_lights,
            &self.scene,
            &t.shadow,
        );
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
            &mut enc,
            &mut self.timer,
            &self.camera_buf,
            &self.lights_buf,
            &t.shadow,
            &t.gbuffer,
            &t.lighting.direct_view,
            size,
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
                    self.gt = None;
                    self.reference_state = None;
                }
            }
        }
        let seed = s
            .vpl
            .seed
            .wrapping_add(if s.vpl.animate { self.frames as u32 } else { 0 });
        let frozen = self.freeze.is_some() && vpl_ok && self.tree.count == self.vpl_frame.count;
        if frozen {
            // Frozen VPLs and tree (debugging): only the flags follow new thresholds.
            let th = (s.tree.v_min, s.tree.sigma_max);
            if self.freeze != Some(th) {
                self.sst_build.record_classify(
                    &device,
                    &queue,
                    &mut enc,
                    &mut self.timer,
                    &self.tree,
                    th.0,
                    th.1,
                );
                self.freeze = Some(th);
            }
        } else if vpl_ok {
            if self.freeze.is_some() {
                self.freeze = Some((s.tree.v_min, s.tree.sigma_max));
            }
            let t = &self.targets;
            self.vpl_frame = self.vpl_gen.record(
                &device,
                &queue,
                &mut enc,
                &mut self.timer,
                &s.vpl,
                &s.gi,
                seed,
                self.scene.bounds.radius().max(1e-3),
                lights,
                &self.camera_buf,
                &t.shadow,
                &t.gbuffer,
                &self.vpl_buffers,
            );
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
            // SST stage 10: the tree over the sorted VPLs, then its usable flags.
            if self.tree.count != self.vpl_frame.count {
                self.tree = TreeBuffers::new(&device, self.vpl_frame.count);
            }
            self.sst_build.record(
                &device,
                &queue,
                &mut enc,
                &mut self.timer,
                &self.vpl_buffers.vpls,
                &self.sort_buffers,
                &self.tree,
                s.tree.v_min,
                s.tree.sigma_max,
            );
            // The flux-pyramid tops (one float per light), read back on a later frame.
            let (per_layer, offsets) = passes::vpl_gen::pyramid_layout(self.vpl_buffers.res);
            let top = *offsets.last().unwrap_or(&0) as u64;
            let fp = &self.vpl_buffers.flux_pyramid;
            let copies: Vec<(&wgpu::Buffer, u64, u64, u64)> = (0..self.vpl_frame.ranges.len() as u64)
                .map(|l| (fp, 4 * (l * per_layer as u64 + top), 4 * l, 4))
                .collect();
            self.flux_readback.record(&mut enc, &copies);
        }
        let indirect_scale = match s.gi.method {
            _ if !vpl_ok => 0.0,
            GiMethod::Off => 0.0,
            GiMethod::GroundTruth => {
                self.step_ground_truth(&mut enc, input, lights, size);
                1.0
            }
            GiMethod::Reference => {
                let n = self.step_reference(&mut enc, input, lights, size);
                if n == 0 { 0.0 } else { 1.0 / n as f32 }
            }
            GiMethod::Slc | GiMethod::Sst | GiMethod::Rtslc => {
                let n = self.step_sampling(&mut enc, input, lights, size);
                if self.compare_on {
                    self.step_compare(&mut enc, input, lights, size);
                }
                1.0 / n.max(1) as f32
            }
        };
        let t = &self.targets;
        self.composite.record(
            &device,
            &queue,
            &mut enc,
            &mut self.timer,
            size,
            indirect_scale,
            &t.lighting.direct_view,
            &t.lighting.gi_accum,
            &t.lighting.indirect_view,
            &t.lighting.final_view,
        );
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
        self.slc.after_submit();
        self.frames += 1;
    }

    /// One view into `targets.view`, then the overlays that apply to it.
    fn record_view_with_overlays(
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
            self.sst_overlay.record(
                &device,
                &queue,
                enc,
                &mut self.timer,
                d.tree_overlay,
                d.tree_color,
                d.tree_level,
                0.003 * self.scene.bounds.radius().max(1e-3),
                &self.camera_buf,
                &self.tree,
                &self.targets.gbuffer.position_view,
                &self.targets.view.view,
            );
        }
    }

    /// Fingerprint of everything the ground truth depends on (not the animated seed).
    fn gt_key(&self, input: &FrameInput<'_>, lights: &[DirectionalLight], size: (u32, u32)) -> u64 {
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

    /// Ground truth: restart on any change (snapshot this frame's VPLs, clear the sums), then
    /// evaluate as many VPL batches as `gi.rays_per_frame` allows.
    fn step_ground_truth(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        input: &FrameInput<'_>,
        lights: &[DirectionalLight],
        size: (u32, u32),
    ) {
        let key = self.gt_key(input, lights, size);
        let mut st = self.gt.take();
        let accum = self.targets.lighting.gi_accum.clone();
        self.advance_ground_truth(enc, &mut st, key, &accum, size);
        self.gt = st;
    }

    /// Starts (when `key` changed: snapshot of the frame's VPLs, accumulation cleared) or
    /// continues a ground truth in `state`, adding at most `gi.rays_per_frame` shadow rays'
    /// worth of VPL batches to `accum`.
    fn advance_ground_truth(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        state: &mut Option<GtState>,
        key: u64,
        accum: &wgpu::Buffer,
        size: (u32, u32),
    ) {
        let device = self.ctx.device.clone();
        let queue = self.ctx.queue.clone();
        let total = self.vpl_frame.count;
        if state.as_ref().is_none_or(|g| g.key != key) {
            let bytes = (std::mem::size_of::<GpuVpl>() as u64) * self.vpl_buffers.capacity as u64;
            let snapshot = match state.take() {
                Some(g) if g.snapshot.size() == bytes => g.snapshot,
                _ => device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("ground_truth::vpl_snapshot"),
                    size: bytes,
                    usage: wgpu::BufferUsages::STORAGE
                        | wgpu::BufferUsages::COPY_DST
                        | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                }),
            };
            enc.copy_buffer_to_buffer(&self.vpl_buffers.vpls, 0, &snapshot, 0, bytes);
            enc.clear_buffer(accum, 0, None);
            *state = Some(GtState {
                key,
                progress: GiProgress { done: 0, total },
                snapshot,
            });
        }
        let Some(gt) = state.as_mut() else { return };
        if gt.progress.finished() {
            return;
        }
        let pixels = (size.0 as u64 * size.1 as u64).max(1);
        let budget_vpls = (self.settings.gi.rays_per_frame as u64 / pixels).max(1);
        let batch = budget_vpls
            .div_ceil(passes::ground_truth::MAX_BATCHES as u64)
            .max(1) as u32;
        let end = (gt.progress.done as u64 + budget_vpls).min(gt.progress.total as u64) as u32;
        let base = GpuGtParams {
            begin: gt.progress.done,
            end,
            width: size.0,
            height: size.1,
            epsilon: self.settings.gi.distance_epsilon,
            ray_offset: self.settings.gi.ray_offset,
            shadow_rays: self.settings.gi.shadow_rays as u32,
            _pad: 0,
        };
        let reached = self.ground_truth.record(
            &device,
            &queue,
            enc,
            &mut self.timer,
            base,
            batch,
            &self.scene,
            &gt.snapshot,
            &self.targets.gbuffer,
            accum,
        );
        gt.progress.done = reached;
    }

    /// Key of the comparison ground truth: what its image depends on (view, lights, size,
    /// VPL and shading settings), not the sampler's settings.
    fn compare_key(&self, input: &FrameInput<'_>, lights: &[DirectionalLight], size: (u32, u32)) -> u64 {
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
    fn step_compare(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        input: &FrameInput<'_>,
        lights: &[DirectionalLight],
        size: (u32, u32),
    ) {
        let device = self.ctx.device.clone();
        let queue = self.ctx.queue.clone();
        let key = self.compare_key(input, lights, size);
        let mut cmp = match self.compare.take() {
            Some(c) if c.targets_size == size => c,
            _ => CompareState {
                gt: None,
                targets: frame::LightingTargets::new(&device, size),
                targets_size: size,
            },
        };
        let accum = cmp.targets.gi_accum.clone();
        self.advance_ground_truth(enc, &mut cmp.gt, key, &accum, size);
        self.compare_composite.record(
            &device,
            &queue,
            enc,
            &mut self.timer,
            size,
            1.0,
            &self.targets.lighting.direct_view,
            &cmp.targets.gi_accum,
            &cmp.targets.indirect_view,
            &cmp.targets.final_view,
        );
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
        self.compare
            .as_ref()
            .and_then(|c| c.gt.as_ref())
            .map(|g| g.progress)
    }

    /// Converged reference: restart on any change (clear the sums), then add
    /// `reference_spp_per_frame` samples per pixel up to `reference_samples`. Returns the
    /// samples per pixel accumulated after this frame.
    /// One frame of the tree samplers (SLC, SST, RTSLC); returns the frames summed in the
    /// accumulation buffer (1 unless `sampling.accumulate` and nothing changed).
    fn step_sampling(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        input: &FrameInput<'_>,
        lights: &[DirectionalLight],
        size: (u32, u32),
    ) -> u32 {
        let s = self.settings.clone();
        let sm = &s.sampling;
        let device = self.ctx.device.clone();
        let queue = self.ctx.queue.clone();
        // Half-resolution GI: the sampler runs on every other G-buffer sample (demodulated)
        // and is upsampled into the full-resolution accumulation afterwards.
        let half = sm.half_resolution;
        let gi_size = if half {
            passes::slc_half::HalfTargets::half_size(size)
        } else {
            size
        };
        if !self.slc_buffers.matches(gi_size, sm.block_size, sm.cut_size) {
            let need = SlcBuffers::largest_binding(gi_size, sm.block_size, sm.cut_size);
            let limit = device.limits().max_storage_buffer_binding_size;
            if need > limit {
                // Refuse (once per change) rather than fail validation; GI stays black.
                self.ctx.errors.report(format!(
                    "sampling: {}x{} pixels with {}x{} blocks and cuts of {} need a {} MiB buffer; \
                     this device binds at most {} MiB (raise sampling.block_size or lower cut_size)",
                    gi_size.0,
                    gi_size.1,
                    sm.block_size,
                    sm.block_size,
                    sm.cut_size,
                    need >> 20,
                    limit >> 20
                ));
                enc.clear_buffer(&self.targets.lighting.gi_accum, 0, None);
                self.slc_state = None;
                return 1;
            }
            self.slc_buffers = SlcBuffers::new(&device, gi_size, sm.block_size, sm.cut_size);
        }
        let d_max = s.vpl.d_max * self.scene.bounds.radius().max(1e-3);
        let half_targets = if half {
            let h = match self.half.take() {
                Some(h) if h.size == gi_size => h,
                _ => passes::slc_half::HalfTargets::new(&device, size),
            };
            self.slc_half.record_downsample(
                &device,
                &queue,
                enc,
                &mut self.timer,
                &self.targets.gbuffer,
                size,
                &h,
                s.vpl.n_min,
                d_max,
            );
            Some(h)
        } else {
            self.half = None;
            None
        };
        // Accumulate while nothing changes (the key also covers the method and its settings);
        // a frozen tree keeps its VPLs, otherwise new VPLs average in too.
        let key = self.gt_key(input, lights, size) ^ 0x51c0_51c0_51c0_51c0;
        if half && self.slc_state.is_none_or(|(k, _)| k != key || !sm.accumulate) {
            // The half-resolution sum restarts with the accumulation.
            if let Some(h) = &half_targets {
                enc.clear_buffer(&h.accum, 0, None);
            }
        }
        let frames = match self.slc_state {
            Some((k, n)) if sm.accumulate && k == key => n + 1,
            _ => 1,
        };
        self.slc_state = Some((key, frames));
        let grid = self.slc_buffers.grid;
        let p = crate::renderer::gpu_data::GpuSlcParams {
            width: gi_size.0,
            height: gi_size.1,
            block: sm.block_size,
            grid_x: grid.0,
            grid_y: grid.1,
            cut_size: sm.cut_size,
            leaves: self.tree.leaves,
            levels: self.tree.levels(),
            method: match s.gi.method {
                GiMethod::Sst => 1,
                GiMethod::Rtslc => 2,
                _ => 0,
            },
            blending: match sm.blending {
                settings::CutBlending::Stochastic => 0,
                settings::CutBlending::Off => 1,
            },
            fallback: match sm.fallback {
                settings::CutFallback::MockCut => 0,
                settings::CutFallback::Average => 1,
                settings::CutFallback::Root => 2,
                settings::CutFallback::Recompute => 3,
            },
            cull: sm.cull_behind as u32,
            seed: if sm.fixed_seed {
                s.vpl.seed
            } else {
                s.vpl.seed ^ (self.frames as u32).wrapping_mul(0x9e37_79b9)
            },
            accumulate: (frames > 1) as u32,
            epsilon: s.gi.distance_epsilon,
            ray_offset: s.gi.ray_offset,
            n_min: s.vpl.n_min,
            d_max,
            demodulate: half as u32,
            trace_pixel: match self.trace_pixel {
                // In GI pixels (half resolution: the GI pixel covering it).
                Some((x, y)) if half => (x / 2) | (y / 2) << 16,
                Some((x, y)) => x | y << 16,
                None => u32::MAX,
            },
            near_field: sm.near_field,
            shadow_rays: s.gi.shadow_rays as u32,
            substitute_offset: sm.substitute_offset,
            child_probability: match sm.child_probability {
                settings::ChildProbability::Mean => 0,
                settings::ChildProbability::MinMax => 1,
                settings::ChildProbability::Defensive => 2,
            },
        };
        let (gbuffer, accum) = match &half_targets {
            Some(h) => (&h.gbuffer, &h.accum),
            None => (&self.targets.gbuffer, &self.targets.lighting.gi_accum),
        };
        self.slc.record(
            &device,
            &queue,
            enc,
            &mut self.timer,
            p,
            &self.tree,
            &self.scene,
            gbuffer,
            accum,
            &self.slc_buffers,
        );
        if let Some(h) = half_targets {
            self.slc_half.record_upsample(
                &device,
                enc,
                &mut self.timer,
                &self.targets.gbuffer,
                size,
                &h,
                &self.targets.lighting.gi_accum,
            );
            self.half = Some(h);
        }
        frames
    }

    /// Every buffer's value at frame pixel (x, y) (final, direct, GI, G-buffer; the tree
    /// samplers' diagnostics and the comparison ground truth when present), as
    /// (name, RGBA) rows, read with one submission.
    pub fn read_pixel(&self, x: u32, y: u32) -> Result<Vec<(&'static str, [f32; 4])>, GpuError> {
        let t = &self.targets;
        let (x, y) = (x.min(t.size.0 - 1), y.min(t.size.1 - 1));
        let mut names = vec![
            "final",
            "direct",
            "GI",
            "position (w: material + 1)",
            "normal",
            "albedo",
        ];
        let mut texels = vec![
            (&t.lighting.final_, x, y),
            (&t.lighting.direct, x, y),
            (&t.lighting.indirect, x, y),
            (&t.gbuffer.position, x, y),
            (&t.gbuffer.normal, x, y),
            (&t.gbuffer.albedo, x, y),
        ];
        if let Some(c) = self.compare.as_ref().filter(|c| c.targets_size == t.size) {
            names.push("ground truth GI");
            texels.push((&c.targets.indirect, x, y));
        }
        let values = readback::read_texels(&self.ctx, &texels)?;
        let mut rows: Vec<(&'static str, [f32; 4])> = names.into_iter().zip(values).collect();
        if self.settings.gi.method.samples_tree() {
            let b = &self.slc_buffers;
            let scale = t.size.0.div_ceil(b.size.0.max(1)).max(1);
            let (dx, dy) = (x / scale, y / scale);
            if dx < b.size.0 && dy < b.size.1 {
                let off = (dy as u64 * b.size.0 as u64 + dx as u64) * 16;
                let bytes = readback::read_buffer_range(&self.ctx, &b.diag, off, 16)?;
                let d: [f32; 4] = bytemuck::pod_read_unaligned(&bytes[..16]);
                rows.push(("sampling (steps, fallback, samples, 1 + block)", d));
            }
        }
        Ok(rows)
    }

    /// Records the tree samples of frame pixel (x, y) from the next frame on (None: stop).
    pub fn set_trace_pixel(&mut self, pixel: Option<(u32, u32)>) {
        self.trace_pixel = pixel.filter(|&(x, y)| x < 8192 && y < 8192);
    }

    /// What the traced pixel's samples did in the last tree-sampling frame (None: no trace,
    /// or the pixel saw no geometry).
    pub fn read_pixel_trace(&self) -> Result<Option<passes::slc::PixelTrace>, GpuError> {
        if self.trace_pixel.is_none() || !self.settings.gi.method.samples_tree() {
            return Ok(None);
        }
        let bytes = readback::read_storage_buffer(&self.ctx, &self.slc_buffers.trace)?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        Ok(passes::slc::PixelTrace::parse(&words))
    }

    /// The top of the traversal-steps heat map: the depth of the tree (root to leaves).
    pub fn sampling_steps_scale(&self) -> f32 {
        (self.tree.levels().max(2) - 1) as f32
    }

    /// Outlines a block in the cut views (None: no outline).
    pub fn select_block(&mut self, block: Option<u32>) {
        self.selected_block = block;
    }

    /// Reads the cut of block `b` (node ids in slot order, without empty slots).
    pub fn read_cut(&self, b: u32) -> Result<Vec<u32>, GpuError> {
        let s = &self.slc_buffers;
        if b >= s.grid.0 * s.grid.1 {
            return Ok(Vec::new());
        }
        let off = b as u64 * s.cut_size as u64 * 4;
        let bytes = readback::read_buffer_range(&self.ctx, &s.cuts, off, s.cut_size as u64 * 4)?;
        Ok(bytemuck::cast_slice::<u8, u32>(&bytes)
            .iter()
            .copied()
            .take_while(|&n| n != 0)
            .collect())
    }

    /// Half-resolution GI of the last frame: its G-buffer position, normal and the sampler's
    /// demodulated sums (None when half resolution is off).
    pub fn read_half_resolution(&self) -> Result<Option<HalfReadback>, GpuError> {
        let Some(h) = &self.half else { return Ok(None) };
        let pos = readback::read_texture_f32(&self.ctx, &h.gbuffer.position, 0)?;
        let nrm = readback::read_texture_f32(&self.ctx, &h.gbuffer.normal, 0)?;
        let acc = readback::read_storage_buffer(&self.ctx, &h.accum)?;
        Ok(Some((pos, nrm, bytemuck::cast_slice(&acc).to_vec())))
    }

    /// Frames summed in the tree samplers' accumulation (0 before the first).
    pub fn sampling_frames(&self) -> u32 {
        self.slc_state.map_or(0, |(_, n)| n)
    }

    /// The last frame's sampling counters, waiting for them.
    pub fn sampling_stats_blocking(&mut self) -> Option<SamplingStats> {
        let _ = self.ctx.device.poll(wgpu::PollType::wait_indefinitely());
        self.slc.poll_stats()
    }

    /// Counters of a recent frame of the tree samplers (non-blocking; None before the first).
    pub fn sampling_stats(&mut self) -> Option<SamplingStats> {
        self.slc.poll_stats()
    }

    /// The tree samplers' buffers (cuts, per-pixel diagnostics, counters) of the last frame.
    pub fn slc_buffers(&self) -> &SlcBuffers {
        &self.slc_buffers
    }

    fn step_reference(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        input: &FrameInput<'_>,
        lights: &[DirectionalLight],
        size: (u32, u32),
    ) -> u32 {
        let key = self.gt_key(input, lights, size) ^ 0x005e_ed0f_7e7e_7e7e;
        let total = self.settings.gi.reference_samples;
        if self.reference_state.is_none_or(|(k, _)| k != key) {
            enc.clear_buffer(&self.targets.lighting.gi_accum, 0, None);
            self.reference_state = Some((key, GiProgress { done: 0, total }));
        }
        let Some((_, progress)) = self.reference_state.as_mut() else {
            return 0;
        };
        // The target may change without restarting (more samples continue the same sums).
        progress.total = total;
        let n = self
            .settings
            .gi
            .reference_spp_per_frame
            .min(progress.total - progress.done.min(progress.total));
        if n > 0 {
            let p = GpuRefParams {
                width: size.0,
                height: size.1,
                samples: n,
                first_sample: progress.done,
                epsilon: self.settings.gi.distance_epsilon,
                ray_offset: self.settings.gi.ray_offset,
                flux_mix: self.settings.gi.reference_flux_mix,
                seed: self.settings.vpl.seed,
            };
            let device = self.ctx.device.clone();
            let queue = self.ctx.queue.clone();
            self.reference.record(
                &device,
                &queue,
                enc,
                &mut self.timer,
                p,
                self.vpl_gen.params_buffer(),
                &self.vpl_buffers,
                &self.targets.shadow,
                &self.targets.gbuffer,
                &self.scene,
                &self.targets.lighting.gi_accum,
            );
            progress.done += n;
        }
        progress.done
    }

    /// Progress of the progressive GI method: VPLs done (ground truth) or samples per pixel
    /// (reference); None when GI is off.
    pub fn gi_progress(&self) -> Option<GiProgress> {
        match self.settings.gi.method {
            GiMethod::GroundTruth => self.gt.as_ref().map(|g| g.progress),
            GiMethod::Reference => self.reference_state.map(|(_, p)| p),
            GiMethod::Off | GiMethod::Slc | GiMethod::Sst | GiMethod::Rtslc => None,
        }
    }

    /// The VPLs of the last frame (count and per-light ranges).
    pub fn vpl_frame(&self) -> &VplFrame {
        &self.vpl_frame
    }

    pub fn vpl_buffers(&self) -> &VplBuffers {
        &self.vpl_buffers
    }

    /// Reads a storage buffer of f32 back (pyramids, importance).
    /// The last frame's sorted (key, index) pairs and tree.
    pub fn tree_buffers(&self) -> (&SortBuffers, &TreeBuffers) {
        (&self.sort_buffers, &self.tree)
    }

    /// Reads the last frame's tree back: nodes decoded (2 x leaves, node 0 unused) and the
    /// usable bits.
    pub fn read_tree(&self) -> Result<(Vec<SstNode>, Vec<u32>), GpuError> {
        let nodes = passes::sst_build::read_nodes(&self.ctx, &self.tree)?;
        let flags = passes::sst_build::read_flags(&self.ctx, &self.tree)?;
        Ok((nodes.iter().map(SstNode::decode).collect(), flags))
    }

    /// Nodes `ids` of the frame's tree (one submission; ids past the tree read as empty)
    /// and the usable flags, without reading the whole tree back.
    pub fn read_tree_nodes(&self, ids: &[u32]) -> Result<(Vec<SstNode>, Vec<u32>), GpuError> {
        const NODE: u64 = std::mem::size_of::<gpu_data::GpuSstNode>() as u64;
        let count = self.tree.nodes.size() / NODE;
        let inside: Vec<u32> = ids.iter().copied().filter(|&i| (i as u64) < count).collect();
        let ranges: Vec<(u64, u64)> = inside.iter().map(|&i| (i as u64 * NODE, NODE)).collect();
        let bytes = readback::read_buffer_ranges(&self.ctx, &self.tree.nodes, &ranges)?;
        let mut decoded = bytes
            .iter()
            .map(|b| SstNode::decode(&bytemuck::pod_read_unaligned(b)));
        let nodes = ids
            .iter()
            .map(|&i| match (i as u64) < count {
                true => decoded.next().unwrap_or(SstNode::EMPTY),
                false => SstNode::EMPTY,
            })
            .collect();
        let flags = passes::sst_build::read_flags(&self.ctx, &self.tree)?;
        Ok((nodes, flags))
    }

    /// Freezes (or thaws) the VPLs and the light tree: while frozen, frames reuse the last
    /// VPLs, sort and tree (the camera can move around them), and a change of v_min /
    /// sigma_max re-runs only the classify pass.
    pub fn set_freeze_tree(&mut self, freeze: bool) {
        if freeze && self.freeze.is_none() {
            self.freeze = Some((self.settings.tree.v_min, self.settings.tree.sigma_max));
        } else if !freeze {
            self.freeze = None;
        }
    }

    pub fn tree_frozen(&self) -> bool {
        self.freeze.is_some()
    }

    /// Re-runs only the classify pass of the last frame's tree with new thresholds (the
    /// settings are not changed).
    pub fn reclassify(&mut self, v_min: f32, sigma_max: f32) {
        let device = self.ctx.device.clone();
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("sst_classify::encoder"),
        });
        let mut timer = GpuTimer::new(&device, &self.ctx.queue);
        self.sst_build.record_classify(
            &device,
            &self.ctx.queue,
            &mut enc,
            &mut timer,
            &self.tree,
            v_min,
            sigma_max,
        );
        self.ctx.queue.submit([enc.finish()]);
    }

    pub fn read_f32_buffer(&self, buffer: &wgpu::Buffer) -> Result<Vec<f32>, GpuError> {
        let bytes = readback::read_storage_buffer(&self.ctx, buffer)?;
        Ok(bytemuck::cast_slice(&bytes).to_vec())
    }

    /// Reads the last frame's VPLs back.
    pub fn read_vpls(&self) -> Result<Vec<GpuVpl>, GpuError> {
        let bytes = readback::read_storage_buffer(&self.ctx, &self.vpl_buffers.vpls)?;
        let all: &[GpuVpl] = bytemuck::cast_slice(&bytes);
        Ok(all[..(self.vpl_frame.count as usize).min(all.len())].to_vec())
    }

    /// The frame's VPLs as discs over the view texture.
    fn record_vpl_overlay(&mut self, enc: &mut wgpu::CommandEncoder, view: ViewBuffer) {
        let device = self.ctx.device.clone();
        let queue = self.ctx.queue.clone();
        let vb = &self.vpl_buffers;
        let (per_layer, offsets) = passes::vpl_gen::pyramid_layout(vb.res);
        let p = GpuSplatParams {
            count: self.vpl_frame.count,
            space: view.is_rsm_space() as u32,
            radius: self.settings.display.vpl_point_size,
            layer: 0,
            rsm_res: vb.res,
            light_count: self.vpl_frame.ranges.len() as u32,
            per_layer,
            top_offset: *offsets.last().unwrap_or(&0),
        };
        self.vpl_splat.record(
            &device,
            &queue,
            enc,
            &mut self.timer,
            p,
            &self.camera_buf,
            &vb.vpls,
            &vb.flux_pyramid,
            &self.targets.gbuffer.position_view,
            &self.targets.view.view,
        );
    }

    fn record_view(&mut self, enc: &mut wgpu::CommandEncoder, spec: &ViewSpec, camera: &Camera) {
        let view = spec.buffer;
        let look = spec.look;
        let ab = spec.effective_ab();
        let device = self.ctx.device.clone();
        let queue = self.ctx.queue.clone();
        let rsm_res = self.targets.shadow.resolution;
        let want = match view {
            ViewBuffer::ShadowMap
            | ViewBuffer::RsmFlux
            | ViewBuffer::RsmNormal
            | ViewBuffer::RsmPosition
            | ViewBuffer::ImportanceRaw
            | ViewBuffer::ImportanceFiltered => (rsm_res, rsm_res),
            ViewBuffer::PdfPyramid => {
                let r = (rsm_res >> self.settings.display.pyramid_level.min(rsm_res.trailing_zeros())).max(1);
                // Small levels are shown enlarged (nearest) so they stay visible.
                let s = (256 / r).max(1);
                (r * s, r * s)
            }
            v if v.is_sampling_view() => self.slc_buffers.size,
            _ => match ab {
                Some(ab) => {
                    let (w, h) = ab_source(&self.targets, self.compare.as_ref(), &self.snapshots, ab.a)
                        .map_or(self.targets.size, |(_, size)| size);
                    if ab.mode == AbMode::SideBySide {
                        (2 * w, h)
                    } else {
                        (w, h)
                    }
                }
                None => self.targets.size,
            },
        };
        if self.targets.view.size != want {
            self.view_generation += 1;
            self.targets.view = ViewTarget::new(&device, want, self.view_generation);
        }
        let t = &self.targets;
        let dst = &t.view.view;
        let b = self.scene.bounds;
        let (bmin, bmax) = if b.is_empty() {
            (Vec3::ZERO, Vec3::ONE)
        } else {
            (b.min, b.max)
        };
        if let Some(ab) = ab {
            let images = (
                ab_source(&self.targets, self.compare.as_ref(), &self.snapshots, ab.a),
                ab_source(&self.targets, self.compare.as_ref(), &self.snapshots, ab.b),
            );
            let (Some((a, _)), Some((b, _))) = images else {
                // An image that does not exist (no comparison running, snapshot gone).
                clear_view(enc, &self.targets.view.view);
                return;
            };
            let p = passes::compare::GpuCmpParams {
                mode: ab.mode.gpu_id(),
                split_x: (ab.split.clamp(0.0, 1.0) * want.0 as f32) as u32,
                exposure: look.exposure_ev.exp2(),
                tonemap: look.tonemap.gpu_id(),
                diff_scale: ab.diff_scale,
                _pad: [0; 3],
            };
            self.compare_views.record(
                &device,
                &queue,
                enc,
                &mut self.timer,
                p,
                a,
                b,
                &t.gbuffer.position_view,
                dst,
                want,
            );
            return;
        }
        if view.is_compare_view() {
            let Some(cmp) = self
                .compare
                .as_ref()
                .filter(|c| c.targets_size == self.targets.size)
            else {
                // No comparison running (or not at this size): nothing to show.
                clear_view(enc, &self.targets.view.view);
                return;
            };
            let src = if view == ViewBuffer::GroundTruthFinal {
                &cmp.targets.final_view
            } else {
                &cmp.targets.indirect_view
            };
            self.display
                .record(&device, &queue, enc, &mut self.timer, &look, src, dst, want);
            return;
        }
        if view.is_sampling_view() {
            let b = &self.slc_buffers;
            let scale = self.targets.size.0.div_ceil(b.size.0.max(1));
            if scale == 0 || b.size.0 * scale < self.targets.size.0 || scale > 2 {
                // No tree-sampling frame at this size yet: nothing to show.
                clear_view(enc, &self.targets.view.view);
                return;
            }
            let p = passes::slc::GpuSlcViewParams {
                mode: match view {
                    ViewBuffer::TraversalSteps => 0,
                    ViewBuffer::CutFallback => 1,
                    ViewBuffer::CutBlocks => 2,
                    _ => 3,
                },
                grid_x: b.grid.0,
                block: b.block,
                cut_size: b.cut_size,
                exposure: look.exposure_ev.exp2(),
                tonemap: look.tonemap.gpu_id(),
                max_steps: self.sampling_steps_scale(),
                levels: self.tree.levels(),
                selected: self.selected_block.map_or(0, |b| b + 1),
                final_scale: scale,
                _pad: [0; 2],
            };
            self.slc.record_view(
                &device,
                &queue,
                enc,
                &mut self.timer,
                p,
                &t.lighting.final_view,
                &t.gbuffer.position_view,
                b,
                dst,
            );
            return;
        }
        let (mode, src, lo, hi) = match view {
            ViewBuffer::Final | ViewBuffer::Direct | ViewBuffer::Indirect => {
                let src = match view {
                    ViewBuffer::Final => &t.lighting.final_view,
                    ViewBuffer::Direct => &t.lighting.direct_view,
                    _ => &t.lighting.indirect_view,
                };
                self.display
                    .record(&device, &queue, enc, &mut self.timer, &look, src, dst, want);
                return;
            }
            ViewBuffer::RsmFlux => {
                // Flux / (E x texel area) is the albedo the light saw: a readable image.
                let l0 = self.light0_lum;
                let texel = self.lights_texel;
                let scale = 1.0 / (l0 * texel * texel).max(1e-30);
                (
                    VisMode::ArrayColor,
                    VisSource::Array(&t.shadow.flux_array, 0),
                    [0.0; 4],
                    [scale, 0.0, 0.0, 0.0],
                )
            }
            ViewBuffer::RsmNormal => (
                VisMode::ArrayNormal,
                VisSource::Array(&t.shadow.normal_array, 0),
                [0.0; 4],
                [0.0; 4],
            ),
            ViewBuffer::RsmPosition => (
                VisMode::ArrayPosition,
                VisSource::Array(&t.shadow.position_array, 0),
                bmin.extend(0.0).to_array(),
                bmax.extend(1.0).to_array(),
            ),
            ViewBuffer::PdfPyramid => {
                let vb = &self.vpl_buffers;
                let (_, offsets) = passes::vpl_gen::pyramid_layout(vb.res);
                let l = (self.settings.display.pyramid_level as usize).min(offsets.len() - 1);
                let top = *offsets.last().unwrap_or(&0) as f32;
                (
                    VisMode::ScalarLogHeat,
                    VisSource::Scalar(&vb.importance_pyramid, &vb.importance_pyramid),
                    [0.0, top, 0.0, 0.0],
                    [0.0, (vb.res >> l) as f32, offsets[l] as f32, 0.0],
                )
            }
            ViewBuffer::ImportanceRaw | ViewBuffer::ImportanceFiltered => {
                let vb = &self.vpl_buffers;
                let (_, offsets) = passes::vpl_gen::pyramid_layout(vb.res);
                let top = *offsets.last().unwrap_or(&0) as f32;
                let values = if view == ViewBuffer::ImportanceRaw {
                    &vb.importance_raw
                } else {
                    &vb.importance_pyramid
                };
                (
                    VisMode::ScalarLogHeat,
                    VisSource::Scalar(values, &vb.importance_pyramid),
                    [0.0, top, 0.0, 0.0],
                    [0.0, vb.res as f32, 0.0, 0.0],
                )
            }
            ViewBuffer::Albedo => (
                VisMode::Albedo,
                VisSource::Float(&t.gbuffer.albedo_view),
                [0.0; 4],
                [1.0; 4],
            ),
            ViewBuffer::Normal => (
                VisMode::Normal,
                VisSource::Float(&t.gbuffer.normal_view),
                [0.0; 4],
                [1.0; 4],
            ),
            ViewBuffer::Position => (
                VisMode::Position,
                VisSource::Float(&t.gbuffer.position_view),
                bmin.extend(0.0).to_array(),
                bmax.extend(1.0).to_array(),
            ),
            ViewBuffer::Depth => {
                let (near, far) = depth_range(camera, &b);
                (
                    VisMode::Depth,
                    VisSource::Float(&t.gbuffer.position_view),
                    camera.position.extend(near).to_array(),
                    camera.forward.extend(far).to_array(),
                )
            }
            ViewBuffer::MaterialId => (
                VisMode::IdFromW,
                VisSource::Float(&t.gbuffer.position_view),
                [0.0; 4],
                [1.0; 4],
            ),
            ViewBuffer::TraversalSteps
            | ViewBuffer::CutFallback
            | ViewBuffer::CutBlocks
            | ViewBuffer::CutDepth
            | ViewBuffer::GroundTruthIndirect
            | ViewBuffer::GroundTruthFinal
            | ViewBuffer::SplitIndirect
            | ViewBuffer::SideBySide
            | ViewBuffer::RelativeError
            | ViewBuffer::AbCompare => unreachable!("drawn above"),
            ViewBuffer::ShadowMap => (
                VisMode::DepthTexture,
                VisSource::Depth(&t.shadow.array_view, 0),
                [0.0; 4],
                [1.0; 4],
            ),
        };
        self.visualise.record(
            &device,
            &queue,
            enc,
            &mut self.timer,
            mode,
            src,
            lo,
            hi,
            dst,
            want,
        );
    }

    /// The `Rgba8Unorm` texture holding the last rendered view, and its generation (bumped
    /// when the texture is recreated).
    pub fn view_texture(&self) -> (&wgpu::Texture, &wgpu::TextureView, u64) {
        (
            &self.targets.view.texture,
            &self.targets.view.view,
            self.targets.view.generation,
        )
    }

    /// The texture of view `slot` of the last `render_views` (0 = [`Renderer::view_texture`]);
    /// None past the views rendered.
    pub fn view_texture_at(&self, slot: usize) -> Option<(&wgpu::Texture, &wgpu::TextureView, u64)> {
        let t = self.view_target(slot)?;
        Some((&t.texture, &t.view, t.generation))
    }

    fn view_target(&self, slot: usize) -> Option<&ViewTarget> {
        match slot {
            0 => Some(&self.targets.view),
            _ => self.extra_views.get(slot - 1),
        }
    }

    /// Reads view `slot` (sRGB-encoded RGBA8, as shown).
    pub fn read_view_rgba8_at(&self, slot: usize) -> Result<(u32, u32, Vec<u8>), GpuError> {
        let t = self
            .view_target(slot)
            .ok_or_else(|| GpuError::Readback(format!("no view {slot}")))?;
        let bytes = readback::read_texture_bytes(&self.ctx, &t.texture, 0)?;
        Ok((t.size.0, t.size.1, bytes))
    }

    /// Copies a live radiance buffer into a new snapshot (replacing the oldest past
    /// [`views::MAX_SNAPSHOTS`]); returns its index.
    pub fn take_snapshot(&mut self, src: AbSource, label: String) -> Result<u32, String> {
        if matches!(src, AbSource::Snapshot(_)) {
            return Err("a snapshot of a snapshot is the snapshot".into());
        }
        let (tex, _, size) = ab_texture(&self.targets, self.compare.as_ref(), &self.snapshots, src)
            .ok_or("the ground-truth comparison is not running")?;
        let device = &self.ctx.device;
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("views::snapshot"),
            size: wgpu::Extent3d {
                width: size.0,
                height: size.1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: tex.format(),
            usage: wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_DST
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let mut enc = device.create_command_encoder(&Default::default());
        enc.copy_texture_to_texture(tex.as_image_copy(), texture.as_image_copy(), tex.size());
        self.ctx.queue.submit([enc.finish()]);
        let snap = views::Snapshot {
            label,
            view: texture.create_view(&Default::default()),
            texture,
            size,
        };
        if self.snapshots.len() >= views::MAX_SNAPSHOTS {
            self.snapshots.remove(0);
        }
        self.snapshots.push(snap);
        Ok(self.snapshots.len() as u32 - 1)
    }

    /// The snapshots' labels, by index.
    pub fn snapshot_labels(&self) -> Vec<String> {
        self.snapshots.iter().map(|s| s.label.clone()).collect()
    }

    pub fn clear_snapshots(&mut self) {
        self.snapshots.clear();
    }

    /// Reads an A/B source back as linear floats (None: it does not exist now).
    pub fn read_ab_source(&self, src: AbSource) -> Result<Option<ImageF32>, GpuError> {
        match ab_texture(&self.targets, self.compare.as_ref(), &self.snapshots, src) {
            Some((tex, _, _)) => readback::read_texture_f32(&self.ctx, tex, 0).map(Some),
            None => Ok(None),
        }
    }

    /// Picks up finished readbacks (timings, flux total) without blocking; returns the latest
    /// per-pass GPU timings, or None if not (yet) available.
    /// Blocks until the GPU has finished all submitted work (wall-clock timing of frames).
    pub fn wait_idle(&self) {
        let _ = self.ctx.device.poll(wgpu::PollType::wait_indefinitely());
    }

    pub fn poll_timings(&mut self) -> Option<PassTimings> {
        let t = self.timer.collect(&self.ctx.device).cloned();
        self.take_flux_total();
        t
    }

    /// Waits for the GPU and returns the last frame's per-pass timings.
    pub fn wait_timings(&mut self) -> Option<PassTimings> {
        let t = self.timer.collect_blocking(&self.ctx.device).cloned();
        self.take_flux_total();
        t
    }

    fn take_flux_total(&mut self) {
        if let Some(bytes) = self.flux_readback.try_take() {
            let tops: &[f32] = bytemuck::cast_slice(&bytes);
            self.flux_total = Some(tops.iter().sum());
        }
    }

    /// Total reflected flux of the RSMs (luminance, W) = the expected total VPL flux, from the
    /// flux pyramids' tops of a recent frame (read back without blocking).
    pub fn flux_total(&self) -> Option<f32> {
        self.flux_total
    }

    pub fn timestamps_supported(&self) -> bool {
        self.timer.supported()
    }

    /// Reads a buffer of the last frame back as linear floats.
    pub fn read(&self, buffer: Buffer) -> Result<ImageF32, GpuError> {
        let t = &self.targets;
        match buffer {
            Buffer::Final => readback::read_texture_f32(&self.ctx, &t.lighting.final_, 0),
            Buffer::Direct => readback::read_texture_f32(&self.ctx, &t.lighting.direct, 0),
            Buffer::Indirect => readback::read_texture_f32(&self.ctx, &t.lighting.indirect, 0),
            Buffer::GroundTruthIndirect => match &self.compare {
                Some(c) => readback::read_texture_f32(&self.ctx, &c.targets.indirect, 0),
                None => Ok(ImageF32 {
                    width: 0,
                    height: 0,
                    pixels: Vec::new(),
                }),
            },
            Buffer::Position => readback::read_texture_f32(&self.ctx, &t.gbuffer.position, 0),
            Buffer::Normal => readback::read_texture_f32(&self.ctx, &t.gbuffer.normal, 0),
            Buffer::Albedo => readback::read_texture_f32(&self.ctx, &t.gbuffer.albedo, 0),
            Buffer::Depth => readback::read_texture_f32(&self.ctx, &t.gbuffer.depth, 0),
            Buffer::ShadowMap(layer) => readback::read_texture_f32(&self.ctx, &t.shadow.texture, layer),
            Buffer::RsmPosition(layer) => readback::read_texture_f32(&self.ctx, &t.shadow.position, layer),
            Buffer::RsmNormal(layer) => readback::read_texture_f32(&self.ctx, &t.shadow.normal, layer),
            Buffer::RsmFlux(layer) => readback::read_texture_f32(&self.ctx, &t.shadow.flux, layer),
        }
    }

    /// Reads the view texture (sRGB-encoded RGBA8, as shown).
    pub fn read_view_rgba8(&self) -> Result<(u32, u32, Vec<u8>), GpuError> {
        self.read_view_rgba8_at(0)
    }
}

/// Clears a view texture to black (a render pass: `clear_texture` needs a device feature).
fn clear_view(enc: &mut wgpu::CommandEncoder, view: &wgpu::TextureView) {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("view::clear"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            resolve_target: None,
            depth_slice: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
}

/// An A/B source's radiance texture, its view and its size (None: it does not exist now).
/// A free function so that `record_view` can borrow the passes mutably beside it.
fn ab_texture<'a>(
    targets: &'a FrameTargets,
    compare: Option<&'a CompareState>,
    snapshots: &'a [views::Snapshot],
    src: AbSource,
) -> Option<(&'a wgpu::Texture, &'a wgpu::TextureView, (u32, u32))> {
    let l = &targets.lighting;
    let cmp = || compare.filter(|c| c.targets_size == targets.size);
    let size = targets.size;
    match src {
        AbSource::Final => Some((&l.final_, &l.final_view, size)),
        AbSource::Direct => Some((&l.direct, &l.direct_view, size)),
        AbSource::Indirect => Some((&l.indirect, &l.indirect_view, size)),
        AbSource::GroundTruthIndirect => cmp().map(|c| (&c.targets.indirect, &c.targets.indirect_view, size)),
        AbSource::GroundTruthFinal => cmp().map(|c| (&c.targets.final_, &c.targets.final_view, size)),
        AbSource::Snapshot(i) => snapshots.get(i as usize).map(|s| (&s.texture, &s.view, s.size)),
    }
}

/// The view and size of an A/B source (see [`ab_texture`]).
fn ab_source<'a>(
    targets: &'a FrameTargets,
    compare: Option<&'a CompareState>,
    snapshots: &'a [views::Snapshot],
    src: AbSource,
) -> Option<(&'a wgpu::TextureView, (u32, u32))> {
    ab_texture(targets, compare, snapshots, src).map(|(_, v, size)| (v, size))
}

/// Hashes what a frame's image depends on besides the settings: camera, lights, size.
fn hash_view(
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

pub fn depth_range(camera: &Camera, b: &crate::scene::Aabb) -> (f32, f32) {
    if b.is_empty() {
        return (camera.znear, camera.zfar);
    }
    let mut lo = f32::INFINITY;
    let mut hi = 0.0f32;
    for i in 0..8 {
        let p = Vec3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        );
        let d = (p - camera.position).dot(camera.forward);
        lo = lo.min(d);
        hi = hi.max(d);
    }
    (lo.max(0.0), hi.max(lo.max(0.0) + 1e-3))
}

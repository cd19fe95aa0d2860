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

use glam::Vec3;
use thiserror::Error;

use crate::scene::{Camera, DirectionalLight, Scene};
use context::{GpuContext, GpuError};
use frame::{FrameTargets, ShadowTargets, ViewTarget};
use gpu_data::{GpuCamera, GpuLights, MAX_LIGHTS};
use passes::{
    direct::DirectPass,
    display::DisplayPass,
    gbuffer::GbufferPass,
    shadow_map::ShadowMapPass,
    visualise::{VisMode, VisSource, VisualisePass},
};
use readback::ImageF32;
use scene_gpu::SceneGpu;
use settings::{RenderSettings, ViewBuffer};
use timing::{GpuTimer, PassTimings};

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
    Position,
    Normal,
    Albedo,
    Depth,
    ShadowMap(u32),
}

pub struct Renderer {
    pub ctx: GpuContext,
    settings: RenderSettings,
    scene: SceneGpu,
    targets: FrameTargets,
    gbuffer: GbufferPass,
    shadow: ShadowMapPass,
    direct: DirectPass,
    display: DisplayPass,
    visualise: VisualisePass,
    camera_buf: wgpu::Buffer,
    lights_buf: wgpu::Buffer,
    timer: GpuTimer,
    frames: u64,
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
            shadow: ShadowMapPass::new(device)?,
            direct: DirectPass::new(device)?,
            display: DisplayPass::new(device)?,
            visualise: VisualisePass::new(device)?,
            camera_buf: uniform("frame::camera", std::mem::size_of::<GpuCamera>()),
            lights_buf: uniform("frame::lights", std::mem::size_of::<GpuLights>()),
            timer: GpuTimer::new(device, &ctx.queue),
            settings,
            frames: 0,
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
            ShadowMapPass::new(device),
            DirectPass::new(device),
            DisplayPass::new(device),
            VisualisePass::new(device),
        );
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RenderError::Pipeline(format!("shader reload failed: {e}")));
        }
        let (g, s, d, disp, v) = passes;
        (
            self.gbuffer,
            self.shadow,
            self.direct,
            self.display,
            self.visualise,
        ) = (g?, s?, d?, disp?, v?);
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
            let gen_ = self.targets.view.generation + 1;
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

    /// Records and submits one frame, ending with the selected view in the view texture.
    pub fn render(&mut self, input: &FrameInput<'_>) {
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
        let light_matrices: Vec<glam::Mat4> = gpu_lights.lights[..lights.len()]
            .iter()
            .map(|l| glam::Mat4::from_cols_array_2d(&l.view_proj))
            .collect();

        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("frame::encoder"),
        });
        self.timer.begin_frame();
        let t = &self.targets;
        self.shadow.record(
            &device,
            &queue,
            &mut enc,
            &mut self.timer,
            &light_matrices,
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
        self.record_view(&mut enc, input.view, input.camera);
        self.timer.resolve(&mut enc);
        queue.submit([enc.finish()]);
        self.timer.after_submit();
        self.frames += 1;
    }

    fn record_view(&mut self, enc: &mut wgpu::CommandEncoder, view: ViewBuffer, camera: &Camera) {
        let device = self.ctx.device.clone();
        let queue = self.ctx.queue.clone();
        let want = match view {
            ViewBuffer::ShadowMap => (self.targets.shadow.resolution, self.targets.shadow.resolution),
            _ => self.targets.size,
        };
        if self.targets.view.size != want {
            let g = self.targets.view.generation + 1;
            self.targets.view = ViewTarget::new(&device, want, g);
        }
        let t = &self.targets;
        let dst = &t.view.view;
        let b = self.scene.bounds;
        let (bmin, bmax) = if b.is_empty() {
            (Vec3::ZERO, Vec3::ONE)
        } else {
            (b.min, b.max)
        };
        let (mode, src, lo, hi) = match view {
            ViewBuffer::Final | ViewBuffer::Direct => {
                self.display.record(
                    &device,
                    &queue,
                    enc,
                    &mut self.timer,
                    &self.settings.display,
                    &t.lighting.direct_view,
                    dst,
                    want,
                );
                return;
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

    /// Latest per-pass GPU timings (non-blocking), or None if not (yet) available.
    pub fn poll_timings(&mut self) -> Option<PassTimings> {
        self.timer.collect(&self.ctx.device).cloned()
    }

    /// Waits for the GPU and returns the last frame's per-pass timings.
    pub fn wait_timings(&mut self) -> Option<PassTimings> {
        self.timer.collect_blocking(&self.ctx.device).cloned()
    }

    pub fn timestamps_supported(&self) -> bool {
        self.timer.supported()
    }

    pub fn frames_rendered(&self) -> u64 {
        self.frames
    }

    /// Reads a buffer of the last frame back as linear floats.
    pub fn read(&self, buffer: Buffer) -> Result<ImageF32, GpuError> {
        let t = &self.targets;
        match buffer {
            Buffer::Final | Buffer::Direct => readback::read_texture_f32(&self.ctx, &t.lighting.direct, 0),
            Buffer::Position => readback::read_texture_f32(&self.ctx, &t.gbuffer.position, 0),
            Buffer::Normal => readback::read_texture_f32(&self.ctx, &t.gbuffer.normal, 0),
            Buffer::Albedo => readback::read_texture_f32(&self.ctx, &t.gbuffer.albedo, 0),
            Buffer::Depth => readback::read_texture_f32(&self.ctx, &t.gbuffer.depth, 0),
            Buffer::ShadowMap(layer) => readback::read_texture_f32(&self.ctx, &t.shadow.texture, layer),
        }
    }

    /// Reads the view texture (sRGB-encoded RGBA8, as shown).
    pub fn read_view_rgba8(&self) -> Result<(u32, u32, Vec<u8>), GpuError> {
        let t = &self.targets.view;
        let bytes = readback::read_texture_bytes(&self.ctx, &t.texture, 0)?;
        Ok((t.size.0, t.size.1, bytes))
    }
}

/// Linear depth range (near, far) of the scene bounds seen from `camera`.
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

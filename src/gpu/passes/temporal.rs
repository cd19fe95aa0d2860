//! The temporal stage after a per-frame GI method (`shaders/temporal.wgsl`): SVGF (Schied et
//! al. 2017) on the albedo-demodulated GI. Reads: the method's accumulation buffer and scale,
//! the G-buffer, this frame's and the previous frame's camera. Keeps: the history (colour with
//! its per-pixel length, luminance moments) and the previous G-buffer, ping-ponged by frame.
//! Writes: the filtered GI radiance the composite reads. Passes (timer names):
//! `temporal_reproject`, `temporal_accumulate`, and with SVGF `temporal_variance` and
//! `temporal_atrous` (every iteration in one compute pass: SVGF's `atrous`, or with
//! `temporal.atrous = conserving` the light-conserving `atrous_prep`, `atrous_weight`,
//! `atrous_conserving` per iteration), then `temporal_modulate`.
//! Settings: `settings::TemporalSettings` (`[temporal]`). Twin: `reference::temporal`.

use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use bytemuck::{Pod, Zeroable};

use super::{direct::RADIANCE_FORMAT, groups_image, storage_buffer};
use crate::gpu::frame::GbufferTargets;
use crate::gpu::gpu_data::GpuCamera;
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;
use crate::settings::temporal::AtrousFilter;
use crate::settings::{TemporalMode, TemporalSettings, TemporalView};

/// Twin: `TemporalParams` in `shaders/temporal.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuTemporalParams {
    pub width: u32,
    pub height: u32,
    pub first: u32,
    pub gradient: u32,
    pub scale: f32,
    pub alpha: f32,
    pub moments_alpha: f32,
    pub max_history: f32,
    pub normal_cos: f32,
    pub depth_tolerance: f32,
    pub sigma_l: f32,
    pub sigma_n: f32,
    pub sigma_z: f32,
    pub gradient_scale: f32,
    pub spatial_frames: f32,
    pub step: u32,
    pub iteration: u32,
    pub feedback: u32,
    pub view_iteration: u32,
    pub view_mode: u32,
    pub view_lo: f32,
    pub view_hi: f32,
    /// 1: the conserving à-trous (the variance pass keeps the colour).
    pub conserving: u32,
    pub _pad: u32,
}

impl GpuTemporalParams {
    /// The parameters of a frame at `size` with the method's accumulation `scale` (`first`:
    /// no history); the à-trous step, iteration and view fields at their first values.
    pub fn new(s: &TemporalSettings, size: (u32, u32), scale: f32, first: bool) -> Self {
        Self {
            width: size.0,
            height: size.1,
            first: first as u32,
            gradient: s.gradient_reset as u32,
            scale,
            alpha: s.alpha,
            moments_alpha: s.moments_alpha,
            max_history: s.max_history as f32,
            normal_cos: s.normal_cos,
            depth_tolerance: s.depth_tolerance,
            sigma_l: s.sigma_l,
            sigma_n: s.sigma_n,
            sigma_z: s.sigma_z,
            gradient_scale: s.gradient_scale,
            spatial_frames: s.spatial_variance_frames as f32,
            step: 1,
            iteration: 0,
            feedback: if s.mode == TemporalMode::Svgf {
                s.feedback_iteration
            } else {
                0
            },
            view_iteration: s.view_iteration,
            view_mode: 0,
            view_lo: 0.0,
            view_hi: 1.0,
            conserving: (s.atrous == AtrousFilter::Conserving) as u32,
            _pad: 0,
        }
    }
    /// The twin's parameters.
    pub fn reference(s: &TemporalSettings) -> crate::reference::temporal::Params {
        crate::reference::temporal::Params {
            alpha: s.alpha,
            moments_alpha: s.moments_alpha,
            max_history: s.max_history as f32,
            normal_cos: s.normal_cos,
            depth_tolerance: s.depth_tolerance,
            sigma_l: s.sigma_l,
            sigma_n: s.sigma_n,
            sigma_z: s.sigma_z,
            spatial_frames: s.spatial_variance_frames as f32,
            gradient: s.gradient_reset,
            gradient_scale: s.gradient_scale,
            conserving: s.atrous == AtrousFilter::Conserving,
        }
    }
}

/// Parameter slots (dynamic offsets) of one frame: reproject, accumulate, variance, the
/// iterations, modulate, then the views.
const SLOT_REPROJECT: u32 = 0;
const SLOT_ACCUMULATE: u32 = 1;
const SLOT_VARIANCE: u32 = 2;
const SLOT_ATROUS: u32 = 3;
const SLOT_MODULATE: u32 = SLOT_ATROUS + crate::settings::MAX_ATROUS_ITERATIONS;
const SLOT_VIEW: u32 = SLOT_MODULATE + 1;
const SLOTS: u32 = SLOT_VIEW + 1;
const SLOT_STRIDE: u64 = 256;

/// The stage's per-pixel buffers (16 bytes per pixel each; the G-buffer copies 32).
pub struct TemporalBuffers {
    pub size: (u32, u32),
    /// The method's estimate (radiance).
    pub raw: wgpu::Buffer,
    /// Demodulated rgb, luminance.
    pub current: wgpu::Buffer,
    /// Reprojected history (demodulated rgb, length) and moments.
    pub reproj: wgpu::Buffer,
    pub reproj_moments: wgpu::Buffer,
    /// dx, dy (pixels to the previous position), mask (bilinear weight kept, -1 fallback,
    /// 0 disoccluded), reset weight.
    pub motion: wgpu::Buffer,
    /// History colour (demodulated rgb, length) and moments (m1, m2, length), by frame parity.
    pub hist_color: [wgpu::Buffer; 2],
    pub hist_moments: [wgpu::Buffer; 2],
    /// Position (w = material id + 1) and normal per pixel, by frame parity.
    pub gb: [wgpu::Buffer; 2],
    /// The blended colour (demodulated rgb, length).
    pub integrated: wgpu::Buffer,
    /// The filter's input (demodulated rgb, variance).
    pub filter_input: wgpu::Buffer,
    pub ping: wgpu::Buffer,
    pub pong: wgpu::Buffer,
    /// The iteration the view shows.
    pub iter_copy: wgpu::Buffer,
    /// The conserving à-trous, per pixel: (view depth, depth derivative, luminance,
    /// prefiltered variance; w = -1 uncovered) of the last iteration's input ...
    pub aux: wgpu::Buffer,
    /// ... and its weight sum W (one f32 per pixel).
    pub weight: wgpu::Buffer,
    /// The result (radiance) the composite reads.
    pub out: wgpu::Buffer,
    _view_tex: wgpu::Texture,
    view_tex_view: wgpu::TextureView,
}

impl TemporalBuffers {
    fn new(device: &wgpu::Device, size: (u32, u32)) -> Self {
        let px = size.0 as u64 * size.1 as u64;
        let b = |label: &str| storage_buffer(device, label, 16 * px);
        let view_tex = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("temporal::view_radiance"),
            size: wgpu::Extent3d {
                width: size.0,
                height: size.1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: RADIANCE_FORMAT,
            usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let view_tex_view = view_tex.create_view(&Default::default());
        Self {
            size,
            raw: b("temporal::raw"),
            current: b("temporal::current"),
            reproj: b("temporal::reproj"),
            reproj_moments: b("temporal::reproj_moments"),
            motion: b("temporal::motion"),
            hist_color: [b("temporal::hist_color0"), b("temporal::hist_color1")],
            hist_moments: [b("temporal::hist_moments0"), b("temporal::hist_moments1")],
            gb: [
                storage_buffer(device, "temporal::gb0", 32 * px),
                storage_buffer(device, "temporal::gb1", 32 * px),
            ],
            integrated: b("temporal::integrated"),
            filter_input: b("temporal::filter_input"),
            ping: b("temporal::ping"),
            pong: b("temporal::pong"),
            iter_copy: b("temporal::iter_copy"),
            aux: b("temporal::aux"),
            weight: storage_buffer(device, "temporal::weight", 4 * px),
            out: b("temporal::out"),
            _view_tex: view_tex,
            view_tex_view,
        }
    }
}

/// What one frame of the stage reads.
pub struct TemporalInputs<'a> {
    pub gbuffer: &'a GbufferTargets,
    pub camera_buf: &'a wgpu::Buffer,
    /// This frame's camera (the next frame reprojects through it).
    pub camera: GpuCamera,
    pub accum: &'a wgpu::Buffer,
    pub scale: f32,
    pub size: (u32, u32),
    /// What the history belongs to (the method, the mode): a new key restarts it.
    pub key: u64,
}

/// What a view of the stage reads and draws into: the view, this frame's G-buffer and camera,
/// and the view texture `dst`.
#[derive(Clone, Copy)]
pub struct TemporalViewInputs<'a> {
    pub view: TemporalView,
    pub gbuffer: &'a GbufferTargets,
    pub camera_buf: &'a wgpu::Buffer,
    pub dst: &'a wgpu::TextureView,
}

/// The bindings an entry point adds to the stage's shared table: the filter's `src` and `dst`
/// buffers and the view texture it writes.
#[derive(Clone, Copy, Default)]
struct OwnBindings<'a> {
    src: Option<&'a wgpu::Buffer>,
    dst: Option<&'a wgpu::Buffer>,
    view_out: Option<&'a wgpu::TextureView>,
}

/// What the last frame of the stage did (its views and the tests read this).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TemporalFrame {
    /// The parity of the history buffers it wrote.
    pub parity: usize,
    /// It started without a history.
    pub first: bool,
    pub iterations: u32,
}

struct Pipe {
    kernel: Kernel,
    pipeline: wgpu::ComputePipeline,
}

pub struct TemporalPass {
    reproject: Pipe,
    accumulate: Pipe,
    variance: Pipe,
    atrous: Pipe,
    atrous_prep: Pipe,
    atrous_weight: Pipe,
    atrous_conserving: Pipe,
    modulate: Pipe,
    view_radiance: Pipe,
    view_heat: Pipe,
    params: wgpu::Buffer,
    prev_camera: wgpu::Buffer,
    buffers: Option<TemporalBuffers>,
    last_camera: Option<GpuCamera>,
    key: Option<u64>,
    frame: Option<TemporalFrame>,
    /// Whether the last rendered frame ran the stage (its views show only that frame's).
    ran_last: bool,
    /// The settings of the last frame (views read their ranges).
    settings: TemporalSettings,
}

impl TemporalPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        // One kernel per entry point (one parse, one module): each binds the slots it reads
        // of one table (`TemporalPass::bind`).
        let entries = [
            "reproject",
            "accumulate",
            "variance",
            "atrous",
            "atrous_prep",
            "atrous_weight",
            "atrous_conserving",
            "modulate",
            "view_radiance",
            "view_heat",
        ];
        let kernels = Kernel::per_entry(
            device,
            "temporal.wgsl",
            &entries,
            KernelOptions { dynamic: &["p"] },
        )?;
        let mut pipes = entries.iter().zip(kernels).map(|(entry, kernel)| {
            let pipeline = kernel.compute(device, entry, entry);
            Pipe { kernel, pipeline }
        });
        let mut pipe = || pipes.next().expect("one kernel per entry point");
        Ok(Self {
            reproject: pipe(),
            accumulate: pipe(),
            variance: pipe(),
            atrous: pipe(),
            atrous_prep: pipe(),
            atrous_weight: pipe(),
            atrous_conserving: pipe(),
            modulate: pipe(),
            view_radiance: pipe(),
            view_heat: pipe(),
            params: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("temporal::params"),
                size: SLOTS as u64 * SLOT_STRIDE,
                usage: wgpu::BufferUsages::UNIFORM
                    | wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            prev_camera: super::uniform_buffer::<GpuCamera>(device, "temporal::prev_camera"),
            buffers: None,
            last_camera: None,
            key: None,
            frame: None,
            ran_last: false,
            settings: TemporalSettings::default(),
        })
    }

    /// Forgets the history (the stage did not run this frame, or the renderer was reset):
    /// the next frame starts fresh and the views are empty.
    pub fn invalidate(&mut self) {
        self.key = None;
        self.frame = None;
        self.last_camera = None;
        self.ran_last = false;
    }

    /// The frame did not run the stage (a progressive method, no VPLs): the history stays for
    /// the next frame that does, the views show nothing meanwhile.
    pub fn skipped(&mut self) {
        self.ran_last = false;
    }

    /// Frees the buffers (the stage is off).
    pub fn release(&mut self) {
        self.invalidate();
        self.buffers = None;
    }

    pub fn buffers(&self) -> Option<&TemporalBuffers> {
        self.buffers.as_ref()
    }

    /// The stage's frame if the last rendered frame ran it.
    pub fn last_frame(&self) -> Option<TemporalFrame> {
        self.frame.filter(|_| self.ran_last)
    }

    fn bind(
        &self,
        device: &wgpu::Device,
        pipe: &Pipe,
        i: &TemporalInputs<'_>,
        parity: usize,
        own: OwnBindings<'_>,
    ) -> Option<wgpu::BindGroup> {
        let OwnBindings { src, dst, view_out } = own;
        let b = self.buffers.as_ref()?;
        let prev = 1 - parity;
        let g = i.gbuffer;
        let params = wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: &self.params,
            offset: 0,
            size: wgpu::BufferSize::new(std::mem::size_of::<GpuTemporalParams>() as u64),
        });
        let mut table = vec![
            ("p", params),
            ("camera", buf(i.camera_buf)),
            ("prev_camera", buf(&self.prev_camera)),
            ("gb_position", tex(&g.position_view)),
            ("gb_normal", tex(&g.normal_view)),
            ("gb_albedo", tex(&g.albedo_view)),
            ("accum", buf(i.accum)),
            ("prev_gb", buf(&b.gb[prev])),
            ("next_gb", buf(&b.gb[parity])),
            ("hist_color_prev", buf(&b.hist_color[prev])),
            ("hist_moments_prev", buf(&b.hist_moments[prev])),
            ("current", buf(&b.current)),
            ("reproj", buf(&b.reproj)),
            ("reproj_moments", buf(&b.reproj_moments)),
            ("motion", buf(&b.motion)),
            ("hist_color_next", buf(&b.hist_color[parity])),
            ("hist_moments_next", buf(&b.hist_moments[parity])),
            ("integrated", buf(&b.integrated)),
            ("out_radiance", buf(&b.out)),
            ("raw", buf(&b.raw)),
            ("iter_copy", buf(&b.iter_copy)),
            ("view_radiance_out", tex(&b.view_tex_view)),
            ("aux", buf(&b.aux)),
            ("weight", buf(&b.weight)),
        ];
        if let Some(src) = src {
            table.push(("src", buf(src)));
        }
        if let Some(dst) = dst {
            table.push(("dst", buf(dst)));
        }
        if let Some(v) = view_out {
            table.push(("view_out", tex(v)));
        }
        pipe.kernel.bind_from(device, 0, &table)
    }

    /// Records one frame of the stage with `s` (mode not off) and returns the buffer the
    /// composite reads (radiance, scale 1).
    pub fn record(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        enc: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        s: &TemporalSettings,
        i: &TemporalInputs<'_>,
    ) -> Option<&wgpu::Buffer> {
        if s.mode == TemporalMode::Off {
            self.release();
            return None;
        }
        if self.buffers.as_ref().is_none_or(|b| b.size != i.size) {
            self.buffers = Some(TemporalBuffers::new(device, i.size));
            self.invalidate();
        }
        let first = self.key != Some(i.key) || self.frame.is_none();
        let parity = self.frame.map_or(0, |f| 1 - f.parity);
        let prev_cam = if first {
            i.camera
        } else {
            self.last_camera.unwrap_or(i.camera)
        };
        queue.write_buffer(&self.prev_camera, 0, bytemuck::bytes_of(&prev_cam));
        let base = GpuTemporalParams::new(s, i.size, i.scale, first);
        let svgf = s.mode == TemporalMode::Svgf && s.iterations > 0;
        let write = |slot: u32, p: GpuTemporalParams| {
            queue.write_buffer(&self.params, slot as u64 * SLOT_STRIDE, bytemuck::bytes_of(&p));
        };
        for slot in [SLOT_REPROJECT, SLOT_ACCUMULATE, SLOT_VARIANCE, SLOT_MODULATE] {
            write(slot, base);
        }
        let groups = groups_image(i.size.0, i.size.1);
        let b = self.buffers.as_ref()?;
        let dispatch = |enc: &mut wgpu::CommandEncoder,
                        timer: &mut GpuTimer,
                        name: &str,
                        steps: &[(&Pipe, &wgpu::BindGroup, u32)]| {
            enc.push_debug_group(name);
            {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(name),
                    timestamp_writes: timer.compute_pass(name),
                });
                for (pipe, bind, slot) in steps {
                    pass.set_pipeline(&pipe.pipeline);
                    pass.set_bind_group(0, *bind, &[slot * SLOT_STRIDE as u32]);
                    pass.dispatch_workgroups(groups.0, groups.1, groups.2);
                }
            }
            enc.pop_debug_group();
        };
        let none = OwnBindings::default();
        let reproject = self.bind(device, &self.reproject, i, parity, none)?;
        dispatch(
            enc,
            timer,
            "temporal_reproject",
            &[(&self.reproject, &reproject, SLOT_REPROJECT)],
        );
        let accumulate = self.bind(device, &self.accumulate, i, parity, none)?;
        dispatch(
            enc,
            timer,
            "temporal_accumulate",
            &[(&self.accumulate, &accumulate, SLOT_ACCUMULATE)],
        );
        let result = if svgf {
            let own = OwnBindings {
                dst: Some(&b.filter_input),
                ..none
            };
            let variance = self.bind(device, &self.variance, i, parity, own)?;
            dispatch(
                enc,
                timer,
                "temporal_variance",
                &[(&self.variance, &variance, SLOT_VARIANCE)],
            );
            // Per iteration: SVGF's one pass, or the conserving prep, weight sums and filter
            // (all three at the iteration's parameters).
            let pipes: &[&Pipe] = match s.atrous {
                AtrousFilter::Svgf => &[&self.atrous],
                AtrousFilter::Conserving => {
                    &[&self.atrous_prep, &self.atrous_weight, &self.atrous_conserving]
                }
            };
            let mut binds = Vec::new();
            let mut src = &b.filter_input;
            for it in 1..=s.iterations {
                let dst = if it % 2 == 1 { &b.ping } else { &b.pong };
                let mut p = base;
                p.step = 1 << (it - 1);
                p.iteration = it;
                write(SLOT_ATROUS + it - 1, p);
                for &pipe in pipes {
                    let own = OwnBindings {
                        src: Some(src),
                        dst: Some(dst),
                        ..none
                    };
                    let bind = self.bind(device, pipe, i, parity, own)?;
                    binds.push((pipe, bind, SLOT_ATROUS + it - 1));
                }
                src = dst;
            }
            let steps: Vec<_> = binds.iter().map(|(pipe, bg, slot)| (*pipe, bg, *slot)).collect();
            dispatch(enc, timer, "temporal_atrous", &steps);
            src
        } else {
            &b.integrated
        };
        let own = OwnBindings {
            src: Some(result),
            ..none
        };
        let modulate = self.bind(device, &self.modulate, i, parity, own)?;
        dispatch(
            enc,
            timer,
            "temporal_modulate",
            &[(&self.modulate, &modulate, SLOT_MODULATE)],
        );
        self.last_camera = Some(i.camera);
        self.key = Some(i.key);
        self.settings = s.clone();
        self.ran_last = true;
        self.frame = Some(TemporalFrame {
            parity,
            first,
            iterations: if svgf { s.iterations } else { 0 },
        });
        self.buffers.as_ref().map(|b| &b.out)
    }

    /// Whether `view` has something to show (a frame of the stage at `size`, and for the
    /// filter's views a frame of SVGF).
    pub fn has_view(&self, view: TemporalView, size: (u32, u32)) -> bool {
        let (Some(f), Some(b)) = (self.last_frame(), self.buffers.as_ref()) else {
            return false;
        };
        b.size == size
            && match view {
                TemporalView::Variance => f.iterations > 0,
                TemporalView::Iteration => f.iterations >= self.settings.view_iteration,
                _ => true,
            }
    }

    /// Draws `v.view` of the last frame: a radiance view into its texture (returned, for the
    /// display pass to draw with the view's look), a diagnostic view straight into `v.dst`.
    pub fn record_view(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        enc: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        v: &TemporalViewInputs<'_>,
    ) -> Option<&wgpu::TextureView> {
        let TemporalViewInputs {
            view,
            gbuffer,
            camera_buf,
            dst,
        } = *v;
        let (Some(f), Some(b)) = (self.last_frame(), self.buffers.as_ref()) else {
            return None;
        };
        let s = &self.settings;
        let mut p = GpuTemporalParams::new(s, b.size, 1.0, false);
        let (src, mode, radiance) = match view {
            TemporalView::Raw => (&b.raw, 0, true),
            TemporalView::Reprojected => (&b.reproj, 1, true),
            TemporalView::Iteration => (&b.iter_copy, 1, true),
            TemporalView::Motion => (&b.motion, 0, false),
            TemporalView::Disocclusion => (&b.motion, 1, false),
            TemporalView::HistoryLength => (&b.hist_color[f.parity], 2, false),
            TemporalView::Variance => (&b.filter_input, 3, false),
            TemporalView::Reset => (&b.motion, 4, false),
        };
        p.view_mode = mode;
        (p.view_lo, p.view_hi) = match view {
            TemporalView::Motion => (0.0, MOTION_FULL_SCALE_PX),
            TemporalView::HistoryLength => (0.0, s.max_history as f32),
            TemporalView::Variance => VARIANCE_RANGE_LOG10,
            _ => (0.0, 1.0),
        };
        queue.write_buffer(
            &self.params,
            SLOT_VIEW as u64 * SLOT_STRIDE,
            bytemuck::bytes_of(&p),
        );
        let i = TemporalInputs {
            gbuffer,
            camera_buf,
            camera: GpuCamera::zeroed(),
            accum: &b.out,
            scale: 1.0,
            size: b.size,
            key: 0,
        };
        let pipe = if radiance {
            &self.view_radiance
        } else {
            &self.view_heat
        };
        let own = OwnBindings {
            src: Some(src),
            dst: None,
            view_out: Some(dst),
        };
        let bind = self.bind(device, pipe, &i, f.parity, own)?;
        let groups = groups_image(b.size.0, b.size.1);
        enc.push_debug_group("temporal_view");
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("temporal_view"),
                timestamp_writes: timer.compute_pass("temporal_view"),
            });
            pass.set_pipeline(&pipe.pipeline);
            pass.set_bind_group(0, &bind, &[SLOT_VIEW * SLOT_STRIDE as u32]);
            pass.dispatch_workgroups(groups.0, groups.1, groups.2);
        }
        enc.pop_debug_group();
        radiance.then_some(&b.view_tex_view)
    }

    /// The colour scale of a diagnostic view (None for the radiance views).
    pub fn legend(&self, view: TemporalView) -> Option<crate::base::colormap::Legend> {
        let l = |title: &str, lo: f32, hi: f32, log: bool| {
            Some(crate::base::colormap::Legend {
                title: title.into(),
                lo,
                hi,
                log,
            })
        };
        match view {
            TemporalView::HistoryLength => l(
                "history length (frames)",
                0.0,
                self.settings.max_history as f32,
                false,
            ),
            TemporalView::Variance => l(
                "relative std. dev. of the GI luminance (log)",
                VARIANCE_RANGE_LOG10.0,
                VARIANCE_RANGE_LOG10.1,
                true,
            ),
            TemporalView::Reset => l("new-frame weight boost of the reset", 0.0, 1.0, false),
            TemporalView::Motion => l(
                "motion (pixels; hue = direction)",
                0.0,
                MOTION_FULL_SCALE_PX,
                false,
            ),
            _ => None,
        }
    }
}

/// Motion of this many pixels shows at full brightness.
pub const MOTION_FULL_SCALE_PX: f32 = 16.0;
/// log10 range of the variance view's relative standard deviation.
pub const VARIANCE_RANGE_LOG10: (f32, f32) = (-2.0, 1.0);

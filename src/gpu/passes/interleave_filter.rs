//! The geometry-aware filter of interleaved sampling (`shaders/interleave_filter.wgsl`;
//! Stochastic Light Culling section 4.2): one pass shared by the methods that interleave
//! (light culling, the tree samplers). Reads: a method's per-pixel estimate (`raw`), the
//! G-buffer it was computed on, the camera. Writes: an accumulation buffer. Settings:
//! `settings::InterleaveSettings`. Twin: `reference::interleave::filter_pixel`.

use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use bytemuck::{Pod, Zeroable};

use super::{groups_image, run_compute, uniform_buffer};
use crate::gpu::frame::GbufferTargets;
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;
use crate::settings::{InterleaveSettings, PatternDefault};

/// Twin: `FilterParams` in `shaders/interleave_filter.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuFilterParams {
    pub width: u32,
    pub height: u32,
    pub radius: u32,
    /// 0: write, 1: add to the accumulation.
    pub accumulate: u32,
    pub normal_cos: f32,
    pub plane_tolerance: f32,
    /// Applied to the window's mean (light culling: 1 / pi; the tree samplers: 1).
    pub scale: f32,
    /// 1: times the pixel's albedo (0: the output stays demodulated).
    pub modulate: u32,
    /// 0: the (2 radius + 1)^2 window; p > 0: the p x p window from -p/2 to p - p/2 - 1,
    /// one pixel of each subset of a p x p pattern (the VAL paper's "filter of size n x m").
    pub period: u32,
    pub _pad: [u32; 3],
}

impl GpuFilterParams {
    /// The filter of `il` on a `size` image, written (not added) and x albedo.
    pub fn new<D: PatternDefault>(size: (u32, u32), il: &InterleaveSettings<D>) -> Self {
        Self {
            width: size.0,
            height: size.1,
            radius: il.filter_radius,
            accumulate: 0,
            normal_cos: il.filter_normal_cos,
            plane_tolerance: il.filter_plane_tolerance,
            scale: 1.0,
            modulate: 1,
            period: 0,
            _pad: [0; 3],
        }
    }
    /// The window's offsets along each axis, from `lo` to `hi` inclusive. Twin: the shader's.
    pub fn window(&self) -> (i32, i32) {
        window(self.radius, self.period)
    }
}

/// The filter window's offsets (lo, hi) along each axis: -r ..= r, or with a period p
/// -p/2 ..= p - p/2 - 1. Twin: `window` in `interleave_filter.wgsl`.
pub fn window(radius: u32, period: u32) -> (i32, i32) {
    if period > 0 {
        let p = period as i32;
        (-(p / 2), p - p / 2 - 1)
    } else {
        (-(radius as i32), radius as i32)
    }
}

/// The filter's uniforms: one per use in a frame (a method filtering twice in one encoder,
/// as light culling's companion run does, needs two: the queue writes them before the
/// frame runs).
pub struct FilterUniform(wgpu::Buffer);

impl FilterUniform {
    pub fn new(device: &wgpu::Device, label: &str) -> Self {
        Self(uniform_buffer::<GpuFilterParams>(device, label))
    }
}

/// What one filter dispatch reads and writes.
pub struct FilterInputs<'a> {
    pub gbuffer: &'a GbufferTargets,
    pub camera: &'a wgpu::Buffer,
    pub raw: &'a wgpu::Buffer,
    pub accum: &'a wgpu::Buffer,
}

/// One filter dispatch: its timer name (the method's: the filter is part of its GI cost) and
/// its parameters with the uniform they are written to.
pub struct FilterDispatch<'a> {
    pub name: &'static str,
    pub uniform: &'a FilterUniform,
    pub params: GpuFilterParams,
}

pub struct InterleaveFilter {
    kernel: Kernel,
    pipeline: wgpu::ComputePipeline,
}

impl InterleaveFilter {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let _c = wgpu::ShaderStages::COMPUTE;
        let kernel = Kernel::new(
            device,
            "interleave_filter.wgsl",
            &["main"],
            KernelOptions::default(),
        )?;
        Ok(Self {
            pipeline: kernel.compute(device, "interleave_filter", "main"),
            kernel,
        })
    }

    /// Records the filter as dispatch `d` says (its timer name, parameters and uniform).
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        d: FilterDispatch<'_>,
        f: &FilterInputs<'_>,
    ) {
        let FilterDispatch {
            name,
            uniform,
            params: p,
        } = d;
        queue.write_buffer(&uniform.0, 0, bytemuck::bytes_of(&p));
        let bind = self.kernel.bind(
            device,
            0,
            &[
                ("fp", buf(&uniform.0)),
                ("camera", buf(f.camera)),
                ("gb_position", tex(&f.gbuffer.position_view)),
                ("gb_normal", tex(&f.gbuffer.normal_view)),
                ("gb_albedo", tex(&f.gbuffer.albedo_view)),
                ("raw", buf(f.raw)),
                ("accum", buf(f.accum)),
            ],
        );
        run_compute(
            encoder,
            timer,
            name,
            &self.pipeline,
            &bind,
            groups_image(p.width, p.height),
        );
    }
}

//! Half-resolution GI for the tree samplers (thesis chapter 6, "Upsampling"): `downsample`
//! copies every other G-buffer sample into a half-resolution G-buffer, the sampler runs there
//! demodulated (without the albedo), and `upsample` fills the full-resolution accumulation with
//! a joint bilateral filter using the similarity S (eq. 5.3), re-modulated with the
//! full-resolution albedo.
//! Reads: the G-buffer, the half-resolution estimate. Writes: [`HalfTargets`], the GI
//! accumulation buffer.

use bytemuck::{Pod, Zeroable};

use crate::gpu::frame::GbufferTargets;
use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use crate::gpu::shaders;
use crate::methods::FrameCx;

use crate::gpu::passes::{groups_image, run_compute, uniform_buffer};

/// Twin: `HalfParams` in `shaders/methods/tree_samplers/slc_half.wgsl` and `slc_upsample.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuHalfParams {
    pub full_w: u32,
    pub full_h: u32,
    pub half_w: u32,
    pub half_h: u32,
    pub n_min: f32,
    /// Metres.
    pub d_max: f32,
    pub _pad: [u32; 2],
}

/// The half-resolution G-buffer and the sampler's (demodulated) accumulation there.
pub struct HalfTargets {
    pub gbuffer: GbufferTargets,
    pub accum: wgpu::Buffer,
    pub size: (u32, u32),
}

impl HalfTargets {
    pub fn half_size(full: (u32, u32)) -> (u32, u32) {
        (full.0.div_ceil(2).max(1), full.1.div_ceil(2).max(1))
    }

    pub fn new(device: &wgpu::Device, full: (u32, u32)) -> Self {
        let size = Self::half_size(full);
        Self {
            gbuffer: GbufferTargets::new_compute(device, size),
            accum: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("slc_half::accum"),
                size: 16 * size.0 as u64 * size.1 as u64,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            size,
        }
    }
}

pub struct HalfPass {
    down: wgpu::ComputePipeline,
    down_kernel: Kernel,
    up: wgpu::ComputePipeline,
    up_kernel: Kernel,
    params: wgpu::Buffer,
}

impl HalfPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let down_kernel = Kernel::new(
            device,
            "methods/tree_samplers/slc_half.wgsl",
            &["downsample"],
            KernelOptions::default(),
        )?;
        let up_kernel = Kernel::new(
            device,
            "methods/tree_samplers/slc_upsample.wgsl",
            &["upsample"],
            KernelOptions::default(),
        )?;
        Ok(Self {
            down: down_kernel.compute(device, "slc_half", "downsample"),
            up: up_kernel.compute(device, "slc_upsample", "upsample"),
            params: uniform_buffer::<GpuHalfParams>(device, "slc_half::params"),
            down_kernel,
            up_kernel,
        })
    }

    fn write_params(
        &self,
        queue: &wgpu::Queue,
        full: (u32, u32),
        half: &HalfTargets,
        n_min: f32,
        d_max: f32,
    ) {
        let p = GpuHalfParams {
            full_w: full.0,
            full_h: full.1,
            half_w: half.size.0,
            half_h: half.size.1,
            n_min,
            d_max,
            _pad: [0; 2],
        };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
    }

    /// The half-resolution G-buffer from the frame's full one (`n_min`, `d_max` the VPL
    /// clamping of the half-resolution parameters).
    pub fn record_downsample(
        &self,
        cx: &mut FrameCx<'_>,
        encoder: &mut wgpu::CommandEncoder,
        half: &HalfTargets,
        n_min: f32,
        d_max: f32,
    ) {
        let full = &cx.targets.gbuffer;
        self.write_params(cx.queue, cx.size, half, n_min, d_max);
        let bind = self
            .down_kernel
            .bind_table(cx.device, 0, &Self::table(&self.params, full, half, None));
        run_compute(
            encoder,
            cx.timer,
            "gi_downsample",
            &self.down,
            &bind,
            groups_image(half.size.0, half.size.1),
        );
    }

    /// What the down- and upsampling kernels read (each binds its part): the parameters, the
    /// full- and half-resolution G-buffers, the half-resolution GI and the full accumulation.
    fn table<'a>(
        params: &'a wgpu::Buffer,
        full: &'a GbufferTargets,
        half: &'a HalfTargets,
        accum: Option<&'a wgpu::Buffer>,
    ) -> Vec<(&'static str, wgpu::BindingResource<'a>)> {
        let mut t = vec![
            ("hp", buf(params)),
            ("full_position", tex(&full.position_view)),
            ("full_normal", tex(&full.normal_view)),
            ("full_albedo", tex(&full.albedo_view)),
            ("half_position", tex(&half.gbuffer.position_view)),
            ("half_normal", tex(&half.gbuffer.normal_view)),
            ("half_albedo", tex(&half.gbuffer.albedo_view)),
            ("half_accum", buf(&half.accum)),
        ];
        if let Some(a) = accum {
            t.push(("accum", buf(a)));
        }
        t
    }

    /// The frame's full-resolution accumulation (`cx.gi_accum`) from the half-resolution one
    /// (joint bilateral).
    pub fn record_upsample(
        &self,
        cx: &mut FrameCx<'_>,
        encoder: &mut wgpu::CommandEncoder,
        half: &HalfTargets,
    ) {
        let full = &cx.targets.gbuffer;
        let bind = self.up_kernel.bind_table(
            cx.device,
            0,
            &Self::table(&self.params, full, half, Some(cx.gi_accum)),
        );
        run_compute(
            encoder,
            cx.timer,
            "gi_upsample",
            &self.up,
            &bind,
            groups_image(cx.size.0, cx.size.1),
        );
    }
}

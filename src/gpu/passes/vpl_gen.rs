//! VPL generation (thesis 4.1, chapter 6): BRSM importance per RSM texel, edge-aware filter,
//! importance and flux pyramids, hierarchical warping of a randomized Hammersley set.
//! Reads: camera, RSM, G-buffer. Writes: [`VplBuffers`] (pyramids and the VPL array).

use glam::Vec3;
use wgpu::util::DeviceExt;

use crate::{
    gpu::{
        frame::{GbufferTargets, ShadowTargets},
        gpu_data::{GpuVpl, GpuVplParams, MAX_LIGHTS},
        kernel::{Kernel, KernelOptions, buf, tex},
        shaders,
        timing::GpuTimer,
    },
    scene::DirectionalLight,
    settings::{GiSettings, VplMode, VplSettings},
};

use super::{WG_1D, groups_2d};

/// Dynamic-offset stride of the per-level uniforms.
const LEVEL_STRIDE: u64 = 256;
/// Most pyramid levels (4096 -> 13 levels).
pub const MAX_LEVELS: u32 = 16;

/// Floats per light layer of a pyramid over a `res` x `res` map, and each level's offset.
pub fn pyramid_layout(res: u32) -> (u32, Vec<u32>) {
    let levels = res.trailing_zeros() + 1;
    let mut offsets = Vec::with_capacity(levels as usize);
    let mut total = 0;
    for l in 0..levels {
        offsets.push(total);
        let r = res >> l;
        total += r * r;
    }
    (total, offsets)
}

/// VPLs per light: proportional to the luminance of each light's irradiance (thesis ch. 6,
/// "Multiple Lights"), the rounding remainder going to the brightest; returns (first, count).
pub fn split_budget(lights: &[DirectionalLight], total: u32) -> Vec<(u32, u32)> {
    let lum: Vec<f32> = lights
        .iter()
        .map(|l| l.irradiance.dot(Vec3::new(0.2126, 0.7152, 0.0722)).max(0.0))
        .collect();
    let sum: f32 = lum.iter().sum();
    if lights.is_empty() || sum <= 0.0 {
        return lights.iter().map(|_| (0, 0)).collect();
    }
    let mut counts: Vec<u32> = lum
        .iter()
        .map(|l| ((l / sum) * total as f32).floor() as u32)
        .collect();
    let assigned: u32 = counts.iter().sum();
    let brightest = lum
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map(|(i, _)| i)
        .unwrap_or(0);
    counts[brightest] += total - assigned;
    let mut first = 0;
    counts
        .into_iter()
        .map(|c| {
            let r = (first, c);
            first += c;
            r
        })
        .collect()
}

/// GPU buffers of the VPL stage.
pub struct VplBuffers {
    pub importance_raw: wgpu::Buffer,
    pub importance_pyramid: wgpu::Buffer,
    pub flux_pyramid: wgpu::Buffer,
    pub vpls: wgpu::Buffer,
    /// Per pyramid node of level >= 1: min and max of its texels' positions (2 x vec4).
    pub bounds_pyramid: wgpu::Buffer,
    pub res: u32,
    pub layers: u32,
    pub capacity: u32,
}

impl VplBuffers {
    /// Bytes of the largest buffer the stage binds for an RSM of `res` and `layers` layers.
    pub fn largest_binding(res: u32, layers: u32, capacity: u32) -> u64 {
        let (per_layer, _) = pyramid_layout(res);
        let layers = layers.max(1) as u64;
        [
            4 * (res as u64 * res as u64) * layers,
            4 * per_layer as u64 * layers,
            32 * (per_layer as u64 - res as u64 * res as u64) * layers,
            std::mem::size_of::<GpuVpl>() as u64 * capacity.max(1) as u64,
        ]
        .into_iter()
        .max()
        .unwrap_or(0)
    }

    pub fn new(device: &wgpu::Device, res: u32, layers: u32, capacity: u32) -> Self {
        let (per_layer, _) = pyramid_layout(res);
        let storage = |label, bytes: u64| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(16),
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let layers = layers.max(1);
        Self {
            importance_raw: storage("vpl::importance_raw", 4 * (res * res * layers) as u64),
            importance_pyramid: storage("vpl::importance_pyramid", 4 * (per_layer * layers) as u64),
            flux_pyramid: storage("vpl::flux_pyramid", 4 * (per_layer * layers) as u64),
            vpls: storage(
                "vpl::vpls",
                (std::mem::size_of::<GpuVpl>() as u32 * capacity.max(1)) as u64,
            ),
            bounds_pyramid: storage(
                "vpl::bounds_pyramid",
                32 * ((per_layer - res * res) * layers) as u64,
            ),
            res,
            layers,
            capacity: capacity.max(1),
        }
    }
}

/// What the VPL stage reads and writes: its settings (`vpl`, `gi`), the frame's seed, the
/// scene's bounding radius (metres, > 0), the lights (at most MAX_LIGHTS, one RSM layer
/// each), the camera, the RSM and G-buffer targets, and the VPL buffers it fills.
#[derive(Clone, Copy)]
pub struct VplGenInputs<'a> {
    pub settings: &'a VplSettings,
    pub gi: &'a GiSettings,
    pub seed: u32,
    pub scene_radius: f32,
    pub lights: &'a [DirectionalLight],
    pub camera: &'a wgpu::Buffer,
    pub rsm: &'a ShadowTargets,
    pub gbuffer: &'a GbufferTargets,
    pub out: &'a VplBuffers,
}

/// What one VPL frame produced.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VplFrame {
    /// (first, count) of the bounce-1 VPLs per light.
    pub ranges: Vec<(u32, u32)>,
    /// Every VPL slot: the bounce-1 VPLs, then (bounces - 1) x paths light-path slots.
    pub count: u32,
    /// Bounce-1 (RSM) VPLs: slots `[0, first_bounce)`.
    pub first_bounce: u32,
    /// Light paths (bounce b's VPLs at `first_bounce + (b - 2) x paths ..`); 0 for one bounce.
    pub paths: u32,
    pub bounces: u32,
    pub seed: u32,
}

pub struct VplGenPass {
    importance: wgpu::ComputePipeline,
    filter: wgpu::ComputePipeline,
    reduce: wgpu::ComputePipeline,
    warp: wgpu::ComputePipeline,
    kernel: Kernel,
    params: wgpu::Buffer,
    level_params: wgpu::Buffer,
}

impl VplGenPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(
            device,
            "vpl_gen.wgsl",
            &["importance", "filter_importance", "reduce", "warp_vpls"],
            KernelOptions {
                dynamic: &["level_params"],
            },
        )?;
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("vpl_gen::params"),
            size: std::mem::size_of::<GpuVplParams>() as u64,
            usage: crate::gpu::passes::PARAMS_USAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        // Level l's uniform is the constant l: written once, at creation.
        let mut levels = vec![0u8; (LEVEL_STRIDE * MAX_LEVELS as u64) as usize];
        for l in 0..MAX_LEVELS as usize {
            levels[l * LEVEL_STRIDE as usize..][..4].copy_from_slice(&(l as u32).to_le_bytes());
        }
        let level_params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("vpl_gen::level_params"),
            contents: &levels,
            usage: crate::gpu::passes::PARAMS_USAGE,
        });
        Ok(Self {
            importance: kernel.compute(device, "vpl_gen::importance", "importance"),
            filter: kernel.compute(device, "vpl_gen::filter", "filter_importance"),
            reduce: kernel.compute(device, "vpl_gen::reduce", "reduce"),
            warp: kernel.compute(device, "vpl_gen::warp", "warp_vpls"),
            kernel,
            params,
            level_params,
        })
    }

    /// The uniform with this frame's `VplParams` (the reference reads the same pyramids).
    pub fn params_buffer(&self) -> &wgpu::Buffer {
        &self.params
    }

    /// Records the whole VPL stage for `v.lights` (at most MAX_LIGHTS, one RSM layer each).
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        v: &VplGenInputs<'_>,
    ) -> VplFrame {
        let VplGenInputs {
            settings,
            gi,
            seed,
            scene_radius,
            lights,
            camera,
            rsm,
            gbuffer,
            out,
        } = *v;
        let lights = &lights[..lights.len().min(MAX_LIGHTS)];
        let count = settings.count.min(out.capacity);
        let (first_bounce, paths) = super::light_paths::split_bounces(count, settings.bounces.max(1));
        let ranges = split_budget(lights, first_bounce);
        let res = out.res;
        let (per_layer, offsets) = pyramid_layout(res);
        let mut p = GpuVplParams {
            res,
            levels: offsets.len() as u32,
            light_count: lights.len() as u32,
            vpl_count: if lights.is_empty() { 0 } else { first_bounce },
            samples: settings.samples_per_texel,
            filter_radius: settings.filter_radius,
            mode: match settings.mode {
                VplMode::Brsm => 0,
                VplMode::Rsm => 1,
            },
            seed,
            sample_radius: settings.sample_radius * scene_radius,
            n_min: settings.n_min,
            d_max: settings.d_max * scene_radius,
            flux_mix: settings.flux_mix,
            epsilon: gi.distance_epsilon,
            per_layer,
            _pad: [0; 2],
            ranges: [[0; 4]; 4],
            level_offsets: [[0; 4]; 4],
        };
        for (i, (first, n)) in ranges.iter().enumerate() {
            p.ranges[i] = [*first, *n, 0, 0];
        }
        for (l, o) in offsets.iter().enumerate() {
            p.level_offsets[l / 4][l % 4] = *o;
        }
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let bind = self.kernel.bind(
            device,
            0,
            &[
                ("params", buf(&self.params)),
                ("camera", buf(camera)),
                ("rsm_position", tex(&rsm.position_array)),
                ("rsm_normal", tex(&rsm.normal_array)),
                ("rsm_flux", tex(&rsm.flux_array)),
                ("gb_position", tex(&gbuffer.position_view)),
                ("gb_normal", tex(&gbuffer.normal_view)),
                ("gb_albedo", tex(&gbuffer.albedo_view)),
                ("importance_raw", buf(&out.importance_raw)),
                ("importance_pyramid", buf(&out.importance_pyramid)),
                ("flux_pyramid", buf(&out.flux_pyramid)),
                ("vpls", buf(&out.vpls)),
                ("bounds_pyramid", buf(&out.bounds_pyramid)),
            ],
        );
        let level_bind = self.kernel.bind(
            device,
            1,
            &[(
                "level_params",
                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &self.level_params,
                    offset: 0,
                    size: wgpu::BufferSize::new(4),
                }),
            )],
        );
        let layers = lights.len().max(1) as u32;
        let (gx, gy) = groups_2d(res, res);
        encoder.push_debug_group("vpl_gen");
        for (name, pipeline) in [
            ("brsm_importance", &self.importance),
            ("brsm_filter", &self.filter),
        ] {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(name),
                timestamp_writes: timer.compute_pass(name),
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups(gx, gy, layers);
        }
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("pdf_pyramid"),
                timestamp_writes: timer.compute_pass("pdf_pyramid"),
            });
            pass.set_pipeline(&self.reduce);
            pass.set_bind_group(0, &bind, &[]);
            for l in 1..offsets.len() as u32 {
                let r = res >> l;
                let (gx, gy) = groups_2d(r, r);
                pass.set_bind_group(1, &level_bind, &[(l as u64 * LEVEL_STRIDE) as u32]);
                pass.dispatch_workgroups(gx, gy, layers);
            }
        }
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("vpl_warp"),
                timestamp_writes: timer.compute_pass("vpl_warp"),
            });
            pass.set_pipeline(&self.warp);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups(p.vpl_count.div_ceil(WG_1D).max(1), 1, 1);
        }
        encoder.pop_debug_group();
        VplFrame {
            ranges,
            count: if lights.is_empty() { 0 } else { count },
            first_bounce: p.vpl_count,
            paths: if lights.is_empty() { 0 } else { paths },
            bounces: settings.bounces.max(1),
            seed,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pyramid_layout_sums_levels() {
        let (total, offsets) = pyramid_layout(8);
        assert_eq!(offsets, vec![0, 64, 80, 84]);
        assert_eq!(total, 85);
    }

    #[test]
    fn budget_split_by_brightness_sums_to_total() {
        let l = |e: f32| DirectionalLight {
            name: "l".into(),
            direction: Vec3::NEG_Y,
            irradiance: Vec3::splat(e),
        };
        let r = split_budget(&[l(1.0), l(3.0)], 4096);
        assert_eq!(r, vec![(0, 1024), (1024, 3072)]);
        let r = split_budget(&[l(1.0), l(1.0), l(1.0)], 100);
        assert_eq!(r.iter().map(|x| x.1).sum::<u32>(), 100);
        assert_eq!(split_budget(&[l(0.0)], 10), vec![(0, 0)]);
    }
}

//! Imperfect shadow maps as a visibility component (`shaders/ism.wgsl`; Ritschel et al. 2008,
//! as the VAL paper's section 5 uses them): the scene's point cloud (sampled once on the CPU,
//! area-uniform: `reference::ism::sample_points`) splatted each frame into one paraboloid map
//! per oriented point light in an atlas, then pull-push hole filling; methods look maps up
//! with `common/ism.wgsl`'s `ism_visible`. Reads: the point cloud, the lights (position,
//! normal). Writes: [`IsmTargets`]. Settings: `settings::IsmSettings`. Twin:
//! `reference::ism`.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use super::{
    StridedUniforms, WG_1D, WG_2D, bind_group_seq, compute_pipeline, dynamic_uniform_entry, storage_buffer,
    storage_entry,
};
use crate::reference::ism::{IsmLayout, IsmLight};
use crate::renderer::{settings::IsmSettings, shaders, timing::GpuTimer};

/// Twin: `IsmParams` in `shaders/common/ism.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuIsmParams {
    pub atlas: u32,
    pub tile: u32,
    pub per_row: u32,
    pub lights: u32,
    pub points: u32,
    pub level: u32,
    pub bias: f32,
    pub level_base: u32,
    /// 0: point k to map k mod lights; else map m takes per_light points spread over the cloud
    /// (`reference::ism::light_points`).
    pub per_light: u32,
    /// Splat threads: the cloud's points, or lights x per_light.
    pub threads: u32,
    pub _pad: [u32; 2],
}

/// The scene's point cloud on the GPU (vec4 per point), built once per scene and settings.
pub struct IsmPoints {
    pub buffer: wgpu::Buffer,
    pub count: u32,
    /// (point count, seed) it was sampled with.
    pub key: (u32, u32),
}

impl IsmPoints {
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, points: &[Vec3], key: (u32, u32)) -> Self {
        let data: Vec<[f32; 4]> = points.iter().map(|p| [p.x, p.y, p.z, 1.0]).collect();
        let buffer = storage_buffer(device, "ism::points", (data.len() * 16) as u64);
        queue.write_buffer(&buffer, 0, bytemuck::cast_slice(&data));
        Self {
            buffer,
            count: points.len() as u32,
            key,
        }
    }
}

/// The atlas (resolved distances), its splat keys, the pull-push pyramid and the lights.
pub struct IsmTargets {
    pub layout: IsmLayout,
    /// Distances per atlas texel (`reference::ism::EMPTY` where nothing landed or filled).
    pub depth: wgpu::Buffer,
    keys: wgpu::Buffer,
    pyramid: wgpu::Buffer,
    /// Per light: position, then normal (vec4 each).
    pub lights: wgpu::Buffer,
    /// Lights the buffers hold.
    pub capacity: u32,
    levels: u32,
}

impl IsmTargets {
    /// Floats of the pull-push levels 1..=levels for `maps` maps of `tile` texels.
    fn pyramid_len(tile: u32, maps: u32, levels: u32) -> u64 {
        (1..=levels)
            .map(|l| maps as u64 * ((tile >> l) as u64).pow(2))
            .sum()
    }

    pub fn new(device: &wgpu::Device, s: &IsmSettings) -> Self {
        let layout = IsmLayout {
            atlas: s.atlas,
            tile: s.tile,
        };
        let cap = layout.capacity();
        let levels = s.levels();
        let texels = (s.atlas as u64).pow(2);
        Self {
            layout,
            depth: storage_buffer(device, "ism::depth", texels * 4),
            keys: storage_buffer(device, "ism::keys", texels * 4),
            pyramid: storage_buffer(device, "ism::pyramid", Self::pyramid_len(s.tile, cap, levels) * 4),
            lights: storage_buffer(device, "ism::lights", cap as u64 * 32),
            capacity: cap,
            levels,
        }
    }

    pub fn matches(&self, s: &IsmSettings) -> bool {
        self.layout.atlas == s.atlas && self.layout.tile == s.tile && self.levels == s.levels()
    }
}

pub struct IsmPass {
    layout: wgpu::BindGroupLayout,
    splat: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
    pull: wgpu::ComputePipeline,
    push: wgpu::ComputePipeline,
    params: StridedUniforms<GpuIsmParams>,
}

impl IsmPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let c = wgpu::ShaderStages::COMPUTE;
        let module = shaders::create_module(device, "ism.wgsl")?;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("ism::layout"),
            entries: &[
                dynamic_uniform_entry(0, c, std::mem::size_of::<GpuIsmParams>() as u64),
                storage_entry(1, c, true),
                storage_entry(2, c, true),
                storage_entry(3, c, false),
                storage_entry(4, c, false),
                storage_entry(5, c, false),
            ],
        });
        let pipe = |entry: &str| compute_pipeline(device, entry, &[Some(&layout)], &module, entry);
        Ok(Self {
            splat: pipe("splat_main"),
            resolve: pipe("resolve_main"),
            pull: pipe("pull_main"),
            push: pipe("push_main"),
            params: StridedUniforms::new(device, "ism::params", 8),
            layout,
        })
    }

    /// Builds the maps of `lights` (at most the atlas's capacity) from `points` (shared out as
    /// `s.points_per_light` says), timed as `name`: clear, splat, resolve, pull-push over
    /// `t`'s levels.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        name: &str,
        s: &IsmSettings,
        points: &IsmPoints,
        lights: &[IsmLight],
        t: &IsmTargets,
    ) {
        let n = (lights.len() as u32).min(t.capacity);
        let data: Vec<[f32; 4]> = lights[..n as usize]
            .iter()
            .flat_map(|l| {
                let (c, nrm) = (l.position, l.normal);
                [[c.x, c.y, c.z, l.range * l.range], [nrm.x, nrm.y, nrm.z, 0.0]]
            })
            .collect();
        if !data.is_empty() {
            queue.write_buffer(&t.lights, 0, bytemuck::cast_slice(&data));
        }
        let base = GpuIsmParams {
            atlas: t.layout.atlas,
            tile: t.layout.tile,
            per_row: t.layout.per_row(),
            lights: n,
            points: points.count,
            level: 0,
            bias: s.bias,
            level_base: 0,
            per_light: s.points_per_light,
            threads: if s.points_per_light == 0 {
                points.count
            } else {
                n.saturating_mul(s.points_per_light)
            },
            _pad: [0; 2],
        };
        // Uniforms: 0 splat / resolve, then pull levels 1..=L, then push levels L-1..=0.
        let level_base = |l: u32| IsmTargets::pyramid_len(t.layout.tile, n, l.saturating_sub(1)) as u32;
        let mut items = vec![base];
        for l in 1..=t.levels {
            items.push(GpuIsmParams {
                level: l,
                level_base: level_base(l),
                ..base
            });
        }
        for l in (0..t.levels).rev() {
            items.push(GpuIsmParams {
                level: l,
                level_base: level_base(l + 1),
                ..base
            });
        }
        self.params.write(device, queue, &items);
        let bind = bind_group_seq(
            device,
            "ism::bind_group",
            &self.layout,
            &[
                self.params.binding(),
                points.buffer.as_entire_binding(),
                t.lights.as_entire_binding(),
                t.keys.as_entire_binding(),
                t.depth.as_entire_binding(),
                t.pyramid.as_entire_binding(),
            ],
        );
        encoder.clear_buffer(&t.keys, 0, None);
        encoder.push_debug_group(name);
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(name),
                timestamp_writes: timer.compute_pass(name),
            });
            let off = StridedUniforms::<GpuIsmParams>::offset;
            if n > 0 && points.count > 0 {
                // Workgroups as (x, y) when one row would pass the 65535 limit.
                let groups = base.threads.div_ceil(WG_1D).max(1);
                let gx = groups.min(65535);
                let gy = groups.div_ceil(gx);
                pass.set_pipeline(&self.splat);
                pass.set_bind_group(0, &bind, &[off(0)]);
                pass.dispatch_workgroups(gx, gy, 1);
                let g = t.layout.tile.div_ceil(WG_2D);
                pass.set_pipeline(&self.resolve);
                pass.dispatch_workgroups(g, g, n);
                pass.set_pipeline(&self.pull);
                for l in 1..=t.levels {
                    let g = (t.layout.tile >> l).div_ceil(WG_2D).max(1);
                    pass.set_bind_group(0, &bind, &[off(l)]);
                    pass.dispatch_workgroups(g, g, n);
                }
                pass.set_pipeline(&self.push);
                for (i, l) in (0..t.levels).rev().enumerate() {
                    let g = (t.layout.tile >> l).div_ceil(WG_2D).max(1);
                    pass.set_bind_group(0, &bind, &[off(1 + t.levels + i as u32)]);
                    pass.dispatch_workgroups(g, g, n);
                }
            }
        }
        encoder.pop_debug_group();
    }
}

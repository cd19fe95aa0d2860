//! Imperfect shadow maps as a visibility component (`shaders/ism.wgsl`; Ritschel et al. 2008,
//! as the VAL paper's section 5 uses them): the scene's point cloud (sampled once on the CPU,
//! area-uniform: `reference::ism::sample_points`) splatted each frame into one paraboloid map
//! per oriented point light in an atlas, then pull-push hole filling; methods look maps up
//! with `common/ism.wgsl`'s `ism_visible`. Reads: the point cloud, the lights (position,
//! range, normal: uploaded from the CPU by [`IsmPass::record`], or written on the GPU by the
//! caller before [`IsmPass::record_maps`]). Writes: [`IsmTargets`]. Settings:
//! `settings::IsmSettings`. Twin: `reference::ism`. `ism_view.wgsl` draws the atlas as a view
//! ([`IsmPass::record_view`]).

use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use super::{StridedUniforms, WG_1D, WG_2D, groups_image, run_compute, storage_buffer, uniform_buffer};
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;
use crate::reference::ism::{IsmLayout, IsmLight, sample_oriented_points};
use crate::settings::{IsmDefault, IsmSettings};

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
    /// 1: front-face culling (points facing the light left out).
    pub front_cull: u32,
    /// A point's world radius (m; 0: one texel per point), `IsmSettings::point_radius`.
    pub point_radius: f32,
}

impl GpuIsmParams {
    /// The parameters of `lights` maps in `t` built from `points` points under `s` (level 0:
    /// the splat and the lookups).
    pub fn new<D: IsmDefault>(t: &IsmTargets, s: &IsmSettings<D>, lights: u32, points: u32) -> Self {
        Self {
            atlas: t.layout.atlas,
            tile: t.layout.tile,
            per_row: t.layout.per_row(),
            lights,
            points,
            level: 0,
            bias: s.bias,
            level_base: 0,
            per_light: s.points_per_light,
            threads: if s.points_per_light == 0 {
                points
            } else {
                lights.saturating_mul(s.points_per_light)
            },
            front_cull: s.front_face_culling as u32,
            point_radius: 0.0,
        }
    }
}

/// Twin: `IsmViewParams` in `shaders/ism_view.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuIsmViewParams {
    pub atlas: u32,
    pub tile: u32,
    pub per_row: u32,
    pub maps: u32,
    /// The false colour's log scale (metres).
    pub lo: f32,
    pub hi: f32,
    /// Map texels per view pixel.
    pub scale: f32,
    /// Columns of the view's grid of maps.
    pub cols: u32,
}

/// The scene's point cloud on the GPU (per point two vec4: position, normal), built once per
/// scene and settings.
pub struct IsmPoints {
    pub buffer: wgpu::Buffer,
    pub count: u32,
    /// The surface area (m^2) the points were sampled on (0: unknown; sized points then take
    /// one texel).
    pub area: f32,
    /// (point count, seed) it was sampled with.
    pub key: (u32, u32),
}

impl IsmPoints {
    /// Points without normals (front-face culling then culls nothing: a zero normal).
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, points: &[Vec3], key: (u32, u32)) -> Self {
        let oriented: Vec<(Vec3, Vec3)> = points.iter().map(|&p| (p, Vec3::ZERO)).collect();
        Self::oriented(device, queue, &oriented, key)
    }

    /// Points with their surface normals.
    pub fn oriented(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        points: &[(Vec3, Vec3)],
        key: (u32, u32),
    ) -> Self {
        let data: Vec<[f32; 4]> = points
            .iter()
            .flat_map(|(p, n)| [[p.x, p.y, p.z, 1.0], [n.x, n.y, n.z, 0.0]])
            .collect();
        let buffer = storage_buffer(device, "ism::points", (data.len() * 16) as u64);
        queue.write_buffer(&buffer, 0, bytemuck::cast_slice(&data));
        Self {
            buffer,
            count: points.len() as u32,
            area: 0.0,
            key,
        }
    }

    /// `count` points uniform in area over the triangles of a scene's BVH (its CPU copy),
    /// deterministic in `seed` (`reference::ism::sample_points` over the BVH's triangle
    /// order); `key` identifies the scene and settings it was built for.
    pub fn from_bvh(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        bvh: &crate::scene::bvh::Bvh,
        count: u32,
        seed: u32,
        key: (u32, u32),
    ) -> Self {
        Self {
            area: bvh_area(bvh),
            ..Self::oriented(device, queue, &cloud_of_bvh(bvh, count, seed), key)
        }
    }
}

/// Keeps a method's maps ready for `s` on `scene`: the point cloud (sampled again for a new
/// scene upload, point count or `seed`) and the atlas (made again for another size). Shared by
/// every method that builds maps.
pub fn ensure_maps<D: IsmDefault>(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    scene: &crate::gpu::scene_gpu::SceneGpu,
    s: &IsmSettings<D>,
    seed: u32,
    points: &mut Option<(u64, IsmPoints)>,
    targets: &mut Option<IsmTargets>,
) {
    let key = (s.points, seed);
    let generation = scene.generation;
    if !matches!(points, Some((g, p)) if *g == generation && p.key == key) {
        *points = Some((
            generation,
            IsmPoints::from_bvh(device, queue, &scene.bvh, s.points, seed, key),
        ));
    }
    if !targets.as_ref().is_some_and(|t| t.matches(s)) {
        *targets = Some(IsmTargets::new(device, s));
    }
}

/// The point cloud [`IsmPoints::from_bvh`] uploads, with normals (its CPU twin, for tests).
pub fn cloud_of_bvh(bvh: &crate::scene::bvh::Bvh, count: u32, seed: u32) -> Vec<(Vec3, Vec3)> {
    let positions: Vec<Vec3> = bvh.triangles.iter().flat_map(|t| t.vertices()).collect();
    let indices: Vec<u32> = (0..positions.len() as u32).collect();
    sample_oriented_points(&positions, &indices, count, seed)
}

/// The total area (m^2) of a scene BVH's triangles (what [`cloud_of_bvh`] samples).
pub fn bvh_area(bvh: &crate::scene::bvh::Bvh) -> f32 {
    bvh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.vertices();
            0.5 * (b - a).cross(c - a).length() as f64
        })
        .sum::<f64>() as f32
}

/// The atlas (resolved distances), its splat keys, the pull-push pyramid and the lights.
pub struct IsmTargets {
    pub layout: IsmLayout,
    /// Distances per atlas texel (`reference::ism::EMPTY` where nothing landed or filled).
    pub depth: wgpu::Buffer,
    /// The splat's keys (0 where no point landed: the holes before pull-push).
    pub keys: wgpu::Buffer,
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

    pub fn new<D: IsmDefault>(device: &wgpu::Device, s: &IsmSettings<D>) -> Self {
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

    pub fn matches<D: IsmDefault>(&self, s: &IsmSettings<D>) -> bool {
        self.layout.atlas == s.atlas && self.layout.tile == s.tile && self.levels == s.levels()
    }
}

/// One build of the maps: its timer name, the settings, the point cloud and the targets it
/// fills.
pub struct IsmBuild<'a, D: IsmDefault> {
    pub name: &'a str,
    pub settings: &'a IsmSettings<D>,
    pub points: &'a IsmPoints,
    pub targets: &'a IsmTargets,
}

/// A view of the maps: the first `maps` maps, distances on a log scale `range` (lo, hi
/// metres), drawn into `dst` of `size`, their linear data into `data` (vec4 per view pixel;
/// at least `dst`'s size).
#[derive(Clone, Copy)]
pub struct IsmView<'a> {
    pub maps: u32,
    pub range: (f32, f32),
    pub size: (u32, u32),
    pub dst: &'a wgpu::TextureView,
    pub data: &'a wgpu::Buffer,
}

pub struct IsmPass {
    kernel: Kernel,
    splat: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
    pull: wgpu::ComputePipeline,
    push: wgpu::ComputePipeline,
    params: StridedUniforms<GpuIsmParams>,
    view_kernel: Kernel,
    view: wgpu::ComputePipeline,
    view_params: wgpu::Buffer,
}

impl IsmPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(
            device,
            "ism.wgsl",
            &["splat_main", "resolve_main", "pull_main", "push_main"],
            KernelOptions { dynamic: &["ism"] },
        )?;
        let pipe = |entry: &str| kernel.compute(device, entry, entry);
        let view_kernel = Kernel::new(device, "ism_view.wgsl", &["main"], KernelOptions::default())?;
        Ok(Self {
            view: view_kernel.compute(device, "ism_view", "main"),
            view_kernel,
            view_params: uniform_buffer::<GpuIsmViewParams>(device, "ism_view::params"),
            splat: pipe("splat_main"),
            resolve: pipe("resolve_main"),
            pull: pipe("pull_main"),
            push: pipe("push_main"),
            params: StridedUniforms::new(device, "ism::params", 8),
            kernel,
        })
    }

    /// Builds the maps of `lights` (at most the atlas's capacity) from `b.points` (shared out
    /// as `b.settings.points_per_light` says), timed as `b.name`: uploads the lights, then
    /// [`Self::record_maps`].
    pub fn record<D: IsmDefault>(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        b: &IsmBuild<'_, D>,
        lights: &[IsmLight],
    ) {
        let t = b.targets;
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
        self.record_maps(device, queue, encoder, timer, b, n);
    }

    /// Builds the maps of the first `n` lights of `b.targets.lights` (written by the caller:
    /// per light (position, squared range), (normal, 0)), timed as `b.name`: clear, splat,
    /// resolve, pull-push over the targets' levels.
    pub fn record_maps<D: IsmDefault>(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        b: &IsmBuild<'_, D>,
        n: u32,
    ) {
        let IsmBuild {
            name,
            settings: s,
            points,
            targets: t,
        } = *b;
        let n = n.min(t.capacity);
        let base = GpuIsmParams {
            point_radius: s.point_radius(points.area, s.points_per_map(points.count, n)),
            ..GpuIsmParams::new(t, s, n, points.count)
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
        let bind = self.kernel.bind(
            device,
            0,
            &[
                ("ism", self.params.binding()),
                ("points", buf(&points.buffer)),
                ("lights", buf(&t.lights)),
                ("keys", buf(&t.keys)),
                ("ism_depth", buf(&t.depth)),
                ("pyramid", buf(&t.pyramid)),
            ],
        );
        // Only the atlas rows of the maps in use (their keys; the rest is never read).
        let rows = n.div_ceil(t.layout.per_row()) as u64 * t.layout.tile as u64;
        let bytes = (rows * t.layout.atlas as u64 * 4).min(t.keys.size());
        if bytes > 0 {
            encoder.clear_buffer(&t.keys, 0, Some(bytes));
        }
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

    /// Draws view `v` of `t`'s maps (`ism_view.wgsl`: a grid shaped like the view, fitted).
    pub fn record_view(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        t: &IsmTargets,
        v: &IsmView<'_>,
    ) {
        let IsmView {
            maps,
            range: (lo, hi),
            size,
            dst,
            data,
        } = *v;
        let l = t.layout;
        let maps = maps.min(t.capacity).max(1);
        let (w, h) = (size.0.max(1) as f32, size.1.max(1) as f32);
        let cols = ((maps as f32 * w / h).sqrt().ceil() as u32).clamp(1, maps);
        let rows = maps.div_ceil(cols);
        let scale = ((cols * l.tile) as f32 / w).max((rows * l.tile) as f32 / h);
        let p = GpuIsmViewParams {
            atlas: l.atlas,
            tile: l.tile,
            per_row: l.per_row(),
            maps,
            lo,
            hi: hi.max(lo * 2.0),
            scale,
            cols,
        };
        queue.write_buffer(&self.view_params, 0, bytemuck::bytes_of(&p));
        let bind = self.view_kernel.bind(
            device,
            0,
            &[
                ("vp", buf(&self.view_params)),
                ("depth", buf(&t.depth)),
                ("keys", buf(&t.keys)),
                ("dst", tex(dst)),
                ("data", buf(data)),
            ],
        );
        run_compute(
            encoder,
            timer,
            "ism_view",
            &self.view,
            &bind,
            groups_image(size.0, size.1),
        );
    }
}

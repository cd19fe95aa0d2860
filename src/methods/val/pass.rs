//! The VAL method's GPU passes, in frame order: `val_downsample` (light 0's RSM summed down to
//! the clustering resolution), `val_seeds` (per cluster its seed texel from the frame's VPLs),
//! `val_cluster` (the shared `passes::val_cluster`: k steps of section 4's
//! clustering of light 0's RSM), `val_ism_lights` and `val_ism` (with map visibility, or while
//! a map view is shown: each VAL's imperfect shadow map, the shared `passes::ism`),
//! `val_shade` (per pixel its interleaving subset's VALs, eq. 2, visibility; demodulated) and
//! `val_filter` (the shared geometry-aware filter, x albedo / pi, into the GI accumulation),
//! then the views (`val_views.wgsl`).
//! Reads: the VPLs, light 0's RSM, the G-buffer, camera, BVH. CPU twins: `crate::reference::val`,
//! `crate::reference::ism`.

use bytemuck::{Pod, Zeroable};

use super::settings::{IsmSettings, IsmVal};
use crate::gpu::frame::GbufferTargets;
use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use crate::gpu::passes::{
    WG_1D, groups_image,
    interleave_filter::{FilterDispatch, FilterInputs, FilterUniform, GpuFilterParams, InterleaveFilter},
    ism::{GpuIsmParams, IsmBuild, IsmPass, IsmPoints, IsmTargets},
    run_compute, storage_buffer, uniform_buffer,
    val_cluster::{ClusterRun, GpuValParams, ValClusterPass, ValSeeds, ValTargets},
};
use crate::gpu::scene_gpu::SceneGpu;
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;
use crate::methods::FrameCx;

/// Twin: `ValShadeParams` in `val_common.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuValShadeParams {
    pub width: u32,
    pub height: u32,
    pub n: u32,
    pub offset: u32,
    pub clusters: u32,
    /// 1: every VAL shaded as a point light (`val-vpl`).
    pub as_point: u32,
    /// 0 none, 1 BVH ray to the centre, 2 simple ISM lookup, 3 PCSS lookup.
    pub visibility: u32,
    /// The frame's VPLs (the seeds' source).
    pub count: u32,
    pub eps: f32,
    pub ray_offset: f32,
    pub blocker_samples: u32,
    pub pcf_samples: u32,
    pub max_radius: f32,
    pub res: u32,
    pub layer: u32,
    pub inspect: u32,
    /// RSM texels per clustering texel edge.
    pub factor: u32,
    pub _pad: [u32; 3],
}

/// Twin: `DownParams` in `val_downsample.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuDownParams {
    pub res: u32,
    pub factor: u32,
    pub layer: u32,
    pub _pad: u32,
    pub light_dir: [f32; 3],
    /// A fine texel's area perpendicular to the light (m^2).
    pub texel_area: f32,
}

/// The clustering RSM (light 0's summed down, `reference::val::downsample`): position,
/// normal, flux (+ surface area in alpha), Rgba32Float.
pub struct ValRsm {
    pub res: u32,
    pub textures: [wgpu::Texture; 3],
    /// One-layer array views (the clustering reads them).
    pub arrays: [wgpu::TextureView; 3],
    /// Storage views (the downsample writes them).
    storage: [wgpu::TextureView; 3],
    /// Per texel the inverted least VPL index on it (`claim_main`).
    claim: wgpu::Buffer,
}

impl ValRsm {
    pub fn new(device: &wgpu::Device, res: u32) -> Self {
        let res = res.max(1);
        let tex = |label| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: res,
                    height: res,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba32Float,
                usage: wgpu::TextureUsages::STORAGE_BINDING
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        };
        let textures = [
            tex("val::rsm_position"),
            tex("val::rsm_normal"),
            tex("val::rsm_flux"),
        ];
        let arrays = textures.each_ref().map(|t| {
            t.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            })
        });
        let storage = textures.each_ref().map(|t| t.create_view(&Default::default()));
        Self {
            res,
            textures,
            arrays,
            storage,
            claim: storage_buffer(device, "val::seed_claim", 4 * res as u64 * res as u64),
        }
    }
}

/// `GpuValShadeParams::visibility` values.
pub const VIS_NONE: u32 = 0;
pub const VIS_RAYS: u32 = 1;
pub const VIS_ISM: u32 = 2;
pub const VIS_PCSS: u32 = 3;
/// 16 BVH rays to points of the VAL's disk (its visible fraction: exact visibility).
pub const VIS_DISK: u32 = 4;

/// Twin: `ValViewParams` in `val_views.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuValViewParams {
    pub mode: u32,
    pub clusters: u32,
    pub exposure: f32,
    pub tonemap: u32,
    pub lo: f32,
    pub hi: f32,
    pub inspect: u32,
    pub gap: u32,
    pub ray_offset: f32,
    pub res: u32,
    pub _pad: [u32; 2],
}

/// The per-pixel buffers of a frame size.
pub struct ValBuffers {
    pub size: (u32, u32),
    /// Demodulated interleaved estimate (before the filter).
    pub raw: wgpu::Buffer,
    /// Per pixel: mean PCSS penumbra width, lookups with blockers, VALs with a non-zero term, 1.
    pub diag: wgpu::Buffer,
}

impl ValBuffers {
    pub fn new(device: &wgpu::Device, size: (u32, u32)) -> Self {
        let px = (size.0.max(1) * size.1.max(1)) as u64;
        Self {
            size,
            raw: storage_buffer(device, "val::raw", 16 * px),
            diag: storage_buffer(device, "val::diag", 16 * px),
        }
    }
}

/// What the frame's passes read and write.
pub struct ValFrame<'a> {
    pub scene: &'a SceneGpu,
    pub gbuffer: &'a GbufferTargets,
    pub camera: &'a wgpu::Buffer,
    pub vpls: &'a wgpu::Buffer,
    pub accum: &'a wgpu::Buffer,
    /// Light 0's RSM: position, normal and flux array views.
    pub rsm: [&'a wgpu::TextureView; 3],
    /// The clustering RSM they are summed down into.
    pub coarse: &'a ValRsm,
    /// The unique seed VPLs: [count, indices] (`seed_list_bytes`).
    pub seed_list: &'a wgpu::Buffer,
    pub down: GpuDownParams,
    /// The VALs' maps to build this frame (None: no maps).
    pub ism: Option<&'a ValIsm<'a>>,
}

/// The VALs' maps to build this frame.
pub struct ValIsm<'a> {
    pub settings: &'a IsmSettings<IsmVal>,
    pub points: &'a IsmPoints,
    pub targets: &'a IsmTargets,
}

/// A frame's GPU parameters: the shading's, the clustering's (`iterations` steps, from the
/// last frame's clusters with `carry`) and the interleave filter's.
#[derive(Clone, Copy)]
pub struct ValRecordParams {
    pub shade: GpuValShadeParams,
    pub cluster: GpuValParams,
    pub iterations: u32,
    pub carry: bool,
    pub filter: GpuFilterParams,
}

/// Workgroup size of `unique_main` (one workgroup compacts the unique seed VPLs).
pub const SEED_WG: u32 = 256;
/// The entry that uses it.
pub const SEED_WG_ENTRY: &str = "unique_main";

/// The bytes of the unique seed VPLs' list for `vpls` VPLs.
pub fn seed_list_bytes(vpls: u32) -> u64 {
    4 * (vpls as u64 + 1)
}

pub struct ValPass {
    params: wgpu::Buffer,
    claim: wgpu::ComputePipeline,
    unique: wgpu::ComputePipeline,
    down_params: wgpu::Buffer,
    down_kernel: Kernel,
    down: wgpu::ComputePipeline,
    kernel: Kernel,
    seeds: wgpu::ComputePipeline,
    lights: wgpu::ComputePipeline,
    shade: wgpu::ComputePipeline,
    shade_timed: wgpu::ComputePipeline,
    pub cluster: ValClusterPass,
    pub ism: IsmPass,
    ism_params: wgpu::Buffer,
    /// Bound in the maps' place without them: depth, lights.
    ism_dummy: [wgpu::Buffer; 2],
    filter: InterleaveFilter,
    filter_params: FilterUniform,
    views_kernel: Kernel,
    views: wgpu::ComputePipeline,
    view_params: wgpu::Buffer,
    view_ism_params: wgpu::Buffer,
}

impl ValPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(
            device,
            "methods/val/val_shade.wgsl",
            &[
                "claim_main",
                "unique_main",
                "seeds_main",
                "lights_main",
                "shade_main",
            ],
            KernelOptions::default(),
        )?;
        let views_kernel = Kernel::new(
            device,
            "methods/val/val_views.wgsl",
            &["main"],
            KernelOptions::default(),
        )?;
        let down_kernel = Kernel::new(
            device,
            "methods/val/val_downsample.wgsl",
            &["main"],
            KernelOptions::default(),
        )?;
        let timed = &[("DIAGNOSTICS", 0.0)];
        Ok(Self {
            params: uniform_buffer::<GpuValShadeParams>(device, "val::params"),
            down_params: uniform_buffer::<GpuDownParams>(device, "val::down_params"),
            down: down_kernel.compute(device, "val_downsample", "main"),
            down_kernel,
            claim: kernel.compute(device, "val_seed_claim", "claim_main"),
            unique: kernel.compute(device, "val_seed_unique", "unique_main"),
            seeds: kernel.compute(device, "val_seeds", "seeds_main"),
            lights: kernel.compute(device, "val_ism_lights", "lights_main"),
            shade: kernel.compute(device, "val_shade", "shade_main"),
            shade_timed: kernel.compute_with(device, "val_shade_timed", "shade_main", timed),
            kernel,
            cluster: ValClusterPass::new(device)?,
            ism: IsmPass::new(device)?,
            ism_params: uniform_buffer::<GpuIsmParams>(device, "val::ism_params"),
            ism_dummy: [
                storage_buffer(device, "val::ism_dummy_depth", 16),
                storage_buffer(device, "val::ism_dummy_lights", 32),
            ],
            filter: InterleaveFilter::new(device)?,
            filter_params: FilterUniform::new(device, "val::filter_params"),
            views: views_kernel.compute(device, "val_views", "main"),
            views_kernel,
            view_params: uniform_buffer::<GpuValViewParams>(device, "val_views::params"),
            view_ism_params: uniform_buffer::<GpuIsmParams>(device, "val_views::ism_params"),
        })
    }

    /// Records the frame (module doc): seeds, `frame.iterations` clustering steps with
    /// `frame.cluster` (from the last frame's clusters with `frame.carry`), the maps
    /// (`f.ism`), shading with `frame.shade` and the filter with `frame.filter` into
    /// `f.accum`. Refused (nothing recorded) when the clustering refuses its targets.
    pub fn record(
        &mut self,
        cx: &mut FrameCx<'_>,
        encoder: &mut wgpu::CommandEncoder,
        frame: ValRecordParams,
        f: &ValFrame<'_>,
        b: &ValBuffers,
        t: &mut ValTargets,
    ) -> Result<(), String> {
        let ValRecordParams {
            shade: p,
            cluster: cp,
            iterations,
            carry,
            filter: fp,
        } = frame;
        let (diagnostics, device, queue, ism) = (cx.diagnostics, cx.device, cx.queue, f.ism);
        if p.clusters == 0 || p.clusters > t.clusters {
            return Err(format!(
                "VAL: {} clusters for targets of {}",
                p.clusters, t.clusters
            ));
        }
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let (ism_depth, ism_lights) = match ism {
            Some(m) => {
                let ip = GpuIsmParams::new(m.targets, m.settings, p.clusters, m.points.count);
                queue.write_buffer(&self.ism_params, 0, bytemuck::bytes_of(&ip));
                (&m.targets.depth, &m.targets.lights)
            }
            None => (&self.ism_dummy[0], &self.ism_dummy[1]),
        };
        let g = f.gbuffer;
        let bind = |vals: &wgpu::Buffer, seeds: &wgpu::Buffer| {
            self.kernel.bind(
                device,
                0,
                &[
                    ("params", buf(&self.params)),
                    ("gb_position", tex(&g.position_view)),
                    ("gb_normal", tex(&g.normal_view)),
                    ("bvh_nodes", buf(&f.scene.bvh_nodes)),
                    ("bvh_triangles", buf(&f.scene.bvh_triangles)),
                    ("vpls", buf(f.vpls)),
                    ("vals", buf(vals)),
                    ("seeds", buf(seeds)),
                    ("ism_lights", buf(ism_lights)),
                    ("raw", buf(&b.raw)),
                    ("diag", buf(&b.diag)),
                    ("ism", buf(&self.ism_params)),
                    ("ism_depth", buf(ism_depth)),
                    ("claim", buf(&f.coarse.claim)),
                    ("list", buf(f.seed_list)),
                ],
            )
        };
        let per_cluster = (p.clusters.div_ceil(WG_1D), 1, 1);
        self.record_downsample(device, queue, encoder, cx.timer, f);
        // The seeds (the VALs bound are not read).
        let before = bind(t.vals(), &t.seeds);
        self.record_seeds(encoder, cx.timer, f, &before, &p);
        let run = ClusterRun {
            name: "val_cluster",
            rsm: [&f.coarse.arrays[0], &f.coarse.arrays[1], &f.coarse.arrays[2]],
            params: cp,
            seeds: ValSeeds::Written(p.clusters),
            iterations,
            carry,
        };
        self.cluster.record(device, queue, encoder, cx.timer, run, t)?;
        // The clusters as the last step left them; the seeds buffer is bound again unread.
        let after = bind(t.vals(), &t.seeds);
        if let Some(m) = ism {
            run_compute(
                encoder,
                cx.timer,
                "val_ism_lights",
                &self.lights,
                &after,
                per_cluster,
            );
            let b = IsmBuild {
                name: "val_ism",
                settings: m.settings,
                points: m.points,
                targets: m.targets,
            };
            self.ism
                .record_maps(device, queue, encoder, cx.timer, &b, p.clusters);
        }
        let shade = if diagnostics {
            &self.shade
        } else {
            &self.shade_timed
        };
        run_compute(
            encoder,
            cx.timer,
            "val_shade",
            shade,
            &after,
            groups_image(p.width, p.height),
        );
        self.filter.record(
            device,
            queue,
            encoder,
            cx.timer,
            FilterDispatch {
                name: "val_filter",
                uniform: &self.filter_params,
                params: fp,
            },
            &FilterInputs {
                gbuffer: f.gbuffer,
                camera: f.camera,
                raw: &b.raw,
                accum: f.accum,
            },
        );
        Ok(())
    }

    /// Draws a view (`val_views.wgsl`, `p.mode`) into `dst`, its linear data into `data`
    /// (vec4 per `dst` pixel).
    pub fn record_view(
        &self,
        cx: &mut crate::methods::ViewCx<'_>,
        encoder: &mut wgpu::CommandEncoder,
        v: ValViewInputs<'_>,
    ) {
        let ValViewInputs {
            params: p,
            size,
            buffers: b,
            targets: t,
            ism,
            data,
        } = v;
        let (device, queue, scene, camera, dst) = (cx.device, cx.queue, cx.scene, cx.camera, cx.dst);
        let final_image = &cx.targets.lighting.final_view;
        let gb_position = &cx.targets.gbuffer.position_view;
        queue.write_buffer(&self.view_params, 0, bytemuck::bytes_of(&p));
        let depth = match ism {
            Some((it, s, maps)) => {
                let ip = GpuIsmParams::new(it, s, maps, 0);
                queue.write_buffer(&self.view_ism_params, 0, bytemuck::bytes_of(&ip));
                &it.depth
            }
            None => &self.ism_dummy[0],
        };
        let bind = self.views_kernel.bind(
            device,
            0,
            &[
                ("vp", buf(&self.view_params)),
                ("final_image", tex(final_image)),
                ("gb_position", tex(gb_position)),
                ("diag", buf(&b.diag)),
                ("dst", tex(dst)),
                ("vals", buf(t.vals())),
                ("keys", buf(&t.keys)),
                ("ism", buf(&self.view_ism_params)),
                ("ism_depth", buf(depth)),
                ("bvh_nodes", buf(&scene.bvh_nodes)),
                ("bvh_triangles", buf(&scene.bvh_triangles)),
                ("data", buf(data)),
                ("camera", buf(camera)),
            ],
        );
        run_compute(
            encoder,
            cx.timer,
            "val_views",
            &self.views,
            &bind,
            groups_image(size.0, size.1),
        );
    }
}

/// What a VAL view draws from (the frame's final image, G-buffer, scene and camera come
/// with the view's `ViewCx`): its parameters, size, the method's buffers and targets, the
/// VALs' shadow maps when it has them (targets, settings, map count), and the buffer of its
/// linear data (vec4 per pixel).
pub struct ValViewInputs<'a> {
    pub params: GpuValViewParams,
    pub size: (u32, u32),
    pub buffers: &'a ValBuffers,
    pub targets: &'a ValTargets,
    pub ism: Option<(&'a IsmTargets, &'a IsmSettings<IsmVal>, u32)>,
    pub data: &'a wgpu::Buffer,
}

/// The structs this method shares with WGSL (its `Module::wgsl_twins`: the registry test
/// checks them against naga's layout).
pub static WGSL_TWINS: &[crate::gpu::gpu_data::WgslTwin] = &[
    crate::wgsl_twin!(
        crate::methods::val::pass::GpuValShadeParams,
        "methods/val/val_shade.wgsl",
        "ValShadeParams",
        [
            width,
            height,
            n,
            offset,
            clusters,
            as_point,
            visibility,
            count,
            eps,
            ray_offset,
            blocker_samples,
            pcf_samples,
            max_radius,
            res,
            layer,
            inspect,
            factor,
            _pad,
            _pad + 4,
            _pad + 8
        ]
    ),
    crate::wgsl_twin!(
        crate::gpu::passes::val_cluster::GpuVal,
        "methods/val/val_shade.wgsl",
        "Val",
        [position, area, normal, pixels, flux, texel]
    ),
    crate::wgsl_twin!(
        crate::methods::val::pass::GpuValViewParams,
        "methods/val/val_views.wgsl",
        "ValViewParams",
        [
            mode,
            clusters,
            exposure,
            tonemap,
            lo,
            hi,
            inspect,
            gap,
            ray_offset,
            res,
            _pad,
            _pad + 4
        ]
    ),
    crate::wgsl_twin!(
        crate::methods::val::pass::GpuDownParams,
        "methods/val/val_downsample.wgsl",
        "DownParams",
        [res, factor, layer, _pad, light_dir, texel_area]
    ),
];

impl ValPass {
    /// The clustering RSM: light 0's RSM summed down by `f.down.factor` into `f.coarse`.
    fn record_downsample(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        f: &ValFrame<'_>,
    ) {
        queue.write_buffer(&self.down_params, 0, bytemuck::bytes_of(&f.down));
        let down = self.down_kernel.bind(
            device,
            0,
            &[
                ("dp", buf(&self.down_params)),
                ("rsm_position", tex(f.rsm[0])),
                ("rsm_normal", tex(f.rsm[1])),
                ("rsm_flux", tex(f.rsm[2])),
                ("out_position", tex(&f.coarse.storage[0])),
                ("out_normal", tex(&f.coarse.storage[1])),
                ("out_flux", tex(&f.coarse.storage[2])),
            ],
        );
        run_compute(
            encoder,
            timer,
            "val_downsample",
            &self.down,
            &down,
            groups_image(f.coarse.res, f.coarse.res),
        );
    }

    /// The seeds: claims, the unique VPLs and a seed per cluster, with the shading kernel's
    /// group `before` (its VALs unread).
    fn record_seeds(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        f: &ValFrame<'_>,
        before: &wgpu::BindGroup,
        p: &GpuValShadeParams,
    ) {
        encoder.clear_buffer(&f.coarse.claim, 0, None);
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("val_seeds"),
                timestamp_writes: timer.compute_pass("val_seeds"),
            });
            pass.set_bind_group(0, before, &[]);
            pass.set_pipeline(&self.claim);
            pass.dispatch_workgroups(p.count.div_ceil(WG_1D).clamp(1, 65535), 1, 1);
            pass.set_pipeline(&self.unique);
            pass.dispatch_workgroups(1, 1, 1);
            pass.set_pipeline(&self.seeds);
            pass.dispatch_workgroups(p.clusters.div_ceil(WG_1D), 1, 1);
        }
    }
}

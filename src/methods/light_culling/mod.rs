//! Stochastic Light Culling (Tokuyoshi & Harada, "Stochastic Light Culling", JCGT 2016,
//! sections 3-4) as stochastic tiled lighting of the frame's VPLs, and its clamped-range
//! baseline (appendix A) at the same error bound.
//!
//! Each frame: one random xi_i per VPL gives it a finite range (eq. 3) beyond which it is
//! culled and inside which its fall-off is divided by the Russian-roulette probability
//! (eq. 2): unbiased, with a variance bounded by the user's eps_max (eq. 6). Tiles of the
//! (de-)interleaved image (section 4.2) collect the VPLs whose range spheres touch them;
//! pixels sum their tile's list; the geometry-aware filter undoes the interleaving. The
//! clamped baseline uses deterministic ranges from the same bound (appendix A): it darkens.
//! Visibility: `gi.shadow_rays` (BVH shadow rays, or none as the paper's figures 1 and 4).
//!
//! Passes: `pass.rs`; CPU twins: `crate::reference::light_culling`; docs/light-culling.md.

pub mod pass;
pub mod settings;
mod ui;

use super::{
    FrameCx, Kind, Legend, Method, MethodId, MethodInfo, MethodView, Module, Resource, ViewCx, ViewInfo,
};
use crate::reference::light_culling::{Interleave, TileGrid};
use crate::renderer::{
    context::{GpuContext, GpuError},
    readback::{self, ImageF32},
    settings::RenderSettings,
    shaders::ShaderError,
};
use pass::{FrameInputs, GpuLcullParams, GpuLcullViewParams, LcullBuffers, LcullPass, LcullStats};
use settings::LightCullingSettings;

/// The paper's stochastic light culling.
pub const ID: MethodId = MethodId::new("light-culling");
/// The clamped-range baseline (appendix A).
pub const CLAMPED: MethodId = MethodId::new("light-culling-clamped");

macro_rules! shader {
    ($name:literal) => {
        (
            concat!("methods/light_culling/", $name),
            include_str!(concat!("../../../shaders/methods/light_culling/", $name)),
        )
    };
}

pub static MODULE: Module = Module {
    name: "light_culling",
    create,
    shaders: &[
        shader!("lcull_common.wgsl"),
        shader!("lcull_ranges.wgsl"),
        shader!("lcull_tiles.wgsl"),
        shader!("lcull_shade.wgsl"),
        shader!("lcull_views.wgsl"),
    ],
    entry_shaders: &[
        "methods/light_culling/lcull_ranges.wgsl",
        "methods/light_culling/lcull_tiles.wgsl",
        "methods/light_culling/lcull_shade.wgsl",
        "methods/light_culling/lcull_views.wgsl",
    ],
};

/// The pixel's tile list length (log heat map).
pub const LIST: MethodView = MethodView::new("culling lights per tile");
/// Tiles over their list's cap (red over the grey final).
pub const OVERFLOW: MethodView = MethodView::new("culling overflow");
/// The interleaving pattern (a colour per subset).
pub const PATTERN: MethodView = MethodView::new("culling pattern");
/// The share of the tile's list in range of each pixel.
pub const IN_RANGE: MethodView = MethodView::new("culling list share in range");

const VIEWS: &[ViewInfo] = &[
    ViewInfo {
        name: LIST.name(),
        file: "culling_lights_per_tile",
        about: "VPLs in the pixel's tile list (log scale up to the list's cap)",
        passes: &["lcull_tiles"],
    },
    ViewInfo {
        name: OVERFLOW.name(),
        file: "culling_overflow",
        about: "tiles whose lights in range exceed the list's cap (shaded by testing every VPL \
                of their subset), red over the grey final",
        passes: &["lcull_tiles"],
    },
    ViewInfo {
        name: PATTERN.name(),
        file: "culling_pattern",
        about: "the interleaving pattern: each pixel in the colour of its VPL subset",
        passes: &["lcull_shade"],
    },
    ViewInfo {
        name: IN_RANGE.name(),
        file: "culling_list_share_in_range",
        about: "the share of the tile's list within range of the pixel (VPLs with a non-zero \
                fall-off / VPLs tested, 0 .. 1): how tight the tile's bounds are",
        passes: &["lcull_shade"],
    },
];

fn invalid_example(s: &mut RenderSettings) -> &'static str {
    let lc = LightCullingSettings {
        interleave: 0,
        ..Default::default()
    };
    let _ = s.set_method(ID, &lc);
    "methods.light-culling.interleave"
}

const TESTS: &[&str] = &[
    "light_culling::gpu_ranges_and_tile_lists_equal_the_cpu_reference",
    "light_culling::gpu_shading_and_filter_equal_the_cpu_reference_and_overflow_changes_nothing",
    "light_culling::the_mean_over_frames_converges_to_the_unshadowed_ground_truth_and_clamping_darkens",
];

pub static INFO: MethodInfo = MethodInfo {
    id: ID,
    aliases: &["stochastic-light-culling", "slcull"],
    label: "Stochastic Light Culling",
    short: "light culling",
    about: "Tokuyoshi & Harada 2016: per-VPL random ranges from an error bound (unbiased \
            Russian roulette), tiled culling, interleaved sampling and a geometry-aware filter.",
    progress_unit: "",
    kind: Kind::PerFrame,
    module: &MODULE,
    reads: &[Resource::Gbuffer, Resource::Vpls, Resource::Bvh],
    views: VIEWS,
    timed_passes: &["lcull_ranges", "lcull_tiles", "lcull_shade", "lcull_filter"],
    story: false,
    shadow_ray_switch: true,
    truth_of_vpls: false,
    validate,
    invalid_example: Some(invalid_example),
    ui: ui::settings_ui,
    tests: TESTS,
    sweep: Some(&SWEEP),
};

pub static CLAMPED_INFO: MethodInfo = MethodInfo {
    id: CLAMPED,
    aliases: &["clamped-light-culling"],
    label: "Light culling, clamped ranges",
    short: "clamped culling",
    about: "The baseline of Stochastic Light Culling (its appendix A): the same tiled lighting \
            with deterministic ranges for the same error bound; biased (darker).",
    progress_unit: "",
    kind: Kind::PerFrame,
    module: &MODULE,
    reads: &[Resource::Gbuffer, Resource::Vpls, Resource::Bvh],
    views: VIEWS,
    timed_passes: &["lcull_ranges", "lcull_tiles", "lcull_shade", "lcull_filter"],
    story: false,
    shadow_ray_switch: true,
    truth_of_vpls: false,
    validate,
    invalid_example: Some(invalid_example),
    ui: ui::settings_ui,
    tests: TESTS,
    sweep: Some(&SWEEP),
};

/// The error bound eps_max, loose to tight (the paper's 0.0005 among them).
pub static SWEEP: super::Sweep = super::Sweep {
    name: "epsilon_max",
    values: &[0.01, 0.002, 0.0005, 0.0001],
    apply: |s, v| {
        let mut lc: LightCullingSettings = s.method(ID).unwrap_or_default();
        lc.epsilon_max = v.clamp(1e-9, 1.0) as f32;
        let _ = s.set_method(ID, &lc);
    },
    integer: false,
};

fn validate(s: &RenderSettings) -> Result<(), String> {
    s.method::<LightCullingSettings>(ID)?.validate()
}

/// Decades of the list-length scales: 1 .. 10^decades >= cap.
fn decades(cap: u32) -> u32 {
    (cap.max(2) as f32).log10().ceil() as u32
}

pub struct LightCulling {
    pass: LcullPass,
    buffers: LcullBuffers,
    /// Accumulation: (key, method, frames summed).
    state: Option<(u64, MethodId, u32)>,
    settings: LightCullingSettings,
}

fn create(device: &wgpu::Device) -> Result<Box<dyn Method>, ShaderError> {
    Ok(Box::new(LightCulling {
        pass: LcullPass::new(device)?,
        buffers: LcullBuffers::new(device, 1, (1, 1), 1, 1),
        state: None,
        settings: LightCullingSettings::default(),
    }))
}

impl LightCulling {
    pub fn buffers(&self) -> &LcullBuffers {
        &self.buffers
    }
    /// The frame's xi seed (a new one per frame unless `sampling.fixed_seed`).
    pub fn seed(s: &RenderSettings, frame_index: u64) -> u32 {
        if s.sampling.fixed_seed {
            s.vpl.seed ^ 0x1b87_3593
        } else {
            (s.vpl.seed ^ 0x1b87_3593) ^ (frame_index as u32).wrapping_mul(0x9e37_79b9)
        }
    }
    /// The tile layout of a frame of `size` under `lc`.
    pub fn grid(lc: &LightCullingSettings, size: (u32, u32)) -> TileGrid {
        TileGrid {
            width: size.0,
            height: size.1,
            tile: lc.tile_size,
            n: lc.interleave,
        }
    }
    /// Counters of a recent diagnostic frame (non-blocking).
    pub fn poll_stats(&mut self) -> Option<LcullStats> {
        self.pass.stats.poll()
    }
}

impl Method for LightCulling {
    fn record(&mut self, cx: &mut FrameCx<'_>, enc: &mut wgpu::CommandEncoder) -> f32 {
        let s = cx.settings;
        let lc: LightCullingSettings = s.method(ID).unwrap_or_default();
        let grid = Self::grid(&lc, cx.size);
        let (tiles_x, tiles_y) = grid.per_subset();
        let tiles = grid.count();
        let cap = lc.max_lights_per_tile;
        let vpl_capacity = cx.vpl_buffers.capacity;
        if !self.buffers.matches(vpl_capacity, cx.size, tiles, cap) {
            let need = LcullBuffers::list_bytes(tiles, cap);
            let limit = cx.device.limits().max_storage_buffer_binding_size;
            if need > limit {
                cx.errors.report(format!(
                    "light culling: {tiles} tiles x {cap} list entries need a {} MiB buffer; this \
                     device binds at most {} MiB (lower methods.light-culling.max_lights_per_tile \
                     or raise tile_size)",
                    need >> 20,
                    limit >> 20
                ));
                enc.clear_buffer(cx.gi_accum, 0, None);
                self.state = None;
                return 1.0;
            }
            self.buffers = LcullBuffers::new(cx.device, vpl_capacity, cx.size, tiles, cap);
        }
        let frames = match self.state {
            Some((k, m, n)) if s.sampling.accumulate && k == cx.key && m == cx.method => n + 1,
            _ => 1,
        };
        self.state = Some((cx.key, cx.method, frames));
        let seed = Self::seed(s, cx.frame_index);
        let count = cx.vpl_frame.count.min(vpl_capacity);
        let il = Interleave::new(lc.interleave, count, seed);
        let p = GpuLcullParams {
            width: cx.size.0,
            height: cx.size.1,
            tile: lc.tile_size,
            n: lc.interleave,
            tiles_x,
            tiles_y,
            tiles,
            cap,
            count,
            offset: il.offset,
            seed,
            mode: (cx.method == CLAMPED) as u32,
            epsilon_max: lc.epsilon_max,
            exposure: s.display.exposure_ev.exp2(),
            eps: s.gi.distance_epsilon,
            ray_offset: s.gi.ray_offset,
            shadow_rays: s.gi.shadow_rays as u32,
            accumulate: (frames > 1) as u32,
            filter_radius: lc.filter_radius,
            trace_pixel: u32::MAX,
            filter_normal_cos: lc.filter_normal_cos,
            filter_plane_tolerance: lc.filter_plane_tolerance,
            stride: il.stride,
            _pad: 0,
        };
        self.settings = lc;
        let inputs = FrameInputs {
            scene: cx.scene,
            gbuffer: &cx.targets.gbuffer,
            camera: cx.camera,
            vpls: &cx.vpl_buffers.vpls,
            accum: cx.gi_accum,
        };
        self.pass.record(
            cx.diagnostics,
            cx.device,
            cx.queue,
            enc,
            cx.timer,
            p,
            &inputs,
            &self.buffers,
        );
        1.0 / frames as f32
    }

    fn after_submit(&mut self) {
        self.pass.stats.after_submit();
    }

    fn frames_averaged(&self) -> Option<u32> {
        Some(self.state.map_or(0, |(_, _, n)| n))
    }

    fn reset(&mut self) {
        self.state = None;
    }

    fn view_size(&self, _view: MethodView, frame: (u32, u32)) -> Option<(u32, u32)> {
        (self.buffers.size == frame && self.state.is_some()).then_some(frame)
    }

    fn record_view(&mut self, view: MethodView, cx: &mut ViewCx<'_>, enc: &mut wgpu::CommandEncoder) {
        let p = GpuLcullViewParams {
            mode: if view == LIST {
                0
            } else if view == OVERFLOW {
                1
            } else if view == PATTERN {
                2
            } else {
                3
            },
            scale_top: 10u32.pow(decades(self.settings.max_lights_per_tile)),
            exposure: cx.look.exposure_ev.exp2(),
            tonemap: cx.look.tonemap.gpu_id(),
            n: self.settings.interleave,
            cap: self.settings.max_lights_per_tile,
            _pad: [0; 2],
        };
        self.pass.record_view(
            cx.device,
            cx.queue,
            enc,
            cx.timer,
            p,
            &cx.targets.lighting.final_view,
            &cx.targets.gbuffer.position_view,
            &self.buffers,
            cx.dst,
        );
    }

    /// Per pixel: tile list length, VPLs in range, VPLs tested, shadow rays.
    fn read_view(&self, ctx: &GpuContext, _view: MethodView) -> Result<Option<ImageF32>, GpuError> {
        if self.state.is_none() {
            return Ok(None);
        }
        readback::read_vec4_image(ctx, &self.buffers.diag, self.buffers.size)
    }

    fn pixel_rows(
        &self,
        ctx: &GpuContext,
        x: u32,
        y: u32,
        frame: (u32, u32),
    ) -> Result<Vec<(&'static str, [f32; 4])>, GpuError> {
        let b = &self.buffers;
        if b.size != frame || x >= frame.0 || y >= frame.1 || self.state.is_none() {
            return Ok(Vec::new());
        }
        let d = readback::read_vec4_pixel(ctx, &b.diag, b.size.0, x, y)?;
        Ok(vec![(
            "light culling (tile list, VPLs in range, VPLs tested, shadow rays)",
            d,
        )])
    }

    fn legend(&self, view: MethodView, _tree_levels: u32) -> Option<Legend> {
        let st = self.pass.stats.last();
        let top = decades(self.settings.max_lights_per_tile) as f32;
        if view == LIST {
            Some(Legend {
                title: match st {
                    Some(st) => format!(
                        "lights per tile + 1 (mean {:.1}, longest {}, cap {})",
                        st.mean_list(),
                        st.longest_list,
                        self.settings.max_lights_per_tile
                    ),
                    None => "lights per tile + 1".into(),
                },
                lo: 0.0,
                hi: top,
                log: true,
            })
        } else if view == IN_RANGE {
            Some(Legend {
                title: match st {
                    Some(st) => format!(
                        "share of the list in range ({:.1} of {:.1} VPLs tested per pixel)",
                        st.in_range_per_pixel(),
                        st.tested_per_pixel()
                    ),
                    None => "share of the list in range".into(),
                },
                lo: 0.0,
                hi: 1.0,
                log: false,
            })
        } else {
            None
        }
    }

    fn stats(&mut self) -> Vec<(&'static str, f64)> {
        match self.pass.stats.poll() {
            Some(st) => vec![
                ("mean_tile_list", st.mean_list()),
                ("longest_tile_list", st.longest_list as f64),
                ("overflow_tiles", st.overflow_tiles as f64),
                ("vpls_tested_per_pixel", st.tested_per_pixel()),
                ("vpls_in_range_per_pixel", st.in_range_per_pixel()),
                ("shadow_rays_per_pixel", st.rays_per_pixel()),
                ("epsilon_max", self.settings.epsilon_max as f64),
                ("interleave", self.settings.interleave as f64),
            ],
            None => Vec::new(),
        }
    }

    fn status(&mut self) -> Option<String> {
        let st = self.pass.stats.poll()?;
        Some(format!(
            "culling {:.1} lights per tile (longest {}, {} over the cap of {}) · {:.1} in range \
             per pixel · {:.1} shadow rays per pixel",
            st.mean_list(),
            st.longest_list,
            st.overflow_tiles,
            self.settings.max_lights_per_tile,
            st.in_range_per_pixel(),
            st.rays_per_pixel()
        ))
    }
}

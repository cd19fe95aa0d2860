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
//! Visibility: `gi.shadow_rays` (none, as the paper's figures 1 and 4), then
//! `visibility`: BVH shadow rays, or one imperfect shadow map per VPL built each frame with
//! the points beyond its range culled (section 4.3, the shared `passes::ism`).
//!
//! Passes: `pass.rs`; CPU twins: `crate::reference::light_culling`; docs/light-culling.md.

pub mod pass;
pub mod settings;
mod ui;

use super::overlay::{MethodOverlay, Prim};
use super::{
    FrameCx, Kind, Legend, Method, MethodId, MethodInfo, MethodView, Module, Resource, ViewCx, ViewInfo,
};
use crate::reference::light_culling::{Interleave, TileGrid};
use crate::renderer::passes::interleave_filter::GpuFilterParams;
use crate::renderer::passes::ism::{IsmPoints, IsmTargets};
use crate::renderer::{
    context::{GpuContext, GpuError},
    readback::{self, ImageF32},
    settings::RenderSettings,
    shaders::ShaderError,
};
use pass::{
    FrameInputs, GpuLcullParams, GpuLcullViewParams, IsmFrame, LcullBuffers, LcullPass, LcullStats,
    TreeCullBuffers, TreeInputs, VISIBILITY_ISM,
};
use settings::{CullingVisibility, IsmAdaptive, IsmSettings, LightCullingSettings};

/// The paper's stochastic light culling.
pub const ID: MethodId = MethodId::new("light-culling");
/// The clamped-range baseline (appendix A).
pub const CLAMPED: MethodId = MethodId::new("light-culling-clamped");
/// Section 5's bounding-sphere-tree culling with per-pixel reservoir lists and one shadow ray.
pub const TREE: MethodId = MethodId::new("light-culling-tree");

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
        shader!("lcull_light.wgsl"),
        shader!("lcull_term.wgsl"),
        shader!("lcull_ranges.wgsl"),
        shader!("lcull_tree.wgsl"),
        shader!("lcull_tiles.wgsl"),
        shader!("lcull_shade.wgsl"),
        shader!("lcull_views.wgsl"),
    ],
    entry_shaders: &[
        "methods/light_culling/lcull_ranges.wgsl",
        "methods/light_culling/lcull_tiles.wgsl",
        "methods/light_culling/lcull_shade.wgsl",
        "methods/light_culling/lcull_tree.wgsl",
        "methods/light_culling/lcull_views.wgsl",
    ],
    wgsl_twins: pass::WGSL_TWINS,
    own_workgroups: &[crate::renderer::passes::OwnWorkgroup {
        // One workgroup per tile.
        file: "methods/light_culling/lcull_tiles.wgsl",
        entries: &[],
        size: [pass::TILE_WG, 1, 1],
    }],
};

/// The pixel's tile list length (log heat map).
pub const LIST: MethodView = MethodView::new("culling lights per tile");
/// Tiles over their list's cap (red over the grey final).
pub const OVERFLOW: MethodView = MethodView::new("culling overflow");
/// The interleaving pattern (a colour per subset).
pub const PATTERN: MethodView = MethodView::new("culling pattern");
/// The share of the tile's list in range of each pixel.
pub const IN_RANGE: MethodView = MethodView::new("culling list share in range");
/// Clamped minus stochastic, relative (the darkening the paper is about).
pub const DIFFERENCE: MethodView = MethodView::new("culling clamped vs stochastic");
/// The difference view's colour scale: relative differences of +-this map to its ends.
pub const DIFFERENCE_RANGE: f32 = 0.5;
/// The VPLs' imperfect shadow maps (the atlas; built while drawn even with rays).
pub const ISM_ATLAS: MethodView = MethodView::new("culling ISM atlas");
/// Seed of the scene's point cloud for the maps.
pub const ISM_CLOUD_SEED: u32 = 0x15a1;

const ISM_VIEW: ViewInfo = ViewInfo {
    name: ISM_ATLAS.name(),
    file: "culling_ism_atlas",
    about: "the VPLs' imperfect shadow maps (one paraboloid map per VPL, the tree variant per \
            leaf; section 4.4's AISMs, culled as `methods.light-culling.ism` and \
            `ism_range_culling` say): distance on a log scale, texels pull-push filled at half \
            brightness, holes black; built each frame with ISM visibility, or while this view \
            is shown",
    passes: &["lcull_ism"],
};

/// The tree variant: VPLs in range of the pixel (log heat map).
pub const TREE_IN_RANGE: MethodView = MethodView::new("culling tree VPLs in range");
/// The tree variant: nodes its traversal visited (log heat map).
pub const TREE_VISITED: MethodView = MethodView::new("culling tree nodes visited");

const TREE_VIEWS: &[ViewInfo] = &[
    ViewInfo {
        name: TREE_IN_RANGE.name(),
        file: "culling_tree_vpls_in_range",
        about: "m: the VPLs whose stochastic range holds the pixel's point (the traversal's \
                overlapping leaves; the list keeps k of them), log scale",
        passes: &["lcull_tree_traverse"],
    },
    ViewInfo {
        name: TREE_VISITED.name(),
        file: "culling_tree_nodes_visited",
        about: "bounding-sphere-tree nodes the pixel's traversal visited, log scale",
        passes: &["lcull_tree_traverse"],
    },
    ISM_VIEW,
];

/// Range spheres drawn for the pinned pixel's tile at most (those holding the pixel first).
pub const OVERLAY_SPHERES: usize = 64;

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
    ViewInfo {
        name: DIFFERENCE.name(),
        file: "culling_clamped_vs_stochastic",
        about: "(clamped - stochastic) / their mean per pixel, each averaged over its frames: \
                the clamped ranges' darkening (low, blue) against the unbiased stochastic \
                image; while shown, diagnostic frames also run the other variant",
        passes: &["lcull_companion_shade"],
    },
    ISM_VIEW,
];

fn invalid_example(s: &mut RenderSettings) -> &'static str {
    let mut lc = LightCullingSettings::default();
    lc.interleave.n = 0;
    let _ = s.set_method(ID, &lc);
    "methods.light-culling.interleave.n"
}

const TESTS: &[&str] = &[
    "light_culling::gpu_ranges_and_tile_lists_equal_the_cpu_reference",
    "light_culling::gpu_shading_and_filter_equal_the_cpu_reference_and_overflow_changes_nothing",
    "light_culling::the_mean_over_frames_converges_to_the_unshadowed_ground_truth_and_clamping_darkens",
    "light_culling::ism_visibility_equals_the_cpu_lookups_and_agrees_with_shadow_rays",
    "light_culling::with_ggx_the_shading_equals_the_cpu_and_the_means_converge_to_the_ggx_truth",
];

const TREE_TESTS: &[&str] = &[
    "light_culling::the_tree_variant_equals_the_cpu_and_its_mean_converges_to_the_unshadowed_truth",
    "light_culling::ism_visibility_equals_the_cpu_lookups_and_agrees_with_shadow_rays",
    "light_culling::with_ggx_the_shading_equals_the_cpu_and_the_means_converge_to_the_ggx_truth",
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
    timed_passes: &[
        "lcull_ranges",
        "lcull_ism",
        "lcull_tiles",
        "lcull_shade",
        "lcull_filter",
    ],
    story: false,
    shadow_ray_switch: true,
    truth_of_vpls: false,
    one_bounce: false,
    glossy: true,
    validate,
    fields,
    invalid_example: Some(invalid_example),
    ui: ui::settings_ui,
    tests: TESTS,
    sweep: Some(&SWEEP),
    bias: stochastic_bias,
    unbiased: Some(super::Unbiased {
        how: "methods.light-culling.interleave.filter_radius = 0 (interleaving alone)",
        apply: no_filter,
    }),
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
    timed_passes: &[
        "lcull_ranges",
        "lcull_ism",
        "lcull_tiles",
        "lcull_shade",
        "lcull_filter",
    ],
    story: false,
    shadow_ray_switch: true,
    truth_of_vpls: false,
    one_bounce: false,
    glossy: true,
    validate,
    fields,
    invalid_example: Some(invalid_example),
    ui: ui::settings_ui,
    tests: TESTS,
    sweep: Some(&SWEEP),
    bias: clamped_bias,
    unbiased: None,
};

pub static TREE_INFO: MethodInfo = MethodInfo {
    id: TREE,
    aliases: &["light-culling-sphere-tree"],
    label: "Light culling, bounding-sphere tree",
    short: "tree culling",
    about: "Stochastic Light Culling's section 5: the same stochastic ranges culled per pixel \
            through a bounding-sphere tree of the VPLs, k of the overlapping VPLs kept by \
            reservoir sampling, one of them shaded (resampled importance sampling, one \
            shadow ray).",
    progress_unit: "",
    kind: Kind::PerFrame,
    module: &MODULE,
    reads: &[Resource::Gbuffer, Resource::Tree, Resource::Bvh],
    views: TREE_VIEWS,
    timed_passes: &[
        "lcull_tree_leaves",
        "lcull_ism",
        "lcull_tree_traverse",
        "lcull_tree_shade",
        "lcull_filter",
    ],
    story: false,
    shadow_ray_switch: true,
    truth_of_vpls: false,
    one_bounce: false,
    glossy: true,
    validate,
    fields,
    invalid_example: Some(invalid_example),
    ui: ui::settings_ui,
    tests: TREE_TESTS,
    sweep: Some(&SWEEP),
    bias: tree_bias,
    unbiased: Some(super::Unbiased {
        how: "methods.light-culling.tree_filter_radius = 0",
        apply: no_filter,
    }),
};

/// What biases every variant alike: imperfect shadow maps, the geometry-aware filter (the
/// filter `radius` the variant uses); None when neither is on.
fn shared_bias(s: &RenderSettings, radius: u32) -> Option<super::Bias> {
    let lc: LightCullingSettings = s.method(ID).unwrap_or_default();
    if s.gi.shadow_rays && lc.visibility == CullingVisibility::Ism {
        Some(super::Bias::Biased {
            tolerance: 0.35,
            reason: "imperfect shadow maps for visibility (mean 1.074x the rays' image: docs/light-culling.md)",
        })
    } else if radius > 0 {
        Some(super::Bias::Biased {
            tolerance: 0.05,
            reason: "the geometry-aware filter averages neighbours' light (section 4.2)",
        })
    } else {
        None
    }
}

/// The variants without the filter (interleaving alone stays unbiased).
fn no_filter(s: &mut RenderSettings) {
    let mut lc: LightCullingSettings = s.method(ID).unwrap_or_default();
    (lc.interleave.filter_radius, lc.tree_filter_radius) = (0, 0);
    let _ = s.set_method(ID, &lc);
}

/// Stochastic ranges are unbiased Russian roulette (eq. 2); interleaving alone keeps it so.
fn stochastic_bias(s: &RenderSettings) -> super::Bias {
    let lc: LightCullingSettings = s.method(ID).unwrap_or_default();
    shared_bias(s, lc.interleave.filter_radius).unwrap_or(super::Bias::Unbiased)
}

/// Appendix A's deterministic ranges drop every VPL's light beyond its range: darker (the
/// filter's smaller bias is inside this tolerance).
fn clamped_bias(s: &RenderSettings) -> super::Bias {
    match shared_bias(s, 0) {
        Some(ism) => ism,
        None => super::Bias::Biased {
            tolerance: 0.10,
            reason: "clamped ranges drop each VPL's light beyond its range (appendix A: darker)",
        },
    }
}

/// Section 5's tree: the same stochastic ranges, and a resampled VPL divided by its
/// resampling probability: unbiased.
fn tree_bias(s: &RenderSettings) -> super::Bias {
    let lc: LightCullingSettings = s.method(ID).unwrap_or_default();
    shared_bias(s, lc.tree_filter_radius).unwrap_or(super::Bias::Unbiased)
}

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

/// The methods that can look VPLs up in imperfect shadow maps (`render --visibility ism`):
/// light culling's three variants and the tree samplers (a map per light-tree leaf).
pub const ISM_METHODS: [MethodId; 6] = [
    ID,
    CLAMPED,
    TREE,
    super::tree_samplers::SLC,
    super::tree_samplers::SST,
    super::tree_samplers::RTSLC,
];

/// Whether `m` can use ISM visibility.
pub fn has_ism(m: MethodId) -> bool {
    ISM_METHODS.contains(&m)
}

/// Sets light culling's and the tree samplers' visibility (while `gi.shadow_rays` is on):
/// maps or rays.
pub fn set_visibility(s: &mut RenderSettings, ism: bool) {
    s.sampling.visibility = if ism {
        super::tree_samplers::settings::SamplerVisibility::Ism
    } else {
        super::tree_samplers::settings::SamplerVisibility::Rays
    };
    // A malformed table is left for validation to name.
    let Ok(mut lc) = s.method::<LightCullingSettings>(ID) else {
        return;
    };
    lc.visibility = if ism {
        settings::CullingVisibility::Ism
    } else {
        settings::CullingVisibility::Rays
    };
    // Cannot fail: the struct serialises to a table.
    let _ = s.set_method(ID, &lc);
}

fn validate(s: &RenderSettings) -> Result<(), String> {
    let lc = s.method::<LightCullingSettings>(ID)?;
    lc.validate()?;
    // The geometry-aware filter averages Lambert's irradiance-like `raw` over a window and
    // multiplies the pixel's albedo / pi back; a glossy BRDF's radiance cannot be averaged so.
    // Interleaving alone (each pixel its subset x n^2) stays unbiased.
    let culling = [ID, CLAMPED, TREE].contains(&s.gi.method);
    if culling && s.gi.brdf == crate::renderer::settings::Brdf::Ggx {
        let (name, r) = if s.gi.method == TREE {
            ("tree_filter_radius", lc.tree_filter_radius)
        } else {
            ("interleave.filter_radius", lc.interleave.filter_radius)
        };
        if r > 0 {
            return Err(format!(
                "gi.brdf = Ggx with methods.light-culling.{name} {r}: the geometry-aware filter averages Lambert's irradiance and multiplies the albedo / pi back; set methods.light-culling.{name}=0 (interleaving alone stays unbiased) or use gi.brdf = Lambert"
            ));
        }
    }
    Ok(())
}

/// Decades of the list-length scales: 1 .. 10^decades >= cap.
fn decades(cap: u32) -> u32 {
    (cap.max(2) as f32).log10().ceil().min(9.0) as u32
}

pub struct LightCulling {
    pass: LcullPass,
    buffers: LcullBuffers,
    /// The tree variant's (allocated by its first frame).
    tree: Option<TreeCullBuffers>,
    /// Accumulation: (key, method, frames summed).
    state: Option<(u64, MethodId, u32)>,
    /// The difference view's companion (the other variant) accumulation, alike.
    companion: Option<(u64, MethodId, u32)>,
    settings: LightCullingSettings,
    /// The scene's point cloud for the maps and the scene upload it was sampled from.
    ism_points: Option<(u64, IsmPoints)>,
    ism_targets: Option<IsmTargets>,
    /// Maps built by the last frame (0: none).
    ism_maps: u32,
    /// Whether the last frame looked its VPLs up in the maps (else rays or none).
    ism_on: bool,
    /// The atlas view's linear data (its size, the buffer).
    ism_view_data: Option<((u32, u32), wgpu::Buffer)>,
    scene_radius: f32,
}

fn create(device: &wgpu::Device) -> Result<Box<dyn Method>, ShaderError> {
    Ok(Box::new(LightCulling {
        pass: LcullPass::new(device)?,
        buffers: LcullBuffers::new(device, 1, (1, 1), 1, 1),
        tree: None,
        state: None,
        companion: None,
        settings: LightCullingSettings::default(),
        ism_points: None,
        ism_targets: None,
        ism_maps: 0,
        ism_on: false,
        ism_view_data: None,
        scene_radius: 1.0,
    }))
}

/// The frame's maps to build, borrowing the method's ISM state.
fn ism_frame<'a>(
    settings: &'a IsmSettings<IsmAdaptive>,
    points: &'a Option<(u64, IsmPoints)>,
    targets: &'a Option<IsmTargets>,
    maps: u32,
    build: bool,
) -> Option<IsmFrame<'a>> {
    let (Some((_, points)), Some(targets)) = (points.as_ref(), targets.as_ref()) else {
        return None;
    };
    build.then_some(IsmFrame {
        settings,
        points,
        targets,
        maps: maps.min(targets.capacity),
    })
}

impl LightCulling {
    pub fn buffers(&self) -> &LcullBuffers {
        &self.buffers
    }
    /// The tree variant's buffers (None before its first frame).
    pub fn tree_buffers(&self) -> Option<&TreeCullBuffers> {
        self.tree.as_ref()
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
            n: lc.interleave.n,
        }
    }
    /// Whether the last frame ran the tree variant.
    fn is_tree(&self) -> bool {
        self.state.is_some_and(|(_, m, _)| m == TREE)
    }
    /// Decades of a heat-map view's log scale: the tile list's cap, the tree's VPLs (VPLs in
    /// range) or its nodes (nodes visited).
    fn view_decades(&self, view: MethodView) -> u32 {
        let leaves = self.tree.as_ref().map_or(2, |t| t.leaves);
        if view == TREE_IN_RANGE {
            decades(leaves)
        } else if view == TREE_VISITED {
            decades(2 * leaves)
        } else {
            decades(self.settings.max_lights_per_tile)
        }
    }
    /// Frames in the difference view's companion image when it matches the method's own
    /// (same key, the other variant); None otherwise.
    pub fn companion_frames(&self) -> Option<u32> {
        let (k, m, _) = self.state?;
        let (ck, cm, n) = self.companion?;
        (ck == k && cm != m && n > 0).then_some(n)
    }
    /// Counters of a recent diagnostic frame (non-blocking).
    pub fn poll_stats(&mut self) -> Option<LcullStats> {
        self.pass.stats.poll()
    }
    /// The imperfect shadow maps of the last frame that built them (None before), and how
    /// many maps it built.
    pub fn ism_targets(&self) -> Option<(&IsmTargets, u32)> {
        self.ism_targets.as_ref().map(|t| (t, self.ism_maps))
    }

    /// The point cloud and the atlas for `s` on the frame's scene (rebuilt when either
    /// changed).
    fn ensure_ism(&mut self, cx: &FrameCx<'_>, s: &IsmSettings<IsmAdaptive>) {
        crate::renderer::passes::ism::ensure_maps(
            cx.device,
            cx.queue,
            cx.scene,
            s,
            ISM_CLOUD_SEED,
            &mut self.ism_points,
            &mut self.ism_targets,
        );
    }

    /// The frame's visibility and maps: (GpuLcullParams::shadow_rays, ism_flags, maps to
    /// build); None (reported) when ISM visibility needs more maps than the atlas holds.
    fn plan_ism(
        &mut self,
        cx: &FrameCx<'_>,
        lc: &LightCullingSettings,
        maps: u32,
    ) -> Option<(u32, u32, u32)> {
        let on = lc.uses_ism(cx.settings.gi.shadow_rays);
        let shown = cx.diagnostics && cx.views.contains(&ISM_ATLAS);
        let rays = if on {
            VISIBILITY_ISM
        } else {
            cx.settings.gi.shadow_rays as u32
        };
        // Failures leave no maps behind (the view and the counters say none).
        self.ism_on = false;
        self.ism_maps = 0;
        let tree = cx.method == TREE;
        if on && maps > lc.ism.capacity() {
            let what = if tree {
                format!(
                    "a map per leaf of the light tree ({} VPLs in {maps} leaves)",
                    cx.vpl_frame.count
                )
            } else {
                format!("a map per VPL ({maps})")
            };
            cx.errors.report(format!(
                "light culling: ISM visibility needs {what}, but an atlas of {} with {} x {} \
                 maps holds {} (raise methods.light-culling.ism.atlas, lower ism.tile or the VPL \
                 count)",
                lc.ism.atlas,
                lc.ism.tile,
                lc.ism.tile,
                lc.ism.capacity()
            ));
            return None;
        }
        let need = lc.ism.atlas_bytes();
        let limit = cx.device.limits().max_storage_buffer_binding_size;
        if (on || shown) && need > limit {
            cx.errors.report(format!(
                "light culling: an ISM atlas of {0} x {0} needs a {1} MiB buffer; this device \
                 binds at most {2} MiB (lower methods.light-culling.ism.atlas)",
                lc.ism.atlas,
                need >> 20,
                limit >> 20
            ));
            return None;
        }
        self.ism_on = on;
        if !(on || shown) {
            self.ism_maps = 0;
            return Some((rays, 0, 0));
        }
        self.ensure_ism(cx, &lc.ism);
        self.ism_maps = maps.min(lc.ism.capacity());
        Some((rays, 1 | (lc.ism_range_culling as u32) << 1, self.ism_maps))
    }
}

impl LightCulling {
    /// The tree variant's frame (section 5): `p` is the tiled frame's parameters.
    fn record_tree(
        &mut self,
        cx: &mut FrameCx<'_>,
        enc: &mut wgpu::CommandEncoder,
        p: GpuLcullParams,
        fp: GpuFilterParams,
        frames: u32,
    ) -> f32 {
        let lc = &self.settings;
        let leaves = cx.tree.leaves.max(1);
        let k = lc.reservoir_k;
        if !self.tree.as_ref().is_some_and(|t| t.matches(cx.size, leaves, k)) {
            let need = TreeCullBuffers::list_bytes(cx.size, k);
            let limit = cx.device.limits().max_storage_buffer_binding_size;
            if need > limit {
                cx.errors.report(format!(
                    "light culling (tree): {} x {} pixels x k = {k} list entries need a {} MiB \
                     buffer; this device binds at most {} MiB (lower \
                     methods.light-culling.reservoir_k or the resolution)",
                    cx.size.0,
                    cx.size.1,
                    need >> 20,
                    limit >> 20
                ));
                enc.clear_buffer(cx.gi_accum, 0, None);
                self.state = None;
                return 1.0;
            }
            self.tree = Some(TreeCullBuffers::new(cx.device, cx.size, leaves, k));
        }
        let Some(t) = self.tree.as_ref() else {
            return 0.0;
        };
        let tp = GpuLcullParams {
            n: 1,
            cap: k,
            count: leaves,
            mode: 2,
            leaves,
            ..p
        };
        let fp = GpuFilterParams {
            radius: lc.tree_filter_radius,
            ..fp
        };
        let inputs = FrameInputs {
            scene: cx.scene,
            gbuffer: &cx.targets.gbuffer,
            camera: cx.camera,
            vpls: &cx.vpl_buffers.vpls,
            accum: cx.gi_accum,
        };
        let tree = TreeInputs {
            nodes: &cx.tree.nodes,
            sorted_vpls: &cx.tree.sorted_vpls,
        };
        let ism = ism_frame(
            &self.settings.ism,
            &self.ism_points,
            &self.ism_targets,
            self.ism_maps,
            tp.ism_flags & 1 != 0,
        );
        self.pass.record_tree(
            cx.diagnostics,
            cx.device,
            cx.queue,
            enc,
            cx.timer,
            tp,
            fp,
            &inputs,
            &tree,
            &self.buffers,
            t,
            ism.as_ref(),
        );
        1.0 / frames as f32
    }
}

impl Method for LightCulling {
    fn record(&mut self, cx: &mut FrameCx<'_>, enc: &mut wgpu::CommandEncoder) -> f32 {
        let s = cx.settings;
        let lc: LightCullingSettings = s.method(ID).unwrap_or_default();
        let grid = Self::grid(&lc, cx.size);
        let (tiles_x, tiles_y) = grid.per_subset();
        // The tree variant uses no tile lists (one entry, never read).
        let tree = cx.method == TREE;
        let (tiles, cap) = if tree {
            (1, 1)
        } else {
            (grid.count(), lc.max_lights_per_tile)
        };
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
                self.companion = None;
                return 1.0;
            }
            self.buffers = LcullBuffers::new(cx.device, vpl_capacity, cx.size, tiles, cap);
            self.companion = None;
        }
        let frames = match self.state {
            Some((k, m, n)) if s.sampling.accumulate && k == cx.key && m == cx.method => n + 1,
            _ => 1,
        };
        let seed = Self::seed(s, cx.frame_index);
        let count = cx.vpl_frame.count.min(vpl_capacity);
        self.scene_radius = cx.scene_radius;
        let maps = if tree { cx.tree.leaves.max(1) } else { count };
        let Some((visibility, ism_flags, _)) = self.plan_ism(cx, &lc, maps) else {
            enc.clear_buffer(cx.gi_accum, 0, None);
            self.state = None;
            self.companion = None;
            return 1.0;
        };
        self.state = Some((cx.key, cx.method, frames));
        let il = Interleave::new(lc.interleave.n, count, seed);
        let p = GpuLcullParams {
            width: cx.size.0,
            height: cx.size.1,
            tile: lc.tile_size,
            n: lc.interleave.n,
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
            shadow_rays: visibility,
            stride: il.stride,
            leaves: 0,
            ism_flags,
            brdf: cx.brdf.gpu(),
            _pad: [0; 3],
            eye: cx.eye.extend(0.0).to_array(),
        };
        // The filter: raw (before albedo / pi) x albedo / pi into the accumulation; with GGX
        // raw is radiance already (and validation keeps the filter's window to the pixel).
        let glossy = cx.brdf != crate::renderer::settings::Brdf::Lambert;
        let fp = GpuFilterParams {
            accumulate: (frames > 1) as u32,
            scale: if glossy { 1.0 } else { std::f32::consts::FRAC_1_PI },
            modulate: (!glossy) as u32,
            ..GpuFilterParams::new(cx.size, &lc.interleave)
        };
        self.settings = lc;
        if cx.method == TREE {
            return self.record_tree(cx, enc, p, fp, frames);
        }
        // The difference view's companion: the other variant with the same settings, in
        // diagnostic frames while the view is drawn, recorded first (the own run then leaves
        // its lists and counters for the other views).
        if cx.diagnostics && cx.views.contains(&DIFFERENCE) {
            self.buffers.ensure_companion(cx.device);
            let other = if cx.method == CLAMPED { ID } else { CLAMPED };
            let n = match self.companion {
                Some((k, m, n)) if s.sampling.accumulate && k == cx.key && m == other => n + 1,
                _ => 1,
            };
            self.companion = Some((cx.key, other, n));
            let cp = GpuLcullParams {
                mode: (other == CLAMPED) as u32,
                ..p
            };
            let cfp = GpuFilterParams {
                accumulate: (n > 1) as u32,
                ..fp
            };
            let Some(companion) = self.buffers.companion.as_ref() else {
                return 0.0;
            };
            let inputs = FrameInputs {
                scene: cx.scene,
                gbuffer: &cx.targets.gbuffer,
                camera: cx.camera,
                vpls: &cx.vpl_buffers.vpls,
                accum: &companion.accum,
            };
            let ism = ism_frame(
                &self.settings.ism,
                &self.ism_points,
                &self.ism_targets,
                self.ism_maps,
                ism_flags & 1 != 0,
            );
            self.pass.record(
                true,
                true,
                cx.device,
                cx.queue,
                enc,
                cx.timer,
                cp,
                cfp,
                &inputs,
                &self.buffers,
                ism.as_ref(),
            );
        }
        let inputs = FrameInputs {
            scene: cx.scene,
            gbuffer: &cx.targets.gbuffer,
            camera: cx.camera,
            vpls: &cx.vpl_buffers.vpls,
            accum: cx.gi_accum,
        };
        let ism = ism_frame(
            &self.settings.ism,
            &self.ism_points,
            &self.ism_targets,
            self.ism_maps,
            ism_flags & 1 != 0,
        );
        self.pass.record(
            false,
            cx.diagnostics,
            cx.device,
            cx.queue,
            enc,
            cx.timer,
            p,
            fp,
            &inputs,
            &self.buffers,
            ism.as_ref(),
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
        self.companion = None;
    }

    fn view_size(&self, view: MethodView, frame: (u32, u32)) -> Option<(u32, u32)> {
        if view == ISM_ATLAS && (self.ism_maps == 0 || self.ism_targets.is_none()) {
            return None;
        }
        (self.buffers.size == frame && self.state.is_some()).then_some(frame)
    }

    fn record_view(&mut self, view: MethodView, cx: &mut ViewCx<'_>, enc: &mut wgpu::CommandEncoder) {
        if view == ISM_ATLAS {
            let size = self.buffers.size;
            if self.ism_view_data.as_ref().is_none_or(|(s, _)| *s != size) {
                let bytes = 16 * size.0 as u64 * size.1 as u64;
                let data = cx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("lcull::ism_view_data"),
                    size: bytes.max(16),
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                });
                self.ism_view_data = Some((size, data));
            }
            if let (Some(t), Some((_, data))) = (self.ism_targets.as_ref(), self.ism_view_data.as_ref()) {
                let r = self.scene_radius;
                self.pass.ism.record_view(
                    cx.device,
                    cx.queue,
                    enc,
                    cx.timer,
                    t,
                    self.ism_maps,
                    (0.005 * r, 2.0 * r),
                    size,
                    cx.dst,
                    data,
                );
            }
            return;
        }
        let p = GpuLcullViewParams {
            mode: if view == LIST || view == TREE_IN_RANGE {
                0
            } else if view == OVERFLOW {
                1
            } else if view == PATTERN {
                2
            } else if view == IN_RANGE {
                3
            } else if view == DIFFERENCE {
                4
            } else {
                5
            },
            scale_top: 10u32.pow(self.view_decades(view)),
            exposure: cx.look.exposure_ev.exp2(),
            tonemap: cx.look.tonemap.gpu_id(),
            n: self.settings.interleave.n,
            cap: self.settings.max_lights_per_tile,
            own_scale: self.state.map_or(0.0, |(_, _, n)| 1.0 / n.max(1) as f32),
            companion_scale: self.companion_frames().map_or(0.0, |n| 1.0 / n as f32),
            own_is_clamped: self.state.is_some_and(|(_, m, _)| m == CLAMPED) as u32,
            range: DIFFERENCE_RANGE,
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
            &cx.targets.lighting.gi_accum,
            &self.buffers,
            cx.dst,
        );
    }

    /// Per pixel: tile list length, VPLs in range, VPLs tested, shadow rays; the difference
    /// view: (relative difference, clamped luminance, stochastic luminance, 1 where both
    /// images exist) as last drawn.
    fn read_view(&self, ctx: &GpuContext, view: MethodView) -> Result<Option<ImageF32>, GpuError> {
        if self.state.is_none() {
            return Ok(None);
        }
        if view == ISM_ATLAS {
            return match self.ism_view_data.as_ref() {
                Some((size, data)) if self.ism_maps > 0 => readback::read_vec4_image(ctx, data, *size),
                _ => Ok(None),
            };
        }
        if view == DIFFERENCE {
            return match self.buffers.companion.as_ref() {
                Some(c) if self.companion_frames().is_some() => {
                    readback::read_vec4_image(ctx, &c.difference, self.buffers.size)
                }
                _ => Ok(None),
            };
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
            if self.is_tree() {
                "tree culling (VPLs in range, listed, nodes visited, shadow rays or ISM lookups)"
            } else {
                "light culling (tile list, VPLs in range, VPLs tested, shadow rays or ISM lookups)"
            },
            d,
        )])
    }

    /// The range spheres of the pinned pixel's tile list (the tree variant: of its
    /// reservoir list) in the last frame, those holding the pixel's point first, at most
    /// [`OVERLAY_SPHERES`]. (Its per-pixel counters are the last diagnostic frame's: the
    /// pixel-values window.)
    fn read_overlay(
        &self,
        ctx: &GpuContext,
        pixel: (u32, u32),
        position: glam::Vec3,
    ) -> Result<Option<MethodOverlay>, GpuError> {
        let b = &self.buffers;
        let (x, y) = pixel;
        if self.state.is_none() || x >= b.size.0 || y >= b.size.1 {
            return Ok(None);
        }
        let read_spheres =
            |lights: &wgpu::Buffer, capacity: u32, list: &[u32]| -> Result<Vec<[f32; 4]>, GpuError> {
                let ranges: Vec<(u64, u64)> = list
                    .iter()
                    .filter(|&&i| i < capacity)
                    .map(|&i| (32 * i as u64, 16))
                    .collect();
                Ok(readback::read_buffer_ranges(ctx, lights, &ranges)?
                    .iter()
                    .map(|v| bytemuck::pod_read_unaligned::<[f32; 4]>(&v[..16]))
                    .collect())
            };
        let (title, mut rows, spheres) = if self.is_tree() {
            let Some(t) = self.tree.as_ref().filter(|t| t.size == b.size) else {
                return Ok(None);
            };
            let k = (y * b.size.0 + x) as u64;
            let mv = readback::read_buffer_range(ctx, &t.m, 8 * k, 8)?;
            let [m, visited]: [u32; 2] = bytemuck::pod_read_unaligned(&mv[..8]);
            let listed = m.min(t.k);
            let list: Vec<u32> = if listed > 0 {
                bytemuck::pod_collect_to_vec(&readback::read_buffer_range(
                    ctx,
                    &t.list,
                    4 * k * t.k as u64,
                    4 * listed as u64,
                )?)
            } else {
                Vec::new()
            };
            let spheres = read_spheres(&t.lights, t.leaves, &list)?;
            let rows = vec![
                (
                    "VPLs in range (m) / listed (k)".to_string(),
                    format!(
                        "{m} / {listed} (k = {}; each kept with probability min(k / m, 1))",
                        t.k
                    ),
                ),
                ("tree nodes visited".into(), visited.to_string()),
            ];
            (
                "the range spheres of its reservoir list (bounding-sphere tree, section 5)".to_string(),
                rows,
                spheres,
            )
        } else {
            let grid = Self::grid(&self.settings, b.size);
            let t = grid.tile_of(x, y);
            if t >= b.tiles {
                return Ok(None);
            }
            let count_bytes = readback::read_buffer_range(ctx, &b.tile_count, 4 * t as u64, 4)?;
            let count = bytemuck::pod_read_unaligned::<u32>(&count_bytes[..4]);
            let listed = count.min(b.cap);
            let list: Vec<u32> = if listed > 0 {
                bytemuck::pod_collect_to_vec(&readback::read_buffer_range(
                    ctx,
                    &b.tile_lists,
                    4 * t as u64 * b.cap as u64,
                    4 * listed as u64,
                )?)
            } else {
                Vec::new()
            };
            let spheres = read_spheres(&b.lights, b.vpl_capacity, &list)?;
            let subset = x % grid.n + grid.n * (y % grid.n);
            let rows = vec![
                (
                    "tile (interleaving subset)".to_string(),
                    format!("{t} (subset {subset} of {})", grid.n * grid.n),
                ),
                (
                    "VPLs in the tile's list".into(),
                    if count > b.cap {
                        format!(
                            "{count}: over the cap of {}, the pixel tests its whole subset",
                            b.cap
                        )
                    } else {
                        count.to_string()
                    },
                ),
            ];
            let variant = if self.state.is_some_and(|(_, m, _)| m == CLAMPED) {
                "clamped ranges"
            } else {
                "stochastic ranges of the frame's xi"
            };
            (
                format!("the range spheres of its tile's light list ({variant})"),
                rows,
                spheres,
            )
        };
        let holds = |s: &[f32; 4]| glam::Vec3::new(s[0], s[1], s[2]).distance(position) < s[3];
        let mut order: Vec<usize> = (0..spheres.len()).collect();
        order.sort_by_key(|&k| !holds(&spheres[k]));
        let inside = spheres.iter().filter(|s| holds(s)).count();
        let mut prims = Vec::new();
        for &k in order.iter().take(OVERLAY_SPHERES) {
            let s = spheres[k];
            let c = glam::Vec3::new(s[0], s[1], s[2]);
            let color = if holds(&s) {
                egui::Color32::from_rgb(90, 230, 110)
            } else {
                egui::Color32::from_rgba_unmultiplied(255, 160, 40, 140)
            };
            prims.push(Prim::Sphere {
                center: c,
                radius: s[3].min(1e6),
                color,
            });
            prims.push(Prim::Point(c, color));
        }
        prims.push(Prim::Point(position, egui::Color32::WHITE));
        rows.push((
            "range spheres holding the pixel's point".into(),
            format!("{inside} of {} listed", spheres.len()),
        ));
        let (rmin, rmax) = spheres
            .iter()
            .fold((f32::INFINITY, 0.0f32), |(a, b), s| (a.min(s[3]), b.max(s[3])));
        if !spheres.is_empty() {
            rows.push((
                "range radii of the list (scene units)".into(),
                format!("{rmin:.3} .. {rmax:.3}"),
            ));
        }
        rows.push((
            "spheres drawn".into(),
            format!("{} of {}", spheres.len().min(OVERLAY_SPHERES), spheres.len()),
        ));
        Ok(Some(MethodOverlay {
            title,
            rows,
            key: if self.is_tree() {
                "green: the listed VPLs (each range sphere holds the pixel's point; one of them \
                 is shaded, resampled by eq. 8); white: the pixel"
                    .into()
            } else {
                "green: listed VPLs whose range sphere holds the pixel's point (the ones that \
                 light it); orange: listed for the tile but out of the pixel's range; white: \
                 the pixel"
                    .into()
            },
            prims,
        }))
    }

    fn legend(&self, view: MethodView, _tree_levels: u32) -> Option<Legend> {
        if view == ISM_ATLAS {
            let r = self.scene_radius;
            let tile = self.ism_targets.as_ref().map_or(0, |t| t.layout.tile);
            return Some(Legend {
                title: if self.ism_maps == 0 {
                    "no maps this frame (ISM visibility off and the view not drawn yet, or \
                     refused: see the problems window)"
                        .to_string()
                } else {
                    format!(
                        "distance from the VPL ({} maps of {tile}^2; dim: filled by pull-push; \
                         black: hole)",
                        self.ism_maps
                    )
                },
                lo: (0.005 * r).log10(),
                hi: (2.0 * r).log10(),
                log: true,
            });
        }
        let st = self.pass.stats.last();
        let top = self.view_decades(view) as f32;
        if view == TREE_IN_RANGE {
            return Some(Legend {
                title: match st {
                    Some(st) => format!(
                        "VPLs in range + 1 (mean {:.1}, most {}; {} pixels over k = {})",
                        st.in_range_per_pixel(),
                        st.longest_list,
                        st.overflow_tiles,
                        self.settings.reservoir_k
                    ),
                    None => "VPLs in range + 1".into(),
                },
                lo: 0.0,
                hi: top,
                log: true,
            });
        }
        if view == TREE_VISITED {
            return Some(Legend {
                title: match st {
                    Some(st) => format!("tree nodes visited + 1 (mean {:.1})", st.visited_per_pixel()),
                    None => "tree nodes visited + 1".into(),
                },
                lo: 0.0,
                hi: top,
                log: true,
            });
        }
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
        } else if view == DIFFERENCE {
            let own = self.state.map_or(0, |(_, _, n)| n);
            Some(Legend {
                title: match self.companion_frames() {
                    Some(n) => {
                        let own_clamped = self.state.is_some_and(|(_, m, _)| m == CLAMPED);
                        let (c, st) = if own_clamped { (own, n) } else { (n, own) };
                        format!(
                            "(clamped - stochastic) / mean, over {c} clamped and {st} stochastic \
                             frames{}",
                            if own <= 1 {
                                " (accumulate frames to see the bias, not the noise)"
                            } else {
                                ""
                            }
                        )
                    }
                    None => "(clamped - stochastic) / mean: the other variant runs from the next \
                             diagnostic frame"
                        .into(),
                },
                lo: -DIFFERENCE_RANGE,
                hi: DIFFERENCE_RANGE,
                log: false,
            })
        } else {
            None
        }
    }

    fn stats(&mut self) -> Vec<(&'static str, f64)> {
        let tree = self.is_tree();
        match self.pass.stats.poll() {
            Some(st) if tree => vec![
                ("vpls_in_range_per_pixel", st.in_range_per_pixel()),
                ("vpls_listed_per_pixel", st.tested_per_pixel()),
                ("most_vpls_in_range", st.longest_list as f64),
                ("pixels_over_k", st.overflow_tiles as f64),
                ("tree_nodes_visited_per_pixel", st.visited_per_pixel()),
                ("shadow_rays_per_pixel", st.rays_per_pixel()),
                ("epsilon_max", self.settings.epsilon_max as f64),
                ("reservoir_k", self.settings.reservoir_k as f64),
                ("ism_maps", if self.ism_on { self.ism_maps as f64 } else { 0.0 }),
            ],
            Some(st) => vec![
                ("mean_tile_list", st.mean_list()),
                ("longest_tile_list", st.longest_list as f64),
                ("overflow_tiles", st.overflow_tiles as f64),
                ("vpls_tested_per_pixel", st.tested_per_pixel()),
                ("vpls_in_range_per_pixel", st.in_range_per_pixel()),
                ("shadow_rays_per_pixel", st.rays_per_pixel()),
                ("epsilon_max", self.settings.epsilon_max as f64),
                ("interleave", self.settings.interleave.n as f64),
                ("ism_maps", if self.ism_on { self.ism_maps as f64 } else { 0.0 }),
            ],
            None => Vec::new(),
        }
    }

    fn status(&mut self) -> Option<String> {
        let st = self.pass.stats.poll()?;
        let vis = if self.ism_on {
            format!("ISM lookups per pixel ({} maps)", self.ism_maps)
        } else {
            "shadow rays per pixel".to_string()
        };
        if self.is_tree() {
            return Some(format!(
                "tree culling {:.1} VPLs in range per pixel (most {}; {} pixels over k = {}) · \
                 {:.1} nodes visited · {:.2} {vis}",
                st.in_range_per_pixel(),
                st.longest_list,
                st.overflow_tiles,
                self.settings.reservoir_k,
                st.visited_per_pixel(),
                st.rays_per_pixel()
            ));
        }
        Some(format!(
            "culling {:.1} lights per tile (longest {}, {} over the cap of {}) · {:.1} in range \
             per pixel · {:.1} {vis}",
            st.mean_list(),
            st.longest_list,
            st.overflow_tiles,
            self.settings.max_lights_per_tile,
            st.in_range_per_pixel(),
            st.rays_per_pixel()
        ))
    }
}

/// `MethodInfo::fields` (the three methods share the table).
fn fields() -> Vec<super::FieldSection> {
    use settings::{Interleave8, InterleaveSettings, IsmAdaptive, IsmSettings};
    vec![
        super::FieldSection::of("methods.light-culling", settings::FIELDS, true),
        super::FieldSection::of(
            "methods.light-culling.interleave",
            &InterleaveSettings::<Interleave8>::fields(settings::MAX_INTERLEAVE),
            false,
        ),
        super::FieldSection::of(
            "methods.light-culling.ism",
            &IsmSettings::<IsmAdaptive>::fields(),
            false,
        ),
    ]
}

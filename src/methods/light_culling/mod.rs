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

mod figure;
mod method;
pub mod pass;
pub mod settings;
mod state;
mod ui;

use super::overlay::{MethodOverlay, Prim};
use super::{
    FrameCx, Kind, Legend, Method, MethodId, MethodInfo, MethodView, Module, Resource, ViewCx, ViewInfo,
};
use crate::gpu::context::{GpuContext, GpuError};
use crate::gpu::passes::interleave_filter::GpuFilterParams;
use crate::gpu::passes::ism::{IsmPoints, IsmTargets};
use crate::gpu::readback::{self, ImageF32};
use crate::gpu::shaders::ShaderError;
use crate::reference::light_culling::{Interleave, TileGrid};
use crate::settings::RenderSettings;
use pass::{
    FrameInputs, GpuLcullParams, GpuLcullViewParams, IsmFrame, LcullBuffers, LcullFrameParams, LcullPass,
    LcullStats, TreeCullBuffers, VISIBILITY_ISM,
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

/// Its WGSL files (paths under `shaders/`), embedded; the GPU layer finds them through
/// `gpu::shaders::ShaderTable` without naming the method.
const SHADERS: &[(&str, &str)] = &[
    shader!("lcull_common.wgsl"),
    shader!("lcull_light.wgsl"),
    shader!("lcull_term.wgsl"),
    shader!("lcull_ranges.wgsl"),
    shader!("lcull_tree.wgsl"),
    shader!("lcull_tiles.wgsl"),
    shader!("lcull_shade.wgsl"),
    shader!("lcull_views.wgsl"),
];

/// Those of its files that are entry points.
const ENTRY_SHADERS: &[&str] = &[
    "methods/light_culling/lcull_ranges.wgsl",
    "methods/light_culling/lcull_tiles.wgsl",
    "methods/light_culling/lcull_shade.wgsl",
    "methods/light_culling/lcull_tree.wgsl",
    "methods/light_culling/lcull_views.wgsl",
];

inventory::submit! {
    crate::gpu::shaders::ShaderTable {
        files: SHADERS,
        entries: ENTRY_SHADERS,
    }
}

pub static MODULE: Module = Module {
    name: "light_culling",
    create,
    shaders: SHADERS,
    entry_shaders: ENTRY_SHADERS,
    wgsl_twins: pass::WGSL_TWINS,
    own_workgroups: &[crate::gpu::passes::OwnWorkgroup {
        // One workgroup per tile.
        file: "methods/light_culling/lcull_tiles.wgsl",
        entries: &[],
        size: [pass::TILE_WG, 1, 1],
    }],
    flags: &[],
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
    visibility: Some(&VISIBILITY),
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
    visibility: Some(&VISIBILITY),
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
    visibility: Some(&VISIBILITY),
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

/// Light culling's visibility (`render --visibility`; `[methods.light-culling] visibility`).
pub static VISIBILITY: super::VisibilityModes = super::VisibilityModes {
    modes: &[
        ("rays", "a BVH shadow ray per VPL in range"),
        (
            "ism",
            "a lookup in each VPL's imperfect shadow map (sections 4.3-4.4)",
        ),
    ],
    set: |s, name| {
        // A malformed table is left for validation to name.
        let Ok(mut lc) = s.method::<LightCullingSettings>(ID) else {
            return;
        };
        lc.visibility = if name == "ism" {
            settings::CullingVisibility::Ism
        } else {
            settings::CullingVisibility::Rays
        };
        // Cannot fail: the struct serialises to a table.
        let _ = s.set_method(ID, &lc);
    },
};

fn validate(s: &RenderSettings) -> Result<(), String> {
    let lc = s.method::<LightCullingSettings>(ID)?;
    lc.validate()?;
    // The geometry-aware filter averages Lambert's irradiance-like `raw` over a window and
    // multiplies the pixel's albedo / pi back; a glossy BRDF's radiance cannot be averaged so.
    // Interleaving alone (each pixel its subset x n^2) stays unbiased.
    let culling = [ID, CLAMPED, TREE].contains(&s.gi.method);
    if culling && s.gi.brdf == crate::settings::Brdf::Ggx {
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

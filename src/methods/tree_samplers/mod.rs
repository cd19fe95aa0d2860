//! The tree samplers (thesis chapter 5 and its baselines), one module with a mode:
//! - **SLC** (the thesis): shallow per-block light cuts, stochastic cut blending with mock
//!   cuts, traversal from each cut node that stops at usable substitute nodes;
//! - **SST** (Tatzgern et al. 2020): `cut_size` traversals per pixel from the root, each
//!   stopping at a usable node;
//! - **RTSLC** (Lin & Yuksel 2020): the same cuts and blending as SLC, traversal always down
//!   to a leaf VPL.
//!
//! Passes: optional `gi_downsample` (half-resolution G-buffer), `slc_cuts` (not for SST),
//! `slc_sample` / `sst_sample` / `rtslc_sample`, optional `slc_filter` (interleaved sampling's
//! geometry-aware filter, `sampling.interleave`), optional `gi_upsample`. CPU twins in
//! `crate::reference::slc` and `crate::reference::interleave`; docs/sampling.md.

mod figure;
pub mod half;
mod method;
pub mod pass;
pub mod settings;
mod ui;

use super::{
    Bias, FrameCx, Kind, Legend, Method, MethodId, MethodInfo, MethodView, Module, Resource, Story, ViewCx,
    ViewInfo,
};
use crate::base::sst_node::TreeKind;
use crate::gpu::context::{GpuContext, GpuError};
use crate::gpu::passes::interleave_filter::{
    FilterDispatch, FilterInputs, FilterUniform, GpuFilterParams, InterleaveFilter,
};
use crate::gpu::readback::{self, ImageF32};
use crate::gpu::shaders::ShaderError;
use crate::reference::interleave::Interleave;
use crate::settings::RenderSettings;
use half::{HalfPass, HalfTargets};
use pass::GpuSlcParams;
use pass::{GpuSlcViewParams, PixelTrace, SamplingStats, SlcBuffers, SlcPass};
use settings::SamplingSettings;
use settings::{ChildProbability, CutBlending, CutFallback, SamplerVisibility};

pub const SLC: MethodId = MethodId::new("slc");
pub const SST: MethodId = MethodId::new("sst");
pub const RTSLC: MethodId = MethodId::new("rtslc");

macro_rules! shader {
    ($name:literal) => {
        (
            concat!("methods/tree_samplers/", $name),
            include_str!(concat!("../../../shaders/methods/tree_samplers/", $name)),
        )
    };
}

/// Its WGSL files (paths under `shaders/`), embedded; the GPU layer finds them through
/// `gpu::shaders::ShaderTable` without naming the method.
const SHADERS: &[(&str, &str)] = &[
    shader!("slc_cuts.wgsl"),
    shader!("slc_sample.wgsl"),
    shader!("slc_views.wgsl"),
    shader!("slc_half.wgsl"),
    shader!("slc_upsample.wgsl"),
];

/// Those of its files that are entry points.
const ENTRY_SHADERS: &[&str] = &[
    "methods/tree_samplers/slc_cuts.wgsl",
    "methods/tree_samplers/slc_sample.wgsl",
    "methods/tree_samplers/slc_views.wgsl",
    "methods/tree_samplers/slc_half.wgsl",
    "methods/tree_samplers/slc_upsample.wgsl",
];

inventory::submit! {
    crate::gpu::shaders::ShaderTable {
        files: SHADERS,
        entries: ENTRY_SHADERS,
    }
}

pub static MODULE: Module = Module {
    name: "tree_samplers",
    create,
    shaders: SHADERS,
    entry_shaders: ENTRY_SHADERS,
    wgsl_twins: pass::WGSL_TWINS,
    own_workgroups: &[],
    flags: FLAGS,
};

/// Traversal steps per traversal, per pixel (heat map, thesis fig. 7.2).
pub const STEPS: MethodView = MethodView::new("traversal steps");
/// Pixels without a similar surrounding cut (red over the grey final; fig. 7.6).
pub const FALLBACK: MethodView = MethodView::new("pixels without a similar cut");
/// The per-block cuts, a colour per cut, over the grey final (fig. 7.4).
pub const CUT_BLOCKS: MethodView = MethodView::new("cuts per block");
/// The per-block cuts coloured by their mean node depth.
pub const CUT_DEPTH: MethodView = MethodView::new("cut depth per block");

/// The diagnostic views every tree sampler draws (one `slc_views` pass, a mode each).
const VIEWS: &[ViewInfo] = &[
    ViewInfo {
        name: STEPS.name(),
        file: "traversal_steps",
        about: "traversal steps per traversal, per pixel (thesis fig. 7.2)",
        passes: &["slc_sample", "sst_sample", "rtslc_sample"],
    },
    ViewInfo {
        name: FALLBACK.name(),
        file: "cut_fallback",
        about: "pixels without a similar surrounding cut, red over the grey final (fig. 7.6)",
        passes: &[],
    },
    ViewInfo {
        name: CUT_BLOCKS.name(),
        file: "cut_blocks",
        about: "the per-block cuts, a colour per cut; click a block to list its cut (fig. 7.4)",
        passes: &["slc_cuts"],
    },
    ViewInfo {
        name: CUT_DEPTH.name(),
        file: "cut_depth",
        about: "the per-block cuts coloured by their mean node depth",
        passes: &[],
    },
];
const READS: &[Resource] = &[
    Resource::Gbuffer,
    Resource::Tree,
    Resource::AnyTree,
    Resource::Bvh,
];
const TESTS: &[&str] = &[
    "slc::gpu_cuts_equal_the_cpu_cuts_and_are_valid",
    "slc::with_ggx_glossy_samples_walk_to_leaves_so_the_samplers_converge_on_metal",
    "slc::glossy_walks_weigh_children_by_the_material_term_as_the_cpu_does",
    "slc::the_defensive_glossy_weights_lower_the_error_on_polished_metal",
    "slc::blending_picks_cuts_by_their_weights_and_falls_back_to_the_mock_cut",
    "slc::rtslc_averaged_over_frames_converges_to_the_ground_truth",
    "slc::slc_without_usable_inner_nodes_equals_rtslc_and_steps_order_as_the_thesis_says",
    "slc::half_resolution_upsampling_equals_the_cpu_reference",
    "slc::the_pixel_story_matches_the_frame_and_the_tree",
    "slc::interleaved_sampling_shares_the_cut_slots_out_and_its_filter_equals_the_cpu_reference",
    "slc::ism_visibility_looks_samples_up_in_the_leaves_maps_as_the_cpu_does",
];

/// Samples per pixel (the cut size), over `results --spp`.
pub static SPP_SWEEP: super::Sweep = super::Sweep {
    name: "spp",
    values: &[],
    apply: |s, v| SamplingSettings::edit(s, |m| m.cut_size = v.round() as u32),
    integer: true,
};

fn invalid_cut_size(s: &mut RenderSettings) -> &'static str {
    SamplingSettings::edit(s, |m| m.cut_size = 0);
    "methods.slc.cut_size"
}

pub static SLC_INFO: MethodInfo = MethodInfo {
    id: SLC,
    aliases: &["stochastic-light-cuts"],
    label: "SLC (thesis)",
    short: "SLC",
    about: "Stochastic Light Cut Exploration (the thesis): per-block cuts, cut blending, \
            traversal to usable substitute nodes.",
    progress_unit: "",
    kind: Kind::PerFrame,
    module: &MODULE,
    reads: READS,
    views: VIEWS,
    timed_passes: &[
        "slc_cuts",
        "slc_ism_lights",
        "slc_ism",
        "slc_sample",
        "slc_filter",
        "gi_downsample",
        "gi_upsample",
    ],
    story: true,
    shadow_ray_switch: true,
    visibility: Some(&VISIBILITY),
    truth_of_vpls: false,
    one_bounce: false,
    glossy: true,
    validate,
    fields,
    invalid_example: Some(invalid_cut_size),
    ui: ui::settings_ui,
    tests: TESTS,
    sweep: Some(&SPP_SWEEP),
    bias: slc_bias,
    unbiased: Some(super::Unbiased {
        how: "tree.v_min = 1, tree.sigma_max = 0 (only leaves usable: RTSLC's traversal), methods.slc.block_size = 1",
        apply: |s| {
            (s.tree.v_min, s.tree.sigma_max) = (1.0, 0.0);
            SamplingSettings::edit(s, |m| m.block_size = 1);
        },
    }),
};

pub static SST_INFO: MethodInfo = MethodInfo {
    id: SST,
    aliases: &["stochastic-substitute-trees"],
    label: "SST (baseline)",
    short: "SST",
    about: "Stochastic Substitute Trees (Tatzgern et al. 2020): traversals from the root to \
            usable substitute nodes.",
    progress_unit: "",
    kind: Kind::PerFrame,
    module: &MODULE,
    reads: READS,
    views: VIEWS,
    timed_passes: &[
        "slc_ism_lights",
        "slc_ism",
        "sst_sample",
        "slc_filter",
        "gi_downsample",
        "gi_upsample",
    ],
    story: true,
    shadow_ray_switch: true,
    visibility: Some(&VISIBILITY),
    truth_of_vpls: false,
    one_bounce: false,
    glossy: true,
    validate,
    fields,
    invalid_example: Some(invalid_cut_size),
    ui: ui::settings_ui,
    tests: TESTS,
    sweep: Some(&SPP_SWEEP),
    bias: sst_bias,
    unbiased: Some(super::Unbiased {
        how: "tree.v_min = 1, tree.sigma_max = 0 (only leaves usable)",
        apply: |s| (s.tree.v_min, s.tree.sigma_max) = (1.0, 0.0),
    }),
};

pub static RTSLC_INFO: MethodInfo = MethodInfo {
    id: RTSLC,
    aliases: &["real-time-stochastic-lightcuts"],
    label: "RTSLC (baseline)",
    short: "RTSLC",
    about: "Real-time stochastic lightcuts (Lin & Yuksel 2020): the same cuts, traversal to a \
            leaf VPL.",
    progress_unit: "",
    kind: Kind::PerFrame,
    module: &MODULE,
    reads: READS,
    views: VIEWS,
    timed_passes: &[
        "slc_cuts",
        "slc_ism_lights",
        "slc_ism",
        "rtslc_sample",
        "slc_filter",
        "gi_downsample",
        "gi_upsample",
    ],
    story: true,
    shadow_ray_switch: true,
    visibility: Some(&VISIBILITY),
    truth_of_vpls: false,
    one_bounce: false,
    glossy: true,
    validate,
    fields,
    invalid_example: Some(invalid_cut_size),
    ui: ui::settings_ui,
    tests: TESTS,
    sweep: Some(&SPP_SWEEP),
    bias: rtslc_bias,
    unbiased: Some(super::Unbiased {
        how: "methods.slc.block_size = 1 (a cut per pixel: culling drops only nodes that cannot light it)",
        apply: |s| SamplingSettings::edit(s, |m| m.block_size = 1),
    }),
};

/// What biases every tree sampler alike: imperfect shadow maps, the interleaving's filter,
/// half-resolution upsampling (docs/sampling.md); None when none of them is on.
fn shared_bias(s: &RenderSettings) -> Option<Bias> {
    let sm = &SamplingSettings::of(s);
    if s.gi.shadow_rays && sm.visibility == SamplerVisibility::Ism {
        Some(Bias::Biased {
            tolerance: 0.35,
            reason: "imperfect shadow maps for visibility (Sponza 1.29x, Breakfast Room 0.83x: docs/sampling.md)",
        })
    } else if sm.half_resolution {
        Some(Bias::Biased {
            tolerance: 0.10,
            reason: "half-resolution GI, upsampled by a joint bilateral filter (1.09x in the corridor at 48 x 32)",
        })
    } else if sm.interleave.filter_radius > 0 {
        Some(Bias::Biased {
            tolerance: 0.05,
            reason: "the interleaving's geometry-aware filter averages neighbours' light",
        })
    } else {
        None
    }
}

/// RTSLC samples leaves: unbiased with complete cuts (`cull_behind` off) or a cut per pixel;
/// otherwise a node culled behind the block centre's surface may still light a pixel of the
/// block (docs/sampling.md, *Unbiasedness*).
fn rtslc_bias(s: &RenderSettings) -> Bias {
    shared_bias(s).unwrap_or(if !SamplingSettings::of(s).cull_behind || SamplingSettings::of(s).block_size == 1 {
        Bias::Unbiased
    } else {
        Bias::Biased {
            tolerance: 0.02,
            reason: "nodes culled behind the block centre's surface (cull_behind) can light other pixels of the block",
        }
    })
}

/// SLC and SST stop at usable inner nodes and shade a point of their substitute
/// distribution (the SST paper's section 4.2): biased, unless only leaves are usable
/// (`tree.v_min` 1, `tree.sigma_max` 0), where SLC traverses exactly as RTSLC does.
fn substitute_bias(s: &RenderSettings, leaf_bias: Bias) -> Bias {
    if s.tree.v_min >= 1.0 && s.tree.sigma_max <= 0.0 {
        return shared_bias(s).unwrap_or(leaf_bias);
    }
    shared_bias(s).unwrap_or(Bias::Biased {
        tolerance: 0.10,
        reason: "substitute sampling: a Gaussian point of a usable node stands for its VPLs (SST paper 4.2)",
    })
}

/// SLC: substitute sampling; with only leaves usable, RTSLC's bias (its cuts and blending).
fn slc_bias(s: &RenderSettings) -> Bias {
    substitute_bias(s, rtslc_bias(s))
}

/// SST starts every traversal at the root: with leaves only it is unbiased.
fn sst_bias(s: &RenderSettings) -> Bias {
    substitute_bias(s, Bias::Unbiased)
}

/// `[methods.slc]`: every field in range, or a message naming it.
fn validate(s: &RenderSettings) -> Result<(), String> {
    for other in [SST, RTSLC] {
        if s.methods.raw(other.cli()).is_some() {
            return Err(format!(
                "methods.{}: SLC, SST and RTSLC share one table; write it as [{SECTION}]",
                other.cli()
            ));
        }
    }
    let sm = &s.method::<SamplingSettings>(settings::TABLE)?;
    sm.ism.validate(SECTION)?;
    // Half-resolution GI and the interleaving's filter work on the GI without the albedo
    // (Lambert's rho / pi factored out), which a glossy BRDF does not allow.
    if s.gi.method.samples_tree()
        && s.gi.brdf == crate::settings::Brdf::Ggx
        && (sm.half_resolution || sm.interleave.filters())
    {
        return Err(format!(
            "gi.brdf = Ggx with {}: the tree samplers' half-resolution GI and interleaving filter divide out Lambert's albedo / pi; use gi.brdf = Lambert or turn them off",
            if sm.half_resolution {
                "methods.slc.half_resolution"
            } else {
                "methods.slc.interleave (n > 1 or a filter radius)"
            }
        ));
    }
    crate::base::field::check(SECTION, settings::FIELDS, sm)?;
    sm.interleave.validate(SECTION, settings::MAX_SLOT_INTERLEAVE)
}

/// Half-resolution G-buffer position and normal, and the sampler's demodulated sums there.
pub type HalfReadback = (ImageF32, ImageF32, Vec<[f32; 4]>);

/// The samplers' command-line flags (`render`, `sheet`): shorthands for `--set methods.slc.*`.
pub static FLAGS: &[super::MethodFlag] = &[
    super::MethodFlag {
        long: "block",
        help: "SLC / RTSLC: cut block edge k in pixels (1 = a cut per pixel)",
        path: "methods.slc.block_size",
        kind: super::FlagKind::Number("K"),
    },
    super::MethodFlag {
        long: "cut-size",
        help: "SLC / SST / RTSLC: nodes per cut = samples per pixel (SST: traversals from the root)",
        path: "methods.slc.cut_size",
        kind: super::FlagKind::Number("N"),
    },
    super::MethodFlag {
        long: "blending",
        help: "SLC / RTSLC: how a pixel picks a cut per slot (Algorithm 1, or its own block's)",
        path: "methods.slc.blending",
        kind: super::FlagKind::Choice(&[("stochastic", "Stochastic"), ("off", "Off")]),
    },
    super::MethodFlag {
        long: "fallback",
        help: "SLC / RTSLC: what a pixel without a similar cut does (thesis 5.1.4)",
        path: "methods.slc.fallback",
        kind: super::FlagKind::Choice(&[
            ("mock", "MockCut"),
            ("average", "Average"),
            ("root", "Root"),
            ("recompute", "Recompute"),
        ]),
    },
    super::MethodFlag {
        long: "no-cull",
        help: "SLC / RTSLC: keep nodes behind the block centre's surface in the cuts (complete cuts)",
        path: "methods.slc.cull_behind",
        kind: super::FlagKind::Switch("false"),
    },
    super::MethodFlag {
        long: "near-field",
        help: "SLC / SST: stop at a usable node only when the shaded point is at least this many box \
               diagonals from its box (0 = off, the thesis's rule; default 1)",
        path: "methods.slc.near_field",
        kind: super::FlagKind::Number("DIAGONALS"),
    },
    super::MethodFlag {
        long: "substitute-offset",
        help: "SLC / SST: metres by which substitute samples' shadow rays stop short of the drawn \
               point (the SST paper's scene-size epsilon; 0 = off, the thesis; default 0.05)",
        path: "methods.slc.substitute_offset",
        kind: super::FlagKind::Number("METRES"),
    },
    super::MethodFlag {
        long: "child-probability",
        help: "SLC / SST / RTSLC: how a traversal step picks a child: mean (eq. 5.5, the thesis), \
               min-max (RTSLC's box distances), defensive (default: 0.8 x the thesis's + 0.2 x \
               the closest-point distance's)",
        path: "methods.slc.child_probability",
        kind: super::FlagKind::Choice(&[
            ("mean", "Mean"),
            ("min-max", "MinMax"),
            ("defensive", "Defensive"),
        ]),
    },
    super::MethodFlag {
        long: "glossy-weights",
        help: "SLC / SST with --brdf ggx: how glossy samples weigh a step's children: geometric, \
               material (the SST paper's 4.1) or defensive (default: material with 25% geometric)",
        path: "methods.slc.glossy_weights",
        kind: super::FlagKind::Choice(&[
            ("geometric", "Geometric"),
            ("material", "Material"),
            ("defensive", "Defensive"),
        ]),
    },
    super::MethodFlag {
        long: "half-res",
        help: "SLC / SST / RTSLC: GI at half resolution, joint-bilateral upsampled with the similarity S",
        path: "methods.slc.half_resolution",
        kind: super::FlagKind::Switch("true"),
    },
];

/// The samplers' visibility (`render --visibility`; `[methods.slc] visibility`).
pub static VISIBILITY: super::VisibilityModes = super::VisibilityModes {
    modes: &[
        ("rays", "a BVH shadow ray per sample (the thesis)"),
        ("ism", "an imperfect shadow map per light-tree leaf"),
    ],
    set: |s, name| {
        SamplingSettings::edit(s, |m| {
            m.visibility = if name == "ism" {
                SamplerVisibility::Ism
            } else {
                SamplerVisibility::Rays
            }
        })
    },
};

/// The tree samplers' settings table, as settings paths and messages name it.
const SECTION: &str = "methods.slc";

/// The samplers' GPU state: pipelines, per-frame buffers, accumulation and half-resolution
/// targets.
pub struct TreeSamplers {
    pass: SlcPass,
    buffers: SlcBuffers,
    half_pass: HalfPass,
    half: Option<HalfTargets>,
    /// Interleaved sampling's filter and the sampler's per-frame estimate it reads (at the
    /// GI resolution; allocated while `sampling.interleave` filters).
    filter: InterleaveFilter,
    filter_params: FilterUniform,
    raw: Option<(wgpu::Buffer, (u32, u32))>,
    /// Accumulation: (key, frames summed).
    state: Option<(u64, u32)>,
    /// Whether the last recorded frame traced a pixel's story.
    traced: bool,
    /// The leaves' maps (ISM visibility): the scene's point cloud (and the scene upload it
    /// was sampled from) and the atlas; maps built by the last frame (0: none).
    ism_points: Option<(u64, crate::gpu::passes::ism::IsmPoints)>,
    ism_targets: Option<crate::gpu::passes::ism::IsmTargets>,
    ism_maps: u32,
}

/// Seed of the scene's point cloud for the leaves' maps (light culling's, so that the two
/// methods' maps of one scene are built from the same points).
pub const ISM_CLOUD_SEED: u32 = crate::methods::light_culling::ISM_CLOUD_SEED;

fn create(device: &wgpu::Device) -> Result<Box<dyn Method>, ShaderError> {
    Ok(Box::new(TreeSamplers {
        pass: SlcPass::new(device)?,
        // Sized at the first frame (after the device-limit check).
        buffers: SlcBuffers::new(device, (1, 1), 1, 1),
        half_pass: HalfPass::new(device)?,
        half: None,
        filter: InterleaveFilter::new(device)?,
        filter_params: FilterUniform::new(device, "slc::filter_params"),
        raw: None,
        state: None,
        traced: false,
        ism_points: None,
        ism_targets: None,
        ism_maps: 0,
    }))
}

impl TreeSamplers {
    /// The leaves' maps of the last frame that built them, and how many (None: none).
    pub fn ism(&self) -> Option<(&crate::gpu::passes::ism::IsmTargets, u32)> {
        self.ism_targets
            .as_ref()
            .filter(|_| self.ism_maps > 0)
            .map(|t| (t, self.ism_maps))
    }

    /// ISM visibility for this frame: the cloud and atlas ready and the maps to build
    /// (`Some(leaves)`), or None (rays or no shadows; more leaves than the atlas holds or an
    /// atlas beyond the device's binding size: reported, the frame traces rays).
    fn plan_ism(&mut self, cx: &FrameCx<'_>) -> Option<u32> {
        let s = cx.settings;
        let sm = &SamplingSettings::of(s);
        self.ism_maps = 0;
        if !(s.gi.shadow_rays && sm.visibility == settings::SamplerVisibility::Ism) {
            return None;
        }
        let leaves = cx.tree.leaves.max(1);
        let need = sm.ism.atlas_bytes();
        let limit = cx.device.limits().max_storage_buffer_binding_size;
        if leaves > sm.ism.capacity() || need > limit {
            cx.errors.report(format!(
                "tree samplers: ISM visibility needs a map per light-tree leaf ({leaves}) in an \
                 atlas of {0} x {0} ({1} maps of {2}^2, {3} MiB; this device binds {4} MiB): \
                 tracing shadow rays instead (raise methods.slc.ism.atlas, lower methods.slc.ism.tile \
                 or the VPL count)",
                sm.ism.atlas,
                sm.ism.capacity(),
                sm.ism.tile,
                need >> 20,
                limit >> 20
            ));
            return None;
        }
        crate::gpu::passes::ism::ensure_maps(
            cx.device,
            cx.queue,
            cx.scene,
            &sm.ism,
            ISM_CLOUD_SEED,
            &mut self.ism_points,
            &mut self.ism_targets,
        );
        self.ism_maps = leaves;
        Some(leaves)
    }

    /// Cuts, per-pixel diagnostics, counters and the story of the last frame.
    pub fn buffers(&self) -> &SlcBuffers {
        &self.buffers
    }
    /// Frames summed in the accumulation (0 before the first).
    pub fn frames(&self) -> u32 {
        self.state.map_or(0, |(_, n)| n)
    }
    /// Counters of a recent frame (non-blocking).
    pub fn poll_stats(&mut self) -> Option<SamplingStats> {
        self.pass.stats.poll()
    }
    /// Half-resolution GI of the last frame: its G-buffer position, normal and the sampler's
    /// demodulated sums (None when half resolution is off).
    pub fn read_half_resolution(&self, ctx: &GpuContext) -> Result<Option<HalfReadback>, GpuError> {
        let Some(h) = self.half_targets() else {
            return Ok(None);
        };
        let pos = readback::read_texture_f32(ctx, &h.gbuffer.position, 0)?;
        let nrm = readback::read_texture_f32(ctx, &h.gbuffer.normal, 0)?;
        let acc = readback::read_storage_buffer(ctx, &h.accum)?;
        Ok(Some((pos, nrm, bytemuck::cast_slice(&acc).to_vec())))
    }
    /// The half-resolution targets of the last frame (None when half resolution is off).
    pub fn half_targets(&self) -> Option<&HalfTargets> {
        self.half.as_ref()
    }
    /// The last frame's demodulated estimate before the interleaving's filter, at the GI
    /// resolution (None while `sampling.interleave` does not filter).
    pub fn interleaved_raw(&self) -> Option<&wgpu::Buffer> {
        self.raw.as_ref().map(|(b, _)| b)
    }
    /// The cut of block `b` (node ids in slot order, without empty slots).
    pub fn read_cut(&self, ctx: &GpuContext, b: u32) -> Result<Vec<u32>, GpuError> {
        let s = &self.buffers;
        if b >= s.grid.0 * s.grid.1 {
            return Ok(Vec::new());
        }
        let off = b as u64 * s.cut_size as u64 * 4;
        let bytes = readback::read_buffer_range(ctx, &s.cuts, off, s.cut_size as u64 * 4)?;
        Ok(bytemuck::cast_slice::<u8, u32>(&bytes)
            .iter()
            .copied()
            .take_while(|&n| n != 0)
            .collect())
    }
}

/// The top of the traversal-steps heat map: the depth of a tree of `levels` levels.
pub fn steps_scale(levels: u32) -> f32 {
    (levels.max(2) - 1) as f32
}

/// `MethodInfo::fields` (`[sampling]`, shared by the three samplers).
fn fields() -> Vec<super::FieldSection> {
    use crate::settings::{InterleaveOff, InterleaveSettings, IsmAdaptive, IsmSettings};
    vec![
        super::FieldSection::of(SECTION, settings::FIELDS, true),
        super::FieldSection::of(
            "methods.slc.interleave",
            &InterleaveSettings::<InterleaveOff>::fields(settings::MAX_SLOT_INTERLEAVE),
            false,
        ),
        super::FieldSection::of("methods.slc.ism", &IsmSettings::<IsmAdaptive>::fields(), false),
    ]
}

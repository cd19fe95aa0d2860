//! Lightcut Interpolation (Rehfeld & Dachsbacher 2016): exact lightcuts at cache records
//! placed in image space (section 3.1), per pixel the best three records by Tabellion and
//! Lamorlette's weight (3.2), their cuts interpolated into one valid cut (3.3) and shaded
//! with a shadow ray per node or with interpolated visibility; pixels without a usable record
//! compute a full lightcut. Same tree, VPLs, representatives and shadow rays as `lightcuts`.
//!
//! Passes in `pass` (module doc there); CPU twins in
//! `crate::reference::lightcut_interpolation`; docs/lightcut-interpolation.md.

mod figure;
mod method;
pub mod pass;
pub mod settings;
mod ui;

use super::{
    CutStory, FrameCx, Kind, Legend, Method, MethodId, MethodInfo, MethodView, Module, Resource, Story,
    StoryCut, ViewCx, ViewInfo,
};
use crate::gpu::context::{GpuContext, GpuError};
use crate::gpu::readback::{self, ImageF32};
use crate::gpu::shaders::ShaderError;
use crate::methods::lightcuts::{
    Lightcuts,
    pass::{GpuLcParams, SCRATCH_BUDGET, steps_per_dispatch},
};
use crate::reference::lightcuts::{Cone, LcTree, MAX_CUT};
use crate::settings::RenderSettings;
use pass::{
    GpuLiParams, GpuLiViewParams, LiBuffers, LiPass, LiStats, TracedInterpolation, walk_steps_per_dispatch,
};
use settings::{LiVisibility, LightcutInterpolationSettings};

pub const ID: MethodId = MethodId::new("lightcut-interpolation");

macro_rules! shader {
    ($name:literal) => {
        (
            concat!("methods/lightcut_interpolation/", $name),
            include_str!(concat!("../../../shaders/methods/lightcut_interpolation/", $name)),
        )
    };
}

/// Its WGSL files (paths under `shaders/`), embedded; the GPU layer finds them through
/// `gpu::shaders::ShaderTable` without naming the method.
const SHADERS: &[(&str, &str)] = &[
    shader!("li_common.wgsl"),
    shader!("li_records.wgsl"),
    shader!("li_select.wgsl"),
    shader!("li_interp.wgsl"),
    shader!("li_views.wgsl"),
];

/// Those of its files that are entry points.
const ENTRY_SHADERS: &[&str] = &[
    "methods/lightcut_interpolation/li_records.wgsl",
    "methods/lightcut_interpolation/li_select.wgsl",
    "methods/lightcut_interpolation/li_interp.wgsl",
    "methods/lightcut_interpolation/li_views.wgsl",
];

inventory::submit! {
    crate::gpu::shaders::ShaderTable {
        files: SHADERS,
        entries: ENTRY_SHADERS,
    }
}

pub static MODULE: Module = Module {
    name: "lightcut_interpolation",
    create,
    shaders: SHADERS,
    entry_shaders: ENTRY_SHADERS,
    wgsl_twins: pass::WGSL_TWINS,
    own_workgroups: &[crate::gpu::passes::OwnWorkgroup {
        // One workgroup per 16 x 16 tile.
        file: "methods/lightcut_interpolation/li_records.wgsl",
        entries: pass::TILE_WG_ENTRIES,
        size: [pass::TILE_WG, 1, 1],
    }],
    flags: &[],
};

/// The cache records over the grey final image (reach from red to green, paper Fig. 4 top).
pub const RECORDS: MethodView = MethodView::new("LI records");
/// Each pixel's records' colours mixed by its weights (Fig. 4 middle).
pub const WEIGHTS: MethodView = MethodView::new("LI weights");
/// Pixels that computed a full lightcut (red over the grey final).
pub const FALLBACK: MethodView = MethodView::new("LI fallback");
/// Nodes in each pixel's cut (log heat map).
pub const CUT_SIZE: MethodView = MethodView::new("LI cut size");
/// How much the input cuts disagree (mean level spread).
pub const LEVEL_SPREAD: MethodView = MethodView::new("LI level spread");

const VIEWS: &[ViewInfo] = &[
    ViewInfo {
        name: RECORDS.name(),
        file: "li_records",
        about: "cache records over the grey final image, coloured by reach (red R-, green R+); \
                the pinned pixel's records ringed in white",
        passes: &["li_radius", "li_place", "li_compact"],
    },
    ViewInfo {
        name: WEIGHTS.name(),
        file: "li_weights",
        about: "each pixel's records (a colour per record) mixed by its interpolation weights; \
                magenta: full lightcut",
        passes: &["li_select"],
    },
    ViewInfo {
        name: FALLBACK.name(),
        file: "li_fallback",
        about: "pixels without a usable record (best weight below epsilon): full lightcuts, red",
        passes: &["li_select", "li_fallback"],
    },
    ViewInfo {
        name: CUT_SIZE.name(),
        file: "li_cut_size",
        about: "nodes in each pixel's cut, interpolated or the fallback's (log scale up to max cut)",
        passes: &["li_interp", "li_fallback"],
    },
    ViewInfo {
        name: LEVEL_SPREAD.name(),
        file: "li_level_spread",
        about: "where the input cuts disagree: mean over the leaves of the largest minus the \
                smallest input level (0 .. 4 levels); grey: fallback",
        passes: &["li_interp"],
    },
];

fn invalid_example(s: &mut RenderSettings) -> &'static str {
    let li = LightcutInterpolationSettings {
        r_min_px: 0.0,
        ..Default::default()
    };
    let _ = s.set_method(ID, &li);
    "methods.lightcut-interpolation.r_min_px"
}

pub static INFO: MethodInfo = MethodInfo {
    id: ID,
    aliases: &["li"],
    label: "Lightcut Interpolation",
    short: "LI",
    about: "Lightcut Interpolation (Rehfeld & Dachsbacher 2016): exact lightcuts at image-space \
            cache records, per pixel the three best records' cuts interpolated into one valid \
            cut; shadow rays per node or interpolated visibility.",
    progress_unit: "",
    kind: Kind::PerFrame,
    module: &MODULE,
    reads: &[Resource::Gbuffer, Resource::Tree, Resource::Bvh],
    views: VIEWS,
    timed_passes: &[
        "li_build",
        "li_radius",
        "li_place",
        "li_compact",
        "li_record_cuts",
        "li_select",
        "li_interp",
        "li_fallback",
    ],
    story: false,
    shadow_ray_switch: true,
    visibility: None,
    truth_of_vpls: false,
    one_bounce: false,
    glossy: false,
    validate,
    fields,
    invalid_example: Some(invalid_example),
    ui: ui::settings_ui,
    tests: &[
        "lightcut_interpolation::gpu_records_selection_and_interpolation_equal_the_cpu_reference",
        "lightcut_interpolation::identical_record_cuts_reproduce_full_lightcuts",
        "lightcut_interpolation::interpolated_visibility_shoots_no_rays_and_stays_close",
    ],
    sweep: Some(&SWEEP),
    bias,
    unbiased: None,
};

/// A pixel's cut is interpolated from its records' cuts, so the error bound holds at the
/// records, not at the pixel; with interpolated visibility the records' visibility stands
/// for the pixel's (the paper's section 3.4).
fn bias(s: &RenderSettings) -> super::Bias {
    match s.method::<LightcutInterpolationSettings>(ID) {
        Ok(li) if li.visibility != LiVisibility::Full => super::Bias::Biased {
            tolerance: 0.15,
            reason: "interpolated cuts with the records' visibility standing for the pixel's",
        },
        _ => super::Bias::Biased {
            tolerance: 0.05,
            reason: "cuts interpolated from records' cuts: the error bound holds at the records, not at the pixel",
        },
    }
}

/// The record density: R- and R+ scaled together (1 = the paper's 4 and 15 pixel sizes).
pub static SWEEP: super::Sweep = super::Sweep {
    name: "record_reach_scale",
    values: &[4.0, 2.0, 1.0, 0.5],
    apply: |s, v| {
        let mut li: LightcutInterpolationSettings = s.method(ID).unwrap_or_default();
        let v = v.clamp(0.0625, 16.0) as f32;
        li.r_min_px = 4.0 * v;
        li.r_max_px = 15.0 * v;
        let _ = s.set_method(ID, &li);
    },
    integer: false,
};

fn validate(s: &RenderSettings) -> Result<(), String> {
    s.method::<LightcutInterpolationSettings>(ID)?.validate()
}

fn decades(max_cut: u32) -> u32 {
    (max_cut.max(2) as f32).log10().ceil() as u32
}

/// What a test or tool reads back of the records.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordsReadback {
    /// Per tile (row-major) its records' pixel indices in placement order.
    pub tiles: Vec<Vec<u32>>,
    /// The compacted record list (pixel indices) and each record's cut (node | visible bit,
    /// left to right).
    pub pixels: Vec<u32>,
    pub cuts: Vec<Vec<u32>>,
    /// Per pixel: (reach in world units, reach in pixels).
    pub radius: Vec<[f32; 2]>,
    pub dropped: u32,
}

/// A pixel's selection as the GPU wrote it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpuSelection {
    pub ids: [u32; 3],
    pub count: u32,
    pub weights: [f32; 3],
    pub best: f32,
}

pub struct LightcutInterpolation {
    /// Created at the first frame (its pipelines cost every renderer otherwise).
    pass: Option<LiPass>,
    buffers: Option<LiBuffers>,
    state: Option<(u64, u32)>,
    traced: bool,
    /// The pinned pixel of the last frame (row-major index; the records view marks its
    /// records).
    pinned: Option<u32>,
    settings: LightcutInterpolationSettings,
    steps: (u32, u32),
}

fn create(_device: &wgpu::Device) -> Result<Box<dyn Method>, ShaderError> {
    Ok(Box::new(LightcutInterpolation {
        pass: None,
        buffers: None,
        state: None,
        traced: false,
        pinned: None,
        settings: LightcutInterpolationSettings::default(),
        steps: (0, 0),
    }))
}

impl LightcutInterpolation {
    pub fn buffers(&self) -> Option<&LiBuffers> {
        self.buffers.as_ref()
    }

    /// The last build's normal cones and representatives.
    pub fn read_build(&self, ctx: &GpuContext) -> Result<Option<LcTree>, GpuError> {
        let Some(b) = &self.buffers else { return Ok(None) };
        let cones: Vec<[f32; 4]> =
            bytemuck::pod_collect_to_vec(&readback::read_storage_buffer(ctx, &b.cones)?);
        let reps: Vec<u32> = bytemuck::pod_collect_to_vec(&readback::read_storage_buffer(ctx, &b.reps)?);
        let n = 2 * b.leaves as usize;
        Ok(Some(LcTree {
            cones: cones.into_iter().take(n).map(Cone::from_gpu).collect(),
            reps: reps.into_iter().take(n).collect(),
        }))
    }

    /// The last frame's records, their cuts and the per-pixel reach.
    pub fn read_records(&self, ctx: &GpuContext) -> Result<Option<RecordsReadback>, GpuError> {
        let Some(b) = &self.buffers else { return Ok(None) };
        let words = |buf: &wgpu::Buffer| -> Result<Vec<u32>, GpuError> {
            Ok(bytemuck::pod_collect_to_vec(&readback::read_storage_buffer(
                ctx, buf,
            )?))
        };
        let counts = words(&b.tile_count)?;
        let recs = words(&b.tile_recs)?;
        let meta = words(&b.rec_meta)?;
        let list = words(&b.records)?;
        let cuts = words(&b.record_cuts)?;
        let radius: Vec<[f32; 2]> =
            bytemuck::pod_collect_to_vec(&readback::read_storage_buffer(ctx, &b.radius)?);
        let nt = (b.tiles.0 * b.tiles.1) as usize;
        let cap = crate::reference::lightcut_interpolation::TILE_CAP as usize;
        let n = (meta[0] as usize).min(b.capacity as usize);
        Ok(Some(RecordsReadback {
            tiles: (0..nt)
                .map(|t| recs[t * cap..t * cap + (counts[t] as usize).min(cap)].to_vec())
                .collect(),
            pixels: list[..n].to_vec(),
            cuts: (0..n)
                .map(|r| {
                    let len = (meta[8 + r] as usize).min(b.max_cut as usize);
                    let base = r * b.max_cut as usize;
                    cuts[base..base + len].to_vec()
                })
                .collect(),
            radius: radius.into_iter().take((b.size.0 * b.size.1) as usize).collect(),
            dropped: meta[1],
        }))
    }

    /// Every pixel's selection (row-major).
    pub fn read_selection(&self, ctx: &GpuContext) -> Result<Option<Vec<GpuSelection>>, GpuError> {
        let Some(b) = &self.buffers else { return Ok(None) };
        let w: Vec<u32> = bytemuck::pod_collect_to_vec(&readback::read_storage_buffer(ctx, &b.sel)?);
        let n = (b.size.0 * b.size.1) as usize;
        Ok(Some(
            w.chunks_exact(8)
                .take(n)
                .map(|c| GpuSelection {
                    ids: [c[0], c[1], c[2]],
                    count: c[3],
                    weights: [f32::from_bits(c[4]), f32::from_bits(c[5]), f32::from_bits(c[6])],
                    best: f32::from_bits(c[7]),
                })
                .collect(),
        ))
    }

    /// The pinned pixel's interpolation in the last diagnostic frame that traced one.
    pub fn read_traced(&self, ctx: &GpuContext) -> Result<Option<TracedInterpolation>, GpuError> {
        let Some(b) = &self.buffers else { return Ok(None) };
        if !self.traced {
            return Ok(None);
        }
        let bytes = readback::read_storage_buffer(ctx, &b.trace)?;
        Ok(TracedInterpolation::parse(
            &bytemuck::pod_collect_to_vec::<u8, u32>(&bytes),
        ))
    }

    /// Counters of a recent diagnostic frame (non-blocking).
    pub fn poll_stats(&mut self) -> Option<LiStats> {
        self.pass.as_mut()?.stats.poll()
    }
}

/// `MethodInfo::fields`.
fn fields() -> Vec<super::FieldSection> {
    vec![super::FieldSection::of(
        "methods.lightcut-interpolation",
        settings::FIELDS,
        true,
    )]
}

//! Lightcuts (Walter et al. 2005; summarised in Rehfeld & Dachsbacher, "Lightcut
//! Interpolation", section 2): per pixel, a deterministic cut through the frame's light tree,
//! refined node by node in the order of the largest error bound until the bound is below a
//! relative threshold of the estimate or the cut reaches its maximum size; each cluster
//! evaluated with its representative VPL and one shadow ray.
//!
//! Passes: `lightcuts_build` (normal cones and representative VPLs, bottom-up), `lightcuts`
//! (the per-pixel cut), `lightcuts_views`. CPU twins in `crate::reference::lightcuts` (which
//! documents the bound); docs/lightcuts.md.

mod kernels;
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
use crate::settings::RenderSettings;
use pass::{GpuLcParams, GpuLcViewParams, LcBuffers, LcStats, LightcutsPass, TracedCut};
use settings::LightcutsSettings;

pub const ID: MethodId = MethodId::new("lightcuts");

macro_rules! shader {
    ($name:literal) => {
        (
            concat!("methods/lightcuts/", $name),
            include_str!(concat!("../../../shaders/methods/lightcuts/", $name)),
        )
    };
}

/// Its WGSL files (paths under `shaders/`), embedded; the GPU layer finds them through
/// `gpu::shaders::ShaderTable` without naming the method.
const SHADERS: &[(&str, &str)] = &[
    shader!("lc_common.wgsl"),
    shader!("lc_brdf_bound.wgsl"),
    shader!("lc_build.wgsl"),
    shader!("lc_merge.wgsl"),
    shader!("lc_build_radix.wgsl"),
    shader!("lightcuts.wgsl"),
    shader!("lc_views.wgsl"),
];

/// Those of its files that are entry points.
const ENTRY_SHADERS: &[&str] = &[
    "methods/lightcuts/lc_build.wgsl",
    "methods/lightcuts/lc_build_radix.wgsl",
    "methods/lightcuts/lightcuts.wgsl",
    "methods/lightcuts/lc_views.wgsl",
];

inventory::submit! {
    crate::gpu::shaders::ShaderTable {
        files: SHADERS,
        entries: ENTRY_SHADERS,
    }
}

pub static MODULE: Module = Module {
    name: "lightcuts",
    create,
    shaders: SHADERS,
    entry_shaders: ENTRY_SHADERS,
    wgsl_twins: pass::WGSL_TWINS,
    own_workgroups: &[],
    flags: &[],
};

/// Nodes in each pixel's cut (log heat map).
pub const CUT_SIZE: MethodView = MethodView::new("lightcut size");
/// The largest error bound left in the cut over the estimate (log heat map).
pub const ERROR_BOUND: MethodView = MethodView::new("lightcut error bound");
/// Refinement steps per pixel (log heat map).
pub const REFINEMENTS: MethodView = MethodView::new("lightcut refinements");
/// Pixels whose refinement stopped at the maximum cut size (red over the grey final).
pub const AT_MAX_CUT: MethodView = MethodView::new("lightcut at max cut");

const VIEWS: &[ViewInfo] = &[
    ViewInfo {
        name: CUT_SIZE.name(),
        file: "lightcut_size",
        about: "nodes in each pixel's lightcut (log scale up to max cut)",
        passes: &["lightcuts"],
    },
    ViewInfo {
        name: ERROR_BOUND.name(),
        file: "lightcut_error_bound",
        about: "the largest error bound left in the cut / the pixel's estimate (log scale; \
                above the relative error where the cut hit its maximum size)",
        passes: &["lightcuts"],
    },
    ViewInfo {
        name: REFINEMENTS.name(),
        file: "lightcut_refinements",
        about: "refinement steps per pixel (log scale up to max cut)",
        passes: &["lightcuts"],
    },
    ViewInfo {
        name: AT_MAX_CUT.name(),
        file: "lightcut_at_max_cut",
        about: "pixels whose cut stopped at the maximum size, red over the grey final",
        passes: &["lightcuts"],
    },
];

fn invalid_example(s: &mut RenderSettings) -> &'static str {
    let lc = LightcutsSettings {
        max_cut: 0,
        ..Default::default()
    };
    let _ = s.set_method(ID, &lc);
    "methods.lightcuts.max_cut"
}

pub static INFO: MethodInfo = MethodInfo {
    id: ID,
    aliases: &["lc"],
    label: "Lightcuts",
    short: "Lightcuts",
    about: "Lightcuts (Walter et al. 2005): per pixel, the cut refined by the largest error bound \
            until it is below a relative threshold; representative VPLs and shadow rays.",
    progress_unit: "",
    kind: Kind::PerFrame,
    module: &MODULE,
    reads: &[
        Resource::Gbuffer,
        Resource::Tree,
        Resource::AnyTree,
        Resource::Bvh,
    ],
    views: VIEWS,
    timed_passes: &["lightcuts_build", "lightcuts"],
    story: false,
    shadow_ray_switch: true,
    visibility: None,
    truth_of_vpls: false,
    one_bounce: false,
    glossy: true,
    validate,
    fields,
    invalid_example: Some(invalid_example),
    ui: ui::settings_ui,
    tests: &[
        "lightcuts::the_error_bound_is_never_below_the_true_geometric_term",
        "lightcuts::gpu_lightcuts_equal_the_cpu_reference_and_cuts_are_valid",
        "lightcuts::threshold_zero_and_unlimited_cut_equal_the_ground_truth",
        "lightcuts::the_mean_over_builds_of_a_fixed_cut_converges_to_the_ground_truth",
        "lightcuts::the_ggx_error_bound_is_never_below_the_true_glossy_term",
        "lightcuts::gpu_lightcuts_with_ggx_equal_the_cpu_reference",
        "lightcuts::with_ggx_threshold_zero_equals_the_ggx_ground_truth",
    ],
    sweep: Some(&SWEEP),
    bias,
    unbiased: Some(super::Unbiased {
        how: "methods.lightcuts.relative_error = 0 (the cut of the max_cut largest bounds)",
        apply: |s| {
            let mut lc: LightcutsSettings = s.method(ID).unwrap_or_default();
            lc.relative_error = 0.0;
            let _ = s.set_method(ID, &lc);
        },
    }),
};

/// At threshold 0 the cut is the `max_cut` nodes of the largest bounds whatever the
/// representatives drew, and the estimate of a fixed cut is unbiased over the draws
/// (docs/lightcuts.md, *Unbiasedness over builds*). With a threshold the cut depends on the
/// estimates: measured 0.9974x in one frame at 2%, 1.0000x over 16 (the same page).
fn bias(s: &RenderSettings) -> super::Bias {
    match s.method::<LightcutsSettings>(ID) {
        Ok(lc) if lc.relative_error == 0.0 => super::Bias::Unbiased,
        _ => super::Bias::Biased {
            tolerance: 0.02,
            reason: "the threshold stops refinement on the representatives' draws, so the cut depends on them",
        },
    }
}

/// The relative error threshold, coarse to fine (Walter et al.'s 2% and the interpolation
/// paper's 1% among them).
pub static SWEEP: super::Sweep = super::Sweep {
    name: "relative_error",
    values: &[0.2, 0.1, 0.05, 0.02, 0.01],
    apply: |s, v| {
        let mut lc: LightcutsSettings = s.method(ID).unwrap_or_default();
        lc.relative_error = v.clamp(0.0, 1.0) as f32;
        let _ = s.set_method(ID, &lc);
    },
    integer: false,
};

fn validate(s: &RenderSettings) -> Result<(), String> {
    s.method::<LightcutsSettings>(ID)?.validate()
}

/// Decades of the cut-size and refinement scales: 1 .. 10^decades >= max_cut.
fn decades(max_cut: u32) -> u32 {
    (max_cut.max(2) as f32).log10().ceil() as u32
}

pub struct Lightcuts {
    pass: LightcutsPass,
    buffers: LcBuffers,
    /// Accumulation: (key, frames summed).
    state: Option<(u64, u32)>,
    traced: bool,
    /// The settings of the last frame (views' scales).
    settings: LightcutsSettings,
    /// Refinements per dispatch on this adapter (`pass::steps_per_dispatch`).
    steps: u32,
}

fn create(device: &wgpu::Device) -> Result<Box<dyn Method>, ShaderError> {
    Ok(Box::new(Lightcuts {
        pass: LightcutsPass::new(device)?,
        buffers: LcBuffers::new(device, 1, (1, 1), 1, pass::SCRATCH_BUDGET),
        state: None,
        traced: false,
        settings: LightcutsSettings::default(),
        steps: 0,
    }))
}

impl Lightcuts {
    pub fn buffers(&self) -> &LcBuffers {
        &self.buffers
    }
    /// The last build's normal cones and representatives.
    pub fn read_build(&self, ctx: &GpuContext) -> Result<crate::reference::lightcuts::LcTree, GpuError> {
        pass::read_build(ctx, &self.buffers)
    }
    /// The pinned pixel's cut in the last diagnostic frame that traced one.
    pub fn read_traced_cut(&self, ctx: &GpuContext) -> Result<Option<TracedCut>, GpuError> {
        if !self.traced {
            return Ok(None);
        }
        let bytes = readback::read_storage_buffer(ctx, &self.buffers.trace)?;
        Ok(TracedCut::parse(&bytemuck::pod_collect_to_vec::<u8, u32>(&bytes)))
    }
    /// Counters of a recent diagnostic frame (non-blocking).
    pub fn poll_stats(&mut self) -> Option<LcStats> {
        self.pass.stats.poll()
    }
    /// The seed of frame `frame_index`'s representatives.
    pub fn seed(s: &RenderSettings, frame_index: u64) -> u32 {
        if s.frame.fixed_seed {
            s.vpl.seed
        } else {
            s.vpl.seed ^ (frame_index as u32).wrapping_mul(0x9e37_79b9)
        }
    }
}

impl Method for Lightcuts {
    fn record(&mut self, cx: &mut FrameCx<'_>, enc: &mut wgpu::CommandEncoder) -> f32 {
        let s = cx.settings;
        let lc: LightcutsSettings = s.method(cx.method).unwrap_or_default();
        if self.steps == 0 {
            self.steps = pass::steps_per_dispatch(cx.adapter_type);
        }
        let leaves = cx.tree.leaves;
        let max_cut = lc.max_cut.clamp(1, crate::reference::lightcuts::MAX_CUT);
        if !self.buffers.matches(leaves, cx.size, max_cut) {
            let need = LcBuffers::largest_binding(leaves, cx.size);
            let limit = cx.device.limits().max_storage_buffer_binding_size;
            if need > limit {
                cx.errors.report(format!(
                    "lightcuts: {}x{} pixels and {leaves} leaves need a {} MiB buffer; this device \
                     binds at most {} MiB",
                    cx.size.0,
                    cx.size.1,
                    need >> 20,
                    limit >> 20
                ));
                enc.clear_buffer(cx.gi_accum, 0, None);
                self.state = None;
                return 1.0;
            }
            let budget = pass::SCRATCH_BUDGET.min(limit);
            self.buffers = LcBuffers::new(cx.device, leaves, cx.size, max_cut, budget);
        }
        let frames = match self.state {
            Some((k, n)) if s.frame.accumulate && k == cx.key => n + 1,
            _ => 1,
        };
        self.state = Some((cx.key, frames));
        let p = GpuLcParams {
            width: cx.size.0,
            height: cx.size.1,
            leaves,
            max_cut,
            relative_error: lc.relative_error,
            epsilon: s.gi.distance_epsilon,
            ray_offset: s.gi.ray_offset,
            shadow_rays: s.gi.shadow_rays as u32,
            accumulate: (frames > 1) as u32,
            trace_pixel: match cx.trace_pixel {
                Some((x, y)) => x | y << 16,
                None => u32::MAX,
            },
            first_pixel: 0,
            slice: self.buffers.slice,
            first: 1,
            last: 1,
            steps: self.steps,
            radix: (cx.tree.kind == crate::settings::TreeKind::Lbvh) as u32,
            brdf: cx.brdf.gpu(),
            _pad: [0; 3],
            eye: cx.eye.extend(0.0).to_array(),
        };
        if cx.diagnostics {
            self.traced = cx.trace_pixel.is_some();
        }
        self.settings = lc;
        let seed = Self::seed(s, cx.frame_index);
        self.pass.record(cx, enc, p, seed, &self.buffers);
        1.0 / frames as f32
    }

    fn after_submit(&mut self) {
        self.pass.stats.after_submit();
    }

    fn frames_averaged(&self) -> Option<u32> {
        Some(self.state.map_or(0, |(_, n)| n))
    }

    fn reset(&mut self) {
        self.state = None;
    }

    fn view_size(&self, _view: MethodView, frame: (u32, u32)) -> Option<(u32, u32)> {
        (self.buffers.size == frame && self.state.is_some()).then_some(frame)
    }

    fn record_view(&mut self, view: MethodView, cx: &mut ViewCx<'_>, enc: &mut wgpu::CommandEncoder) {
        let p = GpuLcViewParams {
            mode: if view == CUT_SIZE {
                0
            } else if view == ERROR_BOUND {
                1
            } else if view == REFINEMENTS {
                2
            } else {
                3
            },
            scale_top: 10u32.pow(decades(self.settings.max_cut)),
            relative_error: self.settings.relative_error,
            exposure: cx.look.exposure_ev.exp2(),
            tonemap: cx.look.tonemap.gpu_id(),
            _pad: [0; 3],
        };
        self.pass.record_view(cx, enc, p, &self.buffers);
    }

    /// The pinned pixel's cut with its refinement counters.
    fn read_story(&self, ctx: &GpuContext) -> Result<Option<Story>, GpuError> {
        let Some(t) = self.read_traced_cut(ctx)? else {
            return Ok(None);
        };
        let w = self.buffers.size.0.max(1);
        let visible = t.nodes.iter().filter(|n| n.estimate != [0.0; 3]).count();
        Ok(Some(Story::Cuts(CutStory {
            rows: vec![
                ("pixel".into(), format!("({}, {})", t.pixel % w, t.pixel / w)),
                (
                    "cut".into(),
                    format!(
                        "{} nodes ({visible} contributing), {} refinements",
                        t.nodes.len(),
                        t.refinements
                    ),
                ),
                (
                    "largest bound left / estimate".into(),
                    format!("{:.3e}", t.relative_bound),
                ),
                ("shadow rays".into(), t.shadow_rays.to_string()),
            ],
            inputs: Vec::new(),
            cut: Some(StoryCut {
                label: format!("lightcut ({} nodes)", t.nodes.len()),
                nodes: t.nodes.iter().map(|n| n.node).collect(),
            }),
            disagreements: Vec::new(),
            links: Vec::new(),
        })))
    }

    /// Per pixel: cut size, refinements, largest bound left / estimate, shadow rays.
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
            "lightcut (cut size, refinements, bound / estimate, shadow rays)",
            d,
        )])
    }

    fn legend(&self, view: MethodView, _tree_levels: u32) -> Option<Legend> {
        let st = self.pass.stats.last();
        let top = decades(self.settings.max_cut) as f32;
        if view == CUT_SIZE {
            Some(Legend {
                title: match st {
                    Some(st) => format!("lightcut size (image mean {:.1})", st.mean_cut()),
                    None => "lightcut size".into(),
                },
                lo: 0.0,
                hi: top,
                log: true,
            })
        } else if view == ERROR_BOUND {
            Some(Legend {
                title: format!(
                    "largest bound left / estimate (threshold {})",
                    self.settings.relative_error
                ),
                lo: -4.0,
                hi: 0.0,
                log: true,
            })
        } else if view == REFINEMENTS {
            Some(Legend {
                title: "refinement steps + 1".into(),
                lo: 0.0,
                hi: top,
                log: true,
            })
        } else {
            None
        }
    }

    fn stats(&mut self) -> Vec<(&'static str, f64)> {
        match self.pass.stats.poll() {
            Some(st) => vec![
                ("mean_cut_size", st.mean_cut()),
                (
                    "refinements_per_pixel",
                    st.refinements as f64 / st.pixels.max(1) as f64,
                ),
                ("shadow_rays_per_pixel", st.rays_per_pixel()),
                ("max_cut_pixel_fraction", st.max_cut_fraction()),
                ("max_cut", self.settings.max_cut as f64),
                ("relative_error", self.settings.relative_error as f64),
            ],
            None => Vec::new(),
        }
    }

    fn status(&mut self) -> Option<String> {
        let st = self.pass.stats.poll()?;
        Some(format!(
            "lightcut {:.1} nodes per pixel · {:.1} shadow rays per pixel · {:.2}% pixels at max cut ({})",
            st.mean_cut(),
            st.rays_per_pixel(),
            100.0 * st.max_cut_fraction(),
            self.settings.max_cut
        ))
    }
}

/// `MethodInfo::fields`.
fn fields() -> Vec<super::FieldSection> {
    vec![super::FieldSection::of(
        "methods.lightcuts",
        settings::FIELDS,
        true,
    )]
}

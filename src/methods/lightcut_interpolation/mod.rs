//! Lightcut Interpolation (Rehfeld & Dachsbacher 2016): exact lightcuts at cache records
//! placed in image space (section 3.1), per pixel the best three records by Tabellion and
//! Lamorlette's weight (3.2), their cuts interpolated into one valid cut (3.3) and shaded
//! with a shadow ray per node or with interpolated visibility; pixels without a usable record
//! compute a full lightcut. Same tree, VPLs, representatives and shadow rays as `lightcuts`.
//!
//! Passes in `pass` (module doc there); CPU twins in
//! `crate::reference::lightcut_interpolation`; docs/lightcut-interpolation.md.

pub mod pass;
pub mod settings;
mod ui;

use super::{
    CutStory, FrameCx, Kind, Legend, Method, MethodId, MethodInfo, MethodView, Module, Resource, StoryCut,
    ViewCx, ViewInfo,
};
use crate::methods::lightcuts::{
    Lightcuts,
    pass::{GpuLcParams, SCRATCH_BUDGET, steps_per_dispatch},
};
use crate::reference::lightcuts::{Cone, LcTree, MAX_CUT};
use crate::renderer::{
    context::{GpuContext, GpuError},
    readback::{self, ImageF32},
    settings::RenderSettings,
    shaders::ShaderError,
};
use pass::{
    FrameInputs, GpuLiParams, GpuLiViewParams, LiBuffers, LiPass, LiStats, TracedInterpolation,
    walk_steps_per_dispatch,
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

pub static MODULE: Module = Module {
    name: "lightcut_interpolation",
    create,
    shaders: &[
        shader!("li_common.wgsl"),
        shader!("li_records.wgsl"),
        shader!("li_select.wgsl"),
        shader!("li_interp.wgsl"),
        shader!("li_views.wgsl"),
    ],
    entry_shaders: &[
        "methods/lightcut_interpolation/li_records.wgsl",
        "methods/lightcut_interpolation/li_select.wgsl",
        "methods/lightcut_interpolation/li_interp.wgsl",
        "methods/lightcut_interpolation/li_views.wgsl",
    ],
    wgsl_twins: pass::WGSL_TWINS,
    own_workgroups: &[crate::renderer::passes::OwnWorkgroup {
        // One workgroup per 16 x 16 tile.
        file: "methods/lightcut_interpolation/li_records.wgsl",
        entries: pass::TILE_WG_ENTRIES,
        size: [pass::TILE_WG, 1, 1],
    }],
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

impl Method for LightcutInterpolation {
    fn record(&mut self, cx: &mut FrameCx<'_>, enc: &mut wgpu::CommandEncoder) -> f32 {
        let s = cx.settings;
        let li: LightcutInterpolationSettings = s.method(cx.method).unwrap_or_default();
        if self.pass.is_none() {
            match LiPass::new(cx.device) {
                Ok(p) => self.pass = Some(p),
                Err(e) => {
                    cx.errors.report(format!("lightcut interpolation: {e}"));
                    enc.clear_buffer(cx.gi_accum, 0, None);
                    return 1.0;
                }
            }
            self.steps = (
                steps_per_dispatch(cx.adapter_type),
                walk_steps_per_dispatch(cx.adapter_type),
            );
        }
        let leaves = cx.tree.leaves;
        let max_cut = li.max_cut.clamp(1, MAX_CUT);
        let split = self.steps.1 != u32::MAX;
        if !self
            .buffers
            .as_ref()
            .is_some_and(|b| b.matches(leaves, cx.size, max_cut, split))
        {
            let need = LiBuffers::largest_binding(leaves, cx.size, split);
            let limit = cx.device.limits().max_storage_buffer_binding_size;
            if need > limit {
                cx.errors.report(format!(
                    "lightcut interpolation: {}x{} pixels and {leaves} leaves need a {} MiB \
                     buffer; this device binds at most {} MiB",
                    cx.size.0,
                    cx.size.1,
                    need >> 20,
                    limit >> 20
                ));
                enc.clear_buffer(cx.gi_accum, 0, None);
                self.state = None;
                return 1.0;
            }
            self.buffers = Some(LiBuffers::new(
                cx.device,
                leaves,
                cx.size,
                max_cut,
                SCRATCH_BUDGET.min(limit),
                limit,
                split,
            ));
        }
        let (Some(pass), Some(b)) = (self.pass.as_mut(), self.buffers.as_ref()) else {
            return 1.0;
        };
        let frames = match self.state {
            Some((k, n)) if s.sampling.accumulate && k == cx.key => n + 1,
            _ => 1,
        };
        self.state = Some((cx.key, frames));
        let trace_pixel = match cx.trace_pixel {
            Some((x, y)) => x | y << 16,
            None => u32::MAX,
        };
        let p = GpuLiParams {
            width: cx.size.0,
            height: cx.size.1,
            tiles_x: b.tiles.0,
            tiles_y: b.tiles.1,
            leaves,
            levels: leaves.trailing_zeros(),
            max_cut,
            capacity: b.capacity,
            r_min_px: li.r_min_px,
            r_max_px: li.r_max_px,
            one_minus_cos_max: 1.0 - li.max_angle_deg.to_radians().cos(),
            epsilon: li.epsilon,
            coverage: li.coverage,
            radius_rays: li.radius_rays,
            ray_offset: s.gi.ray_offset,
            shadow_rays: s.gi.shadow_rays as u32,
            interp_visibility: (li.visibility == LiVisibility::Interpolated) as u32,
            accumulate: (frames > 1) as u32,
            trace_pixel,
            steps: self.steps.1,
            first: 1,
            last: 1,
            distance_epsilon: s.gi.distance_epsilon,
            _pad: 0,
        };
        let lc = GpuLcParams {
            width: cx.size.0,
            height: cx.size.1,
            leaves,
            max_cut,
            relative_error: li.relative_error,
            epsilon: s.gi.distance_epsilon,
            ray_offset: s.gi.ray_offset,
            shadow_rays: s.gi.shadow_rays as u32,
            accumulate: (frames > 1) as u32,
            trace_pixel: u32::MAX,
            first_pixel: 0,
            slice: 0,
            first: 1,
            last: 1,
            steps: self.steps.0,
            radix: 0,
            brdf: 0,
            _pad: [0; 3],
            eye: [0.0; 4],
        };
        if cx.diagnostics {
            self.traced = cx.trace_pixel.is_some();
        }
        if cx.diagnostics {
            // (Timed frames trace nothing: the view keeps the last diagnostic frame's pin.)
            self.pinned = cx
                .trace_pixel
                .filter(|&(x, y)| x < cx.size.0 && y < cx.size.1)
                .map(|(x, y)| y * cx.size.0 + x);
        }
        if li != self.settings {
            pass.stats.clear();
        }
        self.settings = li;
        let f = FrameInputs {
            tree: cx.tree,
            scene: cx.scene,
            gbuffer: &cx.targets.gbuffer,
            camera: cx.camera,
            accum: cx.gi_accum,
        };
        pass.record(
            cx.diagnostics,
            cx.device,
            cx.queue,
            enc,
            cx.timer,
            p,
            lc,
            Lightcuts::seed(s, cx.frame_index),
            &f,
            b,
        );
        1.0 / frames as f32
    }

    fn after_submit(&mut self) {
        if let Some(p) = &self.pass {
            p.stats.after_submit();
        }
    }

    fn frames_averaged(&self) -> Option<u32> {
        Some(self.state.map_or(0, |(_, n)| n))
    }

    fn reset(&mut self) {
        self.state = None;
    }

    fn view_size(&self, _view: MethodView, frame: (u32, u32)) -> Option<(u32, u32)> {
        (self.buffers.as_ref()?.size == frame && self.state.is_some()).then_some(frame)
    }

    fn record_view(&mut self, view: MethodView, cx: &mut ViewCx<'_>, enc: &mut wgpu::CommandEncoder) {
        let (Some(pass), Some(b)) = (self.pass.as_ref(), self.buffers.as_ref()) else {
            return;
        };
        let mode = [RECORDS, WEIGHTS, FALLBACK, CUT_SIZE, LEVEL_SPREAD]
            .iter()
            .position(|v| *v == view)
            .unwrap_or(0) as u32;
        let p = GpuLiViewParams {
            mode,
            scale_top: 10u32.pow(decades(self.settings.max_cut)),
            r_min_px: self.settings.r_min_px,
            r_max_px: self.settings.r_max_px,
            exposure: cx.look.exposure_ev.exp2(),
            tonemap: cx.look.tonemap.gpu_id(),
            tiles_x: b.tiles.0,
            tiles_y: b.tiles.1,
            pinned: self.pinned.unwrap_or(u32::MAX),
            _pad: [0; 3],
        };
        pass.record_view(
            cx.device,
            cx.queue,
            enc,
            cx.timer,
            p,
            &cx.targets.lighting.final_view,
            &cx.targets.gbuffer.position_view,
            b,
            cx.dst,
        );
    }

    /// The pinned pixel: its records (pixel, weight, cut), the interpolated cut, and where
    /// the records' cuts disagree.
    fn read_cut_story(&self, ctx: &GpuContext) -> Result<Option<CutStory>, GpuError> {
        let Some(b) = &self.buffers else { return Ok(None) };
        let Some(t) = self.read_traced(ctx)? else {
            return Ok(None);
        };
        let word = |buf: &wgpu::Buffer, i: u64| -> Result<u32, GpuError> {
            let bytes = readback::read_buffer_range(ctx, buf, 4 * i, 4)?;
            Ok(bytemuck::pod_read_unaligned(&bytes[..4]))
        };
        let levels = b.leaves.trailing_zeros();
        let mut story = CutStory::default();
        let px = |k: u32| (k % b.size.0, k / b.size.0);
        let (x, y) = px(t.pixel);
        story.rows.push(("pixel".into(), format!("({x}, {y})")));
        let mut cuts = Vec::new();
        for (i, (&r, &w)) in t.records.iter().zip(&t.weights).enumerate() {
            let pixel = word(&b.records, r as u64)?;
            let len = word(&b.rec_meta, 8 + r as u64)?.min(b.max_cut);
            let bytes = readback::read_buffer_range(
                ctx,
                &b.record_cuts,
                4 * r as u64 * b.max_cut as u64,
                4 * len.max(1) as u64,
            )?;
            let cut: Vec<u32> = bytemuck::pod_collect_to_vec::<u8, u32>(&bytes)
                .into_iter()
                .take(len as usize)
                .collect();
            let (rx, ry) = px(pixel);
            let visible = cut
                .iter()
                .filter(|&&e| e & crate::reference::lightcut_interpolation::VISIBLE != 0)
                .count();
            story.rows.push((
                format!("record {}", i + 1),
                format!("#{r} at ({rx}, {ry}), weight {w:.3}, cut {len} nodes ({visible} visible)"),
            ));
            story.inputs.push(StoryCut {
                label: format!("record #{r} (w {w:.2})"),
                nodes: cut
                    .iter()
                    .map(|e| e & !crate::reference::lightcut_interpolation::VISIBLE)
                    .collect(),
            });
            cuts.push(cut);
        }
        let refs: Vec<&[u32]> = cuts.iter().map(|c| c.as_slice()).collect();
        story.disagreements = crate::reference::lightcut_interpolation::disagreements(&refs, levels);
        let span: u32 = story.disagreements.iter().map(|(s, e)| e - s).sum();
        story.rows.push((
            "inputs disagree".into(),
            format!(
                "on {span} of {} leaves (level spread {:.2})",
                b.leaves, t.level_spread
            ),
        ));
        story.rows.push((
            "interpolated cut".into(),
            format!(
                "{} nodes, {} walk steps, {} shadow rays ({})",
                t.nodes.len(),
                t.walk_steps,
                t.shadow_rays,
                self.settings.visibility.label()
            ),
        ));
        story.cut = Some(StoryCut {
            label: format!("interpolated ({} nodes)", t.nodes.len()),
            nodes: t.nodes.iter().map(|n| n.0).collect(),
        });
        Ok(Some(story))
    }

    /// Per pixel: cut size, level spread (-1: fallback), records used, shadow rays.
    fn read_view(&self, ctx: &GpuContext, _view: MethodView) -> Result<Option<ImageF32>, GpuError> {
        let Some(b) = &self.buffers else { return Ok(None) };
        if self.state.is_none() {
            return Ok(None);
        }
        readback::read_vec4_image(ctx, &b.diag, b.size)
    }

    fn pixel_rows(
        &self,
        ctx: &GpuContext,
        x: u32,
        y: u32,
        frame: (u32, u32),
    ) -> Result<Vec<(&'static str, [f32; 4])>, GpuError> {
        let Some(b) = &self.buffers else {
            return Ok(Vec::new());
        };
        if b.size != frame || x >= frame.0 || y >= frame.1 || self.state.is_none() {
            return Ok(Vec::new());
        }
        let k = y as u64 * b.size.0 as u64 + x as u64;
        let d = readback::read_vec4_pixel(ctx, &b.diag, b.size.0, x, y)?;
        let sel: [u32; 8] =
            bytemuck::pod_read_unaligned(&readback::read_buffer_range(ctx, &b.sel, k * 32, 32)?[..32]);
        let w = |i: usize| f32::from_bits(sel[i]);
        Ok(vec![
            (
                "LI cut (size, level spread or -1 = fallback, records, shadow rays)",
                d,
            ),
            (
                "LI records (ids)",
                [sel[0] as f32, sel[1] as f32, sel[2] as f32, sel[3] as f32],
            ),
            ("LI weights (3, best raw)", [w(4), w(5), w(6), w(7)]),
        ])
    }

    fn legend(&self, view: MethodView, _tree_levels: u32) -> Option<Legend> {
        let st = self.pass.as_ref()?.stats.last();
        if view == CUT_SIZE {
            Some(Legend {
                title: match st {
                    Some(st) => format!("cut size (image mean {:.1})", st.mean_cut()),
                    None => "cut size".into(),
                },
                lo: 0.0,
                hi: decades(self.settings.max_cut) as f32,
                log: true,
            })
        } else if view == LEVEL_SPREAD {
            Some(Legend {
                title: "input cut level spread (levels)".into(),
                lo: 0.0,
                hi: 4.0,
                log: false,
            })
        } else if view == FALLBACK {
            st.map(|st| Legend {
                title: format!("fallback {:.2}% of pixels", 100.0 * st.fallback_fraction()),
                lo: 0.0,
                hi: 1.0,
                log: false,
            })
        } else {
            None
        }
    }

    fn stats(&mut self) -> Vec<(&'static str, f64)> {
        match self.poll_stats() {
            Some(st) => vec![
                ("records", st.records as f64),
                ("records_per_pixel", st.records_per_pixel()),
                ("mean_record_cut_size", st.mean_record_cut()),
                ("mean_cut_size", st.mean_cut()),
                ("shadow_rays_per_pixel", st.rays_per_pixel()),
                (
                    "interpolation_rays_per_pixel",
                    st.shadow_rays as f64 / st.pixels().max(1) as f64,
                ),
                ("fallback_pixel_fraction", st.fallback_fraction()),
                ("dropped_records", st.dropped_records as f64),
                ("unfinished_walks", st.unfinished as f64),
                ("relative_error", self.settings.relative_error as f64),
                ("r_max_px", self.settings.r_max_px as f64),
                (
                    "interpolated_visibility",
                    (self.settings.visibility == LiVisibility::Interpolated) as u32 as f64,
                ),
            ],
            None => Vec::new(),
        }
    }

    fn status(&mut self) -> Option<String> {
        let st = self.poll_stats()?;
        let dropped = if st.dropped_records > 0 {
            format!(" · {} records dropped (memory)", st.dropped_records)
        } else {
            String::new()
        };
        Some(format!(
            "{} records ({:.2}% of pixels, cuts of {:.0}) · cut {:.1} nodes per pixel · {:.1} shadow rays per pixel · fallback {:.2}%{dropped}",
            st.records,
            100.0 * st.records_per_pixel(),
            st.mean_record_cut(),
            st.mean_cut(),
            st.rays_per_pixel(),
            100.0 * st.fallback_fraction()
        ))
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

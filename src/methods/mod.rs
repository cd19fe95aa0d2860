//! GI methods: one folder each, one line each in [`REGISTRY`].
//!
//! A method is a [`MethodInfo`] (what it is and what it offers: name, label, CLI name, kind,
//! the frame resources it reads, the named views it draws, its timed GPU passes, its pixel
//! story, its settings' validation and UI, its shaders, the tests that check it) and a
//! [`Method`] instance (its pipelines and state between frames) that records its passes after
//! the frame's G-buffer, VPLs and light tree exist and writes the GI accumulation buffer.
//! The shape follows Falcor's render passes (`reflect()` = the declared resources and views,
//! `execute()` = [`Method::record`], `renderUI()` = [`MethodInfo::ui`]).
//!
//! Everything that lists methods (the renderer, the GUI's method combo and settings, `render
//! --method`, `sheet --methods`, `results`, the comparison ground truth, the shader table and
//! the registry test) enumerates [`REGISTRY`]; ARCHITECTURE.md, *Adding a method*, walks
//! through a new one.

pub mod direct_only;
pub mod ground_truth;
mod ids;
pub mod interleave;
pub mod ism_ui;
pub mod light_culling;
pub mod lightcut_interpolation;
pub mod lightcuts;
pub mod overlay;
pub mod reference;
pub mod restir;
pub mod tree_samplers;
pub mod val;
pub use ids::*;

use std::any::Any;
use std::fmt;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

pub use crate::base::{colormap::Legend, progress::GiProgress};

use crate::gpu::context::{ErrorSink, GpuContext, GpuError};
use crate::gpu::frame::FrameTargets;
use crate::gpu::passes::{
    sst_build::TreeBuffers,
    vpl_gen::{VplBuffers, VplFrame},
};
use crate::gpu::readback::ImageF32;
use crate::gpu::scene_gpu::SceneGpu;
use crate::gpu::shaders::ShaderError;
use crate::gpu::timing::GpuTimer;
use crate::gpu::views::ViewLook;
use crate::settings::RenderSettings;

/// Every GI method, in the order the GUI lists them. Adding a method: its folder and one
/// line here.
pub static REGISTRY: &[&MethodInfo] = &[
    &tree_samplers::SLC_INFO,
    &tree_samplers::SST_INFO,
    &tree_samplers::RTSLC_INFO,
    &lightcuts::INFO,
    &lightcut_interpolation::INFO,
    &light_culling::INFO,
    &light_culling::CLAMPED_INFO,
    &light_culling::TREE_INFO,
    &val::INFO,
    &val::VPL_INFO,
    &ground_truth::INFO,
    &reference::INFO,
    &direct_only::INFO,
];

pub use crate::base::story::{CutStory, Story, StoryCut};

/// How a method produces its image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// No indirect light.
    DirectOnly,
    /// Accumulates towards a converged image over frames (progress bar, restarts on change).
    Progressive,
    /// One estimate per frame (averaged over frames only while `frame.accumulate`).
    PerFrame,
}

/// Frame resources a method may read (what its passes bind).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Resource {
    Gbuffer,
    /// The lights' shadow maps / reflective shadow maps (and their pyramids).
    ShadowMaps,
    /// The frame's VPLs.
    Vpls,
    /// The light tree (SST nodes, usable flags, VPLs in leaf order).
    Tree,
    /// Either light tree (`tree.kind`): the method follows the tree's links
    /// (`common/tree_links.wgsl`), so it runs on the radix tree too. A method that reads
    /// `Tree` without this needs the perfect tree, and its settings refuse `tree.kind = lbvh`.
    AnyTree,
    /// The scene BVH (shadow rays).
    Bvh,
}

/// What a module (one folder under `src/methods/`) brings: its GPU instance and shaders.
pub struct Module {
    /// The folder name.
    pub name: &'static str,
    /// Builds its pipelines (again on shader reload).
    pub create: fn(&wgpu::Device) -> Result<Box<dyn Method>, ShaderError>,
    /// Its WGSL files, by path under `shaders/` (`methods/<module>/...`), embedded.
    pub shaders: &'static [(&'static str, &'static str)],
    /// Those of its files that are entry points.
    pub entry_shaders: &'static [&'static str],
    /// Its `#[repr(C)]` structs shared with WGSL (`wgsl_twin!`, beside the structs): one
    /// registry test checks them all against naga's layout.
    pub wgsl_twins: &'static [crate::gpu::gpu_data::WgslTwin],
    /// Its kernels dispatched with a workgroup size of their own (the registry test checks
    /// every other compute entry point has the standard sizes).
    pub own_workgroups: &'static [crate::gpu::passes::OwnWorkgroup],
    /// Its command-line flags (`render`, `sheet`): shorthands for `--set` of its settings.
    pub flags: &'static [MethodFlag],
}

/// A command-line flag a method module declares: it sets one of the module's settings by its
/// TOML path, as `--set path=value` would (and is checked by the same validation).
pub struct MethodFlag {
    /// The long name without dashes (`cut-size`).
    pub long: &'static str,
    /// Its line in `--help`.
    pub help: &'static str,
    /// The settings path it sets (`methods.slc.cut_size`).
    pub path: &'static str,
    pub kind: FlagKind,
}

/// What a [`MethodFlag`] takes.
pub enum FlagKind {
    /// A number (its value name in `--help`), written as given.
    Number(&'static str),
    /// One of these words, each written as its settings value: (CLI word, TOML value).
    Choice(&'static [(&'static str, &'static str)]),
    /// A switch: present, it writes this TOML value.
    Switch(&'static str),
}

/// Every module's flags, each once (the CLI's `render` and `sheet` offer them).
pub fn flags() -> Vec<&'static MethodFlag> {
    let mut v: Vec<&'static MethodFlag> = Vec::new();
    for m in modules() {
        for f in m.flags {
            if !v.iter().any(|x| x.long == f.long) {
                v.push(f);
            }
        }
    }
    v
}

/// A per-frame method's quality knob: what `results` sweeps for its RMSE-vs-GPU-time curve
/// (the tree samplers' samples per pixel, Lightcuts' relative error).
pub struct Sweep {
    /// The setting's name (CSV `setting` column, plot captions): "spp", "relative_error".
    pub name: &'static str,
    /// The values swept, cheapest first (empty: the harness's `--spp` list).
    pub values: &'static [f64],
    /// Sets it in a copy of the settings.
    pub apply: fn(&mut RenderSettings, f64),
    /// Whether the values are integers (interpolated values are rounded).
    pub integer: bool,
}

/// One row of the registry: everything the workbench needs to know of a method.
pub struct MethodInfo {
    pub id: MethodId,
    /// Other spellings accepted by [`MethodId::parse`] (older settings files).
    pub aliases: &'static [&'static str],
    /// The label in the GUI and on sheets.
    pub label: &'static str,
    /// Short label for tables and plots.
    pub short: &'static str,
    /// One sentence: the paper and what the method does.
    pub about: &'static str,
    pub kind: Kind,
    /// What a progressive method's progress counts ("VPLs", "samples per pixel").
    pub progress_unit: &'static str,
    pub module: &'static Module,
    pub reads: &'static [Resource],
    /// The named views it draws beside final / direct / GI (every buffer menu, `--views` and
    /// `render`'s PNGs list them as `ViewBuffer::Method`; export writes the PNG as shown and
    /// the EXR of `Method::read_view`; A/B compares radiance buffers and snapshots, not these).
    pub views: &'static [ViewInfo],
    /// Its GPU passes (timer names) that form its GI cost: the harness's equal-time cost and
    /// the `gi_gpu_ms` column.
    pub timed_passes: &'static [&'static str],
    /// True when the pixel story can trace it.
    pub story: bool,
    /// True when it honours `gi.shadow_rays` (the GUI shows the switch).
    pub shadow_ray_switch: bool,
    /// The ways it can shadow its lights while `gi.shadow_rays` is on, if it offers a choice
    /// (`render --visibility`; None: BVH shadow rays only).
    pub visibility: Option<&'static VisibilityModes>,
    /// True for the ground truth of the frame's own VPLs (the comparison's truth).
    pub truth_of_vpls: bool,
    /// True when it lights the scene from the RSM itself (one bounce: Virtual Area Lights
    /// cluster RSM texels), so it cannot follow `vpl.bounces > 1`: the CLI refuses, the GUI
    /// says so.
    pub one_bounce: bool,
    /// True when its shading follows `gi.brdf` (GGX included); the others refuse
    /// `gi.brdf = ggx` (CLI in one line, GUI below the BRDF combo).
    pub glossy: bool,
    /// Checks its settings; the message names the field.
    pub validate: fn(&RenderSettings) -> Result<(), String>,
    /// Its numeric settings as declared (`base::field`): per settings section, the specs
    /// that drive validation, the GUI's sliders and `--set` (the registry test sets each
    /// to its ends and beyond through `--set`'s path).
    pub fields: fn() -> Vec<FieldSection>,
    /// Sets one of its settings out of range and returns that field's name (the registry test
    /// checks that `validate` refuses it by name); None for a method without settings.
    pub invalid_example: Option<fn(&mut RenderSettings) -> &'static str>,
    /// Its settings in the GUI's Global illumination section.
    pub ui: fn(&mut dyn crate::base::settings_ui::SettingsUi, MethodId, &mut RenderSettings),
    /// The tests (by name, `file::test`) that check it against a CPU reference or for
    /// convergence; the registry test checks that each exists.
    pub tests: &'static [&'static str],
    /// Its quality knob for `results`' equal-time sweep (per-frame methods).
    pub sweep: Option<&'static Sweep>,
    /// What its image estimates under these settings, against the ground truth of the same
    /// VPLs (the bias contract, issue 37: `tests/methods.rs` holds every per-frame method to
    /// it on every built-in scene; `methods` lists it).
    pub bias: fn(&RenderSettings) -> Bias,
    /// For a method biased at its defaults: changes the settings to its unbiased
    /// configuration, if it has one (RTSLC's cut per pixel, Lightcuts' threshold 0, light
    /// culling without the filter); the contract checks that `bias` then says `Unbiased` and
    /// that the N-frame means converge to the truth.
    pub unbiased: Option<Unbiased>,
}

/// A method's visibility modes (`MethodInfo::visibility`): how its lights are shadowed while
/// `gi.shadow_rays` is on. `render --visibility` lists every method's modes (and `none`, the
/// shadow rays off) and refuses a mode the method does not offer.
pub struct VisibilityModes {
    /// (CLI name, what it does), its default first.
    pub modes: &'static [(&'static str, &'static str)],
    /// Sets the mode named `name` (one of `modes`) in the settings.
    pub set: fn(&mut RenderSettings, &str),
}

/// Every visibility mode of the registry, each once (`none` and `rays` first).
pub fn visibility_names() -> Vec<&'static str> {
    let mut v = vec!["none", "rays"];
    for m in REGISTRY {
        for (name, _) in m.visibility.map_or(&[][..], |vm| vm.modes) {
            if !v.contains(name) {
                v.push(name);
            }
        }
    }
    v
}

/// Whether `method` offers visibility mode `name` (`none` and, for a method without a
/// choice, `rays` always); the error says which it offers.
pub fn offers_visibility(method: MethodId, name: &str) -> Result<(), String> {
    let modes = method.info().visibility;
    let offered: Vec<&str> = modes.map_or(vec!["rays"], |vm| vm.modes.iter().map(|(n, _)| *n).collect());
    if name == "none" || offered.contains(&name) {
        return Ok(());
    }
    Err(format!(
        "{method} offers visibility {} (and none), not {name}",
        offered.join(", ")
    ))
}

/// Sets visibility mode `name` in the settings of every method that offers it (`none`: the
/// shadow rays off; otherwise on).
pub fn set_visibility(s: &mut RenderSettings, name: &str) {
    s.gi.shadow_rays = name != "none";
    for m in REGISTRY {
        if let Some(vm) = m.visibility
            && vm.modes.iter().any(|(n, _)| *n == name)
        {
            (vm.set)(s, name);
        }
    }
}

/// Declared numeric settings of one settings section (`MethodInfo::fields`).
pub struct FieldSection {
    /// The section's TOML path (`methods.lightcuts`, `sampling.interleave`, `gi`).
    pub section: String,
    pub specs: Vec<crate::base::field::Spec>,
    /// The section's default table when the section is the method's own (the test checks
    /// that every number in it is declared); None for a shared or nested one.
    pub table: Option<toml::Table>,
}

impl FieldSection {
    /// The section `section` of `fields`, with its default table when `own`.
    pub fn of<T: serde::Serialize + Default>(
        section: &str,
        fields: &[crate::base::field::Field<T>],
        own: bool,
    ) -> Self {
        Self {
            section: section.to_string(),
            specs: crate::base::field::specs(fields),
            table: if own {
                toml::Table::try_from(T::default()).ok()
            } else {
                None
            },
        }
    }
}

/// A method without settings of its own.
pub fn no_fields() -> Vec<FieldSection> {
    Vec::new()
}

/// A biased method's unbiased configuration (`MethodInfo::unbiased`).
pub struct Unbiased {
    /// The settings it changes, as a user would write them (`methods`, docs).
    pub how: &'static str,
    /// Changes a copy of the settings to it.
    pub apply: fn(&mut RenderSettings),
}

/// What a method's image estimates, measured against the ground truth of the frame's own
/// VPLs by the means of the GI (indirect light) images: the contract `tests/methods.rs`
/// checks on every built-in scene (`scene::test_scenes`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bias {
    /// Its expected image is the ground truth of the same VPLs: the mean of N frames
    /// converges to it, with an error that falls as 1/sqrt(N) (zero for a deterministic
    /// method that computes it exactly, Lightcuts at threshold 0).
    Unbiased,
    /// Its expected image differs from that truth by design: the mean of N frames' GI stays
    /// within `tolerance` (relative, of the truth's GI mean) of the truth's mean, on every
    /// built-in scene; `reason` names what biases it (substitute sampling, clustering,
    /// imperfect shadow maps, clamped ranges, ...).
    Biased { tolerance: f64, reason: &'static str },
    /// Not an estimate of the ground truth of the frame's VPLs: the truth itself, the
    /// converged reference over every RSM texel, direct light only.
    NotCompared,
}

impl Bias {
    /// The relative tolerance of an N-frame mean's GI against the truth's (0 for unbiased
    /// estimates, whose allowance is statistical; None where not compared).
    pub fn tolerance(self) -> Option<f64> {
        match self {
            Bias::Unbiased => Some(0.0),
            Bias::Biased { tolerance, .. } => Some(tolerance),
            Bias::NotCompared => None,
        }
    }
    /// One line for tables: "unbiased", "biased (within 10%: clustering)", "not compared".
    pub fn describe(self) -> String {
        match self {
            Bias::Unbiased => "unbiased".into(),
            Bias::Biased { tolerance, reason } => {
                format!("biased, within {:.0}%: {reason}", 100.0 * tolerance)
            }
            Bias::NotCompared => "not compared".into(),
        }
    }
}

/// What a method's `record` may use: the frame's resources and where to write.
pub struct FrameCx<'a> {
    /// Which method of the module runs (the tree samplers share one instance).
    pub method: MethodId,
    pub device: &'a wgpu::Device,
    /// The adapter's kind (a CPU adapter such as lavapipe has limits a GPU has not).
    pub adapter_type: wgpu::DeviceType,
    pub queue: &'a wgpu::Queue,
    pub errors: &'a ErrorSink,
    pub timer: &'a mut GpuTimer,
    pub settings: &'a RenderSettings,
    pub scene: &'a SceneGpu,
    /// Scene bounding radius (metres, > 0).
    pub scene_radius: f32,
    pub targets: &'a FrameTargets,
    /// The frame's camera uniform (`GpuCamera`, common/camera.wgsl).
    pub camera: &'a wgpu::Buffer,
    pub vpl_buffers: &'a VplBuffers,
    pub vpl_frame: &'a VplFrame,
    /// The frame's lights (one RSM layer each).
    pub lights: &'a [crate::scene::DirectionalLight],
    /// The BRDF of this frame (`gi.brdf`, Lambert where the frame's method refuses GGX).
    pub brdf: crate::settings::Brdf,
    /// The camera's position (glossy shading's view direction).
    pub eye: glam::Vec3,
    /// The VPL generation's parameter buffer (the reference reads the RSM pyramids with it).
    pub vpl_params: &'a wgpu::Buffer,
    pub tree: &'a TreeBuffers,
    /// The GI accumulation buffer to write (rgb sum per frame pixel, `vec4<f32>`).
    pub gi_accum: &'a wgpu::Buffer,
    pub size: (u32, u32),
    /// Fingerprint of everything its image depends on: a progressive or accumulating method
    /// restarts when it changes.
    pub key: u64,
    /// Frames rendered so far (the samplers' seeds).
    pub frame_index: u64,
    /// The pinned pixel whose story the method records (if it tells one; diagnostic frames
    /// only).
    pub trace_pixel: Option<(u32, u32)>,
    /// A diagnostic frame (untimed): record counters, per-pixel statistics and the story.
    /// Otherwise a timed frame: record only the work the method's image needs, no
    /// diagnostics and no readbacks (`renderer::FrameMode`).
    pub diagnostics: bool,
    /// The method views drawn for this frame (or kept for drawing after it): a view whose
    /// data needs work in the frame checks for itself here.
    pub views: &'a [MethodView],
    /// Light 0's reflective shadow map raster (None without lights): the VAL clustering
    /// reads layer 0 of `targets.shadow` through it.
    pub rsm: Option<crate::gpu::gpu_data::RsmRaster>,
}

/// What a method's view drawing may use.
pub struct ViewCx<'a> {
    pub device: &'a wgpu::Device,
    pub queue: &'a wgpu::Queue,
    pub timer: &'a mut GpuTimer,
    pub look: &'a ViewLook,
    pub targets: &'a FrameTargets,
    pub tree: &'a TreeBuffers,
    /// The scene (its BVH: views that trace rays).
    pub scene: &'a SceneGpu,
    /// The frame's camera uniform (`GpuCamera`): views that cast camera rays.
    pub camera: &'a wgpu::Buffer,
    /// Destination (`Rgba8Unorm` storage view) of the size [`Method::view_size`] gave.
    pub dst: &'a wgpu::TextureView,
    /// Block outlined in the cut views (set by the UI).
    pub selected_block: Option<u32>,
}

/// A method's GPU instance: pipelines and the state it keeps between frames.
pub trait Method: Any {
    /// Records this frame's passes writing `cx.gi_accum`; returns the composite's scale of
    /// the accumulation (1 / frames summed; 0 = no GI yet).
    fn record(&mut self, cx: &mut FrameCx<'_>, enc: &mut wgpu::CommandEncoder) -> f32;
    /// Frames averaged in its current image (per-frame methods; None: it does not average).
    fn frames_averaged(&self) -> Option<u32> {
        None
    }
    /// Progress towards convergence (progressive methods).
    fn progress(&self) -> Option<GiProgress> {
        None
    }
    /// Forget the state of earlier frames (the VPL buffers were recreated).
    fn reset(&mut self) {}
    /// After the frame's submission (starts non-blocking readbacks).
    fn after_submit(&mut self) {}
    /// The size of one of its views (`MethodInfo::views`), None when it has nothing to show.
    fn view_size(&self, _view: MethodView, _frame: (u32, u32)) -> Option<(u32, u32)> {
        None
    }
    /// Draws one of its views into `cx.dst`.
    fn record_view(&mut self, _view: MethodView, _cx: &mut ViewCx<'_>, _enc: &mut wgpu::CommandEncoder) {}
    /// The linear data behind one of its views (EXR export): None when it has none yet.
    fn read_view(&self, _ctx: &GpuContext, _view: MethodView) -> Result<Option<ImageF32>, GpuError> {
        Ok(None)
    }
    /// The colour scale of one of its views (None: no legend).
    fn legend(&self, _view: MethodView, _tree_levels: u32) -> Option<Legend> {
        None
    }
    /// The pinned pixel's story in the last (diagnostic) frame, None when it tells none: a
    /// sampling method's samples (`Story::Samples`: blocks, blend weights, each sample's path,
    /// stop, point, shadow ray and contribution; `MethodInfo::story` set) or a cut-based
    /// method's cuts (`Story::Cuts`: a table and cuts drawn over the tree's levels).
    fn read_story(&self, _ctx: &GpuContext) -> Result<Option<Story>, GpuError> {
        Ok(None)
    }
    /// Its overlay for the pinned frame pixel (x, y) whose surface point is `position`: a
    /// table and world-space primitives (the story window shows them when the method tells
    /// no sample or cut story). None: it has none.
    fn read_overlay(
        &self,
        _ctx: &GpuContext,
        _pixel: (u32, u32),
        _position: glam::Vec3,
    ) -> Result<Option<overlay::MethodOverlay>, GpuError> {
        Ok(None)
    }
    /// Its rows in the pixel-values window at frame pixel (x, y) of a `frame`-sized image.
    fn pixel_rows(
        &self,
        _ctx: &GpuContext,
        _x: u32,
        _y: u32,
        _frame: (u32, u32),
    ) -> Result<Vec<(&'static str, [f32; 4])>, GpuError> {
        Ok(Vec::new())
    }
    /// One line of its statistics for the GUI (non-blocking; None before there are any).
    fn status(&mut self) -> Option<String> {
        None
    }
    /// Its named statistics of the last diagnostic frame read back (`render` prints them and
    /// writes them to metrics.json as `method_stats`; call after the GPU is idle). Empty when
    /// it keeps none.
    fn stats(&mut self) -> Vec<(&'static str, f64)> {
        Vec::new()
    }
    /// The counters of its light-tree traversals in a recent diagnostic frame (non-blocking:
    /// None until one is read back; the GUI's statistics, the figures' steps, `render`'s
    /// summary). None for a method that does not walk the tree sample by sample.
    fn traversal_stats(&mut self) -> Option<crate::base::traversal::TraversalStats> {
        None
    }
    /// Per pixel of its last diagnostic frame (row-major at its GI resolution): traversal
    /// steps per traversal and whether the pixel had no similar cut (fell back). None for a
    /// method that keeps no such counts.
    fn read_traversal_pixels(
        &self,
        _ctx: &GpuContext,
    ) -> Result<Option<crate::base::traversal::TraversalPixels>, GpuError> {
        Ok(None)
    }
    /// The light cut of the block under `texel` of its view `view` (a view whose texels are
    /// the method's cut blocks: clicking one lists its cut). None where `view` shows no blocks.
    fn pick_block(
        &self,
        _ctx: &GpuContext,
        _view: MethodView,
        _texel: (u32, u32),
    ) -> Result<Option<crate::base::story::BlockCut>, GpuError> {
        Ok(None)
    }
}

#[cfg(test)]
mod tests {
    /// Every method's structs shared with WGSL match naga's layout (each module lists its
    /// own, `Module::wgsl_twins`; the shared passes' are `gpu_data::TWINS`).
    #[test]
    fn every_methods_gpu_structs_match_their_wgsl() {
        let mut n = 0;
        for m in super::modules() {
            for t in m.wgsl_twins {
                assert!(
                    t.file.starts_with(&format!("methods/{}/", m.name)),
                    "{}: {} is not in its folder",
                    m.name,
                    t.file
                );
                if let Err(e) = crate::gpu::gpu_data::check_twin(t) {
                    panic!("{}: {e}", m.name);
                }
                n += 1;
            }
        }
        assert!(n >= 13, "only {n} method structs checked");
    }

    /// Every method's compute kernels have the standard workgroup sizes or ones it declares.
    #[test]
    fn every_methods_workgroup_sizes_match_their_wgsl() {
        for m in super::modules() {
            if let Err(e) = crate::gpu::passes::check_workgroup_sizes(m.entry_shaders, m.own_workgroups) {
                panic!("{}: {e}", m.name);
            }
        }
    }
}

//! `render`'s command line: [`RenderArgs`], the tree samplers' flags ([`SamplingArgs`]), the
//! value enums of the flags, and how they become settings.

use super::*;

/// `--method NAME`: a registered GI method by its CLI name (`crate::methods::REGISTRY`).
pub fn parse_method(name: &str) -> Result<MethodId, String> {
    MethodId::parse(name)
}

/// `--method`'s help: every registered method by its CLI name and label (the registry's
/// order), so that a new method is listed without editing this text.
pub fn method_help() -> String {
    let names: Vec<String> = crate::methods::REGISTRY
        .iter()
        .map(|m| format!("{} ({})", m.id.cli(), m.short))
        .collect();
    format!(
        "GI method by its CLI name: {}. Without it: the settings file's method (default slc); \
         `lightcut-workbench methods` describes them",
        names.join(", ")
    )
}

/// The temporal stage for `--temporal`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TemporalArg {
    /// The method's estimate as it is.
    Off,
    /// Temporal reprojection and an exponential history.
    Reproject,
    /// Reprojection, history, variance and the à-trous filter (SVGF, Schied et al. 2017).
    Svgf,
}

/// The light tree for `--tree`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TreeArg {
    /// The thesis's perfect binary tree over the sorted VPLs (padded to a power of two).
    Perfect,
    /// The SST paper's binary radix tree (LBVH, Karras 2012) over the same keys.
    Lbvh,
}

/// The BRDF for `--brdf`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BrdfArg {
    /// base colour / pi (default).
    Lambert,
    /// Cook-Torrance GGX over glTF's metallic and roughness (factors x textures).
    Ggx,
}

/// Settings flags of the frame and the methods (override `--settings`).
#[derive(clap::Args, Debug, Clone, Default)]
pub struct SamplingArgs {
    /// The methods' own flags (`--cut-size`, `--block`, ...: `MethodFlag`s of the registry).
    #[command(flatten)]
    pub method_flags: crate::cli::method_flags::MethodFlagArgs,
    /// No shadow rays for the ground truth and the tree samplers (every VPL / sample visible).
    #[arg(long)]
    pub no_shadow_rays: bool,
    /// How the method shadows its lights: `none` (every VPL visible, the unshadowed estimate;
    /// the same as `--no-shadow-rays`), `rays` (BVH shadow rays: the only mode of a method
    /// without a choice) or one of the method's own modes (`methods` lists each method's:
    /// imperfect shadow maps for light culling, the tree samplers and the VALs; the VALs' PCSS
    /// lookup and disk rays). A mode the method does not offer is refused.
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(crate::methods::visibility_names()))]
    pub visibility: Option<String>,
    /// The older name of `--visibility` for the VAL methods.
    #[arg(long, hide = true, value_parser = clap::builder::PossibleValuesParser::new(crate::methods::visibility_names()))]
    pub val_visibility: Option<String>,
    /// The temporal stage after a per-frame method: `off`, `reproject` (motion vectors,
    /// history rejection, exponential history) or `svgf` (also the variance-guided à-trous
    /// filter). Its parameters: `--set temporal.<field>=..` (docs/temporal.md).
    #[arg(long, value_enum)]
    pub temporal: Option<TemporalArg>,
    /// The light tree the tree samplers (SST, SLC, RTSLC) and Lightcuts traverse: `perfect`
    /// (the thesis) or `lbvh` (the SST paper's radix tree). Lightcut Interpolation and the
    /// light-culling tree need the perfect tree and refuse `lbvh`.
    #[arg(long, value_enum)]
    pub tree: Option<TreeArg>,
    /// Diffuse bounces of indirect light: 1 = the RSM's VPLs (the thesis), N (2..=8) adds
    /// VPLs at bounces 2..=N from light paths traced through the BVH, each bounce a
    /// 1/N share of the VPL budget (`vpl.bounces`). The VAL methods refuse N > 1.
    #[arg(long)]
    pub bounces: Option<u32>,
    /// Light paths without Russian roulette: every path runs to the last bounce, its flux
    /// x albedo per bounce (`vpl.roulette = false`).
    #[arg(long)]
    pub no_roulette: bool,
    /// The BRDF of every shading point: `lambert` (default) or `ggx` (Cook-Torrance GGX over
    /// glTF's metallic-roughness factors and textures; `gi.brdf`). Methods that shade with Lambert only
    /// refuse `ggx`.
    #[arg(long, value_enum)]
    pub brdf: Option<BrdfArg>,
    /// Least normal similarity of a usable SST node.
    #[arg(long)]
    pub v_min: Option<f32>,
    /// Bound on sigma_z (metres) of a usable SST node.
    #[arg(long)]
    pub sigma_max: Option<f32>,
    /// Similarity S: least normal dot product.
    #[arg(long)]
    pub n_min: Option<f32>,
    /// Similarity S: largest distance, as a fraction of the scene's bounding radius.
    #[arg(long)]
    pub d_max: Option<f32>,
    /// Average this many independent frames of the tree sampler (new random numbers each).
    #[arg(long, default_value_t = 1)]
    pub frames: u32,
    /// Also compute the ground truth of the same VPLs and write ground_truth_indirect.exr
    /// and the RMSE / SSIM of the method against it into metrics.json.
    #[arg(long)]
    pub compare_gt: bool,
}

impl SamplingArgs {
    /// `--visibility` (or its older name `--val-visibility`; not both).
    fn visibility_mode(&self) -> anyhow::Result<Option<&str>> {
        match (self.visibility.as_deref(), self.val_visibility.as_deref()) {
            (Some(_), Some(_)) => Err(anyhow!(
                "--val-visibility is the older name of --visibility; give one"
            )),
            (v, w) => Ok(v.or(w)),
        }
    }

    /// `--visibility ism` with a method that has no imperfect shadow maps is refused (it
    /// would trace rays without saying so).
    pub fn check_visibility(&self, methods: &[crate::methods::MethodId]) -> anyhow::Result<()> {
        // `--tree lbvh` with a method that needs the perfect tree is refused (it would run
        // on the perfect tree without saying so).
        if self.tree == Some(TreeArg::Lbvh)
            && let Some(msg) = methods
                .iter()
                .find_map(|m| m.refuses_tree(crate::settings::TreeKind::Lbvh))
        {
            return Err(anyhow!("--{msg}"));
        }
        if let Some(v) = self.visibility_mode()? {
            for &m in methods {
                crate::methods::offers_visibility(m, v).map_err(|e| anyhow!("--visibility {v}: {e}"))?;
            }
        }
        Ok(())
    }

    pub fn apply(&self, s: &mut crate::settings::RenderSettings) -> anyhow::Result<()> {
        self.method_flags.apply(s)?;
        if self.no_shadow_rays {
            s.gi.shadow_rays = false;
        }
        if let Ok(Some(v)) = self.visibility_mode() {
            crate::methods::set_visibility(s, v);
        }
        if let Some(t) = self.temporal {
            use crate::settings::TemporalMode;
            s.temporal.mode = match t {
                TemporalArg::Off => TemporalMode::Off,
                TemporalArg::Reproject => TemporalMode::Reproject,
                TemporalArg::Svgf => TemporalMode::Svgf,
            };
        }
        if let Some(b) = self.bounces {
            s.vpl.bounces = b;
        }
        if self.no_roulette {
            s.vpl.roulette = false;
        }
        if let Some(b) = self.brdf {
            s.gi.brdf = match b {
                BrdfArg::Lambert => crate::settings::Brdf::Lambert,
                BrdfArg::Ggx => crate::settings::Brdf::Ggx,
            };
        }
        if let Some(t) = self.tree {
            use crate::settings::TreeKind;
            s.tree.kind = match t {
                TreeArg::Perfect => TreeKind::Perfect,
                TreeArg::Lbvh => TreeKind::Lbvh,
            };
        }
        if let Some(v) = self.v_min {
            s.tree.v_min = v;
        }
        if let Some(v) = self.sigma_max {
            s.tree.sigma_max = v;
        }
        if let Some(v) = self.n_min {
            s.vpl.n_min = v;
        }
        if let Some(v) = self.d_max {
            s.vpl.d_max = v;
        }
        s.frame.accumulate = self.frames > 1;
        Ok(())
    }
}

/// Groups of files `render` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Output {
    /// Everything below.
    All,
    /// final.exr (direct + indirect).
    Final,
    /// direct.exr.
    Direct,
    /// indirect.exr (GI only).
    Indirect,
    /// position/normal/albedo/depth.exr.
    Gbuffer,
    /// Tonemapped PNGs of the views.
    Png,
}

#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    /// `default` or another built-in scene (`window-box`, `corridor`, `glossy-thin`), a
    /// .gltf/.glb file, or a preset .toml.
    #[arg(long, default_value = "default")]
    pub scene: String,
    #[arg(long, default_value_t = 640)]
    pub width: u32,
    #[arg(long, default_value_t = 360)]
    pub height: u32,
    /// Output folder (created if missing).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Camera name from the scene (default: the preset's, else the first).
    #[arg(long)]
    pub camera: Option<String>,
    /// Frames to render before reading timings (the first frames include pipeline warm-up).
    #[arg(long, default_value_t = 3)]
    pub timing_frames: u32,
    #[arg(long, value_parser = parse_method, help = method_help())]
    pub method: Option<MethodId>,
    /// What to write (comma-separated).
    #[arg(long, value_enum, value_delimiter = ',', default_value = "all")]
    pub output: Vec<Output>,
    /// Number of VPLs (overrides the settings file).
    #[arg(long)]
    pub vpls: Option<u32>,
    /// Randomisation seed of the VPLs.
    #[arg(long)]
    pub seed: Option<u32>,
    /// Lower bound of the VPL distance in 1/d^2 (metres).
    #[arg(long)]
    pub epsilon: Option<f32>,
    /// Samples per pixel of the converged reference.
    #[arg(long)]
    pub samples: Option<u32>,
    /// Render a sequence along a smooth camera path (Catmull-Rom, constant speed) through the
    /// scene's bookmarks: all in order, or the comma-separated names given. Writes
    /// sequence.csv (per frame: camera, sun, GPU times, and with --compare-gt the raw and
    /// temporally filtered GI's RMSE / SSIM / flicker against each frame's ground truth),
    /// frames/NNNN.png, and the last frame's images.
    #[arg(long, value_name = "NAMES", num_args = 0..=1, default_missing_value = "")]
    pub camera_path: Option<String>,
    /// Turn the sun's azimuth by this many degrees over the sequence (with or without
    /// --camera-path).
    #[arg(long, value_name = "DEGREES", allow_negative_numbers = true)]
    pub sun_sweep: Option<f32>,
    /// Frames of the --camera-path / --sun-sweep sequence (default 60).
    #[arg(long)]
    pub path_frames: Option<u32>,
    #[command(flatten)]
    pub settings: SettingsArgs,
    #[command(flatten)]
    pub sampling: SamplingArgs,
    /// The options given on the command line (by clap id; `main` fills it): a capture record
    /// read with `--settings` supplies the others.
    #[arg(skip)]
    pub explicit: Vec<String>,
}

impl RenderArgs {
    /// With `--settings <capture record>`: the record's scene, size, frame counts and camera
    /// where the command line does not name them (the settings themselves come from the file
    /// as from any settings file). Returns the arguments and the record's camera.
    pub fn with_record(&self) -> anyhow::Result<(RenderArgs, Option<crate::capture::Capture>)> {
        let mut a = self.clone();
        let Some(path) = &self.settings.settings else {
            return Ok((a, None));
        };
        let text = std::fs::read_to_string(path)
            .map_err(|e| anyhow!("cannot read settings file {}: {e}", path.display()))?;
        let (Some(mut c), _) =
            crate::capture::split(&text).map_err(|e| anyhow!("bad settings file {}: {e}", path.display()))?
        else {
            return Ok((a, None));
        };
        let given = |id: &str| self.explicit.iter().any(|e| e == id);
        let mut camera = None;
        if !given("scene") && !c.scene.is_empty() {
            a.scene = c.scene.clone();
        }
        if !given("width") && c.width > 0 {
            a.width = c.width;
        }
        if !given("height") && c.height > 0 {
            a.height = c.height;
        }
        if !given("frames") && c.frames > 0 {
            a.sampling.frames = c.frames;
        }
        if !given("timing_frames") && c.timing_frames > 0 {
            a.timing_frames = c.timing_frames;
        }
        if !given("camera") && !c.camera.name.is_empty() {
            camera = Some(c.camera.clone());
        }
        // A sequence's record: the same sequence again.
        if !given("camera_path") && c.camera_path.is_some() {
            a.camera_path = c.camera_path.clone();
        }
        if !given("sun_sweep") && c.sun_sweep.is_some() {
            a.sun_sweep = c.sun_sweep;
        }
        if !given("path_frames") && c.path_frames.is_some() {
            a.path_frames = c.path_frames;
        }
        if given("camera") || c.camera.name.is_empty() {
            c.camera = Default::default();
        }
        println!(
            "capture record {} ({} at {}): scene {}, camera '{}', {}x{}, {} frame(s) after {} timed",
            path.display(),
            c.what,
            c.commit,
            a.scene,
            camera
                .as_ref()
                .map_or(a.camera.as_deref().unwrap_or("default"), |c| c.name.as_str()),
            a.width,
            a.height,
            a.sampling.frames,
            a.timing_frames
        );
        if c.commit != crate::capture::COMMIT {
            println!(
                "  note: recorded by commit {}, this binary is {} (bit-for-bit only with the same build and adapter)",
                c.commit,
                crate::capture::COMMIT
            );
        }
        Ok((a, Some(c)))
    }
}

//! Renderer settings: one serde struct per pass, documented field by field. The same structs
//! are edited by the UI, saved with the app state, read from presets and set by CLI flags.

use serde::{Deserialize, Serialize};

/// All settings of the frame.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RenderSettings {
    pub shadow: ShadowSettings,
    pub vpl: VplSettings,
    pub gi: GiSettings,
    pub tree: TreeSettings,
    pub sampling: SamplingSettings,
    pub display: DisplaySettings,
    pub textures: TextureSettings,
}

/// Directional shadow map (one square layer per light, covering the scene bounds).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ShadowSettings {
    /// Shadow-map resolution in texels per side. Raising it sharpens shadows and resolves thin
    /// occluders (blinds, chains) at quadratic memory/raster cost; lowering it blurs and loses
    /// thin geometry. Thesis default 512.
    pub resolution: u32,
    /// Constant depth bias in texels of light-space depth. Raise if surfaces shadow themselves
    /// (acne stripes); lower if shadows detach from their casters (peter-panning).
    pub depth_bias: f32,
    /// Offset of the lookup point along the surface normal, in texels, scaled by sin(theta)
    /// of the light's incidence. Raise against acne at grazing light; lower if thin occluders
    /// leak light.
    pub normal_offset: f32,
    /// Slope-scaled depth bias: tan(theta) x (PCF radius + 1/2) texels times this factor
    /// (receiver-plane bound for the PCF taps). Raise if tilted surfaces shadow themselves in
    /// stripes; lower if contact shadows detach.
    pub slope_bias: f32,
    /// Percentage-closer filter radius in texels: 0 = one hard tap, 1 = 3x3, 2 = 5x5. Raising it
    /// softens (and antialiases) shadow edges at more cost per pixel.
    pub pcf_radius: u32,
}

impl Default for ShadowSettings {
    fn default() -> Self {
        Self {
            resolution: 512,
            depth_bias: 1.0,
            normal_offset: 1.0,
            slope_bias: 1.0,
            pcf_radius: 1,
        }
    }
}

/// How VPLs are chosen among the reflective-shadow-map texels (potential VPLs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum VplMode {
    /// Bidirectional RSM (Ritschel et al. 2011; thesis 4.1): texels are chosen in proportion to
    /// their estimated contribution to the image (filtered BRSM importance), mixed with their
    /// flux by `flux_mix`.
    #[default]
    Brsm,
    /// Plain RSM (Dachsbacher & Stamminger 2005): every texel equally likely.
    Rsm,
}

impl VplMode {
    pub const ALL: [VplMode; 2] = [VplMode::Brsm, VplMode::Rsm];
    pub fn name(self) -> &'static str {
        match self {
            VplMode::Brsm => "BRSM",
            VplMode::Rsm => "RSM (uniform)",
        }
    }
}

/// VPL generation (thesis 4.1 and chapter 6): reflective shadow map, BRSM importance, its
/// edge-aware filter, the PDF pyramid and hierarchical warping of a Hammersley set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VplSettings {
    /// VPLs per frame over all lights (split by relative brightness). More VPLs: less
    /// structured noise, more cost for every later stage. Thesis: 4096.
    pub count: u32,
    pub mode: VplMode,
    /// G-buffer samples per RSM texel for the BRSM importance. More: a less noisy PDF.
    /// Thesis: 8-16.
    pub samples_per_texel: u32,
    /// Scale of the 1/r^2 radius distribution of the importance sample points around a texel,
    /// as a fraction of the scene's bounding radius (radius = r x scale x scene radius, r with
    /// density min(1, 1/r^2) / 2). Larger reaches farther surfaces; smaller concentrates on
    /// the texel's surroundings.
    pub sample_radius: f32,
    /// Radius of the edge-aware Gaussian filter of the importance, in texels (0 = off).
    pub filter_radius: u32,
    /// Similarity S (thesis eq. 5.3): two texels are similar if their normals' dot product
    /// exceeds `n_min` ...
    pub n_min: f32,
    /// ... and their distance is below `d_max` (a fraction of the scene's bounding radius).
    /// Lowering `n_min` or raising `d_max` blurs across edges.
    pub d_max: f32,
    /// Fraction of the selection PDF that follows the texels' flux instead of the importance.
    /// Above 0 every texel with flux can be chosen, which keeps the VPL set an unbiased
    /// estimate of the reflected light; 0 is the thesis's pure BRSM.
    pub flux_mix: f32,
    /// Randomisation seed of the Hammersley set; with `animate` the frame index is added.
    pub seed: u32,
    /// New VPLs every frame (a fresh random rotation of the Hammersley set).
    pub animate: bool,
}

impl Default for VplSettings {
    fn default() -> Self {
        Self {
            count: 4096,
            mode: VplMode::Brsm,
            samples_per_texel: 8,
            sample_radius: 0.1,
            filter_radius: 2,
            n_min: 0.9,
            d_max: 0.05,
            flux_mix: 0.1,
            seed: 1,
            animate: false,
        }
    }
}

/// Which indirect (one-bounce) light the frame computes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum GiMethod {
    /// Direct light only.
    #[default]
    Off,
    /// The thesis's ground truth: every VPL of the frame at every pixel with a shadow ray,
    /// accumulated over frames in VPL batches (progressive; restarts when the view changes).
    GroundTruth,
    /// Converged reference: every RSM texel as a VPL, per-pixel Monte Carlo over the RSM
    /// pyramids, accumulated over frames until `reference_samples` per pixel.
    Reference,
    /// The thesis's method (Stochastic Light Cut Exploration): shallow per-block cuts,
    /// stochastic cut blending, traversal from each cut node that stops at usable SST nodes,
    /// substitute-distribution samples.
    Slc,
    /// Baseline, Tatzgern et al. 2020: `cut_size` traversals per pixel from the root, each
    /// stopping at a usable SST node.
    Sst,
    /// Baseline, Lin and Yuksel 2020: the same cuts and blending, traversal always down to a
    /// leaf VPL (no substitutes).
    Rtslc,
}

impl GiMethod {
    pub const ALL: [GiMethod; 6] = [
        GiMethod::Off,
        GiMethod::Slc,
        GiMethod::Sst,
        GiMethod::Rtslc,
        GiMethod::GroundTruth,
        GiMethod::Reference,
    ];
    pub fn name(self) -> &'static str {
        match self {
            GiMethod::Off => "off (direct only)",
            GiMethod::GroundTruth => "ground truth (all VPLs)",
            GiMethod::Reference => "converged reference (all texels)",
            GiMethod::Slc => "SLC (thesis)",
            GiMethod::Sst => "SST (baseline)",
            GiMethod::Rtslc => "RTSLC (baseline)",
        }
    }
    /// The tree samplers (one estimate per frame), as opposed to the progressive references.
    pub fn samples_tree(self) -> bool {
        matches!(self, GiMethod::Slc | GiMethod::Sst | GiMethod::Rtslc)
    }
}

/// Shading of VPLs (shared by every GI method and the references).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GiSettings {
    pub method: GiMethod,
    /// Shadow rays the ground truth may trace per frame in the GUI (it continues next frame).
    /// Higher finishes sooner but makes frames slower.
    pub rays_per_frame: u32,
    /// Samples per pixel the converged reference accumulates before it stops.
    pub reference_samples: u32,
    /// Samples per pixel the reference adds per frame (GUI; the CLI uses larger steps).
    pub reference_spp_per_frame: u32,
    /// Share of the reference's texel PDF that follows flux rather than BRSM importance.
    /// Must be above 0 (every texel that can contribute stays selectable, so the reference
    /// is unbiased); higher is more robust to a poor importance estimate, noisier otherwise.
    pub reference_flux_mix: f32,
    /// Lower bound of the VPL-to-surface distance (metres) in the 1/d^2 term:
    /// 1 / max(d^2, epsilon^2) (the SST paper bounds d from below the same way). It removes
    /// the singularity next to VPLs at the price of darkening corners, where d < epsilon.
    /// Raise it against bright VPL splotches; lower it for accuracy in corners.
    pub distance_epsilon: f32,
    /// Offset of shadow-ray end points along their surfaces' normals (metres).
    pub ray_offset: f32,
    /// Shadow rays of the VPL methods (ground truth, SLC, SST, RTSLC). Off treats every VPL
    /// and cluster sample as visible: the unshadowed estimate, to see what the shadow rays
    /// remove (light through walls) and what they cost (the GI pass without them is the
    /// cost of traversal and evaluation alone). The converged reference always traces.
    pub shadow_rays: bool,
}

impl Default for GiSettings {
    fn default() -> Self {
        Self {
            method: GiMethod::Off,
            rays_per_frame: 1 << 20,
            reference_samples: 4096,
            reference_spp_per_frame: 1,
            reference_flux_mix: 0.25,
            distance_epsilon: 0.05,
            ray_offset: 1e-3,
            shadow_rays: true,
        }
    }
}

/// The Stochastic Substitute Tree (SST paper 3.2, thesis 4.2): when a node's substitute
/// distribution is flat enough to be sampled instead of descending further (eq. 3 of the SST
/// paper). Changing these re-runs only the classify pass, never the build.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TreeSettings {
    /// Least normal similarity v (eq. 4.3, in 0..=1) of a usable node. Higher keeps only
    /// clusters whose VPLs face the same way (deeper traversal, less bias).
    pub v_min: f32,
    /// Bound on the standard deviation along the node's normal (metres) of a usable node
    /// (strict: sigma_z < sigma_max, so 0 turns substitutes off and only leaves are sampled).
    /// Lower keeps only clusters lying on one plane.
    pub sigma_max: f32,
}

impl Default for TreeSettings {
    fn default() -> Self {
        // The thesis's values (chapter 5: "a good balance between quality and speed").
        Self {
            v_min: 0.7,
            sigma_max: 0.3,
        }
    }
}

/// How a pixel picks a cut per slot (thesis 5.1.3, fig. 7.4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum CutBlending {
    /// Algorithm 1: per slot, one of the 4 surrounding blocks' cuts by bilinear weight x S.
    #[default]
    Stochastic,
    /// No blending: the cut of the pixel's own block (if similar, else the fallback).
    Off,
}

impl CutBlending {
    pub const ALL: [CutBlending; 2] = [CutBlending::Stochastic, CutBlending::Off];
    pub fn name(self) -> &'static str {
        match self {
            CutBlending::Stochastic => "stochastic (Algorithm 1)",
            CutBlending::Off => "off (own block)",
        }
    }
}

/// What a pixel does when no surrounding cut is similar (thesis 5.1.4, fig. 7.6).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum CutFallback {
    /// All nodes of tree level floor(log2(cut_size)).
    #[default]
    MockCut,
    /// Blend the dissimilar cuts anyway, by bilinear weight alone.
    Average,
    /// `cut_size` traversals from the root (as SST).
    Root,
    /// Build a cut at the pixel itself (costly).
    Recompute,
}

impl CutFallback {
    pub const ALL: [CutFallback; 4] = [
        CutFallback::MockCut,
        CutFallback::Average,
        CutFallback::Root,
        CutFallback::Recompute,
    ];
    pub fn name(self) -> &'static str {
        match self {
            CutFallback::MockCut => "mock cut",
            CutFallback::Average => "average the cuts",
            CutFallback::Root => "traverse from the root",
            CutFallback::Recompute => "recompute a cut",
        }
    }
}

/// How a traversal step splits its probability between the two children (stage 14).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum ChildProbability {
    /// p_left = w_left / (w_left + w_right), w of eq. 5.5 with the distance to each child's
    /// intensity-weighted mean (the thesis).
    Mean,
    /// RTSLC's default ("MinMax", Lin & Yuksel 2020's public code): the average of the two
    /// normalisations with the closest-point and the farthest-point squared distance to each
    /// child's box (same cosine term). A child holding VPLs close to x keeps at least half its
    /// closest-point share, which bounds the samples' weights (fewer fireflies).
    MinMax,
    /// Ours (the default): 0.8 x the thesis's p_left + 0.2 x the closest-point
    /// normalisation (a "defensive mixture", Hesterberg 1995; `reference::slc::DEFENSIVE`).
    /// Keeps eq. 5.5's choices where the children's means represent them, and a fifth of the
    /// closest-point share where they do not: the perfect binary tree over Morton-sorted VPLs
    /// pairs some VPLs with far partners (Sponza: 10% of the leaf pairs span more than 1.4 m,
    /// the widest 38 m), and eq. 5.5 then gives a VPL next to x the probability of its
    /// cluster's far mean, a firefly when drawn (docs/results.md, *What changed* 5).
    #[default]
    Defensive,
}

impl ChildProbability {
    pub const ALL: [ChildProbability; 3] = [
        ChildProbability::Mean,
        ChildProbability::MinMax,
        ChildProbability::Defensive,
    ];
    pub fn name(self) -> &'static str {
        match self {
            ChildProbability::Mean => "mean position (thesis)",
            ChildProbability::MinMax => "min-max box distance (RTSLC)",
            ChildProbability::Defensive => "mean + 20% closest point (defensive)",
        }
    }
}

/// Sampling the tree (stages 11-16, thesis chapter 5): used by the SLC, SST and RTSLC methods.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SamplingSettings {
    /// k: one shallow light cut per k x k block of GI pixels (1 = a cut per pixel). Larger
    /// blocks cost less and blur the cut choice across edges (blending hides the seams).
    pub block_size: u32,
    /// Nodes per cut = cluster evaluations (shadow rays) per pixel; SST takes this many
    /// traversals from the root.
    pub cut_size: u32,
    /// Leave out of the cuts children whose box lies wholly behind the block centre's
    /// surface (thesis 5.1). Pixels of a block that face differently can then miss light
    /// from those nodes (bias, bounded by the similarity test); off keeps the cuts complete.
    pub cull_behind: bool,
    /// Near-field refinement (ours, not in the thesis; 0 = the thesis's rule): SLC and SST
    /// stop at a usable node only when the shaded point lies at least max(distance epsilon,
    /// `near_field` x the node's box diagonal) from the node's box, and descend otherwise (to
    /// a leaf at most). A substitute distribution stands for its VPLs only seen from afar:
    /// next to it, its samples land off the real surfaces (through thin walls, in front of
    /// the shaded surface) and the 1/d^2 term turns them into fireflies. Higher refines more
    /// (fewer fireflies, more steps). See docs/results.md.
    pub near_field: f32,
    /// Shadow rays of substitute samples (SLC/SST inner nodes, never leaf VPLs) end this far
    /// (m) short of the drawn point, towards the shaded point and at most half way: the SST
    /// paper's "scene size dependent epsilon" (Tatzgern et al. 2020, section 5, Sampling: drawn points
    /// "may be slightly inside geometry"). A Gaussian draw clamped to the box lands behind
    /// walls and under neighbouring surfaces, where the node's real VPLs are not; 0 (only
    /// `gi.ray_offset`, the thesis) left SLC 8.6% dark in the Breakfast Room. Too large leaks
    /// light through walls thinner than it. See docs/results.md.
    pub substitute_offset: f32,
    /// How a traversal step splits its probability between the children (all three
    /// samplers; the cuts are built the same either way).
    pub child_probability: ChildProbability,
    pub blending: CutBlending,
    pub fallback: CutFallback,
    /// Average successive frames while the view, lights and settings stay (progressive);
    /// off shows each frame's estimate alone, as a real-time renderer would.
    pub accumulate: bool,
    /// Render GI at half resolution and upsample it with a joint bilateral filter using S.
    pub half_resolution: bool,
    /// The samplers' random numbers are the same every frame (debugging: a pixel's story
    /// repeats); off, the seed changes per frame (needed to accumulate).
    pub fixed_seed: bool,
}

impl Default for SamplingSettings {
    fn default() -> Self {
        // The thesis's defaults: 8 x 8 blocks, 32 samples per pixel.
        Self {
            block_size: 8,
            cut_size: 32,
            cull_behind: true,
            // Measured on Sponza and Breakfast Room (docs/results.md): 1 removes the
            // substitute fireflies for 3-11% more steps; 0.5 and 2 are within noise of it in
            // error, for fewer / more steps.
            near_field: 1.0,
            // Measured (16-frame means vs the ground truth, docs/results.md): 0.05 m brings
            // SLC from 0.915x to 0.98x in the Breakfast Room; 0.1 m overshoots (light leaks).
            substitute_offset: 0.05,
            child_probability: ChildProbability::Defensive,
            blending: CutBlending::Stochastic,
            fallback: CutFallback::MockCut,
            accumulate: false,
            half_resolution: false,
            fixed_seed: false,
        }
    }
}

/// What the light-tree overlay draws over the camera view.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum TreeOverlay {
    #[default]
    Off,
    /// Each node of the chosen level as its substitute distribution: an ellipse in the node's
    /// plane with semi-axes of 1 and 2 standard deviations.
    Distributions,
    /// Each node of the chosen level as its bounding box.
    Boxes,
}

impl TreeOverlay {
    pub const ALL: [TreeOverlay; 3] = [TreeOverlay::Off, TreeOverlay::Distributions, TreeOverlay::Boxes];
    pub fn name(self) -> &'static str {
        match self {
            TreeOverlay::Off => "off",
            TreeOverlay::Distributions => "distributions",
            TreeOverlay::Boxes => "bounding boxes",
        }
    }
}

/// Colouring of the light-tree overlay.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum TreeColor {
    /// Log-scale false colour of the node's flux relative to the level's mean.
    #[default]
    Intensity,
    /// Green = usable for sampling (v >= v_min, sigma_z < sigma_max), red = not.
    Usable,
    /// A distinct colour per node (to tell neighbours apart).
    Node,
}

impl TreeColor {
    pub const ALL: [TreeColor; 3] = [TreeColor::Intensity, TreeColor::Usable, TreeColor::Node];
    pub fn name(self) -> &'static str {
        match self {
            TreeColor::Intensity => "intensity",
            TreeColor::Usable => "usable flag",
            TreeColor::Node => "node id",
        }
    }
}

/// Tonemapping operator of the display pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Tonemap {
    /// Clamp to [0, 1]: shows linear values faithfully up to 1.
    Clamp,
    /// Reinhard on luminance: keeps hue, compresses highlights gently.
    Reinhard,
    /// ACES filmic fit (Narkowicz 2015): contrasty, saturates highlights.
    #[default]
    Aces,
}

impl Tonemap {
    pub const ALL: [Tonemap; 3] = [Tonemap::Clamp, Tonemap::Reinhard, Tonemap::Aces];
    pub fn gpu_id(self) -> u32 {
        match self {
            Tonemap::Clamp => 0,
            Tonemap::Reinhard => 1,
            Tonemap::Aces => 2,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Tonemap::Clamp => "clamp",
            Tonemap::Reinhard => "Reinhard",
            Tonemap::Aces => "ACES",
        }
    }
}

/// Display of linear radiance (exports to EXR are never affected).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DisplaySettings {
    /// Exposure in EV stops: radiance is multiplied by 2^EV before tonemapping. Raise to
    /// brighten dim (indirect-only) images.
    pub exposure_ev: f32,
    pub tonemap: Tonemap,
    /// Draw the frame's VPLs over the view (in the camera view, or in RSM texel space over
    /// RSM-space views), coloured by flux on a log scale around the mean VPL flux.
    pub vpl_overlay: bool,
    /// Radius of the VPL discs in view pixels (0 = one pixel).
    pub vpl_point_size: u32,
    /// Level shown by the PDF-pyramid view (0 = full resolution).
    pub pyramid_level: u32,
    /// Light-tree overlay over the camera-space views.
    pub tree_overlay: TreeOverlay,
    /// Tree level it draws (0 = the root; clamped to the leaves' level).
    pub tree_level: u32,
    pub tree_color: TreeColor,
    /// Position of the divider in the split comparison view (0 = left edge, 1 = right).
    pub split: f32,
}

impl Default for DisplaySettings {
    fn default() -> Self {
        Self {
            exposure_ev: 0.0,
            tonemap: Tonemap::Aces,
            vpl_overlay: false,
            vpl_point_size: 1,
            pyramid_level: 0,
            tree_overlay: TreeOverlay::Off,
            tree_level: 6,
            tree_color: TreeColor::Intensity,
            split: 0.5,
        }
    }
}

/// Scene texture upload.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TextureSettings {
    /// Base colour textures are resampled to one square size (a texture array layer each), at
    /// most this many texels per side. Raising it sharpens textures and costs memory
    /// (4/3 x 4 B x size^2 per texture); lowering speeds up loading on software devices.
    pub max_size: u32,
    /// Anisotropic filtering of base-colour textures (1 = trilinear only, up to 16). Raising
    /// it keeps floors and walls sharp at grazing view angles; on software rasterisers it is
    /// expensive (lavapipe, Sponza 1280x720: G-buffer 503 ms at 8x, 166 ms at 1x).
    pub anisotropy: u16,
}

impl Default for TextureSettings {
    fn default() -> Self {
        Self {
            max_size: 1024,
            anisotropy: 8,
        }
    }
}

impl RenderSettings {
    /// Checks every value's range; the message names the setting and its valid range.
    pub fn validate(&self) -> Result<(), String> {
        let s = &self.shadow;
        if !(16..=4096).contains(&s.resolution) || !s.resolution.is_power_of_two() {
            return Err(format!(
                "shadow.resolution {} must be a power of two in 16..=4096 (the VPL pyramid halves it)",
                s.resolution
            ));
        }
        if !(0.0..=64.0).contains(&s.depth_bias) {
            return Err(format!(
                "shadow.depth_bias {} is out of range (0..=64)",
                s.depth_bias
            ));
        }
        if !(0.0..=64.0).contains(&s.normal_offset) {
            return Err(format!(
                "shadow.normal_offset {} is out of range (0..=64)",
                s.normal_offset
            ));
        }
        if !(0.0..=16.0).contains(&s.slope_bias) {
            return Err(format!(
                "shadow.slope_bias {} is out of range (0..=16)",
                s.slope_bias
            ));
        }
        if s.pcf_radius > 4 {
            return Err(format!(
                "shadow.pcf_radius {} is out of range (0..=4)",
                s.pcf_radius
            ));
        }
        if self.display.vpl_point_size > 16 || self.display.pyramid_level > 12 {
            return Err(format!(
                "display.vpl_point_size {} (0..=16) or display.pyramid_level {} (0..=12) out of range",
                self.display.vpl_point_size, self.display.pyramid_level
            ));
        }
        if !(-20.0..=20.0).contains(&self.display.exposure_ev) {
            return Err(format!(
                "display.exposure_ev {} is out of range (-20..=20)",
                self.display.exposure_ev
            ));
        }
        if !(1..=8192).contains(&self.textures.max_size) {
            return Err(format!(
                "textures.max_size {} is out of range (1..=8192)",
                self.textures.max_size
            ));
        }
        let v = &self.vpl;
        if !(1..=1 << 20).contains(&v.count) {
            return Err(format!("vpl.count {} is out of range (1..=1048576)", v.count));
        }
        if !(1..=64).contains(&v.samples_per_texel) {
            return Err(format!(
                "vpl.samples_per_texel {} is out of range (1..=64)",
                v.samples_per_texel
            ));
        }
        if !(v.sample_radius > 0.0 && v.sample_radius <= 10.0) {
            return Err(format!(
                "vpl.sample_radius {} is out of range (0..=10, > 0)",
                v.sample_radius
            ));
        }
        if v.filter_radius > 8 {
            return Err(format!(
                "vpl.filter_radius {} is out of range (0..=8)",
                v.filter_radius
            ));
        }
        if !(-1.0..=1.0).contains(&v.n_min) {
            return Err(format!("vpl.n_min {} is out of range (-1..=1)", v.n_min));
        }
        if !(v.d_max > 0.0 && v.d_max <= 10.0) {
            return Err(format!("vpl.d_max {} is out of range (0..=10, > 0)", v.d_max));
        }
        if !(0.0..=1.0).contains(&v.flux_mix) {
            return Err(format!("vpl.flux_mix {} is out of range (0..=1)", v.flux_mix));
        }
        let g = &self.gi;
        if !(g.reference_flux_mix > 0.0 && g.reference_flux_mix <= 1.0) {
            return Err(format!(
                "gi.reference_flux_mix {} is out of range (0..=1, > 0)",
                g.reference_flux_mix
            ));
        }
        if g.reference_samples == 0 || !(1..=4096).contains(&g.reference_spp_per_frame) {
            return Err(
                "gi.reference_samples must be >= 1 and gi.reference_spp_per_frame in 1..=4096".into(),
            );
        }
        if g.rays_per_frame == 0 {
            return Err("gi.rays_per_frame must be at least 1".into());
        }
        if !(g.distance_epsilon > 0.0 && g.distance_epsilon <= 100.0) {
            return Err(format!(
                "gi.distance_epsilon {} is out of range (0..=100 m, > 0)",
                g.distance_epsilon
            ));
        }
        if !(0.0..=1.0).contains(&g.ray_offset) {
            return Err(format!(
                "gi.ray_offset {} is out of range (0..=1 m)",
                g.ray_offset
            ));
        }
        let sm = &self.sampling;
        if !(1..=64).contains(&sm.block_size) {
            return Err(format!(
                "sampling.block_size {} is out of range (1..=64)",
                sm.block_size
            ));
        }
        if !(1..=64).contains(&sm.cut_size) {
            return Err(format!(
                "sampling.cut_size {} is out of range (1..=64)",
                sm.cut_size
            ));
        }
        if !(0.0..=100.0).contains(&sm.near_field) {
            return Err(format!(
                "sampling.near_field {} is out of range (0..=100; 0 = off)",
                sm.near_field
            ));
        }
        if !(0.0..=1.0).contains(&sm.substitute_offset) {
            return Err(format!(
                "sampling.substitute_offset {} is out of range (0..=1 m; 0 = off)",
                sm.substitute_offset
            ));
        }
        let t = &self.tree;
        if !(0.0..=1.0).contains(&t.v_min) {
            return Err(format!("tree.v_min {} is out of range (0..=1)", t.v_min));
        }
        if !(0.0..=1000.0).contains(&t.sigma_max) {
            return Err(format!(
                "tree.sigma_max {} is out of range (0..=1000 m)",
                t.sigma_max
            ));
        }
        if !(0.0..=1.0).contains(&self.display.split) {
            return Err(format!(
                "display.split {} is out of range (0..=1)",
                self.display.split
            ));
        }
        if self.display.tree_level > 20 {
            return Err(format!(
                "display.tree_level {} is out of range (0..=20)",
                self.display.tree_level
            ));
        }
        if !(1..=16).contains(&self.textures.anisotropy) {
            return Err(format!(
                "textures.anisotropy {} is out of range (1..=16)",
                self.textures.anisotropy
            ));
        }
        Ok(())
    }
}

/// Which buffer the viewport shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum ViewBuffer {
    /// The final image: every lighting term (linear radiance, tonemapped for display).
    #[default]
    Final,
    /// Direct light only.
    Direct,
    /// Indirect (one-bounce GI) only, from the selected GI method.
    Indirect,
    /// Reflected flux of the reflective shadow map of light 0.
    RsmFlux,
    /// Normals of the reflective shadow map of light 0.
    RsmNormal,
    /// World positions of the reflective shadow map of light 0 (normalised to the scene bounds).
    RsmPosition,
    /// BRSM importance of light 0's texels, raw (log heat map).
    ImportanceRaw,
    /// BRSM importance after the edge-aware filter (log heat map).
    ImportanceFiltered,
    /// A level of the importance (PDF) pyramid (`display.pyramid_level`; log heat map).
    PdfPyramid,
    /// Diffuse albedo from the G-buffer.
    Albedo,
    /// Shading normals from the G-buffer.
    Normal,
    /// Linear depth along the view direction (false colour, near = bright).
    Depth,
    /// World position normalised to the scene bounds.
    Position,
    /// Material ids (hash colours).
    MaterialId,
    /// The shadow map of light 0 (near = white).
    ShadowMap,
    /// Tree samplers: traversal steps per traversal, per pixel (heat map, thesis fig. 7.2).
    TraversalSteps,
    /// Tree samplers: pixels without a similar surrounding cut (red over the grey final).
    CutFallback,
    /// Tree samplers: the per-block cuts, a colour per cut, over the grey final.
    CutBlocks,
    /// Tree samplers: the per-block cuts coloured by their mean node depth.
    CutDepth,
    /// The ground truth of the same VPLs beside a tree sampler: GI only (comparison on).
    GroundTruthIndirect,
    /// The ground truth of the same VPLs beside a tree sampler: direct + GI (comparison on).
    GroundTruthFinal,
    /// Split view: the sampler's GI left, the ground truth's right (comparison on).
    SplitIndirect,
    /// The sampler's GI and the ground truth's side by side (comparison on).
    SideBySide,
    /// Relative error of the sampler's GI against the ground truth, log false colour.
    RelativeError,
    /// Any two radiance images (live buffers or snapshots) compared: split, side by side, A,
    /// B, difference x N, relative error (`views::AbSpec`).
    AbCompare,
}

impl ViewBuffer {
    pub const ALL: [ViewBuffer; 25] = [
        ViewBuffer::Final,
        ViewBuffer::Direct,
        ViewBuffer::Indirect,
        ViewBuffer::RsmFlux,
        ViewBuffer::RsmNormal,
        ViewBuffer::RsmPosition,
        ViewBuffer::ImportanceRaw,
        ViewBuffer::ImportanceFiltered,
        ViewBuffer::PdfPyramid,
        ViewBuffer::Albedo,
        ViewBuffer::Normal,
        ViewBuffer::Depth,
        ViewBuffer::Position,
        ViewBuffer::MaterialId,
        ViewBuffer::ShadowMap,
        ViewBuffer::TraversalSteps,
        ViewBuffer::CutFallback,
        ViewBuffer::CutBlocks,
        ViewBuffer::CutDepth,
        ViewBuffer::GroundTruthIndirect,
        ViewBuffer::GroundTruthFinal,
        ViewBuffer::SplitIndirect,
        ViewBuffer::SideBySide,
        ViewBuffer::RelativeError,
        ViewBuffer::AbCompare,
    ];
    pub fn name(self) -> &'static str {
        match self {
            ViewBuffer::Final => "final",
            ViewBuffer::Direct => "direct only",
            ViewBuffer::Indirect => "GI only",
            ViewBuffer::RsmFlux => "RSM flux",
            ViewBuffer::RsmNormal => "RSM normal",
            ViewBuffer::RsmPosition => "RSM position",
            ViewBuffer::ImportanceRaw => "BRSM importance (raw)",
            ViewBuffer::ImportanceFiltered => "BRSM importance (filtered)",
            ViewBuffer::PdfPyramid => "PDF pyramid level",
            ViewBuffer::Albedo => "albedo",
            ViewBuffer::Normal => "normal",
            ViewBuffer::Depth => "depth",
            ViewBuffer::Position => "position",
            ViewBuffer::MaterialId => "material id",
            ViewBuffer::ShadowMap => "shadow map",
            ViewBuffer::TraversalSteps => "traversal steps",
            ViewBuffer::CutFallback => "pixels without a similar cut",
            ViewBuffer::CutBlocks => "cuts per block",
            ViewBuffer::CutDepth => "cut depth per block",
            ViewBuffer::GroundTruthIndirect => "ground truth: GI only",
            ViewBuffer::GroundTruthFinal => "ground truth: final",
            ViewBuffer::SplitIndirect => "split: method | ground truth (GI)",
            ViewBuffer::SideBySide => "side by side: method | ground truth (GI)",
            ViewBuffer::RelativeError => "relative error vs ground truth",
            ViewBuffer::AbCompare => "A/B comparison",
        }
    }
    /// The view called `name` (as [`ViewBuffer::name`] spells it, case-insensitive).
    pub fn from_name(name: &str) -> Result<ViewBuffer, String> {
        ViewBuffer::ALL
            .into_iter()
            .find(|v| v.name().eq_ignore_ascii_case(name.trim()))
            .ok_or_else(|| {
                let names: Vec<&str> = ViewBuffer::ALL.iter().map(|v| v.name()).collect();
                format!("unknown view '{name}'; the views are: {}", names.join(", "))
            })
    }

    /// True for views drawn in RSM texel space (VPL overlays go to their texels there).
    pub fn is_rsm_space(self) -> bool {
        matches!(
            self,
            ViewBuffer::RsmFlux
                | ViewBuffer::RsmNormal
                | ViewBuffer::RsmPosition
                | ViewBuffer::ImportanceRaw
                | ViewBuffer::ImportanceFiltered
                | ViewBuffer::PdfPyramid
                | ViewBuffer::ShadowMap
        )
    }

    /// True for the views of the tree samplers' diagnostics.
    pub fn is_sampling_view(self) -> bool {
        matches!(
            self,
            ViewBuffer::TraversalSteps
                | ViewBuffer::CutFallback
                | ViewBuffer::CutBlocks
                | ViewBuffer::CutDepth
        )
    }

    /// True for the views that need the comparison ground truth.
    pub fn is_compare_view(self) -> bool {
        matches!(
            self,
            ViewBuffer::GroundTruthIndirect
                | ViewBuffer::GroundTruthFinal
                | ViewBuffer::SplitIndirect
                | ViewBuffer::SideBySide
                | ViewBuffer::RelativeError
        )
    }

    /// True for log heat maps relative to their mean (the UI draws a legend).
    pub fn is_log_heat(self) -> bool {
        matches!(
            self,
            ViewBuffer::ImportanceRaw | ViewBuffer::ImportanceFiltered | ViewBuffer::PdfPyramid
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_round_trip_through_toml() {
        let s = RenderSettings::default();
        assert!(s.validate().is_ok());
        let text = toml::to_string(&s).unwrap();
        let back: RenderSettings = toml::from_str(&text).unwrap();
        assert_eq!(s, back);
    }

    #[test]
    fn out_of_range_values_are_named() {
        let mut s = RenderSettings::default();
        s.shadow.resolution = 3;
        assert!(s.validate().unwrap_err().contains("shadow.resolution"));
        let mut s = RenderSettings::default();
        s.display.exposure_ev = f32::NAN;
        assert!(s.validate().unwrap_err().contains("exposure_ev"));
    }
}

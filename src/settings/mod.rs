//! Renderer settings: one serde struct per pass, documented field by field. The same structs
//! are edited by the UI, saved with the app state, read from presets and set by CLI flags.

mod frame;
pub mod legacy;
mod method_tables;
mod shared_passes;
pub mod temporal;
mod view_buffer;

pub use frame::FrameSettings;
pub use method_tables::MethodTables;
pub use shared_passes::*;
pub use view_buffer::ViewBuffer;

use serde::{Deserialize, Serialize};

use crate::base::field::{self, Field};

/// All settings of the frame. Read through [`legacy::migrate`] first, so files written
/// before a key moved still load (`Deserialize` below).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields, remote = "Self")]
pub struct RenderSettings {
    /// Frame-wide: accumulation over frames, a fixed seed.
    pub frame: FrameSettings,
    pub shadow: ShadowSettings,
    pub vpl: VplSettings,
    pub gi: GiSettings,
    pub tree: TreeSettings,
    pub display: DisplaySettings,
    pub textures: TextureSettings,
    /// Temporal reuse and SVGF after a per-frame method (`renderer::passes::temporal`).
    pub temporal: TemporalSettings,
    /// Settings of the methods that own no section above: `[methods.<cli name>]` tables, each
    /// read and written as the method's own serde struct ([`RenderSettings::method`]), so a
    /// new method brings its settings in its folder without a field here.
    #[serde(skip_serializing_if = "MethodTables::is_empty")]
    pub methods: MethodTables,
}

impl Serialize for RenderSettings {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        RenderSettings::serialize(self, s)
    }
}

impl<'de> Deserialize<'de> for RenderSettings {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let mut t = toml::Table::deserialize(d)?;
        legacy::migrate(&mut t).map_err(D::Error::custom)?;
        RenderSettings::deserialize(t).map_err(|e| D::Error::custom(e.message()))
    }
}

impl RenderSettings {
    /// A method's settings from its `[methods.<cli name>]` table (its defaults where the table
    /// or a field is absent); the error names the table and the field.
    pub fn method<T: serde::de::DeserializeOwned + Default + Clone + Send + Sync + 'static>(
        &self,
        id: MethodId,
    ) -> Result<T, String> {
        self.methods.get(id.cli())
    }

    /// Sets one field by its TOML path (`methods.lightcuts.max_cut`, `gi.distance_epsilon`) to
    /// `value`, read as a TOML value (a bare word that is not one is a string). The error
    /// names the key (an unknown field, a value of the wrong type). `validate` checks ranges.
    pub fn set_path(&mut self, key: &str, value: &str) -> Result<(), String> {
        let key = &legacy::rename_path(key);
        let parts: Vec<&str> = key.split('.').map(str::trim).collect();
        if parts.iter().any(|p| p.is_empty()) {
            return Err(format!(
                "--set {key}: the key is a dotted path such as gi.shadow_rays"
            ));
        }
        let v: toml::Value = match toml::from_str::<toml::Table>(&format!("v = {value}")) {
            Ok(mut t) => t.remove("v").unwrap_or(toml::Value::String(value.to_string())),
            Err(_) => toml::Value::String(value.to_string()),
        };
        let mut root = toml::Table::try_from(&*self).map_err(|e| format!("--set {key}: {e}"))?;
        let mut t = &mut root;
        for p in &parts[..parts.len() - 1] {
            let entry = t
                .entry(p.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            t = entry
                .as_table_mut()
                .ok_or_else(|| format!("--set {key}: {p} is a value, not a table"))?;
        }
        t.insert(parts[parts.len() - 1].to_string(), v);
        *self = root
            .try_into()
            .map_err(|e: toml::de::Error| format!("--set {key}={value}: {}", e.message()))?;
        // A method's table is read lazily: read it now so that an unknown field is named here.
        if parts[0] == "methods" && parts.len() > 2 {
            let id = MethodId::parse(parts[1]).map_err(|e| format!("--set {key}: {e}"))?;
            (id.info().validate)(self).map_err(|e| format!("--set {key}={value}: {e}"))?;
        }
        Ok(())
    }

    /// Stores a method's settings as its `[methods.<cli name>]` table.
    pub fn set_method<T: Serialize + Default>(&mut self, id: MethodId, value: &T) -> Result<(), String> {
        self.methods.set(id.cli(), value)
    }
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
    /// Diffuse bounces the indirect light makes (instant radiosity; the SST paper's VPL
    /// generation, section 5). 1 = the RSM's VPLs only (the thesis; default). N > 1 adds
    /// VPLs at bounces 2..=N from light paths traced through the BVH: every bounce gets
    /// `count / N` of the budget (one slot per path), bounce 1 the rest. More bounces: light
    /// in places the sun's first bounce cannot reach, fewer VPLs per bounce.
    pub bounces: u32,
    /// Russian roulette on the light paths (the SST paper, Keller): after each hit a path
    /// continues with probability max(albedo) and its flux is divided by it, so a VPL's flux
    /// stays near its path's start and dark surfaces end paths early. Off: every path runs
    /// to `bounces` with its flux x albedo per bounce (no empty slots, smaller VPLs).
    pub roulette: bool,
    /// Share of the light paths' start PDF that follows the RSM texels' flux. 1 (default):
    /// flux only, the SST paper's "sampling of the light sources according to their flux";
    /// below 1 the rest follows bounce 1's BRSM importance, so fewer paths start where
    /// their light leaves the scene unseen (a sunlit roof). Above 0 keeps it unbiased.
    pub path_flux_mix: f32,
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
            bounces: 1,
            roulette: true,
            path_flux_mix: 1.0,
        }
    }
}

pub use crate::methods::{MethodId, MethodView};
pub use temporal::{MAX_ATROUS_ITERATIONS, TemporalMode, TemporalSettings, TemporalView};

pub use crate::base::brdf::Brdf;

/// Shading of VPLs (shared by every GI method and the references).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GiSettings {
    /// The GI method (`crate::methods::REGISTRY`; its CLI name, e.g. "slc", "ground-truth",
    /// "off"). Default: the thesis's SLC.
    pub method: MethodId,
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
    /// Light paths the reference traces per sample per pixel when `vpl.bounces` > 1 (fresh
    /// paths every frame; their bounce 2..=N VPLs are shaded at every pixel with shadow
    /// rays, so the cost per pixel grows with it). More: less noise in the higher bounces.
    pub reference_paths_per_sample: u32,
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
    /// The BRDF of every shading point: Lambert (default) or GGX (metallic-roughness). The
    /// VPLs themselves stay diffuse emitters (their flux is the RSM's diffuse reflection).
    pub brdf: Brdf,
}

impl Default for GiSettings {
    fn default() -> Self {
        Self {
            method: MethodId::default(),
            rays_per_frame: 1 << 20,
            reference_samples: 4096,
            reference_spp_per_frame: 1,
            reference_flux_mix: 0.25,
            reference_paths_per_sample: 16,
            distance_epsilon: 0.05,
            ray_offset: 1e-3,
            shadow_rays: true,
            brdf: Brdf::Lambert,
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
    /// Which tree (`--tree`): the thesis's perfect binary tree or the SST paper's radix tree
    /// (LBVH). The tree samplers run on either; the other tree methods need the perfect tree.
    pub kind: TreeKind,
}

impl Default for TreeSettings {
    fn default() -> Self {
        // The thesis's values (chapter 5: "a good balance between quality and speed").
        Self {
            v_min: 0.7,
            sigma_max: 0.3,
            kind: TreeKind::Perfect,
        }
    }
}

pub use crate::base::sampling::ChildProbability;
pub use crate::base::sst_node::TreeKind;

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

/// Colouring of the VPL overlay (`display.vpl_overlay`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum VplColor {
    /// Log-scale false colour of the VPL's flux around the mean VPL flux.
    #[default]
    Flux,
    /// The diffuse bounce its light has made (`vpl.bounces`): a fixed colour per bounce
    /// (`base::colormap::bounce_color`).
    Bounce,
}

impl VplColor {
    pub const ALL: [VplColor; 2] = [VplColor::Flux, VplColor::Bounce];
    pub fn name(self) -> &'static str {
        match self {
            VplColor::Flux => "flux",
            VplColor::Bounce => "bounce",
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

pub use crate::base::display::Tonemap;

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
    /// What the VPL discs' colour shows: flux, or the bounce (multi-bounce VPLs).
    pub vpl_color: VplColor,
    /// Radius of the VPL discs in view pixels (0 = one pixel).
    pub vpl_point_size: u32,
    /// Level shown by the PDF-pyramid view (0 = full resolution).
    pub pyramid_level: u32,
    /// Light-tree overlay over the camera-space views.
    pub tree_overlay: TreeOverlay,
    /// Tree level it draws (0 = the root; clamped to the leaves' level).
    pub tree_level: u32,
    pub tree_color: TreeColor,
    /// Both trees side by side in the overlay: the perfect tree over the left half, the radix
    /// tree over the right (the frame also builds the tree it does not sample).
    pub tree_compare: bool,
    /// Position of the divider in the split comparison view (0 = left edge, 1 = right).
    pub split: f32,
}

impl Default for DisplaySettings {
    fn default() -> Self {
        Self {
            exposure_ev: 0.0,
            tonemap: Tonemap::Aces,
            vpl_overlay: false,
            vpl_color: VplColor::Flux,
            vpl_point_size: 1,
            pyramid_level: 0,
            tree_overlay: TreeOverlay::Off,
            tree_level: 6,
            tree_color: TreeColor::Intensity,
            tree_compare: false,
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
        self.validate_shadow()?;
        self.validate_display()?;
        self.validate_vpl()?;
        self.validate_gi_and_tree()?;
        self.validate_method_tables()?;
        self.temporal.validate()?;
        crate::methods::validate_all(self)
    }

    /// `[shadow]`: the shadow map's size and biases.
    fn validate_shadow(&self) -> Result<(), String> {
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
        Ok(())
    }

    /// `[display]`'s overlay sizes and exposure, `textures.max_size`.
    fn validate_display(&self) -> Result<(), String> {
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
        Ok(())
    }

    /// `[vpl]`: count, sampling, bounces.
    fn validate_vpl(&self) -> Result<(), String> {
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
        let max_bounces = crate::gpu::passes::light_paths::MAX_BOUNCES;
        if !(1..=max_bounces).contains(&v.bounces) {
            return Err(format!(
                "vpl.bounces {} is out of range (1..={max_bounces})",
                v.bounces
            ));
        }
        if !(v.path_flux_mix > 0.0 && v.path_flux_mix <= 1.0) {
            return Err(format!(
                "vpl.path_flux_mix {} is out of range (0..=1, > 0: the paths stay unbiased)",
                v.path_flux_mix
            ));
        }
        if v.count < v.bounces {
            return Err(format!(
                "vpl.bounces {} needs at least as many VPLs (vpl.count {})",
                v.bounces, v.count
            ));
        }
        Ok(())
    }

    /// `[gi]`'s distances, `[tree]`, the display's split and tree level, texture anisotropy.
    fn validate_gi_and_tree(&self) -> Result<(), String> {
        let g = &self.gi;
        if !(g.distance_epsilon > 0.0 && g.distance_epsilon.is_finite()) {
            return Err(format!(
                "gi.distance_epsilon {} must be a finite distance > 0 m",
                g.distance_epsilon
            ));
        }
        // Metres, so any size: a scene modelled in millimetres-as-metres needs a large one.
        if !(g.ray_offset.is_finite() && g.ray_offset >= 0.0) {
            return Err(format!(
                "gi.ray_offset {} must be a finite distance >= 0 m",
                g.ray_offset
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
        if self.display.tree_level > 47 {
            return Err(format!(
                "display.tree_level {} is out of range (0..=47)",
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

    /// The `[methods.<name>]` tables are named by registered methods' CLI names (each GI
    /// method checks its own settings: the tree samplers' [sampling], the progressive
    /// methods' budgets, the tables).
    fn validate_method_tables(&self) -> Result<(), String> {
        if let Some(k) = self
            .methods
            .keys()
            .find(|k| MethodId::parse(k).map(|m| m.cli()) != Ok(k.as_str()))
        {
            return Err(match MethodId::parse(k) {
                Ok(m) => format!("methods.{k}: write the method's name as [methods.{}]", m.cli()),
                Err(_) => format!(
                    "methods.{k}: no such method (the methods: {})",
                    crate::methods::cli_names().join(", ")
                ),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_from_before_the_frame_section_still_loads() {
        let old: RenderSettings =
            toml::from_str("[sampling]\naccumulate = true\nfixed_seed = true\ncut_size = 8").unwrap();
        assert!(old.frame.accumulate && old.frame.fixed_seed);
        // The rest of [sampling] is the tree samplers' table now (their test reads it).
        let moved = legacy::rename_path("sampling.cut_size");
        let (table, field) = moved
            .strip_prefix("methods.")
            .and_then(|p| p.split_once('.'))
            .unwrap();
        assert_eq!(
            old.methods.raw(table).and_then(|t| t[field].as_integer()),
            Some(8)
        );
        let now = toml::to_string(&old).unwrap();
        assert!(
            now.contains("[frame]") && !now.contains("sampling.accumulate"),
            "{now}"
        );
        let clash =
            toml::from_str::<RenderSettings>("[sampling]\naccumulate = true\n[frame]\naccumulate = false");
        assert!(clash.unwrap_err().to_string().contains("sampling.accumulate"));
        let unknown = toml::from_str::<RenderSettings>("[frame]\nspeed = 2");
        assert!(unknown.unwrap_err().to_string().contains("speed"));
    }

    #[test]
    fn defaults_are_valid_and_round_trip_through_toml() {
        let s = RenderSettings::default();
        assert!(s.validate().is_ok());
        let text = toml::to_string(&s).unwrap();
        let back: RenderSettings = toml::from_str(&text).unwrap();
        assert_eq!(s, back);
    }

    #[test]
    fn ism_settings_refuse_what_the_build_cannot_dispatch() {
        let ok: IsmSettings = IsmSettings::default();
        assert!(ok.validate("t").is_ok());
        // Stochastic Light Culling's 16384 maps of 32^2 fit; 65536 maps would not.
        assert!(
            IsmSettings {
                tile: 32,
                ..ok.clone()
            }
            .validate("t")
            .is_ok()
        );
        let cases = [
            (
                IsmSettings {
                    atlas: 8192,
                    tile: 32,
                    ..ok.clone()
                },
                "t.ism.atlas",
            ),
            (
                IsmSettings {
                    tile: 100,
                    ..ok.clone()
                },
                "t.ism.tile",
            ),
            (
                IsmSettings {
                    points: 0,
                    ..ok.clone()
                },
                "t.ism.points",
            ),
            (
                IsmSettings {
                    points_per_light: 1 << 17,
                    ..ok.clone()
                },
                "t.ism.points_per_light",
            ),
            (
                IsmSettings {
                    bias: 0.5,
                    ..ok.clone()
                },
                "t.ism.bias",
            ),
        ];
        for (s, name) in cases {
            let e = s.validate("t").unwrap_err();
            assert!(e.starts_with(name), "{e}");
        }
    }

    #[test]
    fn a_methods_own_table_round_trips_and_errors_name_it() {
        #[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
        #[serde(default, deny_unknown_fields)]
        struct Knobs {
            threshold: f32,
            cap: u32,
        }
        // A method without settings of its own ignores a table it does not read.
        let id = MethodId::parse("off").unwrap();
        let mut s = RenderSettings::default();
        assert_eq!(s.method::<Knobs>(id), Ok(Knobs::default()));
        let k = Knobs {
            threshold: 0.02,
            cap: 256,
        };
        s.set_method(id, &k).unwrap();
        let back: RenderSettings = toml::from_str(&toml::to_string(&s).unwrap()).unwrap();
        assert_eq!(back.method::<Knobs>(id), Ok(k));
        assert!(s.validate().is_ok());
        let bad: RenderSettings = toml::from_str("[methods.off]\ncap = \"many\"").unwrap();
        assert!(bad.method::<Knobs>(id).unwrap_err().contains("methods.off"));
        let unknown: RenderSettings = toml::from_str("[methods.nope]\ncap = 1").unwrap();
        assert!(unknown.validate().unwrap_err().contains("methods.nope"));
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

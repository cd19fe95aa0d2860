//! The tree samplers' settings (`[sampling]` in a settings file): thesis chapter 5 and the
//! options this workbench adds, each documented with what it trades.

use serde::{Deserialize, Serialize};

use crate::base::field::Field;
use crate::methods::MethodId;
use crate::settings::RenderSettings;

pub use crate::settings::{IsmAdaptive, IsmSettings};

/// How the samplers' samples are shadowed while `gi.shadow_rays` is on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SamplerVisibility {
    /// A BVH shadow ray per sample (the thesis).
    #[default]
    Rays,
    /// Imperfect shadow maps, one per light-tree leaf (issue 21's component, Stochastic Light
    /// Culling's adaptive maps: 32^2, 8192 points): a leaf sample looks its VPL's map up; a
    /// substitute sample the map of a random leaf of its node's subtree (an approximation:
    /// the leaf's VPL stands for the drawn point).
    Ism,
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

pub use crate::base::sampling::{ChildProbability, GlossyWeights};
pub use crate::settings::InterleaveSettings;

/// Largest interleaving pattern of the tree samplers: 8 x 8 = 64 subsets of at most 64 cut
/// slots.
pub const MAX_SLOT_INTERLEAVE: u32 = 8;

/// Sampling the tree (stages 11-16, thesis chapter 5): used by the SLC, SST and RTSLC methods.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SamplingSettings {
    /// k: one shallow light cut per k x k block of GI pixels (1 = a cut per pixel). Larger
    /// blocks cost less and blur the cut choice across edges (blending hides the seams).
    pub block_size: u32,
    /// Nodes per cut = cluster evaluations (shadow rays) per pixel; SST takes this many
    /// traversals from the root. With n x n interleaving a pixel takes 1 / n^2 of them.
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
    /// With a glossy BRDF (`gi.brdf = "Ggx"`), how the glossy samples' walks (SLC, SST)
    /// weigh the children: geometric weights alone, the SST paper's glossy material term
    /// (section 4.1), or (default) that mixed with 25% of the geometric probability. All
    /// are unbiased; see docs/brdf.md for the measurements.
    pub glossy_weights: GlossyWeights,
    pub blending: CutBlending,
    pub fallback: CutFallback,
    /// Render GI at half resolution and upsample it with a joint bilateral filter using S.
    pub half_resolution: bool,
    /// Interleaved sampling over the cut's slots (`[sampling.interleave]`; ours, after
    /// Stochastic Light Culling section 4.2 and RTSLC's code, which interleaves 2 x 2 or
    /// 4 x 4): pixel subset s of the n x n pattern evaluates only the slots i with
    /// (i + the frame's offset) mod n^2 = s, each x n^2 (SST and the root fallback: its share
    /// of the samples, averaged), then the geometry-aware filter averages the pattern back
    /// (at the GI resolution, before the upsampling). n^2 fewer shadow rays per pixel for a
    /// blur within surfaces. Default off (n = 1, the thesis).
    pub interleave: InterleaveSettings,
    /// Visibility of the samples while shadow rays are on: rays, or the leaves' maps.
    pub visibility: SamplerVisibility,
    /// The leaves' maps (`[sampling.ism]`; light culling's adaptive-map defaults).
    pub ism: IsmSettings<IsmAdaptive>,
}

/// The numeric settings of `[sampling]`, declared once (validation, the GUI's sliders,
/// `--set`).
pub static FIELDS: &[Field<SamplingSettings>] = &[
    crate::field!(
        SamplingSettings,
        cut_size: u32,
        "cut size (samples per pixel)",
        "",
        1,
        64,
        Linear,
        "nodes per cut = cluster evaluations (shadow rays) per pixel; SST: traversals from the root"
    ),
    crate::field!(
        SamplingSettings,
        block_size: u32,
        "cut block k",
        "pixels",
        1,
        64,
        Linear,
        "one shallow light cut per k x k block (1 = per pixel)"
    ),
    crate::field!(
        SamplingSettings,
        near_field: f32,
        "near-field refinement",
        "box diagonals",
        0.0,
        100.0,
        Log,
        "stop at a usable node only when the point is at least this many box diagonals from \
         its box (0 = the thesis's rule): substitute samples next to the point turn into fireflies"
    ),
    crate::field!(
        SamplingSettings,
        substitute_offset: f32,
        "substitute ray offset",
        "m",
        0.0,
        1.0,
        Log,
        "substitute samples' shadow rays end this far short of the drawn point (the SST paper's \
         scene-size epsilon; 0 = the thesis): too large leaks light through thin walls"
    ),
];

impl SamplingSettings {
    /// The tree samplers' settings in `s`: the table `[methods.slc]` (SLC's, which its
    /// baselines SST and RTSLC share: the same cuts and samples; `[sampling]` in files from
    /// before issue 38), parsed once per change. Its defaults where the table does not parse
    /// (validation names the error).
    pub fn of(s: &RenderSettings) -> Self {
        s.method::<Self>(TABLE).unwrap_or_default()
    }

    /// Changes the tree samplers' settings in `s` by `f`.
    pub fn edit(s: &mut RenderSettings, f: impl FnOnce(&mut Self)) {
        let mut v = Self::of(s);
        f(&mut v);
        // Cannot fail: the struct serialises to a table.
        let _ = s.set_method(TABLE, &v);
    }
}

/// Whose `[methods.*]` table holds the tree samplers' settings: SLC's.
pub const TABLE: MethodId = super::SLC;

// Files from before issue 38 wrote the table as `[sampling]` (its frame-wide keys moved to
// `[frame]` first: `settings::legacy::MOVED`).
inventory::submit! {
    crate::settings::legacy::Moved { old: "sampling", new: "methods.slc" }
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
            glossy_weights: GlossyWeights::Defensive,
            blending: CutBlending::Stochastic,
            fallback: CutFallback::MockCut,
            half_resolution: false,
            interleave: InterleaveSettings::pattern(1),
            visibility: SamplerVisibility::Rays,
            ism: IsmSettings::default(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_partial_interleave_table_keeps_the_samplers_defaults() {
        // The tree samplers do not interleave unless told (light culling does, 8 x 8).
        let sm: SamplingSettings = toml::from_str("[interleave]\nfilter_radius = 2").unwrap();
        assert_eq!((sm.interleave.n, sm.interleave.filter_radius), (1, 2));
        let sm: SamplingSettings = toml::from_str("[interleave]\nn = 4").unwrap();
        assert_eq!((sm.interleave.n, sm.interleave.filter_radius), (4, 0));
    }

    #[test]
    fn a_file_from_before_issue_38_keeps_its_sampling_section() {
        let old: RenderSettings = toml::from_str(
            "[sampling]\naccumulate = true\nfixed_seed = true\ncut_size = 8\n[sampling.interleave]\nn = 2",
        )
        .unwrap();
        assert!(old.frame.accumulate && old.frame.fixed_seed);
        let sm = SamplingSettings::of(&old);
        assert_eq!((sm.cut_size, sm.interleave.n), (8, 2));
        assert!(old.validate().is_ok());
        let mut set = RenderSettings::default();
        set.set_path("sampling.block_size", "4").unwrap();
        assert_eq!(SamplingSettings::of(&set).block_size, 4);
        // What `render` records: the table as the samplers read it, defaults filled in.
        let (section, t) = crate::methods::own_settings(super::super::RTSLC, &set).unwrap();
        assert_eq!(section, "methods.slc");
        assert_eq!(t["block_size"].as_integer(), Some(4));
        assert_eq!(t["cut_size"].as_integer(), Some(32));
        assert!(t["interleave"].get("n").is_some());
        // The other samplers' tables are SLC's: a table of their own is refused by name.
        let own: RenderSettings = toml::from_str("[methods.rtslc]\ncut_size = 8").unwrap();
        assert!(own.validate().unwrap_err().contains("methods.rtslc"));
    }
}

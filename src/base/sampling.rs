//! Choices shared by the tree samplers' settings and their CPU twin (`reference::slc`).

use serde::{Deserialize, Serialize};

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

/// How a glossy sample's walk (SLC, SST with `gi.brdf = "Ggx"`; SST paper section 4.3:
/// glossy samples walk to leaf VPLs) weighs the two children of a step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum GlossyWeights {
    /// The geometric weights alone (`ChildProbability`), as a diffuse sample walks.
    Geometric,
    /// The SST paper's material term (section 4.1): each child's weight times the specular
    /// BRDF towards the reflected view direction where it meets the child's box, else
    /// towards the box's point nearest it (`reference::slc::glossy_term`).
    Material,
    /// Ours (the default): (1 - [`GLOSSY_DEFENSIVE`]) x the material term's probability +
    /// [`GLOSSY_DEFENSIVE`] x the geometric one (a defensive mixture): the paper's single
    /// direction per box underrates children whose VPLs lie in the lobe off that direction,
    /// a firefly when drawn. Measured in `tests/slc.rs` and docs/brdf.md.
    #[default]
    Defensive,
}

/// The geometric share of [`GlossyWeights::Defensive`] (`SLC_GLOSSY_DEFENSIVE` in
/// `common/slc.wgsl`).
pub const GLOSSY_DEFENSIVE: f32 = 0.25;

impl GlossyWeights {
    pub const ALL: [GlossyWeights; 3] = [
        GlossyWeights::Geometric,
        GlossyWeights::Material,
        GlossyWeights::Defensive,
    ];
    pub fn name(self) -> &'static str {
        match self {
            GlossyWeights::Geometric => "geometric only",
            GlossyWeights::Material => "material term (SST paper)",
            GlossyWeights::Defensive => "material + 25% geometric (defensive)",
        }
    }
    /// `SlcParams.glossy_material`.
    pub fn gpu(self) -> u32 {
        match self {
            GlossyWeights::Geometric => 0,
            GlossyWeights::Material => 1,
            GlossyWeights::Defensive => 2,
        }
    }
}

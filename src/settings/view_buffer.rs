//! Which buffer a view shows ([`ViewBuffer`]): the frame's buffers, the comparison's and the
//! methods' views, by the names menus, `--views` and saved layouts use.

use super::*;

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
    /// A view a GI method draws (`MethodInfo::views`: the tree samplers' traversal steps,
    /// cuts, ...), by its name.
    Method(MethodView),
    /// A view of the temporal stage (`settings.temporal`: history, motion, variance, the
    /// filter's iterations), after a per-frame method.
    Temporal(TemporalView),
}

impl ViewBuffer {
    /// The views every method shares; [`ViewBuffer::all`] adds the methods' own.
    pub const ALL: [ViewBuffer; 21] = [
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
            ViewBuffer::GroundTruthIndirect => "ground truth: GI only",
            ViewBuffer::GroundTruthFinal => "ground truth: final",
            ViewBuffer::SplitIndirect => "split: method | ground truth (GI)",
            ViewBuffer::SideBySide => "side by side: method | ground truth (GI)",
            ViewBuffer::RelativeError => "relative error vs ground truth",
            ViewBuffer::AbCompare => "A/B comparison",
            ViewBuffer::Method(v) => v.name(),
            ViewBuffer::Temporal(v) => v.name(),
        }
    }
    /// Every view: the shared ones, the temporal stage's, then each registered method's.
    pub fn all() -> Vec<ViewBuffer> {
        let mut v = ViewBuffer::ALL.to_vec();
        v.extend(TemporalView::ALL.into_iter().map(ViewBuffer::Temporal));
        v.extend(MethodView::all().into_iter().map(ViewBuffer::Method));
        v
    }
    /// The view called `name` (as [`ViewBuffer::name`] spells it, case-insensitive).
    pub fn from_name(name: &str) -> Result<ViewBuffer, String> {
        let all = ViewBuffer::all();
        all.iter()
            .copied()
            .find(|v| v.name().eq_ignore_ascii_case(name.trim()))
            .ok_or_else(|| {
                let names: Vec<&str> = all.iter().map(|v| v.name()).collect();
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

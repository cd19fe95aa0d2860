//! Settings and views of the temporal stage (`renderer::passes::temporal`): reprojection of
//! the GI through the camera motion with history rejection, an exponential history with a
//! per-pixel length, and the variance-guided à-trous filter of SVGF (Schied et al. 2017,
//! "Spatiotemporal Variance-Guided Filtering"), as the paper has it or conserving the
//! image's light (`atrous`). The `[temporal]` table of a settings file.

use serde::{Deserialize, Serialize};

/// Most à-trous iterations (steps 1, 2, 4, ... 2^(n-1) pixels).
pub const MAX_ATROUS_ITERATIONS: u32 = 8;

/// What runs between a per-frame method's estimate and the composite.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TemporalMode {
    /// The method's estimate as it is (today's frames; a still view may still average frames
    /// with `frame.accumulate`).
    #[default]
    Off,
    /// Temporal reprojection and exponential history only (no spatial filter).
    Reproject,
    /// Reprojection, history, variance estimate and the à-trous filter (SVGF).
    Svgf,
}

impl TemporalMode {
    pub const ALL: [TemporalMode; 3] = [TemporalMode::Off, TemporalMode::Reproject, TemporalMode::Svgf];
    /// The CLI spelling (`render --temporal`).
    pub fn cli(self) -> &'static str {
        match self {
            TemporalMode::Off => "off",
            TemporalMode::Reproject => "reproject",
            TemporalMode::Svgf => "svgf",
        }
    }
    pub fn label(self) -> &'static str {
        match self {
            TemporalMode::Off => "off",
            TemporalMode::Reproject => "reprojection + history",
            TemporalMode::Svgf => "SVGF (history + à-trous)",
        }
    }
}

/// The à-trous iterations' weights (`temporal.atrous`, docs/temporal.md "Where SVGF lost
/// light").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AtrousFilter {
    /// Symmetric weights e(p, q) = e(q, p) (depth scale from the larger depth derivative,
    /// luminance scale from the larger variance), normalised by the larger of the two pixels'
    /// weight sums, applied as out_p = X_p + Σ s_pq (X_q - X_p): what p takes from q, q gives,
    /// so the image's light stays. Three passes per iteration (prep, weight sums, filter). The
    /// variance pass keeps each pixel's colour on short histories.
    #[default]
    Conserving,
    /// SVGF as published (Schied et al. 2017, section 4.3): each output normalised by its own
    /// weight sum, the luminance scale from its own variance; on short histories the variance
    /// pass blurs the colour too. Loses light under right-skewed noise (an outlier gives to
    /// its neighbours and takes little back): SLC on a still view lost 5% (issue 37).
    Svgf,
}

impl AtrousFilter {
    /// Both choices, the default first.
    pub const ALL: [AtrousFilter; 2] = [AtrousFilter::Conserving, AtrousFilter::Svgf];
    /// The settings spelling (`--set temporal.atrous=svgf`).
    pub fn cli(self) -> &'static str {
        match self {
            AtrousFilter::Conserving => "conserving",
            AtrousFilter::Svgf => "svgf",
        }
    }
    /// The GUI's label.
    pub fn label(self) -> &'static str {
        match self {
            AtrousFilter::Conserving => "light-conserving",
            AtrousFilter::Svgf => "SVGF (as published)",
        }
    }
}

/// The temporal stage's parameters. SVGF's values (section 4 of the paper and its reference
/// implementation) are the defaults, with the light-conserving à-trous (`atrous`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TemporalSettings {
    /// Off, reprojection + history, or SVGF. Applies to per-frame methods; progressive
    /// methods converge on their own and pass through.
    pub mode: TemporalMode,
    /// Least weight of the new frame in the colour history: colour = mix(history, new,
    /// max(alpha, 1 / history length)). SVGF: 0.2. Lower: less noise, more lag (ghosting
    /// after lighting changes).
    pub alpha: f32,
    /// The same for the luminance moments (the variance estimate). SVGF: 0.2.
    pub moments_alpha: f32,
    /// Cap of the per-pixel history length (frames). With `alpha` > 1 / cap the cap only
    /// bounds the history-length view.
    pub max_history: u32,
    /// History rejection: a previous pixel is reused only if its normal's cosine with the
    /// pixel's is at least this ...
    pub normal_cos: f32,
    /// ... its point lies within this fraction of the view depth of the pixel's tangent
    /// plane, and its material id is the pixel's (the disocclusion test).
    pub depth_tolerance: f32,
    /// À-trous iterations (steps 1, 2, 4, ... pixels; 5 in SVGF).
    pub iterations: u32,
    /// The iteration (1-based) whose output becomes the colour history (SVGF: 1); 0 keeps
    /// the unfiltered integrated colour.
    pub feedback_iteration: u32,
    /// The iterations' weights: `conserving` (default; keeps the image's light) or `svgf`
    /// (the paper's, which darkens under skewed noise).
    pub atrous: AtrousFilter,
    /// Luminance edge-stopping: weight exp(-|l_p - l_q| / (sigma_l sqrt(g(var_p)))). SVGF: 4.
    pub sigma_l: f32,
    /// Normal edge-stopping: max(0, n_p . n_q)^sigma_n. SVGF: 128.
    pub sigma_n: f32,
    /// Depth edge-stopping: exp(-|z_p - z_q| / (sigma_z |grad z| |p - q|)). SVGF: 1.
    pub sigma_z: f32,
    /// Below this history length the variance is estimated spatially (7x7 bilateral over the
    /// moments, boosted by 4 / length, as SVGF does). SVGF: 4.
    pub spatial_variance_frames: u32,
    /// A-SVGF-style history reset: where the window mean of the new frame differs from the
    /// reprojected history's by more than twice its standard error, the new frame's weight
    /// rises towards 1 by `gradient_scale` x the relative difference (lighting changes, a
    /// moving sun).
    pub gradient_reset: bool,
    pub gradient_scale: f32,
    /// The iteration (1-based) the "à-trous iteration" view shows.
    pub view_iteration: u32,
}

impl Default for TemporalSettings {
    fn default() -> Self {
        Self {
            mode: TemporalMode::Off,
            alpha: 0.2,
            moments_alpha: 0.2,
            max_history: 32,
            normal_cos: 0.9,
            depth_tolerance: 0.02,
            iterations: 5,
            feedback_iteration: 1,
            atrous: AtrousFilter::Conserving,
            sigma_l: 4.0,
            sigma_n: 128.0,
            sigma_z: 1.0,
            spatial_variance_frames: 4,
            gradient_reset: false,
            gradient_scale: 2.0,
            view_iteration: 1,
        }
    }
}

impl TemporalSettings {
    /// Checks each value's range; the message names `temporal.<field>`.
    pub fn validate(&self) -> Result<(), String> {
        let f = |name: &str, v: String, range: &str| {
            Err(format!("temporal.{name} {v} is out of range ({range})"))
        };
        let unit = |v: f32| (0.0..=1.0).contains(&v);
        if !(unit(self.alpha) && self.alpha > 0.0) {
            return f("alpha", self.alpha.to_string(), "0 < alpha <= 1");
        }
        if !(unit(self.moments_alpha) && self.moments_alpha > 0.0) {
            return f(
                "moments_alpha",
                self.moments_alpha.to_string(),
                "0 < moments_alpha <= 1",
            );
        }
        if !(1..=1024).contains(&self.max_history) {
            return f("max_history", self.max_history.to_string(), "1..=1024");
        }
        if !(-1.0..=1.0).contains(&self.normal_cos) {
            return f("normal_cos", self.normal_cos.to_string(), "-1..=1");
        }
        if !unit(self.depth_tolerance) {
            return f("depth_tolerance", self.depth_tolerance.to_string(), "0..=1");
        }
        if self.iterations > MAX_ATROUS_ITERATIONS {
            return f(
                "iterations",
                self.iterations.to_string(),
                &format!("0..={MAX_ATROUS_ITERATIONS}"),
            );
        }
        if self.feedback_iteration > self.iterations {
            return f(
                "feedback_iteration",
                self.feedback_iteration.to_string(),
                "0..=iterations",
            );
        }
        for (name, v, hi) in [
            ("sigma_l", self.sigma_l, 1e4),
            ("sigma_n", self.sigma_n, 1e4),
            ("sigma_z", self.sigma_z, 1e4),
            ("gradient_scale", self.gradient_scale, 1e3),
        ] {
            if !(v > 0.0 && v <= hi) {
                return f(name, v.to_string(), &format!("0 < {name} <= {hi}"));
            }
        }
        if self.spatial_variance_frames > 64 {
            return f(
                "spatial_variance_frames",
                self.spatial_variance_frames.to_string(),
                "0..=64",
            );
        }
        if !(1..=MAX_ATROUS_ITERATIONS).contains(&self.view_iteration) {
            return f(
                "view_iteration",
                self.view_iteration.to_string(),
                &format!("1..={MAX_ATROUS_ITERATIONS}"),
            );
        }
        Ok(())
    }
}

/// The temporal stage's views (`ViewBuffer::Temporal`): empty until a frame ran it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum TemporalView {
    /// The method's estimate of this frame, before the temporal stage (radiance).
    Raw,
    /// The history reprojected to this frame, before the blend (radiance).
    Reprojected,
    /// Screen-space motion to the previous frame (hue: direction, brightness: length).
    Motion,
    /// Reprojection outcome: white = all bilinear taps reused, grey = some, yellow = the 3x3
    /// fallback, red = disoccluded.
    Disocclusion,
    /// The per-pixel history length after this frame (false colour, 0 .. max_history).
    HistoryLength,
    /// The variance estimate the filter starts from, as the relative standard deviation of
    /// the demodulated luminance (log false colour).
    Variance,
    /// The output of one à-trous iteration (`temporal.view_iteration`), remodulated radiance.
    Iteration,
    /// The history reset's new-frame weight boost (0 .. 1; with `gradient_reset`).
    Reset,
}

impl TemporalView {
    pub const ALL: [TemporalView; 8] = [
        TemporalView::Raw,
        TemporalView::Reprojected,
        TemporalView::Motion,
        TemporalView::Disocclusion,
        TemporalView::HistoryLength,
        TemporalView::Variance,
        TemporalView::Iteration,
        TemporalView::Reset,
    ];
    pub fn name(self) -> &'static str {
        match self {
            TemporalView::Raw => "temporal: GI before the filter",
            TemporalView::Reprojected => "temporal: reprojected history",
            TemporalView::Motion => "temporal: motion vectors",
            TemporalView::Disocclusion => "temporal: disocclusion mask",
            TemporalView::HistoryLength => "temporal: history length",
            TemporalView::Variance => "temporal: variance",
            TemporalView::Iteration => "temporal: à-trous iteration",
            TemporalView::Reset => "temporal: history reset",
        }
    }
    /// File name (without extension) `render` writes it to.
    pub fn file(self) -> &'static str {
        match self {
            TemporalView::Raw => "temporal_raw",
            TemporalView::Reprojected => "temporal_reprojected",
            TemporalView::Motion => "temporal_motion",
            TemporalView::Disocclusion => "temporal_disocclusion",
            TemporalView::HistoryLength => "temporal_history_length",
            TemporalView::Variance => "temporal_variance",
            TemporalView::Iteration => "temporal_atrous_iteration",
            TemporalView::Reset => "temporal_reset",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_svgfs_and_bad_values_are_named() {
        let s = TemporalSettings::default();
        assert!(s.validate().is_ok());
        assert_eq!(
            (s.alpha, s.iterations, s.sigma_l, s.sigma_n),
            (0.2, 5, 4.0, 128.0)
        );
        assert_eq!(s.atrous, AtrousFilter::Conserving);
        for (edit, name) in [
            (
                (|s: &mut TemporalSettings| s.alpha = 0.0) as fn(&mut TemporalSettings),
                "temporal.alpha",
            ),
            (|s| s.iterations = 9, "temporal.iterations"),
            (|s| s.feedback_iteration = 6, "temporal.feedback_iteration"),
            (|s| s.sigma_n = f32::NAN, "temporal.sigma_n"),
            (|s| s.view_iteration = 0, "temporal.view_iteration"),
        ] {
            let mut t = TemporalSettings::default();
            edit(&mut t);
            assert!(t.validate().unwrap_err().starts_with(name), "{name}");
        }
        let text = "mode = \"svgf\"\niterations = 3";
        let t: TemporalSettings = toml::from_str(text).unwrap();
        assert_eq!((t.mode, t.iterations, t.alpha), (TemporalMode::Svgf, 3, 0.2));
        for a in AtrousFilter::ALL {
            let t: TemporalSettings = toml::from_str(&format!("atrous = \"{}\"", a.cli())).unwrap();
            assert_eq!(t.atrous, a);
        }
        assert!(toml::from_str::<TemporalSettings>("atrous = \"gaussian\"").is_err());
    }
}

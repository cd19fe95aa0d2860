//! What one image view shows and how. A [`ViewSpec`] is the buffer (any [`ViewBuffer`], by
//! name), its [`ViewLook`] (exposure, tonemap, channel isolation, log false colour, NaN/Inf
//! highlight) and, for the A/B view, an [`AbSpec`]: two images (live radiance buffers or
//! snapshots) and how to compare them (split, side by side, A, B, difference x N, relative
//! error). The workbench renders several specs per frame (`Renderer::render_views`), one
//! `Rgba8Unorm` texture each.
//!
//! Snapshots are copies of a radiance buffer kept on the GPU, so a method can be compared with
//! another method, other settings or an earlier frame (tev-style A/B).

use serde::{Deserialize, Serialize};

use crate::settings::{DisplaySettings, ViewBuffer};

pub use crate::base::display::{Channel, ViewLook};

impl Default for ViewLook {
    fn default() -> Self {
        Self::from_display(&DisplaySettings::default())
    }
}

impl ViewLook {
    /// The look of the global display settings (exposure and tonemap), nothing isolated.
    pub fn from_display(d: &DisplaySettings) -> Self {
        Self {
            exposure_ev: d.exposure_ev,
            tonemap: d.tonemap,
            channel: Channel::Rgb,
            false_color: false,
            range_log10: [-3.0, 1.0],
            nan_highlight: true,
        }
    }
}

/// One image of an A/B comparison.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum AbSource {
    Final,
    Direct,
    Indirect,
    /// The comparison ground truth of the same VPLs (GI), when it runs.
    GroundTruthIndirect,
    GroundTruthFinal,
    /// A snapshot taken earlier (`Renderer::take_snapshot`), by index.
    Snapshot(u32),
}

impl AbSource {
    pub const LIVE: [AbSource; 5] = [
        AbSource::Final,
        AbSource::Direct,
        AbSource::Indirect,
        AbSource::GroundTruthIndirect,
        AbSource::GroundTruthFinal,
    ];
    pub fn name(self) -> String {
        match self {
            AbSource::Final => "final".into(),
            AbSource::Direct => "direct only".into(),
            AbSource::Indirect => "GI only".into(),
            AbSource::GroundTruthIndirect => "ground truth: GI only".into(),
            AbSource::GroundTruthFinal => "ground truth: final".into(),
            AbSource::Snapshot(i) => format!("snapshot {}", i + 1),
        }
    }
}

/// How the A/B view shows its two images.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum AbMode {
    /// A left of the divider, B right of it (drag the divider).
    #[default]
    Split,
    /// A and B side by side (a twice-as-wide image).
    SideBySide,
    /// A alone (toggle with B: key T, or the flicker option).
    A,
    B,
    /// |A - B| x N through the view's exposure and tonemap.
    Difference,
    /// |lum(A) - lum(B)| / lum(B), log10 false colour from 1e-2 to 1e1.
    RelativeError,
}

impl AbMode {
    pub const ALL: [AbMode; 6] = [
        AbMode::Split,
        AbMode::SideBySide,
        AbMode::A,
        AbMode::B,
        AbMode::Difference,
        AbMode::RelativeError,
    ];
    /// Mode id of `shaders/compare_views.wgsl`.
    pub fn gpu_id(self) -> u32 {
        match self {
            AbMode::Split => 0,
            AbMode::RelativeError => 1,
            AbMode::SideBySide => 2,
            AbMode::Difference => 3,
            AbMode::A => 4,
            AbMode::B => 5,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            AbMode::Split => "split",
            AbMode::SideBySide => "side by side",
            AbMode::A => "A",
            AbMode::B => "B",
            AbMode::Difference => "difference x N",
            AbMode::RelativeError => "relative error",
        }
    }
}

/// The two images of the A/B view and how they are compared.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct AbSpec {
    pub a: AbSource,
    pub b: AbSource,
    pub mode: AbMode,
    /// Divider of the split mode (0 = left edge, 1 = right edge).
    pub split: f32,
    /// N of the difference mode.
    pub diff_scale: f32,
}

impl Default for AbSpec {
    fn default() -> Self {
        Self {
            a: AbSource::Indirect,
            b: AbSource::GroundTruthIndirect,
            mode: AbMode::Split,
            split: 0.5,
            diff_scale: 8.0,
        }
    }
}

/// Everything one image view needs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ViewSpec {
    pub buffer: ViewBuffer,
    pub look: ViewLook,
    /// Used when `buffer` is [`ViewBuffer::AbCompare`].
    pub ab: AbSpec,
}

impl Default for ViewSpec {
    fn default() -> Self {
        Self::new(ViewBuffer::Final, &DisplaySettings::default())
    }
}

impl ViewSpec {
    /// `buffer` with the global display look; the ground-truth comparison views map to their
    /// A/B equivalents.
    pub fn new(buffer: ViewBuffer, d: &DisplaySettings) -> Self {
        Self {
            buffer,
            look: ViewLook::from_display(d),
            ab: AbSpec {
                split: d.split,
                ..Default::default()
            },
        }
    }

    /// The A/B comparison this view draws, if it is one: the generic A/B view, or the fixed
    /// "sampler vs ground truth" views.
    pub fn effective_ab(&self) -> Option<AbSpec> {
        let gt = |mode| AbSpec {
            a: AbSource::Indirect,
            b: AbSource::GroundTruthIndirect,
            mode,
            ..self.ab
        };
        match self.buffer {
            ViewBuffer::AbCompare => Some(self.ab),
            ViewBuffer::SplitIndirect => Some(gt(AbMode::Split)),
            ViewBuffer::SideBySide => Some(gt(AbMode::SideBySide)),
            ViewBuffer::RelativeError => Some(gt(AbMode::RelativeError)),
            _ => None,
        }
    }
}

/// A radiance buffer copied for later comparison.
pub struct Snapshot {
    /// What it was (method, buffer, frame), for captions and the source list.
    pub label: String,
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
    pub size: (u32, u32),
}

/// At most this many snapshots are kept (the oldest is replaced).
pub const MAX_SNAPSHOTS: usize = 4;

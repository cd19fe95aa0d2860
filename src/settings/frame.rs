//! `[frame]`: what every method's frames share (how successive frames combine, the random
//! numbers), read by every per-frame method alike. Before issue 38 these two lived in the tree
//! samplers' `[sampling]`; `legacy` moves them here when an older file says so.

use serde::{Deserialize, Serialize};

/// Frame-wide settings of the per-frame methods.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FrameSettings {
    /// Average successive frames while the view, lights and settings stay (progressive);
    /// off shows each frame's estimate alone, as a real-time renderer would.
    pub accumulate: bool,
    /// The methods' random numbers are the same every frame (debugging: a pixel's story
    /// repeats); off, the seed changes per frame (needed to accumulate).
    pub fixed_seed: bool,
}

//! Lightcuts' settings (`[methods.lightcuts]` in a settings file).

use serde::{Deserialize, Serialize};

use crate::base::field::{self, Field};
use crate::reference::lightcuts::MAX_CUT;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LightcutsSettings {
    /// Refine while the largest error bound in the cut exceeds this fraction of the pixel's
    /// current estimate (0..=1). Lower: larger cuts, less error, more shadow rays. 0 refines
    /// until every remaining bound is 0 (up to `max_cut`). Default 0.01, as the Lightcut
    /// Interpolation paper's comparison (section 5); Walter et al. 2005 used 0.02.
    pub relative_error: f32,
    /// Largest cut (nodes per pixel, 1..=1024). Dark pixels reach it first (their threshold
    /// is small); the "lightcut at max cut" view and the status line show how often.
    /// Walter et al. cap cuts at 1000; default 256.
    pub max_cut: u32,
}

impl Default for LightcutsSettings {
    fn default() -> Self {
        Self {
            relative_error: 0.01,
            max_cut: 256,
        }
    }
}

/// The numeric settings, declared once (validation, the GUI's sliders, `--set`).
pub static FIELDS: &[Field<LightcutsSettings>] = &[
    crate::field!(
        LightcutsSettings,
        relative_error: f32,
        "relative error",
        "",
        0.0,
        1.0,
        Log,
        "refine while the largest error bound exceeds this fraction of the pixel's estimate \
         (Walter et al. 2%, the interpolation paper 1%)"
    ),
    crate::field!(
        LightcutsSettings,
        max_cut: u32,
        "max cut size",
        "nodes",
        1,
        MAX_CUT,
        Log,
        "nodes per pixel at most; dark pixels reach it first"
    ),
];

impl LightcutsSettings {
    /// Every field in range, or a message naming it.
    pub fn validate(&self) -> Result<(), String> {
        field::check("methods.lightcuts", FIELDS, self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_of_range_fields_are_named() {
        let ok = LightcutsSettings::default();
        assert!(ok.validate().is_ok());
        let e = LightcutsSettings {
            relative_error: f32::NAN,
            ..ok.clone()
        };
        assert!(e.validate().unwrap_err().contains("relative_error"));
        let e = LightcutsSettings {
            max_cut: MAX_CUT + 1,
            ..ok.clone()
        };
        assert!(e.validate().unwrap_err().contains("max_cut"));
        let e = LightcutsSettings { max_cut: 0, ..ok };
        assert!(e.validate().unwrap_err().contains("max_cut"));
    }
}

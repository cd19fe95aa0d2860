//! Lightcut Interpolation's settings (`[methods.lightcut-interpolation]` in a settings file).
//! Defaults follow Rehfeld & Dachsbacher 2016 where the paper gives a value (relative error
//! 1%, R- = 4 and R+ = 15 pixel sizes, a+ = 15 degrees); where it does not (epsilon, the
//! placement's coverage, the rays for R) the choice is ours and documented.

use serde::{Deserialize, Serialize};

use crate::base::field::{self, Field};
use crate::reference::lightcuts::MAX_CUT;

/// How an interpolated cut's nodes are shadowed (the paper evaluates both, section 6).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LiVisibility {
    /// One shadow ray per node of the interpolated cut ("full visibility").
    #[default]
    Full,
    /// The records' visibility bits interpolated with the nodes ("interpolated visibility").
    Interpolated,
}

impl LiVisibility {
    pub fn label(self) -> &'static str {
        match self {
            LiVisibility::Full => "full (shadow rays)",
            LiVisibility::Interpolated => "interpolated",
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LightcutInterpolationSettings {
    /// The records' (and the fallback's) Lightcuts threshold (0..=1; the paper's 1%).
    pub relative_error: f32,
    /// Largest cut of a record or fallback pixel (1..=1024).
    pub max_cut: u32,
    /// Shadow rays per interpolated node, or interpolated visibility.
    pub visibility: LiVisibility,
    /// R-: the smallest record reach in pixel sizes (paper 4).
    pub r_min_px: f32,
    /// R+: the largest record reach in pixel sizes (paper 15). With r_min_px the record
    /// density's knob (results' sweep scales both).
    pub r_max_px: f32,
    /// a+: records whose normal deviates more are rejected (degrees, paper 15).
    pub max_angle_deg: f32,
    /// A pixel whose best record weight is below this computes a full lightcut (0..1; the
    /// paper names the threshold without a value; ours 0.05).
    pub epsilon: f32,
    /// Placement: a tile's pixel is covered once its records' weights sum to this (0..=4;
    /// ours 1: on a record, or near several).
    pub coverage: f32,
    /// Hemisphere rays per pixel for the harmonic mean distance R (1..=256; ours 16).
    pub radius_rays: u32,
}

impl Default for LightcutInterpolationSettings {
    fn default() -> Self {
        Self {
            relative_error: 0.01,
            max_cut: 256,
            visibility: LiVisibility::Full,
            r_min_px: 4.0,
            r_max_px: 15.0,
            max_angle_deg: 15.0,
            epsilon: 0.05,
            coverage: 1.0,
            radius_rays: 16,
        }
    }
}

type Li = LightcutInterpolationSettings;

/// The numeric settings, declared once (validation, the GUI's sliders, `--set`).
pub static FIELDS: &[Field<Li>] = &[
    crate::field!(
        Li,
        relative_error: f32,
        "record relative error",
        "",
        0.0,
        1.0,
        Log,
        "the records' (and fallback's) Lightcuts threshold (paper 1%)"
    ),
    crate::field!(Li, max_cut: u32, "max cut size", "nodes", 1, MAX_CUT, Log, "nodes per record or fallback pixel at most"),
    crate::field!(
        Li,
        r_min_px: f32,
        "R-",
        "pixels",
        0.25,
        256.0,
        Log,
        "smallest record reach in pixel sizes (paper 4)"
    ),
    crate::field!(
        Li,
        r_max_px: f32,
        "R+",
        "pixels",
        0.25,
        256.0,
        Log,
        "largest record reach in pixel sizes (paper 15): fewer records when larger; at least R-"
    ),
    crate::field!(
        Li,
        max_angle_deg: f32,
        "a+",
        "degrees",
        1.0,
        90.0,
        Linear,
        "records whose normal deviates more are rejected (paper 15)"
    ),
    crate::field!(
        Li,
        epsilon: f32,
        "fallback epsilon",
        "",
        0.0,
        0.99,
        Linear,
        "pixels whose best record weight is below this compute a full lightcut"
    ),
    crate::field!(
        Li,
        coverage: f32,
        "placement coverage",
        "",
        0.01,
        4.0,
        Linear,
        "a pixel is covered once its tile's records' weights sum to this"
    ),
    crate::field!(
        Li,
        radius_rays: u32,
        "rays for R",
        "",
        1,
        256,
        Log,
        "hemisphere rays per pixel for the harmonic mean distance"
    ),
];

impl LightcutInterpolationSettings {
    /// Every field in range, or a message naming it.
    pub fn validate(&self) -> Result<(), String> {
        field::check("methods.lightcut-interpolation", FIELDS, self)?;
        if self.r_max_px < self.r_min_px {
            return Err(format!(
                "methods.lightcut-interpolation.r_max_px {} is below r_min_px {}",
                self.r_max_px, self.r_min_px
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_of_range_fields_are_named() {
        let ok = LightcutInterpolationSettings::default();
        assert!(ok.validate().is_ok());
        let cases: Vec<(LightcutInterpolationSettings, &str)> = vec![
            (
                LightcutInterpolationSettings {
                    relative_error: 2.0,
                    ..ok.clone()
                },
                "relative_error",
            ),
            (
                LightcutInterpolationSettings {
                    max_cut: 0,
                    ..ok.clone()
                },
                "max_cut",
            ),
            (
                LightcutInterpolationSettings {
                    r_max_px: 2.0,
                    ..ok.clone()
                },
                "r_max_px",
            ),
            (
                LightcutInterpolationSettings {
                    max_angle_deg: f32::NAN,
                    ..ok.clone()
                },
                "max_angle_deg",
            ),
            (
                LightcutInterpolationSettings {
                    epsilon: 1.0,
                    ..ok.clone()
                },
                "epsilon",
            ),
            (
                LightcutInterpolationSettings {
                    radius_rays: 0,
                    ..ok.clone()
                },
                "radius_rays",
            ),
        ];
        for (s, field) in cases {
            let e = s.validate().unwrap_err();
            assert!(e.contains(field), "{e} does not name {field}");
        }
    }

    #[test]
    fn visibility_reads_from_toml() {
        let s: LightcutInterpolationSettings = toml::from_str("visibility = \"interpolated\"").unwrap();
        assert_eq!(s.visibility, LiVisibility::Interpolated);
        assert!(toml::from_str::<LightcutInterpolationSettings>("visibility = \"some\"").is_err());
    }
}

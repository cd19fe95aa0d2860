//! Stochastic Light Culling's settings (`[methods.light-culling]` in a settings file; the
//! clamped baseline `light-culling-clamped` reads the same table, so both run at the same
//! error bound, as the paper compares them).

use serde::{Deserialize, Serialize};

use crate::base::field::{self, Field};

pub use crate::settings::{Interleave8, InterleaveSettings, IsmAdaptive, IsmSettings, MAX_FILTER_RADIUS};

/// Largest interleaving pattern edge (n x n subsets).
pub const MAX_INTERLEAVE: u32 = 16;
/// Largest light list per tile.
pub const MAX_LIST: u32 = 1 << 16;
/// Largest per-pixel light list of the tree variant (its reservoir's k).
pub const MAX_RESERVOIR: u32 = 256;

/// How a VPL's visibility is tested while `gi.shadow_rays` is on (`render --visibility
/// rays|ism`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CullingVisibility {
    /// A BVH shadow ray per VPL in range (exact).
    #[default]
    Rays,
    /// A lookup in the VPL's imperfect shadow map (section 4.4's AISMs, built each frame
    /// from the scene's point cloud with section 4.3's culling by the VPL's range; `ism`).
    Ism,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LightCullingSettings {
    /// The user's error bound eps_max (section 3.2, eq. 6) in display units: the largest
    /// standard deviation one VPL may add to a pixel's exposed radiance E x L, with E the
    /// display exposure 2^`display.exposure_ev` (alpha from the VPL's own flux, as the paper;
    /// with n x n interleaving a pixel's unfiltered estimate carries n^2 x that, which the
    /// filter's average over the pattern brings back). Larger: smaller ranges, fewer VPLs per
    /// pixel, more noise (stochastic) or more darkening (clamped, appendix A: the sum of all
    /// VPLs' darkening at most eps_max). Paper's real-time results: 0.0005.
    pub epsilon_max: f32,
    /// Tile edge in pixels of the de-interleaved image (paper 16; 4..=32).
    pub tile_size: u32,
    /// Light indices a tile's list holds (paper: 1024 with 8 x 8 interleaving). A tile with
    /// more lights in range is counted and shown ("culling overflow" view) and shaded by
    /// testing every VPL of its subset: slower, never wrong.
    pub max_lights_per_tile: u32,
    /// Interleaved sampling (section 4.2): an n x n pattern whose pixels each take a
    /// disjoint 1 / n^2 of the VPLs (scaled by n^2), then the geometry-aware filter
    /// (`[methods.light-culling.interleave]`). Paper: n = 8, a 17 x 17 filter (r = 8). The
    /// filter's normal and plane tests also serve the tree variant.
    pub interleave: InterleaveSettings<Interleave8>,
    /// The bounding-sphere-tree variant (section 5, `light-culling-tree`): the per-pixel
    /// light list's k, filled by reservoir sampling during the traversal (5.3.1, Algorithm
    /// 3). Paper 32.
    pub reservoir_k: u32,
    /// The tree variant's geometry-aware filter radius (it has no interleaving to undo;
    /// the paper's path tracer filters nothing: 0).
    pub tree_filter_radius: u32,
    /// Visibility while `gi.shadow_rays` is on: BVH shadow rays, or imperfect shadow maps
    /// (one per VPL, `ism`). The ground truth always traces rays, so the comparison shows
    /// the maps' error.
    pub visibility: CullingVisibility,
    /// The imperfect shadow maps of `visibility = "ism"` (`[methods.light-culling.ism]`):
    /// the paper's adaptive ISMs, 8192 points per VPL on 32^2 maps (section 4.4), one map
    /// per VPL (the tree variant: per leaf), so the atlas must hold the frame's VPLs.
    pub ism: IsmSettings<IsmAdaptive>,
    /// Section 4.3's point-cloud culling: a VPL's map leaves out the points beyond its
    /// stochastic (or clamped) range, where its fall-off is 0 anyway. Off splats every point
    /// of the map's share (the paper's figure 7 compares the two).
    pub ism_range_culling: bool,
}

impl Default for LightCullingSettings {
    fn default() -> Self {
        Self {
            epsilon_max: 0.0005,
            tile_size: 16,
            max_lights_per_tile: 1024,
            interleave: InterleaveSettings::pattern(8),
            reservoir_k: 32,
            tree_filter_radius: 0,
            visibility: CullingVisibility::Rays,
            ism: IsmSettings::default(),
            ism_range_culling: true,
        }
    }
}

/// The numeric settings, declared once (validation, the GUI's sliders, `--set`).
pub static FIELDS: &[Field<LightCullingSettings>] = &[
    crate::field!(
        LightCullingSettings,
        epsilon_max: f32,
        "error bound eps_max",
        "",
        0.0,
        1.0,
        Log,
        "largest standard deviation per VPL (stochastic; in the filtered image) or total darkening \
         (clamped) in exposed display units (paper 0.0005); shared by the variants",
        open
    ),
    crate::field!(
        LightCullingSettings,
        tile_size: u32,
        "tile size",
        "pixels",
        4,
        32,
        Linear,
        "tile edge of the de-interleaved image (paper 16)"
    ),
    crate::field!(
        LightCullingSettings,
        max_lights_per_tile: u32,
        "max lights per tile",
        "",
        1,
        MAX_LIST,
        Log,
        "an overflowing tile is shaded by testing all its subset's VPLs (counted, shown)"
    ),
    crate::field!(
        LightCullingSettings,
        reservoir_k: u32,
        "light list k",
        "",
        1,
        MAX_RESERVOIR,
        Log,
        "per-pixel list filled by reservoir sampling during the tree traversal (paper 32); one \
         listed VPL is shaded by resampled importance sampling (one shadow ray)"
    ),
    crate::field!(
        LightCullingSettings,
        tree_filter_radius: u32,
        "filter radius",
        "pixels",
        0,
        MAX_FILTER_RADIUS,
        Linear,
        "the tree variant's geometry-aware filter window (2r+1)^2 (0 = off, as the paper's path tracer)"
    ),
];

impl LightCullingSettings {
    /// Every field in range, or a message naming it.
    pub fn validate(&self) -> Result<(), String> {
        field::check("methods.light-culling", FIELDS, self)?;
        self.interleave
            .validate("methods.light-culling", MAX_INTERLEAVE)?;
        self.ism.validate("methods.light-culling")
    }

    /// Whether the frame looks VPLs up in imperfect shadow maps (`shadow_rays`: `gi.shadow_rays`).
    pub fn uses_ism(&self, shadow_rays: bool) -> bool {
        shadow_rays && self.visibility == CullingVisibility::Ism
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_partial_interleave_table_keeps_the_methods_defaults() {
        // Light culling interleaves 8 x 8 unless told otherwise (the tree samplers' own test:
        // they do not).
        let lc: LightCullingSettings = toml::from_str("[interleave]\nfilter_radius = 4").unwrap();
        assert_eq!((lc.interleave.n, lc.interleave.filter_radius), (8, 4));
    }

    #[test]
    fn a_partial_ism_table_keeps_the_adaptive_maps_defaults() {
        // Light culling's maps are the paper's AISMs (32^2, 8192 points each), whatever
        // fields a table leaves out; the VAL defaults are 128^2 maps sharing the cloud.
        let lc: LightCullingSettings = toml::from_str("visibility = \"ism\"\n[ism]\nbias = 0.03").unwrap();
        assert_eq!(lc.visibility, CullingVisibility::Ism);
        assert_eq!(
            (lc.ism.tile, lc.ism.points_per_light, lc.ism.bias),
            (32, 8192, 0.03)
        );
        let val: IsmSettings = IsmSettings::default();
        assert_eq!((val.tile, val.points_per_light), (128, 0));
        assert!(lc.uses_ism(true) && !lc.uses_ism(false));
        let back: LightCullingSettings = toml::from_str(&toml::to_string(&lc).unwrap()).unwrap();
        assert_eq!(back, lc);
    }

    #[test]
    fn out_of_range_fields_are_named() {
        let ok = LightCullingSettings::default();
        assert!(ok.validate().is_ok());
        let cases: Vec<(LightCullingSettings, &str)> = vec![
            (
                LightCullingSettings {
                    epsilon_max: 0.0,
                    ..ok.clone()
                },
                "epsilon_max",
            ),
            (
                LightCullingSettings {
                    epsilon_max: f32::NAN,
                    ..ok.clone()
                },
                "epsilon_max",
            ),
            (
                LightCullingSettings {
                    tile_size: 2,
                    ..ok.clone()
                },
                "tile_size",
            ),
            (
                LightCullingSettings {
                    max_lights_per_tile: 0,
                    ..ok.clone()
                },
                "max_lights_per_tile",
            ),
            (
                LightCullingSettings {
                    interleave: InterleaveSettings {
                        n: 0,
                        ..ok.interleave.clone()
                    },
                    ..ok.clone()
                },
                "interleave.n",
            ),
            (
                LightCullingSettings {
                    interleave: InterleaveSettings {
                        filter_radius: 99,
                        ..ok.interleave.clone()
                    },
                    ..ok.clone()
                },
                "filter_radius",
            ),
            (
                LightCullingSettings {
                    interleave: InterleaveSettings {
                        filter_normal_cos: 2.0,
                        ..ok.interleave.clone()
                    },
                    ..ok.clone()
                },
                "filter_normal_cos",
            ),
            (
                LightCullingSettings {
                    interleave: InterleaveSettings {
                        filter_plane_tolerance: -1.0,
                        ..ok.interleave.clone()
                    },
                    ..ok.clone()
                },
                "filter_plane_tolerance",
            ),
            (
                LightCullingSettings {
                    reservoir_k: 0,
                    ..ok.clone()
                },
                "reservoir_k",
            ),
            (
                LightCullingSettings {
                    tree_filter_radius: 17,
                    ..ok.clone()
                },
                "tree_filter_radius",
            ),
            (
                LightCullingSettings {
                    ism: IsmSettings {
                        tile: 48,
                        ..ok.ism.clone()
                    },
                    ..ok.clone()
                },
                "methods.light-culling.ism.tile",
            ),
        ];
        for (s, name) in cases {
            let e = s.validate().unwrap_err();
            assert!(e.contains(name), "{e}");
        }
    }
}

//! Stochastic Light Culling's settings (`[methods.light-culling]` in a settings file; the
//! clamped baseline `light-culling-clamped` reads the same table, so both run at the same
//! error bound, as the paper compares them).

use serde::{Deserialize, Serialize};

/// Largest interleaving pattern edge (n x n subsets).
pub const MAX_INTERLEAVE: u32 = 16;
/// Largest light list per tile.
pub const MAX_LIST: u32 = 1 << 16;
/// Largest filter radius (a (2r + 1)^2 window).
pub const MAX_FILTER_RADIUS: u32 = 16;
/// Largest per-pixel light list of the tree variant (its reservoir's k).
pub const MAX_RESERVOIR: u32 = 256;

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
    /// disjoint 1 / n^2 of the VPLs (scaled by n^2), then the geometry-aware filter. 1 = off.
    /// Paper 8.
    pub interleave: u32,
    /// Radius r of the geometry-aware filter's (2r + 1)^2 window (paper 17 x 17: 8); 0 = no
    /// filter (each pixel keeps its own subset's estimate).
    pub filter_radius: u32,
    /// The filter averages neighbours whose normal is within this cosine of the pixel's.
    pub filter_normal_cos: f32,
    /// ... and whose distance to the pixel's tangent plane is below this fraction of its view
    /// depth.
    pub filter_plane_tolerance: f32,
    /// The bounding-sphere-tree variant (section 5, `light-culling-tree`): the per-pixel
    /// light list's k, filled by reservoir sampling during the traversal (5.3.1, Algorithm
    /// 3). Paper 32.
    pub reservoir_k: u32,
    /// The tree variant's geometry-aware filter radius (it has no interleaving to undo;
    /// the paper's path tracer filters nothing: 0).
    pub tree_filter_radius: u32,
}

impl Default for LightCullingSettings {
    fn default() -> Self {
        Self {
            epsilon_max: 0.0005,
            tile_size: 16,
            max_lights_per_tile: 1024,
            interleave: 8,
            filter_radius: 8,
            filter_normal_cos: 0.9,
            filter_plane_tolerance: 0.02,
            reservoir_k: 32,
            tree_filter_radius: 0,
        }
    }
}

impl LightCullingSettings {
    /// Every field in range, or a message naming it.
    pub fn validate(&self) -> Result<(), String> {
        let f = |name: &str, v: String, range: &str| {
            Err(format!(
                "methods.light-culling.{name} {v} is out of range ({range})"
            ))
        };
        if !(self.epsilon_max > 0.0 && self.epsilon_max <= 1.0) {
            return f("epsilon_max", self.epsilon_max.to_string(), "0 < e <= 1");
        }
        if !(4..=32).contains(&self.tile_size) {
            return f("tile_size", self.tile_size.to_string(), "4..=32");
        }
        if !(1..=MAX_LIST).contains(&self.max_lights_per_tile) {
            return f(
                "max_lights_per_tile",
                self.max_lights_per_tile.to_string(),
                &format!("1..={MAX_LIST}"),
            );
        }
        if !(1..=MAX_INTERLEAVE).contains(&self.interleave) {
            return f(
                "interleave",
                self.interleave.to_string(),
                &format!("1..={MAX_INTERLEAVE}"),
            );
        }
        if self.filter_radius > MAX_FILTER_RADIUS {
            return f(
                "filter_radius",
                self.filter_radius.to_string(),
                &format!("0..={MAX_FILTER_RADIUS}"),
            );
        }
        if !(-1.0..=1.0).contains(&self.filter_normal_cos) {
            return f("filter_normal_cos", self.filter_normal_cos.to_string(), "-1..=1");
        }
        if !(0.0..=1.0).contains(&self.filter_plane_tolerance) {
            return f(
                "filter_plane_tolerance",
                self.filter_plane_tolerance.to_string(),
                "0..=1",
            );
        }
        if !(1..=MAX_RESERVOIR).contains(&self.reservoir_k) {
            return f(
                "reservoir_k",
                self.reservoir_k.to_string(),
                &format!("1..={MAX_RESERVOIR}"),
            );
        }
        if self.tree_filter_radius > MAX_FILTER_RADIUS {
            return f(
                "tree_filter_radius",
                self.tree_filter_radius.to_string(),
                &format!("0..={MAX_FILTER_RADIUS}"),
            );
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
                    interleave: 0,
                    ..ok.clone()
                },
                "interleave",
            ),
            (
                LightCullingSettings {
                    filter_radius: 99,
                    ..ok.clone()
                },
                "filter_radius",
            ),
            (
                LightCullingSettings {
                    filter_normal_cos: 2.0,
                    ..ok.clone()
                },
                "filter_normal_cos",
            ),
            (
                LightCullingSettings {
                    filter_plane_tolerance: -1.0,
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
        ];
        for (s, name) in cases {
            let e = s.validate().unwrap_err();
            assert!(e.contains(name), "{e}");
        }
    }
}

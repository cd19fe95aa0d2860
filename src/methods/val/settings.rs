//! The VAL method's settings (`[methods.val]` in a settings file; `val-vpl`, the same pipeline
//! shading every VAL as a point light, reads the same table so that the two compare on the same
//! clusters).

use serde::{Deserialize, Serialize};

use crate::base::field::{self, Field};

use crate::reference::val::{ClusterParams, MAX_CLUSTERS, MetricWeights, POISSON, Pcss};
pub use crate::settings::{Interleave4, InterleaveSettings, IsmSettings, IsmVal};

pub const MAX_INTERLEAVE: u32 = 16;
pub const MAX_ITERATIONS: u32 = 16;
pub const MAX_SPLAT: u32 = 512;

/// How a VAL is shadowed (while `gi.shadow_rays` is on; off: every VAL visible).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ValVisibility {
    /// One lookup in the VAL's imperfect shadow map (section 5; the paper's "simple" lookup).
    Ism,
    /// The PCSS-style lookup in its map (section 6: blocker search, eq. 3, Poisson PCF), the
    /// paper's answer to few VALs.
    #[default]
    Pcss,
    /// A BVH shadow ray to the VAL's centre (a point light's visibility).
    Rays,
    /// 16 BVH shadow rays to points of the VAL's disk: its visible fraction, the exact
    /// visibility that separates the maps' error from the clustering's (Table 1's reference).
    Disk,
}

impl ValVisibility {
    pub fn name(self) -> &'static str {
        match self {
            ValVisibility::Ism => "ism",
            ValVisibility::Pcss => "pcss",
            ValVisibility::Rays => "rays",
            ValVisibility::Disk => "disk",
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ValSettings {
    /// VALs (clusters) per frame, seeded at this many of the frame's VPLs (spread over them;
    /// the paper: 64 with PCSS, 512 with simple lookups; up to 1024, one map each).
    pub clusters: u32,
    /// Edge of the RSM the clustering runs on: light 0's RSM summed down to it (at most the
    /// RSM's; `reference::val::downsample`). The paper clusters a low-resolution RSM without
    /// naming its size.
    pub resolution: u32,
    /// Edge of a cluster's splat window in clustering-RSM texels (the paper: 32 - 128 pixel splats).
    pub splat: u32,
    /// k-means steps per frame (the paper runs one per frame and carries the clusters over).
    pub iterations: u32,
    /// Start each frame's steps from the last frame's clusters (their empty ones re-seeded)
    /// instead of the frame's seeds: the paper's, with `iterations` 1, converging over frames.
    /// Off: every frame clusters afresh from its seeds (no history: nothing lags when the sun
    /// moves).
    pub carry_over: bool,
    /// Eq. 1's convex weights (position, normal, flux).
    pub weights: MetricWeights,
    pub visibility: ValVisibility,
    /// The PCSS lookup's samples and its largest filter radius.
    pub pcss: Pcss,
    pub interleave: InterleaveSettings<Interleave4>,
    /// The geometry-aware filter's window: the paper's n x n (one pixel of each interleaving
    /// subset, equal weights: section 6's "filter of size n x m"); off: the shared (2r + 1)^2
    /// window of `interleave.filter_radius`, whose odd edge weights the subsets unevenly and
    /// leaves an n-periodic pattern.
    pub paper_filter: bool,
    /// The VALs' imperfect shadow maps (the paper's 128^2 maps in a 4096^2 atlas, the cloud
    /// shared round-robin, 2 pull-push iterations).
    pub ism: IsmSettings<IsmVal>,
    /// The VAL whose map the "VAL ISM vs true map" view shows.
    pub inspect: u32,
}

impl Default for ValSettings {
    fn default() -> Self {
        Self {
            clusters: 64,
            resolution: 128,
            splat: 32,
            iterations: 4,
            carry_over: false,
            weights: MetricWeights::default(),
            visibility: ValVisibility::Pcss,
            pcss: Pcss::default(),
            interleave: InterleaveSettings::pattern(4),
            paper_filter: true,
            ism: IsmSettings::default(),
            inspect: 0,
        }
    }
}

/// Samples of the PCSS Poisson disk.
const POISSON_N: u32 = POISSON.len() as u32;

/// The numeric settings, declared once (validation, the GUI's sliders, `--set`).
pub static FIELDS: &[Field<ValSettings>] = &[
    crate::field!(
        ValSettings,
        clusters: u32,
        "VALs",
        "",
        1,
        MAX_CLUSTERS,
        Log,
        "clusters of the RSM, one map each (paper: 64 with PCSS, 512 with simple lookups)"
    ),
    crate::field!(
        ValSettings,
        resolution: u32,
        "clustering RSM",
        "texels",
        8,
        1024,
        Pow2,
        "the RSM is summed down to this many texels a side before clustering (flux and area kept)"
    ),
    crate::field!(
        ValSettings,
        splat: u32,
        "splat",
        "RSM texels",
        1,
        MAX_SPLAT,
        Log,
        "edge of a cluster's splat window: texels beyond it join a cluster only by the fallback (paper 32 - 128)"
    ),
    crate::field!(
        ValSettings,
        iterations: u32,
        "k-means steps",
        "",
        1,
        MAX_ITERATIONS,
        Linear,
        "clustering steps per frame, from the frame's seeds or the last frame's clusters (the paper: one per frame, carried over)"
    ),
    crate::field!(
        ValSettings,
        weights.position: f32,
        "eq. 1 position weight",
        "",
        0.0,
        1.0,
        Linear,
        "eq. 1's weight of the position distance (at least one weight > 0)"
    ),
    crate::field!(
        ValSettings,
        weights.normal: f32,
        "eq. 1 normal weight",
        "",
        0.0,
        1.0,
        Linear,
        "eq. 1's weight of the normal distance"
    ),
    crate::field!(
        ValSettings,
        weights.flux: f32,
        "eq. 1 flux weight",
        "",
        0.0,
        1.0,
        Linear,
        "eq. 1's weight of the flux distance"
    ),
    crate::field!(
        ValSettings,
        pcss.blocker_samples: u32,
        "blocker samples",
        "",
        1,
        POISSON_N,
        Linear,
        "Poisson samples of the PCSS blocker search"
    ),
    crate::field!(
        ValSettings,
        pcss.pcf_samples: u32,
        "PCF samples",
        "",
        1,
        POISSON_N,
        Linear,
        "Poisson samples of the PCSS filter"
    ),
    crate::field!(
        ValSettings,
        pcss.max_radius: f32,
        "largest filter",
        "texels",
        1.0,
        64.0,
        Linear,
        "the PCSS filter's largest radius"
    ),
    crate::field!(
        ValSettings,
        inspect: u32,
        "VAL inspected",
        "",
        0,
        MAX_CLUSTERS - 1,
        Linear,
        "the VAL whose map the 'VAL ISM vs true map' view shows (below the VAL count)"
    ),
];

impl ValSettings {
    pub fn cluster_params(&self) -> ClusterParams {
        ClusterParams {
            splat: self.splat,
            weights: self.weights,
        }
    }

    pub fn validate(&self) -> Result<(), String> {
        field::check("methods.val", FIELDS, self)?;
        let w = self.weights;
        if w.position + w.normal + w.flux <= 0.0 {
            return Err("methods.val.weights: at least one of position, normal, flux must be > 0".into());
        }
        self.interleave.validate("methods.val", MAX_INTERLEAVE)?;
        self.ism.validate("methods.val")?;
        if self.clusters > self.ism.capacity() {
            return Err(format!(
                "methods.val.clusters {} exceeds the ISM atlas's {} maps (an atlas of {} with {} x {} \
                 maps; raise methods.val.ism.atlas or lower ism.tile)",
                self.clusters,
                self.ism.capacity(),
                self.ism.atlas,
                self.ism.tile,
                self.ism.tile
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_papers_and_partial_tables_keep_them() {
        let v: ValSettings =
            toml::from_str("clusters = 512\nvisibility = \"ism\"\n[ism]\nbias = 0.05").unwrap();
        assert_eq!((v.clusters, v.visibility), (512, ValVisibility::Ism));
        assert_eq!((v.ism.tile, v.ism.atlas, v.ism.pull_push_levels), (128, 4096, 2));
        assert_eq!(v.interleave.n, 4);
        assert!(v.validate().is_ok());
        let back: ValSettings = toml::from_str(&toml::to_string(&v).unwrap()).unwrap();
        assert_eq!(back, v);
    }

    #[test]
    fn out_of_range_fields_are_named() {
        let ok = ValSettings::default();
        assert!(ok.validate().is_ok());
        let cases: Vec<(ValSettings, &str)> = vec![
            (
                ValSettings {
                    clusters: 0,
                    ..ok.clone()
                },
                "clusters",
            ),
            (
                ValSettings {
                    clusters: 2000,
                    ..ok.clone()
                },
                "clusters",
            ),
            (
                ValSettings {
                    splat: 0,
                    ..ok.clone()
                },
                "splat",
            ),
            (
                ValSettings {
                    iterations: 0,
                    ..ok.clone()
                },
                "iterations",
            ),
            (
                ValSettings {
                    weights: MetricWeights {
                        position: 2.0,
                        ..ok.weights
                    },
                    ..ok.clone()
                },
                "weights.position",
            ),
            (
                ValSettings {
                    weights: MetricWeights {
                        position: 0.0,
                        normal: 0.0,
                        flux: 0.0,
                    },
                    ..ok.clone()
                },
                "weights",
            ),
            (
                ValSettings {
                    pcss: Pcss {
                        pcf_samples: 0,
                        ..ok.pcss
                    },
                    ..ok.clone()
                },
                "pcss.pcf_samples",
            ),
            (
                ValSettings {
                    pcss: Pcss {
                        max_radius: f32::NAN,
                        ..ok.pcss
                    },
                    ..ok.clone()
                },
                "pcss.max_radius",
            ),
            (
                ValSettings {
                    ism: IsmSettings {
                        tile: 256,
                        ..ok.ism.clone()
                    },
                    clusters: 512,
                    ..ok.clone()
                },
                "clusters",
            ),
        ];
        for (s, field) in cases {
            let e = s.validate().unwrap_err();
            assert!(e.contains(field), "{e} should name {field}");
        }
    }
}

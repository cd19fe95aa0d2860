//! Settings of the shared passes a method's table may hold: interleaved sampling and its filter
//! ([`InterleaveSettings`]) and imperfect shadow maps ([`IsmSettings`]), each with the method's
//! defaults as a type parameter.

use super::*;

/// Interleaved sampling and its geometry-aware filter (Stochastic Light Culling, section 4.2,
/// after Keller & Heidrich 2001 and Segovia et al. 2006): a method's table holds one
/// (`[methods.light-culling.interleave]`, `[sampling.interleave]`), the shared pass
/// `renderer::passes::interleave_filter` undoes the pattern. `D` names the method's default
/// pattern (light culling 8 x 8, the tree samplers off): a table that sets only some fields
/// keeps the method's defaults for the others.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields, bound = "")]
pub struct InterleaveSettings<D: PatternDefault = InterleaveOff> {
    /// The n x n pattern: each pixel of it takes a disjoint 1 / n^2 of the method's lights
    /// (light culling: VPLs; the tree samplers: cut slots) scaled by n^2, the subsets shifted
    /// by a random offset each frame. 1 = off.
    pub n: u32,
    /// Radius r of the filter's (2r + 1)^2 window (the paper: 8 x 8 interleaving, 17 x 17
    /// filter, r = 8); 0 = no filter (each pixel keeps its own subset's estimate: the pattern
    /// shows).
    pub filter_radius: u32,
    /// The filter averages neighbours whose normal is within this cosine of the pixel's ...
    pub filter_normal_cos: f32,
    /// ... and whose distance to the pixel's tangent plane is below this fraction of its view
    /// depth.
    pub filter_plane_tolerance: f32,
    #[serde(skip)]
    pub _default: std::marker::PhantomData<D>,
}

/// A method's default interleaving pattern edge (a marker type per default: serde cannot
/// derive for const generics).
pub trait PatternDefault: Clone + std::fmt::Debug + PartialEq {
    const N: u32;
}

/// No interleaving by default (the tree samplers: the thesis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InterleaveOff;
impl PatternDefault for InterleaveOff {
    const N: u32 = 1;
}

/// 8 x 8 by default (Stochastic Light Culling's real-time results).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interleave8;
impl PatternDefault for Interleave8 {
    const N: u32 = 8;
}

/// 4 x 4 by default (the VAL method: the paper's split G-buffer of n x m tiles leaves n open;
/// 64 VALs then give each pixel 4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interleave4;
impl PatternDefault for Interleave4 {
    const N: u32 = 4;
}

/// Largest filter radius (a (2r + 1)^2 window).
pub const MAX_FILTER_RADIUS: u32 = 16;

impl<D: PatternDefault> InterleaveSettings<D> {
    /// The pattern of edge n with the paper's filter (r = n; none for n = 1).
    pub fn pattern(n: u32) -> Self {
        Self {
            n,
            filter_radius: if n > 1 { n } else { 0 },
            filter_normal_cos: 0.9,
            filter_plane_tolerance: 0.02,
            _default: std::marker::PhantomData,
        }
    }
    /// Whether the filter pass runs: a pattern to undo or a filter asked for.
    pub fn filters(&self) -> bool {
        self.n > 1 || self.filter_radius > 0
    }
    /// The numeric settings, declared once (validation, the GUI's sliders, `--set`); the
    /// pattern's largest edge is the method's.
    pub fn fields(max_n: u32) -> Vec<Field<Self>> {
        vec![
            crate::field!(
                Self,
                n: u32,
                "interleave n (n x n)",
                "",
                1,
                max_n,
                Linear,
                "each pixel of an n x n pattern takes a disjoint 1/n^2 of the method's lights (x n^2), \
                 the subsets shifted each frame; the filter then averages the pattern (1 = off)"
            ),
            crate::field!(
                Self,
                filter_radius: u32,
                "filter radius",
                "pixels",
                0,
                MAX_FILTER_RADIUS,
                Linear,
                "geometry-aware filter window (2r+1)^2 (the paper: 17 x 17 for 8 x 8, r = n; 0 = off)"
            ),
            crate::field!(
                Self,
                filter_normal_cos: f32,
                "filter normal cos",
                "",
                -1.0,
                1.0,
                Linear,
                "neighbours whose normal is farther from the pixel's than this cosine are skipped"
            ),
            crate::field!(
                Self,
                filter_plane_tolerance: f32,
                "filter plane tolerance",
                "x depth",
                0.0,
                1.0,
                Log,
                "neighbours farther from the pixel's tangent plane than this x depth are skipped"
            ),
        ]
    }

    /// Every field in range, or a message naming `table.interleave.<field>`.
    pub fn validate(&self, table: &str, max_n: u32) -> Result<(), String> {
        field::check(&format!("{table}.interleave"), &Self::fields(max_n), self)
    }
}

impl<D: PatternDefault> Default for InterleaveSettings<D> {
    fn default() -> Self {
        Self::pattern(D::N)
    }
}

/// Imperfect shadow maps (`renderer::passes::ism`; the VAL paper's section 5, Ritschel et al.
/// 2008): a visibility component for methods with many oriented point lights. A method's
/// table holds one (`[methods.light-culling.ism]`); `D` names its defaults (the VAL paper's
/// 128^2 maps sharing the cloud round-robin, or Stochastic Light Culling's adaptive 32^2 maps
/// of 8192 points each), so that a table setting only some fields keeps the method's
/// defaults for the others.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields, bound = "")]
pub struct IsmSettings<D: IsmDefault = IsmVal> {
    /// Points sampled once on the scene's triangles (area-uniform); map i receives every
    /// N-th of them (N lights) unless `points_per_light` says otherwise. More points: fewer
    /// holes, a slower splat.
    pub points: u32,
    /// 0: the lights share the cloud out round-robin (the VAL paper). Otherwise each map takes
    /// this many points spread over the cloud, those within its light's range
    /// (Stochastic Light Culling's adaptive ISMs, section 4.3: 8192 per VPL on 32^2 maps).
    pub points_per_light: u32,
    /// Atlas edge in texels (the paper: 4096).
    pub atlas: u32,
    /// One map's edge (the paper: 128; the atlas holds (atlas / tile)^2 maps: 1024).
    pub tile: u32,
    /// Pull-push levels (the paper: 2 iterations): holes up to about 2^levels texels wide
    /// are filled.
    pub pull_push_levels: u32,
    /// Relative depth bias of the lookup: a point is lit when its distance x (1 - bias) is
    /// at most the map's (the receiver's own points are in the map).
    pub bias: f32,
    /// Front-face culling (Stochastic Light Culling's Program 1): a map leaves out the points
    /// whose surface faces its light, so that lit surfaces do not shadow themselves; one-sided
    /// occluders facing the light then cast no shadow. The VAL paper: off; light culling: on.
    pub front_face_culling: bool,
    /// A point's world radius as a multiple of the cloud's area-derived radius sqrt(A / (pi
    /// N)) (A the scene's surface area, N the points per map): near points cover several
    /// texels, far ones one (the VAL paper sizes its point sprites by distance). 0: one texel
    /// per point (light culling's AISMs).
    pub point_size: f32,
    #[serde(skip)]
    pub _default: std::marker::PhantomData<D>,
}

/// A method's default map size and sharing (a marker type per default, as
/// [`PatternDefault`]).
pub trait IsmDefault: Clone + std::fmt::Debug + PartialEq {
    const TILE: u32;
    const POINTS_PER_LIGHT: u32;
    const FRONT_FACE_CULLING: bool;
    const POINT_SIZE: f32;
    const BIAS: f32;
}

/// The VAL paper's: 128^2 maps (1024 in a 4096^2 atlas), the cloud shared round-robin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IsmVal;
impl IsmDefault for IsmVal {
    const TILE: u32 = 128;
    const POINTS_PER_LIGHT: u32 = 0;
    const FRONT_FACE_CULLING: bool = false;
    // Measured once with tests/val.rs's map-quality loop scaled up (the default room, 64 VALs of
    // 4096 points on 128^2 maps; docs/ism.md): the simple lookup agrees with a ray to the VAL's
    // centre on 77.4% of (pixel, VAL) pairs with one texel per point, 79.9% with size 0.5,
    // 65.4% with 1 (grazing surfaces shadow themselves: sprites are squares) at bias 0.05;
    // 84.0% with size 0.5 at bias 0.1. The test itself checks the tiny case.
    const POINT_SIZE: f32 = 0.5;
    const BIAS: f32 = 0.1;
}

/// Stochastic Light Culling's adaptive ISMs (section 4.4): 32^2 maps (16384 in a 4096^2
/// atlas) of 8192 points each.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IsmAdaptive;
impl IsmDefault for IsmAdaptive {
    const TILE: u32 = 32;
    const POINTS_PER_LIGHT: u32 = 8192;
    const FRONT_FACE_CULLING: bool = true;
    const POINT_SIZE: f32 = 0.0;
    const BIAS: f32 = 0.05;
}

impl<D: IsmDefault> Default for IsmSettings<D> {
    fn default() -> Self {
        Self {
            points: 1 << 18,
            points_per_light: D::POINTS_PER_LIGHT,
            atlas: 4096,
            tile: D::TILE,
            pull_push_levels: 2,
            // Measured (tests/ism.rs, a plane occluder over a floor, 128^2 maps): 0.03 shadows
            // 3% of the lit floor (a texel keeps the nearest of its points, on a floor seen at
            // a grazing angle several centimetres nearer), 0.05 none; the VALs' sized points
            // need more (IsmVal).
            bias: D::BIAS,
            front_face_culling: D::FRONT_FACE_CULLING,
            point_size: D::POINT_SIZE,
            _default: std::marker::PhantomData,
        }
    }
}

impl<D: IsmDefault> IsmSettings<D> {
    /// Maps the atlas holds.
    pub fn capacity(&self) -> u32 {
        (self.atlas / self.tile.max(1)).pow(2)
    }
    /// Bytes of the atlas's depth buffer (what the device must bind in one piece).
    pub fn atlas_bytes(&self) -> u64 {
        4 * (self.atlas as u64).pow(2)
    }
    /// The pull-push levels that fit the map.
    pub fn levels(&self) -> u32 {
        self.pull_push_levels.min(self.tile.max(1).ilog2())
    }
    /// The numeric settings, declared once (validation, the GUI's sliders, `--set`).
    pub fn fields() -> Vec<Field<Self>> {
        vec![
            crate::field!(
                Self,
                points_per_light: u32,
                "points per map",
                "",
                0,
                1 << 16,
                Log,
                "points splatted into each light's map (0 = the cloud shared round-robin)"
            ),
            crate::field!(
                Self,
                points: u32,
                "cloud points",
                "",
                1,
                1 << 24,
                Log,
                "points sampled once on the scene's triangles, uniform in area"
            ),
            crate::field!(
                Self,
                tile: u32,
                "map size",
                "texels",
                8,
                1024,
                Pow2,
                "one paraboloid map's edge"
            ),
            crate::field!(
                Self,
                atlas: u32,
                "atlas size",
                "texels",
                8,
                8192,
                Pow2,
                "the atlas holds (atlas / map)^2 maps, one per light; at least the map size, at most 255 maps a side"
            ),
            crate::field!(
                Self,
                pull_push_levels: u32,
                "pull-push levels",
                "",
                0,
                8,
                Linear,
                "hole filling (the VAL paper: 2)"
            ),
            crate::field!(
                Self,
                bias: f32,
                "relative depth bias",
                "",
                0.0,
                0.5,
                Linear,
                "a point is lit when its distance x (1 - bias) is at most the map's",
                open_max
            ),
            crate::field!(
                Self,
                point_size: f32,
                "point size",
                "",
                0.0,
                8.0,
                Linear,
                "a point's world radius as a multiple of sqrt(scene area / (pi x points per map)): near \
                 points cover several texels (the VAL paper's sized points); 0: one texel per point"
            ),
        ]
    }

    /// Every field in range (and the atlas at least one map, at most 255 maps a side), or a
    /// message naming `table.ism.<field>`.
    pub fn validate(&self, table: &str) -> Result<(), String> {
        let section = format!("{table}.ism");
        field::check(&section, &Self::fields(), self)?;
        if self.atlas < self.tile {
            return Err(format!(
                "{section}.atlas {} is below the map size {} (the atlas holds at least one map)",
                self.atlas, self.tile
            ));
        }
        // The build dispatches one workgroup layer per map (at most 65535), and its splat
        // threads (maps x points_per_light) stay within u32.
        let maps = (self.atlas / self.tile).pow(2);
        if maps > 65535 {
            return Err(format!(
                "{section}.atlas {} holds {maps} maps of tile {}: at most 65535 (atlas / tile <= 255)",
                self.atlas, self.tile
            ));
        }
        Ok(())
    }

    /// A point's world radius (m) in maps of `per_map` points from a cloud on a surface of
    /// `area` m^2: point_size x sqrt(area / (pi per_map)); 0 with point_size 0 or no area.
    pub fn point_radius(&self, area: f32, per_map: u32) -> f32 {
        if self.point_size <= 0.0 || area <= 0.0 {
            return 0.0;
        }
        self.point_size * (area / (std::f32::consts::PI * per_map.max(1) as f32)).sqrt()
    }
    /// The points one of `maps` maps takes from a cloud of `cloud` points.
    pub fn points_per_map(&self, cloud: u32, maps: u32) -> u32 {
        if self.points_per_light > 0 {
            self.points_per_light
        } else {
            cloud / maps.max(1)
        }
    }
}

//! CPU twin of Stochastic Light Culling (Tokuyoshi & Harada 2016, sections 3-4) and of the
//! clamped-range baseline (its appendix A): per-VPL ranges, the interleaved tiles and their
//! light lists, the fall-off and the per-pixel sum; and of section 5's bounding-sphere tree
//! (node bounds, the per-pixel walk with reservoir sampling, the resampled one-ray shading).
//! Twins of `shaders/methods/light_culling/{lcull_common, lcull_light, lcull_tiles,
//! lcull_shade, lcull_tree}.wgsl`.
//!
//! Our VPL is a diffuse emitter of flux Phi: radiant intensity I(w') = Phi / pi x cos, so
//! max I = max_rgb(Phi) / pi. Our fall-off is the workbench's bounded one,
//! f(l) = 1 / max(l^2, eps^2) (`gi.distance_epsilon`), so the method is unbiased with respect
//! to the ground truth of the same VPLs and the same eps.

use crate::reference::brdf;
use glam::{UVec2, Vec3};

pub use super::interleave::{FilterImage, Interleave, filter_pixel};
use super::vpl::{pcg_hash, u01};

/// Largest range we store (a VPL whose xi is 0 lights everything).
pub const RANGE_INF: f32 = 1e30;
/// The threshold of a VPL that never contributes (no flux). Twin: `lcull_ranges.wgsl`.
pub const NEVER: f32 = 3.0e38;

/// Eq. 6 with max I = max_rgb(flux) / pi: alpha_i = 2 pi eps_max / (E max I)
/// = 2 pi^2 eps_max / (E max_rgb(flux)). `exposure` is E (the display's 2^EV).
pub fn alpha(epsilon_max: f32, exposure: f32, flux_max: f32) -> f32 {
    let pi = std::f32::consts::PI;
    2.0 * pi * pi * epsilon_max / (exposure * flux_max)
}

/// Appendix A: the clamped range for the same error bound,
/// r_i = sqrt(E N max I / (pi eps_max)) = sqrt(E N max_rgb(flux) / (pi^2 eps_max)).
pub fn clamped_range(epsilon_max: f32, exposure: f32, count: u32, flux_max: f32) -> f32 {
    let pi = std::f32::consts::PI;
    (exposure * count as f32 * flux_max / (pi * pi * epsilon_max)).sqrt()
}

/// The random number xi_i of VPL `i` in a frame (one per VPL, shared by every pixel: section
/// 3.1). The paper uses the tiny encryption algorithm; we use the PCG hash of the workbench.
/// Twin: `lcull_xi` in `lcull_common.wgsl`.
pub fn xi(seed: u32, i: u32) -> f32 {
    u01(pcg_hash(seed ^ pcg_hash(i ^ 0x6c8e_9cf5)))
}

/// How a VPL's contribution falls off: `f(l) > threshold ? max(floor, f(l)) : 0` with
/// f(l) = 1 / max(l^2, eps^2). Stochastic (eq. 2): threshold = alpha xi, floor = alpha (the
/// Russian roulette's f / p). Clamped: threshold = 1 / r^2, floor = 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Falloff {
    pub threshold: f32,
    pub floor: f32,
}

impl Falloff {
    pub fn stochastic(alpha: f32, xi: f32) -> Self {
        Self {
            threshold: alpha * xi,
            floor: alpha,
        }
    }
    pub fn clamped(range: f32) -> Self {
        Self {
            threshold: 1.0 / (range * range),
            floor: 0.0,
        }
    }
    /// The estimate of f(l) at squared distance `l2`.
    pub fn eval(self, l2: f32, eps: f32) -> f32 {
        let f = 1.0 / l2.max(eps * eps);
        if f > self.threshold {
            f.max(self.floor)
        } else {
            0.0
        }
    }
    /// The range beyond which `eval` is 0: eq. 3, r = f^-1(threshold) = 1 / sqrt(threshold)
    /// (0 when even f(0) = 1 / eps^2 is not above the threshold).
    pub fn range(self, eps: f32) -> f32 {
        if self.threshold <= 0.0 {
            RANGE_INF
        } else if self.threshold * eps * eps >= 1.0 {
            0.0
        } else {
            (1.0 / self.threshold.sqrt()).min(RANGE_INF)
        }
    }
}

/// A VPL's culling data: position, range and fall-off (range 0: never contributes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightRange {
    pub position: Vec3,
    pub range: f32,
    pub falloff: Falloff,
}

/// Which ranges: the paper's stochastic ones or the clamped baseline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RangeMode {
    Stochastic,
    Clamped,
}

/// Parameters of the range pass.
#[derive(Clone, Copy, Debug)]
pub struct RangeParams {
    pub mode: RangeMode,
    pub epsilon_max: f32,
    pub exposure: f32,
    /// VPLs of the frame (N of appendix A).
    pub count: u32,
    pub seed: u32,
    /// `gi.distance_epsilon`.
    pub eps: f32,
}

/// Pass 1 of Algorithm 1 for VPL `i` (position, max_rgb(flux); a VPL without flux, or an
/// empty one (`VPL_NONE`: pass 0), gets range 0).
pub fn light_range(p: &RangeParams, i: u32, position: Vec3, flux_max: f32) -> LightRange {
    if flux_max <= 0.0 || !flux_max.is_finite() {
        return LightRange {
            position,
            range: 0.0,
            falloff: Falloff {
                threshold: NEVER,
                floor: 0.0,
            },
        };
    }
    let falloff = match p.mode {
        RangeMode::Stochastic => {
            Falloff::stochastic(alpha(p.epsilon_max, p.exposure, flux_max), xi(p.seed, i))
        }
        RangeMode::Clamped => Falloff::clamped(clamped_range(p.epsilon_max, p.exposure, p.count, flux_max)),
    };
    LightRange {
        position,
        range: falloff.range(p.eps),
        falloff,
    }
}

/// The camera as the tile pass sees it (`GpuCamera`'s fields).
#[derive(Clone, Copy, Debug)]
pub struct TileCamera {
    pub eye: Vec3,
    /// Unit forward.
    pub forward: Vec3,
    /// right x tan(yfov / 2) x aspect.
    pub right: Vec3,
    /// up x tan(yfov / 2).
    pub up: Vec3,
    pub width: u32,
    pub height: u32,
}

impl TileCamera {
    pub fn new(cam: &crate::scene::Camera, width: u32, height: u32) -> Self {
        let aspect = width as f32 / height.max(1) as f32;
        let t = (0.5 * cam.yfov).tan();
        Self {
            eye: cam.position,
            forward: cam.forward,
            right: cam.right() * t * aspect,
            up: cam.up * t,
            width,
            height,
        }
    }
    /// Direction through screen point (px, py) in pixels (edges at integers).
    fn dir(&self, px: f32, py: f32) -> Vec3 {
        let x = 2.0 * px / self.width as f32 - 1.0;
        let y = 1.0 - 2.0 * py / self.height as f32;
        self.forward + x * self.right + y * self.up
    }
}

/// The tile layout: tiles of `tile` x `tile` pixels of one interleaving subset each (the
/// subset's pixels de-interleaved into a (W / n) x (H / n) image, as Segovia et al.'s
/// non-interleaved deferred shading).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileGrid {
    pub width: u32,
    pub height: u32,
    pub tile: u32,
    pub n: u32,
}

impl TileGrid {
    /// Tiles per subset (x, y).
    pub fn per_subset(self) -> (u32, u32) {
        (
            self.width.div_ceil(self.n).div_ceil(self.tile),
            self.height.div_ceil(self.n).div_ceil(self.tile),
        )
    }
    pub fn count(self) -> u32 {
        let (tx, ty) = self.per_subset();
        tx * ty * self.n * self.n
    }
    /// (subset, tile x, tile y) of tile `t`.
    pub fn coords(self, t: u32) -> (u32, u32, u32) {
        let (tx, ty) = self.per_subset();
        (t / (tx * ty), t % tx, (t / tx) % ty)
    }
    /// The tile of pixel (x, y). Twin: `lcull_tile_of` in `lcull_common.wgsl`.
    pub fn tile_of(self, x: u32, y: u32) -> u32 {
        let (tx, ty) = self.per_subset();
        let s = x % self.n + self.n * (y % self.n);
        let (dx, dy) = (x / self.n / self.tile, y / self.n / self.tile);
        s * tx * ty + dy * tx + dx
    }
    /// Screen pixel of tile `t`'s local pixel (lx, ly), if on screen.
    pub fn pixel(self, t: u32, lx: u32, ly: u32) -> Option<UVec2> {
        let (s, tx, ty) = self.coords(t);
        let x = (tx * self.tile + lx) * self.n + s % self.n;
        let y = (ty * self.tile + ly) * self.n + s / self.n;
        (x < self.width && y < self.height).then_some(UVec2::new(x, y))
    }
    /// The screen rectangle (pixel edges) tile `t`'s pixels span: x0, y0, x1, y1.
    pub fn rect(self, t: u32) -> [f32; 4] {
        let (s, tx, ty) = self.coords(t);
        let (sx, sy) = (s % self.n, s / self.n);
        let x0 = (tx * self.tile) * self.n + sx;
        let y0 = (ty * self.tile) * self.n + sy;
        let x1 = ((tx * self.tile + self.tile - 1) * self.n + sx + 1).min(self.width);
        let y1 = ((ty * self.tile + self.tile - 1) * self.n + sy + 1).min(self.height);
        [x0 as f32, y0 as f32, x1 as f32, y1 as f32]
    }
}

/// A tile's culling volume: its sub-frustum (four planes through the eye, unit inward
/// normals) between the least and greatest view depth of its pixels.
#[derive(Clone, Copy, Debug)]
pub struct TileBounds {
    pub planes: [Vec3; 4],
    pub depth: (f32, f32),
}

/// The tile's bounds from its pixels' view depths (None: no geometry in the tile).
pub fn tile_bounds(cam: &TileCamera, grid: TileGrid, t: u32, depths: &[f32]) -> Option<TileBounds> {
    if depths.is_empty() {
        return None;
    }
    let lo = depths.iter().copied().fold(f32::MAX, f32::min);
    let hi = depths.iter().copied().fold(0.0f32, f32::max);
    let [x0, y0, x1, y1] = grid.rect(t);
    Some(TileBounds {
        planes: frustum_planes(cam, [x0, y0, x1, y1]),
        depth: (lo, hi),
    })
}

/// Inward unit normals of the four side planes through the eye and the rectangle's edges.
/// Twin: the plane loop of `lcull_tiles.wgsl`'s `main`.
pub fn frustum_planes(cam: &TileCamera, [x0, y0, x1, y1]: [f32; 4]) -> [Vec3; 4] {
    let c = [cam.dir(x0, y0), cam.dir(x1, y0), cam.dir(x1, y1), cam.dir(x0, y1)];
    let mid = cam.dir(0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let mut planes = [Vec3::ZERO; 4];
    for k in 0..4 {
        let n = c[k].cross(c[(k + 1) % 4]).normalize_or_zero();
        planes[k] = if n.dot(mid) < 0.0 { -n } else { n };
    }
    planes
}

/// Whether a sphere (centre, radius) touches the tile's volume: inside or within `radius` of
/// every side plane, and its view depth within `radius` of the depth bounds (the standard
/// conservative sphere-frustum test of tiled lighting). Twin: `touches` in `lcull_tiles.wgsl`.
pub fn sphere_touches(cam: &TileCamera, b: &TileBounds, centre: Vec3, radius: f32) -> bool {
    if radius <= 0.0 {
        return false;
    }
    let v = centre - cam.eye;
    let d = v.dot(cam.forward);
    if d < b.depth.0 - radius || d > b.depth.1 + radius {
        return false;
    }
    b.planes.iter().all(|n| n.dot(v) >= -radius)
}

/// View depth of a world point.
pub fn view_depth(cam: &TileCamera, p: Vec3) -> f32 {
    (p - cam.eye).dot(cam.forward)
}

/// The tile lists: for each tile, the VPLs of its subset (increasing index) whose range
/// sphere touches it. `positions[y * width + x]` is the G-buffer position (None: no surface).
pub fn tile_lists(
    cam: &TileCamera,
    grid: TileGrid,
    il: Interleave,
    positions: &[Option<Vec3>],
    lights: &[LightRange],
) -> Vec<Vec<u32>> {
    (0..grid.count())
        .map(|t| {
            let mut depths = Vec::new();
            for ly in 0..grid.tile {
                for lx in 0..grid.tile {
                    if let Some(p) = grid.pixel(t, lx, ly)
                        && let Some(x) = positions[(p.y * grid.width + p.x) as usize]
                    {
                        depths.push(view_depth(cam, x).max(0.0));
                    }
                }
            }
            let Some(b) = tile_bounds(cam, grid, t, &depths) else {
                return Vec::new();
            };
            let s = grid.coords(t).0;
            il.subset(s, lights.len() as u32)
                .filter(|&i| sphere_touches(cam, &b, lights[i as usize].position, lights[i as usize].range))
                .collect()
        })
        .collect()
}

/// A VPL for shading: position, normal, rgb flux.
#[derive(Clone, Copy, Debug)]
pub struct ShadeVpl {
    pub position: Vec3,
    pub normal: Vec3,
    pub flux: Vec3,
}

/// The VPLs a pixel's list indexes, as shading reads them: each one's position, normal and
/// flux (`vpls`), its range and fall-off (`lights`), and the fall-off's distance bound `eps`.
#[derive(Clone, Copy, Debug)]
pub struct ShadeInputs<'a> {
    pub vpls: &'a [ShadeVpl],
    pub lights: &'a [LightRange],
    pub eps: f32,
}

/// The pixel's demodulated estimate (before albedo / pi): n^2 x sum over `list` of
/// flux / pi x cos_x x cos_v x falloff(l) x V, with `visible(i)` the shadow ray (Algorithm 1,
/// step 3). Twin: `lcull_shade.wgsl`.
pub fn shade(
    x: Vec3,
    nx: Vec3,
    list: &[u32],
    s: &ShadeInputs<'_>,
    il: Interleave,
    visible: impl FnMut(u32) -> bool,
) -> Vec3 {
    shade_shaded(x, nx, list, s, il, visible, None)
}

/// [`shade`], each term times the glossy BRDF f(v, l) where `sh` is given (radiance: no
/// albedo / pi after). Twin: `term` in `lcull_term.wgsl` with `gi.brdf = GGX`.
pub fn shade_shaded(
    x: Vec3,
    nx: Vec3,
    list: &[u32],
    s: &ShadeInputs<'_>,
    il: Interleave,
    mut visible: impl FnMut(u32) -> bool,
    sh: Option<&brdf::Shading>,
) -> Vec3 {
    let ShadeInputs { vpls, lights, eps } = *s;
    let pi = std::f32::consts::PI;
    let mut sum = Vec3::ZERO;
    for &i in list {
        let v = vpls[i as usize];
        let d = v.position - x;
        let l2 = d.length_squared();
        let f = lights[i as usize].falloff.eval(l2, eps);
        if f <= 0.0 {
            continue;
        }
        let w = d / l2.max(1e-30).sqrt();
        let (cx, cv) = (nx.dot(w), -v.normal.dot(w));
        if cx <= 0.0 || cv <= 0.0 || !visible(i) {
            continue;
        }
        let value = v.flux / pi * (cx * cv * f);
        sum += match sh {
            Some(sh) => value * brdf::eval(brdf::Brdf::Ggx, nx, sh.v, w, &sh.surface),
            None => value,
        };
    }
    sum * il.cells() as f32
}

/// The tree variant's random streams (section 5; twin: `tree_rng` in `lcull_tree.wgsl`):
/// reservoir sampling in the traversal, the resampling's one number in the shading.
pub const TREE_STREAM_RESERVOIR: u32 = 0x2545_f491;
pub const TREE_STREAM_RIS: u32 = 0x68e3_1da4;

/// The first state of a pixel's stream (pixel = y x width + x).
pub fn tree_rng(seed: u32, pixel: u32, stream: u32) -> u32 {
    pcg_hash(seed ^ pcg_hash(pixel ^ stream))
}

/// Per node of the implicit light tree (root 1, children 2n and 2n + 1, leaf j at
/// leaves + j; entry 0 unused): the largest range of the leaves below it (0: none). Twin:
/// the atomicMax walk of `leaves_main` (which leaves the leaf entries 0: the traversal tests
/// leaves by their own range).
pub fn tree_max_ranges(leaves: u32, ranges: &[f32]) -> Vec<f32> {
    let l = leaves as usize;
    let mut v = vec![0.0f32; 2 * l];
    for (j, r) in ranges.iter().enumerate().take(l) {
        v[l + j] = r.max(0.0);
    }
    for n in (1..l).rev() {
        v[n] = v[2 * n].max(v[2 * n + 1]);
    }
    for x in v.iter_mut().skip(l) {
        *x = 0.0;
    }
    v
}

/// Whether an internal node's bounding sphere holds x: centre the middle of its VPLs' box,
/// radius half the box's diagonal + the largest range below it (it holds every range sphere
/// below), tested conservatively by a relative 1e-5 and 1e-6 of the centre's largest
/// coordinate. Twin: `node_hit`.
pub fn tree_node_hit(bbox_min: Vec3, bbox_max: Vec3, max_range: f32, x: Vec3) -> bool {
    if max_range <= 0.0 {
        return false;
    }
    let c = 0.5 * (bbox_min + bbox_max);
    let radius = (0.5 * (bbox_max - bbox_min).length() + max_range) * 1.00001 + 1e-6 * c.abs().max_element();
    (x - c).length_squared() <= radius * radius
}

/// A pixel's traversal: its k-entry list, m (the VPLs in range) and the nodes visited.
#[derive(Clone, Debug, PartialEq)]
pub struct TreeList {
    pub list: Vec<u32>,
    pub m: u32,
    pub visited: u32,
}

/// The bounding-sphere tree the walk descends (section 5): `leaves` leaves, each node n's VPL
/// box `boxes[n]` and largest range below it `max_range[n]` ([`tree_max_ranges`]), and the
/// leaves' ranges and fall-offs (`lights`).
#[derive(Clone, Copy, Debug)]
pub struct SphereTree<'a> {
    pub leaves: u32,
    pub boxes: &'a [(Vec3, Vec3)],
    pub max_range: &'a [f32],
    pub lights: &'a [LightRange],
}

/// The stackless walk of the implicit tree from the root: a node is entered when its sphere
/// holds x, a leaf listed when its fall-off (with `eps`) is non-zero at x; k of the m listed
/// by reservoir sampling (Algorithm 3) with the stream `rng`. Twin: `traverse_main`.
pub fn tree_traverse(tree: &SphereTree<'_>, x: Vec3, eps: f32, k: u32, mut rng: u32) -> TreeList {
    let SphereTree {
        leaves,
        boxes,
        max_range,
        lights,
    } = *tree;
    let mut list = vec![0u32; k as usize];
    let (mut m, mut visited, mut n) = (0u32, 0u32, 1u32);
    loop {
        visited += 1;
        let mut descend = false;
        if n >= leaves {
            let j = n - leaves;
            let l = lights[j as usize];
            if l.falloff.eval((l.position - x).length_squared(), eps) > 0.0 {
                if m < k {
                    list[m as usize] = j;
                } else {
                    rng = pcg_hash(rng);
                    let r = (u01(rng) * (m + 1) as f32) as u32;
                    if r < k {
                        list[r as usize] = j;
                    }
                }
                m += 1;
            }
        } else {
            let (lo, hi) = boxes[n as usize];
            descend = tree_node_hit(lo, hi, max_range[n as usize], x);
        }
        if descend {
            n *= 2;
            continue;
        }
        while n & 1 == 1 {
            n >>= 1;
        }
        if n == 0 {
            break;
        }
        n += 1;
    }
    list.truncate(m.min(k) as usize);
    TreeList { list, m, visited }
}

/// Eq. 9 for a VPL (a point light) seen from x with normal nx:
/// g_i = f(l) max I_i max(-w . n_i, 0) max(w . n_x, 0), max I = max_rgb(flux) / pi. The
/// paper's second factor, printed with the light's normal n_i over the triangle's vertices,
/// can only be the receiver's (with n_i it is 0 wherever the first is positive); no BRDF, as
/// the paper. Twin: `importance`.
pub fn tree_importance(v: &ShadeVpl, x: Vec3, nx: Vec3, eps: f32) -> f32 {
    let d = v.position - x;
    let l2 = d.length_squared();
    let w = d * (1.0 / l2.max(1e-30).sqrt());
    let cv = (-v.normal.dot(w)).max(0.0);
    let cx = nx.dot(w).max(0.0);
    v.flux.max_element() / std::f32::consts::PI * cv * cx / l2.max(eps * eps)
}

/// A pixel's reservoir after the walk (Algorithm 3): the VPLs it listed (at most `k`, the
/// list's capacity) of the `m` in range.
#[derive(Clone, Copy, Debug)]
pub struct Reservoir<'a> {
    pub list: &'a [u32],
    pub m: u32,
    pub k: u32,
}

/// The pixel's demodulated estimate from its reservoir (section 5.3.2): one VPL i resampled
/// by q(i) = g_i / sum g (eq. 8) with the uniform `u`, its contribution (stochastic fall-off,
/// i.e. f / p_i, and the shadow ray `visible(i)`) over min(k / m, 1) q(i) (eq. 10). Returns
/// the estimate and the VPL shaded. Twin: `shade_main` of `lcull_tree.wgsl`.
pub fn tree_shade(
    x: Vec3,
    nx: Vec3,
    r: Reservoir<'_>,
    s: &ShadeInputs<'_>,
    u: f32,
    mut visible: impl FnMut(u32) -> bool,
) -> (Vec3, Option<u32>) {
    let (Reservoir { list, m, k }, ShadeInputs { vpls, eps, .. }) = (r, *s);
    let g: Vec<f32> = list
        .iter()
        .map(|&i| tree_importance(&vpls[i as usize], x, nx, eps))
        .collect();
    let total: f32 = g.iter().sum();
    if total <= 0.0 {
        return (Vec3::ZERO, None);
    }
    let target = u * total;
    let (mut acc, mut pick, mut g_pick) = (0.0f32, 0usize, 0.0f32);
    for (j, &gj) in g.iter().enumerate() {
        if gj > 0.0 {
            pick = j;
            g_pick = gj;
        }
        acc += gj;
        if target < acc && gj > 0.0 {
            break;
        }
    }
    let i = list[pick];
    let c = shade(x, nx, &[i], s, Interleave::new(1, 1, 0), |_| visible(i));
    let keep = (k as f32 / m as f32).min(1.0);
    (c * total / (keep * g_pick), Some(i))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(mode: RangeMode, epsilon_max: f32) -> RangeParams {
        RangeParams {
            mode,
            epsilon_max,
            exposure: 1.0,
            count: 4096,
            seed: 7,
            eps: 0.05,
        }
    }

    #[test]
    fn the_fall_off_estimate_is_unbiased_and_bounded_by_its_range() {
        // E[f_hat(l)] over xi = f(l) (eq. 2), and f_hat = 0 beyond r (eq. 3).
        let a = alpha(0.0005, 1.0, 0.01);
        let eps = 0.05;
        for &l in &[0.01f32, 0.3, 1.0, 4.0, 30.0] {
            let n = 200_000u32;
            let mean = (0..n)
                .map(|i| Falloff::stochastic(a, (i as f32 + 0.5) / n as f32).eval(l * l, eps) as f64)
                .sum::<f64>()
                / n as f64;
            let f = 1.0 / (l * l).max(eps * eps) as f64;
            assert!((mean - f).abs() < 1e-3 * f, "l {l}: mean {mean} vs f {f}");
            for xi in [0.01f32, 0.5, 0.99] {
                let fo = Falloff::stochastic(a, xi);
                let r = fo.range(eps);
                if l >= r * 1.0001 {
                    assert_eq!(fo.eval(l * l, eps), 0.0, "beyond the range");
                }
            }
        }
    }

    #[test]
    fn the_range_is_monotone_in_the_error_bound_and_follows_eq_3_and_appendix_a() {
        let eps = 0.05;
        let mut last = f32::MAX;
        for e in [1e-5f32, 1e-4, 5e-4, 2e-3, 1e-2] {
            let p = params(RangeMode::Stochastic, e);
            let r = light_range(&p, 3, Vec3::ZERO, 0.02).range;
            let a = alpha(e, 1.0, 0.02);
            let want = 1.0 / (a * xi(7, 3)).sqrt();
            assert!((r - want).abs() < 1e-5 * want, "eq. 3: {r} vs {want}");
            assert!(r < last, "the range shrinks as eps_max grows");
            last = r;
        }
        // Eq. 6 by hand: eps_max 0.0005, E 2, flux 0.01: 2 pi (0.0005) / (2 x 0.01 / pi).
        let pi = std::f32::consts::PI;
        let a = alpha(0.0005, 2.0, 0.01);
        assert!((a - 2.0 * pi * 0.0005 / (2.0 * 0.01 / pi)).abs() < 1e-6 * a);
        // Appendix A: r = sqrt(E N I / (pi eps_max)), constant when N x flux is.
        let r1 = clamped_range(0.0005, 1.0, 1024, 0.04);
        let r2 = clamped_range(0.0005, 1.0, 4096, 0.01);
        assert!((r1 - r2).abs() < 1e-4 * r1);
        let i = 0.04 / pi;
        assert!((r1 - (1024.0 * i / (pi * 0.0005)).sqrt()).abs() < 1e-4 * r1);
        let c = light_range(&params(RangeMode::Clamped, 0.0005), 0, Vec3::ZERO, 0.01);
        assert!((c.range - clamped_range(0.0005, 1.0, 4096, 0.01)).abs() < 1e-3 * c.range);
        // Beyond the clamped range: 0; inside: f exactly (no floor).
        assert_eq!(c.falloff.eval((c.range * 1.01).powi(2), eps), 0.0);
        let l = 0.5 * c.range;
        assert!((c.falloff.eval(l * l, eps) - 1.0 / (l * l)).abs() < 1e-6 / (l * l));
        // No flux: never contributes.
        assert_eq!(
            light_range(&params(RangeMode::Stochastic, 0.01), 0, Vec3::ZERO, 0.0).range,
            0.0
        );
    }

    #[test]
    fn the_interleaving_subsets_partition_the_vpls_and_the_pixels() {
        for n in [1u32, 2, 3, 8] {
            for (offset, total) in [(0u32, 1000u32), (1, 4096), (5, 777), (63, 65536), (7, 3)] {
                let il = Interleave {
                    n,
                    offset: offset % (n * n),
                    stride: Interleave::stride_for(total, n),
                };
                let mut seen = vec![0u32; total as usize];
                for s in 0..il.cells() {
                    let mut last = None;
                    for i in il.subset(s, total) {
                        assert!(i < total && last.is_none_or(|l| l < i), "increasing, in range");
                        assert_eq!(il.vpl_subset(i), s);
                        seen[i as usize] += 1;
                        last = Some(i);
                    }
                }
                assert!(
                    seen.iter().all(|&c| c == 1),
                    "n {n}, {total}: every VPL exactly once"
                );
                // Every screen pixel lies in exactly one tile, at the local pixel that maps back.
                let grid = TileGrid {
                    width: 37,
                    height: 23,
                    tile: 4,
                    n,
                };
                let mut hits = vec![0u32; 37 * 23];
                for t in 0..grid.count() {
                    for ly in 0..grid.tile {
                        for lx in 0..grid.tile {
                            if let Some(p) = grid.pixel(t, lx, ly) {
                                assert_eq!(grid.tile_of(p.x, p.y), t);
                                let r = grid.rect(t);
                                assert!(p.x as f32 >= r[0] && (p.x as f32) < r[2]);
                                assert!(p.y as f32 >= r[1] && (p.y as f32) < r[3]);
                                hits[(p.y * 37 + p.x) as usize] += 1;
                            }
                        }
                    }
                }
                assert!(hits.iter().all(|&h| h == 1), "n {n}: every pixel in one tile");
            }
        }
    }

    #[test]
    fn each_subset_of_hammersley_ordered_vpls_covers_the_unit_square() {
        // 4096 VPLs, 8 x 8 subsets of 64: the stride puts one point of every subset in each
        // cell of an 8 x 8 grid over the Hammersley square (a stride of 1 puts a subset in one
        // strip of 1/64).
        let (count, n) = (4096u32, 8u32);
        let il = Interleave::new(n, count, 3);
        assert_eq!(il.stride, 8);
        for s in 0..il.cells() {
            let mut cells = std::collections::HashSet::new();
            for i in il.subset(s, count) {
                let (u, v) = (i as f32 / count as f32, super::super::vpl::radical_inverse_2(i));
                cells.insert(((u * 8.0) as u32, (v * 8.0) as u32));
            }
            assert_eq!(cells.len(), 64, "subset {s} covers every cell once");
        }
    }

    /// A small tree: its VPLs, leaf ranges, node boxes and largest ranges below each node.
    type SmallTree = (Vec<ShadeVpl>, Vec<LightRange>, Vec<(Vec3, Vec3)>, Vec<f32>);

    /// 13 VPLs and 3 padding leaves under a 16-leaf tree.
    fn small_tree(seed: u32) -> SmallTree {
        let leaves = 16usize;
        let mut h = seed;
        let mut r = || {
            h = pcg_hash(h);
            u01(h)
        };
        let mut vpls = Vec::new();
        let mut lights = Vec::new();
        let p = RangeParams {
            seed: seed ^ 0x55,
            ..params(RangeMode::Stochastic, 0.02)
        };
        for j in 0..leaves {
            let position = Vec3::new(4.0 * r(), 4.0 * r(), 4.0 * r());
            let normal = Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize_or(Vec3::Z);
            let flux = if j < 13 {
                Vec3::new(r(), r(), r()) * 0.5
            } else {
                Vec3::ZERO
            };
            vpls.push(ShadeVpl {
                position,
                normal,
                flux,
            });
            lights.push(light_range(&p, j as u32, position, flux.max_element()));
        }
        let mut boxes = vec![(Vec3::splat(f32::MAX), Vec3::splat(-f32::MAX)); 2 * leaves];
        for j in 0..13 {
            boxes[leaves + j] = (vpls[j].position, vpls[j].position);
        }
        for n in (1..leaves).rev() {
            let (a, b) = (boxes[2 * n], boxes[2 * n + 1]);
            boxes[n] = (a.0.min(b.0), a.1.max(b.1));
        }
        let ranges: Vec<f32> = lights.iter().map(|l| l.range).collect();
        let max = tree_max_ranges(leaves as u32, &ranges);
        (vpls, lights, boxes, max)
    }

    #[test]
    fn the_tree_lists_exactly_the_vpls_in_range_and_its_one_sample_estimate_is_unbiased() {
        let (vpls, lights, boxes, max) = small_tree(3);
        let tree = SphereTree {
            leaves: 16,
            boxes: &boxes,
            max_range: &max,
            lights: &lights,
        };
        let eps = 0.05;
        let in_range = |x: Vec3| -> Vec<u32> {
            (0..16u32)
                .filter(|&j| {
                    lights[j as usize]
                        .falloff
                        .eval((lights[j as usize].position - x).length_squared(), eps)
                        > 0.0
                })
                .collect()
        };
        // A list as large as the tree: exactly the VPLs in range, in leaf order.
        let mut h = 11u32;
        let mut seen_culling = false;
        for _ in 0..300 {
            h = pcg_hash(h);
            let x = Vec3::new(u01(h), u01(pcg_hash(h ^ 1)), u01(pcg_hash(h ^ 2))) * 6.0 - 1.0;
            let t = tree_traverse(&tree, x, eps, 16, h);
            let want = in_range(x);
            assert_eq!(t.list, want, "at {x}");
            assert_eq!(t.m as usize, want.len());
            seen_culling |= t.visited < 31;
        }
        assert!(seen_culling, "some traversals skip subtrees");
        // Find a point with m >= 5, then k = 2: each VPL in range is listed with probability
        // k / m (Algorithm 3), and the resampled one-ray estimate averages to the sum over all
        // of them (eq. 10).
        let (x, want) = (0..2000u32)
            .map(|i| {
                let g = pcg_hash(i ^ 0xabc);
                Vec3::new(u01(g), u01(pcg_hash(g ^ 1)), u01(pcg_hash(g ^ 2))) * 4.0
            })
            .map(|x| (x, in_range(x)))
            .find(|(_, w)| w.len() >= 5)
            .expect("a point with 5 VPLs in range");
        let m = want.len() as f64;
        let nx = (vpls[want[0] as usize].position - x).normalize();
        let si = ShadeInputs {
            vpls: &vpls,
            lights: &lights,
            eps,
        };
        let exact = shade(x, nx, &want, &si, Interleave::new(1, 1, 0), |_| true);
        let trials = 200_000u32;
        let mut listed = [0u32; 16];
        let mut sum = glam::DVec3::ZERO;
        for s in 0..trials {
            let t = tree_traverse(&tree, x, eps, 2, pcg_hash(s ^ 0x9e37));
            assert_eq!(t.list.len(), 2);
            for &j in &t.list {
                listed[j as usize] += 1;
            }
            let u = u01(pcg_hash(s ^ 0x1234_5678));
            let r = Reservoir {
                list: &t.list,
                m: t.m,
                k: 2,
            };
            let (v, _) = tree_shade(x, nx, r, &si, u, |_| true);
            sum += v.as_dvec3();
        }
        let p = 2.0 / m;
        let sigma = (p * (1.0 - p) / trials as f64).sqrt();
        for &j in &want {
            let f = listed[j as usize] as f64 / trials as f64;
            assert!((f - p).abs() < 5.0 * sigma, "VPL {j} listed {f} vs {p}");
        }
        let mean = sum / trials as f64;
        let e = exact.as_dvec3();
        assert!(e.max_element() > 0.0);
        assert!(
            (mean - e).abs().max_element() < 0.02 * e.max_element(),
            "mean {mean} vs exact {e}"
        );
    }

    #[test]
    fn a_sphere_around_any_tile_point_touches_the_tile() {
        // The culling is conservative: every pixel position within r of a light puts the
        // light in the pixel's tile list.
        let cam = TileCamera {
            eye: Vec3::ZERO,
            forward: Vec3::NEG_Z,
            right: Vec3::X * 0.7,
            up: Vec3::Y * 0.4,
            width: 64,
            height: 36,
        };
        let grid = TileGrid {
            width: 64,
            height: 36,
            tile: 8,
            n: 2,
        };
        let mut seed = 1u32;
        let mut rnd = || {
            seed = pcg_hash(seed);
            u01(seed)
        };
        for _ in 0..2000 {
            let (x, y) = ((rnd() * 64.0) as u32, (rnd() * 36.0) as u32);
            let depth = 1.0 + 9.0 * rnd();
            let t = grid.tile_of(x, y);
            let pixel_dir = cam.dir(x as f32 + 0.5, y as f32 + 0.5);
            let p = pixel_dir * depth;
            let b = tile_bounds(&cam, grid, t, &[depth, depth + 0.5 * rnd()]).unwrap();
            let r = 0.05 + rnd();
            let c = p + Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize_or_zero() * r * 0.999;
            assert!(sphere_touches(&cam, &b, c, r), "pixel ({x}, {y}) depth {depth}");
        }
    }
}

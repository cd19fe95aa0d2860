//! CPU twin of the temporal stage (`shaders/temporal.wgsl`, `renderer::passes::temporal`):
//! SVGF (Schied et al. 2017) on the albedo-demodulated GI, with SVGF's à-trous or the
//! light-conserving one (`Params::conserving`, docs/temporal.md). Each function mirrors one
//! entry point pixel by pixel, so that a test can feed it the GPU's inputs of that pass and
//! compare the outputs; [`Frame`] runs them in the pass order on whole images (the statistical
//! tests of the filter use it).

use glam::{Vec2, Vec3};

use crate::base::display::luminance;

/// A camera as the pass sees it: `GpuCamera`'s fields (eye, unit forward, right and up scaled
/// by the half-extents of the image plane at distance 1), light culling's tile camera.
pub use super::light_culling::TileCamera as Cam;

impl Cam {
    pub fn view_depth(&self, x: Vec3) -> f32 {
        (x - self.eye).dot(self.forward)
    }
    /// Continuous pixel coordinates (centres at integers) of `x` and its depth along forward.
    pub fn pixel_of(&self, x: Vec3) -> (Vec2, f32) {
        let d = x - self.eye;
        let z = d.dot(self.forward);
        let sx = d.dot(self.right) / (z * self.right.dot(self.right));
        let sy = d.dot(self.up) / (z * self.up.dot(self.up));
        (
            Vec2::new(
                (sx + 1.0) * 0.5 * self.width as f32 - 0.5,
                (1.0 - sy) * 0.5 * self.height as f32 - 0.5,
            ),
            z,
        )
    }
}

/// The stage's parameters (`TemporalSettings` as the pass uploads them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    pub alpha: f32,
    pub moments_alpha: f32,
    pub max_history: f32,
    pub normal_cos: f32,
    pub depth_tolerance: f32,
    pub sigma_l: f32,
    pub sigma_n: f32,
    pub sigma_z: f32,
    pub spatial_frames: f32,
    pub gradient: bool,
    pub gradient_scale: f32,
    /// The light-conserving à-trous (symmetric weights, `atrous_prep` / `atrous_weight` /
    /// `atrous_conserving`) and the variance pass keeping the colour unfiltered; false:
    /// SVGF's (`atrous`).
    pub conserving: bool,
}

impl Default for Params {
    /// SVGF's values with the conserving à-trous (`TemporalSettings::default`).
    fn default() -> Self {
        Self {
            alpha: 0.2,
            moments_alpha: 0.2,
            max_history: 32.0,
            normal_cos: 0.9,
            depth_tolerance: 0.02,
            sigma_l: 4.0,
            sigma_n: 128.0,
            sigma_z: 1.0,
            spatial_frames: 4.0,
            gradient: false,
            gradient_scale: 2.0,
            conserving: true,
        }
    }
}

/// One frame's G-buffer: world position (w = material id + 1, 0 = nothing), normal, albedo.
#[derive(Clone, Debug, PartialEq)]
pub struct Gbuffer {
    pub width: u32,
    pub height: u32,
    pub position: Vec<[f32; 4]>,
    pub normal: Vec<Vec3>,
    pub albedo: Vec<Vec3>,
}

impl Gbuffer {
    pub fn idx(&self, x: i32, y: i32) -> Option<usize> {
        (x >= 0 && y >= 0 && x < self.width as i32 && y < self.height as i32)
            .then(|| (y as u32 * self.width + x as u32) as usize)
    }
    pub fn covered(&self, k: usize) -> bool {
        self.position[k][3] != 0.0
    }
    pub fn point(&self, k: usize) -> Vec3 {
        Vec3::from_slice(&self.position[k][..3])
    }
}

/// Radiance / albedo per channel (0 below an albedo of 1e-3).
pub fn demodulate(c: Vec3, a: Vec3) -> Vec3 {
    let f = |c: f32, a: f32| if a > 1e-3 { c / a.max(1e-3) } else { 0.0 };
    Vec3::new(f(c.x, a.x), f(c.y, a.y), f(c.z, a.z))
}

/// The previous frame as `reproject` reads it: its G-buffer (normals as stored), camera and
/// history colour and moments.
#[derive(Clone, Copy, Debug)]
pub struct Previous<'a> {
    pub gbuffer: &'a Gbuffer,
    pub cam: &'a Cam,
    pub history: &'a [[f32; 4]],
    pub moments: &'a [[f32; 4]],
}

/// What the twin keeps of a frame: its G-buffer, camera, history colour and moments.
pub type Kept = (Gbuffer, Cam, Vec<[f32; 4]>, Vec<[f32; 4]>);

/// What `reproject` writes for one pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Reprojected {
    /// Demodulated colour and the luminance of this frame's estimate.
    pub current: [f32; 4],
    /// The history at the pixel's previous position (demodulated rgb, length), 0 if none.
    pub history: [f32; 4],
    pub moments: [f32; 4],
    /// Motion to the previous pixel position (pixels).
    pub motion: Vec2,
    /// Bilinear weight of the kept taps (> 0), -1 for the 3x3 fallback, 0 disoccluded.
    pub mask: f32,
}

/// Whether previous pixel `q` shows the surface of the current point (same material, normal,
/// tangent plane).
fn tap_ok(prev: &Gbuffer, q: (i32, i32), g: [f32; 4], n: Vec3, tol: f32, p: &Params) -> Option<usize> {
    let k = prev.idx(q.0, q.1)?;
    let pg = prev.position[k];
    let d = Vec3::from_slice(&pg[..3]) - Vec3::from_slice(&g[..3]);
    (pg[3] == g[3] && prev.normal[k].dot(n) >= p.normal_cos && n.dot(d).abs() <= tol).then_some(k)
}

/// The `reproject` entry point at pixel (x, y): `radiance` the method's estimate there,
/// `prev` the previous frame (its G-buffer with normals as the pass stored them, camera and
/// history buffers), None on a first frame.
pub fn reproject_pixel(
    x: u32,
    y: u32,
    cur: &Gbuffer,
    radiance: Vec3,
    cam: &Cam,
    prev: Option<Previous<'_>>,
    p: &Params,
) -> Reprojected {
    let k = (y * cur.width + x) as usize;
    let g = cur.position[k];
    if g[3] == 0.0 {
        return Reprojected::default();
    }
    let n = cur.normal[k].normalize_or_zero();
    let c = demodulate(radiance, cur.albedo[k]);
    let mut out = Reprojected {
        current: [c.x, c.y, c.z, luminance(c)],
        ..Default::default()
    };
    let Some(pf) = prev else {
        return out;
    };
    let (prev, prev_cam, hist, mom) = (pf.gbuffer, pf.cam, pf.history, pf.moments);
    let (pp, z) = prev_cam.pixel_of(cur.point(k));
    out.motion = pp - Vec2::new(x as f32, y as f32);
    if z <= 0.0 || !(pp.x.abs() < 1e6 && pp.y.abs() < 1e6) {
        return out;
    }
    let tol = p.depth_tolerance * cam.view_depth(cur.point(k)).max(1e-6);
    let base = pp.floor();
    let f = pp - base;
    let mut h = [0.0f32; 4];
    let mut m = [0.0f32; 4];
    let mut wsum = 0.0;
    for (ox, oy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let w = if ox == 1 { f.x } else { 1.0 - f.x } * if oy == 1 { f.y } else { 1.0 - f.y };
        if w <= 0.0 {
            continue;
        }
        if let Some(q) = tap_ok(prev, (base.x as i32 + ox, base.y as i32 + oy), g, n, tol, p) {
            for i in 0..4 {
                h[i] += w * hist[q][i];
                m[i] += w * mom[q][i];
            }
            wsum += w;
        }
    }
    if wsum > 1e-3 {
        out.history = h.map(|v| v / wsum);
        out.moments = m.map(|v| v / wsum);
        out.mask = wsum;
        return out;
    }
    let (mut h, mut m, mut cnt) = ([0.0f32; 4], [0.0f32; 4], 0.0f32);
    let centre = (pp + 0.5).floor();
    for j in 0..9 {
        let q = (centre.x as i32 + j % 3 - 1, centre.y as i32 + j / 3 - 1);
        if let Some(q) = tap_ok(prev, q, g, n, tol, p) {
            for i in 0..4 {
                h[i] += hist[q][i];
                m[i] += mom[q][i];
            }
            cnt += 1.0;
        }
    }
    if cnt > 0.0 {
        out.history = h.map(|v| v / cnt);
        out.moments = m.map(|v| v / cnt);
        out.mask = -1.0;
    }
    out
}

fn same_surface(gb: &Gbuffer, g: Vec3, n: Vec3, q: usize, tol: f32, p: &Params) -> bool {
    gb.covered(q)
        && gb.normal[q].normalize_or_zero().dot(n) >= p.normal_cos
        && n.dot(gb.point(q) - g).abs() <= tol
}

/// What `accumulate` writes for one pixel: the history colour (demodulated rgb, length), the
/// moments (m1, m2, length, 0) and the reset weight.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Accumulated {
    pub color: [f32; 4],
    pub moments: [f32; 4],
    pub reset: f32,
}

/// The `accumulate` entry point at pixel k, from every pixel's `reproject` output.
pub fn accumulate_pixel(k: usize, gb: &Gbuffer, cam: &Cam, rp: &[Reprojected], p: &Params) -> Accumulated {
    if !gb.covered(k) {
        return Accumulated::default();
    }
    let cur = rp[k].current;
    let r = rp[k].history;
    let len_prev = r[3];
    let len = (len_prev + 1.0).min(p.max_history);
    let mut a = p.alpha.max(1.0 / len);
    let mut am = p.moments_alpha.max(1.0 / len);
    let mut reset = 0.0;
    if p.gradient && len_prev > 0.0 {
        let (x, y) = ((k as u32 % gb.width) as i32, (k as u32 / gb.width) as i32);
        let g = gb.point(k);
        let n = gb.normal[k].normalize_or_zero();
        let tol = p.depth_tolerance * cam.view_depth(g).max(1e-6);
        let (mut sc, mut sc2, mut sh, mut cnt) = (0.0f32, 0.0f32, 0.0f32, 0.0f32);
        for dy in -3..=3 {
            for dx in -3..=3 {
                let Some(q) = gb.idx(x + dx, y + dy) else { continue };
                if rp[q].history[3] <= 0.0 || !same_surface(gb, g, n, q, tol, p) {
                    continue;
                }
                let lc = rp[q].current[3];
                sc += lc;
                sc2 += lc * lc;
                sh += luminance(Vec3::from_slice(&rp[q].history[..3]));
                cnt += 1.0;
            }
        }
        let (mc, mh) = (sc / cnt, sh / cnt);
        let var_c = (sc2 / cnt - mc * mc).max(0.0);
        let se = (var_c / cnt).sqrt();
        let delta = ((mc - mh).abs() - 2.0 * se).max(0.0) / mc.max(mh).max(1e-6);
        reset = (p.gradient_scale * delta).clamp(0.0, 1.0);
        a += (1.0 - a) * reset;
        am += (1.0 - am) * reset;
    }
    let mix = |h: f32, c: f32, a: f32| h + (c - h) * a;
    let l = cur[3];
    let m0 = rp[k].moments;
    Accumulated {
        color: [
            mix(r[0], cur[0], a),
            mix(r[1], cur[1], a),
            mix(r[2], cur[2], a),
            len,
        ],
        moments: [mix(m0[0], l, am), mix(m0[1], l * l, am), len, 0.0],
        reset,
    }
}

/// The depth derivative at pixel (x, y): max over the axes of the smaller one-sided
/// difference of the view depth to a covered neighbour.
pub fn depth_fwidth(gb: &Gbuffer, cam: &Cam, x: i32, y: i32, z: f32) -> f32 {
    let mut fw = 0.0;
    for axis in 0..2 {
        let mut best = f32::INFINITY;
        for s in [-1, 1] {
            let (qx, qy) = if axis == 0 { (x + s, y) } else { (x, y + s) };
            if let Some(q) = gb.idx(qx, qy).filter(|&q| gb.covered(q)) {
                best = best.min((cam.view_depth(gb.point(q)) - z).abs());
            }
        }
        if best.is_finite() {
            fw = f32::max(fw, best);
        }
    }
    fw
}

/// A pixel as SVGF's edge-stopping weight sees it: view depth, unit normal, luminance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgePoint {
    pub z: f32,
    pub n: Vec3,
    pub l: f32,
}

/// SVGF's edge-stopping weight (depth, normal, luminance) between pixels p and q, without
/// the kernel.
pub fn edge_weight(p: EdgePoint, q: EdgePoint, phi_z: f32, phi_l: f32, sigma_n: f32) -> f32 {
    let (EdgePoint { z: zp, n: np, l: lp }, EdgePoint { z: zq, n: nq, l: lq }) = (p, q);
    let wz = if phi_z == 0.0 {
        0.0
    } else {
        (zp - zq).abs() / phi_z
    };
    let wl = (lp - lq).abs() / phi_l;
    let wn = np.dot(nq).clamp(0.0, 1.0).powf(sigma_n);
    (-wl.max(0.0) - wz.max(0.0)).exp() * wn
}

/// The `variance` entry point at pixel k: the filter's input (demodulated rgb, variance) from
/// the integrated colours and moments of every pixel (`Accumulated`). On a short history the
/// moments are filtered spatially; SVGF filters the colour with them, the conserving choice
/// keeps the pixel's own (a normalised bilateral blur moves light).
pub fn variance_pixel(k: usize, gb: &Gbuffer, cam: &Cam, acc: &[Accumulated], p: &Params) -> [f32; 4] {
    if !gb.covered(k) {
        return [0.0; 4];
    }
    let it = acc[k].color;
    let len = it[3];
    let m = acc[k].moments;
    if len >= p.spatial_frames {
        return [it[0], it[1], it[2], (m[1] - m[0] * m[0]).max(0.0)];
    }
    let (x, y) = ((k as u32 % gb.width) as i32, (k as u32 / gb.width) as i32);
    let n = gb.normal[k].normalize_or_zero();
    let z = cam.view_depth(gb.point(k));
    let fw = depth_fwidth(gb, cam, x, y, z).max(DEPTH_FLOOR * z);
    let lp = luminance(Vec3::from_slice(&it[..3]));
    let at_k = EdgePoint { z, n, l: lp };
    let (mut wsum, mut c, mut mm) = (0.0f32, Vec3::ZERO, Vec2::ZERO);
    for dy in -3..=3i32 {
        for dx in -3..=3i32 {
            let Some(q) = gb.idx(x + dx, y + dy).filter(|&q| gb.covered(q)) else {
                continue;
            };
            let iq = Vec3::from_slice(&acc[q].color[..3]);
            let phi_z = 3.0 * p.sigma_z * fw * Vec2::new(dx as f32, dy as f32).length();
            let at_q = EdgePoint {
                z: cam.view_depth(gb.point(q)),
                n: gb.normal[q].normalize_or_zero(),
                l: luminance(iq),
            };
            let w = edge_weight(at_k, at_q, phi_z, p.sigma_l, p.sigma_n);
            wsum += w;
            c += w * iq;
            mm += w * Vec2::new(acc[q].moments[0], acc[q].moments[1]);
        }
    }
    let wsum = wsum.max(1e-10);
    let (c, mm) = (c / wsum, mm / wsum);
    let v = (mm.y - mm.x * mm.x).max(0.0) * 4.0 / len.max(1.0);
    if p.conserving {
        return [it[0], it[1], it[2], v];
    }
    [c.x, c.y, c.z, v]
}

/// fwidth(z)'s floor relative to the view depth (a plane facing the camera has a zero depth
/// gradient; the G-buffer's float noise would otherwise stop the filter on it).
pub const DEPTH_FLOOR: f32 = 1e-4;

/// The B3-spline kernel's taps for offsets 0, 1, 2.
pub const B3: [f32; 3] = [3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0];

/// The variance of `src` at (x, y) prefiltered by a 3x3 Gaussian over the covered pixels
/// (SVGF's g(var)).
fn prefiltered_variance(gb: &Gbuffer, src: &[[f32; 4]], x: i32, y: i32) -> f32 {
    let (mut gv, mut gw) = (0.0f32, 0.0f32);
    for dy in -1..=1i32 {
        for dx in -1..=1i32 {
            if let Some(q) = gb.idx(x + dx, y + dy).filter(|&q| gb.covered(q)) {
                let w = if dx != 0 { 0.25 } else { 0.5 } * if dy != 0 { 0.25 } else { 0.5 };
                gv += w * src[q][3];
                gw += w;
            }
        }
    }
    (gv / gw).max(0.0)
}

/// One iteration of SVGF's à-trous (the `atrous` entry point) at pixel k with step `step`,
/// from the input `src` (demodulated rgb, variance) of every pixel: each output normalised by
/// its own weight sum, the luminance scale from the pixel's own variance.
pub fn atrous_pixel(k: usize, gb: &Gbuffer, cam: &Cam, src: &[[f32; 4]], step: i32, p: &Params) -> [f32; 4] {
    if !gb.covered(k) {
        return [0.0; 4];
    }
    let (x, y) = ((k as u32 % gb.width) as i32, (k as u32 / gb.width) as i32);
    let c = src[k];
    let n = gb.normal[k].normalize_or_zero();
    let z = cam.view_depth(gb.point(k));
    let fw = depth_fwidth(gb, cam, x, y, z).max(DEPTH_FLOOR * z);
    let phi_l = p.sigma_l * (prefiltered_variance(gb, src, x, y) + 1e-10).sqrt();
    let lp = luminance(Vec3::from_slice(&c[..3]));
    let at_k = EdgePoint { z, n, l: lp };
    let mut wsum = B3[0] * B3[0];
    let mut sc = wsum * Vec3::from_slice(&c[..3]);
    let mut sv = wsum * wsum * c[3];
    for dy in -2..=2i32 {
        for dx in -2..=2i32 {
            if dx == 0 && dy == 0 {
                continue;
            }
            let Some(q) = gb.idx(x + dx * step, y + dy * step).filter(|&q| gb.covered(q)) else {
                continue;
            };
            let sq = Vec3::from_slice(&src[q][..3]);
            let phi_z = p.sigma_z * fw * step as f32 * Vec2::new(dx as f32, dy as f32).length();
            let at_q = EdgePoint {
                z: cam.view_depth(gb.point(q)),
                n: gb.normal[q].normalize_or_zero(),
                l: luminance(sq),
            };
            let w = B3[dx.unsigned_abs() as usize]
                * B3[dy.unsigned_abs() as usize]
                * edge_weight(at_k, at_q, phi_z, phi_l, p.sigma_n);
            wsum += w;
            sc += w * sq;
            sv += w * w * src[q][3];
        }
    }
    let o = sc / wsum;
    [o.x, o.y, o.z, sv / (wsum * wsum)]
}

/// The `atrous_prep` entry point at pixel k (the conserving à-trous): what the symmetric
/// weights read of each pixel, (view depth, depth derivative, luminance, prefiltered
/// variance); an uncovered pixel is (0, 0, 0, -1).
pub fn atrous_prep_pixel(k: usize, gb: &Gbuffer, cam: &Cam, src: &[[f32; 4]]) -> [f32; 4] {
    if !gb.covered(k) {
        return [0.0, 0.0, 0.0, -1.0];
    }
    let (x, y) = ((k as u32 % gb.width) as i32, (k as u32 / gb.width) as i32);
    let z = cam.view_depth(gb.point(k));
    let fw = depth_fwidth(gb, cam, x, y, z).max(DEPTH_FLOOR * z);
    let l = luminance(Vec3::from_slice(&src[k][..3]));
    [z, fw, l, prefiltered_variance(gb, src, x, y)]
}

/// The symmetric edge-stopping weight of pixels a and b (their `atrous_prep` records and
/// normals) at distance `dist` steps of `step` pixels: SVGF's functions with the depth scale
/// from the larger depth derivative and the luminance scale from the larger variance, so
/// that e(a, b) = e(b, a) exactly.
pub fn symmetric_weight(
    a: [f32; 4],
    b: [f32; 4],
    na: Vec3,
    nb: Vec3,
    dist: f32,
    step: i32,
    p: &Params,
) -> f32 {
    let phi_z = p.sigma_z * a[1].max(b[1]) * step as f32 * dist;
    let phi_l = p.sigma_l * (a[3].max(b[3]) + 1e-10).sqrt();
    let at = |r: [f32; 4], n: Vec3| EdgePoint { z: r[0], n, l: r[2] };
    edge_weight(at(a, na), at(b, nb), phi_z, phi_l, p.sigma_n)
}

/// Calls `f(q, kernel x symmetric weight)` for each covered tap q != k of pixel k's 5x5
/// window with holes `step` (the weight and filter passes share it).
fn conserving_taps(
    k: usize,
    gb: &Gbuffer,
    aux: &[[f32; 4]],
    step: i32,
    p: &Params,
    mut f: impl FnMut(usize, f32),
) {
    let (x, y) = ((k as u32 % gb.width) as i32, (k as u32 / gb.width) as i32);
    let n = gb.normal[k].normalize_or_zero();
    for dy in -2..=2i32 {
        for dx in -2..=2i32 {
            if dx == 0 && dy == 0 {
                continue;
            }
            let Some(q) = gb.idx(x + dx * step, y + dy * step).filter(|&q| aux[q][3] >= 0.0) else {
                continue;
            };
            let dist = Vec2::new(dx as f32, dy as f32).length();
            let e = symmetric_weight(aux[k], aux[q], n, gb.normal[q].normalize_or_zero(), dist, step, p);
            f(
                q,
                B3[dx.unsigned_abs() as usize] * B3[dy.unsigned_abs() as usize] * e,
            );
        }
    }
}

/// The `atrous_weight` entry point at pixel k: its weight sum W_k (the centre's kernel weight
/// plus the kernel x symmetric weight of each covered tap); 0 uncovered.
pub fn atrous_weight_pixel(k: usize, gb: &Gbuffer, aux: &[[f32; 4]], step: i32, p: &Params) -> f32 {
    if aux[k][3] < 0.0 {
        return 0.0;
    }
    let mut w = B3[0] * B3[0];
    conserving_taps(k, gb, aux, step, p, |_, kw| w += kw);
    w
}

/// The share of a conserving transfer between pixels of albedos `a` (the receiver) and `b`,
/// per channel: min(a, b) / a, so that the radiance a takes from b (a x share x the
/// demodulated difference) is what b gives (b x its share); 0 where either albedo is at most
/// 1e-3 (no demodulated GI there).
pub fn albedo_share(a: Vec3, b: Vec3) -> Vec3 {
    let f = |a: f32, b: f32| {
        if a > 1e-3 && b > 1e-3 {
            a.min(b) / a.max(1e-3)
        } else {
            0.0
        }
    };
    Vec3::new(f(a.x, b.x), f(a.y, b.y), f(a.z, b.z))
}

/// The `atrous_conserving` entry point at pixel k: out_k = X_k + sum_q s_kq r_kq (X_q - X_k)
/// per channel, with the symmetric s_kq = kernel x e_kq / max(W_k, W_q) and the albedo share
/// r_kq = min(a_k, a_q) / a_k: the radiance k takes from q, q gives to k, so the remodulated
/// image's sum stays (uncovered pixels give and take nothing). The variance follows as
/// (1 - sum s l(r))^2 var_k + sum (s l(r))^2 var_q (l: the luminance weights).
pub fn atrous_conserving_pixel(
    k: usize,
    gb: &Gbuffer,
    aux: &[[f32; 4]],
    weight: &[f32],
    src: &[[f32; 4]],
    step: i32,
    p: &Params,
) -> [f32; 4] {
    if aux[k][3] < 0.0 {
        return [0.0; 4];
    }
    let c = Vec3::from_slice(&src[k][..3]);
    let (mut d, mut ssum, mut sv) = (Vec3::ZERO, 0.0f32, 0.0f32);
    conserving_taps(k, gb, aux, step, p, |q, kw| {
        let s = kw / weight[k].max(weight[q]);
        let r = s * albedo_share(gb.albedo[k], gb.albedo[q]);
        d += r * (Vec3::from_slice(&src[q][..3]) - c);
        let rl = luminance(r);
        ssum += rl;
        sv += rl * rl * src[q][3];
    });
    let o = c + d;
    [o.x, o.y, o.z, (1.0 - ssum) * (1.0 - ssum) * src[k][3] + sv]
}

/// A whole image through one iteration: SVGF's, or with `p.conserving` the three passes of
/// the conserving one.
pub fn atrous(gb: &Gbuffer, cam: &Cam, src: &[[f32; 4]], step: i32, p: &Params) -> Vec<[f32; 4]> {
    if !p.conserving {
        return (0..src.len())
            .map(|k| atrous_pixel(k, gb, cam, src, step, p))
            .collect();
    }
    let aux: Vec<[f32; 4]> = (0..src.len())
        .map(|k| atrous_prep_pixel(k, gb, cam, src))
        .collect();
    let weight: Vec<f32> = (0..src.len())
        .map(|k| atrous_weight_pixel(k, gb, &aux, step, p))
        .collect();
    (0..src.len())
        .map(|k| atrous_conserving_pixel(k, gb, &aux, &weight, src, step, p))
        .collect()
}

/// The twin's state between frames: the history buffers and the previous G-buffer and
/// camera, as the pass keeps them.
#[derive(Clone, Debug, Default)]
pub struct Frame {
    pub prev: Option<Kept>,
}

/// One frame's outputs.
#[derive(Clone, Debug)]
pub struct FrameOut {
    pub reprojected: Vec<Reprojected>,
    pub accumulated: Vec<Accumulated>,
    /// The filter's input (variance pass), then each iteration's output.
    pub filter_input: Vec<[f32; 4]>,
    pub iterations: Vec<Vec<[f32; 4]>>,
    /// The remodulated result (radiance).
    pub radiance: Vec<Vec3>,
}

impl Frame {
    /// Runs one frame of the stage on `radiance` (the method's estimate) with `iterations`
    /// à-trous steps (0: reprojection + history only) and the history fed from iteration
    /// `feedback` (0: the integrated colour).
    pub fn run(
        &mut self,
        gb: &Gbuffer,
        cam: &Cam,
        radiance: &[Vec3],
        p: &Params,
        iterations: u32,
        feedback: u32,
    ) -> FrameOut {
        let prev = self.prev.as_ref().map(|(g, c, h, m)| Previous {
            gbuffer: g,
            cam: c,
            history: h,
            moments: m,
        });
        let n = radiance.len();
        let reprojected: Vec<Reprojected> = (0..n)
            .map(|k| {
                let (x, y) = (k as u32 % gb.width, k as u32 / gb.width);
                reproject_pixel(x, y, gb, radiance[k], cam, prev, p)
            })
            .collect();
        let accumulated: Vec<Accumulated> = (0..n)
            .map(|k| accumulate_pixel(k, gb, cam, &reprojected, p))
            .collect();
        let mut hist: Vec<[f32; 4]> = accumulated.iter().map(|a| a.color).collect();
        let moments: Vec<[f32; 4]> = accumulated.iter().map(|a| a.moments).collect();
        let mut out_demod: Vec<[f32; 4]> = hist.clone();
        let mut filter_input = Vec::new();
        let mut its = Vec::new();
        if iterations > 0 {
            filter_input = (0..n)
                .map(|k| variance_pixel(k, gb, cam, &accumulated, p))
                .collect();
            let mut cur = filter_input.clone();
            for i in 1..=iterations {
                cur = atrous(gb, cam, &cur, 1 << (i - 1), p);
                if i == feedback {
                    for (h, c) in hist.iter_mut().zip(&cur) {
                        *h = [c[0], c[1], c[2], h[3]];
                    }
                }
                its.push(cur.clone());
            }
            out_demod = cur;
        }
        let radiance_out = (0..n)
            .map(|k| {
                if gb.covered(k) {
                    Vec3::from_slice(&out_demod[k][..3]) * gb.albedo[k]
                } else {
                    Vec3::ZERO
                }
            })
            .collect();
        let mut stored = gb.clone();
        for (k, nrm) in stored.normal.iter_mut().enumerate() {
            if !gb.covered(k) {
                *nrm = Vec3::ZERO;
            } else {
                *nrm = nrm.normalize_or_zero();
            }
        }
        self.prev = Some((stored, *cam, hist, moments));
        FrameOut {
            reprojected,
            accumulated,
            filter_input,
            iterations: its,
            radiance: radiance_out,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Camera;

    /// A camera looking down -z at the plane z = 0 (or a step in it), covering [-1, 1]^2.
    fn plane(w: u32, h: u32, step_at: Option<u32>) -> (Gbuffer, Cam) {
        let cam = Camera::look_at(
            "t",
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::ZERO,
            2.0 * (0.5f32).atan(),
            0.1,
            10.0,
        );
        let c = Cam::new(&cam, w, h);
        let mut gb = Gbuffer {
            width: w,
            height: h,
            position: Vec::new(),
            normal: Vec::new(),
            albedo: Vec::new(),
        };
        for y in 0..h {
            for x in 0..w {
                let px = (x as f32 + 0.5) / w as f32 * 2.0 - 1.0;
                let py = 1.0 - (y as f32 + 0.5) / h as f32 * 2.0;
                let dir = c.forward + px * c.right + py * c.up;
                // A depth step (a second, nearer plane) right of column `step_at`.
                let (zp, mat) = match step_at {
                    Some(s) if x >= s => (0.5, 2.0),
                    _ => (0.0, 1.0),
                };
                let t = (c.eye.z - zp) / -dir.z;
                let pnt = c.eye + t * dir;
                gb.position.push([pnt.x, pnt.y, pnt.z, mat]);
                gb.normal.push(Vec3::Z);
                gb.albedo.push(Vec3::splat(0.5));
            }
        }
        (gb, c)
    }

    /// Uniform numbers in [0, 1] (a PCG hash chain from `seed`).
    fn uniform(seed: u32) -> impl FnMut() -> f32 {
        let mut rng = seed;
        move || {
            rng = rng.wrapping_mul(747796405).wrapping_add(2891336453);
            let x = ((rng >> ((rng >> 28) + 4)) ^ rng).wrapping_mul(277803737);
            ((x >> 22) ^ x) as f32 / u32::MAX as f32
        }
    }

    #[test]
    fn a_pixel_reprojects_to_itself_under_a_still_camera() {
        let (gb, cam) = plane(16, 12, None);
        let (x, y) = (5, 7);
        let (pp, z) = cam.pixel_of(gb.point((y * 16 + x) as usize));
        assert!((pp - Vec2::new(x as f32, y as f32)).length() < 1e-3, "{pp}");
        assert!(z > 0.0);
    }

    /// Both choices of the à-trous.
    fn both() -> [Params; 2] {
        [
            Params::default(),
            Params {
                conserving: false,
                ..Params::default()
            },
        ]
    }

    #[test]
    fn the_filter_leaves_a_constant_image_unchanged() {
        let (gb, cam) = plane(24, 20, Some(12));
        let src = vec![[0.3, 0.6, 0.9, 0.01]; 24 * 20];
        for p in both() {
            for step in [1, 2, 4] {
                let out = atrous(&gb, &cam, &src, step, &p);
                for o in &out {
                    for i in 0..3 {
                        assert!((o[i] - src[0][i]).abs() < 1e-5, "{o:?}");
                    }
                }
            }
        }
    }

    /// The symmetric weights are symmetric to the bit, so the conserving filter moves light
    /// and never makes or loses it: SLC-like right-skewed noise (0.5 with probability 0.95,
    /// 10.5 otherwise: mean 1) of the demodulated GI on a plane with a depth step and a second
    /// albedo, 4 still frames, 5 iterations, history from iteration 1. Its output's mean is
    /// the frames' mean (the history of a still view averages them exactly over 4 frames);
    /// SVGF's normalisation by each pixel's own weight sum, with the luminance scale from the
    /// pixel's own variance, lets an outlier give light to its neighbours but not take
    /// theirs: darker.
    #[test]
    fn the_conserving_filter_keeps_the_mean_of_skewed_noise_and_svgfs_loses_light() {
        let (w, h) = (48, 32);
        let (mut gb, cam) = plane(w, h, Some(30));
        let n = (w * h) as usize;
        // A stripe of another albedo on the far plane.
        for k in 0..n {
            if (10..20).contains(&(k as u32 % w)) {
                gb.albedo[k] = Vec3::new(0.8, 0.6, 0.3);
            }
        }
        let mut next = uniform(777);
        let frames: Vec<Vec<Vec3>> = (0..4)
            .map(|_| {
                (0..n)
                    .map(|k| {
                        let x = if next() < 0.95 { 0.5 } else { 10.5 };
                        x * gb.albedo[k]
                    })
                    .collect()
            })
            .collect();
        let mean = |img: &[Vec3]| img.iter().map(|&c| luminance(c) as f64).sum::<f64>() / img.len() as f64;
        let raw = frames.iter().map(|f| mean(f.as_slice())).sum::<f64>() / frames.len() as f64;
        let mut ratios = Vec::new();
        for p in both() {
            let mut f = Frame::default();
            let mut out = None;
            for img in &frames {
                out = Some(f.run(&gb, &cam, img, &p, 5, 1));
            }
            let out = out.expect("four frames ran");
            let m = mean(&out.radiance);
            eprintln!(
                "{}: output mean {m:.6}, raw mean {raw:.6}, ratio - 1 = {:.2e}",
                if p.conserving { "conserving" } else { "svgf" },
                m / raw - 1.0
            );
            // Not vacuous: the filter smoothed the outliers away.
            let max = out.radiance.iter().map(|c| c.x).fold(0.0f32, f32::max);
            assert!(max < 0.5 * 10.5 * 0.8, "max {max}");
            ratios.push(m / raw);
        }
        assert!((ratios[0] - 1.0).abs() < 1e-4, "conserving: {}", ratios[0]);
        assert!(ratios[1] < 0.97, "svgf: {}", ratios[1]);
    }

    /// The conserving weights' pieces: e(a, b) = e(b, a) bit for bit, each pixel's taps sum
    /// below 1 (a convex combination), and an uncovered pixel neither gives nor takes.
    #[test]
    fn the_conserving_weights_are_symmetric_and_convex() {
        let (w, h) = (20, 16);
        let (mut gb, cam) = plane(w, h, Some(10));
        // A hole (sky) in the middle.
        gb.position[(8 * w + 5) as usize][3] = 0.0;
        let mut next = uniform(99);
        // Albedos of every kind, a black channel (no demodulated GI) among them.
        for a in gb.albedo.iter_mut() {
            *a = Vec3::new(next(), next(), if next() < 0.2 { 0.0 } else { next() });
        }
        let src: Vec<[f32; 4]> = (0..w * h)
            .map(|_| {
                let v = 3.0 * next();
                [v, 0.5 * v, v, next()]
            })
            .collect();
        let p = Params::default();
        let aux: Vec<[f32; 4]> = (0..src.len())
            .map(|k| atrous_prep_pixel(k, &gb, &cam, &src))
            .collect();
        assert_eq!(aux[(8 * w + 5) as usize], [0.0, 0.0, 0.0, -1.0]);
        for step in [1, 2] {
            let weight: Vec<f32> = (0..src.len())
                .map(|k| atrous_weight_pixel(k, &gb, &aux, step, &p))
                .collect();
            let mut taken = vec![vec![0.0f32; src.len()]; src.len()];
            for k in 0..src.len() {
                let mut sum = 0.0;
                conserving_taps(k, &gb, &aux, step, &p, |q, kw| {
                    let s = kw / weight[k].max(weight[q]);
                    taken[k][q] = s;
                    sum += s;
                });
                assert!(sum < 1.0, "{k}: {sum}");
            }
            for (k, row) in taken.iter().enumerate() {
                for (q, s) in row.iter().enumerate() {
                    assert_eq!(s.to_bits(), taken[q][k].to_bits(), "{k} {q}");
                }
            }
            let hole = (8 * w + 5) as usize;
            assert!(taken[hole].iter().all(|&s| s == 0.0));
            let out = atrous(&gb, &cam, &src, step, &p);
            assert_eq!(out[hole], [0.0; 4]);
            // The remodulated sum over the covered pixels (the hole's input is not the
            // image's; a channel of albedo 0 has no GI), per channel.
            let sum = |img: &[[f32; 4]], i: usize| {
                (0..img.len())
                    .filter(|&k| gb.covered(k) && gb.albedo[k][i] > 1e-3)
                    .map(|k| (img[k][i] * gb.albedo[k][i]) as f64)
                    .sum::<f64>()
            };
            for i in 0..3 {
                let r = sum(&out, i) / sum(&src, i);
                assert!((r - 1.0).abs() < 1e-5, "step {step}, channel {i}: {r}");
            }
        }
    }

    /// White noise of variance s^2 on a plane, one iteration without luminance stopping:
    /// the output variance is s^2 times the sum of the squared normalised weights,
    /// (sum_i h_i^2)^2 = 0.0748 for the B3 kernel (away from the image's edges).
    #[test]
    fn one_iteration_reduces_white_noise_variance_by_the_kernels_factor() {
        let (w, h) = (96, 96);
        let (gb, cam) = plane(w, h, None);
        let mut next = uniform(12345);
        let s2 = 1.0 / 12.0; // uniform [0, 1)
        let src: Vec<[f32; 4]> = (0..w * h)
            .map(|_| {
                let v = next();
                [v, v, v, s2]
            })
            .collect();
        // Both choices: with every edge weight 1 the conserving weights are SVGF's.
        for p in both() {
            let p = Params { sigma_l: 1e4, ..p };
            let out = atrous(&gb, &cam, &src, 1, &p);
            let inner: Vec<f32> = (0..(w * h) as usize)
                .filter(|k| {
                    let (x, y) = (*k as u32 % w, *k as u32 / w);
                    (4..w - 4).contains(&x) && (4..h - 4).contains(&y)
                })
                .map(|k| out[k][0])
                .collect();
            let mean = inner.iter().sum::<f32>() / inner.len() as f32;
            let var = inner.iter().map(|v| (v - mean).powi(2)).sum::<f32>() / (inner.len() - 1) as f32;
            let factor: f32 = B3.iter().map(|h| h * h).sum::<f32>() * 2.0 - B3[0] * B3[0];
            let expected = s2 * factor * factor;
            // 7744 correlated samples: the estimate's relative error is a few percent.
            assert!(
                (var / expected - 1.0).abs() < 0.1,
                "variance {var}, expected {expected}"
            );
            // The propagated variance estimate says the same.
            let est = out[(48 * w + 48) as usize][3];
            assert!(
                (est / expected - 1.0).abs() < 0.05,
                "estimate {est}, expected {expected}"
            );
            assert!((mean - 0.5).abs() < 0.01);
        }
    }

    #[test]
    fn edges_in_depth_and_normal_survive_the_filter() {
        let (w, h) = (32, 16);
        let (gb, cam) = plane(w, h, Some(16));
        // Left plane dark, right plane bright: the filter must not blur across the step.
        let src: Vec<[f32; 4]> = (0..w * h)
            .map(|k| {
                if k % w >= 16 {
                    [1.0, 1.0, 1.0, 0.5]
                } else {
                    [0.1, 0.1, 0.1, 0.5]
                }
            })
            .collect();
        for p in both() {
            let mut cur = src.clone();
            for i in 0..5 {
                cur = atrous(&gb, &cam, &cur, 1 << i, &p);
            }
            for y in 0..h {
                let l = cur[(y * w + 15) as usize][0];
                let r = cur[(y * w + 16) as usize][0];
                assert!((l - 0.1).abs() < 0.01 && (r - 1.0).abs() < 0.01, "{l} {r}");
            }
        }
        // A normal step (same depth, a crease) likewise.
        let mut gb2 = gb.clone();
        for k in 0..(w * h) as usize {
            gb2.position[k][2] = 0.0;
            gb2.position[k][3] = 1.0;
            if k as u32 % w >= 16 {
                gb2.normal[k] = Vec3::new(0.6, 0.0, 0.8);
            }
        }
        for p in both() {
            let mut cur = src.clone();
            for i in 0..5 {
                cur = atrous(&gb2, &cam, &cur, 1 << i, &p);
            }
            let l = cur[(8 * w + 15) as usize][0];
            let r = cur[(8 * w + 16) as usize][0];
            assert!((l - 0.1).abs() < 0.01 && (r - 1.0).abs() < 0.01, "{l} {r}");
        }
    }

    #[test]
    fn a_still_camera_keeps_the_whole_history_and_a_reveal_is_disoccluded() {
        let (w, h) = (24, 16);
        let (gb, cam) = plane(w, h, None);
        let mut f = Frame::default();
        let rad = vec![Vec3::splat(0.25); (w * h) as usize];
        f.run(&gb, &cam, &rad, &Params::default(), 0, 0);
        let o = f.run(&gb, &cam, &rad, &Params::default(), 0, 0);
        assert!(o.reprojected.iter().all(|r| (r.mask - 1.0).abs() < 1e-4));
        assert!(o.accumulated.iter().all(|a| a.color[3] == 2.0));
        // The near plane appears over the right half: those pixels lose their history.
        let (gb2, _) = plane(w, h, Some(12));
        let o = f.run(&gb2, &cam, &rad, &Params::default(), 0, 0);
        for k in 0..(w * h) as usize {
            let right = k as u32 % w >= 12;
            assert_eq!(o.reprojected[k].mask == 0.0, right, "{k}");
            assert_eq!(o.accumulated[k].color[3], if right { 1.0 } else { 3.0 });
        }
    }
}

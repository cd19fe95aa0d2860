//! CPU twin of imperfect shadow maps (Ritschel et al. 2008, as the VAL paper uses them:
//! Weinzierl-Heigl, section 5): a point cloud sampled once from the scene's triangles
//! (area-uniform), the points shared out round-robin between the lights (point k to light
//! k mod N) or a share per light (Stochastic Light Culling's adaptive ISMs, its section 4.3),
//! those within the light's range each splatted as one texel into its light's paraboloid map (Brabec et al. 2002:
//! the hemisphere around the light's normal) in one atlas, keeping the nearest distance; holes
//! filled by pull-push over a few coarser levels; a lookup compares a point's distance to the
//! map's. Twin of `shaders/ism.wgsl` and `shaders/common/ism.wgsl`.

use glam::{Vec2, Vec3};

use super::vpl::{pcg_hash, u01};

/// An oriented point light with a range beyond which its map keeps no point (`EMPTY`: none).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IsmLight {
    pub position: Vec3,
    pub normal: Vec3,
    pub range: f32,
}

impl IsmLight {
    /// A light without a range.
    pub fn new(position: Vec3, normal: Vec3) -> Self {
        Self {
            position,
            normal,
            range: EMPTY,
        }
    }
}

/// The points of light `m`'s map: with `per_light` 0 every N-th point of the cloud from
/// point m (the VAL paper: round-robin), otherwise `per_light` points spread over the whole
/// cloud, every (cloud / per_light)-th from point m, wrapping (Stochastic Light Culling's
/// adaptive ISMs, section 4.3: 8192 points per VPL; the cloud is in area order, so a
/// consecutive run would cover a few triangles). Twin: the index arithmetic of `splat_main`.
pub fn light_points(m: u32, lights: u32, per_light: u32, cloud: u32) -> impl Iterator<Item = u32> {
    let n = lights.max(1);
    let (start, step, count) = match cloud.checked_div(per_light) {
        None => (m, n, (cloud + n - 1 - m.min(cloud)) / n),
        Some(stride) => (m, stride.max(1), per_light),
    };
    (0..count).map(move |j| ((start as u64 + j as u64 * step as u64) % cloud.max(1) as u64) as u32)
}

/// An empty texel (no point landed there, nothing filled it): lookups see no occluder.
/// Twin: `ISM_EMPTY`.
pub const EMPTY: f32 = 1e30;

/// The atlas: square maps of `tile` texels in a square of `atlas` texels, row-major.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IsmLayout {
    pub atlas: u32,
    pub tile: u32,
}

impl IsmLayout {
    /// Maps per atlas row.
    pub fn per_row(self) -> u32 {
        (self.atlas / self.tile.max(1)).max(1)
    }
    /// How many maps (lights) the atlas holds.
    pub fn capacity(self) -> u32 {
        self.per_row() * self.per_row()
    }
    /// The atlas index of texel (u, v) of map `m`.
    pub fn texel(self, m: u32, u: u32, v: u32) -> usize {
        let (mx, my) = (m % self.per_row(), m / self.per_row());
        ((my * self.tile + v) * self.atlas + mx * self.tile + u) as usize
    }
}

/// `count` points on the triangles, uniform in area: stratified over the cumulative area
/// (point i at (i + xi) / count), then uniform in its triangle. Deterministic in `seed`.
pub fn sample_points(positions: &[Vec3], indices: &[u32], count: u32, seed: u32) -> Vec<Vec3> {
    sample_oriented_points(positions, indices, count, seed)
        .into_iter()
        .map(|(p, _)| p)
        .collect()
}

/// [`sample_points`] with each point's triangle normal ((b - a) x (c - a), normalised; zero
/// for a degenerate triangle): the orientation front-face culling tests.
pub fn sample_oriented_points(
    positions: &[Vec3],
    indices: &[u32],
    count: u32,
    seed: u32,
) -> Vec<(Vec3, Vec3)> {
    let tri = |t: usize| {
        let i = &indices[3 * t..3 * t + 3];
        [
            positions[i[0] as usize],
            positions[i[1] as usize],
            positions[i[2] as usize],
        ]
    };
    let n = indices.len() / 3;
    let mut cdf = Vec::with_capacity(n);
    let mut total = 0.0f64;
    for t in 0..n {
        let [a, b, c] = tri(t);
        total += 0.5 * (b - a).cross(c - a).length() as f64;
        cdf.push(total);
    }
    if n == 0 || total <= 0.0 {
        return Vec::new();
    }
    (0..count)
        .map(|i| {
            let h = pcg_hash(seed ^ pcg_hash(i));
            let target = (i as f64 + u01(h) as f64) / count as f64 * total;
            let t = cdf.partition_point(|&c| c < target).min(n - 1);
            let [a, b, c] = tri(t);
            let (r1, r2) = (u01(pcg_hash(h ^ 0x68e3_1da4)), u01(pcg_hash(h ^ 0x2545_f491)));
            let s = r1.sqrt();
            (
                a * (1.0 - s) + b * (s * (1.0 - r2)) + c * (s * r2),
                (b - a).cross(c - a).normalize_or_zero(),
            )
        })
        .collect()
}

/// An orthonormal frame (t, b) around unit `n` (Duff et al. 2017). Twin: `ism_basis`.
pub fn basis(n: Vec3) -> (Vec3, Vec3) {
    // As the GPU's select(-1, 1, n.z >= 0): -0.0 counts as positive.
    let sign = if n.z >= 0.0 { 1.0f32 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// The paraboloid projection of `p` seen from a light at `c` with unit normal `n`: map
/// coordinates in [0, 1]^2 and the distance, or None behind the light's hemisphere (or at
/// the light). Twin: `ism_project`.
pub fn project(c: Vec3, n: Vec3, p: Vec3) -> Option<(Vec2, f32)> {
    let d = p - c;
    let dist = d.length();
    if dist <= 1e-6 {
        return None;
    }
    let w = d / dist;
    let z = w.dot(n);
    if z <= 0.0 {
        return None;
    }
    let (t, b) = basis(n);
    let q = Vec2::new(w.dot(t), w.dot(b)) / (1.0 + z);
    Some((q * 0.5 + 0.5, dist))
}

/// The texel of map coordinates `uv` in a `tile`-texel map.
pub fn texel_of(uv: Vec2, tile: u32) -> (u32, u32) {
    let f = |x: f32| ((x * tile as f32) as i32).clamp(0, tile as i32 - 1) as u32;
    (f(uv.x), f(uv.y))
}

/// Splats each light's points (`light_points`) into its map, those within its range, the
/// nearest distance per texel. Twin: `splat_main` in `ism.wgsl`.
pub fn splat(layout: IsmLayout, lights: &[IsmLight], points: &[Vec3], per_light: u32) -> Vec<f32> {
    splat_culled(layout, lights, points, None, per_light)
}

/// [`splat`], and with `normals` front-face culling (Stochastic Light Culling's Program 1,
/// after Tokuyoshi 2014): a point whose normal faces the light (n . (p - c) < 0) is left
/// out (a zero normal never is). A lit receiver faces its light, so its own surface's points never shadow it; the
/// back faces of closed objects still do (a one-sided occluder facing the light does not).
pub fn splat_culled(
    layout: IsmLayout,
    lights: &[IsmLight],
    points: &[Vec3],
    normals: Option<&[Vec3]>,
    per_light: u32,
) -> Vec<f32> {
    splat_sized(layout, lights, points, normals, per_light, 0.0)
}

/// A splat reaches at most this many texels from a point's own. Twin: `ISM_MAX_POINT_TEXELS`.
pub const MAX_POINT_TEXELS: f32 = 8.0;

/// [`splat_culled`] with points of world radius `point_radius` (the VAL paper's point
/// sprites, sized by distance): a point at distance d, at cosine z to the light's normal,
/// covers r = point_radius / d x 0.5 / (1 + z) x tile texels, the (2k + 1)^2 square of
/// k = floor(min(r, MAX_POINT_TEXELS)) around its own texel (inside the map); 0: one texel.
/// Twin: `splat_main` in `ism.wgsl`.
pub fn splat_sized(
    layout: IsmLayout,
    lights: &[IsmLight],
    points: &[Vec3],
    normals: Option<&[Vec3]>,
    per_light: u32,
    point_radius: f32,
) -> Vec<f32> {
    let mut atlas = vec![EMPTY; (layout.atlas * layout.atlas) as usize];
    let n = (lights.len() as u32).min(layout.capacity());
    if points.is_empty() {
        return atlas;
    }
    for m in 0..n {
        let l = lights[m as usize];
        for k in light_points(m, n, per_light, points.len() as u32) {
            let p = points[k as usize];
            if (p - l.position).length_squared() >= l.range * l.range {
                continue;
            }
            if normals.is_some_and(|n| n[k as usize].dot(p - l.position) < 0.0) {
                continue;
            }
            if let Some((uv, dist)) = project(l.position, l.normal, p) {
                let (u, v) = texel_of(uv, layout.tile);
                let k = if point_radius > 0.0 {
                    let z = ((p - l.position) / dist).dot(l.normal);
                    let r = point_radius / dist * 0.5 / (1.0 + z) * layout.tile as f32;
                    r.min(MAX_POINT_TEXELS) as i32
                } else {
                    0
                };
                let t = layout.tile as i32;
                for dv in -k..=k {
                    for du in -k..=k {
                        let (uu, vv) = (u as i32 + du, v as i32 + dv);
                        if uu < 0 || vv < 0 || uu >= t || vv >= t {
                            continue;
                        }
                        let i = layout.texel(m, uu as u32, vv as u32);
                        atlas[i] = atlas[i].min(dist);
                    }
                }
            }
        }
    }
    atlas
}

/// Pull-push hole filling (Ritschel et al. 2008, after Grossman & Dally / Marroquim et al.)
/// over `levels` coarser levels of each of the first `maps` maps: pull averages a 2 x 2
/// block's filled texels into the coarser level; push then fills each empty texel from the
/// level above it, coarsest first. Filled texels keep their depth; a hole wider than about
/// 2^levels texels keeps empty texels. Twin: `pull_main`, `push_main` in `ism.wgsl`.
pub fn pull_push(layout: IsmLayout, atlas: &mut [f32], maps: u32, levels: u32) {
    let tile = layout.tile as usize;
    for m in 0..maps.min(layout.capacity()) {
        let mut pyr: Vec<Vec<f32>> = vec![
            (0..tile * tile)
                .map(|k| atlas[layout.texel(m, (k % tile) as u32, (k / tile) as u32)])
                .collect(),
        ];
        for l in 1..=levels as usize {
            let s = tile >> l;
            if s == 0 {
                break;
            }
            let below = &pyr[l - 1];
            let sb = tile >> (l - 1);
            let lvl: Vec<f32> = (0..s * s)
                .map(|k| {
                    let (x, y) = (k % s, k / s);
                    let (mut sum, mut w) = (0.0f32, 0.0f32);
                    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let v = below[(2 * y + dy) * sb + 2 * x + dx];
                        if v < EMPTY {
                            sum += v;
                            w += 1.0;
                        }
                    }
                    if w > 0.0 { sum / w } else { EMPTY }
                })
                .collect();
            pyr.push(lvl);
        }
        for l in (0..pyr.len() - 1).rev() {
            let s = tile >> l;
            let sa = tile >> (l + 1);
            for k in 0..s * s {
                if pyr[l][k] < EMPTY {
                    continue;
                }
                let (x, y) = (k % s, k / s);
                pyr[l][k] = pyr[l + 1][(y / 2) * sa + x / 2];
            }
        }
        for (k, &v) in pyr[0].iter().enumerate() {
            atlas[layout.texel(m, (k % tile) as u32, (k / tile) as u32)] = v;
        }
    }
}

/// Whether map `m` (light at `c`, normal `n`) sees `x`: its distance shortened by the
/// relative `bias` at most the map's depth (the receiver's own surface is in the map: a texel
/// holds the nearest of the points that land in it); a point behind the light's hemisphere or
/// on an empty texel is seen. Twin: `ism_visible` in `common/ism.wgsl`.
pub fn visible(layout: IsmLayout, atlas: &[f32], m: u32, c: Vec3, n: Vec3, x: Vec3, bias: f32) -> bool {
    let Some((uv, dist)) = project(c, n, x) else {
        return true;
    };
    let (u, v) = texel_of(uv, layout.tile);
    dist * (1.0 - bias) <= atlas[layout.texel(m, u, v)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sized_point_covers_the_texels_within_its_radius() {
        let layout = IsmLayout { atlas: 64, tile: 64 };
        let light = IsmLight::new(Vec3::ZERO, Vec3::Z);
        // On the axis at 2 m: 0.25 uv per radian; radius 0.1 m = 0.05 rad = 0.8 texels (one
        // texel), 0.4 m = 3.2 texels (7 x 7), 10 m capped at 8 texels (17 x 17).
        for (radius, k) in [(0.0, 0), (0.1, 0), (0.4, 3), (10.0, 8)] {
            let a = splat_sized(layout, &[light], &[Vec3::new(0.0, 0.0, 2.0)], None, 0, radius);
            let filled = a.iter().filter(|&&d| d < EMPTY).count();
            assert_eq!(filled, ((2 * k + 1) * (2 * k + 1)) as usize, "radius {radius}");
            assert!(a.iter().all(|&d| d == EMPTY || d == 2.0));
        }
        // Near the map's edge (texel 63 of 64; 1.6 texels: 3 x 3) the square is cut off.
        let p = Vec3::new(2.0, 0.0, 0.01);
        let a = splat_sized(layout, &[light], &[p], None, 0, 0.1);
        assert_eq!(a.iter().filter(|&&d| d < EMPTY).count(), 6);
    }

    #[test]
    fn the_projection_covers_the_hemisphere_and_the_frame_is_orthonormal() {
        for n in [
            Vec3::Z,
            Vec3::NEG_Z,
            Vec3::X,
            Vec3::new(0.3, -0.8, 0.52).normalize(),
        ] {
            let (t, b) = basis(n);
            assert!(t.dot(b).abs() < 1e-5 && t.dot(n).abs() < 1e-5 && b.dot(n).abs() < 1e-5);
            assert!((t.length() - 1.0).abs() < 1e-5 && (b.length() - 1.0).abs() < 1e-5);
            // Along the normal: the map's centre; at the horizon: its rim; behind: none.
            let (uv, d) = project(Vec3::ONE, n, Vec3::ONE + 2.0 * n).unwrap();
            assert!((uv - Vec2::splat(0.5)).length() < 1e-5 && (d - 2.0).abs() < 1e-5);
            let (uv, _) = project(Vec3::ONE, n, Vec3::ONE + t + 1e-4 * n).unwrap();
            assert!(((uv - Vec2::splat(0.5)).length() - 0.5).abs() < 1e-3);
            assert!(project(Vec3::ONE, n, Vec3::ONE - n).is_none());
        }
    }

    #[test]
    fn each_light_takes_its_share_of_the_points() {
        // Round-robin: the lights partition the cloud.
        let mut seen = vec![0; 103];
        for m in 0..7 {
            for k in light_points(m, 7, 0, 103) {
                seen[k as usize] += 1;
                assert_eq!(k % 7, m);
            }
        }
        assert!(seen.iter().all(|&c| c == 1));
        // Per light: every (cloud / per_light)-th point from m, wrapping; distinct points.
        let v: Vec<u32> = light_points(3, 7, 40, 103).collect();
        assert_eq!(v.len(), 40);
        assert_eq!((v[0], v[1], v[39]), (3, 5, 81));
        let w: Vec<u32> = light_points(2, 7, 200, 103).collect();
        assert_eq!((w[0], w[101], w[102], w[103]), (2, 0, 1, 2));
        let distinct: std::collections::HashSet<u32> = v.iter().copied().collect();
        assert_eq!(distinct.len(), 40);
    }

    #[test]
    fn a_range_keeps_farther_points_out_of_the_map() {
        // A light 1 m over a 2 x 2 m floor with a range of 1.2 m: its map (pull-push
        // included) holds no depth of 1.2 or more; without a range it does.
        let pos = vec![
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(-1.0, 0.0, 1.0),
        ];
        let pts = sample_points(&pos, &[0, 1, 2, 0, 2, 3], 20_000, 5);
        let layout = IsmLayout { atlas: 32, tile: 32 };
        let mut light = IsmLight::new(Vec3::Y, Vec3::NEG_Y);
        let far = |a: &[f32]| a.iter().filter(|&&d| (1.2..EMPTY).contains(&d)).count();
        assert!(far(&splat(layout, &[light], &pts, 0)) > 50);
        light.range = 1.2;
        let mut a = splat(layout, &[light], &pts, 0);
        // The disc within range (radius 0.66 m, 34 degrees off the normal) covers about 70
        // texels of the map; pull-push then spreads its depths a few texels outwards, never a
        // farther one.
        let filled = |a: &[f32]| a.iter().filter(|&&d| d < EMPTY).count();
        let splatted = filled(&a);
        assert!((40..120).contains(&splatted), "{splatted}");
        pull_push(layout, &mut a, 1, 2);
        assert_eq!(far(&a), 0);
        assert!(filled(&a) > splatted);
    }

    #[test]
    fn points_are_uniform_in_area() {
        // Two triangles, areas 1 and 3: a quarter of the points on the first.
        let p = vec![
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 5.0),
            Vec3::new(3.0, 0.0, 5.0),
            Vec3::new(0.0, 2.0, 5.0),
        ];
        let pts = sample_points(&p, &[0, 1, 2, 3, 4, 5], 4000, 7);
        let first = pts.iter().filter(|q| q.z < 1.0).count();
        assert_eq!(first, 1000, "stratified over the cumulative area");
        // Inside the first triangle: x / 2 + y <= 1; its centroid's mean.
        let mean: Vec3 = pts.iter().filter(|q| q.z < 1.0).sum::<Vec3>() / first as f32;
        assert!(
            (mean - Vec3::new(2.0 / 3.0, 1.0 / 3.0, 0.0)).length() < 0.03,
            "{mean}"
        );
        assert!(
            pts.iter()
                .filter(|q| q.z < 1.0)
                .all(|q| q.x / 2.0 + q.y <= 1.0 + 1e-5)
        );
    }

    #[test]
    fn pull_push_fills_a_hole_of_known_size() {
        // A 16 x 16 map of a constant depth with a 3 x 3 hole (two levels fill it) and, in a
        // second map, an empty 12 x 12 block (wider than 2^2 texels: its middle stays empty).
        let layout = IsmLayout { atlas: 32, tile: 16 };
        let mut atlas = vec![EMPTY; 32 * 32];
        for m in 0..2 {
            for v in 0..16 {
                for u in 0..16 {
                    let hole = if m == 0 {
                        (5..8).contains(&u) && (9..12).contains(&v)
                    } else {
                        (2..14).contains(&u) && (2..14).contains(&v)
                    };
                    if !hole {
                        atlas[layout.texel(m, u, v)] = 2.5;
                    }
                }
            }
        }
        pull_push(layout, &mut atlas, 2, 2);
        for v in 0..16 {
            for u in 0..16 {
                assert_eq!(atlas[layout.texel(0, u, v)], 2.5, "map 0 ({u}, {v})");
            }
        }
        let empty = (0..256)
            .filter(|k| atlas[layout.texel(1, k % 16, k / 16)] == EMPTY)
            .count();
        assert!(
            empty > 0 && empty < 144,
            "the wide hole is filled at its border only: {empty}"
        );
        // The other maps are untouched.
        assert_eq!(atlas[layout.texel(2, 3, 3)], EMPTY);
    }
}

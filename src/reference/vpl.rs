//! References of `shaders/common/random.wgsl` and `shaders/vpl_gen.wgsl`: Hammersley points,
//! PDF pyramids, hierarchical warping, the edge-aware importance filter.

use glam::Vec3;

pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

pub fn u01(h: u32) -> f32 {
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

pub fn radical_inverse_2(i: u32) -> f32 {
    (i.reverse_bits() >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// Point i of an n-point Hammersley set rotated by `rot` (Cranley-Patterson).
pub fn hammersley(i: u32, n: u32, rot: [f32; 2]) -> [f32; 2] {
    let p = [i as f32 / n as f32 + rot[0], radical_inverse_2(i) + rot[1]];
    p.map(|v| (v - v.floor()).min(0.999_999_94))
}

/// Sum pyramid of a `res` x `res` map (res a power of two): level 0 = the map, each level
/// the 2x2 sums of the one below, the last level one value (the total).
pub fn pyramid(level0: &[f32], res: u32) -> Vec<Vec<f32>> {
    let mut levels = vec![level0.to_vec()];
    let mut r = res;
    while r > 1 {
        let prev = levels.last().map(|l| l.as_slice()).unwrap_or(&[]);
        let n = r / 2;
        let mut next = vec![0.0f32; (n * n) as usize];
        for y in 0..n {
            for x in 0..n {
                let i = |xx: u32, yy: u32| prev[(yy * r + xx) as usize];
                // Same association as the GPU: (a + b) + (c + d).
                next[(y * n + x) as usize] =
                    (i(2 * x, 2 * y) + i(2 * x + 1, 2 * y)) + (i(2 * x, 2 * y + 1) + i(2 * x + 1, 2 * y + 1));
            }
        }
        levels.push(next);
        r = n;
    }
    levels
}

/// Hierarchical warping (Clarberg et al. 2005) of `uv` through `pyr`: from the top, at each
/// level split vertically by the rows' sums, then horizontally within the chosen row, and
/// rescale the coordinate to [0, 1). Returns (texel x, texel y, pmf).
pub fn warp(pyr: &[Vec<f32>], res: u32, uv: [f32; 2]) -> (u32, u32, f32) {
    let (mut u, mut v) = (uv[0], uv[1]);
    let (mut x, mut y) = (0u32, 0u32);
    let one_minus = 0.999_999_94f32;
    for l in (1..pyr.len()).rev() {
        let cl = l - 1;
        let r = res >> cl;
        let w = |xx: u32, yy: u32| pyr[cl][(yy * r + xx) as usize];
        let (a, b, c, d) = (
            w(2 * x, 2 * y),
            w(2 * x + 1, 2 * y),
            w(2 * x, 2 * y + 1),
            w(2 * x + 1, 2 * y + 1),
        );
        let pt = (a + b) / ((a + b) + (c + d));
        let row = if v < pt {
            v = (v / pt).min(one_minus);
            0
        } else {
            v = ((v - pt) / (1.0 - pt)).min(one_minus);
            1
        };
        let (left, right) = if row == 0 { (a, b) } else { (c, d) };
        let pl = left / (left + right);
        let col = if u < pl {
            u = (u / pl).min(one_minus);
            0
        } else {
            u = ((u - pl) / (1.0 - pl)).min(one_minus);
            1
        };
        x = 2 * x + col;
        y = 2 * y + row;
    }
    let total = pyr[pyr.len() - 1][0];
    (x, y, pyr[0][(y * res + x) as usize] / total)
}

/// Similarity S (thesis eq. 5.3) of two RSM texels (positions with w = validity).
pub fn similar(pa: [f32; 4], na: Vec3, pb: [f32; 4], nb: Vec3, n_min: f32, d_max: f32) -> bool {
    pa[3] > 0.0
        && pb[3] > 0.0
        && na.dot(nb) > n_min
        && Vec3::new(pa[0], pa[1], pa[2]).distance(Vec3::new(pb[0], pb[1], pb[2])) < d_max
}

/// The edge-aware Gaussian filter of `shaders/vpl_gen.wgsl` (`filter_importance`) on one layer.
pub fn filter(
    raw: &[f32],
    pos: &[[f32; 4]],
    nrm: &[Vec3],
    res: u32,
    radius: u32,
    n_min: f32,
    d_max: f32,
) -> Vec<f32> {
    let r = radius as i32;
    let sigma = 0.5 * r as f32;
    (0..res * res)
        .map(|k| {
            let (x, y) = ((k % res) as i32, (k / res) as i32);
            let pa = pos[k as usize];
            if r == 0 || pa[3] == 0.0 {
                return raw[k as usize];
            }
            let (mut num, mut den) = (0.0f32, 0.0f32);
            for dy in -r..=r {
                for dx in -r..=r {
                    let (cx, cy) = (x + dx, y + dy);
                    if cx < 0 || cy < 0 || cx >= res as i32 || cy >= res as i32 {
                        continue;
                    }
                    let j = (cy as u32 * res + cx as u32) as usize;
                    if !similar(pa, nrm[k as usize], pos[j], nrm[j], n_min, d_max) {
                        continue;
                    }
                    let g = (-((dx * dx + dy * dy) as f32) / (2.0 * sigma * sigma)).exp();
                    num += g * raw[j];
                    den += g;
                }
            }
            if den > 0.0 { num / den } else { 0.0 }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hammersley_is_stratified() {
        // Every 1/n column and every 1/n row (n = 256 points, power of two) holds one point,
        // and every 16x16 cell of the unit square holds exactly one.
        let n = 256u32;
        let pts: Vec<[f32; 2]> = (0..n).map(|i| hammersley(i, n, [0.0, 0.0])).collect();
        let mut cols = vec![0; n as usize];
        let mut rows = vec![0; n as usize];
        let mut cells = vec![0; 256];
        for p in &pts {
            cols[(p[0] * n as f32) as usize] += 1;
            rows[(p[1] * n as f32) as usize] += 1;
            cells[(p[1] * 16.0) as usize * 16 + (p[0] * 16.0) as usize] += 1;
        }
        assert!(cols.iter().all(|&c| c == 1));
        assert!(rows.iter().all(|&c| c == 1));
        assert!(cells.iter().all(|&c| c == 1), "{cells:?}");
        // A rotation keeps the cells balanced modulo wrap-around: still one point per column.
        let mut cols = vec![0; n as usize];
        for i in 0..n {
            let p = hammersley(i, n, [0.37, 0.81]);
            cols[(p[0] * n as f32) as usize] += 1;
        }
        assert!(cols.iter().all(|&c| c == 1));
    }

    #[test]
    fn pyramid_top_is_the_total() {
        let m: Vec<f32> = (0..64).map(|i| i as f32).collect();
        let p = pyramid(&m, 8);
        assert_eq!(p.len(), 4);
        assert_eq!(p[3][0], m.iter().sum::<f32>());
    }

    /// Chi-square statistic of `counts` against `expected` (cells with expected >= 5 only).
    fn chi2(counts: &[u32], expected: &[f64]) -> (f64, usize) {
        let mut s = 0.0;
        let mut dof = 0usize;
        for (c, e) in counts.iter().zip(expected) {
            if *e >= 5.0 {
                s += (*c as f64 - e).powi(2) / e;
                dof += 1;
            } else {
                assert!(*e > 0.0 || *c == 0, "a zero-probability texel was chosen");
            }
        }
        (s, dof.saturating_sub(1))
    }

    #[test]
    fn warping_matches_the_pdf_chi_square() {
        // 32x32 PDF: a gradient, a few spikes, and a zero region.
        let res = 32u32;
        let mut pdf: Vec<f32> = (0..res * res)
            .map(|k| {
                let (x, y) = (k % res, k / res);
                if x < 4 {
                    0.0
                } else {
                    1.0 + x as f32 * 0.5 + y as f32 * 0.1
                }
            })
            .collect();
        pdf[(10 * res + 20) as usize] = 300.0;
        pdf[(25 * res + 7) as usize] = 150.0;
        pdf[(3 * res + 30) as usize] = 80.0;
        let pyr = pyramid(&pdf, res);
        let total: f64 = pdf.iter().map(|&v| v as f64).sum();
        let n = 100_000u32;
        let mut counts = vec![0u32; (res * res) as usize];
        for i in 0..n {
            let rot = [u01(pcg_hash(7)), u01(pcg_hash(8))];
            let (x, y, pmf) = warp(&pyr, res, hammersley(i, n, rot));
            let k = (y * res + x) as usize;
            assert!((pmf as f64 - pdf[k] as f64 / total).abs() < 1e-6);
            counts[k] += 1;
        }
        let expected: Vec<f64> = pdf.iter().map(|&v| v as f64 / total * n as f64).collect();
        let (s, dof) = chi2(&counts, &expected);
        // Hammersley points are far more even than random ones, so the statistic sits well
        // below its dof; 99.9% quantile of chi2(dof ~ 900) is about dof + 4.4 sqrt(2 dof).
        let limit = dof as f64 + 4.4 * (2.0 * dof as f64).sqrt();
        assert!(s < limit, "chi2 {s:.1} with {dof} dof (limit {limit:.1})");
        // Random (not Hammersley) points must pass the same test.
        let mut counts = vec![0u32; (res * res) as usize];
        let mut h = 12345u32;
        for _ in 0..n {
            h = pcg_hash(h);
            let u = u01(h);
            h = pcg_hash(h);
            let v = u01(h);
            let (x, y, _) = warp(&pyr, res, [u, v]);
            counts[(y * res + x) as usize] += 1;
        }
        let (s, dof) = chi2(&counts, &expected);
        let limit = dof as f64 + 4.4 * (2.0 * dof as f64).sqrt();
        assert!(
            s < limit,
            "random points: chi2 {s:.1} with {dof} dof (limit {limit:.1})"
        );
    }

    #[test]
    fn filter_preserves_a_step_across_different_normals() {
        // Left half: floor (normal +y), importance 1; right half: wall (normal +x), 0.
        let res = 16u32;
        let mut pos = Vec::new();
        let mut nrm = Vec::new();
        let mut raw = Vec::new();
        for k in 0..res * res {
            let x = k % res;
            pos.push([x as f32 * 0.01, 0.0, (k / res) as f32 * 0.01, 1.0]);
            nrm.push(if x < 8 { Vec3::Y } else { Vec3::X });
            raw.push(if x < 8 { 1.0 } else { 0.0 });
        }
        let f = filter(&raw, &pos, &nrm, res, 3, 0.9, 1.0);
        for k in 0..(res * res) as usize {
            assert_eq!(f[k], raw[k], "texel {k} blurred across the edge");
        }
        // The same map with one normal everywhere is blurred at the step.
        let same = vec![Vec3::Y; (res * res) as usize];
        let g = filter(&raw, &pos, &same, res, 3, 0.9, 1.0);
        assert!(g[7] < 1.0 && g[8] > 0.0);
    }
}

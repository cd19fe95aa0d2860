//! Lightcut Interpolation (Rehfeld & Dachsbacher 2016): the CPU twin of
//! `shaders/methods/lightcut_interpolation/{li_records, li_select, li_interp}.wgsl`. Written for clarity,
//! not speed; every function mirrors its kernel op for op where the results are compared.
//!
//! **Cache records** (section 3.1). The paper places records with Ulbrich's tile-based method
//! (a master's thesis we do not have): per image tile, the weights between the tile's shading
//! points are computed and the point with the highest influence on the others becomes a record,
//! repeatedly, until every shading point has found usable records. Our reading
//! ([`place_tile`]): per 16 x 16 tile, greedily pick the pixel whose record would add the most
//! weight to the pixels not yet covered (sum of max(w, 0)), until every pixel's summed weight
//! of the tile's records reaches `coverage` (1 by default: a pixel on a record is covered at
//! once, others need one close or several farther records) or the tile holds [`TILE_CAP`]
//! records. A record carries the harmonic mean distance R to the surrounding geometry
//! (Ward's split sphere; [`harmonic_mean_distance`], from a few cosine-distributed hemisphere
//! rays) clamped per section 3.2 to [R-, R+] multiples of the projected pixel size
//! ([`record_radius`]).
//!
//! **Selection and weights** (section 3.2, [`weight`], [`select`]): Tabellion and
//! Lamorlette's weight w = 1 - max(d_p, d_n) with d_p = |p_p - p_r| / max(min(R/2, R+), R-) and
//! d_n = sqrt((1 - n_p.n_r) / (1 - cos a+)), a+ = 15 degrees; records in front of the shading
//! point ((p_p - p_r).(n_p + n_r) < 0) are rejected. The four best records by w are ranked,
//! the fourth's weight subtracted from the other three and the three normalised (C0
//! continuity). A pixel whose best weight is below epsilon (or whose three weights vanish)
//! computes a full lightcut instead.
//!
//! **Interpolation** (section 3.3, Listings 1 and 2, [`interpolate`]): the input cuts are
//! walked left to right along their lowest edge; each step (a leaf interval on which every
//! input cut has one node) adds width x sum_j w_j L_j (the weighted level) to an accumulator.
//! At a *sync position* (a boundary shared by at least two input cuts, or every boundary for a
//! single cut) the output emits nodes from its current position at the accumulated average
//! level (rounded), lowered until the node is aligned (no overlap with nodes written before:
//! Fig. 7), and defers a node that would reach past the sync position (Fig. 6, far right; its
//! leaves keep accumulating). An emitted node takes its share of the accumulator (the average
//! of the remainder is unchanged, as Listing 2 reuses l_inter / w_interp). The output always
//! covers every leaf exactly once. With interpolated visibility each output node carries the
//! same width-weighted average of the input nodes' visibility bits.
//!
//! The tree is the frame's perfect binary light tree (root 1, leaf i at `leaves + i`); empty
//! nodes (the padded right spine) are not in the input cuts, and the walk fills such gaps with
//! the largest aligned empty nodes ("virtual" nodes, level of the gap, visibility 0), never
//! emitted.

use glam::Vec3;

use crate::base::sst_node::SstNode;
use crate::reference::lightcuts::{CutInputs, cluster_estimate, representative_visible};
use crate::reference::vpl::{pcg_hash, u01};
use crate::scene::bvh::{Bvh, Ray};

/// Records per tile at most (a tile that needs more leaves its last pixels to the fallback).
pub const TILE_CAP: u32 = 64;
/// Tile side in pixels (placement and the selection's grid).
pub const TILE: u32 = 16;
/// The visibility bit of a record's cut node (`node | VISIBLE`).
pub const VISIBLE: u32 = 0x8000_0000;

/// A cache record: where and how far it reaches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Record {
    pub position: Vec3,
    pub normal: Vec3,
    /// max(min(R / 2, R+), R-) in world units (section 3.2).
    pub radius: f32,
}

/// The weight function's constants.
#[derive(Clone, Copy, Debug)]
pub struct WeightParams {
    /// 1 - cos(a+), a+ the largest normal deviation (15 degrees in the paper).
    pub one_minus_cos_max: f32,
}

impl WeightParams {
    pub fn new(max_angle_deg: f32) -> Self {
        Self {
            one_minus_cos_max: 1.0 - max_angle_deg.to_radians().cos(),
        }
    }
}

/// max(min(R / 2, r_max_px x footprint), r_min_px x footprint): the record's reach.
pub fn record_radius(harmonic: f32, footprint: f32, r_min_px: f32, r_max_px: f32) -> f32 {
    (0.5 * harmonic)
        .min(r_max_px * footprint)
        .max(r_min_px * footprint)
}

/// The world size of a pixel at distance `depth` along the view direction of a camera with
/// vertical field of view `yfov` over `height` pixels.
pub fn pixel_footprint(depth: f32, tan_half_yfov: f32, height: u32) -> f32 {
    depth.max(0.0) * 2.0 * tan_half_yfov / height.max(1) as f32
}

/// Tabellion and Lamorlette's weight of record `r` at shading point (p, n); negative when the
/// record is rejected (normals too different, or the record in front of the point).
pub fn weight(p: Vec3, n: Vec3, r: &Record, wp: &WeightParams) -> f32 {
    if (p - r.position).dot(n + r.normal) < 0.0 {
        return -1.0;
    }
    let dp = (p - r.position).length() / r.radius.max(1e-12);
    let dn = ((1.0 - n.dot(r.normal)).max(0.0) / wp.one_minus_cos_max).sqrt();
    1.0 - dp.max(dn)
}

/// The `i`-th of `count` hemisphere directions around `n` at pixel `pixel`: cosine
/// distributed, stratified in the polar coordinate, rotated per pixel. Twin: `li_records.wgsl`.
pub fn hemisphere_dir(n: Vec3, pixel: u32, i: u32, count: u32) -> Vec3 {
    let u1 = (i as f32 + u01(pcg_hash(pixel.wrapping_mul(0x9e37_79b9) ^ i))) / count.max(1) as f32;
    let u2 = u01(pcg_hash(pixel ^ 0x85eb_ca6b)) + i as f32 * 0.618_034;
    let u2 = u2 - u2.floor();
    let r = u1.sqrt();
    let phi = std::f32::consts::TAU * u2;
    let (t, b) = crate::base::sst_node::basis(n);
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt()).normalize()
}

/// The harmonic mean distance from (x, n) to the geometry over `count` hemisphere rays
/// (misses count as infinitely far); f32::MAX when every ray misses.
pub fn harmonic_mean_distance(bvh: &Bvh, x: Vec3, n: Vec3, pixel: u32, count: u32, offset: f32) -> f32 {
    let o = x + n * offset;
    let mut inv = 0.0f32;
    for i in 0..count {
        let d = hemisphere_dir(n, pixel, i, count);
        if let Some(h) = bvh.closest_hit(&Ray {
            origin: o,
            dir: d,
            tmin: 1e-4,
            tmax: 3.0e38,
        }) {
            inv += 1.0 / h.t.max(1e-6);
        }
    }
    if inv > 0.0 { count as f32 / inv } else { f32::MAX }
}

/// A tile's pixel as the placement sees it.
#[derive(Clone, Copy, Debug)]
pub struct TilePixel {
    pub valid: bool,
    pub record: Record,
}

/// Greedy record placement in one tile (the module doc): indices into `px` in the order
/// chosen. Ties go to the lower index; a record's own pixel is covered and never picked
/// again. Twin: `place_main` in `li_records.wgsl`.
pub fn place_tile(px: &[TilePixel], coverage: f32, wp: &WeightParams) -> Vec<u32> {
    let mut acc = vec![0.0f32; px.len()];
    let mut covered: Vec<bool> = px.iter().map(|p| !p.valid).collect();
    let mut chosen = Vec::new();
    while (chosen.len() as u32) < TILE_CAP && covered.iter().any(|c| !c) {
        let mut best = (0.0f32, u32::MAX);
        for (c, cp) in px.iter().enumerate() {
            if !cp.valid || chosen.contains(&(c as u32)) {
                continue;
            }
            let mut gain = 0.0f32;
            for (p, pp) in px.iter().enumerate() {
                if !covered[p] {
                    gain += weight(pp.record.position, pp.record.normal, &cp.record, wp).max(0.0);
                }
            }
            if gain > best.0 {
                best = (gain, c as u32);
            }
        }
        if best.1 == u32::MAX {
            break;
        }
        let r = px[best.1 as usize].record;
        chosen.push(best.1);
        for (p, pp) in px.iter().enumerate() {
            if pp.valid {
                acc[p] += weight(pp.record.position, pp.record.normal, &r, wp).max(0.0);
                // The record's own pixel is covered (its weight there is 1 up to rounding).
                covered[p] = covered[p] || acc[p] >= coverage || p as u32 == best.1;
            }
        }
    }
    chosen
}

/// A pixel's records and interpolation weights; `count` 0 = full lightcut (fallback).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Selection {
    pub records: [u32; 3],
    pub weights: [f32; 3],
    pub count: u32,
    /// The best record's raw weight (0 without any).
    pub best: f32,
}

/// The best three of `candidates` (record id, raw weight), in the order given (ties keep the
/// earlier one), their weights minus the fourth best and normalised (section 3.2). Twin:
/// `li_select.wgsl`.
pub fn select(candidates: impl IntoIterator<Item = (u32, f32)>, epsilon: f32) -> Selection {
    let mut ids = [u32::MAX; 4];
    let mut ws = [0.0f32; 4];
    for (id, w) in candidates {
        if w <= 0.0 || w <= ws[3] {
            continue;
        }
        let mut i = 3;
        while i > 0 && w > ws[i - 1] {
            ws[i] = ws[i - 1];
            ids[i] = ids[i - 1];
            i -= 1;
        }
        ws[i] = w;
        ids[i] = id;
    }
    let mut sel = Selection {
        records: [u32::MAX; 3],
        weights: [0.0; 3],
        count: 0,
        best: ws[0],
    };
    let w: [f32; 3] = [ws[0] - ws[3], ws[1] - ws[3], ws[2] - ws[3]];
    let sum = w[0] + w[1] + w[2];
    if ws[0] < epsilon || sum <= 1e-6 {
        return sel;
    }
    for i in 0..3 {
        if w[i] > 0.0 && ids[i] != u32::MAX {
            let k = sel.count as usize;
            sel.records[k] = ids[i];
            sel.weights[k] = w[i] / sum;
            sel.count += 1;
        }
    }
    sel
}

/// Depth of node `n` (root 0).
pub fn depth(n: u32) -> u32 {
    31 - n.leading_zeros()
}

/// The first leaf under node `n` in a tree of 2^levels leaves.
pub fn first_leaf(n: u32, levels: u32) -> u32 {
    (n << (levels - depth(n))) - (1 << levels)
}

/// Sorts a cut (node ids, optionally with [`VISIBLE`]) left to right.
pub fn sort_cut(cut: &mut [u32], levels: u32) {
    cut.sort_by_key(|&e| first_leaf(e & !VISIBLE, levels));
}

/// One node of an interpolated cut.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InterpNode {
    pub node: u32,
    /// The interpolated visibility (width-weighted mean of the input nodes' bits).
    pub visibility: f32,
}

/// An interpolated cut and what the walk saw.
#[derive(Clone, Debug, PartialEq)]
pub struct Interpolated {
    /// Non-empty nodes, left to right.
    pub cut: Vec<InterpNode>,
    /// Width-weighted mean over the leaves of (largest - smallest input level): 0 where the
    /// input cuts agree.
    pub level_spread: f32,
    /// Lowest-edge steps of the walk.
    pub steps: u32,
    /// Leaf intervals [start, end) where the input cuts' levels differ (merged).
    pub disagreements: Vec<(u32, u32)>,
}

/// The walk's cursor over one input cut.
#[derive(Clone, Copy, Debug)]
struct Cursor {
    /// Index of the next stored node.
    next: usize,
    /// The current node's end (leaf position), level and visibility.
    end: u32,
    level: u32,
    vis: f32,
}

/// The largest aligned node starting at leaf `x` that ends at or before `limit`: its level.
fn aligned_level(x: u32, limit: u32, levels: u32) -> u32 {
    let mut l = if x == 0 {
        0
    } else {
        levels - x.trailing_zeros().min(levels)
    };
    while l < levels && x + (1 << (levels - l)) > limit {
        l += 1;
    }
    l
}

/// Loads cut `c`'s node starting at leaf `x` into the cursor: the stored node if it starts
/// there, else a virtual (empty) node filling the gap.
fn load(cut: &[u32], cur: &mut Cursor, x: u32, levels: u32) {
    let leaves = 1u32 << levels;
    if let Some(&e) = cut.get(cur.next) {
        let n = e & !VISIBLE;
        if first_leaf(n, levels) == x {
            cur.next += 1;
            cur.level = depth(n);
            cur.end = x + (1 << (levels - cur.level));
            cur.vis = if e & VISIBLE != 0 { 1.0 } else { 0.0 };
            return;
        }
        let limit = first_leaf(n, levels);
        cur.level = aligned_level(x, limit, levels);
    } else {
        cur.level = aligned_level(x, leaves, levels);
    }
    cur.end = x + (1 << (levels - cur.level));
    cur.vis = 0.0;
}

/// Interpolates `cuts` (each left to right, node | VISIBLE) with `weights` (summing to 1) in
/// a tree of `leaves` (a power of two) leaves; `nodes` tells empty nodes apart.
pub fn interpolate(nodes: &[SstNode], cuts: &[&[u32]], weights: &[f32]) -> Interpolated {
    let leaves = (nodes.len() / 2) as u32;
    let levels = leaves.trailing_zeros();
    let k = cuts.len().min(3);
    let mut cur = [Cursor {
        next: 0,
        end: 0,
        level: 0,
        vis: 0.0,
    }; 3];
    for j in 0..k {
        load(cuts[j], &mut cur[j], 0, levels);
    }
    let (mut pos, mut x) = (0u32, 0u32);
    let (mut acc_w, mut acc_l, mut acc_v, mut spread) = (0.0f32, 0.0f32, 0.0f32, 0.0f32);
    let mut out = Interpolated {
        cut: Vec::new(),
        level_spread: 0.0,
        steps: 0,
        disagreements: Vec::new(),
    };
    if k == 0 {
        return out;
    }
    while pos < leaves {
        // One lowest-edge step.
        let mut e = u32::MAX;
        for c in &cur[..k] {
            e = e.min(c.end);
        }
        let width = (e - pos) as f32;
        let (mut lavg, mut vavg) = (0.0f32, 0.0f32);
        let (mut lo, mut hi) = (u32::MAX, 0u32);
        for j in 0..k {
            lavg += weights[j] * cur[j].level as f32;
            vavg += weights[j] * cur[j].vis;
            lo = lo.min(cur[j].level);
            hi = hi.max(cur[j].level);
        }
        acc_w += width;
        acc_l += width * lavg;
        acc_v += width * vavg;
        spread += width * (hi - lo) as f32;
        if hi > lo {
            match out.disagreements.last_mut() {
                Some(last) if last.1 == pos => last.1 = e,
                _ => out.disagreements.push((pos, e)),
            }
        }
        out.steps += 1;
        pos = e;
        let mut ended = 0;
        for j in 0..k {
            if cur[j].end == e {
                ended += 1;
                if e < leaves {
                    load(cuts[j], &mut cur[j], e, levels);
                }
            }
        }
        if ended < k.min(2) {
            continue;
        }
        // A sync position: emit what the accumulator allows.
        while x < pos {
            let target = ((acc_l / acc_w + 0.5).floor() as i32).clamp(0, levels as i32) as u32;
            let l = target.max(aligned_level(x, leaves, levels));
            let w = 1u32 << (levels - l);
            if x + w > pos {
                break;
            }
            let node = (leaves + x) >> (levels - l);
            if !nodes[node as usize].is_empty() {
                out.cut.push(InterpNode {
                    node,
                    visibility: acc_v / acc_w,
                });
            }
            let wf = w as f32;
            if wf >= acc_w {
                (acc_w, acc_l, acc_v) = (0.0, 0.0, 0.0);
            } else {
                let keep = 1.0 - wf / acc_w;
                acc_l *= keep;
                acc_v *= keep;
                acc_w -= wf;
            }
            x += w;
        }
    }
    out.level_spread = spread / leaves as f32;
    out
}

/// The leaf intervals [start, end) where `cuts` (left to right, node | VISIBLE) put different
/// levels, in a tree of 2^levels leaves (merged; the walk of [`interpolate`]).
pub fn disagreements(cuts: &[&[u32]], levels: u32) -> Vec<(u32, u32)> {
    let leaves = 1u32 << levels;
    let k = cuts.len().min(3);
    let mut cur = [Cursor {
        next: 0,
        end: 0,
        level: 0,
        vis: 0.0,
    }; 3];
    for j in 0..k {
        load(cuts[j], &mut cur[j], 0, levels);
    }
    let mut out: Vec<(u32, u32)> = Vec::new();
    let mut pos = 0;
    while k > 0 && pos < leaves {
        let e = cur[..k].iter().map(|c| c.end).min().unwrap_or(leaves);
        let lo = cur[..k].iter().map(|c| c.level).min().unwrap_or(0);
        let hi = cur[..k].iter().map(|c| c.level).max().unwrap_or(0);
        if hi > lo {
            match out.last_mut() {
                Some(last) if last.1 == pos => last.1 = e,
                _ => out.push((pos, e)),
            }
        }
        pos = e;
        for (j, c) in cur[..k].iter_mut().enumerate() {
            if c.end == e && e < leaves {
                load(cuts[j], c, e, levels);
            }
        }
    }
    out
}

/// An interpolated cut's shading: sum of the nodes' estimates (with `c.params.eps`) x
/// visibility (the interpolated visibility with `interpolated_visibility`, else shadow rays
/// with the offset `c.params.shadow_rays`, else 1) and the rays traced. The inputs' `topo`
/// and refinement settings play no part.
pub fn shade(
    c: &CutInputs<'_>,
    cut: &[InterpNode],
    x: Vec3,
    n: Vec3,
    interpolated_visibility: bool,
) -> (Vec3, u32) {
    let CutInputs {
        nodes,
        lc,
        sorted,
        bvh,
        params,
        ..
    } = *c;
    let (eps, shadow_ray_offset) = (params.eps, params.shadow_rays);
    let mut sum = Vec3::ZERO;
    let mut rays = 0;
    for c in cut {
        let e = cluster_estimate(nodes, lc, sorted, c.node, x, n, eps);
        if e == Vec3::ZERO {
            continue;
        }
        let v = if interpolated_visibility {
            c.visibility
        } else if let Some(offset) = shadow_ray_offset {
            rays += 1;
            if representative_visible(bvh, lc, sorted, c.node, x, n, offset) {
                1.0
            } else {
                0.0
            }
        } else {
            1.0
        };
        sum += e * v;
    }
    (sum, rays)
}

/// Checks that an interpolated cut is valid: every non-empty leaf covered once.
pub fn check_interpolated(nodes: &[SstNode], cut: &[InterpNode]) -> Result<(), String> {
    let ids: Vec<u32> = cut.iter().map(|c| c.node).collect();
    crate::reference::lightcuts::check_cut(nodes, &ids)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tree(leaves: u32, filled: u32) -> Vec<SstNode> {
        let full = SstNode {
            bbox_min: Vec3::ZERO,
            bbox_max: Vec3::ONE,
            ..SstNode::EMPTY
        };
        let mut nodes = vec![SstNode::EMPTY; 2 * leaves as usize];
        for i in 0..filled {
            nodes[(leaves + i) as usize] = full;
        }
        for n in (1..leaves as usize).rev() {
            if !nodes[2 * n].is_empty() || !nodes[2 * n + 1].is_empty() {
                nodes[n] = full;
            }
        }
        nodes
    }

    /// A random valid cut of the non-empty part (left to right).
    fn random_cut(nodes: &[SstNode], levels: u32, seed: u32) -> Vec<u32> {
        let mut out = Vec::new();
        let mut stack = vec![1u32];
        let mut k = seed;
        while let Some(n) = stack.pop() {
            if nodes[n as usize].is_empty() {
                continue;
            }
            k = pcg_hash(k);
            if depth(n) == levels || (depth(n) >= 2 && u01(k) < 0.3) {
                out.push(n | if k & 1 == 0 { VISIBLE } else { 0 });
            } else {
                stack.push(2 * n + 1);
                stack.push(2 * n);
            }
        }
        out
    }

    #[test]
    fn interpolating_one_or_identical_cuts_returns_the_cut() {
        let nodes = tree(64, 50);
        for seed in 0..50 {
            let c = random_cut(&nodes, 6, seed);
            let ids: Vec<u32> = c.iter().map(|e| e & !VISIBLE).collect();
            let one = interpolate(&nodes, &[&c], &[1.0]);
            assert_eq!(one.cut.iter().map(|n| n.node).collect::<Vec<_>>(), ids);
            let three = interpolate(&nodes, &[&c, &c, &c], &[0.2, 0.3, 0.5]);
            assert_eq!(three.cut.iter().map(|n| n.node).collect::<Vec<_>>(), ids);
            assert_eq!(three.level_spread, 0.0);
            for (o, &e) in three.cut.iter().zip(&c) {
                let v = if e & VISIBLE != 0 { 1.0 } else { 0.0 };
                assert!((o.visibility - v).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn interpolated_cuts_are_valid() {
        let nodes = tree(256, 200);
        for seed in 0..300 {
            let a = random_cut(&nodes, 8, seed);
            let b = random_cut(&nodes, 8, seed + 1000);
            let c = random_cut(&nodes, 8, seed + 2000);
            let u = u01(pcg_hash(seed + 7)) + 0.01;
            let v = u01(pcg_hash(seed + 9)) + 0.01;
            let w = [u / (u + v + 1.0), v / (u + v + 1.0), 1.0 / (u + v + 1.0)];
            let out = interpolate(&nodes, &[&a, &b, &c], &w);
            check_interpolated(&nodes, &out.cut).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
            assert!(out.level_spread > 0.0, "seed {seed}: the inputs differ");
            assert_eq!(out.disagreements, disagreements(&[&a, &b, &c], 8));
            // The spread is the width-weighted level range: positive exactly where they differ.
            let width: u32 = out.disagreements.iter().map(|(s, e)| e - s).sum();
            assert!(width > 0 && out.level_spread * 256.0 >= width as f32 - 1e-3);
            // Two inputs too.
            let two = interpolate(&nodes, &[&a, &b], &[0.5, 0.5]);
            check_interpolated(&nodes, &two.cut).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        }
    }

    #[test]
    fn selection_subtracts_the_fourth_weight_and_normalises() {
        let s = select([(7, 0.9), (3, 0.5), (9, 0.7), (1, 0.3), (2, 0.1)], 0.05);
        assert_eq!(s.records, [7, 9, 3]);
        assert_eq!(s.count, 3);
        let sum = 0.6 + 0.4 + 0.2;
        for (w, e) in s.weights.iter().zip([0.6 / sum, 0.4 / sum, 0.2 / sum]) {
            assert!((w - e).abs() < 1e-6);
        }
        // Below epsilon: fallback.
        assert_eq!(select([(1, 0.04)], 0.05).count, 0);
        // One record: weight 1.
        let one = select([(4, 0.5), (5, -0.2)], 0.05);
        assert_eq!((one.count, one.records[0], one.weights[0]), (1, 4, 1.0));
    }
}

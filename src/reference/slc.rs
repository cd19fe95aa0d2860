//! Reference of the tree sampling (stages 11-15; thesis chapter 5): node weights, shallow
//! light cuts, cut blending weights, mock cuts, traversal and cluster evaluation. The GPU twins
//! are `shaders/common/slc.wgsl`, `shaders/methods/tree_samplers/slc_cuts.wgsl` and `slc_sample.wgsl`.
//!
//! Weight of node C at shading point x with normal n (thesis eq. 5.5 with M = 1 for diffuse
//! surfaces, V = 1, and the geometric term of eq. 5.2):
//!   w = luminance(I_C) x (1/8 sum_corners max(n . (c - x)/|c - x|, 0)) / max(d^2, eps^2)
//! with d the distance from x to the node's intensity-weighted mean position (the quadratic
//! falloff of Lightcuts' representative point, eq. 5.1) and eps the distance bound of the
//! ground truth (`gi.distance_epsilon`). (Until issue 7 d was the distance to the box, 0
//! inside it: every box around x then weighed I/eps^2, see docs/results.md.) w = 0 exactly when the node is empty or every
//! corner lies on or behind x's tangent plane, i.e. when no VPL below can light x.

use glam::Vec3;

use super::brdf;
use super::sst_tree::{SstNode, luminance};
use crate::base::sampling::{ChildProbability, GLOSSY_DEFENSIVE, GlossyWeights};
use crate::base::sst_node::Topology;

/// Largest cut (samples per pixel) the GPU kernels hold in registers.
pub const MAX_CUT: u32 = 64;

/// The average clamped cosine of eq. 5.2: 1/8 sum over the box corners of
/// max(n . (c - x)/|c - x|, 0). Same operations, in the same order, as `box_cos` in
/// `common/box_term.wgsl`.
pub fn box_cos(lo: Vec3, hi: Vec3, x: Vec3, n: Vec3) -> f32 {
    let mut cos_sum = 0.0f32;
    for c in 0..8u32 {
        let p = Vec3::new(
            if c & 1 != 0 { hi.x } else { lo.x },
            if c & 2 != 0 { hi.y } else { lo.y },
            if c & 4 != 0 { hi.z } else { lo.z },
        );
        let d = p - x;
        cos_sum += (n.dot(d) / d.dot(d).max(1e-30).sqrt()).max(0.0);
    }
    if cos_sum.is_nan() || cos_sum <= 0.0 {
        return 0.0;
    }
    cos_sum * 0.125
}

/// Eq. 5.2 over the box [lo, hi] with the inverse squared distance to it (see the module
/// doc): `box_term` in `common/box_term.wgsl` (the converged reference's pyramid descent).
pub fn box_term(lo: Vec3, hi: Vec3, x: Vec3, n: Vec3, eps: f32) -> f32 {
    let g = box_cos(lo, hi, x, n);
    if g == 0.0 {
        return 0.0;
    }
    let q = x.clamp(lo, hi);
    let d2 = (q - x).dot(q - x);
    g / d2.max(eps * eps)
}

/// Eq. 5.5: luminance(I) x eq. 5.2's average clamped cosine over the node's box /
/// max(d^2, eps^2), d = the distance to the node's intensity-weighted mean position (the
/// quadratic falloff of Lightcuts' representative point, eq. 5.1): `slc_node_weight` in
/// `common/slc.wgsl`. Zero exactly where the box term is.
pub fn node_weight(node: &SstNode, x: Vec3, n: Vec3, eps: f32) -> f32 {
    if node.is_empty() {
        return 0.0;
    }
    let g = box_cos(node.bbox_min, node.bbox_max, x, n);
    let d = node.position - x;
    luminance(node.intensity) * (g / d.dot(d).max(eps * eps))
}

/// Share of the closest-point normalisation in [`ChildProbability::Defensive`] (twin:
/// `SLC_DEFENSIVE` in `common/slc.wgsl`).
pub const DEFENSIVE: f32 = 0.2;

/// Probability of taking the left child in a traversal step (stage 14), None for a dead
/// branch: `slc_child_prob` in `common/slc.wgsl`. `Mean`, the thesis: wl / (wl + wr) with
/// [`node_weight`]; `MinMax` (RTSLC): the average of the two normalisations of
/// lum(I) x box_cos / max(d^2, eps^2) with d the distance to each child's box (0 inside) and
/// to its farthest point; `Defensive`: the thesis's and the closest-point normalisation,
/// weighted 1 - [`DEFENSIVE`] and [`DEFENSIVE`].
pub fn child_probability(
    l: &SstNode,
    r: &SstNode,
    x: Vec3,
    n: Vec3,
    eps: f32,
    mode: ChildProbability,
) -> Option<f32> {
    child_probability_m(l, r, x, n, eps, mode, (1.0, 1.0))
}

/// [`child_probability`] with each child's weight times a material term `m` = (left,
/// right), both >= 0 (the glossy walk's [`glossy_term`]): `slc_child_prob_m`.
pub fn child_probability_m(
    l: &SstNode,
    r: &SstNode,
    x: Vec3,
    n: Vec3,
    eps: f32,
    mode: ChildProbability,
    m: (f32, f32),
) -> Option<f32> {
    if mode == ChildProbability::Mean {
        let (wl, wr) = (node_weight(l, x, n, eps) * m.0, node_weight(r, x, n, eps) * m.1);
        let s = wl + wr;
        return (s > 0.0).then(|| wl / s);
    }
    let g = |c: &SstNode| {
        if c.is_empty() {
            0.0
        } else {
            luminance(c.intensity) * box_cos(c.bbox_min, c.bbox_max, x, n)
        }
    };
    let (gl, gr) = (g(l) * m.0, g(r) * m.1);
    // (Also None for NaN.)
    if (gl + gr).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let e2 = eps * eps;
    let near = |c: &SstNode| {
        let q = x.clamp(c.bbox_min, c.bbox_max) - x;
        q.dot(q).max(e2)
    };
    let (nl, nr) = (gl / near(l), gr / near(r));
    if mode == ChildProbability::Defensive {
        // eq. 5.5's weights from the cosine terms above ([`node_weight`] without computing
        // box_cos again).
        let mean = |c: &SstNode, g: f32| g / (c.position - x).length_squared().max(e2);
        let (ml, mr) = (mean(l, gl), mean(r, gr));
        let t = ml / (ml + mr);
        return Some(t + (nl / (nl + nr) - t) * DEFENSIVE);
    }
    let far = |c: &SstNode| {
        let f = (x - c.bbox_min).abs().max((x - c.bbox_max).abs());
        f.dot(f).max(e2)
    };
    let (xl, xr) = (gl / far(l), gr / far(r));
    Some(0.5 * (nl / (nl + nr) + xl / (xl + xr)))
}

/// The direction from x towards the box [lo, hi] for the glossy material term: `r` when
/// the ray x + t r (t >= 0) meets the box, else towards the box point nearest the ray's
/// point level with the box centre, clamp(x + r max((c - x).r, 0), lo, hi) (an approximation
/// of the SST paper's R', the direction into the box closest to R): `slc_mirror_toward`.
pub fn mirror_toward(lo: Vec3, hi: Vec3, x: Vec3, r: Vec3) -> Vec3 {
    let safe = |c: f32| if c.abs() >= 1e-8 { c } else { 1e-8 };
    let inv = Vec3::ONE / Vec3::new(safe(r.x), safe(r.y), safe(r.z));
    let (t0, t1) = ((lo - x) * inv, (hi - x) * inv);
    let (tn, tf) = (t0.min(t1), t0.max(t1));
    let t_in = tn.x.max(tn.y).max(tn.z.max(0.0));
    let t_out = tf.x.min(tf.y).min(tf.z);
    if t_in <= t_out {
        return r;
    }
    let c = 0.5 * (lo + hi);
    let p = (x + r * (c - x).dot(r).max(0.0)).clamp(lo, hi);
    let d = p - x;
    let l2 = d.dot(d);
    if l2.partial_cmp(&1e-20) != Some(std::cmp::Ordering::Greater) {
        return r;
    }
    d / l2.sqrt()
}

/// The SST paper's glossy material term of a node's box (section 4.1): the specular BRDF's
/// luminance(F(v.h)) D(n.h) Vis at l = [`mirror_toward`] of the reflected view direction, with
/// n.l at least 1e-3 (positive wherever n.v > 0, so the glossy walk keeps the support of
/// the geometric weights); 0 when n.v <= 0. `slc_glossy_term` in `common/slc.wgsl`.
pub fn glossy_term(lo: Vec3, hi: Vec3, x: Vec3, n: Vec3, v: Vec3, s: &brdf::Surface) -> f32 {
    let nv = n.dot(v);
    if nv.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return 0.0;
    }
    let a = brdf::alpha(s.roughness);
    let a2 = a * a;
    let r = 2.0 * nv * n - v;
    let l = mirror_toward(lo, hi, x, r);
    let nl = n.dot(l).max(1e-3);
    let hs = v + l;
    let h = if hs.dot(hs) > 1e-12 { hs.normalize() } else { n };
    let nh = n.dot(h).max(0.0);
    let vis = 0.5 / (nl * (nv * nv * (1.0 - a2) + a2).sqrt() + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
    let f = brdf::schlick(brdf::f0(s.base, s.metallic), v.dot(h));
    luminance(f) * brdf::ggx_d(nh, a2) * vis
}

/// How a glossy walk weighs a step's two children: the geometric rule and the material
/// term's part (`sampling.child_probability`, `sampling.glossy_weights`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GlossyWalk {
    pub mode: ChildProbability,
    pub weights: GlossyWeights,
}

/// A glossy walk's probability of the left child (`traverse` in `slc_sample.wgsl`) at (x, n)
/// seen along `sh.v` with `sh.surface`: the geometric [`child_probability`], with `weights`
/// times the children's [`glossy_term`]s (`Material`), or those mixed with
/// [`GLOSSY_DEFENSIVE`] of the geometric one (`Defensive`; the geometric one alone where the
/// material terms are both 0).
pub fn glossy_child_probability(
    l: &SstNode,
    r: &SstNode,
    x: Vec3,
    n: Vec3,
    sh: &brdf::Shading,
    eps: f32,
    walk: GlossyWalk,
) -> Option<f32> {
    let (v, s) = (sh.v, &sh.surface);
    let GlossyWalk { mode, weights } = walk;
    if weights == GlossyWeights::Geometric {
        return child_probability(l, r, x, n, eps, mode);
    }
    let m = |c: &SstNode| {
        if c.is_empty() {
            0.0
        } else {
            glossy_term(c.bbox_min, c.bbox_max, x, n, v, s)
        }
    };
    let pm = child_probability_m(l, r, x, n, eps, mode, (m(l), m(r)));
    if weights == GlossyWeights::Material {
        return pm;
    }
    let pg = child_probability(l, r, x, n, eps, mode)?;
    Some(match pm {
        Some(pm) => pm + (pg - pm) * GLOSSY_DEFENSIVE,
        None => pg,
    })
}

/// Whether a node may enter a cut (as a split's child): not empty, and (with culling) not
/// wholly behind the surface.
fn keep(node: &SstNode, w: f32, cull: bool) -> bool {
    !node.is_empty() && (!cull || w > 0.0)
}

/// A shallow light cut at (x, n) (thesis 5.1): from the root, repeatedly split the splittable
/// (inner) node of highest weight (ties: the lowest slot) until the cut holds `cut_size`
/// nodes or nothing can be split. A split puts the first kept child in the parent's slot and
/// appends the second; a parent with no kept child leaves the cut (the last slot moves into
/// its place). Returns the node ids in slot order.
pub fn build_cut(nodes: &[SstNode], x: Vec3, n: Vec3, eps: f32, cut_size: u32, cull: bool) -> Vec<u32> {
    build_cut_on(nodes, Topology::perfect_of(nodes), x, n, eps, cut_size, cull)
}

/// [`build_cut`] on either tree (`topo`: the perfect tree's heap or the radix tree's links).
pub fn build_cut_on(
    nodes: &[SstNode],
    topo: Topology<'_>,
    x: Vec3,
    n: Vec3,
    eps: f32,
    cut_size: u32,
    cull: bool,
) -> Vec<u32> {
    let leaves = topo.leaves;
    let cut_size = cut_size.clamp(1, MAX_CUT) as usize;
    let mut ids: Vec<u32> = Vec::with_capacity(cut_size);
    let mut ws: Vec<f32> = Vec::with_capacity(cut_size);
    let w_root = node_weight(&nodes[1], x, n, eps);
    if keep(&nodes[1], w_root, cull) {
        ids.push(1);
        ws.push(w_root);
    }
    while ids.len() < cut_size {
        let mut best = usize::MAX;
        let mut best_w = -1.0f32;
        for (i, (&id, &w)) in ids.iter().zip(&ws).enumerate() {
            if id < leaves && w > best_w {
                best = i;
                best_w = w;
            }
        }
        if best == usize::MAX {
            break;
        }
        let (c0, c1) = topo.children(ids[best]);
        let (w0, w1) = (
            node_weight(&nodes[c0 as usize], x, n, eps),
            node_weight(&nodes[c1 as usize], x, n, eps),
        );
        let (k0, k1) = (
            keep(&nodes[c0 as usize], w0, cull),
            keep(&nodes[c1 as usize], w1, cull),
        );
        match (k0, k1) {
            (true, true) => {
                (ids[best], ws[best]) = (c0, w0);
                ids.push(c1);
                ws.push(w1);
            }
            (true, false) => (ids[best], ws[best]) = (c0, w0),
            (false, true) => (ids[best], ws[best]) = (c1, w1),
            (false, false) => {
                ids.swap_remove(best);
                ws.swap_remove(best);
            }
        }
    }
    ids
}

/// Near-field refinement (ours; `theta` = 0 is the thesis's rule): whether the traversal
/// may stop at usable node `node` for shaded point `x`, i.e. x lies at least
/// max(eps, theta x the box diagonal) from the node's box. `slc_far_enough` in
/// `common/slc.wgsl`.
pub fn far_enough(node: &SstNode, x: Vec3, eps: f32, theta: f32) -> bool {
    if theta <= 0.0 {
        return true;
    }
    let q = x.clamp(node.bbox_min, node.bbox_max) - x;
    let r = eps.max(theta * (node.bbox_max - node.bbox_min).length());
    q.dot(q) >= r * r
}

/// Where the shadow ray of a substitute sample ends (`slc_substitute_end` in
/// `common/slc.wgsl`; the SST paper's scene-size epsilon, section 5): `e`, the drawn point
/// already moved `gi.ray_offset` along the node's normal, moved `d` further towards the ray's
/// origin `o`, at most half way. The segment o-e' lies within o-e, so it can only see more.
pub fn substitute_ray_end(e: Vec3, o: Vec3, d: f32) -> Vec3 {
    let l = (o - e).length();
    if l <= 0.0 || d <= 0.0 {
        return e;
    }
    e + (o - e) * (d / l).min(0.5)
}

/// Eq. 5.3: the normals agree (dot > n_min) and the points are closer than d_max (metres).
pub fn similar(px: Vec3, nx: Vec3, py: Vec3, ny: Vec3, n_min: f32, d_max: f32) -> bool {
    nx.dot(ny) > n_min && px.distance(py) < d_max
}

/// The block whose centre sample builds the cut: pixel (bx k + k/2, by k + k/2), clamped to
/// the image.
pub fn block_centre(bx: u32, by: u32, k: u32, w: u32, h: u32) -> (u32, u32) {
    ((bx * k + k / 2).min(w - 1), (by * k + k / 2).min(h - 1))
}

/// The 4 blocks around pixel (x, y) and their bilinear weights (thesis Algorithm 1, line 2,
/// before the similarity factor): block centres at ((b + 1/2) k); blocks outside the grid get
/// weight 0. Returns ((bx, by), weight) with bx, by possibly outside the grid.
pub fn bilinear_blocks(x: u32, y: u32, k: u32, grid: (u32, u32)) -> [((i32, i32), f32); 4] {
    let fx = (x as f32 + 0.5) / k as f32 - 0.5;
    let fy = (y as f32 + 0.5) / k as f32 - 0.5;
    let (bx, by) = (fx.floor(), fy.floor());
    let (tx, ty) = (fx - bx, fy - by);
    let (bx, by) = (bx as i32, by as i32);
    let mut out = [((0, 0), 0.0); 4];
    for (i, (dx, dy)) in [(0, 0), (1, 0), (0, 1), (1, 1)].into_iter().enumerate() {
        let (cx, cy) = (bx + dx, by + dy);
        let wx = if dx == 0 { 1.0 - tx } else { tx };
        let wy = if dy == 0 { 1.0 - ty } else { ty };
        let inside = cx >= 0 && cy >= 0 && (cx as u32) < grid.0 && (cy as u32) < grid.1;
        out[i] = ((cx, cy), if inside { wx * wy } else { 0.0 });
    }
    out
}

/// Level of the mock cut (thesis 5.1.4): floor(log2(cut_size)), at most the leaves' level.
pub fn mock_level(cut_size: u32, levels: u32) -> u32 {
    cut_size.max(1).ilog2().min(levels - 1)
}

/// The mock cut of a tree (thesis 5.1.4): the perfect tree's level [`mock_level`] (2^l nodes,
/// slot i = node 2^l + i); on the radix tree, which has no levels of equal nodes, as many
/// nodes (fewer when leaves stop it) from splitting, from the root, the node covering the
/// most leaves (ties: the lowest slot), the first child taking its slot and the second
/// appended: a partition of the VPLs into about equal key ranges, as the perfect tree's level
/// is. Twin: `slc_mock_cut` in `common/slc.wgsl`.
pub fn mock_cut(topo: Topology<'_>, cut_size: u32, levels: u32) -> Vec<u32> {
    let l = mock_level(cut_size, levels);
    if topo.links.is_none() {
        return ((1u32 << l)..(2u32 << l)).collect();
    }
    let mut ids = vec![1u32];
    while ids.len() < (1usize << l) {
        let span = |i: u32| {
            let (f, e) = topo.leaf_range(i);
            e - f
        };
        let mut best = usize::MAX;
        let mut best_span = 0u32;
        for (k, &i) in ids.iter().enumerate() {
            if !topo.is_leaf(i) && span(i) + 1 > best_span {
                best = k;
                best_span = span(i) + 1;
            }
        }
        if best == usize::MAX {
            break;
        }
        let (c0, c1) = topo.children(ids[best]);
        ids[best] = c0;
        ids.push(c1);
    }
    ids
}

/// Checks a cut: no node twice, none an ancestor of another (so every leaf is covered at
/// most once), no empty node.
pub fn check_cut(cut: &[u32], nodes: &[SstNode]) -> Result<(), String> {
    check_cut_on(cut, nodes, Topology::perfect_of(nodes))
}

/// [`check_cut`] on either tree.
pub fn check_cut_on(cut: &[u32], nodes: &[SstNode], topo: Topology<'_>) -> Result<(), String> {
    for (i, &a) in cut.iter().enumerate() {
        if a == 0 || a as usize >= nodes.len() {
            return Err(format!("slot {i}: node {a} out of range"));
        }
        if nodes[a as usize].is_empty() {
            return Err(format!("slot {i}: node {a} is empty"));
        }
        for &b in &cut[i + 1..] {
            if topo.contains(a, b) || topo.contains(b, a) {
                return Err(format!("nodes {a} and {b}: one contains the other"));
            }
        }
    }
    Ok(())
}

/// Nodes a cut could hold at most: the non-empty leaves reachable from the root through kept
/// nodes (with culling: nodes of positive weight).
pub fn reachable_leaves(nodes: &[SstNode], x: Vec3, n: Vec3, eps: f32, cull: bool) -> u32 {
    reachable_leaves_on(nodes, Topology::perfect_of(nodes), x, n, eps, cull)
}

/// [`reachable_leaves`] on either tree.
pub fn reachable_leaves_on(
    nodes: &[SstNode],
    topo: Topology<'_>,
    x: Vec3,
    n: Vec3,
    eps: f32,
    cull: bool,
) -> u32 {
    let mut count = 0;
    let mut stack = vec![1u32];
    while let Some(i) = stack.pop() {
        let w = node_weight(&nodes[i as usize], x, n, eps);
        if !keep(&nodes[i as usize], w, cull) {
            continue;
        }
        if topo.is_leaf(i) {
            count += 1;
        } else {
            let (c0, c1) = topo.children(i);
            stack.push(c0);
            stack.push(c1);
        }
    }
    count
}

/// The exact sum a traversal from `node` estimates: sum over the non-empty leaves below of
/// their unoccluded contribution flux/pi x G (without the albedo/pi), with `vpl_g` giving
/// G for a leaf (tests pass the VPL geometry term).
pub fn subtree_sum(nodes: &[SstNode], node: u32, g: &dyn Fn(&SstNode) -> f32) -> Vec3 {
    subtree_sum_on(nodes, Topology::perfect_of(nodes), node, g)
}

/// [`subtree_sum`] on either tree.
pub fn subtree_sum_on(nodes: &[SstNode], topo: Topology<'_>, node: u32, g: &dyn Fn(&SstNode) -> f32) -> Vec3 {
    let (first, last) = topo.leaf_range(node);
    (first..=last)
        .map(|k| &nodes[(topo.leaves + k) as usize])
        .filter(|l| !l.is_empty())
        .map(|l| l.intensity / std::f32::consts::PI * g(l))
        .sum()
}

/// The half-resolution image [`upsample_pixel`] reads (half pixel h holds full pixel 2h): its
/// size and, per pixel, its position (None without geometry), unit normal and demodulated
/// value.
#[derive(Clone, Copy)]
pub struct HalfImage<'a> {
    pub size: (u32, u32),
    pub position: &'a dyn Fn(u32, u32) -> Option<Vec3>,
    pub normal: &'a dyn Fn(u32, u32) -> Vec3,
    pub value: &'a dyn Fn(u32, u32) -> Vec3,
}

/// Reference of `shaders/methods/tree_samplers/slc_upsample.wgsl`: full-resolution pixel (x, y)
/// at (p, n) from the 4 samples of `half` around (x/2, y/2), with bilinear weights x S
/// (eq. 5.3); if none is similar, the neighbour with the most similar normal. Returns the
/// demodulated value (multiply by the albedo for radiance).
pub fn upsample_pixel(
    x: u32,
    y: u32,
    p: Vec3,
    n: Vec3,
    half: &HalfImage<'_>,
    n_min: f32,
    d_max: f32,
) -> Vec3 {
    let HalfImage {
        size: half_size,
        position: half_pos,
        normal: half_nrm,
        value: half_val,
    } = *half;
    let (fx, fy) = (x as f32 * 0.5, y as f32 * 0.5);
    let (bx, by) = (fx.floor(), fy.floor());
    let (tx, ty) = (fx - bx, fy - by);
    let (mut sum, mut wsum) = (Vec3::ZERO, 0.0f32);
    let (mut best, mut best_dot) = (Vec3::ZERO, -2.0f32);
    for i in 0..4u32 {
        let (dx, dy) = ((i & 1) as i32, (i >> 1) as i32);
        let (hx, hy) = (bx as i32 + dx, by as i32 + dy);
        if hx < 0 || hy < 0 || hx >= half_size.0 as i32 || hy >= half_size.1 as i32 {
            continue;
        }
        let Some(hp) = half_pos(hx as u32, hy as u32) else {
            continue;
        };
        let hn = half_nrm(hx as u32, hy as u32);
        let v = half_val(hx as u32, hy as u32);
        let nd = n.dot(hn);
        if nd > best_dot {
            best_dot = nd;
            best = v;
        }
        let w = if dx == 1 { tx } else { 1.0 - tx } * if dy == 1 { ty } else { 1.0 - ty };
        if similar(p, n, hp, hn, n_min, d_max) {
            sum += w * v;
            wsum += w;
        }
    }
    if wsum > 0.0 { sum / wsum } else { best }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::gpu_layout::GpuVpl;
    use crate::reference::sst_tree::{build, sort_vpls};

    #[test]
    fn glossy_term_follows_the_mirror_direction_and_keeps_the_support() {
        use super::super::brdf::Surface;
        let (x, n) = (Vec3::ZERO, Vec3::Z);
        let v = Vec3::new(-1.0, 0.0, 1.0).normalize();
        let r = 2.0 * n.dot(v) * n - v;
        let s = Surface {
            base: Vec3::splat(0.9),
            metallic: 1.0,
            roughness: 0.3,
        };
        // A box on the mirror ray: R itself.
        let on = (Vec3::new(1.8, -0.2, 1.8), Vec3::new(2.2, 0.2, 2.2));
        assert_eq!(mirror_toward(on.0, on.1, x, r), r);
        // A box beside it: a direction into the box (its point level with the centre).
        let off = (Vec3::new(1.8, 1.0, 1.8), Vec3::new(2.2, 1.4, 2.2));
        let d = mirror_toward(off.0, off.1, x, r);
        assert!((d.length() - 1.0).abs() < 1e-5);
        let t = ((off.0 + off.1) * 0.5).dot(d);
        let p = x + d * t;
        assert!(
            p.y >= off.0.y - 1e-4 && p.y <= off.1.y + 1e-4,
            "{d} does not point into the box"
        );
        assert!(d.dot(r) < 1.0 - 1e-4);
        let (g_on, g_off) = (
            glossy_term(on.0, on.1, x, n, v, &s),
            glossy_term(off.0, off.1, x, n, v, &s),
        );
        // On the mirror direction the term is the specular BRDF at the lobe's peak (n.h = 1).
        let a2 = brdf::alpha(0.3).powi(2);
        let nv = n.dot(v);
        let peak = luminance(brdf::schlick(brdf::f0(s.base, 1.0), nv)) * brdf::ggx_d(1.0, a2) * 0.5
            / (2.0 * nv * (nv * nv * (1.0 - a2) + a2).sqrt());
        assert!((g_on - peak).abs() < 1e-4 * peak, "{g_on} vs {peak}");
        assert!(g_off > 0.0 && g_off < 0.5 * g_on, "{g_off} vs {g_on}");
        // Farther from the lobe, smaller.
        let far = (Vec3::new(1.8, 3.0, 1.8), Vec3::new(2.2, 3.4, 2.2));
        assert!(glossy_term(far.0, far.1, x, n, v, &s) < g_off);
        // A box behind the view (below the tangent plane too): still positive, so no branch
        // the geometric weights keep is cut off.
        let below = (Vec3::new(-3.0, -0.5, -1.0), Vec3::new(-2.0, 0.5, 0.05));
        assert!(glossy_term(below.0, below.1, x, n, v, &s) > 0.0);
        // A view from below the surface: no glossy light at all.
        assert_eq!(glossy_term(on.0, on.1, x, n, -v, &s), 0.0);
        // The multipliers scale the weights: equal terms change nothing.
        let patch = |lo: Vec3, hi: Vec3| SstNode {
            position: 0.5 * (lo + hi),
            intensity: Vec3::ONE,
            bbox_min: lo,
            bbox_max: hi,
            ..SstNode::EMPTY
        };
        let l = patch(Vec3::new(-1.0, -1.0, 1.0), Vec3::new(0.0, 1.0, 1.2));
        let rr = patch(Vec3::new(1.0, -1.0, 1.0), Vec3::new(2.0, 1.0, 1.2));
        let eps = 0.01;
        for mode in [
            ChildProbability::Mean,
            ChildProbability::MinMax,
            ChildProbability::Defensive,
        ] {
            let p1 = child_probability(&l, &rr, x, n, eps, mode).unwrap();
            let p2 = child_probability_m(&l, &rr, x, n, eps, mode, (0.5, 0.5)).unwrap();
            assert!((p1 - p2).abs() < 1e-6);
            let p3 = child_probability_m(&l, &rr, x, n, eps, mode, (2.0, 0.5)).unwrap();
            assert!(p3 > p1, "{mode:?}: a larger term takes more probability");
        }
    }

    #[test]
    fn child_probabilities_by_hand() {
        use ChildProbability::{Defensive, Mean, MinMax};
        // Two floor patches under a point looking down: the left one is long with its mean at
        // the far end (x sits right above its near end), the right one is small and 2 m away.
        let patch = |lo: Vec3, hi: Vec3, mean: Vec3| SstNode {
            position: mean,
            intensity: Vec3::ONE,
            bbox_min: lo,
            bbox_max: hi,
            ..SstNode::EMPTY
        };
        let l = patch(Vec3::ZERO, Vec3::new(4.0, 1.0, 0.0), Vec3::new(3.5, 0.5, 0.0));
        let r = patch(
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(1.0, 3.0, 0.0),
            Vec3::new(0.5, 2.5, 0.0),
        );
        let (x, n, eps) = (Vec3::new(0.0, 0.5, 0.2), Vec3::NEG_Z, 0.05);
        let mean = child_probability(&l, &r, x, n, eps, Mean).unwrap();
        let (wl, wr) = (node_weight(&l, x, n, eps), node_weight(&r, x, n, eps));
        assert!((mean - wl / (wl + wr)).abs() < 1e-7);
        // MinMax keeps at least half of the closest-point share (0.2 m vs 1.5 m away: > 0.9), so
        // the near patch gets more than eq. 5.5 with its far mean gives it.
        let mm = child_probability(&l, &r, x, n, eps, MinMax).unwrap();
        assert!(
            mm > 0.45 && mm < 1.0 && mm > mean + 0.25,
            "min-max {mm}, mean {mean}"
        );
        // By hand: closest points at d^2 = 0.04 and 2.29, farthest at 16 + 0.25 + 0.04 and
        // 1 + 6.25 + 0.04.
        let (gl, gr) = (
            box_cos(l.bbox_min, l.bbox_max, x, n),
            box_cos(r.bbox_min, r.bbox_max, x, n),
        );
        let (nl, nr, fl, fr) = (gl / 0.04, gr / 2.29, gl / 16.29, gr / 7.29);
        let want = 0.5 * (nl / (nl + nr) + fl / (fl + fr));
        assert!((mm - want).abs() < 1e-5, "{mm} vs {want}");
        // Defensive: 0.8 x the thesis's share + 0.2 x the closest-point one (> 0.9 x 0.2).
        let def = child_probability(&l, &r, x, n, eps, Defensive).unwrap();
        let want = 0.8 * mean + 0.2 * nl / (nl + nr);
        assert!((def - want).abs() < 1e-5, "{def} vs {want}");
        assert!(def > mean + 0.1 && def > 0.18, "defensive {def}, mean {mean}");
        // An empty or unseen child gets nothing; nothing seen: a dead branch.
        let empty = SstNode::EMPTY;
        assert_eq!(child_probability(&l, &empty, x, n, eps, MinMax), Some(1.0));
        assert_eq!(child_probability(&l, &empty, x, n, eps, Mean), Some(1.0));
        assert_eq!(child_probability(&l, &empty, x, n, eps, Defensive), Some(1.0));
        assert_eq!(child_probability(&l, &r, x, Vec3::Z, eps, MinMax), None);
        assert_eq!(child_probability(&l, &r, x, Vec3::Z, eps, Mean), None);
        assert_eq!(child_probability(&l, &r, x, Vec3::Z, eps, Defensive), None);
    }

    #[test]
    fn near_field_rule_by_hand() {
        // A 1 x 1 x 0 box (diagonal sqrt 2) on the floor.
        let node = SstNode {
            bbox_min: Vec3::ZERO,
            bbox_max: Vec3::new(1.0, 1.0, 0.0),
            ..SstNode::EMPTY
        };
        let eps = 0.05;
        // Off: every usable node is a stop, even with x inside its box.
        assert!(far_enough(&node, Vec3::new(0.5, 0.5, 0.0), eps, 0.0));
        // Inside or on the box: never a stop.
        assert!(!far_enough(&node, Vec3::new(0.5, 0.5, 0.0), eps, 1.0));
        assert!(!far_enough(&node, Vec3::new(1.0, 0.0, 0.0), eps, 1e-6));
        // theta = 1: at least sqrt 2 from the box.
        assert!(!far_enough(&node, Vec3::new(0.5, 0.5, 1.4), eps, 1.0));
        assert!(far_enough(&node, Vec3::new(0.5, 0.5, 1.42), eps, 1.0));
        assert!(far_enough(&node, Vec3::new(2.0, 2.0, 0.0), eps, 1.0));
        assert!(!far_enough(&node, Vec3::new(2.0, 2.0, 0.0), eps, 1.0 + 1e-3));
        // A tiny box: eps bounds the radius from below.
        let dot = SstNode {
            bbox_min: Vec3::ZERO,
            bbox_max: Vec3::splat(1e-3),
            ..SstNode::EMPTY
        };
        assert!(!far_enough(&dot, Vec3::new(0.0, 0.0, 0.04), eps, 1.0));
        assert!(far_enough(&dot, Vec3::new(0.0, 0.0, 0.052), eps, 1.0));
    }

    #[test]
    fn substitute_rays_end_short_of_the_point_at_most_half_way() {
        let (e, o) = (Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 2.0, 0.0));
        assert_eq!(substitute_ray_end(e, o, 0.0), e);
        assert!((substitute_ray_end(e, o, 0.05) - Vec3::new(1.0, 0.05, 0.0)).length() < 1e-6);
        // Capped at half the segment: the ray never collapses onto the shaded point.
        assert!((substitute_ray_end(e, o, 5.0) - Vec3::new(1.0, 1.0, 0.0)).length() < 1e-6);
        assert_eq!(substitute_ray_end(e, e, 0.05), e);
        // The shortened segment lies within the original one.
        let f = substitute_ray_end(e, o, 0.3);
        assert!(((f - e).length() + (o - f).length() - (o - e).length()).abs() < 1e-6);
    }

    fn floor_and_wall(n: usize) -> Vec<SstNode> {
        let mut s = 7u32;
        let mut r = move || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            (s >> 8) as f32 / (1 << 24) as f32
        };
        let vpls: Vec<GpuVpl> = (0..n)
            .map(|i| {
                let (p, nrm) = if i % 2 == 0 {
                    (Vec3::new(r() * 4.0, 0.0, r() * 4.0), Vec3::Y)
                } else {
                    (Vec3::new(r() * 4.0, r() * 3.0, 0.0), Vec3::Z)
                };
                GpuVpl {
                    position: p.extend(1.0).to_array(),
                    normal: nrm.to_array(),
                    id: i as u32,
                    flux: [r(), r(), r(), 1.0],
                }
            })
            .collect();
        build(&sort_vpls(&vpls))
    }

    #[test]
    fn weights_by_hand() {
        let mut n = SstNode::EMPTY;
        assert_eq!(node_weight(&n, Vec3::ZERO, Vec3::Y, 0.05), 0.0);
        // A point light 2 m straight above: cos 1, 1/d^2 = 1/4, luminance of (1,1,1) = 1.
        n.intensity = Vec3::ONE;
        n.bbox_min = Vec3::new(0.0, 2.0, 0.0);
        n.bbox_max = n.bbox_min;
        n.position = n.bbox_min;
        assert!((node_weight(&n, Vec3::ZERO, Vec3::Y, 0.05) - 0.25).abs() < 1e-6);
        // Below the surface: 0; at 0.01 m: bounded by eps = 0.05 -> 1/0.0025.
        assert_eq!(node_weight(&n, Vec3::ZERO, -Vec3::Y, 0.05), 0.0);
        n.bbox_min = Vec3::new(0.0, 0.01, 0.0);
        n.bbox_max = n.bbox_min;
        n.position = n.bbox_min;
        assert!((node_weight(&n, Vec3::ZERO, Vec3::Y, 0.05) - 400.0).abs() < 1e-2);
        // A box straddling the tangent plane: half its corners count.
        n.bbox_min = Vec3::new(-1.0, -1.0, -1.0);
        n.bbox_max = Vec3::new(1.0, 1.0, 1.0);
        n.position = Vec3::ZERO;
        let w = node_weight(&n, Vec3::new(0.0, 0.0, 5.0), Vec3::Y, 0.05);
        assert!(w > 0.0);
        // A box around x: the falloff is towards the mean position (3 m away), not the box
        // (distance 0), so a large cluster around x does not weigh 1/eps^2.
        n.bbox_min = Vec3::splat(-4.0);
        n.bbox_max = Vec3::splat(4.0);
        n.position = Vec3::new(0.0, 3.0, 0.0);
        let w = node_weight(&n, Vec3::ZERO, Vec3::Y, 0.05);
        let g = box_cos(n.bbox_min, n.bbox_max, Vec3::ZERO, Vec3::Y);
        // The 4 upper corners at cos 4/sqrt(48) each, the 4 lower ones 0.
        assert!((g - 0.5 * 4.0 / 48f32.sqrt()).abs() < 1e-6, "{g}");
        assert!((w - g / 9.0).abs() < 1e-6, "{w}");
        assert!(box_term(n.bbox_min, n.bbox_max, Vec3::ZERO, Vec3::Y, 0.05) > 100.0 * w);
    }

    #[test]
    fn cuts_are_valid_and_as_large_as_possible() {
        let nodes = floor_and_wall(1000);
        for (x, nx) in [
            (Vec3::new(2.0, 0.0, 2.0), Vec3::Y),
            (Vec3::new(2.0, 1.5, 0.0), Vec3::Z),
            (Vec3::new(3.9, 2.9, 3.9), -Vec3::Y),
            (Vec3::new(-1.0, 1.0, 2.0), Vec3::X),
        ] {
            for cull in [true, false] {
                for size in [1, 2, 7, 32, 64] {
                    let cut = build_cut(&nodes, x, nx, 0.05, size, cull);
                    check_cut(&cut, &nodes).unwrap();
                    let reach = reachable_leaves(&nodes, x, nx, 0.05, cull);
                    assert_eq!(
                        cut.len() as u32,
                        size.min(reach),
                        "size {size} cull {cull} at {x}"
                    );
                    if cull {
                        assert!(
                            cut.iter()
                                .all(|&c| node_weight(&nodes[c as usize], x, nx, 0.05) > 0.0)
                        );
                    }
                }
            }
        }
        // Facing away from everything (above the room looking up): nothing reachable.
        let cut = build_cut(&nodes, Vec3::new(2.0, 10.0, 2.0), Vec3::Y, 0.05, 32, true);
        assert!(cut.is_empty());
    }

    #[test]
    fn a_complete_cut_partitions_the_contributing_leaves() {
        // Without culling, a cut covers every non-empty leaf exactly once.
        let nodes = floor_and_wall(300);
        let leaves = nodes.len() / 2;
        let cut = build_cut(&nodes, Vec3::new(1.0, 1.0, 1.0), Vec3::Y, 0.05, 32, false);
        let mut covered = vec![0u32; leaves];
        for &c in &cut {
            let depth = (leaves as u32).trailing_zeros() - c.ilog2();
            for l in (c << depth)..((c + 1) << depth) {
                covered[l as usize - leaves] += 1;
            }
        }
        for (i, &c) in covered.iter().enumerate() {
            let empty = nodes[leaves + i].is_empty();
            assert_eq!(c, if empty { c.min(1) } else { 1 }, "leaf {i}");
        }
    }

    #[test]
    fn bilinear_weights_sum_to_one_inside() {
        let grid = (10, 8);
        for (x, y) in [(0, 0), (3, 4), (40, 30), (79, 63), (12, 60)] {
            let b = bilinear_blocks(x, y, 8, grid);
            let s: f32 = b.iter().map(|(_, w)| w).sum();
            let all_inside = b
                .iter()
                .all(|((bx, by), _)| *bx >= 0 && *by >= 0 && (*bx as u32) < grid.0 && (*by as u32) < grid.1);
            if all_inside {
                assert!((s - 1.0).abs() < 1e-5, "({x},{y}) {s}");
            }
            assert!(s > 0.0);
        }
        // A pixel at a block centre (k even: between pixels 3 and 4 of the block) weighs
        // its own block most.
        let b = bilinear_blocks(20, 20, 8, grid);
        let best = b.iter().max_by(|a, c| a.1.total_cmp(&c.1)).unwrap();
        assert_eq!(best.0, (2, 2));
        assert_eq!(mock_level(32, 13), 5);
        assert_eq!(mock_level(33, 13), 5);
        assert_eq!(mock_level(64, 4), 3);
        assert_eq!(mock_level(1, 13), 0);
    }
}

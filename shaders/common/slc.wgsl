// Tree sampling helpers (thesis chapter 5): node weights (eq. 5.5 with the geometric term of
// eq. 5.2) and shallow light cuts (5.1). CPU twin: src/reference/slc.rs.
// Contract: the includer declares `tree: array<SstNode>` and includes common/sst_node.wgsl,
// common/color.wgsl, common/box_term.wgsl and common/tree_links.wgsl (with its contract).

const SLC_MAX_CUT: u32 = 64u;

// w = luminance(I) x (average clamped cosine to the box corners, eq. 5.2) / max(d^2, eps^2)
// with d the distance to the node's intensity-weighted mean position: the quadratic falloff
// of Lightcuts' cluster approximation (eq. 5.1) towards its representative point. 0 when the
// node is empty or nothing in it can light x (the support, hence unbiasedness, is that of
// the box term). See docs/results.md for why not the distance to the box.
fn slc_node_weight(node: SstNode, x: vec3<f32>, n: vec3<f32>, eps: f32) -> f32 {
    if sst_is_empty(node) {
        return 0.0;
    }
    let g = box_cos(node.bbox_min, node.bbox_max, x, n);
    let d = node.position - x;
    return luminance(node.intensity) * (g / max(dot(d, d), eps * eps));
}

// Share of the closest-point normalisation in the defensive child probability (twin:
// `reference::slc::DEFENSIVE`).
const SLC_DEFENSIVE: f32 = 0.2;

// Probability of taking the left child of a traversal step (stage 14); < 0: dead branch (both
// children weigh 0). mode 0, the thesis: wl / (wl + wr) with slc_node_weight. mode 1, RTSLC's
// "MinMax": the average of the two normalisations of lum(I) x box_cos / max(d^2, eps^2) with d
// the distance to each child's box (0 inside) and to its farthest point. mode 2, "defensive"
// (ours): (1 - SLC_DEFENSIVE) x the thesis's + SLC_DEFENSIVE x the closest-point
// normalisation. All have the support of box_cos (lum(I) x box_cos = 0 <=> w = 0), so each
// is unbiased wherever eq. 5.5 is.
fn slc_child_prob(l: SstNode, r: SstNode, x: vec3<f32>, n: vec3<f32>, eps: f32, mode: u32) -> f32 {
    return slc_child_prob_m(l, r, x, n, eps, mode, 1.0, 1.0);
}

// slc_child_prob with each child's weight times a material term (ml, mr >= 0; the glossy
// walk's slc_glossy_term, 1 otherwise): the SST paper's eq. 5 weight M_j x G_j x I_j.
fn slc_child_prob_m(l: SstNode, r: SstNode, x: vec3<f32>, n: vec3<f32>, eps: f32, mode: u32,
    ml: f32, mr: f32) -> f32 {
    if mode == 0u {
        let wl = slc_node_weight(l, x, n, eps) * ml;
        let wr = slc_node_weight(r, x, n, eps) * mr;
        let s = wl + wr;
        return select(-1.0, wl / s, s > 0.0);
    }
    let gl = select(luminance(l.intensity) * box_cos(l.bbox_min, l.bbox_max, x, n), 0.0, sst_is_empty(l)) * ml;
    let gr = select(luminance(r.intensity) * box_cos(r.bbox_min, r.bbox_max, x, n), 0.0, sst_is_empty(r)) * mr;
    if !(gl + gr > 0.0) {
        return -1.0;
    }
    let e2 = eps * eps;
    let ql = clamp(x, l.bbox_min, l.bbox_max) - x;
    let qr = clamp(x, r.bbox_min, r.bbox_max) - x;
    let nl = gl / max(dot(ql, ql), e2);
    let nr = gr / max(dot(qr, qr), e2);
    if mode == 2u {
        // eq. 5.5's weights from the cosine terms above (slc_node_weight without computing
        // box_cos again).
        let dl = l.position - x;
        let dr = r.position - x;
        let ml = gl / max(dot(dl, dl), e2);
        let mr = gr / max(dot(dr, dr), e2);
        return mix(ml / (ml + mr), nl / (nl + nr), SLC_DEFENSIVE);
    }
    let fl = max(abs(x - l.bbox_min), abs(x - l.bbox_max));
    let fr = max(abs(x - r.bbox_min), abs(x - r.bbox_max));
    let xl = gl / max(dot(fl, fl), e2);
    let xr = gr / max(dot(fr, fr), e2);
    return 0.5 * (nl / (nl + nr) + xl / (xl + xr));
}

// The SST paper's glossy material term (section 4.1: "For the glossy part of the BRDF ... We
// compute the perfect reflection R of the view vector along the surface normal at x ... test
// if the ray x + t R intersects with the cluster's bounding box. If so, we use R for the glossy
// BRDF computation. Otherwise, the BRDF is evaluated with a direction vector R' that actually
// does intersect the bounding box and minimizes the difference to R"). R' here: towards the
// point of the box nearest the reflected ray's point level with the box centre,
// clamp(x + R max((c - x).R, 0), lo, hi) (an approximation of the minimising direction).
// Returns luminance(F(v.h)) D(n.h) Vis(n.l, n.v) at l = R' with n.l at least 1e-3, so the
// term is positive wherever n.v > 0 and the walk keeps the support of the geometric weights
// (unbiased). 0 when n.v <= 0, where the glossy part is 0 for every light. The cosine is the
// weight's box_cos. f0 = F0, a2 = alpha^2 (common/brdf.wgsl). Twin: `reference::slc::glossy_term`.
// The geometric share of the defensive glossy weights (sampling.glossy_weights; twin:
// `base::sampling::GLOSSY_DEFENSIVE`).
const SLC_GLOSSY_DEFENSIVE: f32 = 0.25;

fn slc_mirror_toward(lo: vec3<f32>, hi: vec3<f32>, x: vec3<f32>, r: vec3<f32>) -> vec3<f32> {
    let rs = select(vec3<f32>(1e-8), r, abs(r) >= vec3<f32>(1e-8));
    let inv = vec3<f32>(1.0) / rs;
    let t0 = (lo - x) * inv;
    let t1 = (hi - x) * inv;
    let tn = min(t0, t1);
    let tf = max(t0, t1);
    let t_in = max(max(tn.x, tn.y), max(tn.z, 0.0));
    let t_out = min(min(tf.x, tf.y), tf.z);
    if t_in <= t_out {
        return r;
    }
    let c = 0.5 * (lo + hi);
    let p = clamp(x + r * max(dot(c - x, r), 0.0), lo, hi);
    let d = p - x;
    let l2 = dot(d, d);
    if !(l2 > 1e-20) {
        return r;
    }
    return d / sqrt(l2);
}

fn slc_glossy_term(lo: vec3<f32>, hi: vec3<f32>, x: vec3<f32>, n: vec3<f32>, v: vec3<f32>,
    f0: vec3<f32>, a2: f32) -> f32 {
    let nv = dot(n, v);
    if !(nv > 0.0) {
        return 0.0;
    }
    let r = 2.0 * nv * n - v;
    let l = slc_mirror_toward(lo, hi, x, r);
    let nl = max(dot(n, l), 1e-3);
    let hs = v + l;
    let h = select(n, normalize(hs), dot(hs, hs) > 1e-12);
    let nh = max(dot(n, h), 0.0);
    let q = nh * nh * (a2 - 1.0) + 1.0;
    let d = a2 / (3.14159265358979 * q * q);
    let vis = 0.5 / (nl * sqrt(nv * nv * (1.0 - a2) + a2) + nv * sqrt(nl * nl * (1.0 - a2) + a2));
    let m = 1.0 - clamp(dot(v, h), 0.0, 1.0);
    let m2 = m * m;
    let f = f0 + (vec3<f32>(1.0) - f0) * (m2 * m2 * m);
    return luminance(f) * d * vis;
}

// Near-field refinement (ours; theta = 0 turns it off, the thesis's rule): a usable node is
// sampled only when x lies at least max(eps, theta x |box diagonal|) from its box, an opening
// criterion like Barnes-Hut's. Closer, its substitute samples land off the real surfaces
// and 1/d^2 turns them into fireflies, so the traversal descends instead.
fn slc_far_enough(node: SstNode, x: vec3<f32>, eps: f32, theta: f32) -> bool {
    if theta <= 0.0 {
        return true;
    }
    let q = clamp(x, node.bbox_min, node.bbox_max) - x;
    let r = max(eps, theta * length(node.bbox_max - node.bbox_min));
    return dot(q, q) >= r * r;
}

// Where the shadow ray of a substitute sample ends (the SST paper's scene-size epsilon,
// section 5: drawn points may lie slightly inside geometry): e, the drawn point moved
// gi.ray_offset along the node's normal, moved a further d towards the ray's origin o, at
// most half way. The segment o-e' lies within o-e, so it can only see more.
fn slc_substitute_end(e: vec3<f32>, o: vec3<f32>, d: f32) -> vec3<f32> {
    let l = length(o - e);
    if l <= 0.0 || d <= 0.0 {
        return e;
    }
    return e + (o - e) * min(d / l, 0.5);
}

fn slc_keep(i: u32, w: f32, cull: bool) -> bool {
    return !sst_is_empty(tree[i]) && (!cull || w > 0.0);
}

// The cut being built (per invocation).
var<private> cut_ids: array<u32, 64>;
var<private> cut_ws: array<f32, 64>;

// Builds a shallow light cut at (x, n) into cut_ids[0..count) and returns count: from the
// root, split the inner node of highest weight (ties: the lowest slot) until `cut_size`
// nodes or nothing splits; the first kept child takes the parent's slot, the second is
// appended; a parent without kept children leaves (the last slot moves into its place).
fn slc_build_cut(x: vec3<f32>, n: vec3<f32>, eps: f32, cut_size: u32, cull: bool, leaves: u32) -> u32 {
    var count = 0u;
    let w_root = slc_node_weight(tree[1], x, n, eps);
    if slc_keep(1u, w_root, cull) {
        cut_ids[0] = 1u;
        cut_ws[0] = w_root;
        count = 1u;
    }
    let size = clamp(cut_size, 1u, SLC_MAX_CUT);
    loop {
        if count >= size {
            break;
        }
        var best = 0xffffffffu;
        var best_w = -1.0;
        for (var i = 0u; i < count; i++) {
            if cut_ids[i] < leaves && cut_ws[i] > best_w {
                best = i;
                best_w = cut_ws[i];
            }
        }
        if best == 0xffffffffu {
            break;
        }
        let c0 = tree_left(cut_ids[best]);
        let c1 = tree_right(cut_ids[best]);
        let w0 = slc_node_weight(tree[c0], x, n, eps);
        let w1 = slc_node_weight(tree[c1], x, n, eps);
        let k0 = slc_keep(c0, w0, cull);
        let k1 = slc_keep(c1, w1, cull);
        if k0 && k1 {
            cut_ids[best] = c0;
            cut_ws[best] = w0;
            cut_ids[count] = c1;
            cut_ws[count] = w1;
            count += 1u;
        } else if k0 {
            cut_ids[best] = c0;
            cut_ws[best] = w0;
        } else if k1 {
            cut_ids[best] = c1;
            cut_ws[best] = w1;
        } else {
            count -= 1u;
            cut_ids[best] = cut_ids[count];
            cut_ws[best] = cut_ws[count];
        }
    }
    return count;
}

// The radix tree's mock cut (thesis 5.1.4 on a tree without levels of equal nodes) into
// cut_ids: from the root, split the inner node covering the most leaves (ties: the lowest
// slot) until `size` nodes or only leaves; returns the count. The perfect tree's mock cut is
// its level, computed where it is used. Twin: `reference::slc::mock_cut`.
fn slc_mock_cut(size: u32, leaves: u32) -> u32 {
    cut_ids[0] = 1u;
    var count = 1u;
    loop {
        if count >= min(size, SLC_MAX_CUT) {
            break;
        }
        var best = 0xffffffffu;
        var best_span = 0u;
        for (var i = 0u; i < count; i++) {
            if cut_ids[i] < leaves {
                let r = tree_leaf_range(cut_ids[i], leaves);
                if r.y - r.x + 1u > best_span {
                    best = i;
                    best_span = r.y - r.x + 1u;
                }
            }
        }
        if best == 0xffffffffu {
            break;
        }
        let p = cut_ids[best];
        cut_ids[best] = tree_left(p);
        cut_ids[count] = tree_right(p);
        count += 1u;
    }
    return count;
}

// Eq. 5.3.
fn slc_similar(px: vec3<f32>, nx: vec3<f32>, py: vec3<f32>, ny: vec3<f32>, n_min: f32, d_max: f32) -> bool {
    return dot(nx, ny) > n_min && distance(px, py) < d_max;
}

//! Reference of the SST build (stage 10; thesis 4.2.2, SST paper 3.2-3.3): a perfect binary
//! tree with implicit indexing over the sorted VPLs, merged bottom-up.
//!
//! Indexing (as RTSLC): `leaves` = the VPL count rounded up to a power of two (at least 2);
//! node 1 is the root, node n has children 2n and 2n+1, leaf i is node `leaves + i`, node 0 is
//! unused. Level l holds nodes 2^l .. 2^(l+1)-1; the leaves are level `levels - 1`.
//! Padding leaves (and empty VPLs, which sort last) have zero intensity and empty bounds.
//!
//! Merge of children a, b with weights w = luminance of their RGB flux (thesis: "relative
//! grayscale intensities"):
//! - position p = (w_a p_a + w_b p_b) / (w_a + w_b)  (eq. 4.1);
//! - normal = normalise(w_a n_a + w_b n_b), stored octahedral (16 bits per axis);
//! - variance in the frame (t, b, n) of the stored normal (eq. 4.2):
//!   sigma^2 = sum_c w_c (sigma_c^2 + d'_c (.) d'_c) / sum w, with d'_c = p_c - p in that frame.
//!   A child's variance lives in its own frame; we carry it into the parent's frame as the
//!   diagonal of R diag(sigma_c^2) R^T (sum_i sigma_ci^2 (f_i . e_k)^2). When the child's and the
//!   parent's normals agree this is eq. 4.2 exactly; when they differ it turns the child's
//!   in-plane spread into sigma_z of the parent (a bent cluster is not flat), and it keeps the
//!   trace: sigma_x^2 + sigma_y^2 + sigma_z^2 is exactly the weighted mean squared distance
//!   of the cluster's VPLs from p;
//! - v = v_a v_b max(n_a . n_b, 0)  (eq. 4.3), leaves v = 1, sigma^2 = 0;
//! - intensity = sum of RGB flux, bounds = union.
//!
//! A node is "usable for sampling" (SST paper eq. 3) when it is not empty, v >= v_min and
//! sigma_z < sigma_max (sigma_z = the standard deviation along the normal, in metres). Eq. 3
//! writes sigma_z <= sigma_max; the strict form differs only where sigma_z equals the bound
//! exactly, and makes sigma_max = 0 switch substitutes off (exactly flat clusters, sigma_z = 0,
//! would otherwise stay usable).
//!
//! The GPU twin (`shaders/sst_build.wgsl`) runs the same operations in the same order; the
//! stored normal and the f16 tangent variances are quantised identically here.

use glam::Vec3;

use crate::renderer::gpu_data::{GpuSstNode, GpuVpl, VPL_NONE};

/// Rec. 709 luminance, the merge weight (twin: `luminance` in `common/color.wgsl`).
pub use super::display::luminance;

/// Leaves of the tree for `count` VPLs: a power of two, at least 2.
pub fn leaf_count(count: u32) -> u32 {
    count.max(2).next_power_of_two()
}

/// Levels of a tree with `leaves` leaves (root = level 0).
pub fn level_count(leaves: u32) -> u32 {
    leaves.trailing_zeros() + 1
}

/// Orthonormal tangent frame of a unit normal (Duff et al. 2017, "Building an orthonormal
/// basis, revisited"). Twin: `basis` in `common/sst_node.wgsl`.
pub fn basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

fn sign_not_zero(v: f32) -> f32 {
    if v >= 0.0 { 1.0 } else { -1.0 }
}

/// Octahedral encoding of a unit vector into 2 x 16 bits (x in the low half; u = round(32767 v)
/// + 32767, so that 0 and +-1 are exact).
pub fn oct_encode(n: Vec3) -> u32 {
    let s = n.x.abs() + n.y.abs() + n.z.abs();
    let (mut px, mut py) = if s > 0.0 { (n.x / s, n.y / s) } else { (0.0, 0.0) };
    if n.z < 0.0 {
        let (ox, oy) = (px, py);
        px = (1.0 - oy.abs()) * sign_not_zero(ox);
        py = (1.0 - ox.abs()) * sign_not_zero(oy);
    }
    // Snorm-like: -1 -> 0, 0 -> 32767 (exact), 1 -> 65534.
    let q = |v: f32| (v.clamp(-1.0, 1.0) * 32767.0 + 32767.5).floor() as u32;
    q(px) | (q(py) << 16)
}

/// Inverse of [`oct_encode`] (unit length).
pub fn oct_decode(e: u32) -> Vec3 {
    let px = ((e & 0xffff) as f32 - 32767.0) / 32767.0;
    let py = ((e >> 16) as f32 - 32767.0) / 32767.0;
    let mut n = Vec3::new(px, py, 1.0 - px.abs() - py.abs());
    if n.z < 0.0 {
        let (ox, oy) = (n.x, n.y);
        n.x = (1.0 - oy.abs()) * sign_not_zero(ox);
        n.y = (1.0 - ox.abs()) * sign_not_zero(oy);
    }
    n.normalize()
}

/// Two f16 (round to nearest even) in one word, `a` in the low half (WGSL `pack2x16float`).
pub fn pack2x16float(a: f32, b: f32) -> u32 {
    half::f16::from_f32(a).to_bits() as u32 | ((half::f16::from_f32(b).to_bits() as u32) << 16)
}

pub fn unpack2x16float(w: u32) -> (f32, f32) {
    (
        half::f16::from_bits(w as u16).to_f32(),
        half::f16::from_bits((w >> 16) as u16).to_f32(),
    )
}

/// A node with its fields decoded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SstNode {
    pub position: Vec3,
    pub v: f32,
    pub intensity: Vec3,
    pub normal: Vec3,
    pub bbox_min: Vec3,
    pub bbox_max: Vec3,
    /// Variance in the node's frame (tangent, bitangent, normal).
    pub variance: Vec3,
}

impl SstNode {
    /// A padding node: zero intensity, empty bounds.
    pub const EMPTY: SstNode = SstNode {
        position: Vec3::ZERO,
        v: 1.0,
        intensity: Vec3::ZERO,
        normal: Vec3::Z,
        bbox_min: Vec3::splat(f32::MAX),
        bbox_max: Vec3::splat(-f32::MAX),
        variance: Vec3::ZERO,
    };

    pub fn is_empty(&self) -> bool {
        self.bbox_min.x > self.bbox_max.x
    }

    /// A leaf for one VPL (`VPL_NONE` gives a padding leaf); its normal as stored.
    pub fn leaf(vpl: &GpuVpl) -> SstNode {
        if vpl.id == VPL_NONE {
            return SstNode::EMPTY;
        }
        let p = Vec3::from_slice(&vpl.position[..3]);
        SstNode {
            position: p,
            v: 1.0,
            intensity: Vec3::from_slice(&vpl.flux[..3]),
            normal: oct_decode(oct_encode(Vec3::from_array(vpl.normal))),
            bbox_min: p,
            bbox_max: p,
            variance: Vec3::ZERO,
        }
    }

    pub fn encode(&self) -> GpuSstNode {
        GpuSstNode {
            position: self.position.to_array(),
            v: self.v,
            intensity: self.intensity.to_array(),
            normal: oct_encode(self.normal),
            bbox_min: self.bbox_min.to_array(),
            var_z: self.variance.z,
            bbox_max: self.bbox_max.to_array(),
            var_xy: pack2x16float(self.variance.x, self.variance.y),
        }
    }

    pub fn decode(g: &GpuSstNode) -> SstNode {
        let (vx, vy) = unpack2x16float(g.var_xy);
        SstNode {
            position: Vec3::from_array(g.position),
            v: g.v,
            intensity: Vec3::from_array(g.intensity),
            normal: oct_decode(g.normal),
            bbox_min: Vec3::from_array(g.bbox_min),
            bbox_max: Vec3::from_array(g.bbox_max),
            variance: Vec3::new(vx, vy, g.var_z),
        }
    }

    /// Standard deviation along the normal (metres).
    pub fn sigma_z(&self) -> f32 {
        self.variance.z.max(0.0).sqrt()
    }

    /// SST paper eq. 3 with a strict sigma bound (see the module doc; sigma_z compared
    /// squared, as on the GPU).
    pub fn usable(&self, v_min: f32, sigma_max: f32) -> bool {
        !self.is_empty() && self.v >= v_min && self.variance.z < sigma_max * sigma_max
    }
}

/// A child's variance (diagonal in its frame of normal `n`) expressed along the axes of the
/// frame (t, b, n2): diag(R Sigma R^T).
fn rotate_variance(var: Vec3, n: Vec3, t2: Vec3, b2: Vec3, n2: Vec3) -> Vec3 {
    if var == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let (t, b) = basis(n);
    let along = |e: Vec3| var.x * t.dot(e).powi(2) + var.y * b.dot(e).powi(2) + var.z * n.dot(e).powi(2);
    Vec3::new(along(t2), along(b2), along(n2))
}

/// Merges two children (both already stored, i.e. quantised) into their parent, and returns
/// the parent as it will be stored (quantised: decode(encode(.))).
pub fn merge(a: &SstNode, b: &SstNode) -> SstNode {
    if a.is_empty() {
        return *b;
    }
    if b.is_empty() {
        return *a;
    }
    let (mut wa, mut wb) = (luminance(a.intensity), luminance(b.intensity));
    if wa + wb <= 0.0 {
        (wa, wb) = (1.0, 1.0);
    }
    let inv = 1.0 / (wa + wb);
    let (ka, kb) = (wa * inv, wb * inv);
    let p = ka * a.position + kb * b.position;
    let ns = ka * a.normal + kb * b.normal;
    let l2 = ns.dot(ns);
    let n = if l2 > 1e-12 {
        ns / l2.sqrt()
    } else if wa >= wb {
        a.normal
    } else {
        b.normal
    };
    // The frame of the normal as stored.
    let n = oct_decode(oct_encode(n));
    let (t, bt) = basis(n);
    let local = |d: Vec3| Vec3::new(d.dot(t), d.dot(bt), d.dot(n));
    let da = local(a.position - p);
    let db = local(b.position - p);
    let var = ka * (rotate_variance(a.variance, a.normal, t, bt, n) + da * da)
        + kb * (rotate_variance(b.variance, b.normal, t, bt, n) + db * db);
    let (vx, vy) = unpack2x16float(pack2x16float(var.x, var.y));
    SstNode {
        position: p,
        v: a.v * b.v * a.normal.dot(b.normal).clamp(0.0, 1.0),
        intensity: a.intensity + b.intensity,
        normal: n,
        bbox_min: a.bbox_min.min(b.bbox_min),
        bbox_max: a.bbox_max.max(b.bbox_max),
        variance: Vec3::new(vx, vy, var.z),
    }
}

/// Builds the tree over VPLs already in sorted order; returns 2 x leaves nodes (node 0 unused,
/// left empty), each as stored (decoded from its GPU encoding).
pub fn build(sorted: &[GpuVpl]) -> Vec<SstNode> {
    build_with_leaves(sorted, leaf_count(sorted.len() as u32) as usize)
}

/// [`build`] with a given leaf count (a power of two >= the VPLs).
pub fn build_with_leaves(sorted: &[GpuVpl], leaves: usize) -> Vec<SstNode> {
    let mut nodes = vec![SstNode::EMPTY; 2 * leaves];
    for i in 0..leaves {
        let leaf = sorted.get(i).map(SstNode::leaf).unwrap_or(SstNode::EMPTY);
        nodes[leaves + i] = leaf;
    }
    // Leaves and merges already hold their stored (quantised) normal and tangent variances.
    for n in (1..leaves).rev() {
        nodes[n] = merge(&nodes[2 * n], &nodes[2 * n + 1]);
    }
    nodes
}

/// The VPLs in the order of their sort keys (the CPU twin of stages 8-9 plus the permutation).
pub fn sort_vpls(vpls: &[GpuVpl]) -> Vec<GpuVpl> {
    let mut bounds = crate::scene::Aabb::EMPTY;
    for v in vpls.iter().filter(|v| v.id != VPL_NONE) {
        bounds.grow(Vec3::from_slice(&v.position[..3]));
    }
    let mut keyed: Vec<(u64, usize)> = vpls
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let k = if v.id == VPL_NONE {
                u64::MAX
            } else {
                super::sst::sort_key(
                    Vec3::from_slice(&v.position[..3]),
                    Vec3::from_array(v.normal),
                    i as u32,
                    &bounds,
                )
            };
            (k, i)
        })
        .collect();
    keyed.sort_unstable();
    keyed.into_iter().map(|(_, i)| vpls[i]).collect()
}

/// The usable flags, one bit per node (word w holds nodes 32w .. 32w+31).
pub fn classify(nodes: &[SstNode], v_min: f32, sigma_max: f32) -> Vec<u32> {
    let mut words = vec![0u32; nodes.len().div_ceil(32)];
    for (i, n) in nodes.iter().enumerate() {
        if i > 0 && n.usable(v_min, sigma_max) {
            words[i / 32] |= 1 << (i % 32);
        }
    }
    words
}

pub fn flag(words: &[u32], node: usize) -> bool {
    words.get(node / 32).is_some_and(|w| w >> (node % 32) & 1 == 1)
}

/// Per-level counts and value distributions of a tree, for the statistics panel.
#[derive(Clone, Debug, Default)]
pub struct TreeStats {
    pub leaves: u32,
    pub levels: u32,
    /// Per level (root first): (non-empty nodes, usable nodes).
    pub per_level: Vec<(u32, u32)>,
    /// v of every non-empty inner node.
    pub v: Vec<f32>,
    /// sigma_z of every non-empty inner node (metres).
    pub sigma_z: Vec<f32>,
    /// Total RGB flux at the root.
    pub root_intensity: Vec3,
}

pub fn stats(nodes: &[SstNode], flags: &[u32]) -> TreeStats {
    let leaves = (nodes.len() / 2) as u32;
    if leaves < 1 {
        return TreeStats::default();
    }
    let levels = level_count(leaves);
    let mut s = TreeStats {
        leaves,
        levels,
        per_level: vec![(0, 0); levels as usize],
        root_intensity: nodes.get(1).map(|n| n.intensity).unwrap_or(Vec3::ZERO),
        ..Default::default()
    };
    for (i, n) in nodes.iter().enumerate().skip(1) {
        if n.is_empty() {
            continue;
        }
        let level = (usize::BITS - 1 - i.leading_zeros()) as usize;
        s.per_level[level].0 += 1;
        s.per_level[level].1 += flag(flags, i) as u32;
        if i < leaves as usize {
            s.v.push(n.v);
            s.sigma_z.push(n.sigma_z());
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vpl(p: Vec3, n: Vec3, flux: Vec3, id: u32) -> GpuVpl {
        GpuVpl {
            position: p.extend(1.0).to_array(),
            normal: n.normalize().to_array(),
            id,
            flux: flux.extend(1.0).to_array(),
        }
    }

    /// xorshift32 in [0, 1).
    fn rng(seed: u32) -> impl FnMut() -> f32 {
        let mut s = seed | 1;
        move || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            (s >> 8) as f32 / (1 << 24) as f32
        }
    }

    fn random_vpls(n: usize, seed: u32) -> Vec<GpuVpl> {
        let mut r = rng(seed);
        (0..n)
            .map(|i| {
                let p = Vec3::new(r() * 10.0 - 5.0, r() * 4.0, r() * 6.0 - 3.0);
                let nrm = Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5);
                let nrm = if nrm.length() < 1e-3 { Vec3::Y } else { nrm };
                vpl(p, nrm, Vec3::new(r(), r(), r()) * 0.01, i as u32)
            })
            .collect()
    }

    #[test]
    fn octahedral_round_trip() {
        let mut r = rng(3);
        for _ in 0..10000 {
            let n = Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5);
            if n.length() < 1e-3 {
                continue;
            }
            let n = n.normalize();
            let d = oct_decode(oct_encode(n));
            assert!((d - n).length() < 1e-4, "{n} -> {d}");
        }
        for n in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z] {
            assert!((oct_decode(oct_encode(n)) - n).length() < 1e-6);
        }
    }

    #[test]
    fn basis_is_orthonormal() {
        let mut r = rng(9);
        for _ in 0..1000 {
            let n = Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize();
            let (t, b) = basis(n);
            assert!((t.length() - 1.0).abs() < 1e-5 && (b.length() - 1.0).abs() < 1e-5);
            assert!(t.dot(b).abs() < 1e-5 && t.dot(n).abs() < 1e-5 && b.dot(n).abs() < 1e-5);
            assert!(t.cross(b).dot(n) > 0.999, "right-handed");
        }
    }

    #[test]
    fn small_trees_by_hand() {
        // N = 1: the root equals the leaf.
        let a = vpl(Vec3::new(1.0, 2.0, 3.0), Vec3::Y, Vec3::splat(1.0), 0);
        let t = build(&[a]);
        assert_eq!(t.len(), 4);
        assert!(t[3].is_empty());
        assert_eq!(t[1], t[2]);
        // N = 2, equal weights, both normals +y: midpoint, variance (d/2)^2 in the plane.
        let b = vpl(Vec3::new(3.0, 2.0, 3.0), Vec3::Y, Vec3::splat(1.0), 1);
        let t = build(&[a, b]);
        assert!((t[1].position - Vec3::new(2.0, 2.0, 3.0)).length() < 1e-6);
        assert!((t[1].variance.x + t[1].variance.y - 1.0).abs() < 1e-3);
        assert!(t[1].variance.z.abs() < 1e-6);
        assert_eq!(t[1].v, 1.0);
        assert_eq!(t[1].intensity, Vec3::splat(2.0));
        assert_eq!(t[1].bbox_min, Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(t[1].bbox_max, Vec3::new(3.0, 2.0, 3.0));
        // Weighted 3:1 -> p at 1/4 of the way, variance 3/4 * 1/4 * d^2 = 0.75.
        let b3 = vpl(Vec3::new(3.0, 2.0, 3.0), Vec3::Y, Vec3::splat(1.0 / 3.0), 1);
        let t = build(&[a, b3]);
        assert!((t[1].position.x - 1.5).abs() < 1e-6);
        assert!((t[1].variance.x + t[1].variance.y - 0.75).abs() < 1e-3);
        // Perpendicular normals: v = 0 (up to the 16-bit normal quantisation).
        let c = vpl(Vec3::new(1.0, 2.0, 4.0), Vec3::X, Vec3::splat(1.0), 1);
        assert!(build(&[a, c])[1].v < 1e-6);
        // Normals at 60 degrees: v = cos 60 = 0.5.
        let d = vpl(
            Vec3::new(1.0, 2.0, 4.0),
            Vec3::new(0.0, 0.5, 3f32.sqrt() / 2.0),
            Vec3::splat(1.0),
            1,
        );
        assert!((build(&[a, d])[1].v - 0.5).abs() < 1e-4);
        // N = 3: padding leaf 7 empty, node 3 = leaf 6.
        let t = build(&[a, b, d]);
        assert_eq!(t.len(), 8);
        assert!(t[7].is_empty());
        assert_eq!(t[3], t[6]);
        // Zero-flux VPLs still merge (equal weights).
        let z1 = vpl(Vec3::ZERO, Vec3::Y, Vec3::ZERO, 0);
        let z2 = vpl(Vec3::X, Vec3::Y, Vec3::ZERO, 1);
        let t = build(&[z1, z2]);
        assert!((t[1].position - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-6);
        assert!(!t[1].is_empty());
    }

    /// Intensity is the sum of the children, bounds contain the children, v never grows
    /// towards the root, and the variance's trace is the weighted mean squared distance of the
    /// cluster's leaves from its position.
    fn check_invariants(t: &[SstNode]) {
        let leaves = t.len() / 2;
        for n in 1..leaves {
            let (a, b, p) = (&t[2 * n], &t[2 * n + 1], &t[n]);
            if a.is_empty() && b.is_empty() {
                assert!(p.is_empty());
                continue;
            }
            let sum = a.intensity + b.intensity;
            assert!((p.intensity - sum).abs().max_element() <= 1e-6 * sum.max_element().max(1e-30));
            for c in [a, b].into_iter().filter(|c| !c.is_empty()) {
                assert!(p.bbox_min.cmple(c.bbox_min).all() && p.bbox_max.cmpge(c.bbox_max).all());
                assert!(p.v <= c.v, "v grows at node {n}");
                assert!(
                    p.bbox_min.cmple(p.position + 1e-4).all() && p.bbox_max.cmpge(p.position - 1e-4).all()
                );
            }
            assert!((p.normal.length() - 1.0).abs() < 1e-5);
            assert!(p.variance.min_element() >= 0.0);
        }
        // Trace against brute force for a sample of nodes.
        for n in (1..leaves).step_by(leaves / 16 + 1) {
            let p = &t[n];
            if p.is_empty() {
                continue;
            }
            let depth = leaves.trailing_zeros() - n.ilog2();
            let (lo, span) = (n << depth, 1usize << depth);
            let (mut sw, mut sd) = (0.0f64, 0.0f64);
            let mut leaves_used = Vec::new();
            for l in &t[lo..lo + span] {
                if !l.is_empty() {
                    leaves_used.push(l);
                }
            }
            let total: f32 = leaves_used.iter().map(|l| luminance(l.intensity)).sum();
            for l in &leaves_used {
                let w = if total > 0.0 {
                    luminance(l.intensity) as f64
                } else {
                    1.0
                };
                sw += w;
                sd += w * (l.position - p.position).length_squared() as f64;
            }
            let want = sd / sw;
            let got = (p.variance.x + p.variance.y + p.variance.z) as f64;
            assert!(
                (got - want).abs() <= 2e-3 * want + 1e-6,
                "node {n}: trace {got} vs brute force {want}"
            );
        }
    }

    #[test]
    fn random_trees_keep_the_invariants() {
        for (n, seed) in [(1, 1), (2, 2), (3, 3), (1000, 4), (4096, 5)] {
            let sorted = sort_vpls(&random_vpls(n, seed));
            let t = build(&sorted);
            assert_eq!(t.len(), 2 * leaf_count(n as u32) as usize);
            check_invariants(&t);
            let root_flux: Vec3 = sorted.iter().map(|v| Vec3::from_slice(&v.flux[..3])).sum();
            assert!((t[1].intensity - root_flux).abs().max_element() < 1e-4 * root_flux.max_element());
        }
    }

    #[test]
    fn a_flat_floor_is_usable_at_every_level() {
        let mut r = rng(11);
        let vpls: Vec<GpuVpl> = (0..1024)
            .map(|i| vpl(Vec3::new(r() * 8.0, 0.5, r() * 8.0), Vec3::Y, Vec3::splat(r()), i))
            .collect();
        let t = build(&sort_vpls(&vpls));
        check_invariants(&t);
        let flags = classify(&t, 0.7, 0.3);
        for (i, n) in t.iter().enumerate().skip(1) {
            assert!(n.variance.z < 1e-6, "node {i} sigma_z^2 = {}", n.variance.z);
            assert!(n.v > 0.9999);
            assert!(flag(&flags, i));
        }
        // The root's in-plane spread: uniform on 8 m -> variance 64/12 per axis (+-10%).
        let s = t[1].variance.x + t[1].variance.y;
        assert!((s - 2.0 * 64.0 / 12.0).abs() < 0.1 * s, "{s}");
    }

    #[test]
    fn a_corner_is_not_flat() {
        // A floor and a wall meeting at a right angle: the root mixes both, so v = 0 and
        // (with the child variance rotated into the parent frame) sigma_z is large.
        let mut r = rng(12);
        let mut vpls = Vec::new();
        for i in 0..512 {
            vpls.push(vpl(Vec3::new(r() * 4.0, 0.0, r() * 4.0), Vec3::Y, Vec3::ONE, i));
            vpls.push(vpl(
                Vec3::new(r() * 4.0, r() * 4.0, 0.0),
                Vec3::Z,
                Vec3::ONE,
                512 + i,
            ));
        }
        let t = build(&sort_vpls(&vpls));
        check_invariants(&t);
        assert!(t[1].v < 1e-6);
        assert!(t[1].sigma_z() > 0.5, "{}", t[1].sigma_z());
        let flags = classify(&t, 0.7, 0.3);
        assert!(!flag(&flags, 1));
        let s = stats(&t, &flags);
        assert_eq!(s.levels, 11);
        assert_eq!(s.per_level[10], (1024, 1024));
        assert_eq!(s.per_level[0], (1, 0));
        assert_eq!(s.v.len(), 1023);
    }
}

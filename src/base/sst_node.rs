//! The light-tree node as the GPU stores it and the CPU reads it (thesis 4.2.2, SST paper
//! 3.2): the decoded [`SstNode`], its 64-byte encoding, the usable-flag words and the merge
//! of two children (eqs. 4.1-4.3). `reference::sst_tree` documents the build and is its twin;
//! the renderer (`sst_build`), the app and the harness read nodes through here.

use glam::Vec3;

use crate::base::gpu_layout::{GpuSstNode, GpuVpl, VPL_NONE};

/// Rec. 709 luminance, the merge weight (twin: `luminance` in `common/color.wgsl`).
pub use crate::base::display::luminance;

/// Leaves of the tree for `count` VPLs: a power of two, at least 2.
pub fn leaf_count(count: u32) -> u32 {
    count.max(2).next_power_of_two()
}

/// Levels of a tree with `leaves` leaves (root = level 0).
pub fn level_count(leaves: u32) -> u32 {
    leaves.trailing_zeros() + 1
}

/// Which light tree the frame builds over the sorted VPL keys (`tree.kind`, `render --tree`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TreeKind {
    /// The thesis's perfect binary tree: leaves padded to a power of two, children 2i, 2i + 1.
    #[default]
    Perfect,
    /// The SST paper's binary radix tree (LBVH, Karras 2012): split where the keys' highest
    /// differing bit changes; children by explicit links.
    Lbvh,
}

impl TreeKind {
    pub const ALL: [TreeKind; 2] = [TreeKind::Perfect, TreeKind::Lbvh];

    /// The CLI / settings spelling.
    pub fn name(self) -> &'static str {
        match self {
            TreeKind::Perfect => "perfect",
            TreeKind::Lbvh => "lbvh",
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            TreeKind::Perfect => "perfect binary tree (thesis)",
            TreeKind::Lbvh => "radix tree / LBVH (SST paper)",
        }
    }

    pub fn parse(s: &str) -> Result<TreeKind, String> {
        TreeKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| format!("unknown tree '{s}' (perfect, lbvh)"))
    }
}

/// A light tree's shape in the samplers' numbering, shared by both trees: the root is node 1
/// and leaf k (the k-th VPL in key order) is node `leaves + k`, so a node is a leaf iff its
/// id >= `leaves`. The perfect tree's inner node i has children 2i and 2i + 1; the radix
/// tree's inner node i (Karras's internal node i - 1) has `links[i]` = (left, right, first
/// leaf, last leaf). Twin of `common/tree_links.wgsl`.
#[derive(Clone, Copy, Debug)]
pub struct Topology<'a> {
    pub leaves: u32,
    pub links: Option<&'a [[u32; 4]]>,
}

impl<'a> Topology<'a> {
    /// The perfect tree whose nodes (2 x leaves, node 0 unused) are `nodes`.
    pub fn perfect_of(nodes: &[SstNode]) -> Topology<'static> {
        Topology {
            leaves: (nodes.len() / 2) as u32,
            links: None,
        }
    }

    /// The frame's tree of `leaves` leaves: the radix tree when `links` (as
    /// `Renderer::read_tree_links` returns them) are given, else the perfect tree.
    pub fn of(leaves: u32, links: &'a [[u32; 4]]) -> Self {
        match links.is_empty() {
            true => Topology {
                leaves: leaves.max(1),
                links: None,
            },
            false => Topology::radix(links),
        }
    }

    /// The radix tree of `links.len()` leaves (`links[0]` unused).
    pub fn radix(links: &'a [[u32; 4]]) -> Self {
        Topology {
            leaves: links.len().max(1) as u32,
            links: Some(links),
        }
    }

    pub fn is_leaf(&self, i: u32) -> bool {
        i >= self.leaves
    }

    /// The two children of inner node `i`.
    pub fn children(&self, i: u32) -> (u32, u32) {
        match self.links {
            Some(l) => (l[i as usize][0], l[i as usize][1]),
            None => (2 * i, 2 * i + 1),
        }
    }

    /// The leaves (indices, not node ids) node `i` covers: first ..= last.
    pub fn leaf_range(&self, i: u32) -> (u32, u32) {
        if self.is_leaf(i) {
            return (i - self.leaves, i - self.leaves);
        }
        match self.links {
            Some(l) => (l[i as usize][2], l[i as usize][3]),
            None => {
                let depth = self.leaves.trailing_zeros() - i.ilog2();
                let first = (i << depth) - self.leaves;
                (first, first + (1 << depth) - 1)
            }
        }
    }

    /// Whether `a` is `b` or one of its ancestors (their leaf ranges nest; a radix tree node's
    /// range is never its child's).
    pub fn contains(&self, a: u32, b: u32) -> bool {
        let (fa, la) = self.leaf_range(a);
        let (fb, lb) = self.leaf_range(b);
        fa <= fb && lb <= la && (a == b || !self.is_leaf(a))
    }

    /// Depth of node `i` (root 0): the perfect tree's level; for the radix tree, walked down
    /// from the root along the leaf ranges.
    pub fn depth(&self, i: u32) -> u32 {
        if self.links.is_none() {
            return i.max(1).ilog2();
        }
        let (f, l) = self.leaf_range(i);
        let (mut node, mut d) = (1u32, 0u32);
        while node != i && !self.is_leaf(node) {
            let (c0, c1) = self.children(node);
            node = if self.leaf_range(c0).1 >= l && self.leaf_range(c0).0 <= f {
                c0
            } else {
                c1
            };
            d += 1;
        }
        d
    }
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

/// The usable flag of `node` in the flag words (one bit per node, word w = nodes 32w..).
pub fn flag(words: &[u32], node: usize) -> bool {
    words.get(node / 32).is_some_and(|w| w >> (node % 32) & 1 == 1)
}

/// Per-level counts and value distributions of a tree, for the statistics panel.
#[derive(Clone, Debug, Default)]
pub struct TreeStats {
    pub leaves: u32,
    /// Non-empty leaves (the frame's VPLs).
    pub valid_leaves: u32,
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
    stats_on(nodes, flags, Topology::perfect_of(nodes))
}

/// [`stats`] of either tree: per depth from the root (the radix tree's leaves lie at many
/// depths; `leaves` counts its VPLs' leaves, `levels` its depth + 1).
pub fn stats_on(nodes: &[SstNode], flags: &[u32], topo: Topology<'_>) -> TreeStats {
    let leaves = topo.leaves;
    if leaves < 1 || nodes.len() < 2 {
        return TreeStats::default();
    }
    let mut s = TreeStats {
        leaves,
        root_intensity: nodes.get(1).map(|n| n.intensity).unwrap_or(Vec3::ZERO),
        ..Default::default()
    };
    let mut stack = vec![(1u32, 0usize)];
    while let Some((i, depth)) = stack.pop() {
        let Some(n) = nodes.get(i as usize) else { continue };
        if s.per_level.len() <= depth {
            s.per_level.resize(depth + 1, (0, 0));
        }
        if !topo.is_leaf(i) {
            let (c0, c1) = topo.children(i);
            stack.push((c1, depth + 1));
            stack.push((c0, depth + 1));
        }
        if n.is_empty() {
            continue;
        }
        s.per_level[depth].0 += 1;
        s.per_level[depth].1 += flag(flags, i as usize) as u32;
        if topo.is_leaf(i) {
            s.valid_leaves += 1;
        } else {
            s.v.push(n.v);
            s.sigma_z.push(n.sigma_z());
        }
    }
    s.levels = s.per_level.len() as u32;
    s
}

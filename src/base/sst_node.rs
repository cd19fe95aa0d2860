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

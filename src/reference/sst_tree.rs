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

use crate::base::gpu_layout::{GpuVpl, VPL_NONE};
pub use crate::base::sst_node::{
    SstNode, TreeStats, basis, flag, leaf_count, level_count, luminance, merge, oct_decode, oct_encode,
    pack2x16float, stats, unpack2x16float,
};

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
    sorted_keys(vpls).into_iter().map(|(_, i)| vpls[i]).collect()
}

/// Each VPL's 64-bit sort key (`reference::sst::sort_key` in the valid VPLs' bounds, its
/// index as the id; empty VPLs `u64::MAX`) and index, in key order.
pub fn sorted_keys(vpls: &[GpuVpl]) -> Vec<(u64, usize)> {
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
    keyed
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

//! CPU reference of the LBVH / binary radix tree (Karras 2012, "Maximizing Parallelism in the
//! Construction of BVHs, Octrees, and k-d Trees", section 4; the SST paper's section 3.3
//! builds its light tree this way) over the sorted 64-bit VPL keys: the first step of issue 23's
//! tree choice (`--tree perfect|lbvh`). The GPU build and the samplers on it come next.
//!
//! Layout (Karras): n leaves 0..n (the sorted keys) and n - 1 internal nodes 0..n-1; internal
//! node 0 is the root. Internal node i covers a contiguous key range that starts or ends at
//! key i; its children split that range where the keys' highest differing bit changes. Equal
//! keys are told apart by their indices (Karras's "augmenting each key with its index"), so
//! duplicates make a valid tree too.
//!
//! [`build`] is Karras's construction, one independent step per internal node (the parallel
//! algorithm run serially). [`build_top_down`] is the radix tree's definition: split every
//! range at its longest common prefix. The tests hold the first to the second on random keys,
//! with duplicates.

use crate::base::gpu_layout::{GpuVpl, VPL_NONE};
use crate::base::sst_node::{SstNode, merge};

/// A child of an internal node.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Child {
    Leaf(u32),
    Internal(u32),
}

/// An internal node: its children and the leaf range [first, last] it covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Internal {
    pub left: Child,
    pub right: Child,
    pub first: u32,
    pub last: u32,
}

/// The length of the common prefix of keys i and j (`None` when j is outside), Karras's
/// delta: with equal keys, 64 + the common prefix of the indices.
pub fn delta(keys: &[u64], i: i64, j: i64) -> Option<u32> {
    if j < 0 || j >= keys.len() as i64 {
        return None;
    }
    let (a, b) = (keys[i as usize], keys[j as usize]);
    Some(if a == b {
        64 + ((i as u32) ^ (j as u32)).leading_zeros()
    } else {
        (a ^ b).leading_zeros()
    })
}

/// Karras's construction (his figure 4): for each internal node i, its direction, the other
/// end of its range by exponential then binary search, and the split by binary search.
/// `keys` sorted ascending, at least 2.
pub fn build(keys: &[u64]) -> Vec<Internal> {
    let n = keys.len() as i64;
    let d_of = |i: i64, j: i64| delta(keys, i, j).map_or(-1, |v| v as i64);
    (0..n - 1)
        .map(|i| {
            // Direction of the range: towards the neighbour with the longer common prefix.
            let d: i64 = if d_of(i, i + 1) - d_of(i, i - 1) >= 0 {
                1
            } else {
                -1
            };
            let d_min = d_of(i, i - d);
            // Upper bound of the range's length, then its exact other end.
            let mut l_max: i64 = 2;
            while d_of(i, i + l_max * d) > d_min {
                l_max *= 2;
            }
            let mut l: i64 = 0;
            let mut t = l_max / 2;
            while t >= 1 {
                if d_of(i, i + (l + t) * d) > d_min {
                    l += t;
                }
                t /= 2;
            }
            let j = i + l * d;
            // The split: the last key (from i) sharing more than the node's prefix.
            let d_node = d_of(i, j);
            let mut s: i64 = 0;
            let mut div: i64 = 2;
            loop {
                let t = (l + div - 1) / div;
                if d_of(i, i + (s + t) * d) > d_node {
                    s += t;
                }
                if t <= 1 {
                    break;
                }
                div *= 2;
            }
            let gamma = i + s * d + d.min(0);
            let (first, last) = (i.min(j), i.max(j));
            Internal {
                left: if first == gamma {
                    Child::Leaf(gamma as u32)
                } else {
                    Child::Internal(gamma as u32)
                },
                right: if last == gamma + 1 {
                    Child::Leaf(gamma as u32 + 1)
                } else {
                    Child::Internal(gamma as u32 + 1)
                },
                first: first as u32,
                last: last as u32,
            }
        })
        .collect()
}

/// The binary radix tree by its definition, top down: each range [first, last] splits after
/// the last key that shares more than the range's common prefix with its first key. Returns
/// (range, split) per internal node, root first.
pub fn build_top_down(keys: &[u64]) -> Vec<((u32, u32), u32)> {
    let mut out = Vec::new();
    let mut stack = vec![(0i64, keys.len() as i64 - 1)];
    while let Some((a, b)) = stack.pop() {
        if a >= b {
            continue;
        }
        let common = delta(keys, a, b).unwrap_or(0);
        // The largest index in [a, b) whose prefix with key a is longer than `common`.
        let mut split = a;
        for k in a..b {
            if delta(keys, a, k).unwrap_or(0) > common {
                split = k;
            }
        }
        out.push(((a as u32, b as u32), split as u32));
        stack.push((a, split));
        stack.push((split + 1, b));
    }
    out
}

/// Each internal node's parent (root: None) and each leaf's, from [`build`]'s children.
pub fn parents(nodes: &[Internal]) -> (Vec<Option<u32>>, Vec<Option<u32>>) {
    let mut internal = vec![None; nodes.len()];
    let mut leaf = vec![None; nodes.len() + 1];
    for (i, n) in nodes.iter().enumerate() {
        for c in [n.left, n.right] {
            match c {
                Child::Leaf(k) => leaf[k as usize] = Some(i as u32),
                Child::Internal(k) => internal[k as usize] = Some(i as u32),
            }
        }
    }
    (internal, leaf)
}

/// Depth of every leaf (root's children at depth 1).
pub fn leaf_depths(nodes: &[Internal]) -> Vec<u32> {
    let mut depth = vec![0u32; nodes.len() + 1];
    let mut stack = vec![(Child::Internal(0), 0u32)];
    while let Some((c, d)) = stack.pop() {
        match c {
            Child::Leaf(k) => depth[k as usize] = d,
            Child::Internal(k) => {
                let n = nodes[k as usize];
                stack.push((n.left, d + 1));
                stack.push((n.right, d + 1));
            }
        }
    }
    depth
}

/// The valid VPLs (not `VPL_NONE`) sorted by their 64-bit keys, with the keys
/// (`sst_tree::sorted_keys`, the GPU's stage 8-9 order, empty VPLs left out).
pub fn sorted_keys(vpls: &[GpuVpl]) -> (Vec<u64>, Vec<GpuVpl>) {
    super::sst_tree::sorted_keys(vpls)
        .into_iter()
        .filter(|&(_, i)| vpls[i].id != VPL_NONE)
        .map(|(k, i)| (k, vpls[i]))
        .unzip()
}

/// The SST node data of every internal node, merged bottom-up from the leaves' (the same
/// merge, eqs. 4.1-4.3, as the perfect tree's).
pub fn node_data(nodes: &[Internal], leaves: &[SstNode]) -> Vec<SstNode> {
    let mut data = vec![SstNode::EMPTY; nodes.len()];
    if nodes.is_empty() {
        return data;
    }
    let mut done = vec![false; nodes.len()];
    // Post-order without recursion: a node is merged once both children are done.
    let mut stack = vec![0u32];
    while let Some(&i) = stack.last() {
        let n = nodes[i as usize];
        let pending: Vec<u32> = [n.left, n.right]
            .iter()
            .filter_map(|c| match c {
                Child::Internal(k) if !done[*k as usize] => Some(*k),
                _ => None,
            })
            .collect();
        if pending.is_empty() {
            let get = |c: Child| match c {
                Child::Leaf(k) => leaves[k as usize],
                Child::Internal(k) => data[k as usize],
            };
            data[i as usize] = merge(&get(n.left), &get(n.right));
            done[i as usize] = true;
            stack.pop();
        } else {
            stack.extend(pending);
        }
    }
    data
}

/// The radix tree in the samplers' numbering (`base::sst_node::Topology`): nodes (2n; node 0
/// unused, Karras's internal node i at i + 1, leaf k at n + k) and links (n; links[i + 1] =
/// (left, right, first leaf, last leaf) of internal node i). `leaves`: the n leaves' data in
/// key order. Twin of what `lbvh.wgsl` writes into the frame's tree.
pub fn sampler_layout(nodes: &[Internal], leaves: &[SstNode]) -> (Vec<SstNode>, Vec<[u32; 4]>) {
    let n = leaves.len().max(1) as u32;
    let slot = |c: Child| match c {
        Child::Leaf(k) => n + k,
        Child::Internal(k) => k + 1,
    };
    let data = node_data(nodes, leaves);
    let mut out = vec![SstNode::EMPTY; 2 * n as usize];
    let mut links = vec![[0u32; 4]; n as usize];
    for (i, nd) in nodes.iter().enumerate() {
        out[i + 1] = data[i];
        links[i + 1] = [slot(nd.left), slot(nd.right), nd.first, nd.last];
    }
    for (k, l) in leaves.iter().enumerate() {
        out[n as usize + k] = *l;
    }
    (out, links)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn random_keys(n: usize, seed: u64, dup_every: usize, bits: u32) -> Vec<u64> {
        let mut s = seed;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        let mut keys: Vec<u64> = Vec::with_capacity(n);
        for i in 0..n {
            if dup_every > 0 && i % dup_every == 1 {
                keys.push(keys[i - 1]);
            } else {
                keys.push(next() >> (64 - bits));
            }
        }
        keys.sort_unstable();
        keys
    }

    fn check(keys: &[u64]) {
        let n = keys.len();
        let nodes = build(keys);
        assert_eq!(nodes.len(), n - 1);
        // The same ranges and splits as the definition.
        let want: HashMap<(u32, u32), u32> = build_top_down(keys).into_iter().collect();
        assert_eq!(want.len(), n - 1);
        for (i, node) in nodes.iter().enumerate() {
            let split = match node.left {
                Child::Leaf(k) | Child::Internal(k) => k,
            };
            // A left child ends at the split: a leaf there, or the internal node whose range
            // ends there.
            assert_eq!(
                want.get(&(node.first, node.last)),
                Some(&split),
                "node {i} {node:?}"
            );
            // Karras's node i has i at one end of its range.
            assert!(
                node.first == i as u32 || node.last == i as u32,
                "node {i} {node:?}"
            );
        }
        assert_eq!((nodes[0].first, nodes[0].last), (0, n as u32 - 1));
        // Every node but the root has one parent; every leaf one.
        let (ip, lp) = parents(&nodes);
        assert!(ip[0].is_none() && ip[1..].iter().all(Option::is_some));
        assert!(lp.iter().all(Option::is_some));
        // Children's ranges tile the parent's.
        for node in &nodes {
            let range = |c: Child| match c {
                Child::Leaf(k) => (k, k),
                Child::Internal(k) => (nodes[k as usize].first, nodes[k as usize].last),
            };
            let (a, b) = (range(node.left), range(node.right));
            assert_eq!((a.0, a.1 + 1, b.1), (node.first, b.0, node.last));
        }
    }

    #[test]
    fn karras_construction_equals_the_radix_tree_definition() {
        for (n, seed) in [(2, 1), (3, 2), (17, 3), (100, 4), (1000, 5), (4097, 6)] {
            check(&random_keys(n, seed, 0, 64));
        }
    }

    #[test]
    fn duplicate_keys_make_a_valid_tree() {
        // Every other key repeated, and few distinct keys (many runs of equal keys).
        check(&random_keys(513, 7, 2, 64));
        check(&random_keys(300, 8, 0, 3));
        check(&vec![42u64; 64]);
    }

    #[test]
    fn node_data_sums_the_flux_and_bounds_of_the_leaves() {
        let vpls: Vec<GpuVpl> = (0..300)
            .map(|i| {
                let f = i as f32;
                GpuVpl {
                    position: [
                        (f * 0.37).sin() * 3.0,
                        (f * 0.11).cos(),
                        (f * 0.07).sin() * 2.0,
                        1.0,
                    ],
                    normal: if i % 3 == 0 {
                        [0.0, 1.0, 0.0]
                    } else {
                        [1.0, 0.0, 0.0]
                    },
                    id: if i % 50 == 49 { VPL_NONE } else { i },
                    flux: [1.0 + f * 0.01, 0.5, 0.25, 1.0],
                }
            })
            .collect();
        let (keys, sorted) = sorted_keys(&vpls);
        assert_eq!(sorted.len(), 294);
        assert!(keys.windows(2).all(|w| w[0] < w[1]));
        let leaves: Vec<SstNode> = sorted.iter().map(SstNode::leaf).collect();
        let tree = build(&keys);
        let data = node_data(&tree, &leaves);
        let perfect = crate::reference::sst_tree::build(&sorted);
        let (a, b) = (data[0], perfect[1]);
        assert!((a.intensity - b.intensity).abs().max_element() < 1e-3 * b.intensity.max_element());
        assert!((a.bbox_min - b.bbox_min).abs().max_element() < 1e-5);
        assert!((a.bbox_max - b.bbox_max).abs().max_element() < 1e-5);
        assert!(
            a.position.distance(b.position) < 1e-3,
            "{} {}",
            a.position,
            b.position
        );
        // Each internal node's box is the union of its children's.
        for (i, n) in tree.iter().enumerate() {
            let get = |c: Child| match c {
                Child::Leaf(k) => leaves[k as usize],
                Child::Internal(k) => data[k as usize],
            };
            let (l, r) = (get(n.left), get(n.right));
            assert_eq!(data[i].bbox_min, l.bbox_min.min(r.bbox_min));
            assert_eq!(data[i].bbox_max, l.bbox_max.max(r.bbox_max));
        }
    }

    #[test]
    fn equal_keys_form_a_balanced_subtree_by_their_indices() {
        // 2^k equal keys: the indices' prefixes split them as a perfect tree.
        let nodes = build(&[7u64; 16]);
        assert!(leaf_depths(&nodes).iter().all(|&d| d == 4));
    }
}

// The binary radix tree over the sorted 64-bit VPL keys (Karras 2012, "Maximizing Parallelism
// in the Construction of BVHs, Octrees, and k-d Trees", section 4 and figure 4; the SST
// paper's section 3.3): one thread per internal node finds its range's direction, its other
// end (exponential, then binary search) and its split (binary search) from the keys' common
// prefixes. Equal keys compare by their indices. Internal node 0 is the root; a child with
// bit 31 set is a leaf (a sorted key's position). CPU twin: reference::lbvh::build.
// `node_data`: the SST node data bottom-up (as sst_build.wgsl: one thread per leaf, the second
// arrival at a node merges its two children and walks on). CPU twin: reference::lbvh::node_data.
#include "common/color.wgsl"
#include "common/vpl.wgsl"
#include "common/sst_node.wgsl"

// Twin: `GpuLbvhParams` in src/renderer/passes/lbvh.rs.
struct LbvhParams {
    count: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(0) @binding(0) var<uniform> params: LbvhParams;
// (key hi, key lo, VPL index, 0) sorted ascending (sst_sort's output).
@group(0) @binding(1) var<storage, read> keys: array<vec4<u32>>;
// left, right (bit 31: leaf), first, last leaf of the range.
@group(0) @binding(2) var<storage, read_write> topology: array<vec4<u32>>;
// Parents: internal nodes 0 .. n-1 (the root's NONE), then leaves at n - 1 + k.
@group(0) @binding(3) var<storage, read_write> parents: array<u32>;
@group(0) @binding(4) var<storage, read> vpls: array<Vpl>;
// SST nodes (16 words each): internal node i at i, leaf k at n - 1 + k.
@group(0) @binding(5) var<storage, read_write> nodes: array<atomic<u32>>;
@group(0) @binding(6) var<storage, read_write> counters: array<atomic<u32>>;

#include "common/sst_merge.wgsl"

const LEAF_BIT: u32 = 0x80000000u;
const NONE: u32 = 0xffffffffu;

// The common prefix length of keys i and j (-1 when j is outside), the indices' when the keys
// are equal: Karras's delta.
fn delta(i: i32, j: i32) -> i32 {
    if j < 0 || j >= i32(params.count) {
        return -1;
    }
    let x = keys[i].xy ^ keys[j].xy;
    if x.x != 0u {
        return i32(countLeadingZeros(x.x));
    }
    if x.y != 0u {
        return 32 + i32(countLeadingZeros(x.y));
    }
    return 64 + i32(countLeadingZeros(u32(i) ^ u32(j)));
}

@compute @workgroup_size(64, 1, 1)
fn build(@builtin(global_invocation_id) gid: vec3<u32>) {
    let n = i32(params.count);
    let i = i32(gid.x);
    if i >= n - 1 {
        return;
    }
    let d = select(-1, 1, delta(i, i + 1) - delta(i, i - 1) >= 0);
    let d_min = delta(i, i - d);
    var l_max = 2;
    while delta(i, i + l_max * d) > d_min {
        l_max *= 2;
    }
    var l = 0;
    var t = l_max / 2;
    while t >= 1 {
        if delta(i, i + (l + t) * d) > d_min {
            l += t;
        }
        t /= 2;
    }
    let j = i + l * d;
    let d_node = delta(i, j);
    var s = 0;
    var div = 2;
    loop {
        let step = (l + div - 1) / div;
        if delta(i, i + (s + step) * d) > d_node {
            s += step;
        }
        if step <= 1 {
            break;
        }
        div *= 2;
    }
    let gamma = i + s * d + min(d, 0);
    let first = min(i, j);
    let last = max(i, j);
    var left = u32(gamma);
    var right = u32(gamma + 1);
    if first == gamma {
        left |= LEAF_BIT;
        parents[u32(n - 1 + gamma)] = u32(i);
    } else {
        parents[u32(gamma)] = u32(i);
    }
    if last == gamma + 1 {
        right |= LEAF_BIT;
        parents[u32(n + gamma)] = u32(i);
    } else {
        parents[u32(gamma + 1)] = u32(i);
    }
    topology[i] = vec4<u32>(left, right, u32(first), u32(last));
    if i == 0 {
        parents[0] = NONE;
    }
}

// Where node data of a stored child lives.
fn child_slot(c: u32) -> u32 {
    if (c & LEAF_BIT) != 0u {
        return params.count - 1u + (c & ~LEAF_BIT);
    }
    return c;
}

@compute @workgroup_size(64, 1, 1)
fn node_data(@builtin(global_invocation_id) gid: vec3<u32>) {
    let n = params.count;
    let k = gid.x;
    if k >= n {
        return;
    }
    // Leaf k: the k-th VPL in key order (empty VPLs and the sort's padding: empty leaves).
    var leaf = empty_node();
    let vi = keys[k].z;
    if vi < n && vpls[vi].id != VPL_NONE {
        let v = vpls[vi];
        let code = oct_encode(v.normal);
        let p = v.position.xyz;
        leaf = Node(p, 1.0, v.flux.rgb, oct_decode(code), code, p, p, vec3<f32>(0.0), 0u);
    }
    let slot = n - 1u + k;
    store_node(slot, leaf);
    if n < 2u {
        return;
    }
    var node = parents[slot];
    loop {
        // First arrival: the other child is not done yet; leave the merge to the second.
        if atomicAdd(&counters[node], 1u) == 0u {
            return;
        }
        let t = topology[node];
        store_node(node, merge(load_node(child_slot(t.x)), load_node(child_slot(t.y))));
        if node == 0u {
            return;
        }
        node = parents[node];
    }
}

// The binary radix tree over the sorted 64-bit VPL keys (Karras 2012, "Maximizing Parallelism
// in the Construction of BVHs, Octrees, and k-d Trees", section 4 and figure 4; the SST
// paper's section 3.3): one thread per internal node finds its range's direction, its other
// end (exponential, then binary search) and its split (binary search) from the keys' common
// prefixes. Equal keys compare by their indices. CPU twin: reference::lbvh::build.
// Nodes are numbered as the samplers read both trees (common/tree_links.wgsl): Karras's
// internal node i is node i + 1 (the root: 1), leaf k is node n + k.
// `node_data`: the SST node data bottom-up (as sst_build.wgsl: one thread per leaf, the second
// arrival at a node merges its two children and walks on), and the VPLs in leaf order. CPU
// twin: reference::lbvh::sampler_layout.
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
// Per inner node (1 .. n-1; 0 unused): left, right, first, last leaf of the range.
@group(0) @binding(2) var<storage, read_write> links: array<vec4<u32>>;
// Per node (1 .. 2n-1): its parent (the root's NONE).
@group(0) @binding(3) var<storage, read_write> parents: array<u32>;
@group(0) @binding(4) var<storage, read> vpls: array<Vpl>;
// SST nodes (16 words each), the frame's tree: node i at i.
@group(0) @binding(5) var<storage, read_write> nodes: array<atomic<u32>>;
// Per inner node: arrivals.
@group(0) @binding(6) var<storage, read_write> counters: array<atomic<u32>>;
// The VPLs in leaf order (empty ones and padding: VPL_NONE).
@group(0) @binding(7) var<storage, read_write> sorted_vpls: array<Vpl>;

#include "common/sst_merge.wgsl"

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
    // Children: leaf gamma (node n + gamma) when the range starts there, else internal gamma
    // (node gamma + 1); likewise gamma + 1.
    let left = select(u32(gamma + 1), u32(n + gamma), first == gamma);
    let right = select(u32(gamma + 2), u32(n + gamma + 1), last == gamma + 1);
    let me = u32(i + 1);
    parents[left] = me;
    parents[right] = me;
    links[me] = vec4<u32>(left, right, u32(first), u32(last));
    if i == 0 {
        parents[1] = NONE;
    }
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
    var vpl = Vpl(vec4<f32>(0.0), vec3<f32>(0.0, 0.0, 1.0), VPL_NONE, vec4<f32>(0.0));
    let vi = keys[k].z;
    if vi < n {
        vpl = vpls[vi];
    }
    sorted_vpls[k] = vpl;
    if vpl.id != VPL_NONE {
        let code = oct_encode(vpl.normal);
        let p = vpl.position.xyz;
        leaf = Node(p, 1.0, vpl.flux.rgb, oct_decode(code), code, p, p, vec3<f32>(0.0), 0u);
    }
    let slot = n + k;
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
        let t = links[node];
        store_node(node, merge(load_node(t.x), load_node(t.y)));
        if node == 1u {
            return;
        }
        node = parents[node];
    }
}

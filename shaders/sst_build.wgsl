// SST stage 10 (thesis 4.2.2, SST paper 3.2-3.3): the perfect binary tree over the sorted
// VPLs. One thread per leaf pair writes both leaves (and the permuted VPLs), merges them
// into their parent and walks up; a per-node atomic counter lets only the second arrival
// at a node merge its two children and continue. CPU twin: src/reference/sst_tree.rs
// (which documents the merge, eqs. 4.1-4.3, with the child variance rotated into the
// parent's frame).
//
// Node data is written and read through atomics (16 words per node): WGSL has no
// device-scope fence, and atomics are what makes one thread's merged node visible to the
// thread that arrives second at the parent (coherent at device scope).
#include "common/color.wgsl"
#include "common/vpl.wgsl"
#include "common/sst_node.wgsl"

struct TreeParams {
    count: u32,  // VPLs (sorted pairs)
    leaves: u32, // power of two >= max(count, 2)
    _pad0: u32,
    _pad1: u32,
};

@group(0) @binding(0) var<uniform> tp: TreeParams;
@group(0) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(2) var<storage, read> keys: array<vec4<u32>>;
@group(0) @binding(3) var<storage, read_write> nodes: array<atomic<u32>>;
@group(0) @binding(4) var<storage, read_write> counters: array<atomic<u32>>;
@group(0) @binding(5) var<storage, read_write> sorted_vpls: array<Vpl>;

#include "common/sst_merge.wgsl"

// Leaf i: the i-th VPL in key order (or padding); also writes the permuted VPL array.
fn make_leaf(i: u32) -> Node {
    var vpl = Vpl(vec4<f32>(0.0), vec3<f32>(0.0, 0.0, 1.0), VPL_NONE, vec4<f32>(0.0));
    // Empty VPLs and the sort's padding share the largest key, so among the first `count`
    // pairs there may be padding indices (>= count): those are padding leaves too.
    if i < tp.count && keys[i].z < tp.count {
        vpl = vpls[keys[i].z];
    }
    sorted_vpls[i] = vpl;
    if vpl.id == VPL_NONE {
        return empty_node();
    }
    let code = oct_encode(vpl.normal);
    let p = vpl.position.xyz;
    return Node(p, 1.0, vpl.flux.rgb, oct_decode(code), code, p, p, vec3<f32>(0.0), 0u);
}

@compute @workgroup_size(64, 1, 1)
fn build(@builtin(global_invocation_id) gid: vec3<u32>) {
    let t = gid.x;
    if t >= tp.leaves / 2u {
        return;
    }
    let a = make_leaf(2u * t);
    let b = make_leaf(2u * t + 1u);
    store_node(tp.leaves + 2u * t, a);
    store_node(tp.leaves + 2u * t + 1u, b);
    var node = (tp.leaves + 2u * t) >> 1u;
    var m = merge(a, b);
    store_node(node, m);
    while node > 1u {
        let parent = node >> 1u;
        // First arrival: the sibling subtree is not merged yet; leave it to the second.
        if atomicAdd(&counters[parent], 1u) == 0u {
            return;
        }
        let sib = load_node(node ^ 1u);
        if (node & 1u) == 0u {
            m = merge(m, sib);
        } else {
            m = merge(sib, m);
        }
        store_node(parent, m);
        node = parent;
    }
}

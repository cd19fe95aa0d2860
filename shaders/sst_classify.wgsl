// The "usable for sampling" flags of every SST node (SST paper eq. 3: v >= v_min and
// sigma_z < sigma_max), one bit per node: word w holds nodes 32w .. 32w+31. Cheap and
// separate from the build, so that changing v_min / sigma_max never rebuilds the tree.
// CPU twin: `classify` in src/reference/sst_tree.rs.
#include "common/sst_node.wgsl"

struct ClassifyParams {
    nodes: u32, // 2 x leaves (node 0 is unused)
    v_min: f32,
    sigma_max: f32,
    _pad: u32,
};

@group(0) @binding(0) var<uniform> cp: ClassifyParams;
@group(0) @binding(1) var<storage, read> tree: array<SstNode>;
@group(0) @binding(2) var<storage, read_write> flags: array<u32>;

@compute @workgroup_size(64, 1, 1)
fn classify(@builtin(global_invocation_id) gid: vec3<u32>) {
    let w = gid.x;
    if w * 32u >= cp.nodes {
        return;
    }
    var bits = 0u;
    for (var k = 0u; k < 32u; k++) {
        let i = w * 32u + k;
        if i > 0u && i < cp.nodes && sst_usable(tree[i], cp.v_min, cp.sigma_max) {
            bits |= 1u << k;
        }
    }
    flags[w] = bits;
}

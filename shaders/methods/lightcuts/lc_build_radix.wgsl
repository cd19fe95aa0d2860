// Lightcuts' per-node data on the radix tree (issue 23), bottom-up in one dispatch: one thread
// per leaf writes the leaf's cone and representative, then walks up the parents; a per-node
// arrival counter lets only the second arrival merge the two children (as lbvh.wgsl's node
// data). The merge is lc_build.wgsl's (lc_merge.wgsl), with the same random number per node,
// so both trees' builds draw representatives alike. Cones and representatives are written and
// read as atomics: what makes one thread's merged node visible to the thread arriving second
// (WGSL has no device-scope fence). CPU twin: `build_on` in src/reference/lightcuts.rs.
#include "common/math.wgsl"
#include "common/color.wgsl"
#include "common/random.wgsl"
#include "common/sst_node.wgsl"
#include "common/vpl.wgsl"
#include "methods/lightcuts/lc_common.wgsl"
#include "methods/lightcuts/lc_merge.wgsl"

@group(0) @binding(0) var<uniform> bp: LcBuildParams;
@group(0) @binding(1) var<storage, read> nodes: array<SstNode>;
@group(0) @binding(2) var<storage, read> sorted_vpls: array<Vpl>;
// vec4 cones, 4 words per node.
@group(0) @binding(3) var<storage, read_write> cones: array<atomic<u32>>;
@group(0) @binding(4) var<storage, read_write> reps: array<atomic<u32>>;
@group(0) @binding(5) var<storage, read> links: array<vec4<u32>>;
@group(0) @binding(6) var<storage, read> parents: array<u32>;
@group(0) @binding(7) var<storage, read_write> counters: array<atomic<u32>>;

fn store_cone(i: u32, c: vec4<f32>) {
    for (var k = 0u; k < 4u; k++) {
        atomicStore(&cones[4u * i + k], bitcast<u32>(c[k]));
    }
}

fn load_cone(i: u32) -> vec4<f32> {
    var c = vec4<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        c[k] = bitcast<f32>(atomicLoad(&cones[4u * i + k]));
    }
    return c;
}

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let k = gid.x;
    if k >= bp.leaves {
        return;
    }
    let leaf = bp.leaves + k;
    let v = sorted_vpls[k];
    if v.id == VPL_NONE {
        store_cone(leaf, vec4<f32>(0.0, 0.0, 1.0, -1.0));
        atomicStore(&reps[leaf], LC_NONE);
    } else {
        store_cone(leaf, vec4<f32>(normalize(v.normal), 0.0));
        atomicStore(&reps[leaf], k);
    }
    if bp.leaves < 2u {
        return;
    }
    var n = parents[leaf];
    loop {
        // First arrival: the other child is not done yet; leave the merge to the second.
        if atomicAdd(&counters[n], 1u) == 0u {
            return;
        }
        let a = links[n].x;
        let b = links[n].y;
        store_cone(n, merge_cones(load_cone(a), load_cone(b)));
        atomicStore(&reps[n], pick_rep(atomicLoad(&reps[a]), atomicLoad(&reps[b]),
            luminance(nodes[a].intensity), luminance(nodes[b].intensity), rep_random(n, bp.seed)));
        if n == 1u {
            return;
        }
        n = parents[n];
    }
}

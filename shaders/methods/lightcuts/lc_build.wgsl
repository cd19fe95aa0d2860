// Lightcuts' per-node data, bottom-up, one dispatch per tree level (leaves first): the normal
// cone of each node (the smallest cone around its children's) and its representative VPL
// (its first child's with probability lum(I_a) / (lum(I_a) + lum(I_b)), one random number per
// node and build; Walter et al. 2005, 3.1). CPU twin: `build` in src/reference/lightcuts.rs.
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
@group(0) @binding(3) var<storage, read_write> cones: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> reps: array<u32>;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= bp.count {
        return;
    }
    let n = bp.first + gid.x;
    if n >= bp.leaves {
        let v = sorted_vpls[n - bp.leaves];
        if v.id == VPL_NONE {
            cones[n] = vec4<f32>(0.0, 0.0, 1.0, -1.0);
            reps[n] = LC_NONE;
        } else {
            cones[n] = vec4<f32>(normalize(v.normal), 0.0);
            reps[n] = n - bp.leaves;
        }
        return;
    }
    let a = 2u * n;
    let b = a + 1u;
    cones[n] = merge_cones(cones[a], cones[b]);
    reps[n] = pick_rep(reps[a], reps[b], luminance(nodes[a].intensity), luminance(nodes[b].intensity),
        rep_random(n, bp.seed));
}

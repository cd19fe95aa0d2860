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

struct LcBuildParams {
    first: u32,  // first node id of the level
    count: u32,  // nodes of the level
    leaves: u32,
    seed: u32,
};

@group(0) @binding(0) var<uniform> bp: LcBuildParams;
@group(0) @binding(1) var<storage, read> nodes: array<SstNode>;
@group(0) @binding(2) var<storage, read> sorted_vpls: array<Vpl>;
@group(0) @binding(3) var<storage, read_write> cones: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> reps: array<u32>;

fn angle_between(a: vec3<f32>, b: vec3<f32>) -> f32 {
    return acos(clamp(dot(a, b), -1.0, 1.0));
}

// Twin: `merge_cones`.
fn merge_cones(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    if a.w < 0.0 {
        return b;
    }
    if b.w < 0.0 {
        return a;
    }
    var w = a;
    var n = b;
    if a.w < b.w {
        w = b;
        n = a;
    }
    let d = angle_between(w.xyz, n.xyz);
    if min(d + n.w, PI) <= w.w {
        return w;
    }
    let half = 0.5 * (w.w + d + n.w);
    if half >= PI {
        return vec4<f32>(w.xyz, PI);
    }
    let rot = half - w.w;
    let perp = n.xyz - w.xyz * dot(w.xyz, n.xyz);
    var dir = vec3<f32>(0.0);
    if dot(perp, perp) > 1e-12 {
        dir = normalize(perp);
    } else {
        dir = sst_basis(w.xyz)[0];
    }
    return vec4<f32>(normalize(w.xyz * cos(rot) + dir * sin(rot)), half);
}

fn rep_random(node: u32, seed: u32) -> f32 {
    return u01(pcg_hash(node ^ pcg_hash(seed)));
}

// Twin: `pick_rep`.
fn pick_rep(ra: u32, rb: u32, la: f32, lb: f32, u: f32) -> u32 {
    if ra == LC_NONE {
        return rb;
    }
    if rb == LC_NONE {
        return ra;
    }
    if la + lb <= 0.0 || u * (la + lb) < la {
        return ra;
    }
    return rb;
}

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

// Section 5's bounding-sphere-tree light culling over the frame's VPLs (Algorithm 2 with the
// GPU techniques of 5.3), for the camera's G-buffer points instead of a path tracer's:
//   leaves_main:   per leaf of the light tree (the SST's perfect binary tree over the
//                  Morton-sorted VPLs, built each frame; the paper prebuilds its tree and
//                  updates its bounds), the VPL's stochastic range (eqs. 3, 6; one xi per
//                  VPL per frame), then its ancestors' largest range below them
//                  (`max_range`, atomicMax on the float's bits: ranges are >= 0; a thread
//                  stops at a node already holding a larger or equal one). A node's
//                  bounding sphere is then (centre of its VPL box, half its diagonal + that
//                  range): it holds every range sphere below it.
//   traverse_main: per pixel, the stackless walk of the implicit tree (children 2n, 2n + 1):
//                  a node is entered when its sphere holds the point, a leaf is listed when
//                  its stochastic fall-off is non-zero there (the point is in its range);
//                  the list keeps k of the m overlapping VPLs by reservoir sampling
//                  (Algorithm 3): traversal decoupled from shading (5.3.1).
//   shade_main:    resampled importance sampling of one listed VPL (5.3.2: one shadow ray
//                  per pixel) with q(i) = g_i / sum g (eq. 8) and the importance of eq. 9 for
//                  a point light: g_i = f(l) max I_i max(-w . n_i, 0) max(w . n_x, 0) (eq. 9's
//                  second factor, printed with the light's normal, can only be the
//                  receiver's: with n_i it is 0 wherever the first is positive; no BRDF, as
//                  the paper); the estimate is its contribution over
//                  p_i min(k / m, 1) q(i) (eq. 10; p_i is the stochastic fall-off's f / p),
//                  demodulated into `raw` (the shared interleave_filter.wgsl then x albedo / pi).
// Twins: reference::light_culling::{tree_max_ranges, tree_traverse, tree_shade}.
#include "common/math.wgsl"
#include "common/brdf.wgsl"
#include "common/random.wgsl"
#include "common/vpl.wgsl"
#include "common/sst_node.wgsl"
#include "common/vpl_visibility.wgsl"
#include "methods/light_culling/lcull_common.wgsl"
#include "methods/light_culling/lcull_light.wgsl"
#include "common/ism.wgsl"

@group(0) @binding(0) var<uniform> params: LcullParams;
@group(0) @binding(1) var gb_position: texture_2d<f32>;
@group(0) @binding(2) var gb_normal: texture_2d<f32>;
@group(0) @binding(3) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(4) var<storage, read> bvh_triangles: array<BvhTriangle>;
// The VPLs in leaf order and the tree's nodes (TreeBuffers).
@group(0) @binding(5) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(6) var<storage, read> nodes: array<SstNode>;
// Two vec4 per leaf, as lcull_light.wgsl.
@group(0) @binding(7) var<storage, read_write> lights: array<vec4<f32>>;
// Per node: the largest range of the VPLs below it (f32 bits; 0 = none in range anywhere).
@group(0) @binding(8) var<storage, read_write> max_range: array<atomic<u32>>;
// Per pixel: k listed leaves, and (m overlapping, nodes visited).
@group(0) @binding(9) var<storage, read_write> tree_list: array<u32>;
@group(0) @binding(10) var<storage, read_write> tree_m: array<vec2<u32>>;
@group(0) @binding(11) var<storage, read_write> raw: array<vec4<f32>>;
@group(0) @binding(12) var<storage, read_write> diag: array<vec4<f32>>;
@group(0) @binding(13) var<storage, read_write> stats: array<atomic<u32>>;
// The leaves' imperfect shadow maps (shadow_rays == 2: map j for leaf j; dummies otherwise).
@group(0) @binding(14) var<uniform> ism: IsmParams;
@group(0) @binding(15) var<storage, read> ism_depth: array<f32>;
@group(0) @binding(16) var<storage, read_write> ism_lights: array<vec4<f32>>;
// The G-buffer's albedo (base colour, metallic in a) for the glossy BRDF.
@group(0) @binding(17) var gb_albedo: texture_2d<f32>;

#include "common/stats64.wgsl"
#include "methods/light_culling/lcull_term.wgsl"

override DIAGNOSTICS: bool = true;

// Twin: reference::light_culling::tree_rng.
fn tree_rng(seed: u32, pixel: u32, stream: u32) -> u32 {
    return pcg_hash(seed ^ pcg_hash(pixel ^ stream));
}

@compute @workgroup_size(64, 1, 1)
fn leaves_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let j = gid.x + gid.y * nwg.x * 64u;
    if j >= params.leaves {
        return;
    }
    let l = lcull_light(params, vpls[j], j);
    lights[2u * j] = l.position_range;
    lights[2u * j + 1u] = l.falloff;
    if (params.ism_flags & 1u) != 0u && 2u * j + 1u < arrayLength(&ism_lights) {
        let m = lcull_ism_light(params, l.position_range.xyz, vpls[j].normal, l.position_range.w);
        ism_lights[2u * j] = m[0];
        ism_lights[2u * j + 1u] = m[1];
    }
    let r = l.position_range.w;
    if r > 0.0 {
        // Up the ancestors while this range is the largest seen there: a thread that finds
        // a larger (or equal) one stops, its owner carries that one up.
        let bits = bitcast<u32>(r);
        var n = (params.leaves + j) >> 1u;
        while n != 0u {
            let old = atomicMax(&max_range[n], bits);
            if old >= bits {
                break;
            }
            n = n >> 1u;
        }
    }
}

// Whether node n's bounding sphere holds x. Twin: tree_node_hit.
fn node_hit(n: u32, x: vec3<f32>) -> bool {
    let r = bitcast<f32>(atomicLoad(&max_range[n]));
    if r <= 0.0 {
        return false;
    }
    let nd = nodes[n];
    let c = 0.5 * (nd.bbox_min + nd.bbox_max);
    // Conservative by a relative 1e-5 and 1e-6 of the coordinates' size (rounding of the
    // centre); the leaves decide exactly.
    let a = abs(c);
    let radius = (0.5 * length(nd.bbox_max - nd.bbox_min) + r) * 1.00001 + 1e-6 * max(a.x, max(a.y, a.z));
    let d = x - c;
    return dot(d, d) <= radius * radius;
}

@compute @workgroup_size(8, 8, 1)
fn traverse_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= params.width || gid.y >= params.height {
        return;
    }
    let k = gid.y * params.width + gid.x;
    let g = textureLoad(gb_position, vec2<i32>(gid.xy), 0);
    if g.w == 0.0 {
        tree_m[k] = vec2<u32>(0u);
        return;
    }
    let x = g.xyz;
    let cap = params.cap;
    var rng = tree_rng(params.seed, k, 0x2545f491u);
    var m = 0u;
    var visited = 0u;
    var n = 1u;
    loop {
        visited += 1u;
        var descend = false;
        if n >= params.leaves {
            let j = n - params.leaves;
            let l = lights[2u * j];
            let fo = lights[2u * j + 1u];
            let d = l.xyz - x;
            if lcull_falloff(dot(d, d), params.eps, fo.x, fo.y) > 0.0 {
                // Algorithm 3 (reservoir sampling of k of the m overlapping VPLs).
                if m < cap {
                    tree_list[k * cap + m] = j;
                } else {
                    rng = pcg_hash(rng);
                    let r = u32(u01(rng) * f32(m + 1u));
                    if r < cap {
                        tree_list[k * cap + r] = j;
                    }
                }
                m += 1u;
            }
        } else {
            descend = node_hit(n, x);
        }
        if descend {
            n = 2u * n;
            continue;
        }
        // Next: the sibling of the nearest ancestor-or-self that is a left child.
        while (n & 1u) == 1u {
            n = n >> 1u;
        }
        if n == 0u {
            break;
        }
        n += 1u;
    }
    tree_m[k] = vec2<u32>(m, visited);
    if DIAGNOSTICS {
        // 3 pixels over k, 4 largest m, 12-13 nodes visited.
        if m > cap {
            atomicAdd(&stats[3], 1u);
        }
        atomicMax(&stats[4], m);
        stats_add64(12u, visited);
    }
}

// Eq. 9 for a point light (VPL i seen from x with normal nx). Twin: tree_importance.
fn importance(i: u32, x: vec3<f32>, nx: vec3<f32>) -> f32 {
    let v = vpls[i];
    let d = v.position.xyz - x;
    let l2 = dot(d, d);
    let w = d * inverseSqrt(max(l2, 1e-30));
    let cv = max(-dot(v.normal, w), 0.0);
    let cx = max(dot(nx, w), 0.0);
    let flux_max = max(v.flux.r, max(v.flux.g, v.flux.b));
    return flux_max / PI * cv * cx / max(l2, params.eps * params.eps);
}

@compute @workgroup_size(8, 8, 1)
fn shade_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= params.width || gid.y >= params.height {
        return;
    }
    let k = gid.y * params.width + gid.x;
    let g = textureLoad(gb_position, vec2<i32>(gid.xy), 0);
    if g.w == 0.0 {
        raw[k] = vec4<f32>(0.0);
        if DIAGNOSTICS {
            diag[k] = vec4<f32>(0.0);
        }
        return;
    }
    let x = g.xyz;
    let nx = normalize(textureLoad(gb_normal, vec2<i32>(gid.xy), 0).xyz);
    lcull_shading(gid.xy, x);
    let cap = params.cap;
    let mv = tree_m[k];
    let m = mv.x;
    let s = min(m, cap);
    // (The CDF walk below evaluates g again rather than keep k of them in a function array,
    // which a CPU adapter indexes slowly.)
    var total = 0.0;
    for (var j = 0u; j < s; j++) {
        total += importance(tree_list[k * cap + j], x, nx);
    }
    var value = vec3<f32>(0.0);
    var rays = 0u;
    if total > 0.0 {
        // Resampled importance sampling (5.3.2): one VPL by the CDF of q (eq. 8).
        let u = u01(pcg_hash(tree_rng(params.seed, k, 0x68e31da4u))) * total;
        var acc = 0.0;
        var pick = 0u;
        var g_pick = 0.0;
        for (var j = 0u; j < s; j++) {
            let gj = importance(tree_list[k * cap + j], x, nx);
            if gj > 0.0 {
                pick = j;
                g_pick = gj;
            }
            acc += gj;
            if u < acc && gj > 0.0 {
                break;
            }
        }
        let t = term(tree_list[k * cap + pick], x, nx);
        rays = t.ray;
        // Eq. 10: p_i (in the fall-off) x min(k / m, 1) x q(i).
        let keep = min(f32(cap) / f32(m), 1.0);
        value = t.value * total / (keep * g_pick);
    }
    raw[k] = vec4<f32>(value, 1.0);
    if DIAGNOSTICS {
        // Per pixel: VPLs in range (m), listed (min(m, k)), tree nodes visited, shadow rays.
        diag[k] = vec4<f32>(f32(m), f32(s), f32(mv.y), f32(rays));
        // 5 pixels, 6-7 listed, 8-9 in range, 10-11 shadow rays (64-bit).
        atomicAdd(&stats[5], 1u);
        stats_add64(6u, s);
        stats_add64(8u, m);
        stats_add64(10u, rays);
    }
}

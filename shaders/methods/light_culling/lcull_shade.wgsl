// Algorithm 1, step 3, and the interleaving's geometry-aware filter.
//   shade_main: per pixel, the VPLs of its tile's list (every VPL of its interleaving subset
//     when the tile is over its cap), each with the stochastic (eq. 2) or clamped fall-off
//     and, with shadow rays on, a BVH shadow ray; the sum x n^2 (the subset is 1 / n^2 of
//     the VPLs), demodulated (before albedo / pi), into `raw`.
//   filter_main: the mean of `raw` over the (2r + 1)^2 window's pixels on the same surface
//     (normal within filter_normal_cos, within filter_plane_tolerance x depth of the tangent
//     plane; section 4.2 after Segovia et al. 2006), x albedo / pi, into the GI accumulation.
// Twins: reference::light_culling::{shade, filter_pixel}.
#include "common/math.wgsl"
#include "common/camera.wgsl"
#include "common/vpl.wgsl"
#include "common/vpl_visibility.wgsl"
#include "methods/light_culling/lcull_common.wgsl"

@group(0) @binding(0) var<uniform> params: LcullParams;
@group(0) @binding(1) var<uniform> camera: Camera;
@group(0) @binding(2) var gb_position: texture_2d<f32>;
@group(0) @binding(3) var gb_normal: texture_2d<f32>;
@group(0) @binding(4) var gb_albedo: texture_2d<f32>;
@group(0) @binding(5) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(6) var<storage, read> bvh_triangles: array<BvhTriangle>;
@group(0) @binding(7) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(8) var<storage, read> lights: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read> tile_count: array<u32>;
@group(0) @binding(10) var<storage, read> tile_lists: array<u32>;
@group(0) @binding(11) var<storage, read_write> raw: array<vec4<f32>>;
@group(0) @binding(12) var<storage, read_write> diag: array<vec4<f32>>;
@group(0) @binding(13) var<storage, read_write> accum: array<vec4<f32>>;
@group(0) @binding(14) var<storage, read_write> stats: array<atomic<u32>>;

#include "common/stats64.wgsl"

override DIAGNOSTICS: bool = true;

#include "methods/light_culling/lcull_term.wgsl"

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
    let nx = normalize(textureLoad(gb_normal, vec2<i32>(gid.xy), 0).xyz);
    let t = lcull_tile_of(params, gid.x, gid.y);
    let c = tile_count[t];
    var sum = vec3<f32>(0.0);
    var in_range = 0u;
    var rays = 0u;
    var tested = 0u;
    if c <= params.cap {
        tested = c;
        for (var j = 0u; j < c; j++) {
            let r = term(tile_lists[t * params.cap + j], g.xyz, nx);
            sum += r.value;
            in_range += r.in_range;
            rays += r.ray;
        }
    } else {
        // Over the cap: every VPL of the subset (the same sum: a VPL out of range adds 0).
        let s = gid.x % params.n + params.n * (gid.y % params.n);
        let m = lcull_members(params, s);
        for (var j = 0u; j < m; j++) {
            let r = term(lcull_member(params, s, j), g.xyz, nx);
            sum += r.value;
            in_range += r.in_range;
            rays += r.ray;
            tested += 1u;
        }
    }
    raw[k] = vec4<f32>(sum * f32(params.n * params.n), 1.0);
    if DIAGNOSTICS {
        // Per pixel: list length, VPLs in range, VPLs tested, shadow rays (over the cap when
        // x > cap).
        diag[k] = vec4<f32>(f32(c), f32(in_range), f32(tested), f32(rays));
        // 5 pixels, 6-7 VPLs tested, 8-9 in range, 10-11 shadow rays (64-bit).
        atomicAdd(&stats[5], 1u);
        stats_add64(6u, tested);
        stats_add64(8u, in_range);
        stats_add64(10u, rays);
    }
}

@compute @workgroup_size(8, 8, 1)
fn filter_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= params.width || gid.y >= params.height {
        return;
    }
    let k = gid.y * params.width + gid.x;
    let px = vec2<i32>(gid.xy);
    let g = textureLoad(gb_position, px, 0);
    var value = vec3<f32>(0.0);
    if g.w != 0.0 {
        let n = normalize(textureLoad(gb_normal, px, 0).xyz);
        let tol = params.filter_plane_tolerance * max(dot(g.xyz - camera.position.xyz, camera.forward.xyz), 1e-6);
        let r = i32(params.filter_radius);
        var sum = vec3<f32>(0.0);
        var w = 0.0;
        for (var dy = -r; dy <= r; dy++) {
            for (var dx = -r; dx <= r; dx++) {
                let q = px + vec2<i32>(dx, dy);
                if q.x < 0 || q.y < 0 || q.x >= i32(params.width) || q.y >= i32(params.height) {
                    continue;
                }
                let gq = textureLoad(gb_position, q, 0);
                if gq.w == 0.0 {
                    continue;
                }
                let nq = normalize(textureLoad(gb_normal, q, 0).xyz);
                if dot(n, nq) >= params.filter_normal_cos && abs(dot(gq.xyz - g.xyz, n)) <= tol {
                    sum += raw[u32(q.y) * params.width + u32(q.x)].rgb;
                    w += 1.0;
                }
            }
        }
        let albedo = textureLoad(gb_albedo, px, 0).rgb;
        value = albedo / PI * sum / max(w, 1.0);
    }
    if params.accumulate != 0u {
        accum[k] += vec4<f32>(value, 0.0);
    } else {
        accum[k] = vec4<f32>(value, 0.0);
    }
}

// Algorithm 1, step 3: per pixel, the VPLs of its tile's list (every VPL of its interleaving
// subset when the tile is over its cap), each with the stochastic (eq. 2) or clamped fall-off
// and, with visibility on, a BVH shadow ray or a lookup in its imperfect shadow map; the
// sum x n^2 (the subset is 1 / n^2 of the VPLs), demodulated (before albedo / pi), into `raw`. The shared geometry-aware filter
// (`interleave_filter.wgsl`, section 4.2) then undoes the interleaving into the GI
// accumulation. Twin: reference::light_culling::shade.
#include "common/math.wgsl"
#include "common/brdf.wgsl"
#include "common/vpl.wgsl"
#include "common/vpl_visibility.wgsl"
#include "methods/light_culling/lcull_common.wgsl"
#include "common/ism.wgsl"

@group(0) @binding(0) var<uniform> params: LcullParams;
@group(0) @binding(1) var gb_position: texture_2d<f32>;
@group(0) @binding(2) var gb_normal: texture_2d<f32>;
@group(0) @binding(3) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(4) var<storage, read> bvh_triangles: array<BvhTriangle>;
@group(0) @binding(5) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(6) var<storage, read> lights: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read> tile_count: array<u32>;
@group(0) @binding(8) var<storage, read> tile_lists: array<u32>;
@group(0) @binding(9) var<storage, read_write> raw: array<vec4<f32>>;
@group(0) @binding(10) var<storage, read_write> diag: array<vec4<f32>>;
@group(0) @binding(11) var<storage, read_write> stats: array<atomic<u32>>;
// The VPLs' imperfect shadow maps (shadow_rays == 2; a dummy otherwise).
@group(0) @binding(12) var<uniform> ism: IsmParams;
@group(0) @binding(13) var<storage, read> ism_depth: array<f32>;
// The G-buffer's albedo (base colour, metallic in a) for the glossy BRDF.
@group(0) @binding(14) var gb_albedo: texture_2d<f32>;

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
    lcull_shading(gid.xy, g.xyz);
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

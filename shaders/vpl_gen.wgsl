// VPL generation (thesis 4.1, chapter 6): BRSM importance of every RSM texel, its
// edge-aware filter, the importance and flux pyramids, and hierarchical warping
// (Clarberg et al. 2005) of a randomized Hammersley set into N VPLs.
// CPU twin: src/reference/vpl.rs.
#include "common/camera.wgsl"
#include "common/color.wgsl"
#include "common/math.wgsl"
#include "common/random.wgsl"



#include "common/vpl.wgsl"
#include "common/rsm_pyramid.wgsl"
#include "common/rsm_warp.wgsl"


struct LevelParams {
    level: u32,
};

@group(0) @binding(0) var<uniform> params: VplParams;
@group(0) @binding(1) var<uniform> camera: Camera;
@group(0) @binding(2) var rsm_position: texture_2d_array<f32>;
@group(0) @binding(3) var rsm_normal: texture_2d_array<f32>;
@group(0) @binding(4) var rsm_flux: texture_2d_array<f32>;
@group(0) @binding(5) var gb_position: texture_2d<f32>;
@group(0) @binding(6) var gb_normal: texture_2d<f32>;
@group(0) @binding(7) var gb_albedo: texture_2d<f32>;
@group(0) @binding(8) var<storage, read_write> importance_raw: array<f32>;
@group(0) @binding(9) var<storage, read_write> importance_pyramid: array<f32>;
@group(0) @binding(10) var<storage, read_write> flux_pyramid: array<f32>;
@group(0) @binding(11) var<storage, read_write> vpls: array<Vpl>;
// Bounding box of each pyramid node's texel positions for levels >= 1 (see bounds_index):
// [2 k] = min, [2 k + 1] = max (empty: min = +big, max = -big). Used by the converged
// reference's geometric bound.
@group(0) @binding(12) var<storage, read_write> bounds_pyramid: array<vec4<f32>>;
@group(1) @binding(0) var<uniform> level_params: LevelParams;


// Radius with density min(1, 1/r^2) / 2 on (0, inf) (the thesis's 1/r^2 falloff capped at 1):
// half the mass uniform on [0, 1), half on [1, inf) with density 1/(2 r^2).
fn sample_radius_capped(u: f32) -> f32 {
    if u < 0.5 {
        return 2.0 * u;
    }
    return 0.5 / max(1.0 - u, 1e-7);
}

// Expected contribution (luminance of the radiance it sends) of the pVPL at texel t of
// `layer` to G-buffer surfaces found around it (thesis 4.1.1, chapter 6).
@compute @workgroup_size(8, 8, 1)
fn importance(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= params.res || gid.y >= params.res || gid.z >= params.light_count {
        return;
    }
    let layer = gid.z;
    let t = vec2<i32>(gid.xy);
    let p4 = textureLoad(rsm_position, t, i32(layer), 0);
    let flux_lum = luminance(textureLoad(rsm_flux, t, i32(layer), 0).rgb);
    let i0 = pyr_index(layer, 0u, gid.x, gid.y);
    let raw_index = layer * params.res * params.res + gid.y * params.res + gid.x;
    flux_pyramid[i0] = select(0.0, flux_lum, p4.w > 0.0);
    if p4.w == 0.0 || flux_lum <= 0.0 {
        importance_raw[raw_index] = 0.0;
        return;
    }
    let p = p4.xyz;
    let nv = normalize(textureLoad(rsm_normal, t, i32(layer), 0).xyz);
    let size = vec2<f32>(textureDimensions(gb_position));
    var rng = rng_new(raw_index, params.seed, 0x9e3779b9u);
    var sum = 0.0;
    for (var s = 0u; s < params.samples; s++) {
        let z = 2.0 * rng_next(&rng) - 1.0;
        let phi = 6.28318530718 * rng_next(&rng);
        let rxy = sqrt(max(1.0 - z * z, 0.0));
        let dir = vec3<f32>(rxy * cos(phi), rxy * sin(phi), z);
        let q = p + dir * (sample_radius_capped(rng_next(&rng)) * params.sample_radius);
        let clip = camera.view_proj * vec4<f32>(q, 1.0);
        if clip.w <= 0.0 {
            continue;
        }
        let ndc = clip.xy / clip.w;
        let px = vec2<f32>(0.5 * ndc.x + 0.5, 0.5 - 0.5 * ndc.y) * size;
        if any(px < vec2<f32>(0.0)) || any(px >= size) {
            continue;
        }
        let g = textureLoad(gb_position, vec2<i32>(px), 0);
        if g.w == 0.0 {
            continue;
        }
        let nx = normalize(textureLoad(gb_normal, vec2<i32>(px), 0).xyz);
        let albedo = luminance(textureLoad(gb_albedo, vec2<i32>(px), 0).rgb);
        sum += albedo / PI * flux_lum / PI * vpl_geometry(p, nv, g.xyz, nx, params.epsilon);
    }
    importance_raw[raw_index] = sum / f32(params.samples);
}

// Similarity S (thesis eq. 5.3) of two RSM texels.
fn similar(pa: vec4<f32>, na: vec3<f32>, pb: vec4<f32>, nb: vec3<f32>) -> bool {
    return pa.w > 0.0 && pb.w > 0.0 && dot(na, nb) > params.n_min && distance(pa.xyz, pb.xyz) < params.d_max;
}

// Edge-aware Gaussian filter of the raw importance (sigma = radius / 2), weights x S; writes
// level 0 of the importance pyramid.
@compute @workgroup_size(8, 8, 1)
fn filter_importance(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= params.res || gid.y >= params.res || gid.z >= params.light_count {
        return;
    }
    let layer = gid.z;
    let t = vec2<i32>(gid.xy);
    let res = i32(params.res);
    let pa = textureLoad(rsm_position, t, i32(layer), 0);
    let na = normalize(textureLoad(rsm_normal, t, i32(layer), 0).xyz);
    let base = layer * params.res * params.res;
    let r = i32(params.filter_radius);
    var out = 0.0;
    if r == 0 || pa.w == 0.0 {
        out = importance_raw[base + gid.y * params.res + gid.x];
    } else {
        let sigma = 0.5 * f32(r);
        var num = 0.0;
        var den = 0.0;
        for (var dy = -r; dy <= r; dy++) {
            for (var dx = -r; dx <= r; dx++) {
                let c = t + vec2<i32>(dx, dy);
                if any(c < vec2<i32>(0)) || any(c >= vec2<i32>(res)) {
                    continue;
                }
                let pb = textureLoad(rsm_position, c, i32(layer), 0);
                let nb = normalize(textureLoad(rsm_normal, c, i32(layer), 0).xyz);
                if !similar(pa, na, pb, nb) {
                    continue;
                }
                let g = exp(-f32(dx * dx + dy * dy) / (2.0 * sigma * sigma));
                num += g * importance_raw[base + u32(c.y) * params.res + u32(c.x)];
                den += g;
            }
        }
        out = select(0.0, num / den, den > 0.0);
    }
    importance_pyramid[pyr_index(layer, 0u, gid.x, gid.y)] = out;
}

// Builds pyramid level `level_params.level` (>= 1) of both pyramids: sums of 2x2 children.
@compute @workgroup_size(8, 8, 1)
fn reduce(@builtin(global_invocation_id) gid: vec3<u32>) {
    let l = level_params.level;
    let r = params.res >> l;
    if gid.x >= r || gid.y >= r || gid.z >= params.light_count {
        return;
    }
    let layer = gid.z;
    let x = 2u * gid.x;
    let y = 2u * gid.y;
    let a = pyr_index(layer, l - 1u, x, y);
    let c = pyr_index(layer, l - 1u, x, y + 1u);
    let o = pyr_index(layer, l, gid.x, gid.y);
    importance_pyramid[o] = (importance_pyramid[a] + importance_pyramid[a + 1u]) + (importance_pyramid[c] + importance_pyramid[c + 1u]);
    flux_pyramid[o] = (flux_pyramid[a] + flux_pyramid[a + 1u]) + (flux_pyramid[c] + flux_pyramid[c + 1u]);
    var lo = vec4<f32>(3.0e38, 3.0e38, 3.0e38, 0.0);
    var hi = -lo;
    for (var k = 0u; k < 4u; k++) {
        let cx = x + (k & 1u);
        let cy = y + (k >> 1u);
        if l == 1u {
            // Level-0 boxes are the texels' positions.
            let p = textureLoad(rsm_position, vec2<i32>(vec2<u32>(cx, cy)), i32(layer), 0);
            if p.w > 0.0 {
                lo = min(lo, vec4<f32>(p.xyz, 0.0));
                hi = max(hi, vec4<f32>(p.xyz, 0.0));
            }
        } else {
            let b = bounds_index(layer, l - 1u, cx, cy);
            lo = min(lo, bounds_pyramid[2u * b]);
            hi = max(hi, bounds_pyramid[2u * b + 1u]);
        }
    }
    let ob = bounds_index(layer, l, gid.x, gid.y);
    bounds_pyramid[2u * ob] = lo;
    bounds_pyramid[2u * ob + 1u] = hi;
}

// One thread per VPL: pick a texel of its light's RSM and make the VPL.
@compute @workgroup_size(64, 1, 1)
fn warp_vpls(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i >= params.vpl_count {
        return;
    }
    let layer = range_layer(i, params.ranges, params.light_count);
    let rg = params.ranges[layer];
    let j = i - rg.x;
    let n = max(rg.y, 1u);
    let rot = vec2<f32>(u01(pcg_hash(params.seed * 2u + layer * 0x51ed27u)), u01(pcg_hash(params.seed * 2u + 1u + layer * 0x51ed27u)));
    let uv = hammersley(j, n, rot);
    var texel = vec2<u32>(0u);
    var pmf = 0.0;
    if params.mode == 1u {
        texel = min(vec2<u32>(uv * f32(params.res)), vec2<u32>(params.res - 1u));
        pmf = 1.0 / f32(params.res * params.res);
    } else {
        let w = warp_mixed(layer, uv, params.flux_mix);
        texel = w.xy;
        pmf = bitcast<f32>(w.z);
    }
    var v: Vpl;
    let t = vec2<i32>(texel);
    let p = textureLoad(rsm_position, t, i32(layer), 0);
    let flux = textureLoad(rsm_flux, t, i32(layer), 0).rgb;
    v.position = vec4<f32>(p.xyz, pmf);
    v.normal = normalize(textureLoad(rsm_normal, t, i32(layer), 0).xyz);
    v.id = (layer << 24u) | (texel.y * params.res + texel.x);
    if p.w > 0.0 && pmf > 0.0 {
        v.flux = vec4<f32>(flux / (f32(n) * pmf), 1.0);
    } else {
        v.flux = vec4<f32>(0.0);
        v.normal = vec3<f32>(0.0, 0.0, 1.0);
        v.id = VPL_NONE;
    }
    vpls[i] = v;
}

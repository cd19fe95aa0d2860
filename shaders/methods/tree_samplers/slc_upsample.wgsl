// The upsampling half of slc_half.wgsl (separate module: it reads the half-resolution
// G-buffer as textures and writes the full-resolution accumulation).

#include "common/slc_half_params.wgsl"

@group(0) @binding(0) var<uniform> hp: HalfParams;
@group(0) @binding(1) var full_position: texture_2d<f32>;
@group(0) @binding(2) var full_normal: texture_2d<f32>;
@group(0) @binding(3) var full_albedo: texture_2d<f32>;
@group(0) @binding(4) var half_position: texture_2d<f32>;
@group(0) @binding(5) var half_normal: texture_2d<f32>;
@group(0) @binding(6) var<storage, read> half_accum: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> accum: array<vec4<f32>>;

@compute @workgroup_size(8, 8, 1)
fn upsample(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= hp.full_w || gid.y >= hp.full_h {
        return;
    }
    let k = gid.y * hp.full_w + gid.x;
    let px = vec2<i32>(gid.xy);
    let g = textureLoad(full_position, px, 0);
    if g.w == 0.0 {
        accum[k] = vec4<f32>(0.0);
        return;
    }
    let n = normalize(textureLoad(full_normal, px, 0).xyz);
    // Half pixel (x, y) holds the sample of full pixel (2x, 2y): its centre is at 2x + 0.5.
    let f = vec2<f32>(gid.xy) * 0.5;
    let b0 = floor(f);
    let t = f - b0;
    var sum = vec3<f32>(0.0);
    var wsum = 0.0;
    var best = vec3<f32>(0.0);
    var best_dot = -2.0;
    for (var i = 0u; i < 4u; i++) {
        let d = vec2<i32>(i32(i & 1u), i32(i >> 1u));
        let h = vec2<i32>(b0) + d;
        if h.x < 0 || h.y < 0 || h.x >= i32(hp.half_w) || h.y >= i32(hp.half_h) {
            continue;
        }
        let hpos = textureLoad(half_position, h, 0);
        if hpos.w == 0.0 {
            continue;
        }
        let hn = normalize(textureLoad(half_normal, h, 0).xyz);
        let v = half_accum[u32(h.y) * hp.half_w + u32(h.x)].rgb;
        let nd = dot(n, hn);
        if nd > best_dot {
            best_dot = nd;
            best = v;
        }
        var w = select(1.0 - t.x, t.x, d.x == 1) * select(1.0 - t.y, t.y, d.y == 1);
        if !(nd > hp.n_min && distance(g.xyz, hpos.xyz) < hp.d_max) {
            w = 0.0;
        }
        sum += w * v;
        wsum += w;
    }
    var e = best;
    if wsum > 0.0 {
        e = sum / wsum;
    }
    let albedo = textureLoad(full_albedo, px, 0).rgb;
    accum[k] = vec4<f32>(albedo * e, 0.0);
}

// The geometry-aware filter of interleaved sampling (Stochastic Light Culling, Tokuyoshi &
// Harada 2016, section 4.2, after Segovia et al. 2006): per pixel, the mean of `raw` over the
// (2r + 1)^2 window's (or, with a period p, the p x p window's: one pixel per subset, the VAL
// paper's n x m filter) pixels on the same surface (normal within normal_cos of the pixel's,
// within plane_tolerance x view depth of its tangent plane), x albedo (modulate) x scale, into
// (or added to) `accum`. Shared by light culling (raw before albedo / pi: scale 1 / pi) and
// the tree samplers (raw demodulated: scale 1; modulate 0 at half resolution, where the
// upsampler applies the albedo). Twin: reference::interleave::filter_pixel.
#include "common/math.wgsl"
#include "common/camera.wgsl"

// Twin: `GpuFilterParams` in src/renderer/passes/interleave_filter.rs.
struct FilterParams {
    width: u32,
    height: u32,
    radius: u32,
    accumulate: u32,   // 0: write, 1: add
    normal_cos: f32,
    plane_tolerance: f32,
    scale: f32,
    modulate: u32,     // 1: x the pixel's albedo
    period: u32,       // 0: the (2 radius + 1)^2 window; p: the p x p window -p/2 ..= p - p/2 - 1
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(0) @binding(0) var<uniform> fp: FilterParams;
@group(0) @binding(1) var<uniform> camera: Camera;
@group(0) @binding(2) var gb_position: texture_2d<f32>;
@group(0) @binding(3) var gb_normal: texture_2d<f32>;
@group(0) @binding(4) var gb_albedo: texture_2d<f32>;
@group(0) @binding(5) var<storage, read> raw: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> accum: array<vec4<f32>>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= fp.width || gid.y >= fp.height {
        return;
    }
    let k = gid.y * fp.width + gid.x;
    let px = vec2<i32>(gid.xy);
    let g = textureLoad(gb_position, px, 0);
    var value = vec3<f32>(0.0);
    if g.w != 0.0 {
        let n = normalize(textureLoad(gb_normal, px, 0).xyz);
        let tol = fp.plane_tolerance * max(dot(g.xyz - camera.position.xyz, camera.forward.xyz), 1e-6);
        var lo = -i32(fp.radius);
        var hi = i32(fp.radius);
        if fp.period > 0u {
            let p = i32(fp.period);
            lo = -(p / 2);
            hi = p - p / 2 - 1;
        }
        var sum = vec3<f32>(0.0);
        var w = 0.0;
        for (var dy = lo; dy <= hi; dy++) {
            for (var dx = lo; dx <= hi; dx++) {
                let q = px + vec2<i32>(dx, dy);
                if q.x < 0 || q.y < 0 || q.x >= i32(fp.width) || q.y >= i32(fp.height) {
                    continue;
                }
                let gq = textureLoad(gb_position, q, 0);
                if gq.w == 0.0 {
                    continue;
                }
                let nq = normalize(textureLoad(gb_normal, q, 0).xyz);
                if dot(n, nq) >= fp.normal_cos && abs(dot(gq.xyz - g.xyz, n)) <= tol {
                    sum += raw[u32(q.y) * fp.width + u32(q.x)].rgb;
                    w += 1.0;
                }
            }
        }
        value = fp.scale * sum / max(w, 1.0);
        if fp.modulate != 0u {
            value *= textureLoad(gb_albedo, px, 0).rgb;
        }
    }
    if fp.accumulate != 0u {
        accum[k] += vec4<f32>(value, 0.0);
    } else {
        accum[k] = vec4<f32>(value, 0.0);
    }
}

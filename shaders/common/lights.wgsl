// Directional lights and shadow-map lookup. Twins of `GpuDirectionalLight` / `GpuLights` in
// src/renderer/gpu_data.rs.
//
// Contract: a shader including this file declares
//   `shadow_maps: texture_depth_2d_array` and `lights: Lights` (a uniform)
// at module scope with its own bindings.
#include "common/math.wgsl"


struct DirectionalLight {
    view_proj: mat4x4<f32>,
    direction: vec4<f32>,  // xyz travel direction, w layer
    irradiance: vec4<f32>, // rgb E in W/m^2 (perpendicular)
    shadow: vec4<f32>,     // x texel size (m), y depth range (m), z depth bias (texels), w normal offset (texels)
};

struct Lights {
    count: vec4<u32>, // x count, y shadow-map resolution, z PCF radius, w slope bias (f32 bits)
    lights: array<DirectionalLight, 4>,
};

// Shadow-map visibility in [0, 1] of world point `p` with normal `n` for light `i`.
// Bias, all in shadow-map texels so it scales with the resolution:
// - normal offset: the lookup point moves along n by `shadow.w` x sin(theta) texels;
// - depth bias: `shadow.z` texels plus a slope term tan(theta) x (PCF radius + 1/2) x
//   `slope_bias` (count.w): on a receiver tilted by theta, a tap k texels away differs in
//   depth by k x texel x tan(theta) (receiver-plane argument), so PCF taps need that much.
// tan(theta) is capped at 10 (84 degrees); beyond that the surface is barely lit anyway.
fn shadow_visibility(i: u32, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let l = lights.lights[i];
    let to_light = -l.direction.xyz;
    let texel = l.shadow.x;
    let cos_t = clamp(dot(n, to_light), 0.0, 1.0);
    let sin_t = sqrt(max(1.0 - cos_t * cos_t, 0.0));
    let tan_t = min(sin_t / max(cos_t, 1e-4), 10.0);
    let q = l.view_proj * vec4<f32>(p + n * (texel * l.shadow.w * sin_t), 1.0);
    let ndc = q.xyz / q.w;
    let uv = vec2<f32>(0.5 * ndc.x + 0.5, 0.5 - 0.5 * ndc.y);
    if any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0)) {
        return 1.0;
    }
    let res = i32(lights.count.y);
    let r = i32(lights.count.z);
    let slope = bitcast<f32>(lights.count.w);
    let bias_texels = l.shadow.z + slope * tan_t * (f32(r) + 0.5);
    let depth = ndc.z - bias_texels * texel / l.shadow.y;
    let base = vec2<i32>(uv * f32(res));
    var lit = 0.0;
    var total = 0.0;
    for (var dy = -r; dy <= r; dy++) {
        for (var dx = -r; dx <= r; dx++) {
            let c = clamp(base + vec2<i32>(dx, dy), vec2<i32>(0), vec2<i32>(res - 1));
            let stored = textureLoad(shadow_maps, c, i32(l.direction.w), 0);
            lit += select(0.0, 1.0, depth <= stored);
            total += 1.0;
        }
    }
    return lit / total;
}


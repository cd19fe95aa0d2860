// Directional lights and shadow-map lookup. Twins of `GpuDirectionalLight` / `GpuLights` in
// src/renderer/gpu_data.rs.
//
// Contract: a shader including this file declares
//   `shadow_maps: texture_depth_2d_array` and `lights: Lights` (a uniform)
// at module scope with its own bindings.

const PI: f32 = 3.14159265358979;

struct DirectionalLight {
    view_proj: mat4x4<f32>,
    direction: vec4<f32>,  // xyz travel direction, w layer
    irradiance: vec4<f32>, // rgb E in W/m^2 (perpendicular)
    shadow: vec4<f32>,     // x texel size (m), y depth range (m), z depth bias (texels), w normal offset (texels)
};

struct Lights {
    count: vec4<u32>, // x count, y shadow-map resolution, z PCF radius
    lights: array<DirectionalLight, 4>,
};

// Shadow-map visibility in [0, 1] of world point `p` with geometric normal `n` for light `i`.
// Normal-offset + constant bias, both in texels (so they scale with the shadow-map resolution);
// optional (2r+1)^2 PCF.
fn shadow_visibility(i: u32, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let l = lights.lights[i];
    let to_light = -l.direction.xyz;
    let texel = l.shadow.x;
    let n_dot_l = dot(n, to_light);
    // Offset along the normal, more at grazing angles.
    let offset = n * texel * l.shadow.w * (1.0 - 0.5 * max(n_dot_l, 0.0)) + to_light * texel * 0.25;
    let q = l.view_proj * vec4<f32>(p + offset, 1.0);
    let ndc = q.xyz / q.w;
    let uv = vec2<f32>(0.5 * ndc.x + 0.5, 0.5 - 0.5 * ndc.y);
    if any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0)) {
        return 1.0;
    }
    let res = i32(lights.count.y);
    let bias = l.shadow.z * texel / l.shadow.y;
    let depth = ndc.z - bias;
    let r = i32(lights.count.z);
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

// Direct diffuse radiance at p: sum over lights of rho/pi * E * max(0, n.l) * visibility.
fn direct_radiance(p: vec3<f32>, n: vec3<f32>, albedo: vec3<f32>) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < lights.count.x; i++) {
        let l = lights.lights[i];
        let cos_t = max(dot(n, -l.direction.xyz), 0.0);
        if cos_t > 0.0 {
            sum += albedo / PI * l.irradiance.rgb * cos_t * shadow_visibility(i, p, n);
        }
    }
    return sum;
}

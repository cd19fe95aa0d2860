// Evaluates common/brdf.wgsl for a buffer of (n, v, l, material) cases: the GPU-vs-CPU test of
// the BRDF (`renderer::brdf_probe`, twin `reference::brdf`).
#include "common/brdf.wgsl"

struct BrdfCase {
    n: vec4<f32>,    // xyz normal, w = model (0 Lambert, 1 GGX)
    v: vec4<f32>,    // xyz view direction, w = metallic
    l: vec4<f32>,    // xyz light direction, w = roughness
    base: vec4<f32>, // rgb base colour
};

@group(0) @binding(0) var<storage, read> cases: array<BrdfCase>;
// rgb = diffuse part, then rgb = specular part (two vec4 per case).
@group(0) @binding(1) var<storage, read_write> out: array<vec4<f32>>;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i >= arrayLength(&cases) {
        return;
    }
    let c = cases[i];
    let model = u32(c.n.w);
    out[2u * i] = vec4<f32>(brdf_diffuse(model, c.n.xyz, c.v.xyz, c.l.xyz, c.base.rgb, c.v.w), 0.0);
    out[2u * i + 1u] = vec4<f32>(brdf_specular(model, c.n.xyz, c.v.xyz, c.l.xyz, c.base.rgb, c.v.w, c.l.w), 0.0);
}

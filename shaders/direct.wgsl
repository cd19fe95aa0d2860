// Direct light from the directional lights: f(v, l) * E * max(0, n.l) * shadow-map visibility,
// f the frame's BRDF (common/brdf.wgsl; Lambert: rho / pi).
#include "common/camera.wgsl"
#include "common/lights.wgsl"
#include "common/brdf.wgsl"

struct DirectParams {
    brdf: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var<uniform> lights: Lights;
@group(0) @binding(2) var shadow_maps: texture_depth_2d_array;
@group(0) @binding(3) var gb_position: texture_2d<f32>;
@group(0) @binding(4) var gb_normal: texture_2d<f32>;
@group(0) @binding(5) var gb_albedo: texture_2d<f32>;
@group(0) @binding(6) var out_direct: texture_storage_2d<rgba32float, write>;
@group(0) @binding(7) var<uniform> dp: DirectParams;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(out_direct);
    if gid.x >= size.x || gid.y >= size.y {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let pos = textureLoad(gb_position, px, 0);
    var radiance = vec3<f32>(0.0);
    if pos.w > 0.0 {
        let nr = textureLoad(gb_normal, px, 0);
        let n = normalize(nr.xyz);
        let albedo = textureLoad(gb_albedo, px, 0);
        let v = normalize(camera.position.xyz - pos.xyz);
        for (var i = 0u; i < lights.count.x; i++) {
            let l = -lights.lights[i].direction.xyz;
            let cos_t = max(dot(n, l), 0.0);
            if cos_t > 0.0 {
                let f = brdf_eval(dp.brdf, n, v, l, albedo.rgb, albedo.a, nr.w);
                radiance += f * lights.lights[i].irradiance.rgb * cos_t * shadow_visibility(i, pos.xyz, n);
            }
        }
    }
    textureStore(out_direct, px, vec4<f32>(radiance, 1.0));
}

// Direct light from the directional lights: rho/pi * E * max(0, n.l) * shadow-map visibility.
#include "common/camera.wgsl"
#include "common/lights.wgsl"

@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var<uniform> lights: Lights;
@group(0) @binding(2) var shadow_maps: texture_depth_2d_array;
@group(0) @binding(3) var gb_position: texture_2d<f32>;
@group(0) @binding(4) var gb_normal: texture_2d<f32>;
@group(0) @binding(5) var gb_albedo: texture_2d<f32>;
@group(0) @binding(6) var out_direct: texture_storage_2d<rgba32float, write>;

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
        let n = normalize(textureLoad(gb_normal, px, 0).xyz);
        let albedo = textureLoad(gb_albedo, px, 0).rgb;
        radiance = direct_radiance(pos.xyz, n, albedo);
    }
    textureStore(out_direct, px, vec4<f32>(radiance, 1.0));
}

// Display: exposure, tonemap and sRGB encoding of a linear-radiance buffer into the Rgba8Unorm
// texture the UI shows (and the PNG exports use).
#include "common/color.wgsl"

struct DisplayParams {
    exposure: f32,
    tonemap: u32,
    _pad: vec2<u32>,
};

@group(0) @binding(0) var<uniform> params: DisplayParams;
@group(0) @binding(1) var src: texture_2d<f32>;
@group(0) @binding(2) var dst: texture_storage_2d<rgba8unorm, write>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(dst);
    if gid.x >= size.x || gid.y >= size.y {
        return;
    }
    let c = textureLoad(src, vec2<i32>(gid.xy), 0).rgb * params.exposure;
    // NaN/inf shows as magenta so it cannot hide (tested on the bits: compilers may fold
    // `x != x` away).
    let exp_bits = bitcast<vec3<u32>>(c) & vec3<u32>(0x7f800000u);
    if any(exp_bits == vec3<u32>(0x7f800000u)) {
        textureStore(dst, vec2<i32>(gid.xy), vec4<f32>(1.0, 0.0, 1.0, 1.0));
        return;
    }
    let t = tonemap(max(c, vec3<f32>(0.0)), params.tonemap);
    textureStore(dst, vec2<i32>(gid.xy), vec4<f32>(linear_to_srgb(t), 1.0));
}

// Half-resolution GI (thesis chapter 6, "Upsampling"), first half: the G-buffer sample at
// pixel (2x, 2y) becomes half-resolution pixel (x, y). The sampler then runs there
// (demodulated: without the albedo) and slc_upsample.wgsl fills each full-resolution
// pixel from the 4 nearest half-resolution samples with bilinear weights x S(x, sample)
// (eq. 5.3: a joint bilateral filter), re-modulated with the full-resolution albedo; where no
// neighbour is similar, the neighbour with the most similar normal is used.

#include "common/slc_half_params.wgsl"

@group(0) @binding(0) var<uniform> hp: HalfParams;
@group(0) @binding(1) var full_position: texture_2d<f32>;
@group(0) @binding(2) var full_normal: texture_2d<f32>;
@group(0) @binding(3) var full_albedo: texture_2d<f32>;
@group(0) @binding(4) var half_position: texture_storage_2d<rgba32float, write>;
@group(0) @binding(5) var half_normal: texture_storage_2d<rgba16float, write>;
@group(0) @binding(6) var half_albedo: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8, 1)
fn downsample(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= hp.half_w || gid.y >= hp.half_h {
        return;
    }
    let src = vec2<i32>(min(2u * gid.xy, vec2<u32>(hp.full_w - 1u, hp.full_h - 1u)));
    let dst = vec2<i32>(gid.xy);
    textureStore(half_position, dst, textureLoad(full_position, src, 0));
    textureStore(half_normal, dst, textureLoad(full_normal, src, 0));
    textureStore(half_albedo, dst, textureLoad(full_albedo, src, 0));
}

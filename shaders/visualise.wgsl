// Visualise: maps a non-radiance buffer to a viewable sRGB image in the same Rgba8Unorm
// texture the display pass writes. Modes (twin of `VisMode` in src/renderer/passes/visualise.rs):
//   0 normal (n * 0.5 + 0.5)        1 albedo (linear -> sRGB)
//   2 position (normalised to range) 3 linear depth from the camera (range -> false colour)
//   4 id from position.w (hash colour)
//   5 depth texture layer (shadow map; range -> grey)
//   6 unsigned integer ids (hash colour; 0 = black)
//   7 unsigned integer heat (range -> false colour)
//   8 array layer, colour x range_max.x (RSM flux / (E x texel area) ~ albedo), sRGB
//   9 array layer, normal (n * 0.5 + 0.5)
//  11 array layer, position normalised to [range_min, range_max] (scene bounds); empty black
//  10 scalar buffer, log heat relative to its mean: t = (log10(v / mean) + 3) / 5, i.e.
//     1/1000 of the mean -> 0, 100x the mean -> 1; zero -> black.
//     The mean is range_min.x (a pyramid's top / texel count, read on the GPU).
#include "common/color.wgsl"

struct VisParams {
    mode: u32,
    layer: u32,
    _pad: vec2<u32>,
    range_min: vec4<f32>,
    range_max: vec4<f32>,
};

@group(0) @binding(0) var<uniform> params: VisParams;
@group(0) @binding(1) var dst: texture_storage_2d<rgba8unorm, write>;
@group(1) @binding(0) var src_float: texture_2d<f32>;
@group(2) @binding(0) var src_depth: texture_depth_2d_array;
@group(3) @binding(0) var src_uint: texture_2d<u32>;
@group(1) @binding(2) var src_array: texture_2d_array<f32>;
@group(1) @binding(3) var<storage, read> src_scalar: array<f32>;
@group(1) @binding(4) var<storage, read> src_pyramid: array<f32>;

fn in_bounds(gid: vec3<u32>) -> bool {
    let size = textureDimensions(dst);
    return gid.x < size.x && gid.y < size.y;
}

fn normalised(v: vec3<f32>) -> vec3<f32> {
    return clamp((v - params.range_min.xyz) / max(params.range_max.xyz - params.range_min.xyz, vec3<f32>(1e-20)), vec3<f32>(0.0), vec3<f32>(1.0));
}

// Float buffers: normal, albedo, position, depth (from position + camera in aux), ids.
@compute @workgroup_size(8, 8, 1)
fn vis_float(@builtin(global_invocation_id) gid: vec3<u32>) {
    if !in_bounds(gid) {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let v = textureLoad(src_float, px, 0);
    var c = vec3<f32>(0.0);
    switch params.mode {
        case 0u: {
            c = select(vec3<f32>(0.0), v.xyz * 0.5 + 0.5, dot(v.xyz, v.xyz) > 0.0);
        }
        case 1u: {
            c = linear_to_srgb(v.rgb);
        }
        case 2u: {
            // Background stays black.
            c = select(vec3<f32>(0.0), normalised(v.xyz), v.w > 0.0);
        }
        case 3u: {
            // Linear depth along the camera forward: range_min.xyz = eye, range_max.xyz = forward,
            // range_min.w / range_max.w = depth range.
            if v.w > 0.0 {
                let d = dot(v.xyz - params.range_min.xyz, params.range_max.xyz);
                let t = (d - params.range_min.w) / max(params.range_max.w - params.range_min.w, 1e-20);
                c = false_color(1.0 - t);
            }
        }
        case 4u: {
            if v.w > 0.0 {
                c = id_color(u32(v.w));
            }
        }
        default: {
            c = vec3<f32>(1.0, 0.0, 1.0);
        }
    }
    textureStore(dst, px, vec4<f32>(c, 1.0));
}

// Depth textures (shadow map layers), sampled nearest to the destination size.
@compute @workgroup_size(8, 8, 1)
fn vis_depth(@builtin(global_invocation_id) gid: vec3<u32>) {
    if !in_bounds(gid) {
        return;
    }
    let src_size = textureDimensions(src_depth);
    let dst_size = textureDimensions(dst);
    let sp = vec2<u32>((vec2<f32>(gid.xy) + 0.5) * vec2<f32>(src_size) / vec2<f32>(dst_size));
    let d = textureLoad(src_depth, vec2<i32>(sp), i32(params.layer), 0);
    let t = clamp((d - params.range_min.x) / max(params.range_max.x - params.range_min.x, 1e-20), 0.0, 1.0);
    textureStore(dst, vec2<i32>(gid.xy), vec4<f32>(vec3<f32>(1.0 - t), 1.0));
}

// Unsigned integer buffers: hashed ids (mode 6) or a heat map over a range (mode 7).
@compute @workgroup_size(8, 8, 1)
fn vis_uint(@builtin(global_invocation_id) gid: vec3<u32>) {
    if !in_bounds(gid) {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let v = textureLoad(src_uint, px, 0).x;
    var c = vec3<f32>(0.0);
    if params.mode == 7u {
        c = false_color((f32(v) - params.range_min.x) / max(params.range_max.x - params.range_min.x, 1e-20));
    } else if v != 0u {
        c = id_color(v);
    }
    textureStore(dst, px, vec4<f32>(c, 1.0));
}

// Array texture layers (RSM), sampled nearest to the destination size.
@compute @workgroup_size(8, 8, 1)
fn vis_array(@builtin(global_invocation_id) gid: vec3<u32>) {
    if !in_bounds(gid) {
        return;
    }
    let src_size = textureDimensions(src_array);
    let dst_size = textureDimensions(dst);
    let sp = vec2<u32>((vec2<f32>(gid.xy) + 0.5) * vec2<f32>(src_size) / vec2<f32>(dst_size));
    let v = textureLoad(src_array, vec2<i32>(sp), i32(params.layer), 0);
    var c = vec3<f32>(0.0);
    if params.mode == 9u {
        c = select(vec3<f32>(0.0), v.xyz * 0.5 + 0.5, dot(v.xyz, v.xyz) > 0.0);
    } else if params.mode == 11u {
        c = select(vec3<f32>(0.0), normalised(v.xyz), v.w > 0.0);
    } else {
        c = linear_to_srgb(v.rgb * params.range_max.x);
    }
    textureStore(dst, vec2<i32>(gid.xy), vec4<f32>(c, 1.0));
}

// Scalar buffers over a square map (res = range_max.y, layer offset = range_max.z texels).
@compute @workgroup_size(8, 8, 1)
fn vis_scalar(@builtin(global_invocation_id) gid: vec3<u32>) {
    if !in_bounds(gid) {
        return;
    }
    let res = u32(params.range_max.y);
    let dst_size = textureDimensions(dst);
    let sp = vec2<u32>((vec2<f32>(gid.xy) + 0.5) * f32(res) / vec2<f32>(dst_size));
    let v = src_scalar[u32(params.range_max.z) + sp.y * res + sp.x];
    let mean = src_pyramid[u32(params.range_min.y)] / f32(res * res);
    var c = vec3<f32>(0.0);
    if v > 0.0 && mean > 0.0 {
        c = false_color((log2(v / mean) * 0.30103 + 3.0) / 5.0);
    }
    textureStore(dst, vec2<i32>(gid.xy), vec4<f32>(c, 1.0));
}

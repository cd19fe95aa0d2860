// A/B comparison of two radiance images (a tree sampler and the ground truth of the same VPLs,
// two snapshots, a snapshot and the live frame, ...). B is read at A's pixel scaled to B's
// size, so images of different sizes still line up. Modes (`views::AbMode::gpu_id`):
//   0: split, A left of `split_x`, B right of it (both through the display transform), a white
//      divider;
//   1: relative error |lum(a) - lum(b)| / lum(b) per pixel, log10 in false colour from 1e-2 (0)
//      to 1e1 (1); pixels black in both images stay black;
//   2: side by side, A on the left half of a twice-as-wide image, B on the right;
//   3: difference |a - b| x diff_scale through the display transform;
//   4: A alone; 5: B alone.
#include "common/color.wgsl"

struct CmpParams {
    mode: u32,
    split_x: u32,
    exposure: f32,  // linear multiplier
    tonemap: u32,
    diff_scale: f32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(0) @binding(0) var<uniform> cp: CmpParams;
@group(0) @binding(1) var image_a: texture_2d<f32>;
@group(0) @binding(2) var image_b: texture_2d<f32>;
@group(0) @binding(3) var gb_position: texture_2d<f32>;
@group(0) @binding(4) var dst: texture_storage_2d<rgba8unorm, write>;

fn show(c: vec3<f32>) -> vec3<f32> {
    return linear_to_srgb(tonemap(max(c * cp.exposure, vec3<f32>(0.0)), cp.tonemap));
}

fn load_b(px: vec2<i32>) -> vec3<f32> {
    let sa = vec2<i32>(textureDimensions(image_a));
    let sb = vec2<i32>(textureDimensions(image_b));
    let q = min(px * sb / max(sa, vec2<i32>(1)), sb - 1);
    return textureLoad(image_b, q, 0).rgb;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(dst);
    if gid.x >= size.x || gid.y >= size.y {
        return;
    }
    var px = vec2<i32>(gid.xy);
    if cp.mode == 2u {
        let w = i32(textureDimensions(image_a).x);
        let right = px.x >= w;
        let src = vec2<i32>(px.x - select(0, w, right), px.y);
        let v = select(textureLoad(image_a, src, 0).rgb, load_b(src), right);
        var c2 = show(v);
        if px.x == w {
            c2 = vec3<f32>(1.0);
        }
        textureStore(dst, px, vec4<f32>(c2, 1.0));
        return;
    }
    let a = textureLoad(image_a, px, 0).rgb;
    let b = load_b(px);
    var c = vec3<f32>(0.0);
    switch cp.mode {
        case 0u: {
            c = select(show(b), show(a), gid.x < cp.split_x);
            if gid.x == cp.split_x {
                c = vec3<f32>(1.0);
            }
        }
        case 1u: {
            if textureLoad(gb_position, px, 0).w > 0.0 || luminance(a) > 0.0 || luminance(b) > 0.0 {
                let rel = abs(luminance(a) - luminance(b)) / max(luminance(b), 1e-6);
                c = false_color((log2(max(rel, 1e-30)) * 0.30103 + 2.0) / 3.0);
            }
        }
        case 3u: {
            c = show(abs(a - b) * cp.diff_scale);
        }
        case 4u: {
            c = show(a);
        }
        default: {
            c = show(b);
        }
    }
    textureStore(dst, px, vec4<f32>(c, 1.0));
}

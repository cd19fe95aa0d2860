// Comparison of a tree sampler's GI with the ground truth of the same VPLs:
//   mode 0: split view, the method's GI left of `split_x`, the ground truth's right of it
//           (both through the display transform), a white divider;
//   mode 1: relative error |lum(a) - lum(b)| / lum(b) per pixel, log10 in false colour from
//           1e-2 (0) to 1e1 (1); pixels without geometry black;
//   mode 2: side by side, the method's GI on the left half of a twice-as-wide image, the
//           ground truth's on the right.
#include "common/color.wgsl"

struct CmpParams {
    mode: u32,
    split_x: u32,
    exposure: f32,  // linear multiplier
    tonemap: u32,
};

@group(0) @binding(0) var<uniform> cp: CmpParams;
@group(0) @binding(1) var method_image: texture_2d<f32>;
@group(0) @binding(2) var reference_image: texture_2d<f32>;
@group(0) @binding(3) var gb_position: texture_2d<f32>;
@group(0) @binding(4) var dst: texture_storage_2d<rgba8unorm, write>;

fn show(c: vec3<f32>) -> vec3<f32> {
    return linear_to_srgb(tonemap(max(c * cp.exposure, vec3<f32>(0.0)), cp.tonemap));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(dst);
    if gid.x >= size.x || gid.y >= size.y {
        return;
    }
    var px = vec2<i32>(gid.xy);
    if cp.mode == 2u {
        let w = i32(textureDimensions(method_image).x);
        let right = px.x >= w;
        let src = vec2<i32>(px.x - select(0, w, right), px.y);
        let v = select(textureLoad(method_image, src, 0).rgb, textureLoad(reference_image, src, 0).rgb, right);
        var c2 = show(v);
        if px.x == w {
            c2 = vec3<f32>(1.0);
        }
        textureStore(dst, px, vec4<f32>(c2, 1.0));
        return;
    }
    let a = textureLoad(method_image, px, 0).rgb;
    let b = textureLoad(reference_image, px, 0).rgb;
    var c = vec3<f32>(0.0);
    if cp.mode == 0u {
        c = select(show(b), show(a), gid.x < cp.split_x);
        if gid.x == cp.split_x {
            c = vec3<f32>(1.0);
        }
    } else if textureLoad(gb_position, px, 0).w > 0.0 {
        let rel = abs(luminance(a) - luminance(b)) / max(luminance(b), 1e-6);
        c = false_color((log2(max(rel, 1e-30)) * 0.30103 + 2.0) / 3.0);
    }
    textureStore(dst, px, vec4<f32>(c, 1.0));
}

// Lightcuts' views over the frame (from the per-pixel diagnostics):
//   mode 0: cut size, false colour on a log scale 1 .. scale_top (the power of ten at or
//           above max_cut, so that the legend's decades fall on its ticks);
//   mode 1: largest error bound left in the cut / the estimate, false colour on a log scale
//           1e-4 .. 1 (the threshold is a tick of the legend; above it: the cut hit max_cut);
//   mode 2: refinement steps + 1, false colour on a log scale 1 .. scale_top;
//   mode 3: the final image in grey, the pixels whose cut stopped at max_cut in red.
// CPU twin of the colour map: base::colormap::false_color.
#include "common/color.wgsl"

struct LcViewParams {
    mode: u32,
    scale_top: u32,
    relative_error: f32,
    exposure: f32,
    tonemap: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(0) @binding(0) var<uniform> vp: LcViewParams;
@group(0) @binding(1) var final_image: texture_2d<f32>;
@group(0) @binding(2) var gb_position: texture_2d<f32>;
@group(0) @binding(3) var<storage, read> diag: array<vec4<f32>>;
@group(0) @binding(4) var dst: texture_storage_2d<rgba8unorm, write>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(dst);
    if gid.x >= size.x || gid.y >= size.y {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let d = diag[gid.y * size.x + gid.x];
    let geometry = textureLoad(gb_position, px, 0).w > 0.0;
    let top = f32(max(vp.scale_top, 2u));
    var c = vec3<f32>(0.0);
    if geometry {
        switch vp.mode {
            case 0u: {
                c = false_color(log_scale(d.x, 1.0, top));
            }
            case 1u: {
                if d.z > 0.0 {
                    c = false_color(log_scale(d.z, 1e-4, 1.0));
                }
            }
            case 2u: {
                c = false_color(log_scale(d.y + 1.0, 1.0, top));
            }
            default: {
                c = vec3<f32>(display_grey(textureLoad(final_image, px, 0).rgb, vp.exposure, vp.tonemap)) * 0.8;
                if d.z > vp.relative_error {
                    c = vec3<f32>(0.95, 0.1, 0.1);
                }
            }
        }
    }
    textureStore(dst, px, vec4<f32>(c, 1.0));
}

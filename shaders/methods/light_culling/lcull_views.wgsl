// Stochastic Light Culling's views over the frame:
//   mode 0: the pixel's tile list length, false colour on a log scale 1 .. scale_top;
//   mode 1: the final image in grey, pixels of tiles over their list's cap in red;
//   mode 2: the interleaving pattern: each pixel in its subset's colour (n x n cells);
//   mode 3: the share of the tile's list in range of the pixel (VPLs with a non-zero
//           fall-off there / list length; over the cap: / the subset's VPLs tested), false
//           colour 0 .. 1: how tight the tile's bounds are;
//   mode 4: clamped vs stochastic: (lum(clamped) - lum(stochastic)) / their mean, each the
//           mean of its accumulation (the method's own and the companion variant's), false
//           colour from -range (0) to +range (1); also written to `difference` as (relative,
//           clamped lum, stochastic lum, 1) for export. Without a companion yet: the grey
//           final (dimmed);
//   mode 5: the tree variant's nodes visited (diag.z), false colour on a log scale.
// (The tree variant's diag: m VPLs in range, listed, nodes visited, shadow rays; mode 0
// shows its m.)
// CPU twin of the colour map: base::colormap::false_color.
#include "common/color.wgsl"
#include "methods/light_culling/lcull_common.wgsl"

struct LcullViewParams {
    mode: u32,
    scale_top: u32,
    exposure: f32,
    tonemap: u32,
    n: u32,
    cap: u32,
    own_scale: f32,
    companion_scale: f32,
    own_is_clamped: u32,
    range: f32,
    _pad1: u32,
    _pad2: u32,
};

@group(0) @binding(0) var<uniform> vp: LcullViewParams;
@group(0) @binding(1) var final_image: texture_2d<f32>;
@group(0) @binding(2) var gb_position: texture_2d<f32>;
@group(0) @binding(3) var<storage, read> diag: array<vec4<f32>>;
@group(0) @binding(4) var dst: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(5) var<storage, read> own_accum: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> companion_accum: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> difference: array<vec4<f32>>;

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
    switch vp.mode {
        case 0u: {
            if geometry {
                c = false_color(log_scale(d.x + 1.0, 1.0, top));
            }
        }
        case 1u: {
            if geometry {
                c = vec3<f32>(display_grey(textureLoad(final_image, px, 0).rgb, vp.exposure, vp.tonemap)) * 0.8;
                if u32(d.x) > vp.cap {
                    c = vec3<f32>(0.95, 0.1, 0.1);
                }
            }
        }
        case 2u: {
            let n = max(vp.n, 1u);
            c = id_color(gid.x % n + n * (gid.y % n));
            if !geometry {
                c *= 0.3;
            }
        }
        case 5u: {
            if geometry {
                c = false_color(log_scale(d.z + 1.0, 1.0, top));
            }
        }
        case 3u: {
            if geometry && d.z >= 0.0 {
                c = false_color(d.y / max(d.z, 1.0));
            }
        }
        default: {
            let k = gid.y * size.x + gid.x;
            if vp.companion_scale <= 0.0 {
                // No companion yet (its buffers may not exist: nothing is written).
                if geometry {
                    c = vec3<f32>(display_grey(textureLoad(final_image, px, 0).rgb, vp.exposure, vp.tonemap)) * 0.5;
                }
            } else {
                let own = luminance(own_accum[k].rgb) * vp.own_scale;
                let other = luminance(companion_accum[k].rgb) * vp.companion_scale;
                let clamped = select(other, own, vp.own_is_clamped != 0u);
                let stochastic = select(own, other, vp.own_is_clamped != 0u);
                let mean = 0.5 * (clamped + stochastic);
                var rel = 0.0;
                if mean > 0.0 {
                    rel = (clamped - stochastic) / mean;
                }
                difference[k] = vec4<f32>(rel, clamped, stochastic, select(0.0, 1.0, geometry));
                if geometry {
                    c = false_color(0.5 + 0.5 * clamp(rel / max(vp.range, 1e-6), -1.0, 1.0));
                }
            }
        }
    }
    textureStore(dst, px, vec4<f32>(c, 1.0));
}

// Lightcut Interpolation's views over the frame:
//   mode 0: the cache records over the grey final image, 3 x 3 dots coloured by their reach
//           from red (r_min_px) to green (r_max_px), as the paper's Fig. 4 (top); the
//           pinned pixel's records as white 5 x 5 rings;
//   mode 1: interpolation weights: each pixel's records' colours (hashed ids) mixed by its
//           weights (Fig. 4, middle); fallback pixels magenta;
//   mode 2: the fallback mask: pixels that computed a full lightcut, red over the grey final;
//   mode 3: cut size (interpolated, or the fallback's lightcut), false colour on a log scale
//           1 .. scale_top;
//   mode 4: level spread of the input cuts (width-weighted mean of the largest minus the
//           smallest input level over the leaves; 0 where they agree), false colour 0 .. 4.
#include "common/color.wgsl"
#include "methods/lightcut_interpolation/li_common.wgsl"

struct LiViewParams {
    mode: u32,
    scale_top: u32,
    r_min_px: f32,
    r_max_px: f32,
    exposure: f32,
    tonemap: u32,
    tiles_x: u32,
    tiles_y: u32,
    pinned: u32, // the pinned pixel (row-major index), or LI_NONE
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

struct LiSel {
    ids: vec4<u32>,
    w: vec4<f32>,
};

@group(0) @binding(0) var<uniform> vp: LiViewParams;
@group(0) @binding(1) var final_image: texture_2d<f32>;
@group(0) @binding(2) var gb_position: texture_2d<f32>;
@group(0) @binding(3) var<storage, read> diag: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> sel: array<LiSel>;
@group(0) @binding(5) var<storage, read> radius: array<vec2<f32>>;
@group(0) @binding(6) var<storage, read> tile_count: array<u32>;
@group(0) @binding(7) var<storage, read> tile_offset: array<u32>;
@group(0) @binding(8) var<storage, read> records: array<u32>;
@group(0) @binding(9) var<storage, read> rec_meta: array<u32>;
@group(0) @binding(10) var dst: texture_storage_2d<rgba8unorm, write>;

fn grey_final(px: vec2<i32>) -> vec3<f32> {
    return vec3<f32>(display_grey(textureLoad(final_image, px, 0).rgb, vp.exposure, vp.tonemap)) * 0.8;
}

// Whether record `id` is one of the pinned pixel's records.
fn pinned_uses(id: u32) -> bool {
    if vp.pinned == LI_NONE {
        return false;
    }
    let s = sel[vp.pinned];
    for (var i = 0u; i < s.ids.w; i++) {
        if s.ids[i] == id {
            return true;
        }
    }
    return false;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(dst);
    if gid.x >= size.x || gid.y >= size.y {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let k = gid.y * size.x + gid.x;
    let d = diag[k];
    let geometry = textureLoad(gb_position, px, 0).w > 0.0;
    let fallback = geometry && d.y < 0.0;
    var c = vec3<f32>(0.0);
    switch vp.mode {
        case 0u: {
            if geometry {
                c = grey_final(px);
            }
            let count = rec_meta[0];
            var ringed = false; // drawn over every dot
            let tx = i32(gid.x / LI_TILE);
            let ty = i32(gid.y / LI_TILE);
            for (var dy = -1; dy <= 1; dy++) {
                for (var dx = -1; dx <= 1; dx++) {
                    let cx = tx + dx;
                    let cy = ty + dy;
                    if cx < 0 || cy < 0 || cx >= i32(vp.tiles_x) || cy >= i32(vp.tiles_y) {
                        continue;
                    }
                    let t = u32(cy) * vp.tiles_x + u32(cx);
                    for (var j = 0u; j < tile_count[t]; j++) {
                        let id = tile_offset[t] + j;
                        if id >= count {
                            break;
                        }
                        let r = records[id];
                        let q = vec2<i32>(i32(r % size.x), i32(r / size.x));
                        let d = abs(q - px);
                        if all(d <= vec2<i32>(1)) {
                            let f = clamp((radius[r].y - vp.r_min_px) / max(vp.r_max_px - vp.r_min_px, 1e-6), 0.0, 1.0);
                            c = mix(vec3<f32>(0.95, 0.1, 0.1), vec3<f32>(0.1, 0.9, 0.2), f);
                        }
                        if max(d.x, d.y) == 2 && pinned_uses(id) {
                            ringed = true;
                        }
                    }
                }
            }
            if ringed {
                c = vec3<f32>(1.0);
            }
        }
        case 1u: {
            if fallback {
                c = vec3<f32>(0.9, 0.1, 0.9);
            } else if geometry {
                let s = sel[k];
                for (var i = 0u; i < s.ids.w; i++) {
                    c += s.w[i] * id_color(s.ids[i]);
                }
            }
        }
        case 2u: {
            if geometry {
                c = grey_final(px);
                if fallback {
                    c = vec3<f32>(0.95, 0.1, 0.1);
                }
            }
        }
        case 3u: {
            if geometry {
                c = false_color(log_scale(d.x, 1.0, f32(max(vp.scale_top, 2u))));
            }
        }
        default: {
            if geometry && !fallback {
                c = false_color(clamp(d.y / 4.0, 0.0, 1.0));
            } else if fallback {
                c = vec3<f32>(0.3);
            }
        }
    }
    textureStore(dst, px, vec4<f32>(c, 1.0));
}

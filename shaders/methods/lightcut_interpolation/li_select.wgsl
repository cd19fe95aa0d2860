// Lightcut Interpolation's record selection (Rehfeld & Dachsbacher 2016, section 3.2): per
// pixel, the records of its tile and the eight around it (the image-space grid), weighted by
// Tabellion and Lamorlette's function (li_weight); the four best ranked, the fourth's weight
// subtracted from the other three and the three normalised. Best weight below epsilon (or
// nothing left after the subtraction): count 0, the pixel computes a full lightcut. CPU twin:
// `select` in src/reference/lightcut_interpolation.rs (candidates in the same order: tile
// rows top to bottom, tiles left to right, records in placement order).
#include "common/math.wgsl"
#include "methods/lightcut_interpolation/li_common.wgsl"

struct LiSel {
    ids: vec4<u32>, // three record ids, w: how many
    w: vec4<f32>,   // three weights, w: the best raw weight
};

@group(0) @binding(0) var<uniform> lp: LiParams;
@group(0) @binding(1) var gb_position: texture_2d<f32>;
@group(0) @binding(2) var gb_normal: texture_2d<f32>;
@group(0) @binding(3) var<storage, read> radius: array<vec2<f32>>;
@group(0) @binding(4) var<storage, read> tile_count: array<u32>;
@group(0) @binding(5) var<storage, read> tile_offset: array<u32>;
@group(0) @binding(6) var<storage, read> records: array<u32>;
@group(0) @binding(7) var<storage, read> rec_meta: array<u32>;
@group(0) @binding(8) var<storage, read_write> sel: array<LiSel>;

fn pixel_of(k: u32) -> vec2<i32> {
    return vec2<i32>(i32(k % lp.width), i32(k / lp.width));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= lp.width || gid.y >= lp.height {
        return;
    }
    let k = gid.y * lp.width + gid.x;
    let g = textureLoad(gb_position, vec2<i32>(gid.xy), 0);
    var out = LiSel(vec4<u32>(LI_NONE, LI_NONE, LI_NONE, 0u), vec4<f32>(0.0));
    if g.w == 0.0 {
        sel[k] = out;
        return;
    }
    let x = g.xyz;
    let n = normalize(textureLoad(gb_normal, vec2<i32>(gid.xy), 0).xyz);
    let count = rec_meta[0];
    var ids = vec4<u32>(LI_NONE);
    var ws = vec4<f32>(0.0);
    let tx = i32(gid.x / LI_TILE);
    let ty = i32(gid.y / LI_TILE);
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let cx = tx + dx;
            let cy = ty + dy;
            if cx < 0 || cy < 0 || cx >= i32(lp.tiles_x) || cy >= i32(lp.tiles_y) {
                continue;
            }
            let t = u32(cy) * lp.tiles_x + u32(cx);
            let off = tile_offset[t];
            let c = tile_count[t];
            for (var j = 0u; j < c; j++) {
                let id = off + j;
                if id >= count {
                    break;
                }
                let rp = records[id];
                let q = pixel_of(rp);
                let pr = textureLoad(gb_position, q, 0).xyz;
                let nr = normalize(textureLoad(gb_normal, q, 0).xyz);
                let w = li_weight(x, n, pr, nr, radius[rp].x, lp.one_minus_cos_max);
                if w <= 0.0 || w <= ws.w {
                    continue;
                }
                // Insertion into the four best (ties keep the earlier record).
                if w > ws.z {
                    ws.w = ws.z;
                    ids.w = ids.z;
                    if w > ws.y {
                        ws.z = ws.y;
                        ids.z = ids.y;
                        if w > ws.x {
                            ws.y = ws.x;
                            ids.y = ids.x;
                            ws.x = w;
                            ids.x = id;
                        } else {
                            ws.y = w;
                            ids.y = id;
                        }
                    } else {
                        ws.z = w;
                        ids.z = id;
                    }
                } else {
                    ws.w = w;
                    ids.w = id;
                }
            }
        }
    }
    out.w.w = ws.x;
    let w3 = vec3<f32>(ws.x - ws.w, ws.y - ws.w, ws.z - ws.w);
    let sum = w3.x + w3.y + w3.z;
    if ws.x >= lp.epsilon && sum > 1e-6 {
        var m = 0u;
        for (var i = 0u; i < 3u; i++) {
            if w3[i] > 0.0 && ids[i] != LI_NONE {
                out.ids[m] = ids[i];
                out.w[m] = w3[i] / sum;
                m += 1u;
            }
        }
        out.ids.w = m;
    }
    sel[k] = out;
}

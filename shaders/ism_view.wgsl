// The atlas of imperfect shadow maps as a view (any method that builds one): the maps in use
// laid out in a grid of `cols` columns shaped like the view (map m at column m mod cols, row
// m / cols), fitted into it (nearest texel, square texels), each texel's distance in false
// colour on a log scale lo .. hi metres; texels no point landed on that pull-push filled at
// half brightness; holes left after pull-push black; outside the maps in use dark grey.
// Also writes the view's linear data for export: (distance or 0, 1 where a point landed,
// map index, 1 inside a map in use). Twin of the layout: reference::ism::IsmLayout.
#include "common/color.wgsl"

struct IsmViewParams {
    atlas: u32,
    tile: u32,
    per_row: u32,
    maps: u32,
    lo: f32,
    hi: f32,
    // Map texels per view pixel (the grid fitted into the view).
    scale: f32,
    cols: u32,
};

const EMPTY: f32 = 1e30;

@group(0) @binding(0) var<uniform> vp: IsmViewParams;
@group(0) @binding(1) var<storage, read> depth: array<f32>;
@group(0) @binding(2) var<storage, read> keys: array<u32>;
@group(0) @binding(3) var dst: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(4) var<storage, read_write> data: array<vec4<f32>>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(dst);
    if gid.x >= size.x || gid.y >= size.y {
        return;
    }
    let gu = u32((f32(gid.x) + 0.5) * vp.scale);
    let gv = u32((f32(gid.y) + 0.5) * vp.scale);
    let col = gu / vp.tile;
    let m = (gv / vp.tile) * vp.cols + col;
    var c = vec3<f32>(0.1);
    var d = vec4<f32>(0.0);
    if col < vp.cols && m < vp.maps {
        let u = (m % vp.per_row) * vp.tile + gu % vp.tile;
        let v = (m / vp.per_row) * vp.tile + gv % vp.tile;
        let i = v * vp.atlas + u;
        let z = depth[i];
        let landed = keys[i] != 0u;
        d = vec4<f32>(select(0.0, z, z < EMPTY), select(0.0, 1.0, landed), f32(m), 1.0);
        if z >= EMPTY {
            c = vec3<f32>(0.0);
        } else {
            c = false_color(log_scale(z, vp.lo, vp.hi)) * select(0.5, 1.0, landed);
        }
    }
    data[gid.y * size.x + gid.x] = d;
    textureStore(dst, vec2<i32>(gid.xy), vec4<f32>(c, 1.0));
}

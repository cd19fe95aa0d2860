// Algorithm 1, step 2: per tile (one workgroup), the depth bounds of its pixels, then every
// VPL of its interleaving subset whose range sphere touches the tile's sub-frustum between
// those depths, in increasing VPL order (a deterministic list: each thread takes a
// contiguous run of candidates, counts its hits, a prefix sum places them). The list holds
// `cap` entries; `tile_count` keeps the true count, so a tile over its cap is known (the
// shading pass then tests every VPL of the subset: never a dropped light).
// Twin: reference::light_culling::{tile_lists, frustum_planes, sphere_touches}.
#include "common/camera.wgsl"
#include "methods/light_culling/lcull_common.wgsl"

@group(0) @binding(0) var<uniform> params: LcullParams;
@group(0) @binding(1) var<uniform> camera: Camera;
@group(0) @binding(2) var gb_position: texture_2d<f32>;
@group(0) @binding(3) var<storage, read> lights: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> tile_count: array<u32>;
@group(0) @binding(5) var<storage, read_write> tile_lists: array<u32>;
@group(0) @binding(6) var<storage, read_write> stats: array<atomic<u32>>;

#include "common/stats64.wgsl"

override DIAGNOSTICS: bool = true;
const WG: u32 = 256u;

var<workgroup> wg_lo: atomic<u32>;
var<workgroup> wg_hi: atomic<u32>;
var<workgroup> wg_counts: array<u32, 256>;
var<workgroup> wg_total: u32;

// Direction through screen point (px, py) in pixels (edges at integers).
fn screen_dir(px: f32, py: f32) -> vec3<f32> {
    let x = 2.0 * px * camera.resolution.z - 1.0;
    let y = 1.0 - 2.0 * py * camera.resolution.w;
    return camera.forward.xyz + x * camera.right.xyz + y * camera.up.xyz;
}

// Conservative sphere test against the tile's four side planes (through the eye) and its
// depth bounds. Twin: sphere_touches.
fn touches(planes: array<vec3<f32>, 4>, lo: f32, hi: f32, c: vec3<f32>, r: f32) -> bool {
    if r <= 0.0 {
        return false;
    }
    let v = c - camera.position.xyz;
    let d = dot(v, camera.forward.xyz);
    if d < lo - r || d > hi + r {
        return false;
    }
    for (var k = 0u; k < 4u; k++) {
        if dot(planes[k], v) < -r {
            return false;
        }
    }
    return true;
}

@compute @workgroup_size(256, 1, 1)
fn main(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let t = wid.x + wid.y * nwg.x;
    let live = t < params.tiles;
    if lid == 0u {
        atomicStore(&wg_lo, 0x7f7fffffu);
        atomicStore(&wg_hi, 0u);
    }
    workgroupBarrier();
    let per = params.tiles_x * params.tiles_y;
    let s = t / max(per, 1u);
    let tx = t % params.tiles_x;
    let ty = (t / params.tiles_x) % params.tiles_y;
    let sx = s % params.n;
    let sy = s / params.n;
    let tp = params.tile;
    for (var k = lid; k < tp * tp; k += WG) {
        let x = (tx * tp + k % tp) * params.n + sx;
        let y = (ty * tp + k / tp) * params.n + sy;
        if live && x < params.width && y < params.height {
            let g = textureLoad(gb_position, vec2<i32>(i32(x), i32(y)), 0);
            if g.w != 0.0 {
                let d = max(dot(g.xyz - camera.position.xyz, camera.forward.xyz), 0.0);
                atomicMin(&wg_lo, bitcast<u32>(d));
                atomicMax(&wg_hi, bitcast<u32>(d));
            }
        }
    }
    workgroupBarrier();
    let lo_bits = atomicLoad(&wg_lo);
    let hi_bits = atomicLoad(&wg_hi);
    let has_geometry = live && lo_bits <= hi_bits;
    let lo = bitcast<f32>(lo_bits);
    let hi = bitcast<f32>(hi_bits);

    // The side planes through the eye and the tile's screen rectangle (pixel edges).
    let x0 = f32((tx * tp) * params.n + sx);
    let y0 = f32((ty * tp) * params.n + sy);
    let x1 = f32(min((tx * tp + tp - 1u) * params.n + sx + 1u, params.width));
    let y1 = f32(min((ty * tp + tp - 1u) * params.n + sy + 1u, params.height));
    let c = array<vec3<f32>, 4>(screen_dir(x0, y0), screen_dir(x1, y0), screen_dir(x1, y1), screen_dir(x0, y1));
    let mid = screen_dir(0.5 * (x0 + x1), 0.5 * (y0 + y1));
    var planes: array<vec3<f32>, 4>;
    for (var k = 0u; k < 4u; k++) {
        let nrm = cross(c[k], c[(k + 1u) % 4u]);
        let l = length(nrm);
        var u = vec3<f32>(0.0);
        if l > 0.0 {
            u = nrm / l;
        }
        if dot(u, mid) < 0.0 {
            u = -u;
        }
        planes[k] = u;
    }

    // Candidates: the subset's VPLs (lcull_member, increasing); thread lid takes a contiguous run.
    var candidates = 0u;
    if has_geometry {
        candidates = lcull_members(params, s);
    }
    let chunk = (candidates + WG - 1u) / WG;
    let begin = min(lid * chunk, candidates);
    let end = min(begin + chunk, candidates);
    var hits = 0u;
    for (var k = begin; k < end; k++) {
        let i = lcull_member(params, s, k);
        let l = lights[2u * i];
        if touches(planes, lo, hi, l.xyz, l.w) {
            hits += 1u;
        }
    }
    wg_counts[lid] = hits;
    workgroupBarrier();
    if lid == 0u {
        var sum = 0u;
        for (var k = 0u; k < WG; k++) {
            let h = wg_counts[k];
            wg_counts[k] = sum;
            sum += h;
        }
        wg_total = sum;
    }
    workgroupBarrier();
    var at = wg_counts[lid];
    let total = wg_total;
    for (var k = begin; k < end && at < params.cap; k++) {
        let i = lcull_member(params, s, k);
        let l = lights[2u * i];
        if touches(planes, lo, hi, l.xyz, l.w) {
            tile_lists[t * params.cap + at] = i;
            at += 1u;
        }
    }
    if live && lid == 0u {
        tile_count[t] = total;
        if DIAGNOSTICS {
            // 0-1 list entries (64-bit), 2 tiles with geometry, 3 tiles over the cap,
            // 4 the longest list.
            stats_add64(0u, total);
            if has_geometry {
                atomicAdd(&stats[2], 1u);
            }
            if total > params.cap {
                atomicAdd(&stats[3], 1u);
            }
            atomicMax(&stats[4], total);
        }
    }
}

// Lightcut Interpolation's cache records (Rehfeld & Dachsbacher 2016, section 3.1), three
// entry points run in this order:
//   radius:  per pixel, the harmonic mean distance R to the geometry over `radius_rays`
//            cosine-distributed hemisphere rays (Ward's split sphere) and the reach
//            max(min(R/2, r_max_px x footprint), r_min_px x footprint) a record there would
//            have (section 3.2's clamps, the footprint the pixel's world size);
//   place:   one 16 x 16 workgroup per tile: greedily the pixel whose record adds the most
//            weight to the tile's uncovered pixels becomes a record, until every pixel's
//            summed weight reaches `coverage` or the tile holds LI_TILE_CAP records (our
//            reading of Ulbrich's tile-based placement the paper uses);
//   compact: one workgroup: the tiles' records into one list in tile order (a prefix sum),
//            at most `capacity` of them (the rest dropped and counted).
// CPU twins: `harmonic_mean_distance`, `record_radius`, `place_tile` in
// src/reference/lightcut_interpolation.rs.
#include "common/math.wgsl"
#include "common/random.wgsl"
#include "common/camera.wgsl"
#include "common/sst_node.wgsl"
#include "common/bvh.wgsl"
#include "methods/lightcut_interpolation/li_common.wgsl"

@group(0) @binding(0) var<uniform> lp: LiParams;
@group(0) @binding(1) var gb_position: texture_2d<f32>;
@group(0) @binding(2) var gb_normal: texture_2d<f32>;
@group(0) @binding(3) var<uniform> camera: Camera;
@group(0) @binding(4) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(5) var<storage, read> bvh_triangles: array<BvhTriangle>;
// Per pixel: (reach in world units, reach in pixels); 0 without geometry.
@group(0) @binding(6) var<storage, read_write> radius: array<vec2<f32>>;
@group(0) @binding(7) var<storage, read_write> tile_count: array<u32>;
// LI_TILE_CAP pixel indices per tile.
@group(0) @binding(8) var<storage, read_write> tile_recs: array<u32>;
@group(0) @binding(9) var<storage, read_write> tile_offset: array<u32>;
// The records' pixel indices.
@group(0) @binding(10) var<storage, read_write> records: array<u32>;
@group(0) @binding(11) var<storage, read_write> rec_meta: array<u32>;

fn hemisphere_dir(n: vec3<f32>, pixel: u32, i: u32, count: u32) -> vec3<f32> {
    let u1 = (f32(i) + u01(pcg_hash((pixel * 0x9e3779b9u) ^ i))) / f32(max(count, 1u));
    let u2 = fract(u01(pcg_hash(pixel ^ 0x85ebca6bu)) + f32(i) * 0.618034);
    let r = sqrt(u1);
    let phi = 2.0 * PI * u2;
    let tb = sst_basis(n);
    return normalize(tb[0] * (r * cos(phi)) + tb[1] * (r * sin(phi)) + n * sqrt(max(1.0 - u1, 0.0)));
}

@compute @workgroup_size(8, 8, 1)
fn radius_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= lp.width || gid.y >= lp.height {
        return;
    }
    let k = gid.y * lp.width + gid.x;
    let g = textureLoad(gb_position, vec2<i32>(gid.xy), 0);
    if g.w == 0.0 {
        radius[k] = vec2<f32>(0.0);
        return;
    }
    let x = g.xyz;
    let n = normalize(textureLoad(gb_normal, vec2<i32>(gid.xy), 0).xyz);
    let o = x + n * lp.ray_offset;
    var inv = 0.0;
    for (var i = 0u; i < lp.radius_rays; i++) {
        let d = hemisphere_dir(n, k, i, lp.radius_rays);
        let h = bvh_closest_hit(o, d, 1e-4, 3.0e38);
        if h.triangle != BVH_NO_HIT {
            inv += 1.0 / max(h.t, 1e-6);
        }
    }
    var harmonic = 3.4e38;
    if inv > 0.0 {
        harmonic = f32(lp.radius_rays) / inv;
    }
    let depth = max(dot(x - camera.position.xyz, camera.forward.xyz), 0.0);
    let footprint = depth * 2.0 * length(camera.up.xyz) / f32(max(lp.height, 1u));
    let reach = max(min(0.5 * harmonic, lp.r_max_px * footprint), lp.r_min_px * footprint);
    radius[k] = vec2<f32>(reach, reach / max(footprint, 1e-30));
}

// The tile's pixels for the placement.
var<workgroup> w_pos: array<vec3<f32>, 256>;
var<workgroup> w_nrm: array<vec3<f32>, 256>;
var<workgroup> w_reach: array<f32, 256>;
var<workgroup> w_acc: array<f32, 256>;
var<workgroup> w_open: array<u32, 256>;
var<workgroup> w_gain: array<f32, 256>;
var<workgroup> w_idx: array<u32, 256>;
var<workgroup> w_any: u32;

@compute @workgroup_size(256, 1, 1)
fn place_main(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) t: u32,
) {
    let tile = wid.x + wid.y * groups.x;
    if tile >= lp.tiles_x * lp.tiles_y {
        return; // the whole workgroup: uniform
    }
    let tx = tile % lp.tiles_x;
    let ty = tile / lp.tiles_x;
    let px = vec2<u32>(tx * LI_TILE + t % LI_TILE, ty * LI_TILE + t / LI_TILE);
    let inside = px.x < lp.width && px.y < lp.height;
    var valid = false;
    if inside {
        let k = px.y * lp.width + px.x;
        let g = textureLoad(gb_position, vec2<i32>(px), 0);
        valid = g.w != 0.0;
        w_pos[t] = g.xyz;
        w_nrm[t] = normalize(textureLoad(gb_normal, vec2<i32>(px), 0).xyz);
        w_reach[t] = radius[k].x;
    } else {
        w_pos[t] = vec3<f32>(0.0);
        w_nrm[t] = vec3<f32>(0.0, 0.0, 1.0);
        w_reach[t] = 0.0;
    }
    w_acc[t] = 0.0;
    w_open[t] = select(0u, 1u, valid);
    var count = 0u;
    var record = false; // this pixel is a record already (no second pick)
    loop {
        // Any pixel still uncovered?
        if t == 0u {
            w_any = 0u;
        }
        workgroupBarrier();
        if w_open[t] != 0u {
            w_any = 1u; // every writer writes the same value
        }
        workgroupBarrier();
        let any = workgroupUniformLoad(&w_any);
        if any == 0u || count >= LI_TILE_CAP {
            break;
        }
        // This pixel's gain as a record.
        var gain = 0.0;
        if valid && !record {
            let pr = w_pos[t];
            let nr = w_nrm[t];
            let rr = w_reach[t];
            for (var p = 0u; p < 256u; p++) {
                if w_open[p] != 0u {
                    gain += max(li_weight(w_pos[p], w_nrm[p], pr, nr, rr, lp.one_minus_cos_max), 0.0);
                }
            }
        }
        w_gain[t] = select(0.0, gain, valid && !record);
        w_idx[t] = select(LI_NONE, t, valid && !record && gain > 0.0);
        workgroupBarrier();
        // Argmax, ties to the lower index.
        for (var s = 128u; s > 0u; s >>= 1u) {
            if t < s {
                let og = w_gain[t + s];
                let oi = w_idx[t + s];
                let better = oi != LI_NONE && (w_idx[t] == LI_NONE || og > w_gain[t] || (og == w_gain[t] && oi < w_idx[t]));
                if better {
                    w_gain[t] = og;
                    w_idx[t] = oi;
                }
            }
            workgroupBarrier();
        }
        let best = workgroupUniformLoad(&w_idx[0]);
        if best == LI_NONE {
            break;
        }
        if t == 0u {
            let bpx = vec2<u32>(tx * LI_TILE + best % LI_TILE, ty * LI_TILE + best / LI_TILE);
            tile_recs[tile * LI_TILE_CAP + count] = bpx.y * lp.width + bpx.x;
        }
        if valid {
            w_acc[t] += max(li_weight(w_pos[t], w_nrm[t], w_pos[best], w_nrm[best], w_reach[best], lp.one_minus_cos_max), 0.0);
            // The record's own pixel is covered (its weight there is 1 up to rounding).
            if w_acc[t] >= lp.coverage || t == best {
                w_open[t] = 0u;
            }
        }
        record = record || t == best;
        count += 1u;
        workgroupBarrier();
    }
    if t == 0u {
        tile_count[tile] = count;
    }
}

var<workgroup> w_sums: array<u32, 256>;

@compute @workgroup_size(256, 1, 1)
fn compact_main(@builtin(local_invocation_index) t: u32) {
    let tiles = lp.tiles_x * lp.tiles_y;
    let chunk = (tiles + 255u) / 256u;
    let lo = min(t * chunk, tiles);
    let hi = min(lo + chunk, tiles);
    var mine = 0u;
    for (var i = lo; i < hi; i++) {
        mine += tile_count[i];
    }
    w_sums[t] = mine;
    workgroupBarrier();
    // Inclusive scan (Hillis-Steele).
    for (var s = 1u; s < 256u; s <<= 1u) {
        var v = w_sums[t];
        if t >= s {
            v += w_sums[t - s];
        }
        workgroupBarrier();
        w_sums[t] = v;
        workgroupBarrier();
    }
    let total = w_sums[255];
    var at = w_sums[t] - mine;
    workgroupBarrier();
    var dropped = 0u;
    var capped = 0u;
    for (var i = lo; i < hi; i++) {
        let c = tile_count[i];
        capped += select(0u, 1u, c >= LI_TILE_CAP);
        tile_offset[i] = at;
        for (var j = 0u; j < c; j++) {
            if at + j < lp.capacity {
                records[at + j] = tile_recs[i * LI_TILE_CAP + j];
            } else {
                dropped += 1u;
            }
        }
        at += c;
    }
    w_sums[t] = dropped | (capped << 16u);
    workgroupBarrier();
    if t == 0u {
        var d = 0u;
        var cp = 0u;
        for (var i = 0u; i < 256u; i++) {
            d += w_sums[i] & 0xffffu;
            cp += w_sums[i] >> 16u;
        }
        rec_meta[0] = min(total, lp.capacity);
        rec_meta[1] = d;
        rec_meta[2] = cp;
    }
}

// The VAL method's per-frame kernels around the shared clustering (`val_cluster.wgsl`) and
// maps (`ism.wgsl`):
//   claim_main, unique_main, seeds_main: per cluster its seed texel (in the clustering RSM,
//                `factor` times coarser): the VPLs of the clustered layer that are the first on
//                their texel, in VPL order, spread over the clusters;
//   lights_main: per VAL its map's light (centre, normal; an empty VAL splats nothing);
//   shade_main:  per pixel the VALs of its interleaving subset (section 6), each with eq. 2
//                (or as a point light) and its visibility: none, a BVH ray to the centre, a
//                simple lookup in its ISM, the PCSS lookup, or 16 rays to its disk; the sum x n^2 demodulated into
//                `raw` (the shared geometry-aware filter follows). Diagnostics per pixel:
//                mean penumbra width of the lookups that found blockers, those lookups, the
//                VALs with a non-zero term, 1.
// Twins: reference::val::{seeds_from_vpls, subset, term, pcss}, reference::ism::visible.
#include "common/math.wgsl"
#include "common/vpl.wgsl"
#include "common/vpl_visibility.wgsl"
#include "common/ism.wgsl"
#include "methods/val/val_common.wgsl"

@group(0) @binding(0) var<uniform> params: ValShadeParams;
@group(0) @binding(1) var gb_position: texture_2d<f32>;
@group(0) @binding(2) var gb_normal: texture_2d<f32>;
@group(0) @binding(3) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(4) var<storage, read> bvh_triangles: array<BvhTriangle>;
@group(0) @binding(5) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(6) var<storage, read> vals: array<Val>;
@group(0) @binding(7) var<storage, read_write> seeds: array<u32>;
@group(0) @binding(8) var<storage, read_write> ism_lights: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read_write> raw: array<vec4<f32>>;
@group(0) @binding(10) var<storage, read_write> diag: array<vec4<f32>>;
@group(0) @binding(11) var<uniform> ism: IsmParams;
@group(0) @binding(12) var<storage, read> ism_depth: array<f32>;
// Per clustering texel the inverted least VPL index on it (claim_main; cleared to 0).
@group(0) @binding(13) var<storage, read_write> claim: array<atomic<u32>>;
// The unique VPLs: [count, their indices in VPL order] (unique_main).
@group(0) @binding(14) var<storage, read_write> list: array<u32>;

override DIAGNOSTICS: bool = true;

// The seeds, three dispatches: claim_main (per VPL of the layer: its clustering texel's
// claim keeps the least VPL index, as atomicMax of ~i), unique_main (one workgroup: the VPLs
// that won their texel's claim, in VPL order, compacted into `list` = [count, indices..]),
// seeds_main (cluster j takes unique VPL j x U / clusters, or j mod U when there are fewer
// unique texels U than clusters: distinct texels spread over the VPLs).
fn seed_texel(id: u32) -> vec2<u32> {
    let i = id & 0x00ffffffu;
    let f = max(params.factor, 1u);
    return vec2<u32>((i % params.res) / f, (i / params.res) / f);
}

fn seed_claim_index(id: u32) -> u32 {
    let t = seed_texel(id);
    return t.y * max(params.res / max(params.factor, 1u), 1u) + t.x;
}

fn seed_valid(id: u32) -> bool {
    return id != VPL_NONE && (id >> 24u) == params.layer;
}

@compute @workgroup_size(64, 1, 1)
fn claim_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i >= params.count {
        return;
    }
    let id = vpls[i].id;
    if seed_valid(id) {
        atomicMax(&claim[seed_claim_index(id)], ~i);
    }
}

fn seed_unique(i: u32) -> bool {
    let id = vpls[i].id;
    return seed_valid(id) && atomicLoad(&claim[seed_claim_index(id)]) == ~i;
}

var<workgroup> chunk_sums: array<u32, 256>;

@compute @workgroup_size(256, 1, 1)
fn unique_main(@builtin(local_invocation_index) li: u32) {
    let count = params.count;
    let chunk = (count + 255u) / 256u;
    let lo = min(li * chunk, count);
    let hi = min(lo + chunk, count);
    var n = 0u;
    for (var i = lo; i < hi; i++) {
        if seed_unique(i) {
            n += 1u;
        }
    }
    chunk_sums[li] = n;
    workgroupBarrier();
    // Inclusive prefix sum over the chunks (Hillis-Steele).
    for (var off = 1u; off < 256u; off <<= 1u) {
        var v = 0u;
        if li >= off {
            v = chunk_sums[li - off];
        }
        workgroupBarrier();
        chunk_sums[li] += v;
        workgroupBarrier();
    }
    var at = chunk_sums[li] - n;
    for (var i = lo; i < hi; i++) {
        if seed_unique(i) {
            list[1u + at] = i;
            at += 1u;
        }
    }
    if li == 255u {
        list[0] = chunk_sums[255];
    }
}

@compute @workgroup_size(64, 1, 1)
fn seeds_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let j = gid.x;
    if j >= params.clusters {
        return;
    }
    let u = list[0];
    if u == 0u {
        seeds[j] = 0u;
        return;
    }
    var k = j % u;
    if u >= params.clusters {
        // floor(j x u / clusters) without overflow.
        k = j * (u / params.clusters) + (j * (u % params.clusters)) / params.clusters;
    }
    let t = seed_texel(vpls[list[1u + k]].id);
    seeds[j] = t.x | (t.y << 16u);
}

@compute @workgroup_size(64, 1, 1)
fn lights_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i >= params.clusters {
        return;
    }
    let v = vals[i];
    // Range 0 for an empty VAL: no point is within it, its map stays empty (never read).
    let r2 = select(3.0e38, 0.0, v.pixels == 0u);
    ism_lights[2u * i] = vec4<f32>(v.position, r2);
    ism_lights[2u * i + 1u] = vec4<f32>(v.normal, 0.0);
}

struct Pcss {
    visibility: f32,
    blocked: bool,
    penumbra: f32,
};

// Section 6's PCSS lookup in map m. Twin: reference::val::pcss.
fn val_pcss(m: u32, v: Val, x: vec3<f32>) -> Pcss {
    let unseen = Pcss(1.0, false, 0.0);
    let pr = ism_project(v.position, v.normal, x);
    if pr.z < 0.0 {
        return unseen;
    }
    let zr = pr.z;
    let z = dot((x - v.position) / zr, v.normal);
    let per_radian = 0.5 / (1.0 + z);
    let texel = 1.0 / f32(ism.tile);
    let rl = sqrt(max(v.area, 0.0) / PI);
    let cmp = zr * (1.0 - ism.bias);
    let max_radius = params.max_radius * texel;
    let search = clamp(per_radian * atan(rl / zr), texel, max_radius);
    var sum = 0.0;
    var nb = 0u;
    for (var i = 0u; i < params.blocker_samples; i++) {
        let d = ism_depth[ism_texel(m, pr.xy + VAL_POISSON[i] * search)];
        if d < cmp {
            sum += d;
            nb += 1u;
        }
    }
    if nb == 0u {
        return unseen;
    }
    let zb = sum / f32(nb);
    let ratio = (zr - zb) / max(zb, 1e-6);
    let radius = clamp(per_radian * atan(rl * ratio / zr), texel, max_radius);
    var lit = 0u;
    for (var i = 0u; i < params.pcf_samples; i++) {
        if cmp <= ism_depth[ism_texel(m, pr.xy + VAL_POISSON[i] * radius)] {
            lit += 1u;
        }
    }
    return Pcss(f32(lit) / f32(max(params.pcf_samples, 1u)), true, 2.0 * rl * ratio);
}

@compute @workgroup_size(8, 8, 1)
fn shade_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= params.width || gid.y >= params.height {
        return;
    }
    let k = gid.y * params.width + gid.x;
    let g = textureLoad(gb_position, vec2<i32>(gid.xy), 0);
    if g.w == 0.0 {
        raw[k] = vec4<f32>(0.0);
        if DIAGNOSTICS {
            diag[k] = vec4<f32>(0.0);
        }
        return;
    }
    let x = g.xyz;
    let nx = normalize(textureLoad(gb_normal, vec2<i32>(gid.xy), 0).xyz);
    let n = max(params.n, 1u);
    let s = gid.x % n + n * (gid.y % n);
    let c = n * n;
    var sum = vec3<f32>(0.0);
    var penumbra = 0.0;
    var blocked = 0u;
    var lit_terms = 0u;
    for (var i = val_first(params, s); i < params.clusters; i += c) {
        let v = vals[i];
        let t = val_term(v, params.as_point != 0u, params.eps, x, nx);
        if all(t == vec3<f32>(0.0)) {
            continue;
        }
        lit_terms += 1u;
        var vis = 1.0;
        switch params.visibility {
            case 1u: {
                vis = select(0.0, 1.0, vpl_visible(v.position, v.normal, x, nx, params.ray_offset));
            }
            case 2u: {
                vis = select(0.0, 1.0, ism_visible(i, v.position, v.normal, x));
            }
            case 4u: {
                // The disk's visible fraction: rays to its 16 Poisson points.
                let f = ism_basis(v.normal);
                let rl = sqrt(max(v.area, 0.0) / PI);
                var seen = 0u;
                for (var j = 0u; j < 16u; j++) {
                    let o = VAL_POISSON[j];
                    let c = v.position + (f[0] * o.x + f[1] * o.y) * rl;
                    if vpl_visible(c, v.normal, x, nx, params.ray_offset) {
                        seen += 1u;
                    }
                }
                vis = f32(seen) / 16.0;
            }
            case 3u: {
                let q = val_pcss(i, v, x);
                vis = q.visibility;
                if q.blocked {
                    blocked += 1u;
                    penumbra += q.penumbra;
                }
            }
            default: {}
        }
        sum += t * vis;
    }
    raw[k] = vec4<f32>(sum * f32(c), 1.0);
    if DIAGNOSTICS {
        diag[k] = vec4<f32>(select(0.0, penumbra / f32(blocked), blocked > 0u), f32(blocked), f32(lit_terms), 1.0);
    }
}

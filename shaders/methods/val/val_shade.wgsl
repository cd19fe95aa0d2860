// The VAL method's per-frame kernels around the shared clustering (`val_cluster.wgsl`) and
// maps (`ism.wgsl`):
//   seeds_main:  per cluster its seed texel (in the clustering RSM, `factor` times coarser)
//                from the frame's VPLs (cluster j starts at VPL j x count / clusters and takes
//                the first VPL of the clustered layer on a texel no earlier cluster took);
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
// A bit per clustering texel: taken by a seed (seeds_main).
@group(0) @binding(13) var<storage, read_write> taken: array<u32>;

override DIAGNOSTICS: bool = true;

// One thread: clusters in order, each taking the first VPL of the layer from its start whose
// clustering texel no earlier cluster took (`taken`: a bit per texel, cleared by the caller).
@compute @workgroup_size(1, 1, 1)
fn seeds_main() {
    let count = params.count;
    let f = max(params.factor, 1u);
    let cres = max(params.res / f, 1u);
    // floor(j x count / clusters) without overflow.
    let q = count / max(params.clusters, 1u);
    let r = count % max(params.clusters, 1u);
    for (var j = 0u; j < params.clusters; j++) {
        seeds[j] = 0u;
        if count == 0u {
            continue;
        }
        let start = j * q + (j * r) / params.clusters;
        var first = 0xffffffffu;
        var chosen = 0xffffffffu;
        for (var t = 0u; t < count; t++) {
            let id = vpls[(start + t) % count].id;
            if id == VPL_NONE || (id >> 24u) != params.layer {
                continue;
            }
            let i = id & 0x00ffffffu;
            let x = (i % params.res) / f;
            let y = (i / params.res) / f;
            let packed = x | (y << 16u);
            if first == 0xffffffffu {
                first = packed;
            }
            let c = y * cres + x;
            if (taken[c / 32u] & (1u << (c % 32u))) == 0u {
                taken[c / 32u] |= 1u << (c % 32u);
                chosen = packed;
                break;
            }
        }
        if chosen == 0xffffffffu {
            chosen = select(first, 0u, first == 0xffffffffu);
        }
        seeds[j] = chosen;
    }
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

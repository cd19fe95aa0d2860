// Virtual Area Lights: one k-means step of the RSM clustering (the VAL paper's section 4,
// after Prutkin et al. 2012), on one light's RSM layer:
//   map_main:      per cluster (workgroup layer z) its splat window (edge `splat` texels around
//                  its centre texel); each lit texel keeps the least key (eq. 1's mu with the
//                  low 10 mantissa bits replaced by the cluster index), stored inverted so that
//                  atomicMax keeps it and a cleared 0 means none;
//   list_main:     the lit texels no splat reached, in texel order, as the fallback list (one
//                  workgroup: a chunk of texels per thread and a scan of the chunks' counts, so
//                  the list, and the sums over it below, do not depend on thread scheduling;
//                  an atomic append made the clusters differ in the last bits from run to run);
//   fallback_main: per texel of the list, the least key over all clusters;
//   average_main:  per cluster (one workgroup) the sums over its window's texels and the
//                  fallback list's that hold its index: mean position, normalised mean normal,
//                  summed flux and surface area, pixel count; its new centre is the texel its
//                  mean position projects into when that one is lit (else the old centre);
//                  a cluster left empty keeps its centre with 0 pixels;
//   seed_main / reseed_main: clusters from their seed texels (all, before the first step;
//                  those the last step left empty, before the next one);
//   clear_main:    the keys and the fallback list before a step.
// Twin: reference::val::{map, average}.

struct ValParams {
    view_proj: mat4x4<f32>,
    light_dir: vec3<f32>,
    texel_area: f32,
    res: u32,
    clusters: u32,
    splat: u32,
    layer: u32,
    w_p: f32,
    w_n: f32,
    w_f: f32,
    extent: f32,
    area_mode: u32,     // 1: a texel's surface area is its flux's alpha (a summed-down RSM)
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

// Twin: reference::val::Val (texel packed x | y << 16).
struct Val {
    position: vec3<f32>,
    area: f32,
    normal: vec3<f32>,
    pixels: u32,
    flux: vec3<f32>,
    texel: u32,
};

@group(0) @binding(0) var<uniform> vp: ValParams;
@group(0) @binding(1) var rsm_position: texture_2d_array<f32>;
@group(0) @binding(2) var rsm_normal: texture_2d_array<f32>;
@group(0) @binding(3) var rsm_flux: texture_2d_array<f32>;
// The clusters before the step (read by map / fallback), after it (written by average).
@group(0) @binding(4) var<storage, read> vals_in: array<Val>;
@group(0) @binding(5) var<storage, read_write> vals_out: array<Val>;
// Per texel the inverted least key (0: none).
@group(0) @binding(6) var<storage, read_write> keys: array<atomic<u32>>;
// [0]: texels in the list; then the texel indices.
@group(0) @binding(7) var<storage, read_write> fallback: array<atomic<u32>>;
// Per cluster its seed texel (packed x | y << 16).
@group(0) @binding(8) var<storage, read> seeds: array<u32>;

const INDEX_BITS: u32 = 10u;

struct Texel {
    position: vec3<f32>,
    normal: vec3<f32>,
    flux: vec3<f32>,
    area: f32,
    lit: bool,
};

fn load(t: vec2<u32>) -> Texel {
    let c = vec2<i32>(t);
    let l = i32(vp.layer);
    let p = textureLoad(rsm_position, c, l, 0);
    let n = textureLoad(rsm_normal, c, l, 0).xyz;
    let f = textureLoad(rsm_flux, c, l, 0);
    let area = select(surface_area(n), f.a, vp.area_mode != 0u);
    return Texel(p.xyz, n, f.rgb, area, p.w > 0.0 && max(f.r, max(f.g, f.b)) > 0.0);
}

fn unpack_texel(t: u32) -> vec2<u32> {
    return vec2<u32>(t & 0xffffu, t >> 16u);
}

// The surface area of a texel: its area perpendicular to the light over the cosine (>= 0.05).
// Twin: Rsm::surface_area.
fn surface_area(n: vec3<f32>) -> f32 {
    return vp.texel_area / max(dot(n, -vp.light_dir), 0.05);
}

// Eq. 1 with unit-free distances. Twin: reference::val::metric.
fn metric(x: Texel, c: Val, centre_flux: vec3<f32>) -> f32 {
    let dp = length(x.position - c.position) / max(vp.extent, 1e-12);
    let dn = clamp((1.0 - dot(x.normal, c.normal)) * 0.5, 0.0, 1.0);
    let s = abs(x.flux) + abs(centre_flux);
    let sum = s.x + s.y + s.z;
    var df = 0.0;
    if sum > 0.0 {
        let d = abs(x.flux - centre_flux);
        df = (d.x + d.y + d.z) / sum;
    }
    return max(vp.w_p * dp + vp.w_n * dn + vp.w_f * df, 0.0);
}

// Twin: reference::val::key, stored inverted.
fn inverted_key(mu: f32, c: u32) -> u32 {
    let k = (bitcast<u32>(max(mu, 0.0)) & ~((1u << INDEX_BITS) - 1u)) | c;
    return ~k;
}

fn window_lo(t: u32) -> u32 {
    return select(0u, t - vp.splat / 2u, t >= vp.splat / 2u);
}

@compute @workgroup_size(8, 8, 1)
fn map_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let ci = gid.z;
    if ci >= vp.clusters {
        return;
    }
    let c = vals_in[ci];
    if c.pixels == 0u || gid.x >= vp.splat || gid.y >= vp.splat {
        return;
    }
    let centre = unpack_texel(c.texel);
    let t = vec2<u32>(window_lo(centre.x), window_lo(centre.y)) + gid.xy;
    if t.x >= vp.res || t.y >= vp.res {
        return;
    }
    let x = load(t);
    if !x.lit {
        return;
    }
    let cf = load(centre).flux;
    atomicMax(&keys[t.y * vp.res + t.x], inverted_key(metric(x, c, cf), ci));
}

const LIST_WG: u32 = 256u;
var<workgroup> s_counts: array<u32, LIST_WG>;

// Dispatched as one workgroup, after map_main. Thread `li` takes the texels
// [li * chunk, (li + 1) * chunk): it counts its unreached lit ones, the workgroup scans the
// counts, and each thread writes its texels' indices from its offset, in texel order.
@compute @workgroup_size(256, 1, 1)
fn list_main(@builtin(local_invocation_index) li: u32) {
    let n = vp.res * vp.res;
    let chunk = (n + LIST_WG - 1u) / LIST_WG;
    let lo = min(li * chunk, n);
    let hi = min(lo + chunk, n);
    var count = 0u;
    for (var i = lo; i < hi; i++) {
        if atomicLoad(&keys[i]) == 0u && load(vec2<u32>(i % vp.res, i / vp.res)).lit {
            count += 1u;
        }
    }
    s_counts[li] = count;
    workgroupBarrier();
    // Inclusive Hillis-Steele scan of the counts.
    for (var d = 1u; d < LIST_WG; d <<= 1u) {
        var add = 0u;
        if li >= d {
            add = s_counts[li - d];
        }
        workgroupBarrier();
        s_counts[li] += add;
        workgroupBarrier();
    }
    var slot = s_counts[li] - count;
    for (var i = lo; i < hi; i++) {
        if atomicLoad(&keys[i]) == 0u && load(vec2<u32>(i % vp.res, i / vp.res)).lit {
            atomicStore(&fallback[1u + slot], i);
            slot += 1u;
        }
    }
    if li == LIST_WG - 1u {
        atomicStore(&fallback[0], s_counts[li]);
    }
}

// Per texel of the fallback list (after list_main): its key, the least over all clusters.
@compute @workgroup_size(64, 1, 1)
fn fallback_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nw: vec3<u32>) {
    let k = gid.x + gid.y * nw.x * 64u;
    if k >= atomicLoad(&fallback[0]) {
        return;
    }
    let i = atomicLoad(&fallback[1u + k]);
    let x = load(vec2<u32>(i % vp.res, i / vp.res));
    var best = 0u;
    for (var ci = 0u; ci < vp.clusters; ci++) {
        let c = vals_in[ci];
        if c.pixels == 0u {
            continue;
        }
        best = max(best, inverted_key(metric(x, c, load(unpack_texel(c.texel)).flux), ci));
    }
    atomicStore(&keys[i], best);
}

// A cluster seeded at texel t (packed): its attributes, one pixel. Twin: reference::val::seed.
fn seed_val(t: u32) -> Val {
    let x = load(unpack_texel(t));
    return Val(x.position, x.area, x.normal, 1u, x.flux, t);
}

// Every cluster from its seed (the first step's input: vals_out).
@compute @workgroup_size(64, 1, 1)
fn seed_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x < vp.clusters {
        vals_out[gid.x] = seed_val(seeds[gid.x]);
    }
}

// Before a step after the first: a cluster left without texels is re-seeded (the paper
// re-initialises it); the caller binds the step's input as vals_out.
@compute @workgroup_size(64, 1, 1)
fn reseed_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x < vp.clusters && vals_out[gid.x].pixels == 0u {
        vals_out[gid.x] = seed_val(seeds[gid.x]);
    }
}

@compute @workgroup_size(64, 1, 1)
fn clear_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nw: vec3<u32>) {
    let i = gid.x + gid.y * nw.x * 64u;
    if i < vp.res * vp.res {
        atomicStore(&keys[i], 0u);
    }
    if i == 0u {
        atomicStore(&fallback[0], 0u);
    }
}

// Twin: Rsm::texel_of (None: 0xffffffff).
fn val_texel_of(p: vec3<f32>) -> u32 {
    let c = vp.view_proj * vec4<f32>(p, 1.0);
    let u = floor((c.x / c.w * 0.5 + 0.5) * f32(vp.res));
    let v = floor((0.5 - c.y / c.w * 0.5) * f32(vp.res));
    if u < 0.0 || v < 0.0 || u >= f32(vp.res) || v >= f32(vp.res) {
        return 0xffffffffu;
    }
    return u32(u) | (u32(v) << 16u);
}

const AVG_WG: u32 = 64u;
var<workgroup> s_position: array<vec3<f32>, AVG_WG>;
var<workgroup> s_normal: array<vec3<f32>, AVG_WG>;
var<workgroup> s_flux: array<vec3<f32>, AVG_WG>;
var<workgroup> s_area: array<f32, AVG_WG>;
var<workgroup> s_pixels: array<u32, AVG_WG>;

@compute @workgroup_size(64, 1, 1)
fn average_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let ci = wg.x;
    // workgroup_id is uniform: every thread of the group takes the same branches below.
    let old = vals_in[min(ci, vp.clusters - 1u)];
    var position = vec3<f32>(0.0);
    var normal = vec3<f32>(0.0);
    var flux = vec3<f32>(0.0);
    var area = 0.0;
    var pixels = 0u;
    if ci < vp.clusters && old.pixels > 0u {
        // Its window's texels, then the fallback's (any cluster may have some; no window
        // reaches them), as one index range.
        let centre = unpack_texel(old.texel);
        let lo = vec2<u32>(window_lo(centre.x), window_lo(centre.y));
        let window = vp.splat * vp.splat;
        let total = window + atomicLoad(&fallback[0]);
        for (var k = li; k < total; k += AVG_WG) {
            var t = lo + vec2<u32>(k % vp.splat, k / vp.splat);
            if k >= window {
                let i = atomicLoad(&fallback[1u + k - window]);
                t = vec2<u32>(i % vp.res, i / vp.res);
            }
            if t.x >= vp.res || t.y >= vp.res {
                continue;
            }
            let key = atomicLoad(&keys[t.y * vp.res + t.x]);
            if key == 0u || ((~key) & ((1u << INDEX_BITS) - 1u)) != ci {
                continue;
            }
            let x = load(t);
            position += x.position;
            normal += x.normal;
            flux += x.flux;
            area += x.area;
            pixels += 1u;
        }
    }
    s_position[li] = position;
    s_normal[li] = normal;
    s_flux[li] = flux;
    s_area[li] = area;
    s_pixels[li] = pixels;
    workgroupBarrier();
    for (var stride = AVG_WG / 2u; stride > 0u; stride >>= 1u) {
        if li < stride {
            s_position[li] += s_position[li + stride];
            s_normal[li] += s_normal[li + stride];
            s_flux[li] += s_flux[li + stride];
            s_area[li] += s_area[li + stride];
            s_pixels[li] += s_pixels[li + stride];
        }
        workgroupBarrier();
    }
    if li != 0u || ci >= vp.clusters {
        return;
    }
    let count = s_pixels[0];
    if count == 0u {
        var v = old;
        v.pixels = 0u;
        vals_out[ci] = v;
        return;
    }
    let mean = s_position[0] / f32(count);
    var texel = val_texel_of(mean);
    if texel == 0xffffffffu || !load(unpack_texel(texel)).lit {
        texel = old.texel;
    }
    let ln = length(s_normal[0]);
    var nrm = old.normal;
    if ln > 0.0 {
        nrm = s_normal[0] / ln;
    }
    vals_out[ci] = Val(mean, s_area[0], nrm, count, s_flux[0], texel);
}

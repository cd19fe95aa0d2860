// Converged reference (stage 19): one-bounce indirect light with EVERY RSM texel as a VPL,
// estimated per pixel by Monte Carlo and accumulated over frames:
//   L(x) = sum_t rho_x / pi x flux_t / pi x cos_x x cos_t / max(d^2, eps^2) x V(x, t)
// Each sample picks a light (in proportion to its flux), then descends that light's RSM
// pyramid from the top, choosing among the 4 children in proportion to
//   W(child) = [(1 - m) importance share + m flux share] x B(child, x),
// B = the average clamped cosine to the child box's corners (thesis eq. 5.2) / max(d_min^2,
// eps^2), 0 only if every corner is behind x's tangent plane (then every texel below has
// cos_x <= 0); at the texel level B is the exact unoccluded G. With m > 0 every texel that can
// contribute has a non-zero probability, so the estimator f / pmf is unbiased.
// CPU twin: src/reference/gi.rs (exact sum over all texels).
#include "common/math.wgsl"
#include "common/vpl_visibility.wgsl"
#include "common/color.wgsl"
#include "common/random.wgsl"
#include "common/vpl.wgsl"
#include "common/rsm_pyramid.wgsl"
#include "common/box_term.wgsl"
#include "common/brdf.wgsl"

struct RefParams {
    width: u32,
    height: u32,
    samples: u32,       // samples per pixel in this dispatch
    first_sample: u32,  // index of the first (for the random numbers)
    epsilon: f32,
    ray_offset: f32,
    flux_mix: f32,      // m above (> 0)
    seed: u32,
    brdf: u32,          // BRDF_LAMBERT (rho / pi, factored out) or BRDF_GGX (per sample)
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    eye: vec4<f32>,     // xyz camera position
};

// The shading point's view direction and material (glossy shading).
struct Shading {
    v: vec3<f32>,
    metallic: f32,
    base: vec3<f32>,
    roughness: f32,
};

@group(0) @binding(0) var<uniform> params: VplParams;
@group(0) @binding(1) var<uniform> rp: RefParams;
@group(0) @binding(2) var rsm_position: texture_2d_array<f32>;
@group(0) @binding(3) var rsm_normal: texture_2d_array<f32>;
@group(0) @binding(4) var rsm_flux: texture_2d_array<f32>;
@group(0) @binding(5) var gb_position: texture_2d<f32>;
@group(0) @binding(6) var gb_normal: texture_2d<f32>;
@group(0) @binding(7) var gb_albedo: texture_2d<f32>;
@group(0) @binding(8) var<storage, read> importance_pyramid: array<f32>;
@group(0) @binding(9) var<storage, read> flux_pyramid: array<f32>;
@group(0) @binding(10) var<storage, read> bounds_pyramid: array<vec4<f32>>;
@group(0) @binding(11) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(12) var<storage, read> bvh_triangles: array<BvhTriangle>;
@group(0) @binding(13) var<storage, read_write> accum: array<vec4<f32>>;

// Geometric weight B of a pyramid node for surface point x with normal n. Levels >= 1: the
// thesis's eq. 5.2 average clamped cosine towards the box's 8 corners over
// max(d_min^2, eps^2) - positive whenever any corner is in front of x, which is whenever any
// texel below can contribute, so every contributing texel keeps a non-zero probability.
// Level 0 (single texels): the exact unoccluded G = cos_x cos_t / max(d^2, eps^2).
fn box_bound(layer: u32, level: u32, nx: u32, ny: u32, x: vec3<f32>, n: vec3<f32>) -> f32 {
    if level == 0u {
        let t = vec2<i32>(vec2<u32>(nx, ny));
        let p = textureLoad(rsm_position, t, i32(layer), 0);
        if p.w == 0.0 {
            return 0.0;
        }
        let tn = normalize(textureLoad(rsm_normal, t, i32(layer), 0).xyz);
        return vpl_geometry(p.xyz, tn, x, n, rp.epsilon);
    }
    let b = bounds_index(layer, level, nx, ny);
    let lo = bounds_pyramid[2u * b].xyz;
    let hi = bounds_pyramid[2u * b + 1u].xyz;
    if lo.x > hi.x {
        return 0.0;
    }
    // Zero when every corner is behind or on x's tangent plane: no texel below contributes.
    return box_term(lo, hi, x, n, rp.epsilon);
}

fn node_w(layer: u32, level: u32, x: u32, y: u32, wi: f32, wf: f32, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let k = pyr_index(layer, level, x, y);
    return (wi * importance_pyramid[k] + wf * flux_pyramid[k]) * box_bound(layer, level, x, y, p, n);
}

// One sample: returns f / pmf (rgb, without rho/pi).
fn sample_once(rng: ptr<function, Rng>, p: vec3<f32>, n: vec3<f32>, sh: Shading) -> vec3<f32> {
    // Light choice in proportion to its flux.
    var total = 0.0;
    for (var l = 0u; l < params.light_count; l++) {
        total += flux_pyramid[pyr_index(l, params.levels - 1u, 0u, 0u)];
    }
    if !(total > 0.0) {
        return vec3<f32>(0.0);
    }
    var u = rng_next(rng) * total;
    var layer = 0u;
    var p_light = 0.0;
    for (var l = 0u; l < params.light_count; l++) {
        let f = flux_pyramid[pyr_index(l, params.levels - 1u, 0u, 0u)];
        if u < f || l + 1u == params.light_count {
            layer = l;
            p_light = f / total;
            break;
        }
        u -= f;
    }
    let top = pyr_index(layer, params.levels - 1u, 0u, 0u);
    let ti = importance_pyramid[top];
    let tf = flux_pyramid[top];
    var m = rp.flux_mix;
    if !(ti > 0.0) {
        m = 1.0;
    }
    let wi = select(0.0, (1.0 - m) / ti, ti > 0.0);
    let wf = m / tf;
    var x = 0u;
    var y = 0u;
    var pmf = p_light;
    for (var lv = params.levels - 1u; lv > 0u; lv--) {
        let cl = lv - 1u;
        let w0 = node_w(layer, cl, 2u * x, 2u * y, wi, wf, p, n);
        let w1 = node_w(layer, cl, 2u * x + 1u, 2u * y, wi, wf, p, n);
        let w2 = node_w(layer, cl, 2u * x, 2u * y + 1u, wi, wf, p, n);
        let w3 = node_w(layer, cl, 2u * x + 1u, 2u * y + 1u, wi, wf, p, n);
        let sum = w0 + w1 + w2 + w3;
        if !(sum > 0.0) {
            return vec3<f32>(0.0);
        }
        let r = rng_next(rng) * sum;
        var c = 3u;
        var wc = w3;
        if r < w0 {
            c = 0u;
            wc = w0;
        } else if r < w0 + w1 {
            c = 1u;
            wc = w1;
        } else if r < w0 + w1 + w2 {
            c = 2u;
            wc = w2;
        }
        if !(wc > 0.0) {
            return vec3<f32>(0.0);
        }
        pmf *= wc / sum;
        x = 2u * x + (c & 1u);
        y = 2u * y + (c >> 1u);
    }
    let t = vec2<i32>(vec2<u32>(x, y));
    let tp = textureLoad(rsm_position, t, i32(layer), 0);
    if tp.w == 0.0 {
        return vec3<f32>(0.0);
    }
    let tn = normalize(textureLoad(rsm_normal, t, i32(layer), 0).xyz);
    let flux = textureLoad(rsm_flux, t, i32(layer), 0).rgb;
    let g = vpl_geometry(tp.xyz, tn, p, n, rp.epsilon);
    if g <= 0.0 || !vpl_visible(tp.xyz, tn, p, n, rp.ray_offset) {
        return vec3<f32>(0.0);
    }
    if rp.brdf == BRDF_LAMBERT {
        return flux / PI * g / pmf;
    }
    let l = normalize(tp.xyz - p);
    return brdf_eval(rp.brdf, n, sh.v, l, sh.base, sh.metallic, sh.roughness) * flux / PI * g / pmf;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= rp.width || gid.y >= rp.height {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let g = textureLoad(gb_position, px, 0);
    if g.w == 0.0 {
        return;
    }
    let nr = textureLoad(gb_normal, px, 0);
    let n = normalize(nr.xyz);
    let albedo = textureLoad(gb_albedo, px, 0);
    let sh = Shading(normalize(rp.eye.xyz - g.xyz), albedo.a, albedo.rgb, nr.w);
    let k = gid.y * rp.width + gid.x;
    var sum = vec3<f32>(0.0);
    for (var s = 0u; s < rp.samples; s++) {
        var rng = rng_new(k, rp.first_sample + s, rp.seed ^ 0x5bd1e995u);
        sum += sample_once(&rng, g.xyz, n, sh);
    }
    if rp.brdf == BRDF_LAMBERT {
        sum *= albedo.rgb / PI;
    }
    accum[k] += vec4<f32>(sum, 0.0);
}

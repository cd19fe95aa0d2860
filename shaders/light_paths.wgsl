// Multi-bounce VPLs by light paths (instant radiosity, Keller 1997; the SST paper's VPL
// generation, section 5: "we start by probabilistic sampling of the original light sources
// according to their size and flux ... at every hit, we generate a new VPL ... cosine-weighted
// sampling for the next bounce direction and early path termination via Russian Roulette").
//
// A path starts where the sun's light first lands: an RSM texel drawn in proportion to its
// reflected flux (the RSM is the sun's first segment, rasterised; drawing texels by flux is
// tracing the sun's rays by power: the SST paper's choice, `vpl.path_flux_mix = 1`), or by a
// mix with bounce 1's BRSM importance (`path_flux_mix` < 1: fewer paths start where their
// light leaves the scene unseen, e.g. on a sunlit roof). Its flux is the texel's reflected
// flux / (paths x pmf): the sum over a light's paths is an unbiased estimate of the light's
// reflected power for any mix above 0. From
// there each thread traces one path through the BVH:
//   direction: cosine-weighted about the vertex's normal (pdf cos / pi); the vertex is a
//     diffuse emitter of intensity flux / pi x cos, so the flux arriving along the sampled
//     direction is flux x (cos / pi) / (cos / pi) = flux;
//   at the hit (common/surface.wgsl): the reflected flux is flux x albedo (Lambert);
//   Russian roulette (optional): continue with q = min(1, max(albedo)) and divide by q;
//   the vertex of bounce b becomes VPL slot first + (b - 2) x paths + p.
// A miss, a dead end or the roulette empties the path's remaining slots (VPL_NONE).
// The frame's bounce-1 VPLs (BRSM, vpl_gen.wgsl) stay separate: bounce b >= 2 light reaches
// the image only through these VPLs. CPU twin: src/reference/light_paths.rs.
#include "common/math.wgsl"
#include "common/random.wgsl"
#include "common/vpl.wgsl"
#include "common/rsm_pyramid.wgsl"
#include "common/rsm_warp.wgsl"
#include "common/bvh.wgsl"
#include "common/material.wgsl"
#include "common/surface.wgsl"

struct PathParams {
    paths: u32,        // light paths this dispatch
    first: u32,        // VPL slot of bounce 2's first path
    bounces: u32,      // deepest bounce that gets a VPL (>= 2)
    roulette: u32,     // 1 Russian roulette, 0 every path runs to `bounces`
    seed: u32,
    ray_offset: f32,   // metres, along the vertex's geometric normal
    lod: u32,          // mip level of the hit surfaces' albedo
    flux_scale: f32,   // every VPL's flux x this (the converged reference weights its frames)
    light_count: u32,
    flux_mix: f32,     // share of the start PDF that follows flux (1: flux only), else BRSM importance
    _pad1: u32,
    _pad2: u32,
    ranges: array<vec4<u32>, 4>, // per light: x first path, y path count
};

// Group 0: what the starts read (the trace never binds it).
@group(0) @binding(0) var<uniform> params: VplParams;
@group(0) @binding(1) var rsm_position: texture_2d_array<f32>;
@group(0) @binding(2) var rsm_normal: texture_2d_array<f32>;
@group(0) @binding(3) var rsm_flux: texture_2d_array<f32>;
@group(0) @binding(4) var<storage, read> importance_pyramid: array<f32>;
@group(0) @binding(5) var<storage, read> flux_pyramid: array<f32>;
// Group 1: the paths (a test binds only this group and writes the starts itself).
@group(1) @binding(0) var<uniform> pp: PathParams;
@group(1) @binding(1) var<storage, read_write> starts: array<Vpl>;
@group(1) @binding(2) var<storage, read_write> vpls: array<Vpl>;
@group(1) @binding(3) var<storage, read> bvh_nodes: array<BvhNode>;
@group(1) @binding(4) var<storage, read> bvh_triangles: array<BvhTriangle>;
@group(1) @binding(5) var<storage, read> scene_vertices: array<u32>;
@group(1) @binding(6) var<storage, read> scene_indices: array<u32>;
@group(1) @binding(7) var<storage, read> materials: array<MaterialGpu>;
@group(1) @binding(8) var textures: texture_2d_array<f32>;
// material.wgsl's fragment-shader sampling names it; this shader never samples.
@group(1) @binding(9) var tex_sampler: sampler;

fn empty_vpl() -> Vpl {
    var v: Vpl;
    v.position = vec4<f32>(0.0);
    v.normal = vec3<f32>(0.0, 0.0, 1.0);
    v.id = VPL_NONE;
    v.flux = vec4<f32>(0.0);
    return v;
}

// Rotation of light `layer`'s Hammersley set of path starts (twin: `path_rotation`).
fn path_rotation(layer: u32) -> vec2<f32> {
    let s = pp.seed * 2u + layer * 0x51ed27u;
    return vec2<f32>(u01(pcg_hash(s ^ 0x68e31da4u)), u01(pcg_hash((s + 1u) ^ 0x68e31da4u)));
}

// One thread per path: its start, an RSM texel drawn by reflected flux.
@compute @workgroup_size(64, 1, 1)
fn path_starts(@builtin(global_invocation_id) gid: vec3<u32>) {
    let p = gid.x;
    if p >= pp.paths {
        return;
    }
    let layer = range_layer(p, pp.ranges, pp.light_count);
    let rg = pp.ranges[layer];
    let n = max(rg.y, 1u);
    var v = empty_vpl();
    // As the bounce-1 warp mixes them (flux share pp.flux_mix); pmf 0 without flux.
    let w = warp_mixed(layer, hammersley(p - rg.x, n, path_rotation(layer)), pp.flux_mix);
    let pmf = bitcast<f32>(w.z);
    let t = vec2<i32>(w.xy);
    let pos = textureLoad(rsm_position, t, i32(layer), 0);
    if pos.w > 0.0 && pmf > 0.0 {
        v.position = vec4<f32>(pos.xyz, pmf);
        v.normal = normalize(textureLoad(rsm_normal, t, i32(layer), 0).xyz);
        v.id = (layer << 24u) | (w.y * params.res + w.x);
        v.flux = vec4<f32>(textureLoad(rsm_flux, t, i32(layer), 0).rgb / (f32(n) * pmf), 1.0);
    }
    starts[p] = v;
}

// An orthonormal basis around unit n (Duff et al. 2017); twin: `onb`.
fn path_onb(n: vec3<f32>) -> mat3x3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    let t = vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let bt = vec3<f32>(b, s + n.y * n.y * a, -n.y);
    return mat3x3<f32>(t, bt, n);
}

// Cosine-weighted direction about n from (u1, u2); twin: `cosine_direction`.
fn cosine_direction(n: vec3<f32>, u1: f32, u2: f32) -> vec3<f32> {
    let r = sqrt(u1);
    let phi = 2.0 * PI * u2;
    let f = path_onb(n);
    return normalize(f * vec3<f32>(r * cos(phi), r * sin(phi), sqrt(max(1.0 - u1, 0.0))));
}

// One thread per path: bounces 2 ..= pp.bounces from its start.
@compute @workgroup_size(64, 1, 1)
fn trace_paths(@builtin(global_invocation_id) gid: vec3<u32>) {
    let p = gid.x;
    if p >= pp.paths {
        return;
    }
    let start = starts[p];
    var alive = start.id != VPL_NONE;
    var x = start.position.xyz;
    var n = start.normal;
    // The RSM stores the shading normal only: it stands in for the geometric one at the start.
    var ng = start.normal;
    var flux = start.flux.rgb * pp.flux_scale;
    var rng = rng_new(p, pp.seed, 0x2545f491u);
    for (var b = 2u; b <= pp.bounces; b++) {
        let slot = pp.first + (b - 2u) * pp.paths + p;
        if !alive {
            vpls[slot] = empty_vpl();
            continue;
        }
        let u1 = rng_next(&rng);
        let u2 = rng_next(&rng);
        let u3 = rng_next(&rng);
        let dir = cosine_direction(n, u1, u2);
        alive = dot(dir, ng) > 0.0;
        var s: Surface;
        if alive {
            let h = bvh_closest_hit(x + ng * pp.ray_offset, dir, 0.0, 3.0e38);
            alive = h.triangle != BVH_NO_HIT;
            if alive {
                s = surface_at(h.triangle, h.u, h.v, dir, pp.lod);
                alive = s.valid != 0u;
            }
        }
        if alive {
            flux *= s.albedo;
            if pp.roulette != 0u {
                let q = min(1.0, max(max(s.albedo.x, s.albedo.y), s.albedo.z));
                alive = u3 < q;
                flux /= max(q, 1e-30);
            }
            alive = alive && max(max(flux.x, flux.y), flux.z) > 0.0;
        }
        if !alive {
            vpls[slot] = empty_vpl();
            continue;
        }
        var v: Vpl;
        v.position = vec4<f32>(s.position, start.position.w);
        v.normal = s.normal;
        v.id = vpl_path_id(b, p);
        v.flux = vec4<f32>(flux, 1.0);
        vpls[slot] = v;
        x = s.position;
        n = s.normal;
        ng = s.geometric_normal;
    }
}

// Stochastic Light Culling (Tokuyoshi & Harada 2016) and its clamped baseline: what every
// pass shares. CPU twin: src/reference/light_culling.rs.
#include "common/random.wgsl"

struct LcullParams {
    width: u32,
    height: u32,
    tile: u32,          // tile edge (pixels of the de-interleaved image)
    n: u32,             // interleaving pattern edge (1 = off)
    tiles_x: u32,       // tiles per subset, x
    tiles_y: u32,
    tiles: u32,         // all tiles: tiles_x x tiles_y x n^2
    cap: u32,           // list entries per tile (the tree variant: its reservoir's k)
    count: u32,         // VPLs of the frame (N)
    offset: u32,        // the frame's interleaving offset
    seed: u32,          // the frame's xi seed
    mode: u32,          // 0 stochastic (eqs. 1-3, 6), 1 clamped (appendix A), 2 tree (section 5)
    epsilon_max: f32,
    exposure: f32,      // E = 2^display.exposure_ev
    eps: f32,           // gi.distance_epsilon: f(l) = 1 / max(l^2, eps^2)
    ray_offset: f32,
    shadow_rays: u32,   // visibility: 0 none, 1 BVH shadow rays, 2 imperfect shadow maps
    stride: u32,        // runs of `stride` consecutive VPLs share an interleaving subset
    leaves: u32,        // the tree variant: leaves of the light tree (a power of two)
    ism_flags: u32,     // bit 0: write the VPLs' ISM lights; bit 1: section 4.3's range culling
    brdf: u32,          // BRDF_LAMBERT / BRDF_GGX (common/brdf.wgsl): the shading's
    pad0: u32,
    pad1: u32,
    pad2: u32,
    eye: vec4<f32>,     // xyz the camera's position (the glossy BRDF's view direction)
};

const LCULL_RANGE_INF: f32 = 1e30;

// xi_i (section 3.1): one uniform number per VPL per frame, shared by every pixel.
// Twin: reference::light_culling::xi.
fn lcull_xi(seed: u32, i: u32) -> f32 {
    return u01(pcg_hash(seed ^ pcg_hash(i ^ 0x6c8e9cf5u)));
}

// f(l) > threshold ? max(floor, f(l)) : 0 with f(l) = 1 / max(l^2, eps^2): eq. 2 for the
// stochastic ranges (threshold alpha xi, floor alpha), the cut-off for the clamped ones
// (threshold 1 / r^2, floor 0). Twin: Falloff::eval.
fn lcull_falloff(l2: f32, eps: f32, threshold: f32, floor_: f32) -> f32 {
    let f = 1.0 / max(l2, eps * eps);
    if f > threshold {
        return max(f, floor_);
    }
    return 0.0;
}

// The tile of pixel (x, y). Twin: TileGrid::tile_of.
fn lcull_tile_of(p: LcullParams, x: u32, y: u32) -> u32 {
    let s = x % p.n + p.n * (y % p.n);
    let dx = x / p.n / p.tile;
    let dy = y / p.n / p.tile;
    return s * p.tiles_x * p.tiles_y + dy * p.tiles_x + dx;
}

// The k-th VPL of interleaving subset s (increasing in k): VPL i is in subset
// ((i / stride) mod n^2 + offset) mod n^2. Twin: Interleave::member.
fn lcull_member(p: LcullParams, s: u32, k: u32) -> u32 {
    let c = p.n * p.n;
    let j = (s + c - p.offset % c) % c;
    return (k / p.stride) * p.stride * c + j * p.stride + k % p.stride;
}

// How many of the frame's VPLs subset s holds. Twin: Interleave::members.
fn lcull_members(p: LcullParams, s: u32) -> u32 {
    let c = p.n * p.n;
    let j = (s + c - p.offset % c) % c;
    let block = p.stride * c;
    let full = p.count / block;
    let rem = p.count - full * block;
    var last = 0u;
    if rem > j * p.stride {
        last = min(rem - j * p.stride, p.stride);
    }
    return full * p.stride + last;
}

// The VPL's light for its imperfect shadow map (ism_flags bit 0; `renderer::passes::ism`'s
// layout: (position, squared range: the splat's cut-off; +inf without section 4.3's range
// culling), (normal, 0)).
fn lcull_ism_light(p: LcullParams, position: vec3<f32>, normal: vec3<f32>, range: f32) -> array<vec4<f32>, 2> {
    // A VPL without range (0: it lights nothing) splats nothing either way.
    var r2 = 3.0e38;
    if range <= 0.0 || ((p.ism_flags & 2u) != 0u && range < LCULL_RANGE_INF) {
        r2 = range * range;
    }
    return array<vec4<f32>, 2>(vec4<f32>(position, r2), vec4<f32>(normal, 0.0));
}

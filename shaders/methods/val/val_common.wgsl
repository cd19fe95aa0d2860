// Virtual Area Lights (Weinzierl-Heigl, "Efficient VAL-based Real-Time Global Illumination"):
// what the method's passes share. CPU twin: src/reference/val.rs.

// Twin: `GpuValShadeParams` in src/methods/val/pass.rs.
struct ValShadeParams {
    width: u32,
    height: u32,
    n: u32,              // interleaving pattern edge (1 = off)
    offset: u32,         // the frame's interleaving offset
    clusters: u32,       // VALs
    as_point: u32,       // 1: every VAL shaded as a point light (the VPL-shading mode)
    visibility: u32,     // 0 none, 1 BVH ray to the centre, 2 simple ISM lookup, 3 PCSS lookup, 4 rays to the disk
    count: u32,          // the frame's VPLs (seeds)
    eps: f32,            // gi.distance_epsilon (the point-light mode's clamp)
    ray_offset: f32,
    blocker_samples: u32,
    pcf_samples: u32,
    max_radius: f32,     // the PCSS filter's largest radius, texels
    res: u32,            // RSM resolution (seeds)
    layer: u32,          // the RSM layer clustered (light 0)
    inspect: u32,        // the VAL of the "ISM vs true map" view
    factor: u32,         // RSM texels per clustering texel edge (seeds)
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

// Twin: `Val` in val_cluster.wgsl (reference::val::Val).
struct Val {
    position: vec3<f32>,
    area: f32,
    normal: vec3<f32>,
    pixels: u32,
    flux: vec3<f32>,
    texel: u32,
};

// Twin: reference::val::POISSON.
const VAL_POISSON = array<vec2<f32>, 16>(
    vec2<f32>(-0.94201624, -0.39906216),
    vec2<f32>(0.94558609, -0.76890725),
    vec2<f32>(-0.094184101, -0.92938870),
    vec2<f32>(0.34495938, 0.29387760),
    vec2<f32>(-0.91588581, 0.45771432),
    vec2<f32>(-0.81544232, -0.87912464),
    vec2<f32>(-0.38277543, 0.27676845),
    vec2<f32>(0.97484398, 0.75648379),
    vec2<f32>(0.44323325, -0.97511554),
    vec2<f32>(0.53742981, -0.47373420),
    vec2<f32>(-0.26496911, -0.41893023),
    vec2<f32>(0.79197514, 0.19090188),
    vec2<f32>(-0.24188840, 0.99706507),
    vec2<f32>(-0.81409955, 0.91437590),
    vec2<f32>(0.19984126, 0.78641367),
    vec2<f32>(0.14383161, -0.14100790));

// The first VAL of pixel subset s and the stride to the next (section 6: VAL v shades tile
// (v + offset) mod n^2). Twin: reference::val::subset.
fn val_first(p: ValShadeParams, s: u32) -> u32 {
    let c = p.n * p.n;
    return (s + c - p.offset % c) % c;
}

// VAL v's light at x without albedo / pi: flux / pi x eq. 2's form factor, or the point
// light's term. Twin: reference::val::term.
fn val_term(v: Val, as_point: bool, eps: f32, x: vec3<f32>, nx: vec3<f32>) -> vec3<f32> {
    let d = v.position - x;
    let d2 = dot(d, d);
    if v.pixels == 0u || d2 <= 0.0 {
        return vec3<f32>(0.0);
    }
    let w = d * inverseSqrt(d2);
    let cx = dot(nx, w);
    let cc = -dot(v.normal, w);
    if cx <= 0.0 || cc <= 0.0 {
        return vec3<f32>(0.0);
    }
    var denom = d2 + v.area / PI;
    if as_point {
        denom = max(d2, eps * eps);
    }
    return v.flux / PI * (cx * cc / denom);
}

// Ground truth (the thesis's reference, chapter 7): every VPL of the frame evaluated at every
// pixel with a BVH shadow ray, accumulated batch by batch (VPLs [begin, end) per dispatch) so
// that no dispatch runs long:
//   L(x) = rho_x / pi x sum_v flux_v / pi x cos_x x cos_v / max(d^2, eps^2) x V(x, v)
// CPU twin: src/reference/gi.rs.
#include "common/bvh.wgsl"
#include "common/vpl.wgsl"

const PI_G: f32 = 3.14159265358979;

struct GtParams {
    begin: u32,
    end: u32,
    width: u32,
    height: u32,
    epsilon: f32,
    ray_offset: f32,
    _pad0: u32,
    _pad1: u32,
};

@group(0) @binding(0) var<uniform> params: GtParams;
@group(0) @binding(1) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(2) var<storage, read> bvh_triangles: array<BvhTriangle>;
@group(0) @binding(3) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(4) var gb_position: texture_2d<f32>;
@group(0) @binding(5) var gb_normal: texture_2d<f32>;
@group(0) @binding(6) var gb_albedo: texture_2d<f32>;
@group(0) @binding(7) var<storage, read_write> accum: array<vec4<f32>>;

// Unoccluded-or-not contribution of VPL v to point x (normal nx), without the albedo/pi.
fn vpl_irradiance_term(v: Vpl, x: vec3<f32>, nx: vec3<f32>) -> vec3<f32> {
    if v.id == VPL_NONE {
        return vec3<f32>(0.0);
    }
    let d = v.position.xyz - x;
    let dist2 = dot(d, d);
    let w = d * inverseSqrt(max(dist2, 1e-30));
    let cx = dot(nx, w);
    let cv = -dot(v.normal, w);
    if cx <= 0.0 || cv <= 0.0 {
        return vec3<f32>(0.0);
    }
    let o = x + nx * params.ray_offset;
    let e = v.position.xyz + v.normal * params.ray_offset;
    if bvh_any_hit(o, e - o, 1e-4, 1.0 - 1e-4) {
        return vec3<f32>(0.0);
    }
    return v.flux.rgb / PI_G * (cx * cv / max(dist2, params.epsilon * params.epsilon));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= params.width || gid.y >= params.height {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let g = textureLoad(gb_position, px, 0);
    if g.w == 0.0 {
        return;
    }
    let nx = normalize(textureLoad(gb_normal, px, 0).xyz);
    let albedo = textureLoad(gb_albedo, px, 0).rgb;
    var sum = vec3<f32>(0.0);
    for (var i = params.begin; i < params.end; i++) {
        sum += vpl_irradiance_term(vpls[i], g.xyz, nx);
    }
    let k = gid.y * params.width + gid.x;
    accum[k] += vec4<f32>(albedo / PI_G * sum, 0.0);
}

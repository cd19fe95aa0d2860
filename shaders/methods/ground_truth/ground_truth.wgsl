// Ground truth (the thesis's reference, chapter 7): every VPL of the frame evaluated at every
// pixel with a BVH shadow ray, accumulated batch by batch (VPLs [begin, end) per dispatch) so
// that no dispatch runs long:
//   L(x) = sum_v f(v_x, l_v) x flux_v / pi x cos_x x cos_v / max(d^2, eps^2) x V(x, v)
// with f the frame's BRDF (common/brdf.wgsl; Lambert: rho_x / pi, factored out of the sum).
// CPU twin: src/reference/gi.rs.
#include "common/math.wgsl"
#include "common/vpl.wgsl"
#include "common/vpl_visibility.wgsl"
#include "common/brdf.wgsl"

struct GtParams {
    begin: u32,
    end: u32,
    width: u32,
    height: u32,
    epsilon: f32,
    ray_offset: f32,
    shadow_rays: u32, // 1 trace shadow rays, 0 every VPL visible
    brdf: u32,        // BRDF_LAMBERT / BRDF_GGX
    eye: vec4<f32>,   // xyz camera position
    // Step i evaluates VPL (i * order.x) % order.y: a stride coprime with the count, so that
    // the sum so far covers the whole set while it converges (GpuGtParams::order).
    order: vec4<u32>,
};

fn vpl_at(i: u32) -> Vpl {
    if params.order.y == 0u {
        return vpls[i];
    }
    return vpls[(i * params.order.x) % params.order.y];
}

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
    let g = vpl_geometry(v.position.xyz, v.normal, x, nx, params.epsilon);
    if g <= 0.0 || (params.shadow_rays != 0u && !vpl_visible(v.position.xyz, v.normal, x, nx, params.ray_offset)) {
        return vec3<f32>(0.0);
    }
    return v.flux.rgb / PI * g;
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
    let nr = textureLoad(gb_normal, px, 0);
    let nx = normalize(nr.xyz);
    let albedo = textureLoad(gb_albedo, px, 0);
    let k = gid.y * params.width + gid.x;
    if params.brdf == BRDF_LAMBERT {
        var sum = vec3<f32>(0.0);
        for (var i = params.begin; i < params.end; i++) {
            sum += vpl_irradiance_term(vpl_at(i), g.xyz, nx);
        }
        accum[k] += vec4<f32>(albedo.rgb / PI * sum, 0.0);
        return;
    }
    // Glossy: the BRDF per VPL direction.
    let v = normalize(params.eye.xyz - g.xyz);
    var sum = vec3<f32>(0.0);
    for (var i = params.begin; i < params.end; i++) {
        let vp = vpl_at(i);
        let t = vpl_irradiance_term(vp, g.xyz, nx);
        if any(t > vec3<f32>(0.0)) {
            let l = normalize(vp.position.xyz - g.xyz);
            sum += brdf_eval(params.brdf, nx, v, l, albedo.rgb, albedo.a, nr.w) * t;
        }
    }
    accum[k] += vec4<f32>(sum, 0.0);
}

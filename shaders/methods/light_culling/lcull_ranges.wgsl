// Algorithm 1, step 1: each VPL's fall-off parameters and range.
//   stochastic: alpha_i = 2 pi eps_max / (E max I_i) (eq. 6), max I_i = max_rgb(flux) / pi;
//               r_i = 1 / sqrt(alpha_i xi_i) (eq. 3); threshold alpha xi, floor alpha (eq. 2)
//   clamped:    r_i = sqrt(E N max I_i / (pi eps_max)) (appendix A); threshold 1 / r^2, floor 0
// Output per VPL: lights[2i] = (position, range), lights[2i + 1] = (threshold, floor, 0, 0).
// Twin: reference::light_culling::light_range.
#include "common/math.wgsl"
#include "common/vpl.wgsl"
#include "methods/light_culling/lcull_common.wgsl"

@group(0) @binding(0) var<uniform> params: LcullParams;
@group(0) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(2) var<storage, read_write> lights: array<vec4<f32>>;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if i >= params.count {
        return;
    }
    let v = vpls[i];
    let flux_max = max(v.flux.r, max(v.flux.g, v.flux.b));
    var threshold = 3.0e38; // never passes (twin: reference::light_culling::NEVER)
    var floor_ = 0.0;
    var range = 0.0;
    if v.id != VPL_NONE && flux_max > 0.0 && flux_max < 3.0e38 {
        if params.mode == 0u {
            let alpha = 2.0 * PI * PI * params.epsilon_max / (params.exposure * flux_max);
            threshold = alpha * lcull_xi(params.seed, i);
            floor_ = alpha;
        } else {
            let r = sqrt(params.exposure * f32(params.count) * flux_max / (PI * PI * params.epsilon_max));
            threshold = 1.0 / (r * r);
        }
        // Eq. 3: r = f^-1(threshold); 0 when even f(0) = 1 / eps^2 is not above it.
        if threshold <= 0.0 {
            range = LCULL_RANGE_INF;
        } else if threshold * params.eps * params.eps >= 1.0 {
            range = 0.0;
        } else {
            range = min(1.0 / sqrt(threshold), LCULL_RANGE_INF);
        }
    }
    lights[2u * i] = vec4<f32>(v.position.xyz, range);
    lights[2u * i + 1u] = vec4<f32>(threshold, floor_, 0.0, 0.0);
}

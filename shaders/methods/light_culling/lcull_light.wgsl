// One VPL's fall-off parameters and range (Algorithm 1, step 1; the tree variant's leaves).
//   stochastic: alpha_i = 2 pi eps_max / (E max I_i) (eq. 6), max I_i = max_rgb(flux) / pi;
//               r_i = 1 / sqrt(alpha_i xi_i) (eq. 3); threshold alpha xi, floor alpha (eq. 2)
//   clamped:    r_i = sqrt(E N max I_i / (pi eps_max)) (appendix A); threshold 1 / r^2, floor 0
// Twin: reference::light_culling::light_range. Needs common/vpl.wgsl, lcull_common.wgsl.

struct LcullLight {
    position_range: vec4<f32>,  // (position, range)
    falloff: vec4<f32>,         // (threshold, floor, 0, 0)
};

// `i`: the VPL's index for its xi.
fn lcull_light(p: LcullParams, v: Vpl, i: u32) -> LcullLight {
    let flux_max = max(v.flux.r, max(v.flux.g, v.flux.b));
    var threshold = 3.0e38; // never passes (twin: reference::light_culling::NEVER)
    var floor_ = 0.0;
    var range = 0.0;
    if v.id != VPL_NONE && flux_max > 0.0 && flux_max < 3.0e38 {
        if p.mode != 1u {
            let alpha = 2.0 * PI * PI * p.epsilon_max / (p.exposure * flux_max);
            threshold = alpha * lcull_xi(p.seed, i);
            floor_ = alpha;
        } else {
            let r = sqrt(p.exposure * f32(p.count) * flux_max / (PI * PI * p.epsilon_max));
            threshold = 1.0 / (r * r);
        }
        // Eq. 3: r = f^-1(threshold); 0 when even f(0) = 1 / eps^2 is not above it.
        if threshold <= 0.0 {
            range = LCULL_RANGE_INF;
        } else if threshold * p.eps * p.eps >= 1.0 {
            range = 0.0;
        } else {
            range = min(1.0 / sqrt(threshold), LCULL_RANGE_INF);
        }
    }
    return LcullLight(vec4<f32>(v.position.xyz, range), vec4<f32>(threshold, floor_, 0.0, 0.0));
}

// Lightcuts' material bound for the GGX BRDF (issue 23; Walter et al. 2005, 4.1 bound the
// materials they use, Lambert, Phong and Ward, the same way: the BRDF's largest value over
// the directions towards the cluster's box). CPU twin: `ggx_cos_bound` in
// src/reference/lightcuts.rs, whose tests check it against sampled VPLs.
// Needs common/brdf.wgsl, common/color.wgsl and lc_common.wgsl.
//
// Upper bound, per RGB channel, of f(v, l) x (n.l) over l = (p - x)/|p - x|, p in [lo, hi],
// where cx >= n.l is lc_cos_bound(n, ...) (> 0). Per channel because the cluster's flux is
// coloured: luminance(sum_i flux_i f_i G_i) <= luminance(I x f_ub) x G_ub, whereas
// luminance(I) x luminance(f_ub) could be 5x (red on red) to 14x (blue on blue) too small.
// - diffuse: (1 - metallic) base / pi x cx (both Fresnel weights are at most 1);
// - D: GGX's D falls with theta_h (alpha <= 1), and theta_h >= angle(l, r) / 2 for r the
//   mirror direction of v (l and r are v reflected about h and about n; u -> 2(u.v)u - v
//   moves at most twice as fast as u), so n.h <= cos(acos(lc_cos_bound(r, ...)) / 2);
// - F (Schlick) falls with v.h = cos(angle(v, l) / 2), and angle(v, l) <= pi - the least
//   angle between -v and the box, so v.h >= cos((pi - acos(lc_cos_bound(-v, ...))) / 2);
// - Vis x n.l: Vis falls with n.l, so Vis x n.l <= 0.5 / (n.v alpha) x cx; and since
//   sqrt((n.l)^2 (1 - alpha^2) + alpha^2) >= n.l, Vis x n.l <= 0.5 / (A + n.v) with
//   A = sqrt((n.v)^2 (1 - alpha^2) + alpha^2): the smaller of the two.
// 0 when n.v <= 0 (the BRDF is 0 there).
fn lc_ggx_cos_bound(x: vec3<f32>, n: vec3<f32>, v: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>, cx: f32,
    base: vec3<f32>, metallic: f32, roughness: f32) -> vec3<f32> {
    let nv = dot(n, v);
    if !(nv > 0.0) {
        return vec3<f32>(0.0);
    }
    let diffuse = (1.0 - metallic) * base / PI * cx;
    let a = brdf_alpha(roughness);
    let a2 = a * a;
    let r = 2.0 * nv * n - v;
    let t_lr = acos(clamp(lc_cos_bound(r, x, lo, hi), 0.0, 1.0));
    let nh = cos(0.5 * t_lr);
    let q = nh * nh * (a2 - 1.0) + 1.0;
    let d = a2 / (PI * q * q);
    let t_back = acos(clamp(lc_cos_bound(-v, x, lo, hi), 0.0, 1.0));
    let vh = cos(0.5 * (PI - t_back));
    let f = brdf_schlick(brdf_f0(base, metallic), vh);
    let big_a = sqrt(nv * nv * (1.0 - a2) + a2);
    let vis_cos = min(0.5 / (nv * a) * cx, 0.5 / (big_a + nv));
    return diffuse + f * d * vis_cos;
}

// Upper bound of luminance(sum over the cluster's VPLs of flux x f(v, l) x cos_x x cos_v /
// max(d^2, eps^2)) for VPLs in [lo, hi] with normals in the cone and total flux `intensity`:
// luminance(intensity x the BRDF's bound) x cos_v / d^2 bounds (pi x lc_geometry_bound's).
fn lc_geometry_brdf_bound(x: vec3<f32>, n: vec3<f32>, v: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>,
    cone: vec4<f32>, eps: f32, base: vec3<f32>, metallic: f32, roughness: f32, intensity: vec3<f32>) -> f32 {
    let c = lc_cosines(x, n, lo, hi, cone);
    if c.x <= 0.0 {
        return 0.0;
    }
    let m = lc_ggx_cos_bound(x, n, v, lo, hi, c.x, base, metallic, roughness);
    return luminance(intensity * m) * c.y / max(lc_box_distance2(x, lo, hi), eps * eps);
}

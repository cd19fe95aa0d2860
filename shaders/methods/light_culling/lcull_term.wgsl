// One VPL's demodulated contribution (without albedo / pi) with its stochastic or clamped
// fall-off and, with visibility on, a BVH shadow ray (shadow_rays 1) or a lookup in the VPL's
// imperfect shadow map (2: map i, common/ism.wgsl). Textual include: the including shader
// declares `params` (LcullParams), `lights` (two vec4 per VPL, lcull_light.wgsl), `vpls`,
// the BVH and `ism` / `ism_depth`. Twin: the body of reference::light_culling::shade with
// its `visible` (a ray, or reference::ism::visible).

struct Term {
    value: vec3<f32>,
    in_range: u32,
    ray: u32,
};

// VPL i's contribution to (x, nx) without albedo / pi.
fn term(i: u32, x: vec3<f32>, nx: vec3<f32>) -> Term {
    var t = Term(vec3<f32>(0.0), 0u, 0u);
    let l = lights[2u * i];
    let fo = lights[2u * i + 1u];
    let d = l.xyz - x;
    let l2 = dot(d, d);
    let f = lcull_falloff(l2, params.eps, fo.x, fo.y);
    if f <= 0.0 {
        return t;
    }
    t.in_range = 1u;
    let v = vpls[i];
    let w = d * inverseSqrt(max(l2, 1e-30));
    let cx = dot(nx, w);
    let cv = -dot(v.normal, w);
    if cx <= 0.0 || cv <= 0.0 {
        return t;
    }
    if params.shadow_rays == 2u {
        t.ray = 1u;
        if !ism_visible(i, v.position.xyz, v.normal, x) {
            return t;
        }
    } else if params.shadow_rays != 0u {
        t.ray = 1u;
        if !vpl_visible(v.position.xyz, v.normal, x, nx, params.ray_offset) {
            return t;
        }
    }
    t.value = v.flux.rgb / PI * (cx * cv * f);
    return t;
}


// One VPL's demodulated contribution (without albedo / pi; with gi.brdf = GGX times f(v, l):
// radiance) with its stochastic or clamped
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

// The shading point's material (gi.brdf = GGX), set per pixel by lcull_shading. The includer
// also includes common/brdf.wgsl and declares gb_albedo and gb_normal.
var<private> glossy: bool;
var<private> sh_v: vec3<f32>;
var<private> sh_base: vec3<f32>;
var<private> sh_metallic: f32;
var<private> sh_roughness: f32;

fn lcull_shading(px: vec2<u32>, x: vec3<f32>) {
    glossy = params.brdf != BRDF_LAMBERT;
    if glossy {
        let a = textureLoad(gb_albedo, vec2<i32>(px), 0);
        sh_v = normalize(params.eye.xyz - x);
        sh_base = a.rgb;
        sh_metallic = a.a;
        sh_roughness = textureLoad(gb_normal, vec2<i32>(px), 0).w;
    }
}

// VPL i's contribution to (x, nx) without albedo / pi (GGX: with f(v, l)).
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
    if glossy {
        t.value *= brdf_eval(params.brdf, nx, sh_v, w, sh_base, sh_metallic, sh_roughness);
    }
    return t;
}


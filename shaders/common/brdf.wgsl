// The BRDF every method shades with (issue 23, `gi.brdf`): Lambert (the default: base / pi)
// or a Cook-Torrance GGX microfacet BRDF over glTF's metallic-roughness parameters (the SST
// paper shades glossy VPLs with Cook-Torrance, section 5). CPU twin: `reference::brdf`.
//
//   alpha = roughness^2 (glTF's perceptual roughness), at least BRDF_MIN_ALPHA;
//   F0 = mix(0.04, base, metallic); F(u) = F0 + (1 - F0) (1 - u)^5 (Schlick);
//   D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2) (GGX / Trowbridge-Reitz);
//   Vis = G / (4 n.l n.v) with Smith's height-correlated G:
//         0.5 / (n.l sqrt((n.v)^2 (1 - alpha^2) + alpha^2) + n.v sqrt((n.l)^2 (1 - alpha^2) + alpha^2));
//   specular = F(v.h) D Vis;
//   diffuse  = (1 - metallic) base / pi x (1 - F(n.v)) (1 - F(n.l)).
// The diffuse weight is not the glTF specification's (1 - F(v.h)): that one reflects up to
// 1.85 x the incident energy at grazing views on a white dielectric (numeric white furnace);
// (1 - F(n.v)) (1 - F(n.l)) is reciprocal and keeps the white furnace at or below 1 (tests:
// `reference::brdf`). Both directions are on the normal's side (else 0).

const BRDF_LAMBERT: u32 = 0u;
const BRDF_GGX: u32 = 1u;
const BRDF_MIN_ALPHA: f32 = 0.002;

fn brdf_alpha(roughness: f32) -> f32 {
    return max(roughness * roughness, BRDF_MIN_ALPHA);
}

fn brdf_f0(base: vec3<f32>, metallic: f32) -> vec3<f32> {
    return mix(vec3<f32>(0.04), base, metallic);
}

fn brdf_schlick(f0: vec3<f32>, u: f32) -> vec3<f32> {
    let m = 1.0 - clamp(u, 0.0, 1.0);
    let m2 = m * m;
    return f0 + (vec3<f32>(1.0) - f0) * (m2 * m2 * m);
}

// The diffuse part of the BRDF (for Lambert the whole BRDF).
fn brdf_diffuse(model: u32, n: vec3<f32>, v: vec3<f32>, l: vec3<f32>, base: vec3<f32>, metallic: f32) -> vec3<f32> {
    if model == BRDF_LAMBERT {
        return base * (1.0 / 3.14159265358979);
    }
    let nl = dot(n, l);
    let nv = dot(n, v);
    if nl <= 0.0 || nv <= 0.0 {
        return vec3<f32>(0.0);
    }
    let f0 = brdf_f0(base, metallic);
    let w = (vec3<f32>(1.0) - brdf_schlick(f0, nv)) * (vec3<f32>(1.0) - brdf_schlick(f0, nl));
    return (1.0 - metallic) * base * w * (1.0 / 3.14159265358979);
}

// The specular (GGX) part; 0 for Lambert.
fn brdf_specular(model: u32, n: vec3<f32>, v: vec3<f32>, l: vec3<f32>, base: vec3<f32>, metallic: f32, roughness: f32) -> vec3<f32> {
    if model == BRDF_LAMBERT {
        return vec3<f32>(0.0);
    }
    let nl = dot(n, l);
    let nv = dot(n, v);
    if nl <= 0.0 || nv <= 0.0 {
        return vec3<f32>(0.0);
    }
    let h = normalize(v + l);
    let nh = max(dot(n, h), 0.0);
    let a = brdf_alpha(roughness);
    let a2 = a * a;
    let q = nh * nh * (a2 - 1.0) + 1.0;
    let d = a2 / (3.14159265358979 * q * q);
    let vis = 0.5 / (nl * sqrt(nv * nv * (1.0 - a2) + a2) + nv * sqrt(nl * nl * (1.0 - a2) + a2));
    return brdf_schlick(brdf_f0(base, metallic), dot(v, h)) * (d * vis);
}

// f(v, l): the whole BRDF (per unit solid angle of l; multiply by n.l for the integrand).
fn brdf_eval(model: u32, n: vec3<f32>, v: vec3<f32>, l: vec3<f32>, base: vec3<f32>, metallic: f32, roughness: f32) -> vec3<f32> {
    return brdf_diffuse(model, n, v, l, base, metallic) + brdf_specular(model, n, v, l, base, metallic, roughness);
}

//! CPU twin of `shaders/common/brdf.wgsl`: Lambert, or Cook-Torrance GGX over glTF's
//! metallic-roughness parameters (Schlick Fresnel, GGX distribution, Smith's
//! height-correlated masking-shadowing), with the diffuse part weighted by
//! (1 - F(n.v)) (1 - F(n.l)) so that it is reciprocal and never reflects more than it
//! receives (the glTF specification's (1 - F(v.h)) does at grazing views: see the tests).

use glam::Vec3;

pub use crate::base::brdf::Brdf;

pub const MIN_ALPHA: f32 = 0.002;
const INV_PI: f32 = 1.0 / std::f32::consts::PI;

/// A shading point's material for the BRDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    pub base: Vec3,
    pub metallic: f32,
    pub roughness: f32,
}

/// A receiver's view direction (unit, towards the eye) and material for the glossy BRDF
/// (`gi.brdf = "Ggx"`): what the methods' CPU twins shade with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shading {
    pub v: Vec3,
    pub surface: Surface,
}

pub fn alpha(roughness: f32) -> f32 {
    (roughness * roughness).max(MIN_ALPHA)
}

/// GGX's distribution D at cos(theta_h) = `nh` for alpha^2 = `a2`.
pub fn ggx_d(nh: f32, a2: f32) -> f32 {
    let q = nh * nh * (a2 - 1.0) + 1.0;
    a2 / (std::f32::consts::PI * q * q)
}

pub fn f0(base: Vec3, metallic: f32) -> Vec3 {
    Vec3::splat(0.04).lerp(base, metallic)
}

pub fn schlick(f0: Vec3, u: f32) -> Vec3 {
    let m = 1.0 - u.clamp(0.0, 1.0);
    let m2 = m * m;
    f0 + (Vec3::ONE - f0) * (m2 * m2 * m)
}

/// The diffuse part (the whole BRDF for Lambert).
pub fn diffuse(model: Brdf, n: Vec3, v: Vec3, l: Vec3, s: &Surface) -> Vec3 {
    if model == Brdf::Lambert {
        return s.base * INV_PI;
    }
    let (nl, nv) = (n.dot(l), n.dot(v));
    if nl <= 0.0 || nv <= 0.0 {
        return Vec3::ZERO;
    }
    let f0 = f0(s.base, s.metallic);
    let w = (Vec3::ONE - schlick(f0, nv)) * (Vec3::ONE - schlick(f0, nl));
    (1.0 - s.metallic) * s.base * w * INV_PI
}

/// The specular (GGX) part; zero for Lambert.
pub fn specular(model: Brdf, n: Vec3, v: Vec3, l: Vec3, s: &Surface) -> Vec3 {
    if model == Brdf::Lambert {
        return Vec3::ZERO;
    }
    let (nl, nv) = (n.dot(l), n.dot(v));
    if nl <= 0.0 || nv <= 0.0 {
        return Vec3::ZERO;
    }
    let h = (v + l).normalize();
    let nh = n.dot(h).max(0.0);
    let a = alpha(s.roughness);
    let a2 = a * a;
    let d = ggx_d(nh, a2);
    let vis = 0.5 / (nl * (nv * nv * (1.0 - a2) + a2).sqrt() + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
    schlick(f0(s.base, s.metallic), v.dot(h)) * (d * vis)
}

/// f(v, l), per unit solid angle of l.
pub fn eval(model: Brdf, n: Vec3, v: Vec3, l: Vec3, s: &Surface) -> Vec3 {
    diffuse(model, n, v, l, s) + specular(model, n, v, l, s)
}

/// The directional albedo E(v) = integral of f(v, l) (n.l) dl over the hemisphere, by Monte
/// Carlo with `samples` directions drawn half from the cosine density and half as GGX
/// reflections (one-sample MIS, the mixture's pdf): the white furnace's measurement.
pub fn albedo(model: Brdf, v: Vec3, s: &Surface, samples: u32, seed: u32) -> (f64, f64) {
    albedo_of(
        |v, l| eval(model, Vec3::Z, v, l, s),
        v,
        s.roughness,
        samples,
        seed,
    )
}

/// [`albedo`] of any BRDF `f(v, l)` around n = +z (importance sampled for `roughness`).
pub fn albedo_of(
    f: impl Fn(Vec3, Vec3) -> Vec3,
    v: Vec3,
    roughness: f32,
    samples: u32,
    seed: u32,
) -> (f64, f64) {
    let n = Vec3::Z;
    let a = alpha(roughness);
    let a2 = a * a;
    let mut rng = crate::reference::light_paths::Rng::new(seed, 17, 29);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..samples {
        let (u1, u2, pick) = (rng.next_f32(), rng.next_f32(), rng.next_f32());
        let l = if pick < 0.5 {
            crate::reference::light_paths::cosine_direction(n, u1, u2)
        } else {
            let phi = 2.0 * std::f32::consts::PI * u2;
            let c = ((1.0 - u1) / (1.0 + (a2 - 1.0) * u1)).max(0.0).sqrt();
            let st = (1.0 - c * c).max(0.0).sqrt();
            let h = Vec3::new(st * phi.cos(), st * phi.sin(), c);
            2.0 * v.dot(h) * h - v
        };
        let nl = l.z;
        let mut val = 0.0f64;
        if nl > 0.0 {
            let h = (l + v).normalize();
            let nh = h.z.max(0.0);
            let pdf_s = ggx_d(nh, a2) * nh / (4.0 * v.dot(h).abs().max(1e-8));
            let pdf = 0.5 * pdf_s + 0.5 * nl * INV_PI;
            let f = f(v, l);
            // The luminance-free white furnace: the largest channel.
            val = (f.max_element() * nl / pdf) as f64;
        }
        sum += val;
        sum2 += val * val;
    }
    let k = samples as f64;
    let mean = sum / k;
    (mean, ((sum2 / k - mean * mean).max(0.0) / k).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(theta_deg: f32, phi_deg: f32) -> Vec3 {
        let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
        Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
    }

    #[test]
    fn white_furnace_reflects_at_most_what_it_receives() {
        // A white base (the most a material can reflect), every roughness and metalness, views
        // from normal to grazing: E(v) <= 1 within 4 standard errors.
        let mut worst = 0.0f64;
        for roughness in [0.02, 0.1, 0.3, 0.5, 0.8, 1.0] {
            for metallic in [0.0, 0.5, 1.0] {
                for theta in [0.0, 30.0, 60.0, 80.0, 89.0] {
                    let s = Surface {
                        base: Vec3::ONE,
                        metallic,
                        roughness,
                    };
                    let (e, se) = albedo(Brdf::Ggx, dir(theta, 0.0), &s, 100_000, 7);
                    worst = worst.max(e);
                    assert!(
                        e <= 1.0 + 4.0 * se + 1e-3,
                        "roughness {roughness}, metallic {metallic}, view {theta} deg: E = {e} +- {se}"
                    );
                }
            }
        }
        // A rough white dielectric still reflects most of the light (no gross energy loss:
        // the Fresnel-weighted diffuse keeps about (1 - F0)^2 = 0.92 of it).
        let (e, _) = albedo(
            Brdf::Ggx,
            dir(30.0, 0.0),
            &Surface {
                base: Vec3::ONE,
                metallic: 0.0,
                roughness: 0.8,
            },
            100_000,
            3,
        );
        assert!(e > 0.85, "{e}");
        // Lambert with a white base: exactly 1.
        let (e, se) = albedo(
            Brdf::Lambert,
            dir(45.0, 0.0),
            &Surface {
                base: Vec3::ONE,
                metallic: 0.0,
                roughness: 1.0,
            },
            100_000,
            5,
        );
        assert!((e - 1.0).abs() < 4.0 * se + 1e-3, "{e} +- {se}");
        eprintln!("largest white-furnace albedo: {worst:.4}");
    }

    #[test]
    fn the_gltf_diffuse_weight_would_break_the_white_furnace() {
        // Why the diffuse part is weighted by (1 - F(n.v)) (1 - F(n.l)): the glTF
        // specification's (1 - F(v.h)) reflects far more than 1 at grazing views.
        let s = Surface {
            base: Vec3::ONE,
            metallic: 0.0,
            roughness: 0.1,
        };
        let n = Vec3::Z;
        let gltf = |v: Vec3, l: Vec3| {
            if n.dot(l) <= 0.0 || n.dot(v) <= 0.0 {
                return Vec3::ZERO;
            }
            let h = (v + l).normalize();
            (Vec3::ONE - schlick(f0(s.base, s.metallic), v.dot(h))) * s.base * INV_PI
                + specular(Brdf::Ggx, n, v, l, &s)
        };
        let (e, se) = albedo_of(gltf, dir(85.0, 0.0), s.roughness, 100_000, 9);
        assert!(e > 1.2, "{e} +- {se}");
        let (ours, _) = albedo(Brdf::Ggx, dir(85.0, 0.0), &s, 100_000, 9);
        assert!(ours <= 1.0, "{ours}");
    }

    #[test]
    fn the_brdf_is_reciprocal() {
        let n = Vec3::Z;
        for (roughness, metallic) in [(0.05, 0.0), (0.3, 1.0), (0.7, 0.4), (1.0, 0.0)] {
            let s = Surface {
                base: Vec3::new(0.9, 0.5, 0.2),
                metallic,
                roughness,
            };
            for (a, b) in [
                ((10.0, 0.0), (70.0, 120.0)),
                ((45.0, 30.0), (45.0, 210.0)),
                ((80.0, 0.0), (5.0, 90.0)),
            ] {
                let (v, l) = (dir(a.0, a.1), dir(b.0, b.1));
                let (f, g) = (eval(Brdf::Ggx, n, v, l, &s), eval(Brdf::Ggx, n, l, v, &s));
                assert!(
                    (f - g).abs().max_element() <= 1e-5 * f.max_element().max(1e-3),
                    "{f} vs {g}"
                );
                assert!(f.min_element() >= 0.0);
            }
        }
    }

    #[test]
    fn lambert_is_base_over_pi_and_ggx_vanishes_below_the_surface() {
        let s = Surface {
            base: Vec3::new(0.5, 0.25, 1.0),
            metallic: 0.0,
            roughness: 0.5,
        };
        let (n, v, l) = (Vec3::Z, dir(20.0, 0.0), dir(50.0, 180.0));
        assert_eq!(eval(Brdf::Lambert, n, v, l, &s), s.base * INV_PI);
        assert_eq!(eval(Brdf::Ggx, n, v, -l, &s), Vec3::ZERO);
        assert_eq!(eval(Brdf::Ggx, n, -v, l, &s), Vec3::ZERO);
        // A rough dielectric is close to Lambert away from grazing; a smooth metal's peak is
        // in the mirror direction.
        let rough = eval(Brdf::Ggx, n, v, l, &Surface { roughness: 1.0, ..s });
        assert!(
            ((rough / (s.base * INV_PI)) - Vec3::ONE).abs().max_element() < 0.2,
            "{rough}"
        );
        let metal = Surface {
            base: Vec3::ONE,
            metallic: 1.0,
            roughness: 0.2,
        };
        let mirror = dir(20.0, 180.0);
        assert!(eval(Brdf::Ggx, n, v, mirror, &metal).x > 10.0 * eval(Brdf::Ggx, n, v, l, &metal).x);
    }
}

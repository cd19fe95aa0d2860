//! References of the one-bounce GI kernels: the exact sum over every RSM texel (what the
//! converged reference `shaders/methods/reference/reference.wgsl` estimates) at one surface point.

use glam::Vec3;

use crate::scene::bvh::{Bvh, Ray};

/// One RSM texel as a VPL.
#[derive(Clone, Copy, Debug)]
pub struct Texel {
    pub position: Vec3,
    pub normal: Vec3,
    pub flux: Vec3,
}

/// rho/pi x sum over texels of flux/pi x cos_x x cos_t / max(d^2, eps^2) x V, with V from a
/// shadow ray whose end points are offset along their normals by `shadow_rays` (None: V = 1,
/// `GiSettings::shadow_rays` off).
pub fn exact_indirect(
    bvh: &Bvh,
    x: Vec3,
    n: Vec3,
    albedo: Vec3,
    texels: &[Texel],
    eps: f32,
    shadow_rays: Option<f32>,
) -> Vec3 {
    albedo / std::f32::consts::PI * emitted_sum(bvh, x, n, texels, eps, shadow_rays, |_| Vec3::ONE)
}

/// The same sum shaded with a BRDF (the ground truth's glossy path): sum over texels of
/// f(v, l) x flux/pi x cos_x x cos_t / max(d^2, eps^2) x V, l towards the texel, `v` the unit
/// direction to the eye.
#[allow(clippy::too_many_arguments)]
pub fn exact_indirect_brdf(
    bvh: &Bvh,
    x: Vec3,
    n: Vec3,
    v: Vec3,
    model: crate::base::brdf::Brdf,
    surface: &crate::reference::brdf::Surface,
    texels: &[Texel],
    eps: f32,
    shadow_rays: Option<f32>,
) -> Vec3 {
    emitted_sum(bvh, x, n, texels, eps, shadow_rays, |l| {
        crate::reference::brdf::eval(model, n, v, l, surface)
    })
}

/// Sum over texels of weight(l) x flux/pi x cos_x x cos_t / max(d^2, eps^2) x V.
fn emitted_sum(
    bvh: &Bvh,
    x: Vec3,
    n: Vec3,
    texels: &[Texel],
    eps: f32,
    shadow_rays: Option<f32>,
    weight: impl Fn(Vec3) -> Vec3,
) -> Vec3 {
    let pi = std::f32::consts::PI;
    let mut sum = Vec3::ZERO;
    for t in texels {
        let d = t.position - x;
        let dist2 = d.length_squared();
        if dist2 <= 0.0 {
            continue;
        }
        let w = d / dist2.sqrt();
        let (cx, ct) = (n.dot(w), -t.normal.dot(w));
        if cx <= 0.0 || ct <= 0.0 {
            continue;
        }
        if let Some(offset) = shadow_rays {
            let o = x + n * offset;
            let e = t.position + t.normal * offset;
            if bvh.any_hit(&Ray {
                origin: o,
                dir: e - o,
                tmin: 1e-4,
                tmax: 1.0 - 1e-4,
            }) {
                continue;
            }
        }
        sum += weight(w) * t.flux / pi * (cx * ct / dist2.max(eps * eps));
    }
    sum
}

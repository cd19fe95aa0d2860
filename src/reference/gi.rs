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

/// The emitting texels of the exact sum with what the sum needs besides the receiver: the
/// distance bound `eps` and the BVH of the shadow rays, whose end points are offset along
/// their normals by `shadow_rays` (None: V = 1, `GiSettings::shadow_rays` off).
#[derive(Clone, Copy)]
pub struct Emitters<'a> {
    pub texels: &'a [Texel],
    pub bvh: &'a Bvh,
    pub eps: f32,
    pub shadow_rays: Option<f32>,
}

/// rho/pi x sum over texels of flux/pi x cos_x x cos_t / max(d^2, eps^2) x V at (x, n).
pub fn exact_indirect(em: &Emitters<'_>, x: Vec3, n: Vec3, albedo: Vec3) -> Vec3 {
    albedo / std::f32::consts::PI * emitted_sum(em, x, n, |_| Vec3::ONE)
}

/// The same sum shaded with a BRDF (the ground truth's glossy path): sum over texels of
/// f(v, l) x flux/pi x cos_x x cos_t / max(d^2, eps^2) x V, l towards the texel, `sh.v` the
/// unit direction to the eye.
pub fn exact_indirect_brdf(
    em: &Emitters<'_>,
    x: Vec3,
    n: Vec3,
    model: crate::base::brdf::Brdf,
    sh: &crate::reference::brdf::Shading,
) -> Vec3 {
    emitted_sum(em, x, n, |l| {
        crate::reference::brdf::eval(model, n, sh.v, l, &sh.surface)
    })
}

/// Sum over texels of weight(l) x flux/pi x cos_x x cos_t / max(d^2, eps^2) x V.
fn emitted_sum(em: &Emitters<'_>, x: Vec3, n: Vec3, weight: impl Fn(Vec3) -> Vec3) -> Vec3 {
    let Emitters {
        texels,
        bvh,
        eps,
        shadow_rays,
    } = *em;
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

//! Reference of `shaders/direct.wgsl`: the same sum with exact (ray-traced) visibility.

use glam::Vec3;

use crate::scene::{
    DirectionalLight,
    bvh::{Bvh, Ray},
};

/// sum over lights of rho/pi * E * max(0, n.l) * V(p, l), V from a BVH shadow ray.
pub fn radiance(bvh: &Bvh, p: Vec3, n: Vec3, albedo: Vec3, lights: &[DirectionalLight], eps: f32) -> Vec3 {
    lights
        .iter()
        .map(|l| {
            let to_light = -l.direction.normalize();
            let cos = n.dot(to_light).max(0.0);
            if cos == 0.0 {
                return Vec3::ZERO;
            }
            let ray = Ray {
                origin: p + n * eps,
                dir: to_light,
                tmin: 0.0,
                tmax: 3.0e38,
            };
            if bvh.any_hit(&ray) {
                Vec3::ZERO
            } else {
                albedo / std::f32::consts::PI * l.irradiance * cos
            }
        })
        .sum()
}

/// True when the visibility of `p` is the same at 32 points within `margin` of it in the
/// surface plane (8 directions x 4 radii), i.e. no shadow edge, and no shadow stripe wider
/// than about margin/4, passes within `margin` of the pixel.
pub fn away_from_shadow_edges(
    bvh: &Bvh,
    p: Vec3,
    n: Vec3,
    lights: &[DirectionalLight],
    margin: f32,
    eps: f32,
) -> bool {
    let t = n.any_orthonormal_vector();
    let b = n.cross(t);
    lights.iter().all(|l| {
        let to_light = -l.direction.normalize();
        let vis = |q: Vec3| {
            !bvh.any_hit(&Ray {
                origin: q + n * eps,
                dir: to_light,
                tmin: 0.0,
                tmax: 3.0e38,
            })
        };
        let v = vis(p);
        (0..8).all(|k| {
            let a = k as f32 * std::f32::consts::FRAC_PI_4;
            let d = t * a.cos() + b * a.sin();
            (1..=4).all(|r| vis(p + d * (margin * r as f32 / 4.0)) == v)
        })
    })
}

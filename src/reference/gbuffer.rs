//! Reference of the G-buffer raster: one BVH ray through each pixel centre.

use glam::Vec3;

use crate::scene::{
    Camera, Scene,
    bvh::{Bvh, Ray},
};

/// What the G-buffer holds at one pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    pub position: Vec3,
    /// Interpolated vertex normal, flipped to face the camera.
    pub normal: Vec3,
    pub material: u32,
    pub triangle: u32,
}

/// G-buffer samples of a `w` x `h` image, row-major (None = background).
pub fn raycast(scene: &Scene, bvh: &Bvh, cam: &Camera, w: u32, h: u32) -> Vec<Option<Sample>> {
    let mut out = Vec::with_capacity((w * h) as usize);
    for j in 0..h {
        for i in 0..w {
            let d = cam.ray_dir(i, j, w, h);
            let ray = Ray {
                origin: cam.position,
                dir: d,
                tmin: 0.0,
                tmax: 3.0e38,
            };
            out.push(bvh.closest_hit(&ray).map(|hit| {
                let t = hit.triangle as usize;
                let idx = &scene.indices[3 * t..3 * t + 3];
                let n = |k: usize| scene.normals[idx[k] as usize];
                let mut normal =
                    ((1.0 - hit.u - hit.v) * n(0) + hit.u * n(1) + hit.v * n(2)).normalize_or(Vec3::Y);
                // Two-sided like the raster: which side is seen follows the triangle's winding.
                let [a, b, c] = scene.triangle(t);
                let face = (b - a).cross(c - a);
                if face.dot(d) > 0.0 {
                    normal = -normal;
                }
                Sample {
                    position: cam.position + hit.t * d,
                    normal,
                    material: scene.triangle_materials[t],
                    triangle: hit.triangle,
                }
            }));
        }
    }
    out
}

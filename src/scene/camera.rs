//! Pinhole camera shared by the renderer, the CPU references and the UI controls.

use glam::{Mat4, Vec3};

use super::Aabb;

/// A perspective pinhole camera in world space.
///
/// Pixel (i, j) of a W x H image looks along the ray through its centre:
/// `x = 2(i+0.5)/W - 1`, `y = 1 - 2(j+0.5)/H`,
/// `dir = fwd + x tan(yfov/2) aspect right + y tan(yfov/2) up` (see [`Camera::ray_dir`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub name: String,
    pub position: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// Unit up vector, orthogonal to `forward`.
    pub up: Vec3,
    /// Vertical field of view in radians.
    pub yfov: f32,
    pub znear: f32,
    pub zfar: f32,
}

impl Camera {
    /// Builds a camera at `eye` looking at `target` (world up +Y unless the view is vertical).
    pub fn look_at(name: &str, eye: Vec3, target: Vec3, yfov: f32, znear: f32, zfar: f32) -> Self {
        let forward = (target - eye).normalize_or(Vec3::NEG_Z);
        let world_up = if forward.y.abs() > 0.999 { Vec3::Z } else { Vec3::Y };
        let right = forward.cross(world_up).normalize();
        Self {
            name: name.into(),
            position: eye,
            forward,
            up: right.cross(forward),
            yfov,
            znear,
            zfar,
        }
    }

    /// A camera that frames `bounds`, looking at the centre from the +Z/+Y side.
    pub fn framing(bounds: &Aabb) -> Self {
        let (c, r) = if bounds.is_empty() {
            (Vec3::ZERO, 1.0)
        } else {
            // Any scale: a scene of micrometres is framed as one of metres is.
            (bounds.center(), bounds.radius().max(f32::MIN_POSITIVE * 1e6))
        };
        let yfov = 50f32.to_radians();
        let dist = r / (0.5 * yfov).sin();
        let eye = c + Vec3::new(0.35, 0.35, 1.0).normalize() * dist;
        Self::look_at("framing", eye, c, yfov, dist * 1e-3, dist + 2.0 * r)
    }

    /// The view depths (along `forward`) that `bounds` spans from this camera: (nearest, farthest),
    /// the nearest 0 when the camera is inside or beside them; None when all of them lie
    /// behind the camera.
    pub fn depth_range(&self, bounds: &Aabb) -> Option<(f32, f32)> {
        let mut lo = f32::INFINITY;
        let mut hi = f32::NEG_INFINITY;
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { bounds.min.x } else { bounds.max.x },
                if i & 2 == 0 { bounds.min.y } else { bounds.max.y },
                if i & 4 == 0 { bounds.min.z } else { bounds.max.z },
            );
            let z = (c - self.position).dot(self.forward);
            lo = lo.min(z);
            hi = hi.max(z);
        }
        (hi > 0.0 && hi.is_finite()).then_some((lo.max(0.0), hi))
    }

    /// When the clip range [znear, zfar] misses `bounds` (holds under 10^-3 of their depths: a
    /// scene scaled by 10^6 beyond a fixed far plane, or by 10^-6 inside the near plane), a
    /// range from the bounds'
    /// depths: far twice the farthest, near 10^-3 of it or the old near if smaller, but at
    /// least 10^-6 of far (depth precision). Returns the warning to show; None when the range
    /// already holds some of the scene. A scene wholly behind the camera is only warned of.
    pub fn fit_clip_range(&mut self, bounds: &Aabb) -> Option<String> {
        if bounds.is_empty() {
            return None;
        }
        let Some((lo, hi)) = self.depth_range(bounds) else {
            return Some(format!(
                "camera '{}' looks away from the scene: all of it lies behind the camera (the view will be empty)",
                self.name
            ));
        };
        // Misses: the clip range holds less than 10^-3 of the depths the bounds span (none of
        // them, or a sliver: a camera inside a room scaled by 10^6 with its far plane at 30 m).
        let overlap = self.zfar.min(hi) - self.znear.max(lo);
        let holds = self.znear.is_finite()
            && self.znear > 0.0
            && self.zfar > self.znear
            && overlap.partial_cmp(&(1e-3 * (hi - lo))) != Some(std::cmp::Ordering::Less)
            && !overlap.is_nan();
        let misses = !holds;
        if !misses {
            return None;
        }
        let (old_near, old_far) = (self.znear, self.zfar);
        self.zfar = 2.0 * hi;
        let near = if old_near.is_finite() && old_near > 0.0 {
            old_near.min(1e-3 * hi)
        } else {
            1e-3 * hi
        };
        self.znear = near.max(1e-6 * self.zfar);
        Some(format!(
            "camera '{}': its clip range {old_near:.3e}..{old_far:.3e} misses the scene ({lo:.3e}..{hi:.3e} in front of it); using {:.3e}..{:.3e}",
            self.name, self.znear, self.zfar
        ))
    }

    pub fn right(&self) -> Vec3 {
        self.forward.cross(self.up).normalize()
    }

    /// Unnormalised direction of the ray through the centre of pixel (i, j).
    pub fn ray_dir(&self, i: u32, j: u32, width: u32, height: u32) -> Vec3 {
        let aspect = width as f32 / height as f32;
        let x = 2.0 * (i as f32 + 0.5) / width as f32 - 1.0;
        let y = 1.0 - 2.0 * (j as f32 + 0.5) / height as f32;
        let t = (0.5 * self.yfov).tan();
        self.forward + x * t * aspect * self.right() + y * t * self.up
    }

    pub fn view(&self) -> Mat4 {
        Mat4::look_to_rh(self.position, self.forward, self.up)
    }

    /// Right-handed perspective projection with a [0, 1] depth range (wgpu convention).
    pub fn projection(&self, aspect: f32) -> Mat4 {
        Mat4::perspective_rh(self.yfov, aspect, self.znear, self.zfar)
    }

    pub fn view_projection(&self, aspect: f32) -> Mat4 {
        self.projection(aspect) * self.view()
    }

    /// Re-orthonormalises `forward`/`up` after an edit.
    pub fn orthonormalize(&mut self) {
        self.forward = self.forward.normalize_or(Vec3::NEG_Z);
        let right = self.forward.cross(self.up).normalize_or(Vec3::X);
        self.up = right.cross(self.forward).normalize();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_pixel_ray_is_forward_and_projection_matches_ray() {
        let cam = Camera::look_at("t", Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO, 0.9, 0.1, 100.0);
        let (w, h) = (64, 48);
        let vp = cam.view_projection(w as f32 / h as f32);
        for &(i, j) in &[(0u32, 0u32), (63, 47), (10, 30), (32, 24)] {
            let d = cam.ray_dir(i, j, w, h).normalize();
            let p = cam.position + 5.0 * d;
            let clip = vp * p.extend(1.0);
            let ndc = clip.truncate() / clip.w;
            let px = (ndc.x + 1.0) * 0.5 * w as f32;
            let py = (1.0 - ndc.y) * 0.5 * h as f32;
            assert!((px - (i as f32 + 0.5)).abs() < 1e-3, "x {px} vs {i}");
            assert!((py - (j as f32 + 0.5)).abs() < 1e-3, "y {py} vs {j}");
        }
    }
}

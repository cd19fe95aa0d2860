//! Orbit and fly camera controls for the viewport.

use glam::{Vec2, Vec3};

use crate::scene::{Aabb, Camera};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraMode {
    /// Left drag orbits around the target, right/middle drag pans, wheel zooms.
    Orbit,
    /// Left/right drag looks around, W/A/S/D/Q/E move (Shift: faster), wheel changes speed.
    Fly,
}

/// Turns mouse/keyboard input into camera motion. Keeps yaw/pitch so that the camera never
/// rolls (world up is +Y).
#[derive(Clone, Debug)]
pub struct CameraController {
    pub mode: CameraMode,
    pub target: Vec3,
    pub distance: f32,
    /// Radians around +Y; 0 looks down -Z.
    pub yaw: f32,
    /// Radians above the horizon.
    pub pitch: f32,
    /// Fly speed in m/s.
    pub speed: f32,
}

fn forward_from(yaw: f32, pitch: f32) -> Vec3 {
    Vec3::new(-yaw.sin() * pitch.cos(), pitch.sin(), -yaw.cos() * pitch.cos())
}

impl CameraController {
    pub fn from_camera(cam: &Camera, bounds: &Aabb) -> Self {
        let f = cam.forward.normalize_or(Vec3::NEG_Z);
        let pitch = f.y.clamp(-1.0, 1.0).asin();
        let yaw = (-f.x).atan2(-f.z);
        let r = if bounds.is_empty() { 1.0 } else { bounds.radius() };
        // Orbit around the point the camera looks at, at the distance of the scene centre.
        let d = if bounds.is_empty() {
            r
        } else {
            (bounds.center() - cam.position).dot(f).clamp(0.05 * r, 4.0 * r)
        };
        Self {
            mode: CameraMode::Orbit,
            target: cam.position + f * d,
            distance: d,
            yaw,
            pitch,
            speed: (0.25 * r).max(0.1),
        }
    }

    pub fn forward(&self) -> Vec3 {
        forward_from(self.yaw, self.pitch)
    }

    /// Writes the controller's pose into `cam` (keeps fov and clip planes).
    pub fn apply(&self, cam: &mut Camera) {
        let f = self.forward();
        cam.forward = f;
        cam.position = self.target - f * self.distance;
        let right = f.cross(Vec3::Y).normalize_or(Vec3::X);
        cam.up = right.cross(f).normalize();
    }

    /// Mouse drag in points (primary = left button), wheel in points.
    pub fn on_drag(&mut self, delta: Vec2, primary: bool) {
        let rot = 0.005;
        match (self.mode, primary) {
            (CameraMode::Orbit, true) | (CameraMode::Fly, _) => {
                let eye = self.target - self.forward() * self.distance;
                self.yaw -= delta.x * rot;
                self.pitch = (self.pitch - delta.y * rot).clamp(-1.55, 1.55);
                if self.mode == CameraMode::Fly {
                    // Fly: rotate about the eye, so the target moves with the view.
                    self.target = eye + self.forward() * self.distance;
                }
            }
            (CameraMode::Orbit, false) => {
                let f = self.forward();
                let right = f.cross(Vec3::Y).normalize_or(Vec3::X);
                let up = right.cross(f);
                let s = self.distance * 0.0015;
                self.target += (-delta.x * right + delta.y * up) * s;
            }
        }
    }

    pub fn on_scroll(&mut self, wheel: f32) {
        match self.mode {
            CameraMode::Orbit => self.distance = (self.distance * (-wheel * 0.002).exp()).max(1e-3),
            CameraMode::Fly => self.speed = (self.speed * (wheel * 0.002).exp()).clamp(1e-3, 1e4),
        }
    }

    /// Fly movement: `dir` in camera space (x right, y up, z forward), for `dt` seconds.
    pub fn on_move(&mut self, dir: Vec3, dt: f32) {
        let f = self.forward();
        let right = f.cross(Vec3::Y).normalize_or(Vec3::X);
        let world = right * dir.x + Vec3::Y * dir.y + f * dir.z;
        self.target += world * self.speed * dt;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_camera_then_apply_round_trips() {
        let b = Aabb {
            min: Vec3::splat(-1.0),
            max: Vec3::splat(1.0),
        };
        let cam = Camera::look_at("c", Vec3::new(2.0, 1.0, 3.0), Vec3::ZERO, 0.8, 0.01, 100.0);
        let ctl = CameraController::from_camera(&cam, &b);
        let mut out = cam.clone();
        ctl.apply(&mut out);
        assert!(
            (out.position - cam.position).length() < 1e-4,
            "{} {}",
            out.position,
            cam.position
        );
        assert!((out.forward - cam.forward).length() < 1e-5);
        assert!((out.up - cam.up).length() < 1e-4);
    }

    #[test]
    fn fly_rotation_keeps_the_eye_fixed() {
        let b = Aabb {
            min: Vec3::splat(-1.0),
            max: Vec3::splat(1.0),
        };
        let cam = Camera::look_at("c", Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 0.8, 0.01, 100.0);
        let mut ctl = CameraController::from_camera(&cam, &b);
        ctl.mode = CameraMode::Fly;
        ctl.on_drag(Vec2::new(40.0, 10.0), true);
        let mut out = cam.clone();
        ctl.apply(&mut out);
        assert!((out.position - cam.position).length() < 1e-4);
        assert!((out.forward - cam.forward).length() > 0.1);
    }
}

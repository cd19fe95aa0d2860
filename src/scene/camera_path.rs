//! Repeatable motion for temporal measurements: a smooth camera path through bookmarks (a
//! Catmull-Rom spline through their positions and view directions, walked at constant speed)
//! and a sweep of the sun's azimuth. `render --camera-path / --sun-sweep`, `results temporal`
//! and the GUI's animation section use them.

use glam::Vec3;

use super::{Camera, DirectionalLight};

/// A spline through two or more cameras, parametrised by arc length.
#[derive(Clone, Debug)]
pub struct CameraPath {
    keys: Vec<Camera>,
    /// (spline parameter in segments, arc length from the start) samples, increasing.
    table: Vec<(f32, f32)>,
}

const SAMPLES_PER_SEGMENT: usize = 64;

fn catmull_rom(p0: Vec3, p1: Vec3, p2: Vec3, p3: Vec3, t: f32) -> Vec3 {
    let (t2, t3) = (t * t, t * t * t);
    0.5 * ((2.0 * p1)
        + (-p0 + p2) * t
        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2
        + (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * t3)
}

impl CameraPath {
    /// The path through `cameras` in order (at least two).
    pub fn through(cameras: &[Camera]) -> Result<CameraPath, String> {
        if cameras.len() < 2 {
            return Err(format!(
                "a camera path needs at least two bookmarks (cameras); the scene has {}",
                cameras.len()
            ));
        }
        let mut path = CameraPath {
            keys: cameras.to_vec(),
            table: Vec::new(),
        };
        let segments = cameras.len() - 1;
        let n = segments * SAMPLES_PER_SEGMENT;
        let mut len = 0.0;
        let mut last = path.position(0.0);
        path.table.push((0.0, 0.0));
        for i in 1..=n {
            let u = i as f32 / SAMPLES_PER_SEGMENT as f32;
            let p = path.position(u);
            len += p.distance(last);
            last = p;
            path.table.push((u, len));
        }
        Ok(path)
    }

    /// The bookmarks it goes through.
    pub fn keys(&self) -> &[Camera] {
        &self.keys
    }

    /// Length in metres.
    pub fn length(&self) -> f32 {
        self.table.last().map_or(0.0, |t| t.1)
    }

    fn segment(&self, u: f32) -> (usize, f32) {
        let segments = self.keys.len() - 1;
        let u = u.clamp(0.0, segments as f32);
        let i = (u.floor() as usize).min(segments - 1);
        (i, u - i as f32)
    }

    fn spline(&self, u: f32, f: impl Fn(&Camera) -> Vec3) -> Vec3 {
        let (i, t) = self.segment(u);
        let k = |j: isize| f(&self.keys[j.clamp(0, self.keys.len() as isize - 1) as usize]);
        let i = i as isize;
        catmull_rom(k(i - 1), k(i), k(i + 1), k(i + 2), t)
    }

    fn position(&self, u: f32) -> Vec3 {
        self.spline(u, |c| c.position)
    }

    /// The camera at fraction `s` (0 ..= 1) of the path's length (of its parameter if all
    /// bookmarks share one position).
    pub fn at(&self, s: f32) -> Camera {
        let s = s.clamp(0.0, 1.0);
        let total = self.length();
        let u = if total <= 1e-6 {
            s * (self.keys.len() - 1) as f32
        } else {
            let want = s * total;
            let j = self
                .table
                .partition_point(|t| t.1 < want)
                .clamp(1, self.table.len() - 1);
            let (u0, l0) = self.table[j - 1];
            let (u1, l1) = self.table[j];
            u0 + (u1 - u0) * if l1 > l0 { (want - l0) / (l1 - l0) } else { 0.0 }
        };
        let (i, t) = self.segment(u);
        let a = &self.keys[i];
        let b = &self.keys[i + 1];
        let forward = self.spline(u, |c| c.forward).normalize_or(a.forward);
        let up = self.spline(u, |c| c.up);
        let up = (up - forward * up.dot(forward)).normalize_or(a.up);
        Camera {
            name: format!("path {:.3}", s),
            position: self.position(u),
            forward,
            up,
            yfov: a.yfov + (b.yfov - a.yfov) * t,
            znear: a.znear.min(b.znear),
            zfar: a.zfar.max(b.zfar),
        }
    }

    /// `n` cameras evenly spaced along the path, the first and last at its ends.
    pub fn frames(&self, n: u32) -> Vec<Camera> {
        (0..n)
            .map(|i| self.at(if n > 1 { i as f32 / (n - 1) as f32 } else { 0.0 }))
            .collect()
    }
}

/// `n` copies of `light` whose azimuth advances evenly by `degrees` in all (elevation and
/// irradiance kept): the sun sweep.
pub fn sun_sweep(light: &DirectionalLight, degrees: f32, n: u32) -> Vec<DirectionalLight> {
    let (az, el) = light.angles_deg();
    (0..n)
        .map(|i| {
            let f = if n > 1 { i as f32 / (n - 1) as f32 } else { 0.0 };
            DirectionalLight::from_angles(&light.name, az + degrees * f, el, light.irradiance)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cams() -> Vec<Camera> {
        vec![
            Camera::look_at("a", Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO, 0.8, 0.1, 50.0),
            Camera::look_at("b", Vec3::new(3.0, 1.5, 3.0), Vec3::ZERO, 0.9, 0.1, 50.0),
            Camera::look_at("c", Vec3::new(5.0, 1.0, 0.0), Vec3::ZERO, 0.8, 0.1, 50.0),
        ]
    }

    #[test]
    fn the_path_passes_through_its_bookmarks_at_constant_speed() {
        let c = cams();
        let path = CameraPath::through(&c).unwrap();
        let first = path.at(0.0);
        let last = path.at(1.0);
        assert!(first.position.distance(c[0].position) < 1e-5);
        assert!(last.position.distance(c[2].position) < 1e-5);
        assert!(first.forward.distance(c[0].forward) < 1e-5);
        let frames = path.frames(41);
        let steps: Vec<f32> = frames
            .windows(2)
            .map(|w| w[0].position.distance(w[1].position))
            .collect();
        let mean = steps.iter().sum::<f32>() / steps.len() as f32;
        assert!((mean * 40.0 / path.length() - 1.0).abs() < 0.01);
        for s in &steps {
            assert!((s / mean - 1.0).abs() < 0.02, "{s} vs {mean}");
        }
        for f in &frames {
            assert!((f.forward.length() - 1.0).abs() < 1e-4);
            assert!(f.forward.dot(f.up).abs() < 1e-4);
        }
        // The middle bookmark is on the path.
        let closest = frames
            .iter()
            .map(|f| f.position.distance(c[1].position))
            .fold(f32::INFINITY, f32::min);
        assert!(closest < 0.5 * mean + 1e-4, "{closest}");
        assert!(CameraPath::through(&c[..1]).unwrap_err().contains("at least two"));
    }

    #[test]
    fn the_sun_sweep_turns_the_azimuth_and_keeps_the_rest() {
        let l = DirectionalLight::from_angles("sun", 30.0, 40.0, Vec3::splat(5.0));
        let s = sun_sweep(&l, 90.0, 4);
        let (az0, el0) = s[0].angles_deg();
        let (az3, el3) = s[3].angles_deg();
        assert!((az0 - 30.0).abs() < 1e-3 && (az3 - 120.0).abs() < 1e-3);
        assert!((el0 - 40.0).abs() < 1e-3 && (el3 - 40.0).abs() < 1e-3);
        assert_eq!(s[2].irradiance, l.irradiance);
    }
}

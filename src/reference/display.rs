//! Reference of `shaders/display.wgsl` and the colour helpers of `shaders/common/color.wgsl`.

use glam::Vec3;

use crate::renderer::settings::Tonemap;

pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

pub fn linear_to_srgb(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.0031308 {
        x * 12.92
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

pub fn tonemap(c: Vec3, mode: Tonemap) -> Vec3 {
    match mode {
        Tonemap::Clamp => c.clamp(Vec3::ZERO, Vec3::ONE),
        Tonemap::Reinhard => c / (1.0 + luminance(c)),
        Tonemap::Aces => {
            let (a, b, cc, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
            ((c * (a * c + b)) / (c * (cc * c + d) + e)).clamp(Vec3::ZERO, Vec3::ONE)
        }
    }
}

/// The RGBA8 the display pass stores for linear radiance `c` at `exposure_ev`.
pub fn encode(c: [f32; 4], exposure_ev: f32, mode: Tonemap) -> [u8; 4] {
    let c = Vec3::new(c[0], c[1], c[2]) * exposure_ev.exp2();
    if !c.is_finite() {
        return [255, 0, 255, 255];
    }
    let t = tonemap(c.max(Vec3::ZERO), mode);
    let q = |x: f32| (linear_to_srgb(x) * 255.0).round() as u8;
    [q(t.x), q(t.y), q(t.z), 255]
}

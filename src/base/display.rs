//! Display encoding: the tonemaps, channel isolation and sRGB of `shaders/display.wgsl` and
//! `shaders/common/color.wgsl`, on the CPU (sheets, plots, metrics on the displayed image,
//! and the twin the display pass is tested against).

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Tonemapping operator of the display pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Tonemap {
    /// Clamp to [0, 1]: shows linear values faithfully up to 1.
    Clamp,
    /// Reinhard on luminance: keeps hue, compresses highlights gently.
    Reinhard,
    /// ACES filmic fit (Narkowicz 2015): contrasty, saturates highlights.
    #[default]
    Aces,
}

impl Tonemap {
    pub const ALL: [Tonemap; 3] = [Tonemap::Clamp, Tonemap::Reinhard, Tonemap::Aces];
    pub fn gpu_id(self) -> u32 {
        match self {
            Tonemap::Clamp => 0,
            Tonemap::Reinhard => 1,
            Tonemap::Aces => 2,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Tonemap::Clamp => "clamp",
            Tonemap::Reinhard => "Reinhard",
            Tonemap::Aces => "ACES",
        }
    }
}

/// Channel isolation of radiance views.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Channel {
    #[default]
    Rgb,
    R,
    G,
    B,
    /// Rec. 709 luminance (as grey).
    Luminance,
}

impl Channel {
    pub const ALL: [Channel; 5] = [
        Channel::Rgb,
        Channel::R,
        Channel::G,
        Channel::B,
        Channel::Luminance,
    ];
    pub fn gpu_id(self) -> u32 {
        match self {
            Channel::Rgb => 0,
            Channel::R => 1,
            Channel::G => 2,
            Channel::B => 3,
            Channel::Luminance => 4,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Channel::Rgb => "RGB",
            Channel::R => "R",
            Channel::G => "G",
            Channel::B => "B",
            Channel::Luminance => "luminance",
        }
    }
}

/// How a view turns linear radiance into display pixels.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ViewLook {
    /// Radiance is multiplied by 2^EV before the tonemap.
    pub exposure_ev: f32,
    pub tonemap: Tonemap,
    pub channel: Channel,
    /// Show the channel's value (luminance for RGB) in false colour, log10 over
    /// `range_log10` in W/(m^2 sr); the exposure does not apply (the legend reads radiance).
    pub false_color: bool,
    pub range_log10: [f32; 2],
    /// NaN/Inf as magenta (off: black).
    pub nan_highlight: bool,
}

pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// An 8-bit sRGB value to linear (the decode of an `Rgba8UnormSrgb` texel).
pub fn srgb8_to_linear(c: u8) -> f32 {
    let x = c as f32 / 255.0;
    if x <= 0.04045 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
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

/// The RGBA8 the display pass stores for linear radiance `c` at `exposure_ev` (default look).
pub fn encode(c: [f32; 4], exposure_ev: f32, mode: Tonemap) -> [u8; 4] {
    encode_look(
        c,
        &ViewLook {
            exposure_ev,
            tonemap: mode,
            ..Default::default()
        },
    )
}

/// The RGBA8 the display pass stores for linear radiance `c` with a view's look.
pub fn encode_look(c: [f32; 4], look: &ViewLook) -> [u8; 4] {
    let c = Vec3::new(c[0], c[1], c[2]);
    let raw = match look.channel {
        Channel::Rgb => c,
        Channel::R => Vec3::splat(c.x),
        Channel::G => Vec3::splat(c.y),
        Channel::B => Vec3::splat(c.z),
        Channel::Luminance => Vec3::splat(luminance(c)),
    };
    if !raw.is_finite() {
        return if look.nan_highlight {
            [255, 0, 255, 255]
        } else {
            [0, 0, 0, 255]
        };
    }
    let q = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    if look.false_color {
        let v = if look.channel == Channel::Rgb {
            luminance(raw)
        } else {
            raw.x
        };
        if v <= 0.0 {
            return [0, 0, 0, 255];
        }
        let [lo, hi] = look.range_log10;
        let f = super::colormap::false_color((v.log10() - lo) / (hi - lo).max(1e-6));
        return [q(f[0]), q(f[1]), q(f[2]), 255];
    }
    let t = tonemap((raw * look.exposure_ev.exp2()).max(Vec3::ZERO), look.tonemap);
    let s = |x: f32| (linear_to_srgb(x) * 255.0).round() as u8;
    [s(t.x), s(t.y), s(t.z), 255]
}

//! Renderer settings: one serde struct per pass, documented field by field. The same structs
//! are edited by the UI, saved with the app state, read from presets and set by CLI flags.

use serde::{Deserialize, Serialize};

/// All settings of the frame.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RenderSettings {
    pub shadow: ShadowSettings,
    pub display: DisplaySettings,
    pub textures: TextureSettings,
}

/// Directional shadow map (one square layer per light, covering the scene bounds).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ShadowSettings {
    /// Shadow-map resolution in texels per side. Raising it sharpens shadows and resolves thin
    /// occluders (blinds, chains) at quadratic memory/raster cost; lowering it blurs and loses
    /// thin geometry. Thesis default 512.
    pub resolution: u32,
    /// Constant depth bias in texels of light-space depth. Raise if surfaces shadow themselves
    /// (acne stripes); lower if shadows detach from their casters (peter-panning).
    pub depth_bias: f32,
    /// Offset of the lookup point along the surface normal, in texels, scaled by sin(theta)
    /// of the light's incidence. Raise against acne at grazing light; lower if thin occluders
    /// leak light.
    pub normal_offset: f32,
    /// Slope-scaled depth bias: tan(theta) x (PCF radius + 1/2) texels times this factor
    /// (receiver-plane bound for the PCF taps). Raise if tilted surfaces shadow themselves in
    /// stripes; lower if contact shadows detach.
    pub slope_bias: f32,
    /// Percentage-closer filter radius in texels: 0 = one hard tap, 1 = 3x3, 2 = 5x5. Raising it
    /// softens (and antialiases) shadow edges at more cost per pixel.
    pub pcf_radius: u32,
}

impl Default for ShadowSettings {
    fn default() -> Self {
        Self {
            resolution: 512,
            depth_bias: 1.0,
            normal_offset: 1.0,
            slope_bias: 1.0,
            pcf_radius: 1,
        }
    }
}

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

/// Display of linear radiance (exports to EXR are never affected).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DisplaySettings {
    /// Exposure in EV stops: radiance is multiplied by 2^EV before tonemapping. Raise to
    /// brighten dim (indirect-only) images.
    pub exposure_ev: f32,
    pub tonemap: Tonemap,
}

impl Default for DisplaySettings {
    fn default() -> Self {
        Self {
            exposure_ev: 0.0,
            tonemap: Tonemap::Aces,
        }
    }
}

/// Scene texture upload.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TextureSettings {
    /// Base colour textures are resampled to one square size (a texture array layer each), at
    /// most this many texels per side. Raising it sharpens textures and costs memory
    /// (4/3 x 4 B x size^2 per texture); lowering speeds up loading on software devices.
    pub max_size: u32,
    /// Anisotropic filtering of base-colour textures (1 = trilinear only, up to 16). Raising
    /// it keeps floors and walls sharp at grazing view angles; on software rasterisers it is
    /// expensive (lavapipe, Sponza 1280x720: G-buffer 503 ms at 8x, 166 ms at 1x).
    pub anisotropy: u16,
}

impl Default for TextureSettings {
    fn default() -> Self {
        Self {
            max_size: 1024,
            anisotropy: 8,
        }
    }
}

impl RenderSettings {
    /// Checks every value's range; the message names the setting and its valid range.
    pub fn validate(&self) -> Result<(), String> {
        let s = &self.shadow;
        if !(16..=8192).contains(&s.resolution) {
            return Err(format!(
                "shadow.resolution {} is out of range (16..=8192)",
                s.resolution
            ));
        }
        if !(0.0..=64.0).contains(&s.depth_bias) {
            return Err(format!(
                "shadow.depth_bias {} is out of range (0..=64)",
                s.depth_bias
            ));
        }
        if !(0.0..=64.0).contains(&s.normal_offset) {
            return Err(format!(
                "shadow.normal_offset {} is out of range (0..=64)",
                s.normal_offset
            ));
        }
        if !(0.0..=16.0).contains(&s.slope_bias) {
            return Err(format!(
                "shadow.slope_bias {} is out of range (0..=16)",
                s.slope_bias
            ));
        }
        if s.pcf_radius > 4 {
            return Err(format!(
                "shadow.pcf_radius {} is out of range (0..=4)",
                s.pcf_radius
            ));
        }
        if !(-20.0..=20.0).contains(&self.display.exposure_ev) {
            return Err(format!(
                "display.exposure_ev {} is out of range (-20..=20)",
                self.display.exposure_ev
            ));
        }
        if !(1..=8192).contains(&self.textures.max_size) {
            return Err(format!(
                "textures.max_size {} is out of range (1..=8192)",
                self.textures.max_size
            ));
        }
        if !(1..=16).contains(&self.textures.anisotropy) {
            return Err(format!(
                "textures.anisotropy {} is out of range (1..=16)",
                self.textures.anisotropy
            ));
        }
        Ok(())
    }
}

/// Which buffer the viewport shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum ViewBuffer {
    /// The final image: every lighting term (linear radiance, tonemapped for display).
    #[default]
    Final,
    /// Direct light only.
    Direct,
    /// Diffuse albedo from the G-buffer.
    Albedo,
    /// Shading normals from the G-buffer.
    Normal,
    /// Linear depth along the view direction (false colour, near = bright).
    Depth,
    /// World position normalised to the scene bounds.
    Position,
    /// Material ids (hash colours).
    MaterialId,
    /// The shadow map of light 0 (near = white).
    ShadowMap,
}

impl ViewBuffer {
    pub const ALL: [ViewBuffer; 8] = [
        ViewBuffer::Final,
        ViewBuffer::Direct,
        ViewBuffer::Albedo,
        ViewBuffer::Normal,
        ViewBuffer::Depth,
        ViewBuffer::Position,
        ViewBuffer::MaterialId,
        ViewBuffer::ShadowMap,
    ];
    pub fn name(self) -> &'static str {
        match self {
            ViewBuffer::Final => "final",
            ViewBuffer::Direct => "direct only",
            ViewBuffer::Albedo => "albedo",
            ViewBuffer::Normal => "normal",
            ViewBuffer::Depth => "depth",
            ViewBuffer::Position => "position",
            ViewBuffer::MaterialId => "material id",
            ViewBuffer::ShadowMap => "shadow map",
        }
    }
    /// True for linear-radiance buffers (shown through exposure + tonemap).
    pub fn is_radiance(self) -> bool {
        matches!(self, ViewBuffer::Final | ViewBuffer::Direct)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_round_trip_through_toml() {
        let s = RenderSettings::default();
        assert!(s.validate().is_ok());
        let text = toml::to_string(&s).unwrap();
        let back: RenderSettings = toml::from_str(&text).unwrap();
        assert_eq!(s, back);
    }

    #[test]
    fn out_of_range_values_are_named() {
        let mut s = RenderSettings::default();
        s.shadow.resolution = 3;
        assert!(s.validate().unwrap_err().contains("shadow.resolution"));
        let mut s = RenderSettings::default();
        s.display.exposure_ev = f32::NAN;
        assert!(s.validate().unwrap_err().contains("exposure_ev"));
    }
}

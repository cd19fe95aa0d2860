//! The BRDF choice (`gi.brdf`), shared by the settings and the BRDF's CPU twin
//! (`reference::brdf`).

/// The BRDF every method shades with (`shaders/common/brdf.wgsl`, docs/brdf.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Brdf {
    /// base colour / pi (the thesis; the references against Mitsuba are diffuse).
    #[default]
    Lambert,
    /// Cook-Torrance GGX over glTF's metallic and roughness (factors x textures).
    Ggx,
}

impl Brdf {
    pub const ALL: [Brdf; 2] = [Brdf::Lambert, Brdf::Ggx];
    pub fn name(self) -> &'static str {
        match self {
            Brdf::Lambert => "Lambert",
            Brdf::Ggx => "GGX (metallic-roughness)",
        }
    }
    /// The shader's model constant (`BRDF_LAMBERT` / `BRDF_GGX`).
    pub fn gpu(self) -> u32 {
        match self {
            Brdf::Lambert => 0,
            Brdf::Ggx => 1,
        }
    }
}

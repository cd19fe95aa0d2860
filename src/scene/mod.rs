//! Scene data on the CPU: glTF loading, the embedded default scene, presets, the BVH, cameras.
//!
//! Everything here is plain Rust (no wgpu, no egui) so that tests and CPU references can use it.
//! Geometry is flattened to world space at load time: every node that references a mesh
//! contributes its own transformed copy of the mesh's triangles (instancing is resolved here).

pub mod bvh;
pub mod camera;
pub mod camera_path;
pub mod default_scene;
pub mod gltf_load;
pub mod preset;
pub mod scene_path;
pub mod test_scenes;

#[cfg(test)]
mod loader_tests;

use glam::{Vec2, Vec3};

pub use bvh::Bvh;
pub use camera::Camera;
pub use gltf_load::SceneError;

/// Axis-aligned bounding box. An empty box has `min > max` (min = +inf, max = -inf).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }
    pub fn grow(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }
    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }
    pub fn extent(&self) -> Vec3 {
        if self.is_empty() {
            Vec3::ZERO
        } else {
            self.max - self.min
        }
    }
    /// Half the diagonal: radius of the bounding sphere around `center()`.
    pub fn radius(&self) -> f32 {
        0.5 * self.extent().length()
    }
    pub fn surface_area(&self) -> f32 {
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
}

/// A material: base colour = `base_color_factor` x texture(uv) (texture sRGB-decoded); with
/// `gi.brdf = ggx` also glTF's metallic and (perceptual) roughness factors
/// (`shaders/common/brdf.wgsl`). Lambert shading reads the base colour only.
#[derive(Clone, Debug)]
pub struct Material {
    pub name: String,
    /// Linear RGBA factor (glTF `baseColorFactor`).
    pub base_color_factor: [f32; 4],
    /// Index into [`Scene::textures`], if the material has a base colour texture that loaded.
    pub base_color_texture: Option<usize>,
    /// glTF `metallicFactor` (0 dielectric .. 1 metal).
    pub metallic: f32,
    /// glTF `roughnessFactor` (perceptual roughness; the GGX alpha is its square).
    pub roughness: f32,
    /// Index into [`Scene::textures`] of the texture whose G channel multiplies `roughness`
    /// (glTF `metallicRoughnessTexture`, or AMD_split_roughnessMetallic's roughness texture).
    /// Data textures are stored sRGB-encoded so that sampling decodes them to linear.
    pub roughness_texture: Option<usize>,
    /// Likewise, the texture whose B channel multiplies `metallic`.
    pub metallic_texture: Option<usize>,
    /// The affine map from the vertex texture coordinates to those the metallic-roughness
    /// textures read, rows (a, b, c) and (d, e, f): u' = a u + b v + c, v' = d u + e v + f.
    /// The identity unless glTF's KHR_texture_transform gives that texture another transform
    /// than the one already applied to the vertices (the base colour's).
    pub metal_rough_uv: [[f32; 3]; 2],
}

/// [`Material::metal_rough_uv`]'s identity.
pub const UV_IDENTITY: [[f32; 3]; 2] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

impl Default for Material {
    fn default() -> Self {
        Self {
            name: "default".into(),
            base_color_factor: [0.8, 0.8, 0.8, 1.0],
            base_color_texture: None,
            metallic: 0.0,
            roughness: 1.0,
            roughness_texture: None,
            metallic_texture: None,
            metal_rough_uv: UV_IDENTITY,
        }
    }
}

/// An 8-bit RGBA image whose RGB is sRGB-encoded (as stored in PNG/JPG files).
#[derive(Clone, Debug)]
pub struct TextureImage {
    pub name: String,
    pub width: u32,
    pub height: u32,
    /// `width * height * 4` bytes, row-major, top row first.
    pub rgba8: Vec<u8>,
}

impl TextureImage {
    /// Re-encodes linear 8-bit data (a metallic-roughness texture) as the sRGB bytes whose
    /// decode gives it back, to within half an sRGB step (at most 0.0040); alpha is
    /// kept. The renderer's texture array is sRGB: its sampler then returns the linear data.
    pub fn encode_linear_as_srgb(&mut self) {
        let lut: Vec<u8> = (0..=255u32)
            .map(|v| {
                let x = v as f32 / 255.0;
                let s = if x <= 0.0031308 {
                    12.92 * x
                } else {
                    1.055 * x.powf(1.0 / 2.4) - 0.055
                };
                (s * 255.0 + 0.5).clamp(0.0, 255.0) as u8
            })
            .collect();
        for px in self.rgba8.chunks_exact_mut(4) {
            for c in &mut px[..3] {
                *c = lut[*c as usize];
            }
        }
    }
}

/// A directional light (sun).
#[derive(Clone, Debug, PartialEq)]
pub struct DirectionalLight {
    pub name: String,
    /// Unit vector in the direction the light *travels* (glTF: the node's local -Z in world
    /// space). The direction towards the light is `-direction`.
    pub direction: Vec3,
    /// Irradiance E in W/m^2 on a surface perpendicular to the light, per RGB channel
    /// (glTF `intensity` x `color`; no photometric conversion).
    pub irradiance: Vec3,
}

impl DirectionalLight {
    /// Builds a sun from azimuth/elevation in degrees (elevation above the horizon, azimuth
    /// measured from +X towards +Z around +Y) and a scalar irradiance times colour.
    pub fn from_angles(name: &str, azimuth_deg: f32, elevation_deg: f32, irradiance: Vec3) -> Self {
        let (az, el) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
        let to_light = Vec3::new(el.cos() * az.cos(), el.sin(), el.cos() * az.sin());
        Self {
            name: name.into(),
            direction: -to_light.normalize(),
            irradiance,
        }
    }
    /// (azimuth, elevation) in degrees of the direction towards the light; inverse of
    /// [`DirectionalLight::from_angles`].
    pub fn angles_deg(&self) -> (f32, f32) {
        let l = -self.direction.normalize_or(Vec3::Y);
        let el = l.y.clamp(-1.0, 1.0).asin();
        let az = l.z.atan2(l.x);
        (az.to_degrees(), el.to_degrees())
    }
}

/// A loaded scene: world-space triangles, materials, textures, cameras and lights.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    pub name: String,
    /// World-space vertex positions.
    pub positions: Vec<Vec3>,
    /// World-space unit vertex normals (computed flat when the file has none).
    pub normals: Vec<Vec3>,
    /// Texture coordinates (zero when the file has none).
    pub uvs: Vec<Vec2>,
    /// Three indices per triangle into the vertex arrays.
    pub indices: Vec<u32>,
    /// Material index per triangle (into `materials`).
    pub triangle_materials: Vec<u32>,
    pub materials: Vec<Material>,
    pub textures: Vec<TextureImage>,
    pub cameras: Vec<Camera>,
    pub lights: Vec<DirectionalLight>,
    /// Bounds of all triangles.
    pub bounds: Aabb,
    /// Non-fatal problems met while loading (unsupported extensions, missing images, ...).
    pub warnings: Vec<String>,
    /// What the loader decoded beyond plain glTF (one line per extension: compressed buffer
    /// views and primitives, instances expanded, quantisation, texture transforms), for the
    /// load summary.
    pub load_notes: Vec<String>,
}

impl Scene {
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }
    /// The three world-space corners of triangle `t`.
    pub fn triangle(&self, t: usize) -> [Vec3; 3] {
        let i = &self.indices[3 * t..3 * t + 3];
        [
            self.positions[i[0] as usize],
            self.positions[i[1] as usize],
            self.positions[i[2] as usize],
        ]
    }
    /// Warnings for a scene whose size defeats the settings kept in metres (a file exported
    /// in the wrong unit, scaled by 10^6 or 10^-6): shadow rays offset by `gi.ray_offset`
    /// (default 1 mm) start inside their own surface where a float's step at the scene's
    /// coordinates is larger (black GI), and `gi.distance_epsilon` (default 5 cm) clamps
    /// every VPL of a scene not much larger than it (dark GI). Each names the setting to change.
    pub fn scale_warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.bounds.is_empty() {
            return out;
        }
        let defaults = crate::settings::GiSettings::default();
        let extent = self.bounds.min.abs().max(self.bounds.max.abs()).max_element();
        let step = extent * f32::EPSILON;
        if 16.0 * step > defaults.ray_offset {
            out.push(format!(
                "coordinates reach {extent:.3e} m, where a float's step is {step:.1e} m: the default gi.ray_offset of {} m cannot lift shadow rays off their surfaces (black GI); set gi.ray_offset to at least {:.2e} (--set gi.ray_offset=..., or a settings file)",
                defaults.ray_offset,
                64.0 * step
            ));
        }
        let radius = self.bounds.radius();
        if radius < 20.0 * defaults.distance_epsilon {
            out.push(format!(
                "the scene's radius is {radius:.3e} m, not much larger than the default gi.distance_epsilon of {} m, which bounds every VPL's distance from below (dark GI); set gi.distance_epsilon to about {:.2e} (--set gi.distance_epsilon=...)",
                defaults.distance_epsilon,
                radius * 0.01
            ));
        }
        // The RSM keeps each texel's flux (albedo x E x texel area, W) in half floats: at the
        // default 512 texels over the scene's diameter, a sun of E W/m^2 on albedo 0.5 gives
        // 0.5 E (2 r / 512)^2 W, which must lie in 6e-8..65504.
        let e = self
            .lights
            .iter()
            .map(|l| l.irradiance.max_element())
            .fold(0.0f32, f32::max);
        let texel_flux = 0.5 * e * (2.0 * radius / 512.0).powi(2);
        if e > 0.0 && !(6e-8..=65504.0).contains(&texel_flux) {
            out.push(format!(
                "a reflective-shadow-map texel of this scene carries ~{texel_flux:.1e} W, outside the half floats' 6e-8..65504 the RSM stores flux in: its VPLs will be {}; is the file in metres? (rescale it)",
                if texel_flux < 6e-8 { "black" } else { "infinite" }
            ));
        }
        out
    }

    pub fn recompute_bounds(&mut self) {
        let mut b = Aabb::EMPTY;
        for &p in &self.positions {
            b.grow(p);
        }
        self.bounds = b;
    }
    /// The camera named `name`, or the first one, or one framing the bounds.
    pub fn camera_or_default(&self, name: Option<&str>) -> Result<Camera, String> {
        match name {
            Some(n) => self.cameras.iter().find(|c| c.name == n).cloned().ok_or_else(|| {
                let names: Vec<&str> = self.cameras.iter().map(|c| c.name.as_str()).collect();
                format!(
                    "no camera named '{n}' in the scene (it has: {})",
                    names.join(", ")
                )
            }),
            None => Ok(self
                .cameras
                .first()
                .cloned()
                .unwrap_or_else(|| Camera::framing(&self.bounds))),
        }
    }
}

//! Scene presets: small TOML files under `scenes/` that name a glTF file plus what it lacks
//! (a sun, a chosen camera, an exposure).
//!
//! ```toml
//! name = "Sponza"
//! gltf = "sponza/Sponza.gltf"   # found beside this preset or on the scene search path
//! camera = "CameraMain"          # a camera name from the file (optional)
//! exposure_ev = 0.0              # display exposure in EV stops (optional, default 0)
//! [sun]                          # optional: replaces the lights from the file
//! azimuth_deg = 30.0             # as in DirectionalLight::from_angles
//! elevation_deg = 70.0
//! irradiance = 10.0              # W/m^2 on a surface perpendicular to the sun
//! color = [1.0, 0.95, 0.9]       # optional, default white; multiplies `irradiance`
//! [camera_pose]                  # optional explicit camera (instead of `camera`)
//! eye = [0.0, 1.5, 4.0]
//! target = [0.0, 1.0, 0.0]
//! yfov_deg = 50.0
//! [[bookmarks]]                  # optional, any number: saved cameras (the workbench's
//! name = "table"                 # "save bookmark" appends them), listed after the file's
//! eye = [1.0, 1.2, 0.5]          # cameras
//! target = [0.0, 0.8, -1.0]
//! yfov_deg = 55.0
//! ```

use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::Deserialize;

use super::gltf_load::{SceneError, load_gltf};
use super::{Camera, DirectionalLight, Scene, default_scene, test_scenes};

/// A scene preset as stored in a `.toml` file. Unknown fields are rejected.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ScenePreset {
    /// Display name of the scene (defaults to the glTF file stem).
    #[serde(default)]
    pub name: Option<String>,
    /// The `.gltf`/`.glb` file; a relative path is looked up beside the preset file, then on
    /// the scene search path ([`super::scene_path`]).
    pub gltf: PathBuf,
    /// Name of a camera in the glTF file to start with. Mutually exclusive with `camera_pose`.
    #[serde(default)]
    pub camera: Option<String>,
    /// Display exposure in EV stops (0 = no scaling; +1 doubles the displayed radiance).
    #[serde(default)]
    pub exposure_ev: f32,
    /// The sun; when given it replaces any lights in the glTF file.
    #[serde(default)]
    pub sun: Option<SunPreset>,
    /// An explicit camera, added to the scene and selected.
    #[serde(default)]
    pub camera_pose: Option<CameraPose>,
    /// Saved cameras (camera bookmarks), added to the scene's cameras.
    #[serde(default)]
    pub bookmarks: Vec<CameraPose>,
}

/// A directional light given by angles (see [`DirectionalLight::from_angles`]).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SunPreset {
    /// Azimuth of the direction towards the sun in degrees, from +X towards +Z around +Y.
    pub azimuth_deg: f32,
    /// Elevation of the sun above the horizon in degrees, in [-90, 90].
    pub elevation_deg: f32,
    /// Irradiance in W/m^2 on a surface perpendicular to the sun (>= 0).
    pub irradiance: f32,
    /// Linear RGB colour multiplying `irradiance` (each >= 0); default white.
    #[serde(default = "white")]
    pub color: [f32; 3],
}

fn white() -> [f32; 3] {
    [1.0; 3]
}

/// An explicit pinhole camera pose.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CameraPose {
    /// Camera name in the scene's camera list (default "preset").
    #[serde(default = "pose_name")]
    pub name: String,
    /// Eye position in world space (metres).
    pub eye: [f32; 3],
    /// Point looked at, in world space; must differ from `eye`.
    pub target: [f32; 3],
    /// Vertical field of view in degrees, in (0, 180); default 50.
    #[serde(default = "default_yfov")]
    pub yfov_deg: f32,
    /// Near plane distance (> 0); default 0.01.
    #[serde(default = "default_znear")]
    pub znear: f32,
    /// Far plane distance (> znear); default: covers the scene bounds.
    #[serde(default)]
    pub zfar: Option<f32>,
}

fn pose_name() -> String {
    "preset".into()
}
fn default_yfov() -> f32 {
    50.0
}
fn default_znear() -> f32 {
    0.01
}

impl SunPreset {
    /// The directional light this describes.
    pub fn light(&self) -> DirectionalLight {
        DirectionalLight::from_angles(
            "sun",
            self.azimuth_deg,
            self.elevation_deg,
            self.irradiance * Vec3::from_array(self.color),
        )
    }
}

/// The `[[bookmarks]]` entry of `camera` (appended to a preset file by the workbench).
pub fn bookmark_toml(camera: &Camera) -> String {
    let f = |v: Vec3| format!("[{:.4}, {:.4}, {:.4}]", v.x, v.y, v.z);
    let name = camera.name.replace(['"', '\\'], "_");
    format!(
        "\n[[bookmarks]]\nname = \"{name}\"\neye = {}\ntarget = {}\nyfov_deg = {:.3}\n",
        f(camera.position),
        f(camera.position + camera.forward),
        camera.yfov.to_degrees()
    )
}

/// Appends a camera bookmark to the preset file `path` (comments and order stay), after
/// checking that the result still parses.
pub fn append_bookmark(path: &Path, camera: &Camera) -> Result<(), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let new = format!("{}{}", text.trim_end(), bookmark_toml(camera));
    ScenePreset::from_toml_str(&new, path)
        .map_err(|e| format!("the bookmark would break {}: {e}", path.display()))?;
    std::fs::write(path, new).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

impl CameraPose {
    /// The camera this describes; `bounds_far` is used when `zfar` is not given.
    pub fn camera(&self, bounds_far: f32) -> Camera {
        let zfar = self.zfar.unwrap_or(bounds_far.max(self.znear * 1000.0));
        Camera::look_at(
            &self.name,
            Vec3::from_array(self.eye),
            Vec3::from_array(self.target),
            self.yfov_deg.to_radians(),
            self.znear,
            zfar,
        )
    }
}

impl ScenePreset {
    /// Parses and validates a preset from TOML text (`path` is only used in messages).
    pub fn from_toml_str(text: &str, path: &Path) -> Result<Self, SceneError> {
        let bad = |message: String| SceneError::Preset {
            path: path.to_path_buf(),
            message,
        };
        let preset: ScenePreset = toml::from_str(text).map_err(|e| {
            let at = e
                .span()
                .map(|s| {
                    let before = text.get(..s.start).unwrap_or(text);
                    let line = before.matches('\n').count() + 1;
                    let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
                    format!("line {line}, column {col}: ")
                })
                .unwrap_or_default();
            bad(format!("{at}{}", e.message().trim().replace('\n', " ")))
        })?;
        preset.validate().map_err(bad)?;
        Ok(preset)
    }

    fn validate(&self) -> Result<(), String> {
        if self.gltf.as_os_str().is_empty() {
            return Err("`gltf` is empty".into());
        }
        if !self.exposure_ev.is_finite() || self.exposure_ev.abs() > 40.0 {
            return Err(format!(
                "exposure_ev = {} is out of range [-40, 40]",
                self.exposure_ev
            ));
        }
        if let Some(s) = &self.sun {
            if !s.azimuth_deg.is_finite() {
                return Err("sun.azimuth_deg must be finite".into());
            }
            if !(-90.0..=90.0).contains(&s.elevation_deg) {
                return Err(format!(
                    "sun.elevation_deg = {} is out of range [-90, 90]",
                    s.elevation_deg
                ));
            }
            if !(s.irradiance.is_finite() && s.irradiance >= 0.0) {
                return Err(format!(
                    "sun.irradiance = {} must be a finite value >= 0 (W/m^2)",
                    s.irradiance
                ));
            }
            if s.color.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
                return Err(format!("sun.color = {:?} must be finite and >= 0", s.color));
            }
        }
        if let Some(c) = &self.camera_pose {
            if self.camera.is_some() {
                return Err("give either `camera` or `[camera_pose]`, not both".into());
            }
            let (eye, target) = (Vec3::from_array(c.eye), Vec3::from_array(c.target));
            if !(eye.is_finite() && target.is_finite()) || eye.distance(target) < 1e-6 {
                return Err("camera_pose.eye and camera_pose.target must be finite and differ".into());
            }
            if !(c.yfov_deg > 0.0 && c.yfov_deg < 180.0) {
                return Err(format!(
                    "camera_pose.yfov_deg = {} is out of range (0, 180)",
                    c.yfov_deg
                ));
            }
            if !(c.znear.is_finite() && c.znear > 0.0) {
                return Err(format!("camera_pose.znear = {} must be > 0", c.znear));
            }
            if let Some(f) = c.zfar
                && !(f.is_finite() && f > c.znear)
            {
                return Err(format!("camera_pose.zfar = {f} must be finite and > znear"));
            }
        }
        for b in &self.bookmarks {
            let ok = b.eye.iter().chain(&b.target).all(|v| v.is_finite()) && b.eye != b.target;
            if !(ok && b.yfov_deg > 0.0 && b.yfov_deg < 180.0) {
                return Err(format!(
                    "bookmark '{}': eye and target must be finite and differ, yfov_deg in (0, 180)",
                    b.name
                ));
            }
        }
        Ok(())
    }

    /// The glTF path: absolute as given, relative ones through the scene search path
    /// ([`super::scene_path`]: beside the preset file `preset_path` first).
    pub fn gltf_path(&self, preset_path: &Path) -> Result<PathBuf, SceneError> {
        let dir = preset_path.parent().unwrap_or(Path::new("."));
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        super::scene_path::find(&self.gltf, Some(dir)).map_err(|message| SceneError::MissingScene {
            path: self.gltf.clone(),
            message,
        })
    }
}

/// Reads and validates a preset file.
pub fn load_preset(path: &Path) -> Result<ScenePreset, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    ScenePreset::from_toml_str(&text, path)
}

/// Where a scene comes from (a command-line argument or a UI choice).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SceneSource {
    /// The embedded default scene ([`default_scene::build`]).
    Default,
    /// One of the other scenes built in code ([`test_scenes::BUILTIN`], by name).
    Builtin(&'static str),
    /// A `.gltf` / `.glb` file.
    Gltf(PathBuf),
    /// A `.toml` scene preset.
    Preset(PathBuf),
}

impl SceneSource {
    /// `"default"` -> `Default`; another built-in scene's name (`window-box`, `corridor`,
    /// `glossy-thin`) -> `Builtin`; a path ending in `.toml` -> `Preset`; anything else ->
    /// `Gltf`.
    pub fn from_arg(s: &str) -> SceneSource {
        let p = PathBuf::from(s);
        if s == "default" {
            SceneSource::Default
        } else if let Some(b) = test_scenes::find(s) {
            SceneSource::Builtin(b.name)
        } else if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml")) {
            SceneSource::Preset(p)
        } else {
            SceneSource::Gltf(p)
        }
    }
}

/// A loaded scene plus the view settings its source asked for.
#[derive(Clone, Debug)]
pub struct OpenedScene {
    pub scene: Scene,
    /// Camera to start with (`None`: the scene's first camera, see [`Scene::camera_or_default`]).
    pub camera_name: Option<String>,
    /// Display exposure in EV stops.
    pub exposure_ev: f32,
    pub source: SceneSource,
    /// The glTF file the scene was loaded from, as found (none for built-in scenes).
    pub file: Option<PathBuf>,
}

/// Irradiance of the sun added to scenes that have no light at all (W/m^2).
pub const DEFAULT_SUN_IRRADIANCE: f32 = 10.0;

/// Loads a scene from any source, applies a preset's sun/camera, and makes sure the scene
/// has at least one light (a default sun is added with a warning otherwise).
pub fn open_scene(src: &SceneSource) -> Result<OpenedScene, SceneError> {
    let mut opened = match src {
        SceneSource::Default => OpenedScene {
            scene: default_scene::build(),
            camera_name: None,
            exposure_ev: 0.0,
            source: src.clone(),
            file: None,
        },
        SceneSource::Builtin(name) => OpenedScene {
            scene: test_scenes::find(name)
                .map(|b| (b.build)())
                .ok_or_else(|| SceneError::UnknownScene {
                    name: name.to_string(),
                    builtin: test_scenes::names(),
                })?,
            camera_name: None,
            exposure_ev: 0.0,
            source: src.clone(),
            file: None,
        },
        SceneSource::Gltf(p) if p.extension().is_none() && !p.exists() => {
            return Err(SceneError::UnknownScene {
                name: p.display().to_string(),
                builtin: test_scenes::names(),
            });
        }
        SceneSource::Gltf(p) => {
            // A path that does not exist as given is looked up in the scene search path
            // (`--scene sponza/Sponza.gltf` opens the fetched Sponza).
            let file = super::scene_path::find(p, None).map_err(|message| SceneError::MissingScene {
                path: p.clone(),
                message,
            })?;
            OpenedScene {
                scene: load_gltf(&file)?,
                camera_name: None,
                exposure_ev: 0.0,
                source: src.clone(),
                file: Some(file),
            }
        }
        SceneSource::Preset(p) => {
            let preset = load_preset(p)?;
            let file = preset.gltf_path(p)?;
            let mut scene = load_gltf(&file)?;
            let camera_name = apply_preset(&preset, &mut scene, p)?;
            OpenedScene {
                scene,
                camera_name,
                exposure_ev: preset.exposure_ev,
                source: src.clone(),
                file: Some(file),
            }
        }
    };
    let scene = &mut opened.scene;
    for w in scene.scale_warnings() {
        log::warn!("{w}");
        scene.warnings.push(w);
    }
    if scene.lights.is_empty() {
        let msg = format!(
            "the scene has no directional light; a default sun (azimuth 30, elevation 60 degrees, {DEFAULT_SUN_IRRADIANCE} W/m^2) was added"
        );
        log::warn!("{msg}");
        scene.warnings.push(msg);
        scene.lights.push(DirectionalLight::from_angles(
            "default sun",
            30.0,
            60.0,
            Vec3::splat(DEFAULT_SUN_IRRADIANCE),
        ));
    }
    Ok(opened)
}

/// Applies a preset's name, sun and camera to a loaded scene; returns the camera to select.
pub fn apply_preset(
    preset: &ScenePreset,
    scene: &mut Scene,
    preset_path: &Path,
) -> Result<Option<String>, SceneError> {
    if let Some(n) = &preset.name {
        scene.name = n.clone();
    }
    if let Some(sun) = &preset.sun {
        if !scene.lights.is_empty() {
            scene.warnings.push(format!(
                "the preset's sun replaces {} light(s) from the glTF file",
                scene.lights.len()
            ));
        }
        scene.lights = vec![sun.light()];
    }
    for b in &preset.bookmarks {
        let far = 2.0 * (b.eye_distance_to(&scene.bounds) + scene.bounds.radius());
        let mut cam = b.camera(far.max(1.0));
        if let Some(w) = cam.fit_clip_range(&scene.bounds) {
            scene.warnings.push(w);
        }
        scene.cameras.retain(|c| c.name != cam.name);
        scene.cameras.push(cam);
    }
    if let Some(pose) = &preset.camera_pose {
        let far = 2.0 * (pose.eye_distance_to(&scene.bounds) + scene.bounds.radius());
        let cam = pose.camera(far.max(1.0));
        scene.cameras.retain(|c| c.name != cam.name);
        let name = cam.name.clone();
        scene.cameras.push(cam);
        return Ok(Some(name));
    }
    if let Some(name) = &preset.camera {
        if !scene.cameras.iter().any(|c| &c.name == name) {
            let names: Vec<&str> = scene.cameras.iter().map(|c| c.name.as_str()).collect();
            return Err(SceneError::Preset {
                path: preset_path.to_path_buf(),
                message: format!(
                    "no camera named '{name}' in the glTF file (it has: {})",
                    names.join(", ")
                ),
            });
        }
        return Ok(Some(name.clone()));
    }
    Ok(None)
}

impl CameraPose {
    fn eye_distance_to(&self, bounds: &super::Aabb) -> f32 {
        if bounds.is_empty() {
            0.0
        } else {
            Vec3::from_array(self.eye).distance(bounds.center())
        }
    }
}

//! Capture records (issue 41): the sidecar TOML every `render` output, view export,
//! screenshot and comparison sheet writes. It holds the full `RenderSettings` at the top
//! level (so `--settings` reads it as any settings file) plus a `[capture]` table: commit,
//! adapter, driver, scene and its file's SHA-256, camera, size, seed, frames and frame index,
//! the command. `render --settings <record> --out DIR` takes the scene, camera, size and
//! frame counts from `[capture]` (flags given on the command line win) and reproduces a
//! `render` capture bit for bit on the same adapter (tests/first_hour.rs).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::scene::Camera;
use crate::settings::RenderSettings;

/// The commit this binary was built from (`build.rs`; `-dirty` when the work tree differed).
pub const COMMIT: &str = env!("LIGHTCUT_COMMIT");

/// A camera exactly as rendered (all of [`Camera`]'s fields).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CameraRecord {
    pub name: String,
    pub position: [f32; 3],
    pub forward: [f32; 3],
    pub up: [f32; 3],
    pub yfov: f32,
    pub znear: f32,
    pub zfar: f32,
}

impl From<&Camera> for CameraRecord {
    fn from(c: &Camera) -> Self {
        Self {
            name: c.name.clone(),
            position: c.position.to_array(),
            forward: c.forward.to_array(),
            up: c.up.to_array(),
            yfov: c.yfov,
            znear: c.znear,
            zfar: c.zfar,
        }
    }
}

impl CameraRecord {
    pub fn camera(&self) -> Camera {
        Camera {
            name: self.name.clone(),
            position: self.position.into(),
            forward: self.forward.into(),
            up: self.up.into(),
            yfov: self.yfov,
            znear: self.znear,
            zfar: self.zfar,
        }
    }
}

/// A directional light exactly as rendered (the GUI's sun controls change light 0).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LightRecord {
    pub name: String,
    pub direction: [f32; 3],
    /// W/m^2 per RGB channel.
    pub irradiance: [f32; 3],
}

impl From<&crate::scene::DirectionalLight> for LightRecord {
    fn from(l: &crate::scene::DirectionalLight) -> Self {
        Self {
            name: l.name.clone(),
            direction: l.direction.to_array(),
            irradiance: l.irradiance.to_array(),
        }
    }
}

impl LightRecord {
    pub fn light(&self) -> crate::scene::DirectionalLight {
        crate::scene::DirectionalLight {
            name: self.name.clone(),
            direction: self.direction.into(),
            irradiance: self.irradiance.into(),
        }
    }
}

/// The `[capture]` table of a record.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Capture {
    /// What wrote it: `render`, `view export`, `screenshot`, `sheet`.
    pub what: String,
    /// The files it describes (names beside the record).
    pub files: Vec<String>,
    pub commit: String,
    pub version: String,
    /// The adapter as the status line names it (name, type, backend).
    pub adapter: String,
    /// The driver and its version.
    pub driver: String,
    /// The scene as given (`default`, a built-in name, a .gltf / .glb or a preset .toml).
    pub scene: String,
    /// The glTF file the scene was loaded from (none for built-in scenes).
    pub scene_file: String,
    /// SHA-256 of that file's bytes (`builtin` for scenes built in code: the commit fixes them).
    pub scene_sha256: String,
    pub camera: CameraRecord,
    /// The lights as rendered (they replace the scene's when reproducing).
    pub lights: Vec<LightRecord>,
    pub width: u32,
    pub height: u32,
    /// The VPL seed (`vpl.seed`, also in the settings).
    pub seed: u32,
    /// Frames the image averaged (`render --frames`).
    pub frames: u32,
    /// Timed frames rendered before the image frames (`render --timing-frames`).
    pub timing_frames: u32,
    /// The renderer's frame index at the capture (random numbers are keyed by it).
    pub frame_index: u64,
    /// The frame index of the first frame the image averages (a per-frame method's image is
    /// frames `first_frame .. first_frame + frames`): `render --settings` numbers its image
    /// frames from it, so a view exported from the GUI after any number of frames renders
    /// again bit for bit. None: a progressive method, or a record from before it was kept.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_frame: Option<u64>,
    /// The command line that made it.
    pub command: String,
    /// A sequence's `render --camera-path` (bookmark names; empty: all of them).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub camera_path: Option<String>,
    /// A sequence's `render --sun-sweep` in degrees.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sun_sweep: Option<f32>,
    /// A sequence's `render --path-frames`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub path_frames: Option<u32>,
}

impl Capture {
    /// A record of what is open now: the commit, the adapter and the scene's file hash filled.
    pub fn new(what: &str, adapter: &wgpu::AdapterInfo, scene: &str, scene_file: Option<&Path>) -> Capture {
        let scene_sha256 = match scene_file {
            Some(p) => std::fs::read(p)
                .map(|b| crate::scene::scene_path::sha256_hex(&b))
                .unwrap_or_else(|e| format!("unreadable: {e}")),
            None => "builtin".into(),
        };
        Capture {
            what: what.into(),
            commit: COMMIT.into(),
            version: env!("CARGO_PKG_VERSION").into(),
            adapter: crate::gpu::context::describe_adapter(adapter),
            driver: format!("{} {}", adapter.driver, adapter.driver_info)
                .trim()
                .to_string(),
            scene: absolute_scene(scene),
            scene_file: scene_file.map(|p| p.display().to_string()).unwrap_or_default(),
            scene_sha256,
            // The program's own path is left out (it names a folder of this machine).
            command: std::iter::once("lightcut-workbench".to_string())
                .chain(
                    std::env::args_os()
                        .skip(1)
                        .map(|a| a.to_string_lossy().into_owned()),
                )
                .collect::<Vec<_>>()
                .join(" "),
            ..Default::default()
        }
    }
}

/// A scene argument that names a file, made absolute (a record then reproduces from any
/// folder); built-in scene names as they are.
fn absolute_scene(scene: &str) -> String {
    let p = Path::new(scene);
    if p.is_file() {
        std::fs::canonicalize(p).map_or_else(|_| scene.to_string(), |a| a.display().to_string())
    } else {
        scene.to_string()
    }
}

/// The record's text: a comment saying how to reproduce, the settings, then `[capture]`.
pub fn record_toml(capture: &Capture, settings: &RenderSettings) -> Result<String, String> {
    let mut table = toml::Table::try_from(settings).map_err(|e| format!("settings: {e}"))?;
    table.insert(
        "capture".into(),
        toml::Value::try_from(capture).map_err(|e| format!("capture: {e}"))?,
    );
    let body = toml::to_string(&table).map_err(|e| e.to_string())?;
    Ok(format!(
        "# Capture record of {} ({}). `lightcut-workbench render --settings <this file> --out DIR`\n\
         # renders it again: the settings below, the scene, camera, size and frames of [capture].\n\n{body}",
        capture.what,
        capture.files.join(", ")
    ))
}

/// Writes `record_toml` to `path`.
pub fn write_record(path: &Path, capture: &Capture, settings: &RenderSettings) -> Result<(), String> {
    let text = record_toml(capture, settings)?;
    std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// The record beside an exported file: `name.png` -> `name.capture.toml`.
pub fn sidecar_path(file: &Path) -> PathBuf {
    let stem = file.file_stem().and_then(|s| s.to_str()).unwrap_or("capture");
    file.with_file_name(format!("{stem}.capture.toml"))
}

/// Splits a settings file's text into its `[capture]` table (if any) and the rest.
pub fn split(text: &str) -> Result<(Option<Capture>, toml::Table), String> {
    let mut table: toml::Table = toml::from_str(text).map_err(|e| e.message().to_string())?;
    let capture = match table.remove("capture") {
        Some(v) => Some(
            v.try_into::<Capture>()
                .map_err(|e| format!("[capture]: {}", e.message()))?,
        ),
        None => None,
    };
    Ok((capture, table))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_record_round_trips_settings_and_capture() {
        let mut s = RenderSettings::default();
        s.vpl.seed = 7;
        s.vpl.count = 1024;
        let cam = Camera::look_at(
            "pose",
            glam::Vec3::new(0.1, 1.3, 2.7),
            glam::Vec3::ZERO,
            0.9,
            0.01,
            40.0,
        );
        let c = Capture {
            what: "render".into(),
            files: vec!["final.exr".into()],
            camera: (&cam).into(),
            width: 64,
            height: 48,
            frames: 4,
            timing_frames: 3,
            frame_index: 7,
            seed: 7,
            ..Default::default()
        };
        let text = record_toml(&c, &s).unwrap();
        let (back, rest) = split(&text).unwrap();
        assert_eq!(back.as_ref(), Some(&c));
        let settings: RenderSettings = rest.try_into().unwrap();
        assert_eq!(settings, s);
        // The camera comes back bit for bit.
        let cam2 = back.unwrap().camera.camera();
        assert_eq!(
            cam2.position.to_array().map(f32::to_bits),
            cam.position.to_array().map(f32::to_bits)
        );
        assert_eq!(
            cam2.forward.to_array().map(f32::to_bits),
            cam.forward.to_array().map(f32::to_bits)
        );
        assert_eq!(cam2.yfov.to_bits(), cam.yfov.to_bits());
        assert!(COMMIT.len() >= 7, "{COMMIT}");
        assert_eq!(
            sidecar_path(Path::new("a/b/final_001.png")),
            Path::new("a/b/final_001.capture.toml")
        );
    }
}

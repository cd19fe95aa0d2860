//! glTF 2.0 (`.gltf` / `.glb`) loading into a flattened, world-space [`Scene`].
//!
//! The loader is deliberately forgiving about things that do not change geometry or diffuse
//! albedo (material extensions, DDS texture alternatives, missing images): those become
//! entries in [`Scene::warnings`] (and `log::warn!`). Things that would make the geometry wrong
//! (compressed/quantised geometry required by the file, unknown required extensions, missing
//! or truncated buffers) are errors with a one-line message.
//!
//! All buffer and accessor reads are bounds-checked here (the `gltf` crate's own readers can
//! panic on malformed files), so no user file can make the loader panic.

use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::{Mat3, Mat4, Vec2, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::json::camera::Type as CameraType;
use gltf::json::extensions::scene::khr_lights_punctual::Type as LightType;
use gltf::json::validation::Checked;
use gltf::mesh::Mode;

mod data;
mod materials;
mod prepare;
mod walk;
use materials::*;
use prepare::*;
use walk::*;

use super::{Aabb, Camera, DirectionalLight, Material, Scene, TextureImage};
use data::*;

/// Everything that can stop a scene from loading. Each variant displays as one line.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A scene named without a file extension that is neither a built-in scene nor a file.
    #[error(
        "no scene '{name}': not a built-in scene ({}) and no such file (a glTF file ends in .gltf or .glb, a preset in .toml)",
        builtin.join(", ")
    )]
    UnknownScene {
        name: String,
        builtin: Vec<&'static str>,
    },
    /// A scene file named by a preset or `--scene` is on no folder of the search path (the
    /// message names them and, for the reference scenes, the command that fetches them).
    #[error("{message}")]
    MissingScene { path: PathBuf, message: String },
    /// The file (glTF, preset, ...) could not be opened or read.
    #[error("cannot read {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The file is not a glTF 2.0 asset the parser accepts (bad JSON, bad GLB header, invalid
    /// references, ...).
    #[error("{} is not a valid glTF file: {message}", path.display())]
    InvalidGltf { path: PathBuf, message: String },
    /// An external `.bin` buffer named by the file does not exist.
    #[error("{}: buffer {index} file {} is missing", gltf.display(), buffer.display())]
    MissingBuffer {
        gltf: PathBuf,
        index: usize,
        buffer: PathBuf,
    },
    /// A buffer holds fewer bytes than its declared `byteLength`.
    #[error(
        "{}: buffer {index} ({name}) is truncated: {declared} bytes declared, only {actual} present",
        path.display()
    )]
    TruncatedBuffer {
        path: PathBuf,
        index: usize,
        name: String,
        declared: usize,
        actual: usize,
    },
    /// A buffer could not be loaded for another reason (bad data URI, unsupported URI scheme,
    /// GLB without a BIN chunk, ...).
    #[error("{}: buffer {index} cannot be loaded: {message}", path.display())]
    BadBuffer {
        path: PathBuf,
        index: usize,
        message: String,
    },
    /// The file requires an extension this loader cannot honour without getting the geometry
    /// wrong.
    #[error("{}: required glTF extension {name} is not supported ({reason})", path.display())]
    UnsupportedExtension {
        path: PathBuf,
        name: String,
        reason: String,
    },
    /// Nothing renderable is left after skipping unsupported primitives and bad triangles.
    #[error("{}: no triangles left to render ({details})", path.display())]
    NoTriangles { path: PathBuf, details: String },
    /// A scene preset (`.toml`) is malformed or inconsistent.
    #[error("bad scene preset {}: {message}", path.display())]
    Preset { path: PathBuf, message: String },
}

/// The most vertices a scene may have (indices are u32; instancing must not get past it).
const MAX_VERTICES: usize = 1 << 31;

/// What the loader does with a glTF extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ExtPolicy {
    /// Fully or partly implemented (details are warned about where data is skipped).
    Supported,
    /// Does not change geometry or diffuse albedo: ignored with a warning.
    Ignored(&'static str),
    /// Read, with a note on what of it is not (a warning).
    Partial(&'static str),
    /// Changes how geometry is stored or placed: an error when required.
    Geometry(&'static str),
    /// Not known to this loader.
    Unknown,
}

fn ext_policy(name: &str) -> ExtPolicy {
    match name {
        "KHR_lights_punctual" => ExtPolicy::Supported,
        "MSFT_texture_dds" => ExtPolicy::Ignored(
            "DDS images are not decoded; each texture's PNG/JPG source is used (a DDS-only \
             roughness / metallic texture: the PNG/JPG beside its .dds, if there is one)",
        ),
        "AMD_split_roughnessMetallic" => ExtPolicy::Partial(
            "its roughness / metallic textures are read (G / B channels; shading with --brdf ggx); \
             DDS-only ones through the PNG/JPG beside their .dds",
        ),
        // Offset, rotation and scale applied to the UVs of the base colour texture's set
        // (`texture_transform`); a different transform on a material's other textures is
        // warned about.
        "KHR_texture_transform" => ExtPolicy::Supported,
        "KHR_texture_basisu" | "EXT_texture_webp" | "EXT_texture_avif" => ExtPolicy::Ignored(
            "only PNG/JPG texture sources are decoded; other textures fall back to the colour factor",
        ),
        "KHR_materials_variants" => {
            ExtPolicy::Ignored("material variants are ignored; the default materials are used")
        }
        "KHR_xmp_json_ld" | "KHR_animation_pointer" => ExtPolicy::Ignored("metadata/animation is not used"),
        // Decoded with draco-core (`data::read_draco_primitive`).
        "KHR_draco_mesh_compression" => ExtPolicy::Supported,
        // Decoded with meshoptimizer-rs (`data::decode_meshopt_views`).
        "EXT_meshopt_compression" => ExtPolicy::Supported,
        // Normalised and integer accessors are dequantised by `data::read_floats`; node
        // transforms carry the scale.
        "KHR_mesh_quantization" => ExtPolicy::Supported,
        // Instances expanded into the scene (`instance_transforms`).
        "EXT_mesh_gpu_instancing" => ExtPolicy::Supported,
        "KHR_meshopt_compression" => ExtPolicy::Geometry(
            "its buffer views are not decoded (EXT_meshopt_compression is: write the file with \
             `gltf-transform meshopt` or `gltfpack -c`)",
        ),
        n if n.starts_with("KHR_materials_") => {
            ExtPolicy::Ignored("only the base colour of materials is used")
        }
        _ => ExtPolicy::Unknown,
    }
}

/// Loads a `.gltf` or `.glb` file (detected from its content) into a world-space [`Scene`].
pub fn load_gltf(path: &Path) -> Result<Scene, SceneError> {
    let bytes = std::fs::read(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let invalid = |message: String| invalid_gltf(path, message);

    // Container: GLB or plain JSON.
    let (json_bytes, blob): (Vec<u8>, Option<Vec<u8>>) = if bytes.starts_with(b"glTF") {
        let glb = gltf::Glb::from_slice(&bytes).map_err(|e| invalid(format!("bad GLB: {e}")))?;
        (glb.json.into_owned(), glb.bin.map(|b| b.into_owned()))
    } else {
        (bytes, None)
    };
    let mut root: gltf::json::Root =
        gltf::json::deserialize::from_slice(&json_bytes).map_err(|e| invalid(one_line(&e.to_string())))?;
    drop(json_bytes);

    let mut warnings = Warnings::default();
    apply_extension_policy(&mut root, path, &mut warnings)?;
    let sources = point_sourceless_textures(&mut root).map_err(invalid)?;
    point_draco_accessors(&mut root);
    relax_position_bounds(&mut root).map_err(invalid)?;

    // Last line of defence: a panic inside the parser's validation becomes an error.
    let doc = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| gltf::Document::from_json(root)))
        .map_err(|_| invalid("the glTF validator failed on this file".into()))?
        .map_err(|e| invalid(validation_message(&e)))?;
    let base_dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();

    let data = load_buffers(&doc, path, &base_dir, blob)?;
    let decoded = decode_meshopt_views(&doc, &data).map_err(invalid)?;
    let mut info: Vec<String> = Vec::new();
    if !decoded.is_empty() {
        info.push(format!(
            "EXT_meshopt_compression: {} buffer view(s) decoded (meshoptimizer-rs)",
            decoded.len()
        ));
    }
    let buffers = Buffers { data, decoded };

    let (requests, users) = texture_requests(&doc, &sources, &base_dir, &mut warnings);
    let (textures, texture_of) = load_textures(&doc, &buffers, &base_dir, &users, &mut warnings);
    let materials = build_materials(&doc, requests, &texture_of, &mut warnings);
    let scene = Scene {
        name: path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".into()),
        textures,
        ..Default::default()
    };
    let mut walk = Walk {
        doc: &doc,
        buffers: &buffers,
        path,
        materials,
        default_material: None,
        scene,
        stats: GeomStats::default(),
        cameras: Vec::new(),
        warnings,
    };
    walk.nodes()?;
    let Walk {
        materials,
        mut scene,
        stats,
        cameras: pending_cameras,
        mut warnings,
        ..
    } = walk;
    stats.summarise(&doc, materials.used_transform, &mut info, &mut warnings);

    if scene.indices.is_empty() {
        let mut details = String::new();
        let _ = write!(
            details,
            "{} mesh(es); {} non-finite, {} zero-area, {} bad-index triangles dropped",
            doc.meshes().len(),
            stats.non_finite,
            stats.degenerate,
            stats.bad_index
        );
        if !stats.skipped_modes.is_empty() {
            let modes: Vec<&str> = stats.skipped_modes.keys().map(String::as_str).collect();
            let _ = write!(details, "; non-triangle primitives skipped: {}", modes.join(", "));
        }
        // Why primitives were skipped (their data unreadable), the first of them.
        if let Some(w) = warnings.0.iter().find(|w| w.contains(" skipped: ")) {
            let _ = write!(details, "; {w}");
        }
        return Err(SceneError::NoTriangles {
            path: path.to_path_buf(),
            details,
        });
    }
    if scene.positions.len() > u32::MAX as usize {
        return Err(invalid("more than 2^32 vertices".into()));
    }

    scene.materials = materials.materials;
    scene.recompute_bounds();
    let bounds = scene.bounds;
    for (mut cam, zfar) in pending_cameras {
        cam.zfar = match zfar {
            Some(f) if f.is_finite() && f > cam.znear => f,
            _ => finite_far(&cam, &bounds),
        };
        let mut name = cam.name.clone();
        let mut k = 2;
        while scene.cameras.iter().any(|c| c.name == name) {
            name = format!("{}_{k}", cam.name);
            k += 1;
        }
        cam.name = name;
        if let Some(w) = cam.fit_clip_range(&bounds) {
            warnings.push(w);
        }
        scene.cameras.push(cam);
    }

    for w in &warnings.0 {
        log::warn!("{}: {w}", path.display());
    }
    scene.warnings = warnings.0;
    for i in &info {
        log::info!("{}: {i}", path.display());
    }
    scene.load_notes = info;
    Ok(scene)
}

/// A file the loader refuses, with the message.
fn invalid_gltf(path: &Path, message: String) -> SceneError {
    SceneError::InvalidGltf {
        path: path.to_path_buf(),
        message,
    }
}

/// The TEXCOORD set a texture reads: KHR_texture_transform's `texCoord` override, else the
/// texture info's.
fn tex_coord(info: &gltf::texture::Info) -> u32 {
    info.extension_value("KHR_texture_transform")
        .and_then(|v| v.get("texCoord"))
        .and_then(|c| c.as_u64())
        .map_or(info.tex_coord(), |c| c as u32)
}

/// KHR_texture_transform of a texture reference as the 3x3 matrix T * R * S of the extension's
/// specification (uv' = offset + R(rotation) * (scale * uv), R = [[cos, sin], [-sin, cos]] in
/// row-major order); `None` without the extension.
fn texture_transform(info: &gltf::texture::Info) -> Option<Mat3> {
    let ext = info.extension_value("KHR_texture_transform")?;
    let pair = |k: &str, d: [f32; 2]| {
        ext.get(k)
            .and_then(|v| v.as_array())
            .filter(|a| a.len() == 2)
            .map(|a| {
                [
                    a[0].as_f64().unwrap_or(d[0] as f64) as f32,
                    a[1].as_f64().unwrap_or(d[1] as f64) as f32,
                ]
            })
            .unwrap_or(d)
    };
    let [ox, oy] = pair("offset", [0.0, 0.0]);
    let [sx, sy] = pair("scale", [1.0, 1.0]);
    let r = ext.get("rotation").and_then(|v| v.as_f64()).unwrap_or(0.0) as f32;
    let (s, c) = r.sin_cos();
    // Columns of T * R * S (glam is column-major): x' = c sx x + s sy y + ox,
    // y' = -s sx x + c sy y + oy.
    let m = Mat3::from_cols(
        Vec3::new(c * sx, -s * sx, 0.0),
        Vec3::new(s * sy, c * sy, 0.0),
        Vec3::new(ox, oy, 1.0),
    );
    m.is_finite().then_some(m)
}

/// EXT_mesh_gpu_instancing's per-instance transforms (TRANSLATION, ROTATION, SCALE accessors,
/// each optional; float or normalised integer components as the extension allows).
fn instance_transforms(
    doc: &gltf::Document,
    ext: &serde_json::Value,
    buffers: &Buffers,
) -> Result<Vec<Mat4>, String> {
    let attrs = ext.get("attributes").ok_or("no attributes")?;
    let read = |name: &str, comps: usize| -> Result<Option<Vec<f32>>, String> {
        let Some(i) = attrs.get(name).and_then(|v| v.as_u64()) else {
            return Ok(None);
        };
        let acc = doc
            .accessors()
            .nth(i as usize)
            .ok_or_else(|| format!("{name} names missing accessor {i}"))?;
        let v = read_floats(&acc, buffers).map_err(|e| format!("{name}: {e}"))?;
        if v.len() != acc.count() * comps {
            return Err(format!("{name} is not a {comps}-component accessor"));
        }
        Ok(Some(v))
    };
    let t = read("TRANSLATION", 3)?;
    let r = read("ROTATION", 4)?;
    let s = read("SCALE", 3)?;
    let counts: Vec<usize> = [(&t, 3), (&r, 4), (&s, 3)]
        .iter()
        .filter_map(|(v, c)| v.as_ref().map(|v| v.len() / c))
        .collect();
    let n = *counts.first().ok_or("no TRANSLATION, ROTATION or SCALE")?;
    if counts.iter().any(|&c| c != n) {
        return Err("its accessors have different counts".into());
    }
    Ok((0..n)
        .map(|i| {
            let tr = t.as_ref().map_or(Vec3::ZERO, |v| Vec3::from_slice(&v[3 * i..]));
            // A zero quaternion would be NaN: the identity, as for a missing ROTATION.
            let ro = r.as_ref().map_or(glam::Quat::IDENTITY, |v| {
                let q = glam::Quat::from_slice(&v[4 * i..]);
                if q.is_finite() && q.length_squared() > 0.0 {
                    q.normalize()
                } else {
                    glam::Quat::IDENTITY
                }
            });
            let sc = s.as_ref().map_or(Vec3::ONE, |v| Vec3::from_slice(&v[3 * i..]));
            Mat4::from_scale_rotation_translation(sc, ro, tr)
        })
        .collect())
}

#[derive(Default)]
struct Warnings(Vec<String>);

impl Warnings {
    fn push(&mut self, w: String) {
        self.0.push(w);
    }
}

#[derive(Default)]
struct GeomStats {
    non_finite: usize,
    degenerate: usize,
    bad_index: usize,
    skipped_modes: BTreeMap<String, usize>,
    skipped_lights: BTreeMap<String, usize>,
    uv_missing: BTreeSet<String>,
    /// KHR_draco_mesh_compression primitives decoded (counted per node that draws them).
    draco: usize,
    /// EXT_mesh_gpu_instancing: nodes and their instances.
    instanced_nodes: usize,
    instances: usize,
}

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

fn validation_message(e: &gltf::Error) -> String {
    match e {
        gltf::Error::Validation(errors) => {
            let shown: Vec<String> = errors
                .iter()
                .take(3)
                .map(|(p, err)| format!("{p}: {err}"))
                .collect();
            let more = if errors.len() > 3 {
                format!(" (and {} more)", errors.len() - 3)
            } else {
                String::new()
            };
            format!("validation failed: {}{more}", shown.join("; "))
        }
        other => one_line(&other.to_string()),
    }
}

/// An image's label (for messages) and its decoded texture or error.
type DecodeResult = (String, Result<TextureImage, String>);

/// Appends one world-space instance of a primitive, dropping bad triangles.
fn append_primitive(scene: &mut Scene, p: &PrimData, world: &Mat4, material: u32, stats: &mut GeomStats) {
    let m3 = Mat3::from_mat4(*world);
    let flip = m3.determinant() < 0.0;
    let normal_matrix = m3.inverse().transpose();
    let wpos: Vec<Vec3> = p.positions.iter().map(|&v| world.transform_point3(v)).collect();
    let n = wpos.len();
    let mut remap = vec![u32::MAX; if p.normals.is_some() { n } else { 0 }];

    for tri in p.indices.chunks_exact(3) {
        let (a, mut b, mut c) = (tri[0] as usize, tri[1] as usize, tri[2] as usize);
        if a >= n || b >= n || c >= n {
            stats.bad_index += 1;
            continue;
        }
        if flip {
            std::mem::swap(&mut b, &mut c);
        }
        let (pa, pb, pc) = (wpos[a], wpos[b], wpos[c]);
        if !(pa.is_finite() && pb.is_finite() && pc.is_finite()) {
            stats.non_finite += 1;
            continue;
        }
        let cross = (pb - pa).cross(pc - pa);
        let max_edge2 = (pb - pa)
            .length_squared()
            .max((pc - pa).length_squared())
            .max((pc - pb).length_squared());
        let area2 = cross.length_squared();
        if area2.is_nan()
            || area2 <= f32::MIN_POSITIVE
            || !area2.is_finite()
            || area2 <= 1e-14 * max_edge2 * max_edge2
        {
            stats.degenerate += 1;
            continue;
        }
        let face_n = cross / area2.sqrt();
        let uv = |i: usize| {
            p.uvs
                .as_ref()
                .and_then(|u| u.get(i).copied())
                .unwrap_or(Vec2::ZERO)
        };
        match &p.normals {
            None => {
                for &v in &[a, b, c] {
                    scene.indices.push(scene.positions.len() as u32);
                    scene.positions.push(wpos[v]);
                    scene.normals.push(face_n);
                    scene.uvs.push(uv(v));
                }
            }
            Some(normals) => {
                for &v in &[a, b, c] {
                    if remap[v] == u32::MAX {
                        remap[v] = scene.positions.len() as u32;
                        let wn = normal_matrix * normals[v];
                        let wn = if wn.is_finite() && wn.length_squared() > 1e-20 {
                            wn.normalize()
                        } else {
                            face_n
                        };
                        scene.positions.push(wpos[v]);
                        scene.normals.push(wn);
                        scene.uvs.push(uv(v));
                    }
                    scene.indices.push(remap[v]);
                }
            }
        }
        scene.triangle_materials.push(material);
    }
}

fn make_camera(name: &str, world: &Mat4, yfov: f32, znear: f32, warnings: &mut Warnings) -> Camera {
    let m3 = Mat3::from_mat4(*world);
    let position = world.transform_point3(Vec3::ZERO);
    let forward = (m3 * Vec3::NEG_Z).normalize_or(Vec3::NEG_Z);
    let up = (m3 * Vec3::Y).normalize_or(Vec3::Y);
    let yfov = if yfov.is_finite() && yfov > 1e-3 && yfov < std::f32::consts::PI - 1e-3 {
        yfov
    } else {
        warnings.push(format!(
            "camera '{name}' has an invalid yfov {yfov}; using 50 degrees"
        ));
        50f32.to_radians()
    };
    let znear = if znear.is_finite() && znear > 0.0 {
        znear
    } else {
        0.01
    };
    let mut cam = Camera {
        name: name.to_string(),
        position: if position.is_finite() {
            position
        } else {
            Vec3::ZERO
        },
        forward,
        up,
        yfov,
        znear,
        zfar: f32::INFINITY,
    };
    cam.orthonormalize();
    if !(cam.forward.is_finite() && cam.up.is_finite()) {
        cam.forward = Vec3::NEG_Z;
        cam.up = Vec3::Y;
    }
    cam
}

/// A finite far plane that covers the whole scene from the camera.
fn finite_far(cam: &Camera, bounds: &Aabb) -> f32 {
    let d = (cam.position - bounds.center()).length() + bounds.radius();
    (2.0 * d).max(cam.znear * 1000.0).max(1.0)
}

/// A glTF factor in [0, 1]: clamped, NaN to the default 1.
fn clamp_factor(v: f32) -> f32 {
    if v.is_nan() { 1.0 } else { v.clamp(0.0, 1.0) }
}

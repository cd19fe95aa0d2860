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
    let invalid = |message: String| SceneError::InvalidGltf {
        path: path.to_path_buf(),
        message,
    };

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

    // Extension policy. Required extensions are removed from the list before validation
    // (the gltf crate rejects required extensions it does not know, even harmless ones).
    let required = std::mem::take(&mut root.extensions_required);
    for name in &required {
        match ext_policy(name) {
            ExtPolicy::Supported => {}
            ExtPolicy::Ignored(why) => {
                warnings.push(format!("glTF extension {name} (required) is ignored: {why}"))
            }
            ExtPolicy::Partial(why) => warnings.push(format!("glTF extension {name} (required): {why}")),
            ExtPolicy::Geometry(why) => {
                return Err(SceneError::UnsupportedExtension {
                    path: path.to_path_buf(),
                    name: name.clone(),
                    reason: why.to_string(),
                });
            }
            ExtPolicy::Unknown => {
                return Err(SceneError::UnsupportedExtension {
                    path: path.to_path_buf(),
                    name: name.clone(),
                    reason: "unknown extension; it could change the geometry".into(),
                });
            }
        }
    }
    for name in root.extensions_used.iter().filter(|n| !required.contains(n)) {
        match ext_policy(name) {
            ExtPolicy::Supported => {}
            ExtPolicy::Ignored(why) => warnings.push(format!("glTF extension {name} is ignored: {why}")),
            ExtPolicy::Partial(why) => warnings.push(format!("glTF extension {name}: {why}")),
            ExtPolicy::Geometry(why) => warnings.push(format!(
                "glTF extension {name} is used but not required and is ignored ({why}); \
                 the uncompressed fallback data is loaded"
            )),
            ExtPolicy::Unknown => warnings.push(format!("unknown glTF extension {name} is ignored")),
        }
    }

    // Textures whose only image is given through an extension (e.g. MSFT_texture_dds without
    // a plain `source`) are pointed at a placeholder image so validation passes, and are
    // treated as "no texture" below.
    let mut sourceless: HashSet<usize> = HashSet::new();
    // Their DDS image's URI (MSFT_texture_dds), where the file gives one.
    let mut dds_uris: HashMap<usize, String> = HashMap::new();
    for (i, t) in root.textures.iter().enumerate() {
        if t.source.value() != u32::MAX as usize {
            continue;
        }
        let uri = t
            .extensions
            .as_ref()
            .and_then(|e| e.others.get("MSFT_texture_dds"))
            .and_then(|v| v.get("source"))
            .and_then(|v| v.as_u64())
            .and_then(|k| root.images.get(k as usize))
            .and_then(|img| img.uri.clone());
        if let Some(uri) = uri {
            dds_uris.insert(i, uri);
        }
    }
    if root
        .textures
        .iter()
        .any(|t| t.source.value() == u32::MAX as usize)
    {
        let placeholder: gltf::json::Image =
            gltf::json::deserialize::from_str(r#"{"uri":"data:,","name":"placeholder"}"#)
                .map_err(|e| invalid(e.to_string()))?;
        let idx = root.images.len() as u32;
        root.images.push(placeholder);
        for (i, t) in root.textures.iter_mut().enumerate() {
            if t.source.value() == u32::MAX as usize {
                t.source = gltf::json::Index::new(idx);
                sourceless.insert(i);
            }
        }
    }

    // KHR_draco_mesh_compression: the primitive's accessors have no buffer view (their data
    // is in the Draco stream, `data::read_draco_primitive`), which the gltf crate's validation
    // rejects; they are pointed at the Draco buffer view, and never read through it.
    for mesh in &root.meshes {
        for prim in &mesh.primitives {
            let Some(view) = prim
                .extensions
                .as_ref()
                .and_then(|e| e.others.get("KHR_draco_mesh_compression"))
                .and_then(|d| d.get("bufferView"))
                .and_then(|v| v.as_u64())
            else {
                continue;
            };
            let accessors = prim
                .attributes
                .values()
                .map(|a| a.value())
                .chain(prim.indices.map(|i| i.value()));
            for a in accessors {
                if let Some(acc) = root.accessors.get_mut(a)
                    && acc.buffer_view.is_none()
                    && acc.sparse.is_none()
                {
                    acc.buffer_view = Some(gltf::json::Index::new(view as u32));
                    acc.byte_offset = None;
                }
            }
        }
    }

    // POSITION min/max are required by the spec but unused here: do not reject files that
    // lack them or get them wrong.
    let position_accessors: Vec<usize> = root
        .meshes
        .iter()
        .flat_map(|m| m.primitives.iter())
        .flat_map(|p| p.attributes.iter())
        .filter(|(sem, _)| matches!(sem, Checked::Valid(gltf::Semantic::Positions)))
        .map(|(_, a)| a.value())
        .collect();
    for a in position_accessors {
        // (the gltf crate's validation indexes POSITION accessors without a bounds check)
        let acc = root
            .accessors
            .get_mut(a)
            .ok_or_else(|| invalid(format!("a POSITION attribute names missing accessor {a}")))?;
        let zero = gltf::json::Value::from(vec![0.0f32; 3]);
        acc.min = Some(zero.clone());
        acc.max = Some(zero);
    }

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

    // Materials and their textures: base colour, and metallic-roughness (glTF's
    // `metallicRoughnessTexture`, or AMD_split_roughnessMetallic's separate roughness and
    // metallic textures; roughness is read from G and metallic from B either way, which also
    // reads a grey image right).
    let mut requests: Vec<MaterialTextures> = Vec::new();
    let mut users: BTreeMap<(TexSource, TexKind), Vec<String>> = BTreeMap::new();
    for (i, m) in doc.materials().enumerate() {
        let name = m
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("material{i}"));
        let pbr = m.pbr_metallic_roughness();
        let mut req = MaterialTextures::default();
        // A texture's source: its image, or for a DDS-only data texture the image beside it.
        let source = |tex: usize, kind: TexKind, what: &str, warnings: &mut Warnings| -> Option<TexSource> {
            if !sourceless.contains(&tex) {
                return doc
                    .textures()
                    .nth(tex)
                    .map(|t| TexSource::Image(t.source().index()));
            }
            let sibling = (kind == TexKind::Data)
                .then(|| dds_uris.get(&tex).and_then(|u| dds_sibling(&base_dir, u)))
                .flatten();
            if sibling.is_none() {
                let fallback = match kind {
                    TexKind::Color => "the colour factor only",
                    TexKind::Data => "the factor only",
                };
                let beside = if kind == TexKind::Data {
                    " (nor one beside its DDS)"
                } else {
                    ""
                };
                warnings.push(format!(
                    "material '{name}': {what} texture {tex} has no PNG/JPG source{beside}; using {fallback}"
                ));
            }
            sibling.map(TexSource::File)
        };
        if let Some(info) = pbr.base_color_texture() {
            req.base = source(
                info.texture().index(),
                TexKind::Color,
                "base colour",
                &mut warnings,
            )
            .map(|src| (src, tex_coord(&info)));
        }
        if let Some(info) = pbr.metallic_roughness_texture() {
            let src = source(
                info.texture().index(),
                TexKind::Data,
                "metallic-roughness",
                &mut warnings,
            );
            req.roughness = src.clone().map(|s| (s, tex_coord(&info)));
            req.metallic = src.map(|s| (s, tex_coord(&info)));
        }
        if let Some(split) = m.extension_value("AMD_split_roughnessMetallic") {
            for (key, what) in [("roughnessTexture", "roughness"), ("metallicTexture", "metallic")] {
                let Some(tex) = split
                    .get(key)
                    .and_then(|t| t.get("index"))
                    .and_then(|v| v.as_u64())
                else {
                    continue;
                };
                let set = split
                    .get(key)
                    .and_then(|t| t.get("texCoord"))
                    .and_then(|v| v.as_u64())
                    .unwrap_or(0) as u32;
                let slot = if key == "roughnessTexture" {
                    &mut req.roughness
                } else {
                    &mut req.metallic
                };
                // glTF's own metallicRoughnessTexture takes precedence.
                if slot.is_some() {
                    continue;
                }
                let found = if (tex as usize) < doc.textures().len() {
                    source(tex as usize, TexKind::Data, what, &mut warnings)
                } else {
                    warnings.push(format!(
                        "material '{name}': AMD_split_roughnessMetallic names missing texture {tex}; using the factor only"
                    ));
                    None
                };
                *slot = found.map(|s| (s, set));
            }
        }
        for (src, kind) in [
            (&req.base, TexKind::Color),
            (&req.roughness, TexKind::Data),
            (&req.metallic, TexKind::Data),
        ] {
            if let Some((src, _)) = src {
                let u = users.entry((src.clone(), kind)).or_default();
                if !u.contains(&name) {
                    u.push(name.clone());
                }
            }
        }
        requests.push(req);
    }
    let (textures, texture_of) = load_textures(&doc, &buffers, &base_dir, &users, &mut warnings);
    let mut materials: Vec<Material> = Vec::new();
    let mut material_uv_set: Vec<u32> = Vec::new();
    let mut material_uv_transform: Vec<Option<Mat3>> = Vec::new();
    let mut used_transform = false;
    for ((i, m), req) in doc.materials().enumerate().zip(requests) {
        let pbr = m.pbr_metallic_roughness();
        let factor = pbr.base_color_factor();
        let factor = if factor.iter().all(|c| c.is_finite()) {
            factor
        } else {
            warnings.push(format!(
                "material {i} has a non-finite baseColorFactor; using white"
            ));
            [1.0; 4]
        };
        let name = m
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("material{i}"));
        let texture = |t: &Option<(TexSource, u32)>, kind: TexKind| {
            t.as_ref()
                .and_then(|(src, _)| texture_of.get(&(src.clone(), kind)).copied().flatten())
        };
        let (base, roughness_tex, metallic_tex) = (
            texture(&req.base, TexKind::Color),
            texture(&req.roughness, TexKind::Data),
            texture(&req.metallic, TexKind::Data),
        );
        // One UV set per material (the vertices carry one): the base colour's, else the
        // metallic-roughness texture's.
        let sets: Vec<u32> = [
            (base, &req.base),
            (roughness_tex, &req.roughness),
            (metallic_tex, &req.metallic),
        ]
        .iter()
        .filter(|(t, _)| t.is_some())
        .filter_map(|(_, r)| r.as_ref().map(|(_, set)| *set))
        .collect();
        let set = sets
            .first()
            .copied()
            .unwrap_or_else(|| pbr.base_color_texture().map(|t| tex_coord(&t)).unwrap_or(0));
        if sets.iter().any(|&s| s != set) {
            warnings.push(format!(
                "material '{name}': its textures use different TEXCOORD sets; all read set {set}"
            ));
        }
        // KHR_texture_transform: the base colour's (else the metallic-roughness texture's)
        // goes into the vertex UVs; the metallic-roughness texture reads through its own
        // transform relative to that one (`Material::metal_rough_uv`).
        let base_t = pbr.base_color_texture().and_then(|t| texture_transform(&t));
        let mr_t = pbr
            .metallic_roughness_texture()
            .and_then(|t| texture_transform(&t));
        let transform = if pbr.base_color_texture().is_some() {
            base_t
        } else {
            mr_t
        };
        let relative = mr_t.unwrap_or(Mat3::IDENTITY) * transform.unwrap_or(Mat3::IDENTITY).inverse();
        let metal_rough_uv = if pbr.metallic_roughness_texture().is_some()
            && relative.is_finite()
            && !relative.abs_diff_eq(Mat3::IDENTITY, 1e-7)
        {
            used_transform = true;
            [
                [relative.x_axis.x, relative.y_axis.x, relative.z_axis.x],
                [relative.x_axis.y, relative.y_axis.y, relative.z_axis.y],
            ]
        } else {
            crate::scene::UV_IDENTITY
        };
        if let Some(t) = transform.filter(|t| *t != Mat3::IDENTITY) {
            material_uv_transform.push(Some(t));
            used_transform = true;
        } else {
            material_uv_transform.push(None);
        }
        materials.push(Material {
            name,
            base_color_factor: factor,
            base_color_texture: base,
            // glTF's defaults are 1 and 1; out-of-range or non-finite factors are clamped to
            // the nearest valid value (NaN: the default).
            metallic: clamp_factor(pbr.metallic_factor()),
            roughness: clamp_factor(pbr.roughness_factor()),
            roughness_texture: roughness_tex,
            metallic_texture: metallic_tex,
            metal_rough_uv,
        });
        material_uv_set.push(set);
    }
    let mut default_material: Option<u32> = None;

    let mut scene = Scene {
        name: path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".into()),
        textures,
        ..Default::default()
    };

    // Walk the node hierarchy.
    let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(s) => s.nodes().collect(),
        None => {
            let mut is_child = vec![false; doc.nodes().len()];
            for n in doc.nodes() {
                for c in n.children() {
                    is_child[c.index()] = true;
                }
            }
            doc.nodes().filter(|n| !is_child[n.index()]).collect()
        }
    };

    let mut stats = GeomStats::default();
    let mut pending_cameras: Vec<(Camera, Option<f32>)> = Vec::new();
    let mut visited = vec![false; doc.nodes().len()];
    let mut stack: Vec<(gltf::Node, Mat4)> = roots.into_iter().rev().map(|n| (n, Mat4::IDENTITY)).collect();
    let json = doc.as_json();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut visited[node.index()], true) {
            warnings.push(format!(
                "node {} is reached twice (cycle or shared child); the repeat is skipped",
                node.index()
            ));
            continue;
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        for c in node.children().collect::<Vec<_>>().into_iter().rev() {
            stack.push((c, world));
        }

        if let Some(mesh) = node.mesh() {
            // EXT_mesh_gpu_instancing: the mesh once per instance (each instance's TRS after
            // the node's transform), else once.
            let instances = match node.extension_value("EXT_mesh_gpu_instancing") {
                Some(ext) => match instance_transforms(&doc, ext, &buffers) {
                    Ok(v) => {
                        stats.instanced_nodes += 1;
                        stats.instances += v.len();
                        v
                    }
                    Err(e) => {
                        warnings.push(format!(
                            "node {}: EXT_mesh_gpu_instancing: {e}; its mesh is loaded once",
                            node.index()
                        ));
                        vec![Mat4::IDENTITY]
                    }
                },
                None => vec![Mat4::IDENTITY],
            };
            for (pi, prim) in mesh.primitives().enumerate() {
                if prim.mode() != Mode::Triangles {
                    *stats
                        .skipped_modes
                        .entry(format!("{:?}", prim.mode()))
                        .or_insert(0) += 1;
                    continue;
                }
                let mat = match prim.material().index() {
                    Some(m) => m as u32,
                    None => *default_material.get_or_insert_with(|| {
                        materials.push(Material::default());
                        material_uv_set.push(0);
                        material_uv_transform.push(None);
                        (materials.len() - 1) as u32
                    }),
                };
                let uv_set = material_uv_set.get(mat as usize).copied().unwrap_or(0);
                let label = format!(
                    "mesh {} ('{}') primitive {pi}",
                    mesh.index(),
                    mesh.name().unwrap_or("")
                );
                let draco = prim.extension_value("KHR_draco_mesh_compression");
                let read = match draco {
                    Some(ext) => {
                        let r = read_draco_primitive(&doc, &prim, ext, &buffers, uv_set);
                        stats.draco += r.is_ok() as usize;
                        r
                    }
                    None => read_primitive(&prim, &buffers, uv_set),
                };
                match read {
                    Ok((mut data, uv_missing)) => {
                        if uv_missing {
                            stats.uv_missing.insert(label.clone());
                        }
                        if let (Some(t), Some(uvs)) = (
                            material_uv_transform.get(mat as usize).copied().flatten(),
                            data.uvs.as_mut(),
                        ) {
                            for uv in uvs.iter_mut() {
                                *uv = t.transform_point2(*uv);
                            }
                        }
                        // Instancing multiplies the geometry: a budget keeps a small file from
                        // asking for more vertices than the u32 indices address.
                        let adds = data.positions.len().saturating_mul(instances.len());
                        if scene.positions.len().saturating_add(adds) > MAX_VERTICES {
                            return Err(invalid(format!(
                                "{label} with {} instance(s) would make the scene more than {MAX_VERTICES} vertices",
                                instances.len()
                            )));
                        }
                        for inst in &instances {
                            append_primitive(&mut scene, &data, &(world * *inst), mat, &mut stats);
                        }
                    }
                    Err(e) => warnings.push(format!("{label} skipped: {e}")),
                }
            }
        }

        let node_json = json.nodes.get(node.index());
        if let Some(ci) = node_json.and_then(|n| n.camera).map(|c| c.value()) {
            match json.cameras.get(ci) {
                Some(cam) => match (cam.type_, cam.perspective.as_ref()) {
                    (Checked::Valid(CameraType::Perspective), Some(p)) => {
                        let name = cam
                            .name
                            .clone()
                            .or_else(|| node.name().map(str::to_string))
                            .unwrap_or_else(|| format!("camera{ci}"));
                        let c = make_camera(&name, &world, p.yfov, p.znear, &mut warnings);
                        pending_cameras.push((c, p.zfar));
                    }
                    _ => warnings.push(format!(
                        "camera {ci} ('{}') is not a perspective camera; skipped",
                        cam.name.as_deref().unwrap_or("")
                    )),
                },
                None => warnings.push(format!("node {} references missing camera {ci}", node.index())),
            }
        }

        let light_index = node_json
            .and_then(|n| n.extensions.as_ref())
            .and_then(|e| e.khr_lights_punctual.as_ref())
            .map(|l| l.light.value());
        if let Some(li) = light_index {
            let light = json
                .extensions
                .as_ref()
                .and_then(|e| e.khr_lights_punctual.as_ref())
                .and_then(|l| l.lights.get(li));
            match light {
                Some(l) => match l.type_ {
                    Checked::Valid(LightType::Directional) => {
                        let dir = Mat3::from_mat4(world) * Vec3::NEG_Z;
                        let name = l
                            .name
                            .clone()
                            .or_else(|| node.name().map(str::to_string))
                            .unwrap_or_else(|| format!("light{li}"));
                        // KHR_lights_punctual: intensity (here irradiance, W/m^2) and colour
                        // are non-negative; a negative or non-finite one is refused, not
                        // clamped into a black or NaN image.
                        let color = Vec3::from_array(l.color);
                        if !(l.intensity.is_finite()
                            && l.intensity >= 0.0
                            && color.is_finite()
                            && color.min_element() >= 0.0)
                        {
                            return Err(invalid(format!(
                                "directional light '{name}' has intensity {} W/m^2 and colour {:?}: both must be finite and >= 0",
                                l.intensity, l.color
                            )));
                        }
                        if dir.is_finite() && dir.length_squared() > 0.0 {
                            scene.lights.push(DirectionalLight {
                                name,
                                direction: dir.normalize(),
                                irradiance: l.intensity * color,
                            });
                        } else {
                            warnings.push(format!(
                                "directional light '{name}' has a degenerate direction (a zero-scale node?); skipped"
                            ));
                        }
                    }
                    Checked::Valid(t) => {
                        *stats.skipped_lights.entry(format!("{t:?}")).or_insert(0) += 1;
                    }
                    Checked::Invalid => warnings.push(format!("light {li} has an invalid type; skipped")),
                },
                None => warnings.push(format!("node {} references missing light {li}", node.index())),
            }
        }
    }

    // What was decoded (the load summary's extension lines).
    if stats.draco > 0 {
        info.push(format!(
            "KHR_draco_mesh_compression: {} primitive(s) decoded (draco-core)",
            stats.draco
        ));
    }
    if stats.instanced_nodes > 0 {
        info.push(format!(
            "EXT_mesh_gpu_instancing: {} instance(s) of {} node(s) expanded",
            stats.instances, stats.instanced_nodes
        ));
    }
    if doc.extensions_used().any(|e| e == "KHR_mesh_quantization") {
        info.push("KHR_mesh_quantization: quantised attributes dequantised".into());
    }
    if used_transform {
        info.push("KHR_texture_transform: applied to the UVs of the transformed textures' sets".into());
    }

    // Summaries of skipped/dropped things, one warning each.
    for (mode, n) in &stats.skipped_modes {
        warnings.push(format!(
            "{n} primitive(s) with mode {mode} skipped: only triangle lists are supported"
        ));
    }
    for (kind, n) in &stats.skipped_lights {
        warnings.push(format!(
            "{n} {kind} light(s) skipped: only directional lights are supported"
        ));
    }
    if stats.non_finite > 0 {
        warnings.push(format!(
            "{} triangle(s) with non-finite (NaN/inf) vertex positions dropped",
            stats.non_finite
        ));
    }
    if stats.degenerate > 0 {
        warnings.push(format!("{} zero-area triangle(s) dropped", stats.degenerate));
    }
    if stats.bad_index > 0 {
        warnings.push(format!(
            "{} triangle(s) with out-of-range vertex indices dropped",
            stats.bad_index
        ));
    }
    if !stats.uv_missing.is_empty() {
        let list: Vec<&str> = stats.uv_missing.iter().map(String::as_str).take(5).collect();
        warnings.push(format!(
            "{} textured primitive(s) lack the TEXCOORD set their material uses; zero UVs used (e.g. {})",
            stats.uv_missing.len(),
            list.join(", ")
        ));
    }

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

    scene.materials = materials;
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

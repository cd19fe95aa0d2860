//! `export-scene`: the scene as world-space PLY meshes (one per material) plus a JSON file with
//! the camera, the sun and the materials, for independent renderers (scripts/mitsuba_check.py).
//!
//! Output folder layout:
//! - `mesh_<i>.ply`: binary little-endian PLY with the triangles of material `i` (world space;
//!   `x y z nx ny nz u v` per vertex). UVs are written exactly as the scene holds them (glTF
//!   convention: v = 0 is the top row of the image). Mitsuba 3 needs no flip: its `bitmap`
//!   texture also puts v = 0 at the first (top) row and its PLY loader keeps v (checked, see
//!   docs/mitsuba_check.md); a consumer with v = 0 at the bottom row uses 1 - v.
//! - `textures/tex_<i>.png`: the base-colour textures that some exported material uses, as the
//!   scene holds them (sRGB-encoded RGBA8, top row first).
//! - `scene.json`: camera, suns, materials and bounds (see [`scene_json`]).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, anyhow};
use clap::Args;
use glam::Vec3;

use crate::export::write_png;
use crate::scene::preset::{SceneSource, open_scene};
use crate::scene::{Camera, Scene};

#[derive(Args, Debug)]
pub struct ExportSceneArgs {
    /// `default` or another built-in scene (`window-box`, `corridor`, `glossy-thin`), a
    /// .gltf/.glb file, or a preset .toml.
    #[arg(long, default_value = "default")]
    pub scene: String,
    /// Camera name (default: the preset's, else the first).
    #[arg(long)]
    pub camera: Option<String>,
    #[arg(long)]
    pub out: PathBuf,
    /// `ply`: PLY meshes + scene.json (for independent renderers); `gltf`: scene.gltf +
    /// scene.bin + textures/ (world space, a primitive per material, every camera, the suns as
    /// KHR_lights_punctual): the built-in scenes as files other tools (glTF-Transform,
    /// gltfpack, Blender) can read.
    #[arg(long, value_enum, default_value = "ply")]
    pub format: ExportFormat,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ExportFormat {
    Ply,
    Gltf,
}

/// One material's triangles with their own compact vertex list.
struct MeshPart {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    uvs: Vec<[f32; 2]>,
    faces: Vec<[u32; 3]>,
}

/// Splits the scene's triangles by material; vertices are shared within a part. Triangles with
/// an out-of-range index or material are skipped and counted.
fn split_by_material(scene: &Scene) -> (Vec<MeshPart>, usize) {
    let mut parts: Vec<MeshPart> = (0..scene.materials.len())
        .map(|_| MeshPart {
            positions: Vec::new(),
            normals: Vec::new(),
            uvs: Vec::new(),
            faces: Vec::new(),
        })
        .collect();
    // remap[v] = (material + 1, local index) of the last part vertex v was copied into.
    let mut remap: Vec<(u32, u32)> = vec![(0, 0); scene.positions.len()];
    let mut skipped = 0usize;
    for t in 0..scene.triangle_count() {
        let m = scene.triangle_materials.get(t).copied().unwrap_or(0) as usize;
        let ids = &scene.indices[3 * t..3 * t + 3];
        if m >= parts.len() || ids.iter().any(|&i| i as usize >= scene.positions.len()) {
            skipped += 1;
            continue;
        }
        let part = &mut parts[m];
        let mut face = [0u32; 3];
        for (k, &vi) in ids.iter().enumerate() {
            let v = vi as usize;
            let (tag, local) = remap[v];
            if tag == m as u32 + 1 {
                face[k] = local;
                continue;
            }
            // A vertex shared by several materials is copied once per material; when the
            // materials alternate, a duplicate may be written (harmless).
            let local = part.positions.len() as u32;
            let p = scene.positions[v];
            // A missing or degenerate normal becomes the triangle's geometric normal (consumers
            // normalise normals; a zero one would give them NaNs).
            let n = scene
                .normals
                .get(v)
                .copied()
                .filter(|n| n.is_finite() && n.length_squared() > 1e-12)
                .unwrap_or_else(|| {
                    let [a, b, c] = scene.triangle(t);
                    (b - a).cross(c - a).normalize_or(Vec3::Y)
                });
            let uv = scene
                .uvs
                .get(v)
                .copied()
                .filter(|u| u.is_finite())
                .unwrap_or_default();
            part.positions.push(p.to_array());
            part.normals.push(n.to_array());
            part.uvs.push(uv.to_array());
            remap[v] = (m as u32 + 1, local);
            face[k] = local;
        }
        part.faces.push(face);
    }
    (parts, skipped)
}

/// Binary little-endian PLY with `x y z nx ny nz u v` vertices and triangle faces.
fn ply_bytes(part: &MeshPart) -> Vec<u8> {
    let header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment lightcut-workbench export-scene (world space)\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        part.positions.len(),
        part.faces.len()
    );
    let mut out = Vec::with_capacity(header.len() + part.positions.len() * 32 + part.faces.len() * 13);
    out.extend_from_slice(header.as_bytes());
    for i in 0..part.positions.len() {
        for x in part.positions[i]
            .iter()
            .chain(&part.normals[i])
            .chain(&part.uvs[i])
        {
            out.extend_from_slice(&x.to_le_bytes());
        }
    }
    for f in &part.faces {
        out.push(3u8);
        for &i in f {
            out.extend_from_slice(&(i as i32).to_le_bytes());
        }
    }
    out
}

/// A finite f32 as a JSON number (non-finite values are rejected earlier; 0 as a fallback).
fn num(x: f32) -> String {
    if x.is_finite() { format!("{x}") } else { "0".into() }
}

fn vec3(v: [f32; 3]) -> String {
    format!("[{}, {}, {}]", num(v[0]), num(v[1]), num(v[2]))
}

/// A JSON string literal.
fn jstr(s: &str) -> String {
    let mut o = String::with_capacity(s.len() + 2);
    o.push('"');
    for c in s.chars() {
        match c {
            '"' => o.push_str("\\\""),
            '\\' => o.push_str("\\\\"),
            '\n' => o.push_str("\\n"),
            '\r' => o.push_str("\\r"),
            '\t' => o.push_str("\\t"),
            c if (c as u32) < 0x20 => {
                let _ = write!(o, "\\u{:04x}", c as u32);
            }
            c => o.push(c),
        }
    }
    o.push('"');
    o
}

/// Material entry for the JSON: (name, linear albedo factor, texture path, mesh file).
struct MaterialEntry {
    name: String,
    albedo: [f32; 3],
    /// glTF metallic and roughness factors (`gi.brdf = ggx`).
    metallic: f32,
    roughness: f32,
    texture: Option<String>,
    mesh: Option<String>,
    triangles: usize,
}

/// The JSON document:
/// `{ "format", "scene", "camera": {name, position, forward, up, yfov_deg},
///    "sun": [{name, direction (travel), irradiance [r,g,b] W/m^2}],
///    "materials": [{name, albedo, metallic, roughness, texture, mesh, triangles}],
///    "bounds": {min, max},
///    "uv_origin": "top-left" }`.
fn scene_json(scene: &Scene, cam: &Camera, materials: &[MaterialEntry]) -> String {
    let mut j = String::new();
    j.push_str("{\n");
    let _ = writeln!(j, "  \"format\": \"lightcut-export-scene/1\",");
    let _ = writeln!(j, "  \"scene\": {},", jstr(&scene.name));
    let _ = writeln!(
        j,
        "  \"uv_origin\": \"top-left\",\n  \"uv_note\": \"PLY u,v as in glTF: v = 0 is the first (top) row of the texture image (as in Mitsuba 3's bitmap: no flip)\","
    );
    let _ = writeln!(
        j,
        "  \"camera\": {{\"name\": {}, \"position\": {}, \"forward\": {}, \"up\": {}, \"yfov_deg\": {}}},",
        jstr(&cam.name),
        vec3(cam.position.to_array()),
        vec3(cam.forward.to_array()),
        vec3(cam.up.to_array()),
        num(cam.yfov.to_degrees())
    );
    j.push_str("  \"sun\": [");
    for (i, l) in scene.lights.iter().enumerate() {
        let _ = write!(
            j,
            "{}\n    {{\"name\": {}, \"direction\": {}, \"irradiance\": {}}}",
            if i == 0 { "" } else { "," },
            jstr(&l.name),
            vec3(l.direction.normalize_or_zero().to_array()),
            vec3(l.irradiance.to_array())
        );
    }
    j.push_str(if scene.lights.is_empty() {
        "],\n"
    } else {
        "\n  ],\n"
    });
    j.push_str("  \"materials\": [");
    for (i, m) in materials.iter().enumerate() {
        let opt = |s: &Option<String>| s.as_deref().map(jstr).unwrap_or_else(|| "null".into());
        let _ = write!(
            j,
            "{}\n    {{\"name\": {}, \"albedo\": {}, \"metallic\": {}, \"roughness\": {}, \"texture\": {}, \"mesh\": {}, \"triangles\": {}}}",
            if i == 0 { "" } else { "," },
            jstr(&m.name),
            vec3(m.albedo),
            num(m.metallic),
            num(m.roughness),
            opt(&m.texture),
            opt(&m.mesh),
            m.triangles
        );
    }
    j.push_str(if materials.is_empty() { "],\n" } else { "\n  ],\n" });
    let b = scene.bounds;
    let (bmin, bmax) = if b.is_empty() {
        ([0.0; 3], [0.0; 3])
    } else {
        (b.min.to_array(), b.max.to_array())
    };
    let _ = writeln!(
        j,
        "  \"bounds\": {{\"min\": {}, \"max\": {}}}",
        vec3(bmin),
        vec3(bmax)
    );
    j.push_str("}\n");
    j
}

fn write_file(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    std::fs::write(path, bytes).with_context(|| format!("cannot write {}", path.display()))
}

pub fn run(args: &ExportSceneArgs) -> anyhow::Result<()> {
    let opened = open_scene(&SceneSource::from_arg(&args.scene)).map_err(|e| anyhow!("{e}"))?;
    let scene = &opened.scene;
    let cam_name = args.camera.clone().or(opened.camera_name.clone());
    let cam = scene
        .camera_or_default(cam_name.as_deref())
        .map_err(|e| anyhow!("{e}"))?;

    // Everything written as a JSON number must be finite.
    let cam_ok = cam.position.is_finite()
        && cam.forward.is_finite()
        && cam.up.is_finite()
        && cam.yfov.is_finite()
        && cam.forward.length_squared() > 0.0;
    if !cam_ok {
        return Err(anyhow!(
            "camera '{}' has a non-finite or degenerate pose",
            cam.name
        ));
    }
    for l in &scene.lights {
        if !l.direction.is_finite() || !l.irradiance.is_finite() || l.direction.length_squared() == 0.0 {
            return Err(anyhow!(
                "light '{}' has a non-finite direction or irradiance",
                l.name
            ));
        }
    }
    if let Some(i) = scene.positions.iter().position(|p| !p.is_finite()) {
        return Err(anyhow!("vertex {i} has a non-finite position"));
    }
    if scene.triangle_count() == 0 {
        return Err(anyhow!("the scene '{}' has no triangles to export", scene.name));
    }

    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let (parts, skipped) = split_by_material(scene);
    if args.format == ExportFormat::Gltf {
        write_gltf(scene, &cam, &parts, &args.out)?;
        if skipped > 0 {
            println!("warning: skipped {skipped} triangle(s) with an invalid material or vertex index");
        }
        println!("wrote {}", args.out.join("scene.gltf").display());
        return Ok(());
    }

    let mut entries = Vec::with_capacity(scene.materials.len());
    let mut written: Vec<usize> = Vec::new();
    for (i, (m, part)) in scene.materials.iter().zip(&parts).enumerate() {
        let f = m.base_color_factor;
        let albedo = [f[0], f[1], f[2]];
        if albedo.iter().any(|x| !x.is_finite()) {
            return Err(anyhow!(
                "material '{}' has a non-finite base colour factor",
                m.name
            ));
        }
        let used = !part.faces.is_empty();
        let mesh = if used {
            let name = format!("mesh_{i}.ply");
            write_file(&args.out.join(&name), &ply_bytes(part))?;
            Some(name)
        } else {
            None
        };
        let texture = match m.base_color_texture {
            Some(t) if used => {
                let tex = scene.textures.get(t).ok_or_else(|| {
                    anyhow!(
                        "material '{}' refers to texture {t}, which the scene lacks",
                        m.name
                    )
                })?;
                let rel = format!("textures/tex_{t}.png");
                if !written.contains(&t) {
                    let dir = args.out.join("textures");
                    std::fs::create_dir_all(&dir)
                        .with_context(|| format!("cannot create {}", dir.display()))?;
                    if tex.rgba8.len() != (tex.width as usize) * (tex.height as usize) * 4 {
                        return Err(anyhow!(
                            "texture '{}' has {} bytes for {}x{} RGBA8",
                            tex.name,
                            tex.rgba8.len(),
                            tex.width,
                            tex.height
                        ));
                    }
                    write_png(&args.out.join(&rel), tex.width, tex.height, &tex.rgba8)
                        .map_err(|e| anyhow!("{e}"))?;
                    written.push(t);
                }
                Some(rel)
            }
            _ => None,
        };
        entries.push(MaterialEntry {
            name: m.name.clone(),
            albedo,
            metallic: m.metallic,
            roughness: m.roughness,
            texture,
            mesh,
            triangles: part.faces.len(),
        });
    }
    write_file(
        &args.out.join("scene.json"),
        scene_json(scene, &cam, &entries).as_bytes(),
    )?;

    let meshes = entries.iter().filter(|e| e.mesh.is_some()).count();
    println!(
        "scene: {} ({} triangles, {} materials -> {} meshes, {} texture file(s), {} sun(s)), camera '{}'",
        scene.name,
        scene.triangle_count(),
        scene.materials.len(),
        meshes,
        written.len(),
        scene.lights.len(),
        cam.name
    );
    if skipped > 0 {
        println!("warning: skipped {skipped} triangle(s) with an invalid material or vertex index");
    }
    println!("wrote {}", args.out.display());
    Ok(())
}

/// Writes `scene.gltf`, `scene.bin` and `textures/tex_<i>.png`: one mesh with a primitive per
/// used material (POSITION with min/max, NORMAL, TEXCOORD_0, u32 indices; world space, so every
/// node is at the identity), metallic-roughness materials with their base colour factor and
/// texture (roughness / metallic textures are not written: the scene holds them re-encoded),
/// every camera (the chosen one first) and every sun as a KHR_lights_punctual directional light
/// whose `intensity` x `color` is its irradiance in W/m^2.
fn write_gltf(scene: &Scene, cam: &Camera, parts: &[MeshPart], out: &Path) -> anyhow::Result<()> {
    use serde_json::{Value, json};
    let mut bin: Vec<u8> = Vec::new();
    let mut views: Vec<Value> = Vec::new();
    let mut accessors: Vec<Value> = Vec::new();
    let mut view = |bin: &mut Vec<u8>, bytes: &[u8], target: u32| -> usize {
        let offset = bin.len();
        bin.extend_from_slice(bytes);
        views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len(), "target": target}));
        views.len() - 1
    };
    let f32_bytes = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let mut textures: Vec<usize> = Vec::new();
    let mut materials: Vec<Value> = Vec::new();
    let mut primitives: Vec<Value> = Vec::new();
    for (m, part) in scene.materials.iter().zip(parts) {
        if part.faces.is_empty() {
            continue;
        }
        let mut pbr = json!({
            "baseColorFactor": m.base_color_factor,
            "metallicFactor": m.metallic,
            "roughnessFactor": m.roughness,
        });
        if let Some(t) = m.base_color_texture.filter(|&t| t < scene.textures.len()) {
            let i = textures.iter().position(|&x| x == t).unwrap_or_else(|| {
                textures.push(t);
                textures.len() - 1
            });
            pbr["baseColorTexture"] = json!({"index": i});
        }
        materials.push(json!({"name": m.name, "pbrMetallicRoughness": pbr, "doubleSided": true}));
        let flat = |v: &[[f32; 3]]| v.iter().flatten().copied().collect::<Vec<f32>>();
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for p in &part.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let n = part.positions.len();
        let pv = view(&mut bin, &f32_bytes(&flat(&part.positions)), 34962);
        accessors.push(json!({"bufferView": pv, "componentType": 5126, "count": n, "type": "VEC3", "min": lo, "max": hi}));
        let nv = view(&mut bin, &f32_bytes(&flat(&part.normals)), 34962);
        accessors.push(json!({"bufferView": nv, "componentType": 5126, "count": n, "type": "VEC3"}));
        let uvs: Vec<f32> = part.uvs.iter().flatten().copied().collect();
        let tv = view(&mut bin, &f32_bytes(&uvs), 34962);
        accessors.push(json!({"bufferView": tv, "componentType": 5126, "count": n, "type": "VEC2"}));
        let idx: Vec<u8> = part
            .faces
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let iv = view(&mut bin, &idx, 34963);
        accessors.push(
            json!({"bufferView": iv, "componentType": 5125, "count": part.faces.len() * 3, "type": "SCALAR"}),
        );
        let a = accessors.len();
        primitives.push(json!({
            "attributes": {"POSITION": a - 4, "NORMAL": a - 3, "TEXCOORD_0": a - 2},
            "indices": a - 1,
            "material": materials.len() - 1,
        }));
    }
    let mut nodes: Vec<Value> = vec![json!({"name": scene.name, "mesh": 0})];
    let cameras = camera_nodes(scene, cam, &mut nodes);
    let lights = light_nodes(scene, &mut nodes);
    let images = write_textures(scene, &textures, out)?;
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": "lightcut-workbench export-scene"},
        "scene": 0,
        "scenes": [{"name": scene.name, "nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": [{"name": scene.name, "primitives": primitives}],
        "materials": materials,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"uri": "scene.bin", "byteLength": bin.len()}],
    });
    if !cameras.is_empty() {
        doc["cameras"] = json!(cameras);
    }
    if !textures.is_empty() {
        doc["images"] = json!(images);
        doc["samplers"] = json!([{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}]);
        doc["textures"] = json!(
            (0..textures.len())
                .map(|i| json!({"source": i, "sampler": 0}))
                .collect::<Vec<_>>()
        );
    }
    if !lights.is_empty() {
        doc["extensionsUsed"] = json!(["KHR_lights_punctual"]);
        doc["extensions"] = json!({"KHR_lights_punctual": {"lights": lights}});
    }
    write_file(&out.join("scene.bin"), &bin)?;
    let text = serde_json::to_string_pretty(&doc).context("cannot encode the glTF JSON")?;
    write_file(&out.join("scene.gltf"), text.as_bytes())?;
    println!(
        "scene: {} ({} triangles, {} primitives, {} texture(s), {} camera(s), {} sun(s))",
        scene.name,
        scene.triangle_count(),
        primitives.len(),
        textures.len(),
        cameras.len(),
        lights.len()
    );
    Ok(())
}

/// The glTF cameras (`cam` first, then the scene's others), each with its node in `nodes`.
fn camera_nodes(scene: &Scene, cam: &Camera, nodes: &mut Vec<serde_json::Value>) -> Vec<serde_json::Value> {
    use glam::{Mat3, Quat};
    use serde_json::{Value, json};
    let mut cameras: Vec<Value> = Vec::new();
    let mut cams: Vec<&Camera> = vec![cam];
    cams.extend(scene.cameras.iter().filter(|c| c.name != cam.name));
    for c in cams {
        let f = c.forward.normalize_or(Vec3::NEG_Z);
        let r = f.cross(c.up).normalize_or(Vec3::X);
        let u = r.cross(f);
        let q = Quat::from_mat3(&Mat3::from_cols(r, u, -f)).normalize();
        cameras.push(json!({"name": c.name, "type": "perspective",
            "perspective": {"yfov": c.yfov, "znear": c.znear, "zfar": c.zfar}}));
        nodes.push(json!({"name": c.name, "camera": cameras.len() - 1,
            "translation": c.position.to_array(), "rotation": q.to_array()}));
    }
    cameras
}

/// The suns as `KHR_lights_punctual` directional lights (colour and intensity in W/m²), each
/// with its node in `nodes`.
fn light_nodes(scene: &Scene, nodes: &mut Vec<serde_json::Value>) -> Vec<serde_json::Value> {
    use glam::{Mat3, Quat};
    use serde_json::{Value, json};
    let mut lights: Vec<Value> = Vec::new();
    for l in &scene.lights {
        let z = -l.direction.normalize_or(Vec3::NEG_Y);
        let x = if z.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
        let y = z.cross(x).normalize();
        let x = y.cross(z);
        let q = Quat::from_mat3(&Mat3::from_cols(x, y, z)).normalize();
        let intensity = l.irradiance.max_element().max(0.0);
        let color = if intensity > 0.0 {
            l.irradiance / intensity
        } else {
            Vec3::ONE
        };
        lights.push(
            json!({"name": l.name, "type": "directional", "color": color.to_array(), "intensity": intensity}),
        );
        nodes.push(json!({"name": l.name, "rotation": q.to_array(),
            "extensions": {"KHR_lights_punctual": {"light": lights.len() - 1}}}));
    }
    lights
}

/// The used textures as PNGs under `out/textures/`, and their glTF images.
fn write_textures(scene: &Scene, textures: &[usize], out: &Path) -> anyhow::Result<Vec<serde_json::Value>> {
    use serde_json::{Value, json};
    let mut images: Vec<Value> = Vec::new();
    if !textures.is_empty() {
        std::fs::create_dir_all(out.join("textures"))
            .with_context(|| format!("cannot create {}", out.join("textures").display()))?;
    }
    for &t in textures {
        let tex = &scene.textures[t];
        if tex.rgba8.len() != (tex.width as usize) * (tex.height as usize) * 4 {
            return Err(anyhow!(
                "texture '{}' is not {}x{} RGBA8",
                tex.name,
                tex.width,
                tex.height
            ));
        }
        let rel = format!("textures/tex_{t}.png");
        write_png(&out.join(&rel), tex.width, tex.height, &tex.rgba8).map_err(|e| anyhow!("{e}"))?;
        images.push(json!({"uri": rel, "name": tex.name}));
    }
    Ok(images)
}

//! Tests of the scene-loading side: a corpus of broken glTF inputs (each must give a warning
//! or a specific `SceneError`, never a panic), exact transform/camera/light checks on a small
//! valid file, the embedded default scene, and (when present) the shared reference scenes
//! and the presets in `scenes/`.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::{Quat, Vec3};

use super::gltf_load::{SceneError, load_gltf};
use super::preset::{ScenePreset, SceneSource, load_preset, open_scene};
use super::{Scene, default_scene};

// ---------------------------------------------------------------------------------------
// Fixture helpers
// ---------------------------------------------------------------------------------------

/// A fresh, empty temporary folder for one test, removed when dropped.
struct TempDir(PathBuf);

impl std::ops::Deref for TempDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn temp_dir(tag: &str) -> TempDir {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("lightcut_loader_tests_{}_{tag}_{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    TempDir(dir)
}

/// Builds a binary buffer plus the matching `bufferViews` / `accessors` JSON.
#[derive(Default)]
struct Gb {
    bin: Vec<u8>,
    views: Vec<String>,
    accessors: Vec<String>,
}

impl Gb {
    fn add_view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let off = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.views.push(format!(
            r#"{{"buffer":0,"byteOffset":{off},"byteLength":{}}}"#,
            bytes.len()
        ));
        self.views.len() - 1
    }
    fn vec3(&mut self, v: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = v.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.add_view(&bytes);
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        for p in v {
            for k in 0..3 {
                if p[k].is_finite() {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
        }
        self.accessors.push(format!(
            r#"{{"bufferView":{view},"componentType":5126,"count":{},"type":"VEC3","min":[{},{},{}],"max":[{},{},{}]}}"#,
            v.len(),
            lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
        ));
        self.accessors.len() - 1
    }
    fn vec2(&mut self, v: &[[f32; 2]]) -> usize {
        let bytes: Vec<u8> = v.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.add_view(&bytes);
        self.accessors.push(format!(
            r#"{{"bufferView":{view},"componentType":5126,"count":{},"type":"VEC2"}}"#,
            v.len()
        ));
        self.accessors.len() - 1
    }
    fn indices(&mut self, v: &[u32]) -> usize {
        let bytes: Vec<u8> = v.iter().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.add_view(&bytes);
        self.accessors.push(format!(
            r#"{{"bufferView":{view},"componentType":5125,"count":{},"type":"SCALAR"}}"#,
            v.len()
        ));
        self.accessors.len() - 1
    }
    /// The full glTF JSON; `rest` holds the remaining top-level members (meshes, nodes, ...).
    fn json(&self, buffer_uri: &str, rest: &str) -> String {
        format!(
            r#"{{"asset":{{"version":"2.0"}},
"buffers":[{{"uri":"{buffer_uri}","byteLength":{}}}],
"bufferViews":[{}],
"accessors":[{}],
{rest}}}"#,
            self.bin.len(),
            self.views.join(","),
            self.accessors.join(",")
        )
    }
    /// Writes `name.gltf` + `name.bin` into `dir`; returns the glTF path.
    fn write(&self, dir: &Path, name: &str, rest: &str) -> PathBuf {
        let gltf = dir.join(format!("{name}.gltf"));
        std::fs::write(dir.join(format!("{name}.bin")), &self.bin).unwrap();
        std::fs::write(&gltf, self.json(&format!("{name}.bin"), rest)).unwrap();
        gltf
    }
}

const TRI: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// One triangle mesh (accessors 0 = positions, 1 = indices) in one node.
fn one_triangle() -> Gb {
    let mut gb = Gb::default();
    gb.vec3(&TRI);
    gb.indices(&[0, 1, 2]);
    gb
}

const ONE_NODE: &str = r#""meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0"#;

fn has_warning(scene: &Scene, needle: &str) -> bool {
    scene.warnings.iter().any(|w| w.contains(needle))
}

fn assert_close(a: Vec3, b: Vec3, what: &str) {
    assert!((a - b).length() < 1e-5, "{what}: got {a:?}, expected {b:?}");
}

// ---------------------------------------------------------------------------------------
// Broken inputs
// ---------------------------------------------------------------------------------------

#[test]
fn minimal_triangle_loads() {
    let dir = temp_dir("minimal");
    let path = one_triangle().write(&dir, "tri", ONE_NODE);
    let s = load_gltf(&path).unwrap();
    assert_eq!(s.triangle_count(), 1);
    assert_eq!(s.name, "tri");
    assert_eq!(s.materials.len(), 1, "a default material is added");
    assert_eq!(s.triangle_materials, vec![0]);
    // no NORMAL attribute: flat normal, +Z for a CCW triangle in the XY plane
    for n in &s.normals {
        assert_close(*n, Vec3::Z, "flat normal");
    }
    assert_close(s.bounds.min, Vec3::ZERO, "bounds min");
    assert_close(s.bounds.max, Vec3::new(1.0, 1.0, 0.0), "bounds max");
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

#[test]
fn missing_file_is_io_error() {
    let dir = temp_dir("nofile");
    let err = load_gltf(&dir.join("nothing.gltf")).unwrap_err();
    assert!(matches!(err, SceneError::Io { .. }), "{err}");
    assert!(err.to_string().contains("nothing.gltf"), "{err}");
}

#[test]
fn garbage_is_invalid_gltf() {
    let dir = temp_dir("garbage");
    let p = dir.join("bad.gltf");
    std::fs::write(&p, "{ this is not json").unwrap();
    assert!(matches!(load_gltf(&p), Err(SceneError::InvalidGltf { .. })));
    let p = dir.join("bad.glb");
    std::fs::write(&p, b"glTF\x02\x00\x00\x00\xff\xff").unwrap();
    assert!(matches!(load_gltf(&p), Err(SceneError::InvalidGltf { .. })));
    // dangling mesh index
    let gb = one_triangle();
    let p = gb.write(
        &dir,
        "dangling",
        r#""nodes":[{"mesh":7}],"scenes":[{"nodes":[0]}]"#,
    );
    let err = load_gltf(&p).unwrap_err();
    assert!(matches!(err, SceneError::InvalidGltf { .. }), "{err}");
    assert!(!err.to_string().contains('\n'), "one line: {err}");
}

#[test]
fn missing_bin_is_error() {
    let dir = temp_dir("missingbin");
    let path = one_triangle().write(&dir, "m", ONE_NODE);
    std::fs::remove_file(dir.join("m.bin")).unwrap();
    let err = load_gltf(&path).unwrap_err();
    match &err {
        SceneError::MissingBuffer { buffer, index, .. } => {
            assert_eq!(*index, 0);
            assert!(buffer.ends_with("m.bin"), "{err}");
        }
        e => panic!("expected MissingBuffer, got {e}"),
    }
}

#[test]
fn truncated_bin_is_error() {
    let dir = temp_dir("truncated");
    let gb = one_triangle();
    let path = gb.write(&dir, "t", ONE_NODE);
    std::fs::write(dir.join("t.bin"), &gb.bin[..20]).unwrap();
    match load_gltf(&path).unwrap_err() {
        SceneError::TruncatedBuffer { declared, actual, .. } => {
            assert_eq!(declared, gb.bin.len());
            assert_eq!(actual, 20);
        }
        e => panic!("expected TruncatedBuffer, got {e}"),
    }
}

#[test]
fn accessor_outside_buffer_view_warns_not_panics() {
    let dir = temp_dir("badaccessor");
    let mut gb = one_triangle();
    // accessor 2 claims 1000 vertices in the 36-byte view 0
    gb.accessors.push(
        r#"{"bufferView":0,"componentType":5126,"count":1000,"type":"VEC3","min":[0,0,0],"max":[1,1,1]}"#
            .into(),
    );
    let rest = r#""meshes":[{"primitives":[{"attributes":{"POSITION":2},"indices":1},{"attributes":{"POSITION":0},"indices":1}]}],
"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]"#;
    let s = load_gltf(&gb.write(&dir, "a", rest)).unwrap();
    assert_eq!(s.triangle_count(), 1);
    assert!(has_warning(&s, "primitive 0 skipped"), "{:?}", s.warnings);
    // index out of range of the vertices: the triangle is dropped with a warning
    let mut gb = one_triangle();
    gb.indices(&[0, 1, 9, 0, 1, 2]);
    let rest = r#""meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":2}]}],
"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]"#;
    let s = load_gltf(&gb.write(&dir, "b", rest)).unwrap();
    assert_eq!(s.triangle_count(), 1);
    assert!(has_warning(&s, "out-of-range vertex indices"), "{:?}", s.warnings);
}

/// A textured material whose image is given by `image_uri`.
fn textured(image_uri: &str) -> (Gb, String) {
    let mut gb = Gb::default();
    gb.vec3(&TRI);
    gb.indices(&[0, 1, 2]);
    gb.vec2(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let rest = format!(
        r#""meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":2}},"indices":1,"material":0}}]}}],
"materials":[{{"name":"Painted","pbrMetallicRoughness":{{"baseColorFactor":[0.5,0.25,0.125,1.0],"baseColorTexture":{{"index":0}}}}}}],
"textures":[{{"source":0}}],
"images":[{{"uri":"{image_uri}"}}],
"nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}]"#
    );
    (gb, rest)
}

#[test]
fn missing_texture_image_warns_and_uses_factor() {
    let dir = temp_dir("missingtex");
    let (gb, rest) = textured("nope.png");
    let s = load_gltf(&gb.write(&dir, "m", &rest)).unwrap();
    assert!(has_warning(&s, "nope.png"), "{:?}", s.warnings);
    assert_eq!(s.materials[0].name, "Painted");
    assert_eq!(s.materials[0].base_color_texture, None);
    assert_eq!(s.materials[0].base_color_factor, [0.5, 0.25, 0.125, 1.0]);
    assert!(s.textures.is_empty());
    // an undecodable image is the same
    std::fs::write(dir.join("nope.png"), b"not a png").unwrap();
    let s = load_gltf(&dir.join("m.gltf")).unwrap();
    assert!(has_warning(&s, "nope.png"), "{:?}", s.warnings);
    assert_eq!(s.materials[0].base_color_texture, None);
}

#[test]
fn texture_png_16bit_grey_decodes_to_rgba8() {
    let dir = temp_dir("tex16");
    let img = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(4, 2, |x, _| {
        image::Luma([if x < 2 { 0 } else { 65535 }])
    });
    img.save(dir.join("grey16.png")).unwrap();
    let (gb, rest) = textured("grey16.png");
    let s = load_gltf(&gb.write(&dir, "t", &rest)).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let t = &s.textures[s.materials[0].base_color_texture.unwrap()];
    assert_eq!((t.width, t.height), (4, 2));
    assert_eq!(t.rgba8.len(), 4 * 2 * 4);
    assert_eq!(&t.rgba8[0..4], &[0, 0, 0, 255]);
    assert_eq!(&t.rgba8[8..12], &[255, 255, 255, 255]);
    assert_eq!(s.uvs[..3].len(), 3);
}

#[test]
fn unknown_required_extension_is_error() {
    let dir = temp_dir("ext");
    for (name, reason) in [
        ("EXT_totally_unknown", "unknown"),
        ("KHR_meshopt_compression", "EXT_meshopt_compression"),
    ] {
        let rest = format!(r#"{ONE_NODE},"extensionsUsed":["{name}"],"extensionsRequired":["{name}"]"#);
        match load_gltf(&one_triangle().write(&dir, name, &rest)).unwrap_err() {
            SceneError::UnsupportedExtension {
                name: n, reason: r, ..
            } => {
                assert_eq!(n, name);
                assert!(r.contains(reason), "{r}");
            }
            e => panic!("{name}: expected UnsupportedExtension, got {e}"),
        }
    }
    // harmless ones (required or used) only warn
    let rest = format!(
        r#"{ONE_NODE},"extensionsUsed":["AMD_split_roughnessMetallic","KHR_materials_specular","EXT_unknown_used"],
"extensionsRequired":["AMD_split_roughnessMetallic","KHR_materials_specular"]"#
    );
    let s = load_gltf(&one_triangle().write(&dir, "harmless", &rest)).unwrap();
    for e in [
        "AMD_split_roughnessMetallic",
        "KHR_materials_specular",
        "EXT_unknown_used",
    ] {
        assert!(has_warning(&s, e), "{e}: {:?}", s.warnings);
    }
}

#[test]
fn nan_positions_dropped_and_all_nan_is_error() {
    let dir = temp_dir("nan");
    let mut gb = Gb::default();
    gb.vec3(&[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [f32::NAN, 0.0, 0.0],
        [2.0, f32::INFINITY, 0.0],
    ]);
    gb.indices(&[0, 1, 2, 0, 1, 3, 4, 1, 2, 2, 1, 0]);
    let s = load_gltf(&gb.write(&dir, "some", ONE_NODE)).unwrap();
    assert_eq!(s.triangle_count(), 2);
    assert!(s.positions.iter().all(|p| p.is_finite()));
    assert!(
        has_warning(&s, "2 triangle(s) with non-finite"),
        "{:?}",
        s.warnings
    );

    let mut gb = Gb::default();
    gb.vec3(&[[f32::NAN; 3], [1.0, 0.0, 0.0], [0.0, f32::NAN, 0.0]]);
    gb.indices(&[0, 1, 2]);
    match load_gltf(&gb.write(&dir, "all", ONE_NODE)).unwrap_err() {
        SceneError::NoTriangles { details, .. } => assert!(details.contains("1 non-finite")),
        e => panic!("expected NoTriangles, got {e}"),
    }
}

#[test]
fn zero_area_triangles_dropped() {
    let dir = temp_dir("zeroarea");
    let mut gb = Gb::default();
    gb.vec3(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [2.0, 0.0, 0.0]]);
    gb.indices(&[0, 1, 2, 0, 1, 3, 1, 1, 2]);
    let s = load_gltf(&gb.write(&dir, "z", ONE_NODE)).unwrap();
    assert_eq!(s.triangle_count(), 1);
    assert!(has_warning(&s, "2 zero-area"), "{:?}", s.warnings);
}

#[test]
fn zero_triangles_is_error() {
    let dir = temp_dir("zerotris");
    // a mesh without any primitive index data: empty index list
    let mut gb = Gb::default();
    gb.vec3(&TRI);
    gb.indices(&[]);
    let p = gb.write(&dir, "empty", ONE_NODE);
    assert!(matches!(load_gltf(&p), Err(SceneError::NoTriangles { .. })));
    // no nodes at all
    let p = one_triangle().write(
        &dir,
        "nonodes",
        r#""meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}]"#,
    );
    assert!(matches!(load_gltf(&p), Err(SceneError::NoTriangles { .. })));
    // only lines
    let rest = r#""meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"mode":1}]}],
"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]"#;
    let err = load_gltf(&one_triangle().write(&dir, "lines", rest)).unwrap_err();
    assert!(matches!(err, SceneError::NoTriangles { .. }), "{err}");
    assert!(err.to_string().contains("Lines"), "{err}");
}

#[test]
fn non_triangle_primitives_skipped_with_warning() {
    let dir = temp_dir("modes");
    let rest = r#""meshes":[{"primitives":[
  {"attributes":{"POSITION":0},"mode":0},
  {"attributes":{"POSITION":0},"indices":1,"mode":1},
  {"attributes":{"POSITION":0},"mode":0},
  {"attributes":{"POSITION":0},"indices":1}]}],
"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]"#;
    let s = load_gltf(&one_triangle().write(&dir, "m", rest)).unwrap();
    assert_eq!(s.triangle_count(), 1);
    assert!(
        has_warning(&s, "2 primitive(s) with mode Points"),
        "{:?}",
        s.warnings
    );
    assert!(
        has_warning(&s, "1 primitive(s) with mode Lines"),
        "{:?}",
        s.warnings
    );
}

#[test]
fn glb_container_loads() {
    let dir = temp_dir("glb");
    let gb = one_triangle();
    let json = gb.json("x", ONE_NODE).replace(r#""uri":"x","#, "");
    let mut json = json.into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut bin = gb.bin.clone();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut glb = Vec::new();
    glb.extend_from_slice(b"glTF");
    glb.extend_from_slice(&2u32.to_le_bytes());
    glb.extend_from_slice(&(total as u32).to_le_bytes());
    glb.extend_from_slice(&(json.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"JSON");
    glb.extend_from_slice(&json);
    glb.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"BIN\0");
    glb.extend_from_slice(&bin);
    let p = dir.join("m.glb");
    std::fs::write(&p, &glb).unwrap();
    let s = load_gltf(&p).unwrap();
    assert_eq!(s.triangle_count(), 1);
    // truncated GLB must not panic
    std::fs::write(&p, &glb[..glb.len() - 10]).unwrap();
    assert!(load_gltf(&p).is_err());
}

#[test]
fn random_corruption_never_panics() {
    use rand::{Rng, SeedableRng};
    let dir = temp_dir("fuzz");
    let (gb, rest) = textured("nope.png");
    let json = gb.json("f.bin", &rest).into_bytes();
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    for i in 0..300 {
        let mut j = json.clone();
        let mut b = gb.bin.clone();
        for _ in 0..rng.random_range(1..4) {
            if rng.random_bool(0.5) {
                let k = rng.random_range(0..j.len());
                j[k] = b"0123456789-,:[]{}\"e."[rng.random_range(0..20)];
            } else {
                let k = rng.random_range(0..b.len());
                b[k] = rng.random();
            }
        }
        std::fs::write(dir.join("f.bin"), &b).unwrap();
        let p = dir.join("f.gltf");
        std::fs::write(&p, &j).unwrap();
        if let Ok(s) = load_gltf(&p) {
            assert!(s.positions.iter().all(|p| p.is_finite()), "case {i}");
            assert!(
                s.indices.iter().all(|&k| (k as usize) < s.positions.len()),
                "case {i}"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------
// Valid content: hierarchy, instancing, lights, cameras
// ---------------------------------------------------------------------------------------

#[test]
fn node_hierarchy_instancing_transforms_exact() {
    let dir = temp_dir("hierarchy");
    let mut gb = Gb::default();
    gb.vec3(&TRI);
    gb.indices(&[0, 1, 2]);
    gb.vec3(&[[0.0, 0.0, 1.0]; 3]);
    // rotation of 90 degrees about +Y: (x, y, z) -> (z, y, -x)
    let q = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
    let rest = format!(
        r#""meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"NORMAL":2}},"indices":1}}]}}],
"nodes":[
  {{"name":"parent","translation":[10,0,0],"children":[1,2]}},
  {{"name":"child","rotation":[{},{},{},{}],"mesh":0}},
  {{"name":"mirror","scale":[-1,1,1],"translation":[0,5,0],"mesh":0}}
],
"scenes":[{{"nodes":[0]}}],"scene":0"#,
        q.x, q.y, q.z, q.w
    );
    let s = load_gltf(&gb.write(&dir, "h", &rest)).unwrap();
    assert_eq!(s.triangle_count(), 2, "the mesh is instanced twice");
    // instance 1: parent translation * child rotation
    let t0 = s.triangle(0);
    assert_close(t0[0], Vec3::new(10.0, 0.0, 0.0), "child v0");
    assert_close(t0[1], Vec3::new(10.0, 0.0, -1.0), "child v1");
    assert_close(t0[2], Vec3::new(10.0, 1.0, 0.0), "child v2");
    let n0 = s.normals[s.indices[0] as usize];
    assert_close(n0, Vec3::X, "rotated normal (+Z -> +X)");
    // instance 2: mirrored (negative determinant): winding flipped so the geometric normal
    // still agrees with the (mirrored) shading normal
    let t1 = s.triangle(1);
    let mut expected = [
        Vec3::new(10.0, 5.0, 0.0),
        Vec3::new(9.0, 5.0, 0.0),
        Vec3::new(10.0, 6.0, 0.0),
    ];
    expected.swap(1, 2);
    for k in 0..3 {
        assert_close(t1[k], expected[k], "mirrored vertex");
    }
    let geo = (t1[1] - t1[0]).cross(t1[2] - t1[0]).normalize();
    let n1 = s.normals[s.indices[3] as usize];
    assert_close(
        n1,
        Vec3::Z,
        "mirrored normal (inverse transpose of scale(-1,1,1) keeps +Z)",
    );
    assert!(geo.dot(n1) > 0.99, "winding agrees with the normal: {geo:?}");
    assert!(s.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-5));
}

#[test]
fn scaled_normals_use_inverse_transpose() {
    let dir = temp_dir("scalednormal");
    let mut gb = Gb::default();
    gb.vec3(&[[0.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 1.0, 0.0]]);
    gb.indices(&[0, 1, 2]);
    let nrm = Vec3::new(-1.0, 0.0, 1.0).normalize();
    gb.vec3(&[nrm.to_array(); 3]);
    let rest = r#""meshes":[{"primitives":[{"attributes":{"POSITION":0,"NORMAL":2},"indices":1}]}],
"nodes":[{"scale":[2,1,1],"mesh":0}],"scenes":[{"nodes":[0]}]"#;
    let s = load_gltf(&gb.write(&dir, "s", rest)).unwrap();
    // plane z - x = 0 scaled by 2 in x becomes z - x/2 = 0 with normal (-1, 0, 2)/sqrt(5)
    let n = s.normals[s.indices[0] as usize];
    assert_close(
        n,
        Vec3::new(-1.0, 0.0, 2.0).normalize(),
        "inverse-transpose normal",
    );
    let t = s.triangle(0);
    assert!((t[1] - t[0]).cross(t[2] - t[0]).normalize().dot(n) > 0.999);
}

#[test]
fn directional_light_and_camera_from_nodes() {
    let dir = temp_dir("lightcam");
    // light node: rotated -90 degrees about X, so local -Z points to world -Y (straight down);
    // camera node: at (1, 2, 3) rotated 90 degrees about Y, so it looks down world -X.
    let ql = Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2);
    let qc = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
    let rest = format!(
        r#"{ONE_NODE_NO_SCENE},
"extensionsUsed":["KHR_lights_punctual"],
"extensions":{{"KHR_lights_punctual":{{"lights":[
  {{"name":"Sun","type":"directional","intensity":3.0,"color":[1.0,0.5,0.25]}},
  {{"type":"point","intensity":100.0}}]}}}},
"cameras":[{{"name":"Cam","type":"perspective","perspective":{{"yfov":0.8,"znear":0.05,"zfar":100.0}}}},
           {{"type":"perspective","perspective":{{"yfov":0.5,"znear":0.1}}}},
           {{"type":"orthographic","orthographic":{{"xmag":1,"ymag":1,"znear":0.1,"zfar":10}}}}],
"nodes":[{{"mesh":0}},
  {{"name":"sunnode","rotation":[{},{},{},{}],"extensions":{{"KHR_lights_punctual":{{"light":0}}}}}},
  {{"name":"bulb","extensions":{{"KHR_lights_punctual":{{"light":1}}}}}},
  {{"name":"camnode","translation":[1,2,3],"rotation":[{},{},{},{}],"camera":0}},
  {{"name":"second","translation":[0,0,5],"camera":1}},
  {{"name":"ortho","camera":2}}],
"scenes":[{{"nodes":[0,1,2,3,4,5]}}],"scene":0"#,
        ql.x, ql.y, ql.z, ql.w, qc.x, qc.y, qc.z, qc.w
    );
    let s = load_gltf(&one_triangle().write(&dir, "lc", &rest)).unwrap();
    assert_eq!(s.lights.len(), 1);
    let l = &s.lights[0];
    assert_eq!(l.name, "Sun");
    assert_close(l.direction, Vec3::NEG_Y, "light direction");
    assert_close(
        l.irradiance,
        Vec3::new(3.0, 1.5, 0.75),
        "irradiance = intensity * color",
    );
    assert!(has_warning(&s, "Point light(s) skipped"), "{:?}", s.warnings);

    assert_eq!(s.cameras.len(), 2, "the orthographic camera is skipped");
    assert!(has_warning(&s, "not a perspective camera"), "{:?}", s.warnings);
    let c = &s.cameras[0];
    assert_eq!(c.name, "Cam");
    assert_close(c.position, Vec3::new(1.0, 2.0, 3.0), "camera position");
    assert_close(c.forward, Vec3::NEG_X, "camera forward");
    assert_close(c.up, Vec3::Y, "camera up");
    assert_eq!((c.yfov, c.znear, c.zfar), (0.8, 0.05, 100.0));
    let c2 = &s.cameras[1];
    assert_eq!(c2.name, "second", "node name when the camera has none");
    assert!(
        c2.zfar.is_finite() && c2.zfar > 5.0,
        "infinite zfar made finite: {}",
        c2.zfar
    );
    assert_close(c2.forward, Vec3::NEG_Z, "default camera looks down -Z");
}

const ONE_NODE_NO_SCENE: &str = r#""meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}]"#;

#[test]
fn uv_set_follows_material_texcoord() {
    let dir = temp_dir("uvset");
    let img = image::RgbImage::from_pixel(2, 2, image::Rgb([10, 20, 30]));
    img.save(dir.join("c.png")).unwrap();
    let mut gb = Gb::default();
    gb.vec3(&TRI);
    gb.indices(&[0, 1, 2]);
    gb.vec2(&[[0.0, 0.0]; 3]);
    gb.vec2(&[[0.25, 0.75]; 3]);
    let rest = r#""meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":2,"TEXCOORD_1":3},"indices":1,"material":0}]}],
"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0,"texCoord":1}}},
             {"name":"same image","pbrMetallicRoughness":{"baseColorTexture":{"index":1}}}],
"textures":[{"source":0},{"source":0}],
"images":[{"uri":"c.png"}],
"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]"#;
    let s = load_gltf(&gb.write(&dir, "u", rest)).unwrap();
    assert!(
        s.uvs
            .iter()
            .all(|uv| (uv.x - 0.25).abs() < 1e-6 && (uv.y - 0.75).abs() < 1e-6)
    );
    assert_eq!(s.textures.len(), 1, "an image used twice is decoded once");
    assert_eq!(s.materials[0].base_color_texture, Some(0));
    assert_eq!(s.materials[1].base_color_texture, Some(0));
    assert_eq!(&s.textures[0].rgba8[..4], &[10, 20, 30, 255]);
}

#[test]
fn metallic_roughness_textures_are_read_as_linear_data() {
    let dir = temp_dir("mrtex");
    // G = roughness, B = metallic (glTF); two texels.
    let img = image::RgbImage::from_fn(2, 1, |x, _| {
        image::Rgb(if x == 0 { [0, 64, 200] } else { [255, 255, 0] })
    });
    img.save(dir.join("mr.png")).unwrap();
    let mut gb = Gb::default();
    gb.vec3(&TRI);
    gb.indices(&[0, 1, 2]);
    gb.vec2(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let rest = r#""meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":2},"indices":1,"material":0}]}],
"materials":[{"name":"Rough","pbrMetallicRoughness":{"metallicFactor":0.5,"roughnessFactor":0.8,"metallicRoughnessTexture":{"index":0}}}],
"textures":[{"source":0}],
"images":[{"uri":"mr.png"}],
"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]"#;
    let s = load_gltf(&gb.write(&dir, "m", rest)).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let m = &s.materials[0];
    assert_eq!((m.metallic, m.roughness), (0.5, 0.8), "the factors stay");
    assert_eq!(m.roughness_texture, Some(0));
    assert_eq!(m.metallic_texture, Some(0));
    assert_eq!(m.base_color_texture, None);
    // Stored sRGB-encoded: decoding gives the linear data back within half an sRGB step.
    let t = &s.textures[0];
    let dec = |i: usize| crate::base::display::srgb8_to_linear(t.rgba8[i]);
    for (i, want) in [
        (0usize, 0.0f32),
        (1, 64.0 / 255.0),
        (2, 200.0 / 255.0),
        (5, 1.0),
        (6, 0.0),
    ] {
        assert!((dec(i) - want).abs() < 0.0025, "byte {i}: {} vs {want}", dec(i));
    }
    // The same image as base colour too: two textures (colour and data).
    let rest2 = rest.replace(
        r#""metallicRoughnessTexture""#,
        r#""baseColorTexture":{"index":0},"metallicRoughnessTexture""#,
    );
    let s = load_gltf(&gb.write(&dir, "m2", &rest2)).unwrap();
    assert_eq!(s.textures.len(), 2);
    let m = &s.materials[0];
    assert!(m.base_color_texture.is_some() && m.roughness_texture.is_some());
    assert_ne!(m.base_color_texture, m.roughness_texture);
    assert_eq!(
        s.textures[m.base_color_texture.unwrap()].rgba8[1],
        64,
        "colour bytes unchanged"
    );
    // Every byte value comes back within half an sRGB step (at most 0.0040, near 0.85).
    let mut all = crate::scene::TextureImage {
        name: "ramp".into(),
        width: 256,
        height: 1,
        rgba8: (0..=255u8).flat_map(|v| [v, v, v, 255]).collect(),
    };
    all.encode_linear_as_srgb();
    for v in 0..256usize {
        let back = crate::base::display::srgb8_to_linear(all.rgba8[4 * v]);
        assert!((back - v as f32 / 255.0).abs() <= 0.0041, "byte {v}: {back}");
    }
}

#[test]
fn split_roughness_metallic_textures_find_the_image_beside_their_dds() {
    // Sponza's AMD_split_roughnessMetallic textures are DDS-only; the glTF metallic-roughness
    // PNG they were split from lies beside them under the DDS's base name.
    let dir = temp_dir("splitmr");
    image::RgbImage::from_pixel(2, 2, image::Rgb([255, 51, 102]))
        .save(dir.join("arch_rough.png"))
        .unwrap();
    image::RgbImage::from_pixel(2, 2, image::Rgb([9, 9, 9]))
        .save(dir.join("plain.png"))
        .unwrap();
    let mut gb = Gb::default();
    gb.vec3(&TRI);
    gb.indices(&[0, 1, 2]);
    gb.vec2(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let rest = r#""extensionsUsed":["AMD_split_roughnessMetallic","MSFT_texture_dds"],
"meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":2},"indices":1,"material":0},{"attributes":{"POSITION":0,"TEXCOORD_0":2},"indices":1,"material":1}]}],
"materials":[{"name":"Arch","pbrMetallicRoughness":{"metallicFactor":0.1},"extensions":{"AMD_split_roughnessMetallic":{"roughnessTexture":{"index":0},"metallicTexture":{"index":1}}}},
             {"name":"Lost","extensions":{"AMD_split_roughnessMetallic":{"roughnessTexture":{"index":2}}}},
             {"name":"Plain","extensions":{"AMD_split_roughnessMetallic":{"roughnessTexture":{"index":3}}}}],
"textures":[{"extensions":{"MSFT_texture_dds":{"source":0}}},{"extensions":{"MSFT_texture_dds":{"source":1}}},{"extensions":{"MSFT_texture_dds":{"source":2}}},{"extensions":{"MSFT_texture_dds":{"source":3}}}],
"images":[{"uri":"arch_rough.roughness.dds"},{"uri":"arch_rough.metallic.dds"},{"uri":"gone.roughness.dds"},{"uri":"plain.dds"}],
"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]"#;
    let s = load_gltf(&gb.write(&dir, "s", rest)).unwrap();
    let arch = &s.materials[0];
    assert_eq!(arch.roughness_texture, Some(0), "{:?}", s.warnings);
    assert_eq!(arch.metallic_texture, Some(0), "one image, one data texture");
    assert_eq!(s.textures.len(), 1);
    // A plain name.dds is not a split map: name.png beside it may be a colour image.
    assert_eq!(s.materials[2].roughness_texture, None);
    assert!(has_warning(&s, "material 'Plain'"), "{:?}", s.warnings);
    let lost = &s.materials[1];
    assert_eq!(lost.roughness_texture, None);
    assert!(has_warning(&s, "nor one beside its DDS"), "{:?}", s.warnings);
    assert!(!has_warning(&s, "Arch"), "{:?}", s.warnings);
}

// ---------------------------------------------------------------------------------------
// Default scene
// ---------------------------------------------------------------------------------------

#[test]
fn default_scene_is_sane() {
    let s = default_scene::build();
    let n = s.triangle_count();
    assert!(n > 100 && n < 5000, "{n} triangles");
    assert_eq!(s.indices.len() % 3, 0);
    assert_eq!(s.triangle_materials.len(), n);
    assert_eq!(s.positions.len(), s.normals.len());
    assert_eq!(s.positions.len(), s.uvs.len());
    assert!(s.indices.iter().all(|&i| (i as usize) < s.positions.len()));
    assert!(
        s.triangle_materials
            .iter()
            .all(|&m| (m as usize) < s.materials.len())
    );
    assert!(s.positions.iter().all(|p| p.is_finite()));
    assert!(s.uvs.iter().all(|p| p.is_finite()));
    assert!(s.normals.iter().all(|v| (v.length() - 1.0).abs() < 1e-4));
    assert!(!s.lights.is_empty());
    let e = s.lights[0].irradiance;
    assert!(e.min_element() > 0.0 && e.is_finite());
    let (_, el) = s.lights[0].angles_deg();
    assert!((30.0..=50.0).contains(&el), "sun elevation {el}");
    assert!(s.cameras.iter().any(|c| c.name == "Main"));
    assert!(s.cameras.iter().any(|c| c.name == "Overview"));
    for m in &s.materials {
        if let Some(t) = m.base_color_texture {
            let t = &s.textures[t];
            assert_eq!(t.rgba8.len(), (t.width * t.height * 4) as usize);
        }
    }
    assert!(s.materials.iter().any(|m| m.base_color_texture.is_some()));
    // every triangle is non-degenerate and its winding agrees with its vertex normals
    for t in 0..n {
        let [a, b, c] = s.triangle(t);
        let g = (b - a).cross(c - a);
        assert!(g.length() > 1e-8, "triangle {t} degenerate");
        let i = &s.indices[3 * t..3 * t + 3];
        let nsum: Vec3 = i.iter().map(|&k| s.normals[k as usize]).sum();
        assert!(
            g.dot(nsum) > 0.0,
            "triangle {t} winding disagrees with its normals"
        );
    }
    // deterministic
    let s2 = default_scene::build();
    assert_eq!(s.positions, s2.positions);
    assert_eq!(s.indices, s2.indices);
    // cameras are inside the room
    for c in &s.cameras {
        assert!(c.position.x.abs() < 3.0 && c.position.z.abs() < 2.5);
        assert!(c.position.y > 0.0 && c.position.y < 3.0);
    }
}

#[test]
fn default_scene_interior_faces_face_the_room() {
    // The first surface hit from the room centre towards each of the six room surfaces must
    // face the centre (front faces are CCW, normals point into the room).
    let s = default_scene::build();
    let centre = Vec3::new(0.0, 1.5, 0.0);
    // points on the six room surfaces (the back wall's point is beside the window)
    for target in [
        Vec3::new(3.0, 1.4, 0.3),
        Vec3::new(-3.0, 1.6, -0.2),
        Vec3::new(0.2, 3.0, 0.3),
        Vec3::new(1.9, 0.0, 1.7),
        Vec3::new(0.3, 1.3, 2.5),
        Vec3::new(2.0, 0.5, -2.5),
    ] {
        let dir = (target - centre).normalize();
        // brute-force nearest hit
        let mut best: Option<(f32, usize)> = None;
        for t in 0..s.triangle_count() {
            let [a, b, c] = s.triangle(t);
            if let Some(d) = ray_triangle(centre, dir, a, b, c)
                && best.is_none_or(|(bd, _)| d < bd)
            {
                best = Some((d, t));
            }
        }
        let (_, t) = best.expect("the room is closed");
        let [a, b, c] = s.triangle(t);
        let g = (b - a).cross(c - a);
        assert!(
            g.dot(dir) < 0.0,
            "surface hit along {dir:?} faces away from the room"
        );
    }
}

fn ray_triangle(o: Vec3, d: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Option<f32> {
    let (e1, e2) = (b - a, c - a);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - a;
    let u = s.dot(p) * inv;
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    let t = e2.dot(q) * inv;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 1e-4).then_some(t)
}

// ---------------------------------------------------------------------------------------
// Presets
// ---------------------------------------------------------------------------------------

#[test]
fn preset_parsing_and_errors() {
    let dir = temp_dir("preset");
    let p = dir.join("x.toml");
    let ok = r#"name = "X"
gltf = "m.gltf"
camera = "Cam"
exposure_ev = 1.5
[sun]
azimuth_deg = 30.0
elevation_deg = 70.0
irradiance = 10.0
"#;
    let pr = ScenePreset::from_toml_str(ok, &p).unwrap();
    assert_eq!(pr.sun.as_ref().unwrap().color, [1.0; 3]);
    // Found beside the preset; missing, one line naming where it looked.
    let e = pr.gltf_path(&p).unwrap_err().to_string();
    assert!(e.contains("m.gltf not found") && e.contains("looked in"), "{e}");
    std::fs::write(dir.join("m.gltf"), "{}").unwrap();
    assert_eq!(pr.gltf_path(&p).unwrap(), dir.join("m.gltf"));
    for (bad, needle) in [
        ("gltf = 3", "line 1"),
        ("gltf = \"a.gltf\"\nbogus = 1", "bogus"),
        (
            "gltf = \"a.gltf\"\n[sun]\nazimuth_deg = 0.0\nelevation_deg = 95.0\nirradiance = 1.0",
            "elevation_deg",
        ),
        (
            "gltf = \"a.gltf\"\n[sun]\nazimuth_deg = 0.0\nelevation_deg = 5.0\nirradiance = -1.0",
            "irradiance",
        ),
        (
            "gltf = \"a.gltf\"\ncamera = \"c\"\n[camera_pose]\neye = [0,0,0]\ntarget = [0,0,1]",
            "not both",
        ),
        ("camera = \"c\"", "gltf"),
    ] {
        match ScenePreset::from_toml_str(bad, &p) {
            Err(e @ SceneError::Preset { .. }) => {
                let msg = e.to_string();
                assert!(msg.contains(needle), "{bad:?}: {msg}");
                assert!(!msg.contains('\n'), "one line: {msg}");
            }
            other => panic!("{bad:?}: expected a preset error, got {other:?}"),
        }
    }
    assert!(matches!(
        load_preset(&dir.join("none.toml")),
        Err(SceneError::Io { .. })
    ));
}

#[test]
fn scene_source_from_arg() {
    assert_eq!(SceneSource::from_arg("default"), SceneSource::Default);
    assert_eq!(
        SceneSource::from_arg("scenes/a.toml"),
        SceneSource::Preset("scenes/a.toml".into())
    );
    assert_eq!(
        SceneSource::from_arg("x/B.glb"),
        SceneSource::Gltf("x/B.glb".into())
    );
}

#[test]
fn open_scene_applies_preset_sun_and_pose() {
    let dir = temp_dir("openpreset");
    std::fs::create_dir_all(dir.join("models")).unwrap();
    one_triangle().write(&dir.join("models"), "m", ONE_NODE);
    let p = dir.join("p.toml");
    std::fs::write(
        &p,
        r#"gltf = "models/m.gltf"
exposure_ev = -1.0
[sun]
azimuth_deg = 90.0
elevation_deg = 90.0
irradiance = 4.0
color = [1.0, 0.5, 0.5]
[camera_pose]
name = "pose"
eye = [0.0, 0.0, 5.0]
target = [0.0, 0.0, 0.0]
yfov_deg = 40.0
"#,
    )
    .unwrap();
    let o = open_scene(&SceneSource::Preset(p.clone())).unwrap();
    assert_eq!(o.exposure_ev, -1.0);
    assert_eq!(o.camera_name.as_deref(), Some("pose"));
    let cam = o.scene.camera_or_default(o.camera_name.as_deref()).unwrap();
    assert_close(cam.forward, Vec3::NEG_Z, "pose forward");
    assert_eq!(o.scene.lights.len(), 1);
    assert_close(o.scene.lights[0].direction, Vec3::NEG_Y, "sun straight down");
    assert_close(
        o.scene.lights[0].irradiance,
        Vec3::new(4.0, 2.0, 2.0),
        "sun irradiance",
    );

    // a glTF without lights gets a default sun and a warning
    let o = open_scene(&SceneSource::Gltf(dir.join("models/m.gltf"))).unwrap();
    assert_eq!(o.scene.lights.len(), 1);
    assert!(has_warning(&o.scene, "default sun"));
    // a preset naming a camera the file lacks is an error
    std::fs::write(&p, "gltf = \"models/m.gltf\"\ncamera = \"Nope\"\n").unwrap();
    let err = open_scene(&SceneSource::Preset(p)).unwrap_err();
    assert!(matches!(err, SceneError::Preset { .. }) && err.to_string().contains("Nope"));
    // the default scene opens with its own sun
    let o = open_scene(&SceneSource::Default).unwrap();
    assert!(o.scene.warnings.is_empty());
    assert!(o.scene.camera_or_default(None).unwrap().name == "Main");
}

// ---------------------------------------------------------------------------------------
// Shared reference scenes (skipped when absent)
// ---------------------------------------------------------------------------------------

/// The folder of the reference scenes, found through the scene search path (`fetch-scenes`,
/// `LIGHTCUT_SCENES`, `../shared/scenes`).
fn shared_scenes() -> Option<PathBuf> {
    let presets = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    match super::scene_path::find(Path::new("sponza/Sponza.gltf"), Some(&presets)) {
        Ok(p) => p.parent().and_then(|d| d.parent()).map(Path::to_path_buf),
        Err(e) => {
            println!("skipping: {e}");
            None
        }
    }
}

fn check_reference(scene: &Scene, cameras: &[&str], extensions: &[&str]) {
    assert!(
        scene.triangle_count() > 50_000,
        "{} triangles",
        scene.triangle_count()
    );
    for c in cameras {
        assert!(scene.cameras.iter().any(|k| k.name == *c), "camera {c} missing");
    }
    for e in extensions {
        assert!(
            has_warning(scene, e),
            "no warning about {e}: {:?}",
            scene.warnings
        );
    }
    let textured = scene
        .materials
        .iter()
        .filter(|m| m.base_color_texture.is_some())
        .count();
    assert!(textured > 0 && !scene.textures.is_empty());
    for t in &scene.textures {
        assert_eq!(t.rgba8.len(), (t.width * t.height * 4) as usize);
    }
    assert!(scene.positions.iter().all(|p| p.is_finite()));
    assert!(scene.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-3));
    assert!(!scene.bounds.is_empty());
}

#[test]
fn sponza_loads() {
    let Some(dir) = shared_scenes() else { return };
    let t = std::time::Instant::now();
    let s = load_gltf(&dir.join("sponza/Sponza.gltf")).unwrap();
    println!(
        "Sponza: {} triangles, {} textures in {:.2}s",
        s.triangle_count(),
        s.textures.len(),
        t.elapsed().as_secs_f32()
    );
    check_reference(
        &s,
        &["CameraMain", "CameraAlternate", "CameraBalcony", "CameraAlcove"],
        &["AMD_split_roughnessMetallic", "MSFT_texture_dds"],
    );
    assert!(s.textures.len() >= 20, "{} textures", s.textures.len());
    // the three 16x16 curtain stand-ins are decoded
    assert!(s.textures.iter().any(|t| t.width == 16 && t.height == 16));
    // the split roughness / metallic textures come from the PNGs beside their DDS files
    let with = |f: fn(&crate::scene::Material) -> Option<usize>| {
        s.materials.iter().filter(|m| f(m).is_some()).count()
    };
    assert!(
        with(|m| m.roughness_texture) >= 15,
        "{} roughness textures",
        with(|m| m.roughness_texture)
    );
    assert!(
        with(|m| m.metallic_texture) >= 6,
        "{} metallic textures",
        with(|m| m.metallic_texture)
    );
    assert!(!has_warning(&s, "beside its DDS"), "{:?}", s.warnings);
}

#[test]
fn breakfast_room_loads() {
    let Some(dir) = shared_scenes() else { return };
    let t = std::time::Instant::now();
    let s = load_gltf(&dir.join("breakfast_room/BreakfastRoom.gltf")).unwrap();
    println!(
        "Breakfast Room: {} triangles, {} textures in {:.2}s",
        s.triangle_count(),
        s.textures.len(),
        t.elapsed().as_secs_f32()
    );
    check_reference(
        &s,
        &["CameraMain", "CameraTableTop", "CameraTopDown"],
        &["MSFT_texture_dds", "KHR_materials_specular"],
    );
}

#[test]
fn presets_in_scenes_folder_open() {
    let Some(_) = shared_scenes() else { return };
    let presets = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for (file, name) in [
        ("sponza.toml", "Sponza"),
        ("breakfast_room.toml", "Breakfast Room"),
    ] {
        let o = open_scene(&SceneSource::Preset(presets.join(file))).unwrap();
        assert_eq!(o.scene.name, name);
        assert_eq!(o.camera_name.as_deref(), Some("CameraMain"));
        assert!(o.scene.camera_or_default(o.camera_name.as_deref()).is_ok());
        assert_eq!(o.scene.lights.len(), 1);
        let l = &o.scene.lights[0];
        assert!(l.irradiance.min_element() > 0.0);
        assert!(l.direction.y < -0.3, "{file}: the sun shines downwards");
        assert!(!has_warning(&o.scene, "default sun"));
    }
}

#[test]
fn camera_bookmarks_append_to_a_preset_and_load_as_cameras() {
    use super::preset::append_bookmark;
    let dir = temp_dir("bookmark");
    let p = dir.join("b.toml");
    let text = "# a comment that must survive\nname = \"B\"\ngltf = \"m.gltf\"\n[sun]\nazimuth_deg = 30.0\nelevation_deg = 70.0\nirradiance = 10.0\n";
    std::fs::write(&p, text).unwrap();
    let cam = crate::scene::Camera::look_at(
        "desk view",
        glam::Vec3::new(1.0, 2.0, 3.0),
        glam::Vec3::new(0.0, 1.0, 0.0),
        50f32.to_radians(),
        0.01,
        100.0,
    );
    append_bookmark(&p, &cam).unwrap();
    append_bookmark(
        &p,
        &crate::scene::Camera {
            name: "second".into(),
            ..cam.clone()
        },
    )
    .unwrap();
    let after = std::fs::read_to_string(&p).unwrap();
    assert!(after.starts_with("# a comment that must survive"));
    let pr = load_preset(&p).unwrap();
    assert_eq!(pr.bookmarks.len(), 2);
    let b = &pr.bookmarks[0];
    assert_eq!(b.name, "desk view");
    // Opening the preset lists the bookmarks among the scene's cameras.
    one_triangle().write(&dir, "m", ONE_NODE);
    let opened = open_scene(&SceneSource::Preset(p.clone())).unwrap();
    let names: Vec<&str> = opened.scene.cameras.iter().map(|c| c.name.as_str()).collect();
    assert!(
        names.contains(&"desk view") && names.contains(&"second"),
        "{names:?}"
    );
    let back = b.camera(100.0);
    assert!((back.position - cam.position).length() < 1e-3);
    assert!((back.forward - cam.forward).length() < 1e-3);
    assert!((back.yfov - cam.yfov).abs() < 1e-4);
}

/// A sun with `intensity` and `color` (JSON text) over one triangle.
fn sun_file(dir: &Path, name: &str, intensity: &str, color: &str) -> PathBuf {
    let rest = format!(
        r#"{ONE_NODE_NO_SCENE},
"extensionsUsed":["KHR_lights_punctual"],
"extensions":{{"KHR_lights_punctual":{{"lights":[
  {{"name":"Noon","type":"directional","intensity":{intensity},"color":{color}}}]}}}},
"nodes":[{{"mesh":0}},{{"name":"sunnode","extensions":{{"KHR_lights_punctual":{{"light":0}}}}}}],
"scenes":[{{"nodes":[0,1]}}],"scene":0"#
    );
    one_triangle().write(dir, name, &rest)
}

#[test]
fn negative_or_non_finite_light_is_refused_naming_the_light() {
    let dir = temp_dir("badlight");
    for (i, (intensity, color)) in [("-3.0", "[1,1,1]"), ("2.0", "[1,-0.5,1]"), ("1e39", "[1,1,1]")]
        .into_iter()
        .enumerate()
    {
        let err = load_gltf(&sun_file(&dir, &format!("l{i}"), intensity, color)).unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, SceneError::InvalidGltf { .. }), "{msg}");
        assert!(
            msg.contains("'Noon'") && msg.contains("must be finite and >= 0"),
            "{msg}"
        );
        assert!(!msg.contains('\n'), "one line: {msg}");
    }
    let ok = load_gltf(&sun_file(&dir, "ok", "0.0", "[1,1,1]")).unwrap();
    assert_eq!(ok.lights[0].irradiance, Vec3::ZERO, "a dark sun is allowed");
}

/// One triangle under a node scaled by `scale`, seen by a camera 2 units away (before the
/// scale) with the clip range 0.05..100.
fn scaled_scene(dir: &Path, name: &str, scale: f32) -> Scene {
    let rest = format!(
        r#"{ONE_NODE_NO_SCENE},
"cameras":[{{"name":"Cam","type":"perspective","perspective":{{"yfov":0.8,"znear":0.05,"zfar":100.0}}}}],
"nodes":[{{"scale":[{scale},{scale},{scale}],"children":[1,2]}},{{"mesh":0}},
  {{"name":"camnode","translation":[0.3,0.3,2],"camera":0}}],
"scenes":[{{"nodes":[0]}}],"scene":0"#
    );
    load_gltf(&one_triangle().write(dir, name, &rest)).unwrap()
}

#[test]
fn a_camera_whose_clip_range_misses_a_scaled_scene_gets_one_from_the_bounds() {
    let dir = temp_dir("scaled");
    let s = scaled_scene(&dir, "one", 1.0);
    assert_eq!(
        (s.cameras[0].znear, s.cameras[0].zfar),
        (0.05, 100.0),
        "kept when it fits"
    );
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    for scale in [1e6f32, 1e-6] {
        let s = scaled_scene(&dir, &format!("s{}", scale.log10()), scale);
        let c = &s.cameras[0];
        let (lo, hi) = c.depth_range(&s.bounds).unwrap();
        assert!(
            lo <= hi && (hi - 2.0 * scale).abs() < 0.01 * scale,
            "{scale}: {lo}..{hi}"
        );
        assert!(
            c.znear < lo.max(1e-3 * hi) + 1e-30 && c.zfar > hi && c.zfar / c.znear <= 1.0001e6,
            "{scale}: {}..{} for the scene's {lo}..{hi}",
            c.znear,
            c.zfar
        );
        assert!(has_warning(&s, "misses the scene"), "{scale}: {:?}", s.warnings);
    }
}

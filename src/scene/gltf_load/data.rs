//! The bounds-checked reading of a glTF file's data: URIs and data URIs, buffers, base-colour
//! images, accessors (with sparse substitution) and primitives. Nothing here trusts the
//! file: every range is checked, every failure is a one-line message.

mod compressed;
pub(crate) use compressed::*;

use super::*;

/// Geometry of one primitive in its local space.
pub(super) struct PrimData {
    pub(super) positions: Vec<Vec3>,
    pub(super) normals: Option<Vec<Vec3>>,
    pub(super) uvs: Option<Vec<Vec2>>,
    pub(super) indices: Vec<u32>,
}

/// Upper bound on elements of an accessor that has no buffer view (all zeros).
const MAX_VIEWLESS_COUNT: usize = 1 << 26;

/// Decodes `%XX` escapes of a relative URI (invalid escapes are kept as they are).
pub(super) fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = |c: u8| (c as char).to_digit(16);
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Resolves a non-`data:` URI against the glTF file's folder.
pub(super) fn resolve_uri(base_dir: &Path, uri: &str) -> Result<PathBuf, String> {
    if let Some(rest) = uri.strip_prefix("file://").or_else(|| uri.strip_prefix("file:")) {
        return Ok(PathBuf::from(percent_decode(rest)));
    }
    if let Some(colon) = uri.find(':') {
        // A scheme is letters before ':' (Windows drive letters are one letter long).
        let scheme = &uri[..colon];
        if scheme.len() > 1
            && scheme
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
        {
            return Err(format!("unsupported URI scheme '{scheme}:'"));
        }
    }
    Ok(base_dir.join(percent_decode(uri)))
}

pub(super) fn decode_data_uri(uri: &str) -> Result<Vec<u8>, String> {
    gltf::buffer::Data::from_source(gltf::buffer::Source::Uri(uri), None)
        .map(|d| d.0)
        .map_err(|e| format!("bad data URI: {}", one_line(&e.to_string())))
}

/// The file's buffers, and the buffer views decoded from EXT_meshopt_compression (by view
/// index; [`view_slice`] reads those instead of the view's own, fallback, bytes).
pub(super) struct Buffers {
    pub(super) data: Vec<Vec<u8>>,
    pub(super) decoded: HashMap<usize, Vec<u8>>,
}

/// Whether a buffer is an EXT_meshopt_compression fallback
/// (`"extensions": {"EXT_meshopt_compression": {"fallback": true}}`): the extension's schema
/// says it need not be loaded, with or without a `uri` (its views are all compressed).
fn is_meshopt_fallback(buffer: &gltf::Buffer) -> bool {
    buffer
        .extension_value("EXT_meshopt_compression")
        .and_then(|e| e.get("fallback"))
        .and_then(|v| v.as_bool())
        == Some(true)
}

pub(super) fn load_buffers(
    doc: &gltf::Document,
    path: &Path,
    base_dir: &Path,
    mut blob: Option<Vec<u8>>,
) -> Result<Vec<Vec<u8>>, SceneError> {
    let mut out = Vec::new();
    for buffer in doc.buffers() {
        let index = buffer.index();
        let bad = |message: String| SceneError::BadBuffer {
            path: path.to_path_buf(),
            index,
            message,
        };
        // A meshopt fallback is never read; nor is a buffer without a `uri` other than a
        // GLB's first (its BIN chunk): EXT_meshopt_compression allows such placeholders, and a
        // view that reads one is refused by `view_slice`.
        let placeholder =
            matches!(buffer.source(), gltf::buffer::Source::Bin) && (index > 0 || blob.is_none());
        if is_meshopt_fallback(&buffer) || placeholder {
            if index == 0 {
                blob = None;
            }
            out.push(Vec::new());
            continue;
        }
        let (data, name) = match buffer.source() {
            gltf::buffer::Source::Bin => match blob.take() {
                Some(b) => (b, "GLB BIN chunk".to_string()),
                None => return Err(bad("the GLB file has no BIN chunk".into())),
            },
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                (decode_data_uri(uri).map_err(bad)?, "data URI".to_string())
            }
            gltf::buffer::Source::Uri(uri) => {
                let file = resolve_uri(base_dir, uri).map_err(bad)?;
                match std::fs::read(&file) {
                    Ok(d) => (d, file.display().to_string()),
                    Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                        return Err(SceneError::MissingBuffer {
                            gltf: path.to_path_buf(),
                            index,
                            buffer: file,
                        });
                    }
                    Err(source) => return Err(SceneError::Io { path: file, source }),
                }
            }
        };
        if data.len() < buffer.length() {
            return Err(SceneError::TruncatedBuffer {
                path: path.to_path_buf(),
                index,
                name,
                declared: buffer.length(),
                actual: data.len(),
            });
        }
        out.push(data);
    }
    Ok(out)
}

/// A material's texture requests: (source, TEXCOORD set) of its base colour, roughness and
/// metallic textures.
#[derive(Default)]
pub(super) struct MaterialTextures {
    pub(super) base: Option<(TexSource, u32)>,
    pub(super) roughness: Option<(TexSource, u32)>,
    pub(super) metallic: Option<(TexSource, u32)>,
}

/// Where a texture's pixels come from: a glTF image, or an image file found beside a
/// DDS-only texture's `.dds` (see [`dds_sibling`]).
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(super) enum TexSource {
    Image(usize),
    File(PathBuf),
}

/// What a texture holds: colour (sRGB-encoded, base colour) or data (linear: glTF's
/// metallic-roughness, roughness in G and metallic in B). Data textures are stored
/// sRGB-encoded ([`TextureImage::encode_linear_as_srgb`]) so that they share the base colour array, whose
/// sampler decodes them back to linear.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(super) enum TexKind {
    Color,
    Data,
}

impl TexKind {
    fn what(self) -> &'static str {
        match self {
            TexKind::Color => "base colour",
            TexKind::Data => "metallic-roughness",
        }
    }
    fn fallback(self) -> &'static str {
        match self {
            TexKind::Color => "their colour factor only",
            TexKind::Data => "their metallic / roughness factors only",
        }
    }
}

/// The image file beside a DDS-only texture's `.dds`: `name.roughness.dds` / `name.metallic.dds` ->
/// `name.png` / `.jpg` / `.jpeg`, if it exists. Sponza's `AMD_split_roughnessMetallic`
/// textures are DDS-only (`sponza_arch_rough.roughness.dds`), split from the glTF
/// metallic-roughness PNGs shipped beside them (`sponza_arch_rough.png`: roughness in G,
/// metallic in B).
pub(super) fn dds_sibling(base_dir: &Path, dds_uri: &str) -> Option<PathBuf> {
    let lower = dds_uri.to_ascii_lowercase();
    let stem_len = lower.strip_suffix(".dds")?.len();
    let stem = &dds_uri[..stem_len];
    // Only a split map's name (`.roughness` / `.metallic` before `.dds`): a plain `name.dds`
    // beside `name.png` is as likely a base colour image.
    let stem = [".roughness", ".metallic"].iter().find_map(|part| {
        stem.to_ascii_lowercase()
            .ends_with(part)
            .then(|| &stem[..stem.len() - part.len()])
    })?;
    ["png", "jpg", "jpeg"]
        .iter()
        .filter_map(|ext| resolve_uri(base_dir, &format!("{stem}.{ext}")).ok())
        .find(|p| p.is_file())
}

/// Decodes every texture the materials use (each source and kind once, in parallel).
/// `users`: (source, kind) -> names of the materials using it. Returns the textures and a
/// map (source, kind) -> texture index (`None` when it failed, with a warning).
#[allow(clippy::type_complexity)]
pub(super) fn load_textures(
    doc: &gltf::Document,
    buffers: &Buffers,
    base_dir: &Path,
    users: &BTreeMap<(TexSource, TexKind), Vec<String>>,
    warnings: &mut Warnings,
) -> (Vec<TextureImage>, HashMap<(TexSource, TexKind), Option<usize>>) {
    let images: Vec<gltf::Image> = doc.images().collect();
    let jobs: Vec<&(TexSource, TexKind)> = users.keys().collect();
    let results: Mutex<Vec<Option<DecodeResult>>> = Mutex::new((0..jobs.len()).map(|_| None).collect());
    let next = AtomicUsize::new(0);
    let threads = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(2)
        .clamp(1, 8)
        .min(jobs.len().max(1));

    let work = || {
        loop {
            let j = next.fetch_add(1, Ordering::Relaxed);
            let Some(&(source, kind)) = jobs.get(j) else { break };
            let (label, mut res) = match source {
                TexSource::Image(i) => {
                    let Some(img) = images.get(*i) else {
                        continue;
                    };
                    decode_image(img, buffers, base_dir)
                }
                TexSource::File(p) => decode_file(p),
            };
            if *kind == TexKind::Data
                && let Ok(t) = &mut res
            {
                t.encode_linear_as_srgb();
            }
            if let Ok(mut r) = results.lock() {
                r[j] = Some((label, res));
            }
        }
    };
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads).map(|_| s.spawn(work)).collect();
        for h in handles {
            // A decoder panic only loses that image (it is reported as a failure below).
            let _ = h.join();
        }
    });
    let results = results.into_inner().unwrap_or_else(|p| p.into_inner());

    let mut textures = Vec::new();
    let mut map = HashMap::new();
    for (j, &key) in jobs.iter().enumerate() {
        let user_list = users.get(key).map(|u| u.join("', '")).unwrap_or_default();
        let (what, fallback) = (key.1.what(), key.1.fallback());
        match results.get(j).cloned().flatten() {
            Some((_, Ok(t))) => {
                map.insert(key.clone(), Some(textures.len()));
                textures.push(t);
            }
            Some((label, Err(e))) => {
                warnings.push(format!(
                    "{what} image {label} not loaded ({e}); material(s) '{user_list}' use {fallback}"
                ));
                map.insert(key.clone(), None);
            }
            None => {
                let name = match &key.0 {
                    TexSource::Image(i) => i.to_string(),
                    TexSource::File(p) => format!("'{}'", p.display()),
                };
                warnings.push(format!(
                    "{what} image {name} not loaded (decoder failure); material(s) '{user_list}' use {fallback}"
                ));
                map.insert(key.clone(), None);
            }
        }
    }
    (textures, map)
}

/// Decodes an image file found beside a DDS-only texture.
fn decode_file(p: &Path) -> (String, Result<TextureImage, String>) {
    let label = format!("'{}'", p.display());
    let name = p
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "image".into());
    let res = std::fs::read(p)
        .map_err(|e| e.to_string())
        .and_then(|b| decode_bytes(&b, name));
    (label, res)
}

fn decode_bytes(b: &[u8], name: String) -> Result<TextureImage, String> {
    let decoded = image::load_from_memory(b).map_err(|e| one_line(&e.to_string()))?;
    let rgba = decoded.into_rgba8();
    Ok(TextureImage {
        name,
        width: rgba.width(),
        height: rgba.height(),
        rgba8: rgba.into_raw(),
    })
}

pub(super) fn decode_image(
    img: &gltf::Image,
    buffers: &Buffers,
    base_dir: &Path,
) -> (String, Result<TextureImage, String>) {
    let (label, bytes): (String, Result<Vec<u8>, String>) = match img.source() {
        gltf::image::Source::Uri { uri, .. } if uri.starts_with("data:") => (
            format!("{} (data URI)", img.name().unwrap_or("image")),
            decode_data_uri(uri),
        ),
        gltf::image::Source::Uri { uri, .. } => match resolve_uri(base_dir, uri) {
            Ok(p) => (
                format!("'{}'", p.display()),
                std::fs::read(&p).map_err(|e| e.to_string()),
            ),
            Err(e) => (format!("'{uri}'"), Err(e)),
        },
        gltf::image::Source::View { view, .. } => (
            format!("{} (buffer view {})", img.name().unwrap_or("image"), view.index()),
            view_slice(&view, buffers).map(<[u8]>::to_vec),
        ),
    };
    let name = img
        .name()
        .map(str::to_string)
        .unwrap_or_else(|| format!("image{}", img.index()));
    let res = bytes.and_then(|b| decode_bytes(&b, name));
    (label, res)
}

pub(super) fn view_slice<'b>(view: &gltf::buffer::View, buffers: &'b Buffers) -> Result<&'b [u8], String> {
    // A view compressed with EXT_meshopt_compression: its decoded bytes.
    if let Some(d) = buffers.decoded.get(&view.index()) {
        return Ok(d.get(..view.length()).unwrap_or(d));
    }
    let buf = buffers
        .data
        .get(view.buffer().index())
        .ok_or_else(|| format!("buffer view {} names a missing buffer", view.index()))?;
    if buf.is_empty() && view.length() > 0 {
        return Err(format!(
            "buffer view {} reads buffer {}, which holds no data (a meshopt fallback or a \
             placeholder without a uri)",
            view.index(),
            view.buffer().index()
        ));
    }
    let end = view
        .offset()
        .checked_add(view.length())
        .ok_or("buffer view range overflows")?;
    buf.get(view.offset()..end).ok_or_else(|| {
        format!(
            "buffer view {} (bytes {}..{end}) lies outside its buffer ({} bytes)",
            view.index(),
            view.offset(),
            buf.len()
        )
    })
}

pub(super) fn read_primitive(
    prim: &gltf::Primitive,
    buffers: &Buffers,
    uv_set: u32,
) -> Result<(PrimData, bool), String> {
    let pos_acc = prim
        .get(&gltf::Semantic::Positions)
        .ok_or("no POSITION attribute")?;
    if pos_acc.dimensions() != Dimensions::Vec3 {
        return Err("POSITION is not a VEC3 accessor".into());
    }
    let positions: Vec<Vec3> = read_floats(&pos_acc, buffers)
        .map_err(|e| format!("POSITION: {e}"))?
        .chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect();
    let n = positions.len();

    let normals = match prim.get(&gltf::Semantic::Normals) {
        Some(acc) if acc.dimensions() == Dimensions::Vec3 && acc.count() == n => {
            let v = read_floats(&acc, buffers).map_err(|e| format!("NORMAL: {e}"))?;
            Some(v.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect())
        }
        _ => None,
    };
    let (uvs, uv_missing) = match prim.get(&gltf::Semantic::TexCoords(uv_set)) {
        Some(acc) if acc.dimensions() == Dimensions::Vec2 && acc.count() == n => {
            let v = read_floats(&acc, buffers).map_err(|e| format!("TEXCOORD_{uv_set}: {e}"))?;
            let uvs: Vec<Vec2> = v
                .chunks_exact(2)
                .map(|c| {
                    let uv = Vec2::new(c[0], c[1]);
                    if uv.is_finite() { uv } else { Vec2::ZERO }
                })
                .collect();
            (Some(uvs), false)
        }
        _ => (
            None,
            prim.material()
                .pbr_metallic_roughness()
                .base_color_texture()
                .is_some(),
        ),
    };
    let indices = match prim.indices() {
        Some(acc) => read_indices(&acc, buffers).map_err(|e| format!("indices: {e}"))?,
        None => (0..n as u32).collect(),
    };
    Ok((
        PrimData {
            positions,
            normals,
            uvs,
            indices,
        },
        uv_missing,
    ))
}

pub(super) fn component_size(t: DataType) -> usize {
    match t {
        DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::U32 | DataType::F32 => 4,
    }
}

/// Reads all components of an accessor (including sparse substitution) through `conv`,
/// which turns the bytes of one component into a value. Every range is checked.
pub(super) fn read_accessor<T: Copy + Default>(
    acc: &gltf::Accessor,
    buffers: &Buffers,
    conv: &dyn Fn(&[u8], DataType) -> T,
) -> Result<Vec<T>, String> {
    let comps = match acc.dimensions() {
        Dimensions::Scalar => 1,
        Dimensions::Vec2 => 2,
        Dimensions::Vec3 => 3,
        Dimensions::Vec4 => 4,
        d => return Err(format!("unsupported accessor type {d:?}")),
    };
    let ct = acc.data_type();
    let csize = component_size(ct);
    let elem = comps * csize;
    let count = acc.count();
    let total = count.checked_mul(comps).ok_or("accessor count overflows")?;
    let mut out: Vec<T>;
    match acc.view() {
        Some(view) => {
            let data = view_slice(&view, buffers)?;
            let stride = view.stride().unwrap_or(elem);
            if stride < elem {
                return Err(format!(
                    "byteStride {stride} is smaller than the element size {elem}"
                ));
            }
            if count > 0 {
                let end = (count - 1)
                    .checked_mul(stride)
                    .and_then(|x| x.checked_add(acc.offset()))
                    .and_then(|x| x.checked_add(elem))
                    .ok_or("accessor range overflows")?;
                if end > data.len() {
                    return Err(format!(
                        "accessor {} needs {end} bytes but its buffer view has {}",
                        acc.index(),
                        data.len()
                    ));
                }
            }
            out = Vec::with_capacity(total);
            for i in 0..count {
                let start = acc.offset() + i * stride;
                for c in 0..comps {
                    let s = start + c * csize;
                    out.push(conv(&data[s..s + csize], ct));
                }
            }
        }
        None => {
            if count > MAX_VIEWLESS_COUNT {
                return Err(format!(
                    "accessor {} without buffer view has count {count}",
                    acc.index()
                ));
            }
            out = vec![T::default(); total];
        }
    }

    if let Some(sparse) = acc.sparse() {
        let sc = sparse.count();
        let idx = sparse.indices();
        let idx_data = view_slice(&idx.view(), buffers)?;
        let isize_ = idx.index_type().size();
        let idx_end = sc
            .checked_mul(isize_)
            .and_then(|x| x.checked_add(idx.offset()))
            .ok_or("sparse index range overflows")?;
        let vals = sparse.values();
        let val_data = view_slice(&vals.view(), buffers)?;
        let val_end = sc
            .checked_mul(elem)
            .and_then(|x| x.checked_add(vals.offset()))
            .ok_or("sparse value range overflows")?;
        if idx_end > idx_data.len() || val_end > val_data.len() {
            return Err("sparse accessor data lies outside its buffer views".into());
        }
        for k in 0..sc {
            let s = idx.offset() + k * isize_;
            let b = &idx_data[s..s + isize_];
            let target = match isize_ {
                1 => b[0] as usize,
                2 => u16::from_le_bytes([b[0], b[1]]) as usize,
                _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
            };
            if target >= count {
                return Err(format!("sparse index {target} out of range (count {count})"));
            }
            let vs = vals.offset() + k * elem;
            for c in 0..comps {
                let s = vs + c * csize;
                out[target * comps + c] = conv(&val_data[s..s + csize], ct);
            }
        }
    }
    Ok(out)
}

/// A normalised integer component of type `t` as a float (glTF 2.0's accessor rule, as
/// KHR_mesh_quantization: c / max, signed ones clamped at -1); floats and u32 unchanged.
pub(super) fn unnormalize(v: f32, t: DataType) -> f32 {
    match t {
        DataType::U8 => v / 255.0,
        DataType::I8 => (v / 127.0).max(-1.0),
        DataType::U16 => v / 65535.0,
        DataType::I16 => (v / 32767.0).max(-1.0),
        DataType::U32 | DataType::F32 => v,
    }
}

pub(super) fn read_floats(acc: &gltf::Accessor, buffers: &Buffers) -> Result<Vec<f32>, String> {
    let norm = acc.normalized();
    read_accessor(acc, buffers, &|b: &[u8], t: DataType| {
        let v = match t {
            DataType::F32 => return f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            DataType::U8 => b[0] as f32,
            DataType::I8 => b[0] as i8 as f32,
            DataType::U16 => u16::from_le_bytes([b[0], b[1]]) as f32,
            DataType::I16 => i16::from_le_bytes([b[0], b[1]]) as f32,
            DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
        };
        if norm { unnormalize(v, t) } else { v }
    })
}

pub(super) fn read_indices(acc: &gltf::Accessor, buffers: &Buffers) -> Result<Vec<u32>, String> {
    if acc.dimensions() != Dimensions::Scalar {
        return Err("index accessor is not SCALAR".into());
    }
    match acc.data_type() {
        DataType::U8 | DataType::U16 | DataType::U32 => {}
        t => return Err(format!("index component type {t:?} is not unsigned")),
    }
    read_accessor(acc, buffers, &|b: &[u8], t: DataType| match t {
        DataType::U8 => b[0] as u32,
        DataType::U16 => u16::from_le_bytes([b[0], b[1]]) as u32,
        _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
    })
}

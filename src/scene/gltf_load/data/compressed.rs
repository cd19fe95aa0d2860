//! Compressed geometry: EXT_meshopt_compression buffer views (meshoptimizer-rs) and
//! KHR_draco_mesh_compression primitives.

use super::*;

/// Decodes every buffer view compressed with EXT_meshopt_compression (its extension object:
/// `buffer`, `byteOffset`, `byteLength`, `byteStride`, `count`, `mode`, `filter`) with
/// meshoptimizer-rs (a Rust port of meshoptimizer's decoders: the vertex codec, the index
/// codecs and the OCTAHEDRAL / QUATERNION / EXPONENTIAL filters). Returns the decoded views
/// and how many there were; a view that fails to decode is an error naming it.
pub(crate) fn decode_meshopt_views(
    doc: &gltf::Document,
    data: &[Vec<u8>],
) -> Result<HashMap<usize, Vec<u8>>, String> {
    use meshoptimizer_rs::codec::{Filter, Mode, decode_buffer_view};
    let mut out = HashMap::new();
    let mut workspace = meshoptimizer_rs::Workspace::default();
    for view in doc.views() {
        let Some(ext) = view.extension_value("EXT_meshopt_compression") else {
            continue;
        };
        let i = view.index();
        let num = |k: &str| ext.get(k).and_then(|v| v.as_u64()).map(|v| v as usize);
        let (Some(buffer), Some(length), Some(stride), Some(count)) =
            (num("buffer"), num("byteLength"), num("byteStride"), num("count"))
        else {
            return Err(format!(
                "buffer view {i}: EXT_meshopt_compression lacks buffer, byteLength, byteStride or count"
            ));
        };
        let offset = num("byteOffset").unwrap_or(0);
        let text = |k: &str, d: &'static str| ext.get(k).and_then(|v| v.as_str()).unwrap_or(d).to_string();
        let mode = Mode::parse(&text("mode", "")).map_err(|_| {
            format!(
                "buffer view {i}: EXT_meshopt_compression mode '{}' is not ATTRIBUTES, TRIANGLES or INDICES",
                text("mode", "")
            )
        })?;
        let filter = Filter::parse(&text("filter", "NONE")).map_err(|_| {
            format!(
                "buffer view {i}: unknown EXT_meshopt_compression filter '{}'",
                text("filter", "NONE")
            )
        })?;
        let src = data
            .get(buffer)
            .and_then(|b| b.get(offset..offset.checked_add(length)?))
            .ok_or_else(|| format!("buffer view {i}: its compressed bytes lie outside buffer {buffer}"))?;
        if mode == Mode::Attributes && view.stride().is_some_and(|s| s != stride) {
            return Err(format!(
                "buffer view {i}: byteStride {:?} differs from EXT_meshopt_compression's {stride}",
                view.stride()
            ));
        }
        // Both decoders are written for untrusted input; a panic still becomes an error.
        let decoded = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            decode_buffer_view(mode, filter, count, stride, src, &mut workspace)
        }))
        .map_err(|_| format!("buffer view {i}: the meshopt decoder failed"))?
        .map_err(|e| format!("buffer view {i}: EXT_meshopt_compression data does not decode ({e:?})"))?;
        if count.checked_mul(stride) != Some(view.length()) || decoded.len() < view.length() {
            return Err(format!(
                "buffer view {i}: {count} x {stride} decoded bytes, the view declares {}",
                view.length()
            ));
        }
        out.insert(i, decoded);
    }
    Ok(out)
}

/// A primitive compressed with KHR_draco_mesh_compression (`bufferView` and `attributes`:
/// glTF attribute name to Draco unique id), decoded with draco-core (a pure-Rust Draco
/// decoder: sequential and EdgeBreaker connectivity, the quantisation and octahedral
/// transforms, as Draco 1.5 writes them). The attributes come out dequantised, as floats.
pub(crate) fn read_draco_primitive(
    doc: &gltf::Document,
    prim: &gltf::Primitive,
    ext: &serde_json::Value,
    buffers: &Buffers,
    uv_set: u32,
) -> Result<(PrimData, bool), String> {
    let doc_view = ext
        .get("bufferView")
        .and_then(|v| v.as_u64())
        .ok_or("KHR_draco_mesh_compression has no bufferView")? as usize;
    let view = doc
        .views()
        .nth(doc_view)
        .ok_or_else(|| format!("KHR_draco_mesh_compression names missing buffer view {doc_view}"))?;
    let bytes = view_slice(&view, buffers)?;
    let mut mesh = draco_core::Mesh::new();
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        draco_core::MeshDecoder::new().decode(&mut draco_core::DecoderBuffer::new(bytes), &mut mesh)
    }))
    .map_err(|_| "the Draco decoder failed".to_string())?
    .map_err(|e| format!("the Draco data does not decode ({e})"))?;
    let n = mesh.num_points();
    // An attribute from the Draco stream (integer data normalised as its accessor says), or,
    // where the extension does not list it, from its own accessor as usual (the spec).
    let attr = |name: &str, semantic: gltf::Semantic, comps: usize| -> Result<Option<Vec<f32>>, String> {
        let acc = prim.get(&semantic);
        let Some(id) = ext
            .get("attributes")
            .and_then(|a| a.get(name))
            .and_then(|v| v.as_u64())
        else {
            return match acc {
                Some(acc) if acc.count() == n => read_floats(&acc, buffers)
                    .map(Some)
                    .map_err(|e| format!("{name}: {e}")),
                _ => Ok(None),
            };
        };
        let Some(a) = mesh.attribute_by_unique_id(id as u32) else {
            return Err(format!("{name}: Draco attribute {id} is not in the stream"));
        };
        if (a.num_components() as usize) < comps {
            return Ok(None);
        }
        let mut v = a.read_f32s(n, comps);
        if let Some(acc) = acc.filter(|acc| acc.normalized())
            && a.data_type() != draco_core::DataType::Float32
        {
            for x in &mut v {
                *x = unnormalize(*x, acc.data_type());
            }
        }
        Ok(Some(v))
    };
    let positions: Vec<Vec3> = attr("POSITION", gltf::Semantic::Positions, 3)?
        .ok_or("the Draco data has no POSITION attribute")?
        .chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect();
    let normals = attr("NORMAL", gltf::Semantic::Normals, 3)?
        .map(|v| v.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect());
    let set = format!("TEXCOORD_{uv_set}");
    let uvs: Option<Vec<Vec2>> = attr(&set, gltf::Semantic::TexCoords(uv_set), 2)?.map(|v| {
        v.chunks_exact(2)
            .map(|c| {
                let uv = Vec2::new(c[0], c[1]);
                if uv.is_finite() { uv } else { Vec2::ZERO }
            })
            .collect()
    });
    let uv_missing = uvs.is_none()
        && prim
            .material()
            .pbr_metallic_roughness()
            .base_color_texture()
            .is_some();
    let indices: Vec<u32> = mesh.faces().iter().flat_map(|f| f.iter().map(|p| p.0)).collect();
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

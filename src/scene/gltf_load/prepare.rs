//! The glTF JSON made ready for the gltf crate's validation: the extension policy, textures whose
//! image only an extension gives, Draco primitives' accessors, POSITION bounds.

use super::*;

/// A file's extensions against [`ext_policy`]: supported ones pass, ignored and partial ones
/// warn, geometry-changing or unknown required ones are errors. Required extensions are taken
/// off the list before validation (the gltf crate rejects required extensions it does not
/// know, even harmless ones).
pub(super) fn apply_extension_policy(
    root: &mut gltf::json::Root,
    path: &Path,
    warnings: &mut Warnings,
) -> Result<(), SceneError> {
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
    Ok(())
}

/// Textures whose only image is given through an extension (e.g. MSFT_texture_dds without a
/// plain `source`): pointed at a placeholder image so validation passes, and treated as "no
/// texture" when materials are read.
#[derive(Default)]
pub(super) struct ExtensionSources {
    /// The textures without a plain source.
    pub(super) sourceless: HashSet<usize>,
    /// Their DDS image's URI (MSFT_texture_dds), where the file gives one.
    pub(super) dds_uris: HashMap<usize, String>,
}

/// Finds the textures without a plain image source and points them at a placeholder.
pub(super) fn point_sourceless_textures(root: &mut gltf::json::Root) -> Result<ExtensionSources, String> {
    let mut sourceless: HashSet<usize> = HashSet::new();
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
                .map_err(|e| e.to_string())?;
        let idx = root.images.len() as u32;
        root.images.push(placeholder);
        for (i, t) in root.textures.iter_mut().enumerate() {
            if t.source.value() == u32::MAX as usize {
                t.source = gltf::json::Index::new(idx);
                sourceless.insert(i);
            }
        }
    }
    Ok(ExtensionSources { sourceless, dds_uris })
}

/// KHR_draco_mesh_compression: the primitive's accessors have no buffer view (their data is in
/// the Draco stream, `data::read_draco_primitive`), which the gltf crate's validation rejects;
/// they are pointed at the Draco buffer view, and never read through it.
pub(super) fn point_draco_accessors(root: &mut gltf::json::Root) {
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
}

/// POSITION min/max are required by the spec but unused here: files that lack them or get them
/// wrong are not rejected.
pub(super) fn relax_position_bounds(root: &mut gltf::json::Root) -> Result<(), String> {
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
            .ok_or_else(|| format!("a POSITION attribute names missing accessor {a}"))?;
        let zero = gltf::json::Value::from(vec![0.0f32; 3]);
        acc.min = Some(zero.clone());
        acc.max = Some(zero);
    }
    Ok(())
}

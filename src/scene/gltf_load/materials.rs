//! Materials: the textures each reads ([`texture_requests`]) and the materials with their UV set
//! and KHR_texture_transform ([`build_materials`]).

use super::*;

/// Per texture and kind, the materials that use it.
pub(super) type TextureUsers = BTreeMap<(TexSource, TexKind), Vec<String>>;

/// The textures a material reads: base colour, and metallic-roughness (glTF's
/// `metallicRoughnessTexture`, or AMD_split_roughnessMetallic's separate roughness and metallic
/// textures; roughness is read from G and metallic from B either way, which also reads a grey
/// image right); with the materials that use each texture.
pub(super) fn texture_requests(
    doc: &gltf::Document,
    sources: &ExtensionSources,
    base_dir: &Path,
    warnings: &mut Warnings,
) -> (Vec<MaterialTextures>, TextureUsers) {
    let mut requests: Vec<MaterialTextures> = Vec::new();
    let mut users: TextureUsers = BTreeMap::new();
    for (i, m) in doc.materials().enumerate() {
        let name = m
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("material{i}"));
        let pbr = m.pbr_metallic_roughness();
        let mut req = MaterialTextures::default();
        // A texture's source: its image, or for a DDS-only data texture the image beside it.
        let source = |tex: usize, kind: TexKind, what: &str, warnings: &mut Warnings| -> Option<TexSource> {
            if !sources.sourceless.contains(&tex) {
                return doc
                    .textures()
                    .nth(tex)
                    .map(|t| TexSource::Image(t.source().index()));
            }
            let sibling = (kind == TexKind::Data)
                .then(|| sources.dds_uris.get(&tex).and_then(|u| dds_sibling(base_dir, u)))
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
            req.base = source(info.texture().index(), TexKind::Color, "base colour", warnings)
                .map(|src| (src, tex_coord(&info)));
        }
        if let Some(info) = pbr.metallic_roughness_texture() {
            let src = source(
                info.texture().index(),
                TexKind::Data,
                "metallic-roughness",
                warnings,
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
                    source(tex as usize, TexKind::Data, what, warnings)
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
    (requests, users)
}

/// The materials, and per material the UV set its vertices carry and the KHR_texture_transform
/// applied to them.
pub(super) struct Materials {
    pub(super) materials: Vec<Material>,
    pub(super) uv_set: Vec<u32>,
    pub(super) uv_transform: Vec<Option<Mat3>>,
    /// Some texture reads through a KHR_texture_transform.
    pub(super) used_transform: bool,
}

pub(super) fn build_materials(
    doc: &gltf::Document,
    requests: Vec<MaterialTextures>,
    texture_of: &HashMap<(TexSource, TexKind), Option<usize>>,
    warnings: &mut Warnings,
) -> Materials {
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
    Materials {
        materials,
        uv_set: material_uv_set,
        uv_transform: material_uv_transform,
        used_transform,
    }
}

//! The node hierarchy's walk ([`Walk`]): meshes (instanced, Draco or plain), cameras and
//! KHR_lights_punctual lights in world space; the load summary's counts.

use super::*;

/// The node hierarchy's walk: meshes (instanced), cameras and lights in world space.
pub(super) struct Walk<'a> {
    pub(super) doc: &'a gltf::Document,
    pub(super) buffers: &'a Buffers,
    pub(super) path: &'a Path,
    pub(super) materials: Materials,
    /// The material made for primitives without one (on first use).
    pub(super) default_material: Option<u32>,
    pub(super) scene: Scene,
    pub(super) stats: GeomStats,
    /// Cameras with the file's far plane, completed when the scene's bounds are known.
    pub(super) cameras: Vec<(Camera, Option<f32>)>,
    pub(super) warnings: Warnings,
}

impl Walk<'_> {
    /// Every node reachable from the scene's roots (each once), parents before children.
    pub(super) fn nodes(&mut self) -> Result<(), SceneError> {
        let doc = self.doc;
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

        let mut visited = vec![false; doc.nodes().len()];
        let mut stack: Vec<(gltf::Node, Mat4)> =
            roots.into_iter().rev().map(|n| (n, Mat4::IDENTITY)).collect();
        let json = doc.as_json();
        while let Some((node, parent)) = stack.pop() {
            if std::mem::replace(&mut visited[node.index()], true) {
                self.warnings.push(format!(
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
                self.mesh(&node, &mesh, &world)?;
            }
            let node_json = json.nodes.get(node.index());
            self.camera(&node, node_json, &world);
            self.light(&node, node_json, &world)?;
        }
        Ok(())
    }

    /// A node's mesh: each triangle primitive read (Draco or plain), its UVs transformed, once
    /// per EXT_mesh_gpu_instancing instance.
    pub(super) fn mesh(
        &mut self,
        node: &gltf::Node,
        mesh: &gltf::Mesh,
        world: &Mat4,
    ) -> Result<(), SceneError> {
        let world = *world;
        // EXT_mesh_gpu_instancing: the mesh once per instance (each instance's TRS after
        // the node's transform), else once.
        let instances = match node.extension_value("EXT_mesh_gpu_instancing") {
            Some(ext) => match instance_transforms(self.doc, ext, self.buffers) {
                Ok(v) => {
                    self.stats.instanced_nodes += 1;
                    self.stats.instances += v.len();
                    v
                }
                Err(e) => {
                    self.warnings.push(format!(
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
                *self
                    .stats
                    .skipped_modes
                    .entry(format!("{:?}", prim.mode()))
                    .or_insert(0) += 1;
                continue;
            }
            let mat = match prim.material().index() {
                Some(m) => m as u32,
                None => {
                    let materials = &mut self.materials;
                    *self.default_material.get_or_insert_with(|| {
                        materials.materials.push(Material::default());
                        materials.uv_set.push(0);
                        materials.uv_transform.push(None);
                        (materials.materials.len() - 1) as u32
                    })
                }
            };
            let uv_set = self.materials.uv_set.get(mat as usize).copied().unwrap_or(0);
            let label = format!(
                "mesh {} ('{}') primitive {pi}",
                mesh.index(),
                mesh.name().unwrap_or("")
            );
            let draco = prim.extension_value("KHR_draco_mesh_compression");
            let read = match draco {
                Some(ext) => {
                    let r = read_draco_primitive(self.doc, &prim, ext, self.buffers, uv_set);
                    self.stats.draco += r.is_ok() as usize;
                    r
                }
                None => read_primitive(&prim, self.buffers, uv_set),
            };
            match read {
                Ok((mut data, uv_missing)) => {
                    if uv_missing {
                        self.stats.uv_missing.insert(label.clone());
                    }
                    if let (Some(t), Some(uvs)) = (
                        self.materials.uv_transform.get(mat as usize).copied().flatten(),
                        data.uvs.as_mut(),
                    ) {
                        for uv in uvs.iter_mut() {
                            *uv = t.transform_point2(*uv);
                        }
                    }
                    // Instancing multiplies the geometry: a budget keeps a small file from
                    // asking for more vertices than the u32 indices address.
                    let adds = data.positions.len().saturating_mul(instances.len());
                    if self.scene.positions.len().saturating_add(adds) > MAX_VERTICES {
                        return Err(invalid_gltf(
                            self.path,
                            format!(
                                "{label} with {} instance(s) would make the scene more than {MAX_VERTICES} vertices",
                                instances.len()
                            ),
                        ));
                    }
                    for inst in &instances {
                        append_primitive(&mut self.scene, &data, &(world * *inst), mat, &mut self.stats);
                    }
                }
                Err(e) => self.warnings.push(format!("{label} skipped: {e}")),
            }
        }
        Ok(())
    }

    /// A node's perspective camera (others are skipped with a warning).
    pub(super) fn camera(&mut self, node: &gltf::Node, node_json: Option<&gltf::json::Node>, world: &Mat4) {
        let doc = self.doc;
        let (json, world) = (doc.as_json(), *world);
        if let Some(ci) = node_json.and_then(|n| n.camera).map(|c| c.value()) {
            match json.cameras.get(ci) {
                Some(cam) => match (cam.type_, cam.perspective.as_ref()) {
                    (Checked::Valid(CameraType::Perspective), Some(p)) => {
                        let name = cam
                            .name
                            .clone()
                            .or_else(|| node.name().map(str::to_string))
                            .unwrap_or_else(|| format!("camera{ci}"));
                        let c = make_camera(&name, &world, p.yfov, p.znear, &mut self.warnings);
                        self.cameras.push((c, p.zfar));
                    }
                    _ => self.warnings.push(format!(
                        "camera {ci} ('{}') is not a perspective camera; skipped",
                        cam.name.as_deref().unwrap_or("")
                    )),
                },
                None => self
                    .warnings
                    .push(format!("node {} references missing camera {ci}", node.index())),
            }
        }
    }

    /// A node's KHR_lights_punctual light: directional lights in world space; a negative or
    /// non-finite intensity or colour is an error; other kinds are counted and skipped.
    pub(super) fn light(
        &mut self,
        node: &gltf::Node,
        node_json: Option<&gltf::json::Node>,
        world: &Mat4,
    ) -> Result<(), SceneError> {
        let doc = self.doc;
        let (json, world) = (doc.as_json(), *world);
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
                            return Err(invalid_gltf(
                                self.path,
                                format!(
                                    "directional light '{name}' has intensity {} W/m^2 and colour {:?}: both must be finite and >= 0",
                                    l.intensity, l.color
                                ),
                            ));
                        }
                        if dir.is_finite() && dir.length_squared() > 0.0 {
                            self.scene.lights.push(DirectionalLight {
                                name,
                                direction: dir.normalize(),
                                irradiance: l.intensity * color,
                            });
                        } else {
                            self.warnings.push(format!(
                                "directional light '{name}' has a degenerate direction (a zero-scale node?); skipped"
                            ));
                        }
                    }
                    Checked::Valid(t) => {
                        *self.stats.skipped_lights.entry(format!("{t:?}")).or_insert(0) += 1;
                    }
                    Checked::Invalid => self
                        .warnings
                        .push(format!("light {li} has an invalid type; skipped")),
                },
                None => self
                    .warnings
                    .push(format!("node {} references missing light {li}", node.index())),
            }
        }
        Ok(())
    }
}

impl GeomStats {
    /// The load summary's extension lines (`info`) and one warning per kind of thing skipped or
    /// dropped.
    pub(super) fn summarise(
        &self,
        doc: &gltf::Document,
        used_transform: bool,
        info: &mut Vec<String>,
        warnings: &mut Warnings,
    ) {
        // What was decoded (the load summary's extension lines).
        if self.draco > 0 {
            info.push(format!(
                "KHR_draco_mesh_compression: {} primitive(s) decoded (draco-core)",
                self.draco
            ));
        }
        if self.instanced_nodes > 0 {
            info.push(format!(
                "EXT_mesh_gpu_instancing: {} instance(s) of {} node(s) expanded",
                self.instances, self.instanced_nodes
            ));
        }
        if doc.extensions_used().any(|e| e == "KHR_mesh_quantization") {
            info.push("KHR_mesh_quantization: quantised attributes dequantised".into());
        }
        if used_transform {
            info.push("KHR_texture_transform: applied to the UVs of the transformed textures' sets".into());
        }

        // Summaries of skipped/dropped things, one warning each.
        for (mode, n) in &self.skipped_modes {
            warnings.push(format!(
                "{n} primitive(s) with mode {mode} skipped: only triangle lists are supported"
            ));
        }
        for (kind, n) in &self.skipped_lights {
            warnings.push(format!(
                "{n} {kind} light(s) skipped: only directional lights are supported"
            ));
        }
        if self.non_finite > 0 {
            warnings.push(format!(
                "{} triangle(s) with non-finite (NaN/inf) vertex positions dropped",
                self.non_finite
            ));
        }
        if self.degenerate > 0 {
            warnings.push(format!("{} zero-area triangle(s) dropped", self.degenerate));
        }
        if self.bad_index > 0 {
            warnings.push(format!(
                "{} triangle(s) with out-of-range vertex indices dropped",
                self.bad_index
            ));
        }
        if !self.uv_missing.is_empty() {
            let list: Vec<&str> = self.uv_missing.iter().map(String::as_str).take(5).collect();
            warnings.push(format!(
                "{} textured primitive(s) lack the TEXCOORD set their material uses; zero UVs used (e.g. {})",
                self.uv_missing.len(),
                list.join(", ")
            ));
        }
    }
}

//! Kernels: a WGSL file's bind-group layouts reflected from its naga module, and bind groups
//! made by WGSL variable name.
//!
//! A pass used to write each binding three times by number: `@binding(n)` in WGSL, a layout
//! entry, and a bind-group entry. Here the shader is the one declaration: [`Kernel::new`]
//! parses and validates the (preprocessed) file, walks the global variables that its entry
//! points use, and makes one `wgpu::BindGroupLayout` per `@group` (the union over the entry
//! points it was made for, so every pipeline of the kernel shares them). [`Kernel::bind`] takes
//! `(variable name, resource)` pairs and checks, before wgpu sees them, that every name is a
//! variable of that group, that each is given once, that none is missing, and that a buffer
//! goes to a buffer, a texture view to a texture and a sampler to a sampler: a renamed or
//! reordered WGSL binding cannot bind the wrong resource silently. (Falcor binds by name;
//! kajiya reflects its layouts from SPIR-V.)
//!
//! What WGSL does not say is fixed by rule: float textures are filterable exactly when the
//! entry points use a filtering `sampler`; uniforms named in [`KernelOptions::dynamic`] take a
//! dynamic offset and the struct's WGSL size as their minimum binding size. On CPU adapters the
//! layouts read uniforms as read-only storage ([`super::passes::bind_group_layout`]), as the
//! module's text does ([`super::shaders::module_from_text`]).

use std::collections::{BTreeMap, BTreeSet};

use super::shaders::{self, ShaderError};

/// One `@group(g) @binding(b) var name` of a kernel: its layout entry and its name.
#[derive(Clone, Debug, PartialEq)]
pub struct Slot {
    pub name: String,
    pub entry: wgpu::BindGroupLayoutEntry,
}

/// What a WGSL declaration leaves open.
#[derive(Clone, Copy, Debug, Default)]
pub struct KernelOptions<'a> {
    /// Uniform variables bound with a dynamic offset (one buffer holding many parameter
    /// blocks, [`super::passes::StridedUniforms`]).
    pub dynamic: &'a [&'a str],
}

/// The slots of each group used by `entries` (every entry point of the module when empty),
/// sorted by binding; visibility is the union of the stages of the entry points that use a
/// variable.
pub fn reflect(
    file: &str,
    module: &naga::Module,
    info: &naga::valid::ModuleInfo,
    entries: &[&str],
    options: &KernelOptions<'_>,
) -> Result<BTreeMap<u32, Vec<Slot>>, String> {
    for e in entries {
        if !module.entry_points.iter().any(|ep| ep.name == *e) {
            return Err(format!("{file} has no entry point '{e}'"));
        }
    }
    for d in options.dynamic {
        let found = module
            .global_variables
            .iter()
            .any(|(_, v)| v.name.as_deref() == Some(*d) && v.space == naga::AddressSpace::Uniform);
        if !found {
            return Err(format!(
                "{file} has no uniform variable '{d}' to bind with a dynamic offset"
            ));
        }
    }
    let chosen = |name: &str| entries.is_empty() || entries.contains(&name);
    // Float textures are filterable when the entry points sample with a filtering sampler.
    let filtering = module.entry_points.iter().enumerate().any(|(i, ep)| {
        chosen(&ep.name)
            && module.global_variables.iter().any(|(h, v)| {
                v.binding.is_some()
                    && !info.get_entry_point(i)[h].is_empty()
                    && matches!(
                        module.types[v.ty].inner,
                        naga::TypeInner::Sampler { comparison: false }
                    )
            })
    });
    let mut groups: BTreeMap<u32, Vec<Slot>> = BTreeMap::new();
    for (i, ep) in module.entry_points.iter().enumerate() {
        if !chosen(&ep.name) {
            continue;
        }
        let stage = match ep.stage {
            naga::ShaderStage::Vertex => wgpu::ShaderStages::VERTEX,
            naga::ShaderStage::Fragment => wgpu::ShaderStages::FRAGMENT,
            naga::ShaderStage::Compute => wgpu::ShaderStages::COMPUTE,
            other => return Err(format!("{file}::{}: stage {other:?} is not used here", ep.name)),
        };
        let uses = info.get_entry_point(i);
        for (handle, var) in module.global_variables.iter() {
            let Some(rb) = &var.binding else { continue };
            if uses[handle].is_empty() {
                continue;
            }
            let name = var
                .name
                .clone()
                .ok_or_else(|| format!("{file}: binding {} of group {} has no name", rb.binding, rb.group))?;
            let slots = groups.entry(rb.group).or_default();
            if let Some(s) = slots.iter_mut().find(|s| s.entry.binding == rb.binding) {
                if s.name != name {
                    return Err(format!(
                        "@group({}) @binding({}) is both '{}' and '{name}' in the entry points asked for",
                        rb.group, rb.binding, s.name
                    ));
                }
                s.entry.visibility |= stage;
                continue;
            }
            let dynamic = options.dynamic.contains(&name.as_str());
            let ty = binding_type(module, var, filtering, dynamic)
                .map_err(|e| format!("{file}: variable '{name}': {e}"))?;
            slots.push(Slot {
                name,
                entry: wgpu::BindGroupLayoutEntry {
                    binding: rb.binding,
                    visibility: stage,
                    ty,
                    count: None,
                },
            });
        }
    }
    for slots in groups.values_mut() {
        slots.sort_by_key(|s| s.entry.binding);
    }
    Ok(groups)
}

fn binding_type(
    module: &naga::Module,
    var: &naga::GlobalVariable,
    filtering: bool,
    dynamic: bool,
) -> Result<wgpu::BindingType, String> {
    let inner = &module.types[var.ty].inner;
    Ok(match var.space {
        naga::AddressSpace::Uniform => wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: dynamic,
            min_binding_size: if dynamic {
                wgpu::BufferSize::new(inner.size(module.to_ctx()) as u64)
            } else {
                None
            },
        },
        naga::AddressSpace::Storage { access } => wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage {
                read_only: !access.contains(naga::StorageAccess::STORE),
            },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        naga::AddressSpace::Handle => match inner {
            naga::TypeInner::Sampler { comparison } => wgpu::BindingType::Sampler(if *comparison {
                wgpu::SamplerBindingType::Comparison
            } else {
                wgpu::SamplerBindingType::Filtering
            }),
            naga::TypeInner::Image { dim, arrayed, class } => {
                let view_dimension = view_dimension(*dim, *arrayed)?;
                match class {
                    naga::ImageClass::Sampled { kind, multi } => wgpu::BindingType::Texture {
                        sample_type: match kind {
                            naga::ScalarKind::Float => wgpu::TextureSampleType::Float {
                                filterable: filtering,
                            },
                            naga::ScalarKind::Uint => wgpu::TextureSampleType::Uint,
                            naga::ScalarKind::Sint => wgpu::TextureSampleType::Sint,
                            k => return Err(format!("sampled texture of {k:?}")),
                        },
                        view_dimension,
                        multisampled: *multi,
                    },
                    naga::ImageClass::Depth { multi } => wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension,
                        multisampled: *multi,
                    },
                    naga::ImageClass::Storage { format, access } => wgpu::BindingType::StorageTexture {
                        access: match (
                            access.contains(naga::StorageAccess::LOAD),
                            access.contains(naga::StorageAccess::STORE),
                        ) {
                            (true, true) => wgpu::StorageTextureAccess::ReadWrite,
                            (true, false) => wgpu::StorageTextureAccess::ReadOnly,
                            _ => wgpu::StorageTextureAccess::WriteOnly,
                        },
                        format: storage_format(*format)?,
                        view_dimension,
                    },
                    naga::ImageClass::External => return Err("external textures are not used here".into()),
                }
            }
            other => return Err(format!("unsupported handle type {other:?}")),
        },
        other => return Err(format!("address space {other:?} cannot be bound")),
    })
}

fn view_dimension(dim: naga::ImageDimension, arrayed: bool) -> Result<wgpu::TextureViewDimension, String> {
    use wgpu::TextureViewDimension as D;
    Ok(match (dim, arrayed) {
        (naga::ImageDimension::D1, false) => D::D1,
        (naga::ImageDimension::D2, false) => D::D2,
        (naga::ImageDimension::D2, true) => D::D2Array,
        (naga::ImageDimension::D3, false) => D::D3,
        (naga::ImageDimension::Cube, false) => D::Cube,
        (naga::ImageDimension::Cube, true) => D::CubeArray,
        (d, a) => return Err(format!("texture dimension {d:?} (arrayed {a})")),
    })
}

fn storage_format(f: naga::StorageFormat) -> Result<wgpu::TextureFormat, String> {
    use naga::StorageFormat as S;
    use wgpu::TextureFormat as T;
    Ok(match f {
        S::R8Unorm => T::R8Unorm,
        S::R8Snorm => T::R8Snorm,
        S::R8Uint => T::R8Uint,
        S::R8Sint => T::R8Sint,
        S::R16Uint => T::R16Uint,
        S::R16Sint => T::R16Sint,
        S::R16Float => T::R16Float,
        S::Rg8Unorm => T::Rg8Unorm,
        S::Rg8Snorm => T::Rg8Snorm,
        S::Rg8Uint => T::Rg8Uint,
        S::Rg8Sint => T::Rg8Sint,
        S::R32Uint => T::R32Uint,
        S::R32Sint => T::R32Sint,
        S::R32Float => T::R32Float,
        S::Rg16Uint => T::Rg16Uint,
        S::Rg16Sint => T::Rg16Sint,
        S::Rg16Float => T::Rg16Float,
        S::Rgba8Unorm => T::Rgba8Unorm,
        S::Rgba8Snorm => T::Rgba8Snorm,
        S::Rgba8Uint => T::Rgba8Uint,
        S::Rgba8Sint => T::Rgba8Sint,
        S::Bgra8Unorm => T::Bgra8Unorm,
        S::Rgb10a2Uint => T::Rgb10a2Uint,
        S::Rgb10a2Unorm => T::Rgb10a2Unorm,
        S::Rg11b10Ufloat => T::Rg11b10Ufloat,
        S::Rg32Uint => T::Rg32Uint,
        S::Rg32Sint => T::Rg32Sint,
        S::Rg32Float => T::Rg32Float,
        S::Rgba16Uint => T::Rgba16Uint,
        S::Rgba16Sint => T::Rgba16Sint,
        S::Rgba16Float => T::Rgba16Float,
        S::Rgba32Uint => T::Rgba32Uint,
        S::Rgba32Sint => T::Rgba32Sint,
        S::Rgba32Float => T::Rgba32Float,
        other => return Err(format!("storage format {other:?} is not mapped")),
    })
}

/// One group's layout and the names of its variables.
pub struct GroupLayout {
    pub layout: wgpu::BindGroupLayout,
    pub slots: Vec<Slot>,
}

/// A WGSL file made into a shader module once, with the layouts of its groups reflected for a
/// set of entry points (see the module docs).
pub struct Kernel {
    file: String,
    /// The file's stem, the first part of the labels (`stem::group0`): GPU errors name it.
    stem: String,
    pub module: wgpu::ShaderModule,
    groups: BTreeMap<u32, GroupLayout>,
    /// Per entry point, the groups it uses (its pipeline layout holds those, `None` between).
    used_groups: BTreeMap<String, BTreeSet<u32>>,
}

impl Kernel {
    /// Loads `file` (preprocessed and validated) and reflects the layouts of the groups that
    /// `entries` use (every entry point of the file when empty).
    pub fn new(
        device: &wgpu::Device,
        file: &str,
        entries: &[&str],
        options: KernelOptions<'_>,
    ) -> Result<Self, ShaderError> {
        let text = shaders::preprocessed(file)?;
        let (naga_module, info) = shaders::parse_validated(file, &text)?;
        let module = shaders::module_from_text(device, file, text);
        Self::from_parsed(device, file, module, &naga_module, &info, entries, &options)
    }

    /// One kernel per entry point of `file`, sharing one parse and one shader module: for a
    /// file whose entry points bind different variables at the same slots, or different
    /// parts of one group (each kernel's layouts are its entry point's alone).
    pub fn per_entry(
        device: &wgpu::Device,
        file: &str,
        entries: &[&str],
        options: KernelOptions<'_>,
    ) -> Result<Vec<Self>, ShaderError> {
        let text = shaders::preprocessed(file)?;
        let (naga_module, info) = shaders::parse_validated(file, &text)?;
        let module = shaders::module_from_text(device, file, text);
        entries
            .iter()
            .map(|e| Self::from_parsed(device, file, module.clone(), &naga_module, &info, &[e], &options))
            .collect()
    }

    fn from_parsed(
        device: &wgpu::Device,
        file: &str,
        module: wgpu::ShaderModule,
        naga_module: &naga::Module,
        info: &naga::valid::ModuleInfo,
        entries: &[&str],
        options: &KernelOptions<'_>,
    ) -> Result<Self, ShaderError> {
        let reflected =
            reflect(file, naga_module, info, entries, options).map_err(|message| ShaderError::Parse {
                file: file.to_string(),
                message,
            })?;
        let stem = file.trim_end_matches(".wgsl").rsplit('/').next().unwrap_or(file);
        let groups = reflected
            .into_iter()
            .map(|(g, slots)| {
                let entries: Vec<wgpu::BindGroupLayoutEntry> = slots.iter().map(|s| s.entry).collect();
                let label = format!("{stem}::group{g}");
                let layout = super::passes::bind_group_layout(
                    device,
                    &wgpu::BindGroupLayoutDescriptor {
                        label: Some(&label),
                        entries: &entries,
                    },
                );
                (g, GroupLayout { layout, slots })
            })
            .collect();
        let mut used_groups = BTreeMap::new();
        for (i, ep) in naga_module.entry_points.iter().enumerate() {
            if !entries.is_empty() && !entries.contains(&ep.name.as_str()) {
                continue;
            }
            let uses = info.get_entry_point(i);
            let used: BTreeSet<u32> = naga_module
                .global_variables
                .iter()
                .filter(|(h, _)| !uses[*h].is_empty())
                .filter_map(|(_, v)| v.binding.as_ref().map(|b| b.group))
                .collect();
            used_groups.insert(ep.name.clone(), used);
        }
        Ok(Self {
            file: file.to_string(),
            stem: stem.to_string(),
            module,
            groups,
            used_groups,
        })
    }

    /// The layout of `group` (panics when no entry point of the kernel uses the group: a
    /// programming error the first run finds).
    pub fn group(&self, group: u32) -> &GroupLayout {
        self.groups.get(&group).unwrap_or_else(|| {
            panic!(
                "{}: no entry point of this kernel uses @group({group})",
                self.file
            )
        })
    }

    /// The pipeline layout for the entry points of one pipeline (a compute entry, or a
    /// vertex and a fragment entry): the groups they use, `None` for a group below the
    /// highest that none of them uses (a dispatch need not bind it).
    pub fn pipeline_layout(&self, device: &wgpu::Device, entries: &[&str]) -> wgpu::PipelineLayout {
        let mut used = BTreeSet::new();
        for e in entries {
            let u = self
                .used_groups
                .get(*e)
                .unwrap_or_else(|| panic!("{}: '{e}' is not an entry point of this kernel", self.file));
            used.extend(u.iter().copied());
        }
        let last = used.iter().next_back().copied();
        let layouts: Vec<Option<&wgpu::BindGroupLayout>> = match last {
            None => Vec::new(),
            Some(last) => (0..=last)
                .map(|g| {
                    if used.contains(&g) {
                        self.groups.get(&g).map(|l| &l.layout)
                    } else {
                        None
                    }
                })
                .collect(),
        };
        let label = format!("{}::{}", self.stem, entries.join("+"));
        device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(&label),
            bind_group_layouts: &layouts,
            immediate_size: 0,
        })
    }

    /// The compute pipeline of `entry`.
    pub fn compute(&self, device: &wgpu::Device, label: &str, entry: &str) -> wgpu::ComputePipeline {
        self.compute_with(device, label, entry, &[])
    }

    /// [`Kernel::compute`] with values of the shader's pipeline-overridable constants.
    pub fn compute_with(
        &self,
        device: &wgpu::Device,
        label: &str,
        entry: &str,
        constants: &[(&str, f64)],
    ) -> wgpu::ComputePipeline {
        let layout = self.pipeline_layout(device, &[entry]);
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: Some(&layout),
            module: &self.module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants,
                ..Default::default()
            },
            cache: None,
        })
    }

    /// A bind group of `group` from `(WGSL variable name, resource)` pairs, checked against
    /// the reflected slots (see the module docs); panics with the kernel, group and name on a
    /// mismatch (a programming error, found by the first frame that records the pass).
    pub fn bind(
        &self,
        device: &wgpu::Device,
        group: u32,
        resources: &[(&str, wgpu::BindingResource<'_>)],
    ) -> wgpu::BindGroup {
        let layout = self.group(group);
        let entries = match check_bindings(&layout.slots, resources) {
            Ok(e) => e,
            Err(e) => panic!("{} @group({group}): {e}", self.file),
        };
        let label = format!("{}::bind{group}", self.stem);
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(&label),
            layout: &layout.layout,
            entries: &entries,
        })
    }
}

impl Kernel {
    /// A bind group of `group` whose slots take their resources from `table` by name: for
    /// kernels that each read a part of one table (Lightcuts' two tree builds, the temporal
    /// stage's entry points). Names of the table that the group lacks are skipped; a slot
    /// missing from the table panics as in [`Kernel::bind`].
    pub fn bind_table(
        &self,
        device: &wgpu::Device,
        group: u32,
        table: &[(&str, wgpu::BindingResource<'_>)],
    ) -> wgpu::BindGroup {
        let layout = self.group(group);
        let picked: Vec<(&str, wgpu::BindingResource<'_>)> = table
            .iter()
            .filter(|(n, _)| layout.slots.iter().any(|s| s.name == *n))
            .map(|(n, r)| (*n, r.clone()))
            .collect();
        self.bind(device, group, &picked)
    }

    /// [`Kernel::bind_table`], or `None` when a slot's name is not in the table (a pass whose
    /// optional inputs decide whether it runs).
    pub fn bind_from(
        &self,
        device: &wgpu::Device,
        group: u32,
        table: &[(&str, wgpu::BindingResource<'_>)],
    ) -> Option<wgpu::BindGroup> {
        let layout = self.group(group);
        let complete = layout
            .slots
            .iter()
            .all(|s| table.iter().any(|(n, _)| *n == s.name));
        complete.then(|| self.bind_table(device, group, table))
    }
}

/// Matches `resources` to `slots` by name: each slot once, no unknown name, the resource of
/// the slot's kind.
pub fn check_bindings<'a>(
    slots: &[Slot],
    resources: &[(&str, wgpu::BindingResource<'a>)],
) -> Result<Vec<wgpu::BindGroupEntry<'a>>, String> {
    let names = || {
        slots
            .iter()
            .map(|s| s.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut entries = Vec::with_capacity(resources.len());
    for (i, (name, res)) in resources.iter().enumerate() {
        if resources[..i].iter().any(|(n, _)| n == name) {
            return Err(format!("'{name}' is given twice"));
        }
        let slot = slots
            .iter()
            .find(|s| s.name == *name)
            .ok_or_else(|| format!("no variable '{name}' (its variables: {})", names()))?;
        let fits = matches!(
            (&slot.entry.ty, res),
            (
                wgpu::BindingType::Buffer { .. },
                wgpu::BindingResource::Buffer(_) | wgpu::BindingResource::BufferArray(_),
            ) | (
                wgpu::BindingType::Texture { .. } | wgpu::BindingType::StorageTexture { .. },
                wgpu::BindingResource::TextureView(_) | wgpu::BindingResource::TextureViewArray(_),
            ) | (
                wgpu::BindingType::Sampler(_),
                wgpu::BindingResource::Sampler(_) | wgpu::BindingResource::SamplerArray(_),
            )
        );
        if !fits {
            return Err(format!(
                "'{name}' is a {:?} and was given another kind of resource",
                slot.entry.ty
            ));
        }
        entries.push(wgpu::BindGroupEntry {
            binding: slot.entry.binding,
            resource: res.clone(),
        });
    }
    let missing: Vec<&str> = slots
        .iter()
        .filter(|s| !resources.iter().any(|(n, _)| *n == s.name))
        .map(|s| s.name.as_str())
        .collect();
    if !missing.is_empty() {
        return Err(format!("not given: {}", missing.join(", ")));
    }
    Ok(entries)
}

/// The whole buffer as a binding resource (short for `as_entire_binding`).
pub fn buf(b: &wgpu::Buffer) -> wgpu::BindingResource<'_> {
    b.as_entire_binding()
}

/// A texture view as a binding resource.
pub fn tex(v: &wgpu::TextureView) -> wgpu::BindingResource<'_> {
    wgpu::BindingResource::TextureView(v)
}

/// A sampler as a binding resource.
pub fn sampler(s: &wgpu::Sampler) -> wgpu::BindingResource<'_> {
    wgpu::BindingResource::Sampler(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reflect_text(
        text: &str,
        entries: &[&str],
        dynamic: &[&str],
    ) -> Result<BTreeMap<u32, Vec<Slot>>, String> {
        let (m, info) = shaders::parse_validated("t.wgsl", text).map_err(|e| e.to_string())?;
        reflect("t.wgsl", &m, &info, entries, &KernelOptions { dynamic })
    }

    const TEXT: &str = r#"
struct P { a: vec4<f32>, b: u32 }
@group(0) @binding(0) var<uniform> p: P;
@group(0) @binding(3) var<storage, read> src: array<u32>;
@group(0) @binding(2) var<storage, read_write> dst: array<u32>;
@group(0) @binding(4) var img: texture_2d<f32>;
@group(0) @binding(5) var out: texture_storage_2d<rgba32float, write>;
@group(0) @binding(6) var depth: texture_depth_2d_array;
@group(1) @binding(0) var<uniform> level: P;
@compute @workgroup_size(8, 8, 1) fn one(@builtin(global_invocation_id) id: vec3<u32>) {
    dst[id.x] = src[id.x] + p.b + u32(textureLoad(img, id.xy, 0).x) + u32(textureLoad(depth, id.xy, 0, 0));
    textureStore(out, id.xy, vec4<f32>(0.0));
}
@compute @workgroup_size(64, 1, 1) fn two(@builtin(global_invocation_id) id: vec3<u32>) {
    dst[id.x] = level.b;
}
"#;

    #[test]
    fn slots_are_reflected_by_name_type_and_use() {
        let g = reflect_text(TEXT, &["one"], &[]).unwrap();
        assert_eq!(g.len(), 1, "entry 'one' uses group 0 only");
        let names: Vec<&str> = g[&0].iter().map(|s| s.name.as_str()).collect();
        assert_eq!(
            names,
            ["p", "dst", "src", "img", "out", "depth"],
            "sorted by binding"
        );
        let ty = |n: &str| g[&0].iter().find(|s| s.name == n).unwrap().entry.ty;
        assert!(matches!(
            ty("p"),
            wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                ..
            }
        ));
        assert!(matches!(
            ty("src"),
            wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                ..
            }
        ));
        assert!(matches!(
            ty("dst"),
            wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: false },
                ..
            }
        ));
        assert_eq!(
            ty("img"),
            wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false
            }
        );
        assert_eq!(
            ty("out"),
            wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format: wgpu::TextureFormat::Rgba32Float,
                view_dimension: wgpu::TextureViewDimension::D2
            }
        );
        assert_eq!(
            ty("depth"),
            wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Depth,
                view_dimension: wgpu::TextureViewDimension::D2Array,
                multisampled: false
            }
        );
        // Both entries: the union, group 1 with a dynamic offset and the struct's size.
        let g = reflect_text(TEXT, &[], &["level"]).unwrap();
        assert_eq!(g[&0].len(), 6);
        assert_eq!(
            g[&1][0].entry.ty,
            wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: true,
                min_binding_size: wgpu::BufferSize::new(32)
            }
        );
        assert!(
            reflect_text(TEXT, &["three"], &[])
                .unwrap_err()
                .contains("no entry point 'three'")
        );
        assert!(
            reflect_text(TEXT, &[], &["src"])
                .unwrap_err()
                .contains("no uniform variable 'src'")
        );
    }

    #[test]
    fn a_filtering_sampler_makes_float_textures_filterable() {
        let text = r#"
@group(0) @binding(0) var t: texture_2d<f32>;
@group(0) @binding(1) var s: sampler;
@fragment fn fs() -> @location(0) vec4<f32> { return textureSample(t, s, vec2<f32>(0.5)); }
"#;
        let g = reflect_text(text, &[], &[]).unwrap();
        assert_eq!(
            g[&0][0].entry.ty,
            wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false
            }
        );
        assert_eq!(g[&0][0].entry.visibility, wgpu::ShaderStages::FRAGMENT);
        assert_eq!(
            g[&0][1].entry.ty,
            wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering)
        );
    }

    /// Every shader of the table reflects: every type it binds has a layout entry.
    #[test]
    fn every_shader_reflects() {
        for file in shaders::entry_shaders() {
            let text = shaders::preprocess(&shaders::Embedded, file).unwrap();
            let (m, info) = shaders::parse_validated(file, &text).unwrap();
            let groups =
                reflect(file, &m, &info, &[], &KernelOptions::default()).unwrap_or_else(|e| panic!("{e}"));
            assert!(!groups.is_empty() || m.global_variables.iter().all(|(_, v)| v.binding.is_none()));
        }
    }

    #[test]
    fn bindings_are_checked_by_name_and_kind() {
        let g = reflect_text(TEXT, &["two"], &[]).unwrap();
        let slots = &g[&0];
        assert_eq!(slots.iter().map(|s| s.name.as_str()).collect::<Vec<_>>(), ["dst"]);
        // Without a device: the error that needs no resource; names, kinds and duplicates
        // are checked with a device in tests/kernel_bindings.rs.
        let e = check_bindings(slots, &[]).unwrap_err();
        assert_eq!(e, "not given: dst");
    }
}

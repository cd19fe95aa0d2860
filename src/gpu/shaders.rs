//! WGSL sources and the one small include mechanism that joins them.
//!
//! A line `#include "common/camera.wgsl"` is replaced by that file's text (resolved
//! recursively, each file at most once per shader, so diamond includes are fine). Sources are
//! embedded in the binary; builds with debug assertions re-read them from `shaders/` on disk
//! when they exist there (hot reload for shader work, see [`ShaderSource::reload_from_disk`]).

use std::collections::HashSet;

use thiserror::Error;

/// The WGSL files of the frame's shared passes and includes, by their path under `shaders/`.
/// Each GI method declares its own files (`Module::shaders`, under
/// `shaders/methods/<method>/`, submitted as [`ShaderTable`]s); [`all_files`] joins the two.
pub const SHADER_FILES: &[(&str, &str)] = &[
    ("common/bvh.wgsl", include_str!("../../shaders/common/bvh.wgsl")),
    (
        "common/bvh_binary.wgsl",
        include_str!("../../shaders/common/bvh_binary.wgsl"),
    ),
    (
        "common/bvh_wide.wgsl",
        include_str!("../../shaders/common/bvh_wide.wgsl"),
    ),
    (
        "common/bvh_triangle.wgsl",
        include_str!("../../shaders/common/bvh_triangle.wgsl"),
    ),
    (
        "common/camera.wgsl",
        include_str!("../../shaders/common/camera.wgsl"),
    ),
    (
        "common/color.wgsl",
        include_str!("../../shaders/common/color.wgsl"),
    ),
    (
        "common/lights.wgsl",
        include_str!("../../shaders/common/lights.wgsl"),
    ),
    (
        "common/material.wgsl",
        include_str!("../../shaders/common/material.wgsl"),
    ),
    (
        "common/random.wgsl",
        include_str!("../../shaders/common/random.wgsl"),
    ),
    ("common/slc.wgsl", include_str!("../../shaders/common/slc.wgsl")),
    (
        "common/surface.wgsl",
        include_str!("../../shaders/common/surface.wgsl"),
    ),
    (
        "common/tree_links.wgsl",
        include_str!("../../shaders/common/tree_links.wgsl"),
    ),
    (
        "common/box_term.wgsl",
        include_str!("../../shaders/common/box_term.wgsl"),
    ),
    (
        "common/slc_half_params.wgsl",
        include_str!("../../shaders/common/slc_half_params.wgsl"),
    ),
    (
        "common/slc_params.wgsl",
        include_str!("../../shaders/common/slc_params.wgsl"),
    ),
    (
        "common/sst_node.wgsl",
        include_str!("../../shaders/common/sst_node.wgsl"),
    ),
    (
        "common/vertex.wgsl",
        include_str!("../../shaders/common/vertex.wgsl"),
    ),
    ("common/math.wgsl", include_str!("../../shaders/common/math.wgsl")),
    (
        "common/stats64.wgsl",
        include_str!("../../shaders/common/stats64.wgsl"),
    ),
    (
        "common/vpl_visibility.wgsl",
        include_str!("../../shaders/common/vpl_visibility.wgsl"),
    ),
    ("common/vpl.wgsl", include_str!("../../shaders/common/vpl.wgsl")),
    (
        "common/rsm_pyramid.wgsl",
        include_str!("../../shaders/common/rsm_pyramid.wgsl"),
    ),
    ("vpl_gen.wgsl", include_str!("../../shaders/vpl_gen.wgsl")),
    ("composite.wgsl", include_str!("../../shaders/composite.wgsl")),
    (
        "gbuffer_overdraw.wgsl",
        include_str!("../../shaders/gbuffer_overdraw.wgsl"),
    ),
    ("vpl_splat.wgsl", include_str!("../../shaders/vpl_splat.wgsl")),
    ("sst_sort.wgsl", include_str!("../../shaders/sst_sort.wgsl")),
    ("sst_build.wgsl", include_str!("../../shaders/sst_build.wgsl")),
    (
        "compare_views.wgsl",
        include_str!("../../shaders/compare_views.wgsl"),
    ),
    ("sst_overlay.wgsl", include_str!("../../shaders/sst_overlay.wgsl")),
    (
        "sst_classify.wgsl",
        include_str!("../../shaders/sst_classify.wgsl"),
    ),
    ("gbuffer.wgsl", include_str!("../../shaders/gbuffer.wgsl")),
    ("rsm.wgsl", include_str!("../../shaders/rsm.wgsl")),
    ("direct.wgsl", include_str!("../../shaders/direct.wgsl")),
    ("display.wgsl", include_str!("../../shaders/display.wgsl")),
    ("visualise.wgsl", include_str!("../../shaders/visualise.wgsl")),
    ("bvh_rays.wgsl", include_str!("../../shaders/bvh_rays.wgsl")),
    (
        "bvh_rays_wide.wgsl",
        include_str!("../../shaders/bvh_rays_wide.wgsl"),
    ),
    (
        "bvh_rays_entries.wgsl",
        include_str!("../../shaders/bvh_rays_entries.wgsl"),
    ),
    (
        "interleave_filter.wgsl",
        include_str!("../../shaders/interleave_filter.wgsl"),
    ),
    ("ism.wgsl", include_str!("../../shaders/ism.wgsl")),
    ("common/ism.wgsl", include_str!("../../shaders/common/ism.wgsl")),
    ("ism_view.wgsl", include_str!("../../shaders/ism_view.wgsl")),
    ("val_cluster.wgsl", include_str!("../../shaders/val_cluster.wgsl")),
    ("temporal.wgsl", include_str!("../../shaders/temporal.wgsl")),
    ("lbvh.wgsl", include_str!("../../shaders/lbvh.wgsl")),
    (
        "surface_rays.wgsl",
        include_str!("../../shaders/surface_rays.wgsl"),
    ),
    (
        "common/sst_merge.wgsl",
        include_str!("../../shaders/common/sst_merge.wgsl"),
    ),
    (
        "common/rsm_warp.wgsl",
        include_str!("../../shaders/common/rsm_warp.wgsl"),
    ),
    ("light_paths.wgsl", include_str!("../../shaders/light_paths.wgsl")),
    ("common/brdf.wgsl", include_str!("../../shaders/common/brdf.wgsl")),
    ("brdf_eval.wgsl", include_str!("../../shaders/brdf_eval.wgsl")),
];

/// The shared shaders that are entry points (not include-only files); [`entry_shaders`] adds
/// the methods'.
pub const ENTRY_SHADERS: &[&str] = &[
    "gbuffer.wgsl",
    "gbuffer_overdraw.wgsl",
    "rsm.wgsl",
    "direct.wgsl",
    "display.wgsl",
    "visualise.wgsl",
    "bvh_rays.wgsl",
    "bvh_rays_wide.wgsl",
    "vpl_gen.wgsl",
    "light_paths.wgsl",
    "brdf_eval.wgsl",
    "composite.wgsl",
    "vpl_splat.wgsl",
    "sst_sort.wgsl",
    "sst_build.wgsl",
    "sst_classify.wgsl",
    "sst_overlay.wgsl",
    "compare_views.wgsl",
    "interleave_filter.wgsl",
    "ism.wgsl",
    "ism_view.wgsl",
    "val_cluster.wgsl",
    "temporal.wgsl",
    "lbvh.wgsl",
    "surface_rays.wgsl",
];

/// A GI method's WGSL files and entry points, submitted by its module
/// (`inventory::submit!` beside its `Module`): the GPU layer finds every method's shaders
/// without naming a method.
pub struct ShaderTable {
    /// (path under `shaders/`, text), embedded.
    pub files: &'static [(&'static str, &'static str)],
    /// Those of the files that are entry points.
    pub entries: &'static [&'static str],
}

inventory::collect!(ShaderTable);

/// Every WGSL file: the shared ones and those the GI methods submit.
pub fn all_files() -> impl Iterator<Item = (&'static str, &'static str)> {
    SHADER_FILES.iter().copied().chain(
        inventory::iter::<ShaderTable>
            .into_iter()
            .flat_map(|t| t.files.iter().copied()),
    )
}

/// Every entry-point shader: the shared ones, then the methods' (sorted; each file once).
pub fn entry_shaders() -> Vec<&'static str> {
    let mut methods: Vec<&'static str> = inventory::iter::<ShaderTable>
        .into_iter()
        .flat_map(|t| t.entries.iter().copied())
        .collect();
    methods.sort_unstable();
    methods.dedup();
    let mut v: Vec<&'static str> = ENTRY_SHADERS.to_vec();
    v.extend(methods);
    v
}

#[derive(Debug, Error, PartialEq)]
pub enum ShaderError {
    #[error("shader '{0}' not found")]
    NotFound(String),
    #[error("{file}:{line}: malformed #include (expected #include \"path\")")]
    BadInclude { file: String, line: usize },
    #[error("WGSL error in {file}: {message}")]
    Parse { file: String, message: String },
}

/// Where shader text comes from: the embedded table, or files on disk for hot reload.
pub trait ShaderSource {
    fn get(&self, name: &str) -> Option<String>;
}

/// The sources compiled into the binary.
pub struct Embedded;

impl ShaderSource for Embedded {
    fn get(&self, name: &str) -> Option<String> {
        all_files().find(|(n, _)| *n == name).map(|(_, s)| s.to_string())
    }
}

/// Reads `shaders/` from the source tree when it exists (debug builds), else the embedded copy.
pub struct ShaderSourceDisk;

impl ShaderSourceDisk {
    fn dir() -> std::path::PathBuf {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders")
    }
    /// True in builds with debug assertions when the source tree is present.
    pub fn reload_from_disk() -> bool {
        cfg!(debug_assertions) && Self::dir().is_dir()
    }
}

impl ShaderSource for ShaderSourceDisk {
    fn get(&self, name: &str) -> Option<String> {
        std::fs::read_to_string(Self::dir().join(name))
            .ok()
            .or_else(|| Embedded.get(name))
    }
}

/// Resolves `#include` lines of `name`, recursively, each file once.
pub fn preprocess(source: &dyn ShaderSource, name: &str) -> Result<String, ShaderError> {
    let mut seen = HashSet::new();
    let mut out = String::new();
    expand(source, name, &mut seen, &mut out)?;
    Ok(out)
}

fn expand(
    source: &dyn ShaderSource,
    name: &str,
    seen: &mut HashSet<String>,
    out: &mut String,
) -> Result<(), ShaderError> {
    if !seen.insert(name.to_string()) {
        return Ok(());
    }
    let text = source
        .get(name)
        .ok_or_else(|| ShaderError::NotFound(name.to_string()))?;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim_start();
        if let Some(rest) = t.strip_prefix("#include") {
            let rest = rest.trim();
            let inc = rest
                .strip_prefix('"')
                .and_then(|r| r.strip_suffix('"'))
                .ok_or_else(|| ShaderError::BadInclude {
                    file: name.to_string(),
                    line: i + 1,
                })?;
            // `common/bvh.wgsl` is the frames' BVH layout (`scene_gpu::BvhLayout`).
            let inc = if inc == "common/bvh.wgsl"
                && super::scene_gpu::frame_bvh_layout() == super::scene_gpu::BvhLayout::Wide
            {
                "common/bvh_wide.wgsl"
            } else {
                inc
            };
            expand(source, inc, seen, out)?;
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    Ok(())
}

/// Preprocesses and validates a shader with naga, returning the WGSL text.
pub fn load_validated(source: &dyn ShaderSource, name: &str) -> Result<String, ShaderError> {
    let text = preprocess(source, name)?;
    validate(name, &text)?;
    Ok(text)
}

/// Parses and validates WGSL with naga (all capabilities: the device decides what it accepts).
pub fn validate(name: &str, text: &str) -> Result<naga::Module, ShaderError> {
    parse_validated(name, text).map(|(module, _)| module)
}

/// [`validate`], keeping naga's analysis (which globals each entry point uses: the kernels'
/// reflection, `kernel::reflect`).
pub fn parse_validated(
    name: &str,
    text: &str,
) -> Result<(naga::Module, naga::valid::ModuleInfo), ShaderError> {
    let module = naga::front::wgsl::parse_str(text).map_err(|e| ShaderError::Parse {
        file: name.to_string(),
        message: e.emit_to_string(text),
    })?;
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| ShaderError::Parse {
        file: name.to_string(),
        message: e.emit_to_string(text),
    })?;
    Ok((module, info))
}

/// The preprocessed text of `name`: from `shaders/` on disk in builds that hot-reload, else
/// the embedded copy.
pub fn preprocessed(name: &str) -> Result<String, ShaderError> {
    if ShaderSourceDisk::reload_from_disk() {
        preprocess(&ShaderSourceDisk, name)
    } else {
        preprocess(&Embedded, name)
    }
}

/// `var<uniform>` declarations read as `var<storage, read>` (the same struct layout).
pub fn uniforms_to_storage(text: &str) -> String {
    text.replace("var<uniform>", "var<storage, read>")
}

/// The wgpu shader module of a preprocessed, validated shader's text.
pub fn module_from_text(device: &wgpu::Device, name: &str, text: String) -> wgpu::ShaderModule {
    // Parameter blocks as read-only storage where the layouts make them so (lavapipe; see
    // `passes::uniforms_as_storage`).
    let text = if super::passes::uniforms_as_storage(device) {
        uniforms_to_storage(&text)
    } else {
        text
    };
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(name),
        source: wgpu::ShaderSource::Wgsl(text.into()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Mem(Vec<(&'static str, &'static str)>);
    impl ShaderSource for Mem {
        fn get(&self, name: &str) -> Option<String> {
            self.0
                .iter()
                .find(|(n, _)| *n == name)
                .map(|(_, s)| s.to_string())
        }
    }

    #[test]
    fn includes_resolve_once_and_recursively() {
        let src = Mem(vec![
            ("a.wgsl", "#include \"b.wgsl\"\n#include \"c.wgsl\"\nfn a() {}"),
            ("b.wgsl", "#include \"c.wgsl\"\nfn b() {}"),
            ("c.wgsl", "fn c() {}"),
        ]);
        let out = preprocess(&src, "a.wgsl").unwrap();
        assert_eq!(out, "fn c() {}\nfn b() {}\nfn a() {}\n");
    }

    #[test]
    fn include_errors_are_reported() {
        let src = Mem(vec![
            ("a.wgsl", "#include b.wgsl"),
            ("m.wgsl", "#include \"x.wgsl\""),
        ]);
        assert_eq!(
            preprocess(&src, "a.wgsl"),
            Err(ShaderError::BadInclude {
                file: "a.wgsl".into(),
                line: 1
            })
        );
        assert_eq!(
            preprocess(&src, "m.wgsl"),
            Err(ShaderError::NotFound("x.wgsl".into()))
        );
    }

    #[test]
    fn every_shader_passes_naga() {
        for name in entry_shaders() {
            if let Err(e) = load_validated(&Embedded, name) {
                panic!("{e}");
            }
        }
    }

    /// The storage rewrite (lavapipe, `passes::uniforms_as_storage`) leaves no uniform
    /// binding behind, validates, and keeps every global at the same group and binding.
    #[test]
    fn every_shader_reads_its_uniforms_as_storage_with_the_same_bindings() {
        for name in entry_shaders() {
            let text = load_validated(&Embedded, name).unwrap();
            let rewritten = uniforms_to_storage(&text);
            assert!(
                !rewritten.contains("uniform>"),
                "{name}: a uniform declaration the rewrite missed"
            );
            let a = validate(name, &text).unwrap();
            let b = validate(name, &rewritten).unwrap_or_else(|e| panic!("{e}"));
            let bindings = |m: &naga::Module| -> Vec<_> {
                m.global_variables
                    .iter()
                    .map(|(_, g)| (g.name.clone(), g.binding, g.ty))
                    .collect()
            };
            assert_eq!(bindings(&a), bindings(&b), "{name}");
            for (_, g) in b.global_variables.iter() {
                assert_ne!(g.space, naga::AddressSpace::Uniform, "{name}: {:?}", g.name);
            }
        }
    }

    /// Every bind group layout is made by `passes::bind_group_layout`, so that none keeps a
    /// uniform binding the rewritten shaders no longer declare.
    #[test]
    fn bind_group_layouts_are_made_in_one_place() {
        fn walk(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
            for e in std::fs::read_dir(dir).unwrap().flatten() {
                let p = e.path();
                if p.is_dir() {
                    walk(&p, out);
                } else if p.extension().is_some_and(|x| x == "rs") {
                    out.push(p);
                }
            }
        }
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut files = Vec::new();
        walk(&root.join("src"), &mut files);
        walk(&root.join("tests"), &mut files);
        let call = ["create_bind_group", "_layout("].concat();
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap();
            let n = text.matches(&call).count();
            let allowed = usize::from(f.ends_with("src/gpu/passes/mod.rs")) * 2;
            assert!(
                n <= allowed,
                "{}: {n} direct layout creation(s); use passes::bind_group_layout",
                f.display()
            );
        }
    }
}

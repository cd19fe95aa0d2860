//! `sheet`: a comparison sheet of methods on the same VPLs and tree (`crate::sheet`), as the
//! GUI's "comparison sheet" export writes it: PNG + JSON of the metrics.

use std::path::PathBuf;

use anyhow::{Context, anyhow};
use clap::Args;

use super::{
    SettingsArgs,
    render::{SamplingArgs, parse_method},
};
use crate::{
    renderer::{Renderer, context::GpuContext, settings::MethodId},
    scene::preset::{SceneSource, open_scene},
    sheet::{SheetJob, compose},
};

#[derive(Args, Debug)]
pub struct SheetArgs {
    /// `default` or another built-in scene (`window-box`, `corridor`, `glossy-thin`), a
    /// .gltf/.glb file, or a preset .toml.
    #[arg(long, default_value = "default")]
    pub scene: String,
    #[arg(long)]
    pub camera: Option<String>,
    #[arg(long, default_value_t = 320)]
    pub width: u32,
    #[arg(long, default_value_t = 200)]
    pub height: u32,
    /// The columns, in order: any method but the ground truth (the sheet's first column)
    /// and `off`, by CLI name.
    #[arg(long, value_parser = parse_method, value_delimiter = ',', default_value = "slc,rtslc,sst")]
    pub methods: Vec<MethodId>,
    /// The sheet (PNG; a JSON of the metrics is written beside it).
    #[arg(long, default_value = "screenshots/sheet.png")]
    pub out: PathBuf,
    #[arg(long)]
    pub vpls: Option<u32>,
    #[arg(long)]
    pub seed: Option<u32>,
    #[command(flatten)]
    pub settings: SettingsArgs,
    /// Sampler settings; --frames is the frames each method accumulates.
    #[command(flatten)]
    pub sampling: SamplingArgs,
}

pub fn run(args: &SheetArgs) -> anyhow::Result<()> {
    let opened = open_scene(&SceneSource::from_arg(&args.scene)).map_err(|e| anyhow!("{e}"))?;
    let mut settings = args.settings.resolve(opened.exposure_ev)?;
    args.sampling.apply(&mut settings)?;
    if let Some(v) = args.vpls {
        settings.vpl.count = v;
    }
    if let Some(v) = args.seed {
        settings.vpl.seed = v;
    }
    settings.validate().map_err(|e| anyhow!("{e}"))?;
    let columns = crate::methods::sheet_columns();
    let methods: Vec<MethodId> = args
        .methods
        .iter()
        .map(|&m| {
            if columns.contains(&m) {
                Ok(m)
            } else {
                let names: Vec<&str> = columns.iter().map(|c| c.cli()).collect();
                Err(anyhow!(
                    "--methods: {m} cannot be a sheet column ({})",
                    names.join(", ")
                ))
            }
        })
        .collect::<anyhow::Result<_>>()?;
    args.sampling.check_visibility(&methods)?;
    if let Some(msg) = methods.iter().find_map(|m| {
        m.refuses_tree(settings.tree.kind)
            .or(m.refuses_bounces(settings.vpl.bounces))
            .or(m.refuses_brdf(settings.gi.brdf))
    }) {
        return Err(anyhow!("{msg}"));
    }
    let cam_name = args.camera.clone().or(opened.camera_name.clone());
    let camera = opened
        .scene
        .camera_or_default(cam_name.as_deref())
        .map_err(|e| anyhow!("{e}"))?;
    let title = format!("{} · camera {}", args.scene, camera.name);
    let job = SheetJob::new(
        settings.clone(),
        methods,
        args.sampling.frames,
        Some(1 << 26),
        title,
    )
    .map_err(|e| anyhow!("{e}"))?;
    if let Some(dir) = args.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    let ctx = GpuContext::new_headless()?;
    println!("adapter: {}", ctx.describe());
    let settings_for_record = settings.clone();
    let mut r = Renderer::new(ctx, &opened.scene, (args.width, args.height), settings)?;
    let mut last = -1.0f32;
    let sheet = job
        .run(&mut r, &camera, &opened.scene.lights, |f, label| {
            if f - last >= 0.1 {
                eprintln!("{:3.0}% {label}", 100.0 * f);
                last = f;
            }
        })
        .map_err(|e| anyhow!("{e}"))?;
    let canvas = compose(&sheet).map_err(|e| anyhow!("{e}"))?;
    crate::export::write_png(&args.out, canvas.width, canvas.height, &canvas.rgba)?;
    for c in &sheet.columns {
        let m = &c.metrics;
        println!(
            "{:<16} RMSE {:.4e} (rel. {:.4}) · mean ratio {:.4} · SSIM {:.4} · FLIP {:.4} · GPU {} ms/frame",
            c.method.name(),
            m.rmse,
            m.relative_rmse,
            m.mean_ratio,
            m.ssim,
            m.flip,
            c.gpu_ms.map_or("n/a".into(), |t| format!("{t:.2}"))
        );
    }
    let jpath = args.out.with_extension("json");
    std::fs::write(&jpath, crate::sheet::metrics_json(&sheet))
        .with_context(|| format!("cannot write {}", jpath.display()))?;
    // The capture record (the base settings, scene, camera; the sheet's JSON names each
    // column's method and settings).
    let mut rec =
        crate::capture::Capture::new("sheet", &r.ctx.adapter_info, &args.scene, opened.file.as_deref());
    rec.camera = (&camera).into();
    rec.lights = opened.scene.lights.iter().map(Into::into).collect();
    (rec.width, rec.height) = (args.width, args.height);
    rec.seed = r.settings().vpl.seed;
    rec.frames = args.sampling.frames;
    rec.frame_index = r.frame_index();
    rec.files = [&args.out, &jpath]
        .iter()
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().to_string()))
        .collect();
    let rpath = crate::capture::sidecar_path(&args.out);
    crate::capture::write_record(&rpath, &rec, &settings_for_record).map_err(|e| anyhow!("{e}"))?;
    println!(
        "wrote {}, {} and {}",
        args.out.display(),
        jpath.display(),
        rpath.display()
    );
    Ok(())
}

//! `render`: one frame (or a few, for stable timings) written to disk.

use std::path::PathBuf;

use anyhow::{Context, anyhow};
use clap::Args;

use super::SettingsArgs;
use crate::{
    export::{write_exr, write_png},
    renderer::{Buffer, FrameInput, Renderer, context::GpuContext, readback::ImageF32, settings::ViewBuffer},
    scene::preset::{SceneSource, open_scene},
};

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// `default`, a .gltf/.glb file, or a preset .toml.
    #[arg(long, default_value = "default")]
    pub scene: String,
    #[arg(long, default_value_t = 640)]
    pub width: u32,
    #[arg(long, default_value_t = 360)]
    pub height: u32,
    /// Output folder (created if missing).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Camera name from the scene (default: the preset's, else the first).
    #[arg(long)]
    pub camera: Option<String>,
    /// Frames to render before reading timings (the first frames include pipeline warm-up).
    #[arg(long, default_value_t = 3)]
    pub timing_frames: u32,
    #[command(flatten)]
    pub settings: SettingsArgs,
}

/// Linear view depth (metres along the camera forward; 0 where there is no geometry).
fn linear_depth(position: &ImageF32, eye: glam::Vec3, fwd: glam::Vec3) -> ImageF32 {
    ImageF32 {
        width: position.width,
        height: position.height,
        pixels: position
            .pixels
            .iter()
            .map(|p| {
                let d = if p[3] > 0.0 {
                    (glam::Vec3::new(p[0], p[1], p[2]) - eye).dot(fwd)
                } else {
                    0.0
                };
                [d, d, d, 1.0]
            })
            .collect(),
    }
}

pub fn run(args: &RenderArgs) -> anyhow::Result<()> {
    let opened = open_scene(&SceneSource::from_arg(&args.scene)).map_err(|e| anyhow!("{e}"))?;
    let settings = args.settings.resolve(opened.exposure_ev)?;
    let cam_name = args.camera.clone().or(opened.camera_name.clone());
    let camera = opened
        .scene
        .camera_or_default(cam_name.as_deref())
        .map_err(|e| anyhow!("{e}"))?;
    let ctx = GpuContext::new_headless()?;
    println!("adapter: {}", ctx.describe());
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let mut r = Renderer::new(ctx, &opened.scene, (args.width, args.height), settings)?;
    let lights = opened.scene.lights.clone();
    let frame = |r: &mut Renderer, view| {
        r.render(&FrameInput {
            camera: &camera,
            lights: &lights,
            view,
        })
    };
    for _ in 0..args.timing_frames.max(1) {
        frame(&mut r, ViewBuffer::Final);
        r.ctx.wait_idle()?;
    }
    let timings = r.wait_timings();
    if let Some(e) = r.ctx.errors.take().into_iter().next() {
        return Err(anyhow!("GPU error: {e}"));
    }

    let out = &args.out;
    let direct = r.read(Buffer::Direct)?;
    write_exr(&out.join("direct.exr"), &direct)?;
    write_exr(&out.join("final.exr"), &r.read(Buffer::Final)?)?;
    let position = r.read(Buffer::Position)?;
    write_exr(&out.join("position.exr"), &position)?;
    write_exr(&out.join("normal.exr"), &r.read(Buffer::Normal)?)?;
    write_exr(&out.join("albedo.exr"), &r.read(Buffer::Albedo)?)?;
    write_exr(
        &out.join("depth.exr"),
        &linear_depth(&position, camera.position, camera.forward),
    )?;
    let pngs = [
        (ViewBuffer::Final, "final.png"),
        (ViewBuffer::Direct, "direct.png"),
        (ViewBuffer::Albedo, "albedo.png"),
        (ViewBuffer::Normal, "normal.png"),
        (ViewBuffer::Depth, "depth.png"),
        (ViewBuffer::ShadowMap, "shadow_map.png"),
    ];
    for (view, name) in pngs {
        frame(&mut r, view);
        let (w, h, bytes) = r.read_view_rgba8()?;
        write_png(&out.join(name), w, h, &bytes)?;
    }
    if let Some(e) = r.ctx.errors.take().into_iter().next() {
        return Err(anyhow!("GPU error: {e}"));
    }
    let mean = direct.mean_rgb();
    println!(
        "scene: {} ({} triangles, {} materials, {} textures), camera '{}', {}x{}",
        opened.scene.name,
        opened.scene.triangle_count(),
        opened.scene.materials.len(),
        opened.scene.textures.len(),
        camera.name,
        args.width,
        args.height
    );
    println!(
        "mean direct radiance (linear RGB): {:.5} {:.5} {:.5}",
        mean[0], mean[1], mean[2]
    );
    match timings {
        Some(t) => {
            println!(
                "GPU time per pass (last of {} frames):",
                args.timing_frames.max(1)
            );
            for (name, ms) in &t.passes {
                println!("  {name:<14} {ms:>9.3} ms");
            }
            println!("  {:<14} {:>9.3} ms", "total", t.total_ms());
        }
        None => println!("GPU time per pass: timestamps not supported on this adapter"),
    }
    println!("wrote {}", out.display());
    Ok(())
}

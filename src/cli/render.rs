//! `render`: one frame (or a few, for stable timings) written to disk.

mod args;
mod output;

pub use args::*;
use output::*;
use std::path::PathBuf;

use anyhow::{Context, anyhow};
use clap::Args;

use clap::ValueEnum;

use super::SettingsArgs;
use crate::{
    export::{write_exr, write_png},
    renderer::{
        Buffer, FrameInput, FrameMode, Renderer,
        context::GpuContext,
        readback::ImageF32,
        settings::{MethodId, MethodView, TreeColor, TreeOverlay, ViewBuffer},
        soak::{self, Watch},
        timing::PassTimings,
    },
    scene::preset::{SceneSource, open_scene},
};

/// What the timed frames of `render` measured, and the frames the image averaged.
struct Timed<'a> {
    /// Mean GPU time per pass over the timed frames.
    timings: Option<&'a PassTimings>,
    frames: usize,
    wall_ms: f64,
    frames_averaged: u32,
}

/// Mean time of each pass over timed frames (passes in the first frame's order).
fn mean_timings(frames: &[PassTimings]) -> Option<PassTimings> {
    let first = frames.first()?;
    let passes = first
        .passes
        .iter()
        .map(|(name, _)| {
            let v: Vec<f64> = frames.iter().filter_map(|f| f.get(name)).collect();
            (name.clone(), crate::harness::mean_std(&v).0)
        })
        .collect();
    Some(PassTimings { passes })
}

/// The images and metrics in `out` (sorted): the files a capture record describes.
fn written_files(out: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(out)
        .map(|rd| {
            rd.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().to_string())
                .filter(|n| n.ends_with(".exr") || n.ends_with(".png") || n == "metrics.json")
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// Prints the run's resources line and writes them to resources.json (`render` and its
/// sequences): live GPU objects and resident memory after the warm-up and at the end.
pub(super) fn write_resources(out: &std::path::Path, report: &soak::Report) -> anyhow::Result<()> {
    println!("{}", report.line());
    let path = out.join("resources.json");
    std::fs::write(&path, serde_json::to_string_pretty(report)?)
        .with_context(|| format!("cannot write {}", path.display()))
}

/// metrics.json of a per-frame method: frames averaged, per-pass GPU times of the timed
/// frames, the tree samplers' traversal statistics, and (with --compare-gt) RMSE / SSIM
/// against the ground truth of the same VPLs.
fn write_metrics(
    r: &mut Renderer,
    args: &RenderArgs,
    indirect: &ImageF32,
    timed: &Timed<'_>,
    frame: &dyn Fn(&mut Renderer, ViewBuffer),
) -> anyhow::Result<()> {
    let timings = timed.timings;
    let s = r.settings().clone();
    let tree = s.gi.method.samples_tree();
    let st = if tree { r.sampling_stats_blocking() } else { None };
    let mut json = serde_json::json!({
        "method": s.gi.method.cli(),
        "width": args.width,
        "height": args.height,
        "vpls": r.vpl_frame().count,
        "frames_averaged": timed.frames_averaged,
        "timed_frames": timed.frames,
        "frame_wall_ms": timed.wall_ms,
        "tree": &s.tree,
        "n_min": s.vpl.n_min,
        "d_max_fraction_of_scene_radius": s.vpl.d_max,
        "distance_epsilon": s.gi.distance_epsilon,
        "gpu_ms": timings.map(|t| t.passes.iter().map(|(n, ms)| (n.clone(), *ms)).collect::<std::collections::BTreeMap<_, _>>()),
        "indirect_mean_rgb": indirect.mean_rgb(),
    });
    // The method's own settings as it read them (defaults filled in).
    if let Some((section, table)) = crate::methods::own_settings(s.gi.method, &s) {
        json["method_settings"] = serde_json::json!({ "section": section, "values": table });
    }
    // The tree samplers' traversal statistics.
    if let Some(st) = st {
        json["steps_per_traversal"] = st.steps_per_traversal().into();
        json["steps_per_pixel"] = st.steps_per_pixel().into();
        json["fallback_pixel_fraction"] = st.fallback_fraction().into();
        json["dead_branches"] = st.dead.into();
        json["traversals"] = st.traversals.into();
        json["shadow_rays"] = st.rays.into();
    }
    // A method's own statistics (Lightcuts' cut sizes, ...).
    let ms = r.method_stats_blocking();
    if !ms.is_empty() {
        let line: Vec<String> = ms.iter().map(|(k, v)| format!("{k} {v:.4}")).collect();
        println!("{}: {}", s.gi.method.info().short, line.join(", "));
        json["method_stats"] = ms
            .iter()
            .map(|(k, v)| (k.to_string(), serde_json::json!(v)))
            .collect();
    }
    if args.sampling.compare_gt {
        let mut g = s.clone();
        g.gi.method = crate::methods::comparison_truth();
        g.gi.rays_per_frame = 1 << 26;
        r.set_settings(g)?;
        loop {
            frame(r, ViewBuffer::Final);
            r.ctx.wait_idle()?;
            if r.gi_progress().is_some_and(|p| p.finished()) {
                break;
            }
        }
        let gt = r.read(Buffer::Indirect)?;
        write_exr(&args.out.join("ground_truth_indirect.exr"), &gt)?;
        let m = crate::metrics::compare(indirect, &gt, s.display.exposure_ev, s.display.tonemap);
        println!(
            "vs ground truth ({} VPLs): RMSE {:.6} (relative {:.4}), SSIM {:.4}, FLIP {:.4}, mean ratio {:.4}",
            r.vpl_frame().count,
            m.rmse,
            m.relative_rmse,
            m.ssim,
            m.flip,
            m.mean_ratio
        );
        json["vs_ground_truth"] = serde_json::to_value(m)?;
        r.set_settings(s)?;
    }
    let path = args.out.join("metrics.json");
    std::fs::write(&path, serde_json::to_string_pretty(&json)?)
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

/// GPU time of `method`'s own passes in one frame's timings.
pub(super) fn method_ms(t: &PassTimings, method: MethodId) -> f64 {
    method.info().timed_passes.iter().filter_map(|p| t.get(p)).sum()
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
    let (args, record) = args.with_record()?;
    let args = &args;
    let mut opened = open_scene(&SceneSource::from_arg(&args.scene)).map_err(|e| anyhow!("{e}"))?;
    let record_camera = record.as_ref().map(|c| &c.camera).filter(|c| !c.name.is_empty());
    if let Some(c) = &record {
        apply_record(c, &mut opened);
    }
    let settings = run_settings(args, record.as_ref(), &opened)?;
    let method = settings.gi.method;
    let wants = |o: Output| args.output.contains(&Output::All) || args.output.contains(&o);
    // The record's camera, else `--camera`, else the preset's.
    let camera = match record_camera {
        Some(c) => c.camera(),
        None => opened
            .scene
            .camera_or_default(args.camera.as_deref().or(opened.camera_name.as_deref()))
            .map_err(|e| anyhow!("{e}"))?,
    };
    if args.camera_path.is_some() || args.sun_sweep.is_some() {
        return super::render_sequence::run(args, &opened, settings, &camera);
    }
    if args.path_frames.is_some() {
        return Err(anyhow!(
            "--path-frames: a sequence needs --camera-path and/or --sun-sweep"
        ));
    }
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
    let redraw = |r: &mut Renderer, view| {
        r.redraw_view(&FrameInput {
            camera: &camera,
            lights: &lights,
            view,
        })
    };
    let render_start = std::time::Instant::now();
    // Timed frames: nothing but the frame's passes (FrameMode::Timed: no diagnostics, no
    // readbacks). A per-frame method times frames that do not accumulate; the first of two
    // or more is a warm-up (pipelines, buffers) and is not counted.
    r.set_frame_mode(FrameMode::Timed);
    let image_settings = r.settings().clone();
    let image_settings_for_record = image_settings.clone();
    if method.per_frame() {
        let mut s = image_settings.clone();
        s.frame.accumulate = false;
        r.set_settings(s)?;
    }
    let n_timing = args.timing_frames.max(1);
    // Live GPU objects and resident memory after 30 frames and at the end (issue 42).
    let mut watch = Watch::new(Watch::WARM_FRAMES);
    let (timed, wall_ms, mut gi_ms) = timed_frames(&mut r, &frame, &mut watch, n_timing, method)?;
    let timings = mean_timings(&timed);
    // The image: a per-frame method averages exactly --frames new diagnostic frames
    // (untimed; the accumulation restarts with the settings change). A progressive method
    // goes on in timed frames (below), each adding its GPU time.
    r.set_settings(image_settings)?;
    // The method's views are drawn after the image frames: those needing work in the frames
    // (light culling's clamped-vs-stochastic difference) are announced now.
    if wants(Output::Png) {
        r.keep_views(
            method
                .info()
                .views
                .iter()
                .map(|v| MethodView::new(v.name))
                .collect(),
        );
    }
    let mut frames_averaged = None;
    // A record's first image frame (a GUI export's last frames): the image frames are
    // numbered from it, so their random numbers are the captured ones.
    if method.per_frame()
        && let Some(first) = record.as_ref().and_then(|c| c.first_frame)
    {
        r.set_frame_index(first);
    }
    let first_frame = method.per_frame().then(|| r.frame_index());
    if method.per_frame() {
        frames_averaged = Some(image_frames(
            &mut r,
            &frame,
            &mut watch,
            args.sampling.frames,
            method,
        )?);
    }
    let info = method.info();
    gi_ms += progressive_frames(&mut r, &frame, &mut watch, method)?;
    if let Some(p) = r.gi_progress() {
        let what = format!("{}: {} {}", info.short, p.total, info.progress_unit);
        println!(
            "{what} x {}x{} pixels in {:.2} s wall (from the first frame), {:.1} ms GPU",
            args.width,
            args.height,
            render_start.elapsed().as_secs_f64(),
            gi_ms
        );
    }
    gpu_error(&r)?;
    let out = &args.out;
    write_resources(out, &watch.finish(&r.ctx))?;

    let (direct, indirect) = write_exrs(&mut r, out, &wants, &camera)?;
    if wants(Output::Png) {
        write_pngs(&mut r, out, method, &redraw)?;
    }
    if method.per_frame() {
        let timed = Timed {
            timings: timings.as_ref(),
            frames: timed.len(),
            wall_ms: crate::harness::mean_std(&wall_ms).0,
            frames_averaged: frames_averaged.unwrap_or(1),
        };
        write_metrics(&mut r, args, &indirect, &timed, &frame)?;
    }
    gpu_error(&r)?;
    print_summary(
        &opened,
        &camera,
        args,
        &direct,
        timings.as_ref(),
        (timed.len(), n_timing),
        &wall_ms,
    );
    write_capture(
        &r,
        args,
        &opened,
        (&camera, &lights),
        (n_timing, first_frame),
        &image_settings_for_record,
    )?;
    println!("wrote {}", out.display());
    Ok(())
}

/// The first GPU error the device reported since the last look, as an error.
fn gpu_error(r: &Renderer) -> anyhow::Result<()> {
    match r.ctx.errors.take().into_iter().next() {
        Some(e) => Err(anyhow!("GPU error: {e}")),
        None => Ok(()),
    }
}

/// A capture record's scene notes and lights: a note when the scene file differs from the
/// recorded one (SHA-256), the recorded lights replacing the scene's.
fn apply_record(c: &crate::capture::Capture, opened: &mut crate::scene::preset::OpenedScene) {
    if !c.scene_sha256.is_empty()
        && let Some(f) = &opened.file
        && let Ok(bytes) = std::fs::read(f)
        && crate::scene::scene_path::sha256_hex(&bytes) != c.scene_sha256
    {
        println!(
            "  note: {} differs from the recorded scene file (SHA-256)",
            f.display()
        );
    }
    if !c.lights.is_empty() {
        opened.scene.lights = c.lights.iter().map(|l| l.light()).collect();
    }
}

/// A per-frame method's image: `frames` diagnostic frames averaged (untimed); prints the
/// tree samplers' statistics. Returns the frames averaged.
fn image_frames(
    r: &mut Renderer,
    frame: &dyn Fn(&mut Renderer, ViewBuffer),
    watch: &mut Watch,
    frames: u32,
    method: MethodId,
) -> anyhow::Result<u32> {
    r.set_frame_mode(FrameMode::Diagnostic);
    for _ in 0..frames {
        gpu_error(r)?;
        frame(r, ViewBuffer::Final);
        r.ctx.wait_idle()?;
        watch.frame(&r.ctx);
    }
    let averaged = r.sampling_frames();
    if let Some(st) = r.sampling_stats_blocking().filter(|_| method.samples_tree()) {
        println!(
            "tree sampling: {} frame(s) averaged; {:.3} traversal steps per traversal, {:.2} per pixel; {:.3}% of pixels without a similar cut; {} dead branches and {} shadow rays in the last frame",
            r.sampling_frames(),
            st.steps_per_traversal(),
            st.steps_per_pixel(),
            100.0 * st.fallback_fraction(),
            st.dead,
            st.rays
        );
    }
    Ok(averaged)
}

/// The settings of a `render` run: the settings file / `--set`, `--method` and the flags,
/// checked (the method's refusals, ranges).
fn run_settings(
    args: &RenderArgs,
    record: Option<&crate::capture::Capture>,
    opened: &crate::scene::preset::OpenedScene,
) -> anyhow::Result<crate::settings::RenderSettings> {
    let mut settings = args.settings.resolve(opened.exposure_ev)?;
    if let Some(m) = args.method {
        settings.gi.method = m;
    }
    let method = settings.gi.method;
    if let Some(c) = record
        && c.what != "render"
        && c.first_frame.is_some()
        && settings.temporal.mode != crate::settings::TemporalMode::Off
    {
        println!(
            "  note: the temporal stage's history from the window's earlier frames is not in the record: its image is the stage's over the frames rendered here"
        );
    }
    args.sampling.apply(&mut settings)?;
    args.sampling.check_visibility(&[method])?;
    // `tree.kind = lbvh` from a settings file or --set: the same refusal as --tree's.
    if let Some(msg) = method.refuses_tree(settings.tree.kind) {
        return Err(anyhow!("{msg}"));
    }
    if let Some(msg) = method
        .refuses_bounces(settings.vpl.bounces)
        .or(method.refuses_brdf(settings.gi.brdf))
    {
        return Err(anyhow!("{msg}"));
    }
    if args.sampling.frames == 0 {
        return Err(anyhow!("--frames must be at least 1"));
    }
    if let Some(v) = args.samples {
        settings.gi.reference_samples = v;
    }
    settings.gi.reference_spp_per_frame = settings.gi.reference_samples.min(16);
    if let Some(v) = args.vpls {
        settings.vpl.count = v;
    }
    if let Some(v) = args.seed {
        settings.vpl.seed = v;
    }
    if let Some(v) = args.epsilon {
        settings.gi.distance_epsilon = v;
    }
    // Headless: large GI steps (each submit still splits into bounded dispatches).
    settings.gi.rays_per_frame = 1 << 26;
    settings.validate().map_err(|e| anyhow!("{e}"))?;
    Ok(settings)
}

/// The timed frames (`FrameMode::Timed`): their timings and wall times (the first of two or
/// more is a warm-up, not counted) and the GI's GPU time of all of them.
fn timed_frames(
    r: &mut Renderer,
    frame: &dyn Fn(&mut Renderer, ViewBuffer),
    watch: &mut Watch,
    n_timing: u32,
    method: MethodId,
) -> anyhow::Result<(Vec<PassTimings>, Vec<f64>, f64)> {
    let mut timed: Vec<PassTimings> = Vec::new();
    let mut wall_ms: Vec<f64> = Vec::new();
    // Progressive methods: the GPU time of every frame's passes adds up.
    let mut gi_ms = 0.0;
    for i in 0..n_timing {
        let t0 = std::time::Instant::now();
        frame(r, ViewBuffer::Final);
        r.ctx.wait_idle()?;
        watch.frame(&r.ctx);
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        let t = r.wait_new_timings();
        gi_ms += t.as_ref().map_or(0.0, |t| method_ms(t, method));
        if i > 0 || n_timing == 1 {
            wall_ms.push(ms);
            timed.extend(t);
        }
    }
    Ok((timed, wall_ms, gi_ms))
}

/// A progressive method's frames until it has seen every VPL / sample (progress on stderr);
/// returns their GI GPU time.
fn progressive_frames(
    r: &mut Renderer,
    frame: &dyn Fn(&mut Renderer, ViewBuffer),
    watch: &mut Watch,
    method: MethodId,
) -> anyhow::Result<f64> {
    let info = method.info();
    let mut gi_ms = 0.0;
    // Progressive GI: keep rendering the same frame until it has seen every VPL / sample.
    while let Some(p) = r.gi_progress() {
        if p.finished() {
            break;
        }
        frame(r, ViewBuffer::Final);
        r.ctx.wait_idle()?;
        watch.frame(&r.ctx);
        if let Some(t) = r.wait_new_timings() {
            gi_ms += method_ms(&t, method);
        }
        if let Some(p) = r.gi_progress() {
            eprint!(
                "\r{} ({}): {:5.1}% of {}",
                info.label,
                info.progress_unit,
                100.0 * p.fraction(),
                p.total
            );
        }
    }
    if r.gi_progress().is_some() {
        eprintln!();
    }
    Ok(gi_ms)
}

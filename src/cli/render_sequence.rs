//! `render --camera-path / --sun-sweep`: a repeatable sequence (`harness::sequence::Motion`)
//! for temporal measurements. Timed frames along the sequence first (GPU timestamps of every
//! pass, no readbacks), then diagnostic frames along it again from a fresh history that write
//! frames/NNNN.png and, with --compare-gt, the raw and filtered GI's error and flicker against
//! each frame's ground truth; sequence.csv holds both per frame.

use anyhow::{Context, anyhow};

use super::render::{Output, RenderArgs, method_ms};
use crate::{
    export::{write_exr, write_png},
    harness::{
        Csv, mean_std, num,
        sequence::{self, Motion, SeqFrame},
    },
    renderer::{
        Buffer, Renderer, context::GpuContext, settings::RenderSettings, soak::Watch, timing::PassTimings,
    },
    scene::{Camera, preset::OpenedScene},
};

/// The motion the arguments ask for.
fn motion(args: &RenderArgs, opened: &OpenedScene, camera: &Camera) -> anyhow::Result<Motion> {
    let n = args.path_frames.unwrap_or(60);
    if !(2..=100_000).contains(&n) {
        return Err(anyhow!("--path-frames must be 2..=100000 (got {n})"));
    }
    let lights = &opened.scene.lights;
    let path = match &args.camera_path {
        Some(names) => {
            let names: Vec<String> = names
                .split(',')
                .map(|s| s.trim().to_string())
                .filter(|s| !s.is_empty())
                .collect();
            Some(Motion::camera_path(&opened.scene, &names, n, lights)?)
        }
        None => None,
    };
    let sun = match args.sun_sweep {
        Some(d) if !d.is_finite() => return Err(anyhow!("--sun-sweep: {d} is not a number of degrees")),
        Some(d) => Some(Motion::sun_sweep(camera, lights, d, n)?),
        None => None,
    };
    Ok(match (path, sun) {
        (Some(p), Some(s)) => p.with_lights_of(&s),
        (Some(p), None) => p,
        (None, Some(s)) => s,
        (None, None) => Motion::still(camera, lights, n),
    })
}

pub fn run(
    args: &RenderArgs,
    opened: &OpenedScene,
    mut settings: RenderSettings,
    camera: &Camera,
) -> anyhow::Result<()> {
    let method = settings.gi.method;
    if !method.per_frame() {
        return Err(anyhow!(
            "--camera-path / --sun-sweep: {method} converges over frames of one view; a sequence needs a per-frame method"
        ));
    }
    if args.sampling.frames > 1 {
        return Err(anyhow!(
            "--frames: a sequence renders one frame per step (the temporal stage, --temporal, reuses them)"
        ));
    }
    let m = motion(args, opened, camera)?;
    settings.frame.accumulate = false;
    settings.vpl.animate = false;
    let ctx = GpuContext::new_headless()?;
    println!("adapter: {}", ctx.describe());
    let out = &args.out;
    std::fs::create_dir_all(out.join("frames"))
        .with_context(|| format!("cannot create {}", out.display()))?;
    let mut r = Renderer::new(ctx, &opened.scene, (args.width, args.height), settings.clone())?;
    println!(
        "sequence: {} frames, {}, method {}, temporal {}",
        m.len(),
        m.name,
        method.cli(),
        settings.temporal.mode.cli()
    );
    // 1. Timed frames along the sequence (two warm-up frames of its first view).
    let timed: Vec<PassTimings> = sequence::time(&mut r, &settings, &m, m.len(), 2)?;
    // 2. Diagnostic frames: PNGs and, with --compare-gt, the errors.
    let wants_png = args.output.contains(&Output::All) || args.output.contains(&Output::Png);
    // Live GPU objects and resident memory after 30 frames of the walk and at its end.
    let watch = std::cell::RefCell::new(Watch::new(Watch::WARM_FRAMES));
    let write_frame = |r: &mut Renderer, i: usize| -> anyhow::Result<()> {
        watch.borrow_mut().frame(&r.ctx);
        if wants_png {
            let (w, h, bytes) = r.read_view_rgba8()?;
            write_png(&out.join("frames").join(format!("{i:04}.png")), w, h, &bytes)?;
        }
        Ok(())
    };
    let metrics: Option<Vec<SeqFrame>> = if args.sampling.compare_gt {
        let t0 = std::time::Instant::now();
        let truths = sequence::ground_truths(&mut r, &settings, &m, |i| {
            eprint!("\rground truth of frame {}/{}", i + 1, m.len());
        })?;
        eprintln!(" ({:.1} s)", t0.elapsed().as_secs_f64());
        let gi_ev = settings.display.exposure_ev + 3.0;
        Some(
            sequence::measure(
                &mut r,
                &settings,
                &m,
                &truths,
                gi_ev,
                settings.display.tonemap,
                write_frame,
            )?
            .0,
        )
    } else {
        sequence::walk(&mut r, &settings, &m, write_frame)?;
        None
    };
    if let Some(e) = r.ctx.errors.take().into_iter().next() {
        return Err(anyhow!("GPU error: {e}"));
    }
    super::render::write_resources(out, &watch.borrow().finish(&r.ctx))?;
    write_sequence_csv(out, &m, &timed, metrics.as_deref(), method)?;
    // The last frame's images.
    write_exr(&out.join("final.exr"), &r.read(Buffer::Final)?)?;
    write_exr(&out.join("indirect.exr"), &r.read(Buffer::Indirect)?)?;
    write_exr(&out.join("direct.exr"), &r.read(Buffer::Direct)?)?;
    print_sequence_summary(&timed, metrics.as_deref(), method);
    // The capture record: `render --settings capture.toml` renders the same sequence again.
    let mut capture = crate::capture::Capture::new(
        "render sequence",
        &r.ctx.adapter_info,
        &args.scene,
        opened.file.as_deref(),
    );
    capture.camera = camera.into();
    capture.lights = opened.scene.lights.iter().map(Into::into).collect();
    (capture.width, capture.height) = (args.width, args.height);
    capture.seed = settings.vpl.seed;
    capture.frames = 1;
    capture.frame_index = r.frame_index();
    capture.camera_path = args.camera_path.clone();
    capture.sun_sweep = args.sun_sweep;
    capture.path_frames = args.path_frames;
    capture.files = vec!["sequence.csv".into(), "frames/".into()];
    crate::capture::write_record(&out.join("capture.toml"), &capture, &settings)
        .map_err(|e| anyhow!("{e}"))?;
    println!("wrote {}", out.display());
    Ok(())
}

/// sequence.csv: per frame its camera, sun, GPU times and (with the ground truths) errors.
fn write_sequence_csv(
    out: &std::path::Path,
    m: &Motion,
    timed: &[PassTimings],
    metrics: Option<&[SeqFrame]>,
    method: crate::methods::MethodId,
) -> anyhow::Result<()> {
    let mut csv = Csv::new(&[
        "frame",
        "camera_x",
        "camera_y",
        "camera_z",
        "sun_azimuth_deg",
        "temporal_gpu_ms",
        "gi_gpu_ms",
        "frame_gpu_ms",
        "rmse_raw",
        "rmse_filtered",
        "mean_ratio_raw",
        "mean_ratio_filtered",
        "ssim_raw",
        "ssim_filtered",
        "flicker_raw",
        "flicker_filtered",
    ]);
    for i in 0..m.len() {
        let c = &m.cameras[i];
        let az = m.lights[i].first().map_or(f64::NAN, |l| l.angles_deg().0 as f64);
        let t = timed.get(i);
        let f = metrics.and_then(|v| v.get(i)).copied();
        let g = |x: Option<f64>| x.map_or(String::new(), num);
        csv.row(vec![
            i.to_string(),
            num(c.position.x as f64),
            num(c.position.y as f64),
            num(c.position.z as f64),
            num(az),
            g(t.map(sequence::temporal_ms)),
            g(t.map(|t| method_ms(t, method))),
            g(t.map(|t| t.total_ms())),
            g(f.map(|f| f.rmse_raw)),
            g(f.map(|f| f.rmse_filtered)),
            g(f.map(|f| f.mean_ratio_raw)),
            g(f.map(|f| f.mean_ratio_filtered)),
            g(f.map(|f| f.ssim_raw)),
            g(f.map(|f| f.ssim_filtered)),
            g(f.map(|f| f.flicker_raw)),
            g(f.map(|f| f.flicker_filtered)),
        ]);
    }
    csv.write(&out.join("sequence.csv"))?;
    Ok(())
}

/// Prints the sequence's mean GPU times and, with the ground truths, its mean errors.
fn print_sequence_summary(
    timed: &[PassTimings],
    metrics: Option<&[SeqFrame]>,
    method: crate::methods::MethodId,
) {
    let col = |f: fn(&PassTimings) -> f64| mean_std(&timed.iter().map(f).collect::<Vec<_>>()).0;
    if timed.is_empty() {
        println!("GPU time per frame: timestamps not supported on this adapter");
    } else {
        let gi: Vec<f64> = timed.iter().map(|t| method_ms(t, method)).collect();
        println!(
            "GPU time per frame (GPU timestamps, mean of {} timed frames along the sequence): temporal stage {:.3} ms, {} {:.3} ms, frame {:.3} ms",
            timed.len(),
            col(sequence::temporal_ms),
            method.info().short,
            mean_std(&gi).0,
            col(|t| t.total_ms()),
        );
    }
    if let Some(v) = metrics {
        let mean = |f: fn(&SeqFrame) -> f64| {
            let x: Vec<f64> = v.iter().map(f).filter(|x| x.is_finite()).collect();
            mean_std(&x).0
        };
        println!(
            "vs each frame's ground truth (mean over {} frames): RMSE raw {:.6} / filtered {:.6} (ratio {:.3}), image mean / truth's raw {:.4} / filtered {:.4}, SSIM raw {:.4} / filtered {:.4}, flicker raw {:.4} / filtered {:.4}",
            v.len(),
            mean(|f| f.rmse_raw),
            mean(|f| f.rmse_filtered),
            mean(|f| f.rmse_filtered) / mean(|f| f.rmse_raw),
            mean(|f| f.mean_ratio_raw),
            mean(|f| f.mean_ratio_filtered),
            mean(|f| f.ssim_raw),
            mean(|f| f.ssim_filtered),
            mean(|f| f.flicker_raw),
            mean(|f| f.flicker_filtered),
        );
    }
}

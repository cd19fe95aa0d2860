//! `render`'s files: the EXRs, the PNGs of every view, the printed summary and the capture
//! record.

use super::*;

/// The PNGs of `render`: the frame's buffers, the VPLs, the PDF pyramid, the method's and
/// the temporal stage's views and the light tree, each redrawn from the last frame.
pub(super) fn write_pngs(
    r: &mut Renderer,
    out: &std::path::Path,
    method: MethodId,
    redraw: &dyn Fn(&mut Renderer, ViewBuffer),
) -> anyhow::Result<()> {
    let info = method.info();
    let pngs = [
        (ViewBuffer::Final, "final.png"),
        (ViewBuffer::Direct, "direct.png"),
        (ViewBuffer::Indirect, "indirect.png"),
        (ViewBuffer::Albedo, "albedo.png"),
        (ViewBuffer::Normal, "normal.png"),
        (ViewBuffer::Depth, "depth.png"),
        (ViewBuffer::ShadowMap, "shadow_map.png"),
        (ViewBuffer::RsmFlux, "rsm_flux.png"),
        (ViewBuffer::ImportanceRaw, "brsm_importance_raw.png"),
        (ViewBuffer::ImportanceFiltered, "brsm_importance_filtered.png"),
    ];
    // Views are drawn from the last frame's buffers (no new frame: the averaged GI and
    // its frame count stay those of the EXRs).
    for (view, name) in pngs {
        redraw(r, view);
        let (w, h, bytes) = r.read_view_rgba8()?;
        write_png(&out.join(name), w, h, &bytes)?;
    }
    // The VPLs over the RSM and in the camera view, and a coarse PDF-pyramid level.
    let mut s2 = r.settings().clone();
    s2.display.vpl_overlay = true;
    s2.display.vpl_point_size = 1;
    s2.display.pyramid_level = 4;
    r.set_settings(s2)?;
    for (view, name) in [
        (ViewBuffer::RsmFlux, "vpls_over_rsm.png"),
        (ViewBuffer::Final, "vpls_in_view.png"),
        (ViewBuffer::PdfPyramid, "pdf_pyramid_level4.png"),
    ] {
        redraw(r, view);
        let (w, h, bytes) = r.read_view_rgba8()?;
        write_png(&out.join(name), w, h, &bytes)?;
    }
    // The method's own views (the tree samplers': thesis figs. 7.2, 7.4, 7.6).
    if !info.views.is_empty() {
        let mut s3 = r.settings().clone();
        s3.display.vpl_overlay = false;
        r.set_settings(s3)?;
        for v in info.views {
            redraw(r, ViewBuffer::Method(MethodView::new(v.name)));
            let (w, h, bytes) = r.read_view_rgba8()?;
            write_png(&out.join(format!("{}.png", v.file)), w, h, &bytes)?;
        }
    }
    // The temporal stage's views (motion, disocclusion, history, variance, ...).
    if r.settings().temporal.mode != crate::settings::TemporalMode::Off && method.per_frame() {
        for v in crate::settings::TemporalView::ALL {
            redraw(r, ViewBuffer::Temporal(v));
            let (w, h, bytes) = r.read_view_rgba8()?;
            write_png(&out.join(format!("{}.png", v.file())), w, h, &bytes)?;
        }
    }
    // The light tree over the albedo (which shows the geometry): distributions by flux
    // and by usable flag, and bounding boxes of a coarse level.
    for (overlay, color, level, name) in [
        (
            TreeOverlay::Distributions,
            TreeColor::Intensity,
            6,
            "tree_distributions_level6.png",
        ),
        (
            TreeOverlay::Distributions,
            TreeColor::Usable,
            8,
            "tree_usable_level8.png",
        ),
        (TreeOverlay::Boxes, TreeColor::Node, 4, "tree_boxes_level4.png"),
    ] {
        let mut s3 = r.settings().clone();
        s3.display.vpl_overlay = false;
        s3.display.tree_overlay = overlay;
        s3.display.tree_color = color;
        s3.display.tree_level = level;
        r.set_settings(s3)?;
        redraw(r, ViewBuffer::Albedo);
        let (w, h, bytes) = r.read_view_rgba8()?;
        write_png(&out.join(name), w, h, &bytes)?;
    }
    Ok(())
}

/// Prints the scene, the mean direct radiance and the GPU time per pass of the timed
/// frames (`frames`: timed frames counted, asked).
pub(super) fn print_summary(
    opened: &crate::scene::preset::OpenedScene,
    camera: &crate::scene::Camera,
    args: &RenderArgs,
    direct: &ImageF32,
    timings: Option<&PassTimings>,
    frames: (usize, u32),
    wall_ms: &[f64],
) {
    let (n_timed, n_timing) = frames;
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
    for note in &opened.scene.load_notes {
        println!("  decoded: {note}");
    }
    println!(
        "mean direct radiance (linear RGB): {:.5} {:.5} {:.5}",
        mean[0], mean[1], mean[2]
    );
    match timings {
        Some(t) => {
            println!(
                "GPU time per pass (GPU timestamps, mean of {} timed frame(s) without diagnostics{}):",
                n_timed,
                if n_timing > 1 {
                    ", after 1 warm-up frame"
                } else {
                    ""
                }
            );
            for (name, ms) in &t.passes {
                println!("  {name:<14} {ms:>9.3} ms");
            }
            println!("  {:<14} {:>9.3} ms", "total", t.total_ms());
            println!(
                "frame wall clock (render + submit + wait): {:.3} ms",
                crate::harness::mean_std(wall_ms).0
            );
        }
        None => println!("GPU time per pass: timestamps not supported on this adapter"),
    }
}

/// The EXRs `render` was asked for (`wants`); returns the direct and indirect images.
pub(super) fn write_exrs(
    r: &mut Renderer,
    out: &std::path::Path,
    wants: &dyn Fn(Output) -> bool,
    camera: &crate::scene::Camera,
) -> anyhow::Result<(ImageF32, ImageF32)> {
    let direct = r.read(Buffer::Direct)?;
    let indirect = r.read(Buffer::Indirect)?;
    if wants(Output::Direct) {
        write_exr(&out.join("direct.exr"), &direct)?;
    }
    if wants(Output::Indirect) {
        write_exr(&out.join("indirect.exr"), &indirect)?;
    }
    if wants(Output::Final) {
        write_exr(&out.join("final.exr"), &r.read(Buffer::Final)?)?;
    }
    if wants(Output::Gbuffer) {
        let position = r.read(Buffer::Position)?;
        write_exr(&out.join("position.exr"), &position)?;
        write_exr(&out.join("normal.exr"), &r.read(Buffer::Normal)?)?;
        write_exr(&out.join("albedo.exr"), &r.read(Buffer::Albedo)?)?;
        write_exr(
            &out.join("depth.exr"),
            &linear_depth(&position, camera.position, camera.forward),
        )?;
    }
    Ok((direct, indirect))
}

/// The capture record: what reproduces these files (`render --settings capture.toml`);
/// `frames`: the timed frames and the first image frame.
pub(super) fn write_capture(
    r: &Renderer,
    args: &RenderArgs,
    opened: &crate::scene::preset::OpenedScene,
    view: (&crate::scene::Camera, &[crate::scene::DirectionalLight]),
    frames: (u32, Option<u64>),
    settings: &crate::settings::RenderSettings,
) -> anyhow::Result<()> {
    let (camera, lights) = view;
    let (n_timing, first_frame) = frames;
    let out = &args.out;
    let mut capture =
        crate::capture::Capture::new("render", &r.ctx.adapter_info, &args.scene, opened.file.as_deref());
    capture.camera = camera.into();
    capture.lights = lights.iter().map(Into::into).collect();
    capture.width = args.width;
    capture.height = args.height;
    capture.seed = r.settings().vpl.seed;
    capture.frames = args.sampling.frames;
    capture.timing_frames = n_timing;
    capture.frame_index = r.frame_index();
    capture.first_frame = first_frame;
    capture.files = written_files(out);
    crate::capture::write_record(&out.join("capture.toml"), &capture, settings)
        .map_err(|e| anyhow!("{e}"))?;
    Ok(())
}

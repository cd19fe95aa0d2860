//! `bench rays`: the binary and the wide BVH traced in one run (batches and in-frame shadow
//! rays, GPU timestamps), with both CPU twins' counters per ray; fails if the layouts answer
//! any ray differently.

use super::*;
use crate::methods::tree_samplers::settings::SamplingSettings;

pub(super) fn run_rays(args: &BenchArgs) -> anyhow::Result<()> {
    let opened = open_scene(&SceneSource::from_arg(&args.scene)).map_err(|e| anyhow!("{e}"))?;
    let scene = &opened.scene;
    let n = args.rays.clamp(1, MAX_RAYS) as usize;
    let ctx = GpuContext::new_headless()?;
    println!("adapter: {}", ctx.describe());
    let t0 = std::time::Instant::now();
    let bvh = Bvh::build(&scene.positions, &scene.indices);
    let build_ms = t0.elapsed().as_secs_f64() * 1e3;
    let wide = WideBvh::from_binary(&bvh);
    println!(
        "scene: {} ({} triangles); binary BVH: {} nodes x {} B, depth {}, built in {:.1} ms on the \
         CPU; wide BVH: {} nodes x {} B ({:.2} children per node), depth {}, collapsed in {:.1} ms",
        scene.name,
        scene.triangle_count(),
        bvh.nodes.len(),
        wide::BINARY_NODE_BYTES,
        bvh.stats.depth,
        build_ms,
        wide.nodes.len(),
        wide::WIDE_NODE_BYTES,
        wide.stats.mean_children,
        wide.stats.depth,
        wide.stats.build_ms
    );
    let (bin_nodes, bin_tris) = upload_bvh(&ctx.device, &bvh);
    let (wide_nodes, wide_tris) = upload_wide_bvh(&ctx.device, &wide);
    let bin_tracer = BvhTracer::new(&ctx.device)?;
    let wide_tracer = BvhTracer::new_wide(&ctx.device)?;
    let mut disagreements = 0usize;
    for (label, rays, mode) in [
        (
            "shadow rays (any hit)",
            shadow_rays(scene, n, args.seed),
            TraceMode::AnyHit,
        ),
        (
            "random rays (closest hit)",
            probe_rays(scene, n, args.seed),
            TraceMode::ClosestHit,
        ),
    ] {
        let any = mode == TraceMode::AnyHit;
        let m = (args.proxy_rays as usize).min(rays.len());
        let (cb, cw, differ) = count_both(&bvh, &wide, &rays[..m], any);
        disagreements += differ;
        print_counters(&format!("{label}, {m} rays (CPU counters)"), &cb, &cw);
        let gpu: Vec<GpuRay> = rays.iter().map(to_gpu_ray).collect();
        let (bin_hits, bin_times) =
            bin_tracer.trace(&ctx, &bin_nodes, &bin_tris, &gpu, mode, args.repeat + 1)?;
        let (wide_hits, wide_times) =
            wide_tracer.trace(&ctx, &wide_nodes, &wide_tris, &gpu, mode, args.repeat + 1)?;
        let gpu_differ = bin_hits
            .iter()
            .zip(&wide_hits)
            .filter(|(a, b)| {
                a.triangle != b.triangle || (!any && (a.t - b.t).abs() > 1e-5 * a.t.abs().max(1.0))
            })
            .count();
        disagreements += gpu_differ;
        let frac = match mode {
            TraceMode::AnyHit => wide_hits.iter().filter(|h| h.triangle == 1).count(),
            TraceMode::ClosestHit => wide_hits.iter().filter(|h| h.triangle != u32::MAX).count(),
        } as f64
            / n as f64;
        // The first repetition includes pipeline warm-up: drop it.
        let (bm, wm) = (
            median(bin_times.into_iter().skip(1).collect()),
            median(wide_times.into_iter().skip(1).collect()),
        );
        let rate = |ms: f64| n as f64 / (ms * 1e-3) / 1e6;
        match (bm, wm) {
            (Some(b), Some(w)) => println!(
                "{label:<26} {n} rays (GPU timestamps, median of {}): binary {b:.3} ms ({:.1} Mrays/s), \
                 wide {w:.3} ms ({:.1} Mrays/s): wide {:.2}x the binary rate; {:.1}% hit; \
                 {gpu_differ} rays answered differently",
                args.repeat,
                rate(b),
                rate(w),
                b / w,
                100.0 * frac
            ),
            _ => println!(
                "{label:<26} {n} rays: timestamps not supported on this adapter; {:.1}% hit; \
                 {gpu_differ} rays answered differently by the two layouts",
                100.0 * frac
            ),
        }
    }
    if let Some(e) = ctx.errors.take().into_iter().next() {
        return Err(anyhow!("GPU error: {e}"));
    }
    drop(ctx);
    let mut per_layout = Vec::new();
    let frames = crate::gpu::scene_gpu::frame_bvh_layout();
    for layout in [BvhLayout::Binary, BvhLayout::Wide] {
        set_frame_bvh_layout(layout);
        let r = in_frame_rays(args, &opened, layout);
        set_frame_bvh_layout(frames);
        per_layout.push(r?);
    }
    if let (Some(b), Some(w)) = (&per_layout[0].timing, &per_layout[1].timing) {
        println!(
            "in-frame shadow rays, wide / binary BVH (same frames, one run): {:.2}x the ray rate, \
             the sampling pass {:.2}x faster",
            w.rate / b.rate,
            b.with / w.with
        );
    }
    disagreements += in_frame_proxy(args, &opened, &bvh, &wide, &per_layout[1].vpls)?;
    if disagreements > 0 {
        return Err(anyhow!(
            "{disagreements} rays were answered differently by the binary and the wide BVH"
        ));
    }
    Ok(())
}

/// Traces `rays` through both layouts on the CPU, counting; returns the counters and the
/// number of rays answered differently (hit/miss, closest triangle).
pub(super) fn count_both(
    bvh: &Bvh,
    wide: &WideBvh,
    rays: &[Ray],
    any: bool,
) -> (TraceCounters, TraceCounters, usize) {
    let (mut cb, mut cw, mut differ) = (TraceCounters::default(), TraceCounters::default(), 0);
    for r in rays {
        let a = bvh.trace_counted(r, any, &mut cb);
        let b = wide.trace_counted(r, any, &mut cw);
        let same = if any {
            a.is_some() == b.is_some()
        } else {
            a.map(|h| h.triangle) == b.map(|h| h.triangle)
        };
        differ += !same as usize;
    }
    (cb, cw, differ)
}

pub(super) fn print_counters(label: &str, b: &TraceCounters, w: &TraceCounters) {
    let (bn, bb, bx, bt) = b.per_ray();
    let (wn, wb, wx, wt) = w.per_ray();
    let less = |x: f64, y: f64| 100.0 * (1.0 - y / x.max(1e-12));
    println!("{label}: per ray");
    println!(
        "    binary: {bn:>7.2} nodes, {bb:>8.1} bytes, {bx:>7.2} box tests, {bt:>6.2} triangle tests, stack {}",
        b.max_stack
    );
    println!(
        "    wide:   {wn:>7.2} nodes, {wb:>8.1} bytes, {wx:>7.2} box tests, {wt:>6.2} triangle tests, stack {}",
        w.max_stack
    );
    println!(
        "    wide vs binary: {:.1}% fewer nodes, {:.1}% fewer bytes, {:.1}% fewer box tests, {:.1}% fewer triangle tests",
        less(bn, wn),
        less(bb, wb),
        less(bx, wx),
        less(bt, wt)
    );
}

/// One layout's in-frame measurement.
pub(super) struct InFrame {
    timing: Option<InFrameTiming>,
    /// The frame's VPLs (for the CPU proxy).
    vpls: Vec<GpuVpl>,
}

pub(super) struct InFrameTiming {
    with: f64,
    rate: f64,
}

/// The shadow-ray rate inside the frame: SLC's sampling pass at the scene's settings and
/// camera, timed with and without shadow rays (timed frames, median of `--repeat`), and the
/// rays it traces (a diagnostic frame's counter): rays / (time with - time without). The
/// frames trace `layout` (set by the caller).
pub(super) fn in_frame_rays(
    args: &BenchArgs,
    opened: &crate::scene::preset::OpenedScene,
    layout: BvhLayout,
) -> anyhow::Result<InFrame> {
    let scene = &opened.scene;
    let camera = scene
        .camera_or_default(opened.camera_name.as_deref())
        .map_err(|e| anyhow!("{e}"))?;
    let s = in_frame_settings(opened);
    let size = (args.width, args.height);
    let mut r = Renderer::new(GpuContext::new_headless()?, scene, size, s.clone())?;
    let lights = scene.lights.clone();
    let input = FrameInput {
        camera: &camera,
        lights: &lights,
        view: ViewBuffer::Final,
    };
    r.set_frame_mode(FrameMode::Diagnostic);
    r.render(&input);
    let rays = r.sampling_stats_blocking().map_or(0, |st| st.rays);
    let vpls = r.read_vpls()?;
    if !r.timestamps_supported() {
        println!("in-frame shadow rays ({layout:?} BVH): timestamps not supported on this adapter");
        return Ok(InFrame { timing: None, vpls });
    }
    // Median GPU time of the sampling pass over back-to-back timed frames (2 warm-up).
    let sample_ms = |r: &mut Renderer| -> anyhow::Result<f64> {
        r.set_frame_mode(FrameMode::Timed);
        let mut v = Vec::new();
        for i in 0..args.repeat + 2 {
            r.render(&input);
            if let Some(t) = r.wait_new_timings()
                && i >= 2
            {
                v.push(t.get("slc_sample").unwrap_or(f64::NAN));
            }
        }
        median(v).ok_or_else(|| anyhow!("no timestamps came back"))
    };
    let with = sample_ms(&mut r)?;
    let mut open = s.clone();
    open.gi.shadow_rays = false;
    r.set_settings(open)?;
    let without = sample_ms(&mut r)?;
    let rate = rays as f64 / ((with - without).max(1e-9) * 1e-3) / 1e6;
    println!(
        "in-frame shadow rays, {layout:?} BVH (SLC's sampling pass, {}x{}, {} spp, {} VPLs; GPU \
         timestamps of slc_sample): {rays} rays per frame; pass {with:.3} ms with them, \
         {without:.3} ms without: {rate:.2} Mrays/s",
        size.0,
        size.1,
        SamplingSettings::of(&s).cut_size,
        s.vpl.count,
    );
    if let Some(e) = r.ctx.errors.take().into_iter().next() {
        return Err(anyhow!("GPU error: {e}"));
    }
    Ok(InFrame {
        timing: Some(InFrameTiming { with, rate }),
        vpls,
    })
}

pub(super) fn in_frame_settings(opened: &crate::scene::preset::OpenedScene) -> RenderSettings {
    let mut s = RenderSettings::default();
    s.display.exposure_ev = opened.exposure_ev;
    s.gi.method = crate::methods::tree_samplers::SLC;
    s.frame.accumulate = false;
    s
}

/// The machine-independent proxy of the in-frame rays: SLC's shadow rays, drawn on the CPU
/// as the sampling pass draws them (the frame's VPLs, the CPU twin of the tree, a light cut of
/// `cut_size` nodes per pixel and a descent by the child probabilities to a leaf per cut
/// node; `reference::slc`) from the G-buffer points of every k-th pixel, traced through both
/// layouts with counters. Returns the rays answered differently.
pub(super) fn in_frame_proxy(
    args: &BenchArgs,
    opened: &crate::scene::preset::OpenedScene,
    bvh: &Bvh,
    wide: &WideBvh,
    vpls: &[GpuVpl],
) -> anyhow::Result<usize> {
    use crate::reference::{gbuffer, slc, sst_tree};
    let scene = &opened.scene;
    let camera = scene
        .camera_or_default(opened.camera_name.as_deref())
        .map_err(|e| anyhow!("{e}"))?;
    let s = in_frame_settings(opened);
    let (w, h) = (args.width, args.height);
    let stride = (((w as f64 * h as f64) / args.proxy_pixels.max(1) as f64)
        .sqrt()
        .ceil() as u32)
        .max(1);
    let (pw, ph) = (w.div_ceil(stride), h.div_ceil(stride));
    let samples = gbuffer::raycast(scene, bvh, &camera, pw, ph);
    let nodes = sst_tree::build(&sst_tree::sort_vpls(vpls));
    let leaves = (nodes.len() / 2) as u32;
    let (eps, offset) = (s.gi.distance_epsilon, s.gi.ray_offset);
    let cp = SamplingSettings::of(&s).child_probability;
    let mut rng = Pcg32::new(args.seed ^ 0x51C);
    let mut rays = Vec::new();
    for smp in samples.iter().flatten() {
        let (p, n) = (smp.position, smp.normal);
        for start in slc::build_cut(&nodes, p, n, eps, SamplingSettings::of(&s).cut_size, true) {
            let mut k = start;
            while k < leaves {
                let (l, r) = (&nodes[2 * k as usize], &nodes[2 * k as usize + 1]);
                let Some(pl) = slc::child_probability(l, r, p, n, eps, cp) else {
                    break;
                };
                k = if rng.next_f32() < pl { 2 * k } else { 2 * k + 1 };
            }
            let leaf = &nodes[k as usize];
            if k < leaves || leaf.is_empty() {
                continue;
            }
            let o = p + n * offset;
            let e = leaf.position + leaf.normal * offset;
            if n.dot(e - o) <= 0.0 || leaf.normal.dot(o - e) <= 0.0 {
                continue;
            }
            rays.push(Ray::new(o, e - o, 1e-4, 1.0 - 1e-4));
        }
    }
    let (cb, cw, differ) = count_both(bvh, wide, &rays, true);
    print_counters(
        &format!(
            "in-frame proxy: SLC's shadow rays on the CPU ({} rays from {}x{} pixels, every {stride}th \
             of {w}x{h}, {} VPLs, cut {})",
            rays.len(),
            pw,
            ph,
            vpls.len(),
            SamplingSettings::of(&s).cut_size
        ),
        &cb,
        &cw,
    );
    println!(
        "in-frame proxy: {differ} of {} rays answered differently by the two layouts",
        rays.len()
    );
    Ok(differ)
}

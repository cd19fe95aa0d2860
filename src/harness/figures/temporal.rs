//! `results temporal`: the temporal stage (reprojection + history + SVGF, Schied et al. 2017)
//! after every per-frame method, on three repeatable motions: a camera path through the
//! scene's bookmarks (`--temporal-path-frames` from first to last, its first `--temporal-frames`
//! measured: a few pixels of motion per frame), a sun sweep (`--sun-sweep-deg` over the
//! frames) and a still view. Per frame and method: RMSE, the image-mean ratio and SSIM of the
//! raw estimate and of the stage's output against the ground truth of that frame's VPLs
//! (`temporal_summary.csv`: their means over the frames), and flicker (the frame-to-frame
//! change in static pixels beyond the truth's own change, over the second half of the frames,
//! after the history's warm-up). Then the stage's GPU time per pass at
//! `--temporal-timing-width x height` (1280 x 720 by default) along the path.

use super::*;
use crate::harness::{
    median,
    sequence::{self, Motion, SeqFrame},
};
use crate::settings::TemporalMode;

/// The stage's passes (timer names), in order.
const PASSES: [&str; 5] = [
    "temporal_reproject",
    "temporal_accumulate",
    "temporal_variance",
    "temporal_atrous",
    "temporal_modulate",
];

/// The motions of the figure at `frames` frames.
fn motions(b: &Bench, o: &Opts) -> anyhow::Result<Vec<Motion>> {
    let n = o.temporal_frames as usize;
    let step = 0.1 * b.scene_radius;
    let keys = Motion::path_keys(&b.bookmarks, &b.camera, step);
    Ok(vec![
        Motion::through(&keys, o.temporal_path_frames.max(o.temporal_frames), &b.lights)?.first(n),
        Motion::sun_sweep(&b.camera, &b.lights, o.sun_sweep_deg, o.temporal_frames)?,
        Motion::still(&b.camera, &b.lights, o.temporal_frames),
    ])
}

/// The stage's settings for the figure: the base settings' if they switch it on, else SVGF's
/// defaults.
fn stage(b: &Bench, method: MethodId) -> RenderSettings {
    with(b, |s| {
        s.gi.method = method;
        s.frame.accumulate = false;
        if s.temporal.mode == TemporalMode::Off {
            s.temporal.mode = TemporalMode::Svgf;
        }
    })
}

fn mean_finite(v: impl Iterator<Item = f64>) -> f64 {
    let x: Vec<f64> = v.filter(|x| x.is_finite()).collect();
    if x.is_empty() { f64::NAN } else { mean_std(&x).0 }
}

inventory::submit! {
    FigureDef {
        cli: "temporal",
        label: "Temporal",
        order: 70,
        doc: "Temporal reuse (reprojection, history, SVGF) after every per-frame method along a camera path, a sun sweep and a still view: per-frame RMSE / SSIM of raw and filtered GI against each frame's ground truth, flicker, and the stage's GPU time per pass.",
        make: temporal,
    }
}

pub fn temporal(b: &mut Bench, o: &Opts, dir: &Path) -> anyhow::Result<Report> {
    let methods = methods(o);
    let motions = motions(b, o)?;
    if b.r.size() != o.size {
        b.r.resize(o.size.0, o.size.1)?;
    }
    let per_frame = Csv::new(&[
        "scene",
        "motion",
        "method",
        "frame",
        "rmse_raw",
        "rmse_filtered",
        "mean_ratio_raw",
        "mean_ratio_filtered",
        "ssim_raw",
        "ssim_filtered",
        "flicker_raw",
        "flicker_filtered",
        "static_pixels",
    ]);
    let summary = Csv::new(&[
        "scene",
        "motion",
        "method",
        "temporal",
        "frames",
        "rmse_raw",
        "rmse_filtered",
        "rmse_ratio",
        "mean_ratio_raw",
        "mean_ratio_filtered",
        "ssim_raw",
        "ssim_filtered",
        "flicker_raw",
        "flicker_filtered",
    ]);
    let mut report = Report {
        table: String::new(),
        checks: Vec::new(),
    };
    report.table += &format!(
        "temporal stage ({}) at {}x{}, {} frames per motion, vs each frame's ground truth ({}):\n{:<22} {:<10} {:>10} {:>10} {:>6} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8}\n",
        stage(b, SLC).temporal.mode.cli(),
        o.size.0,
        o.size.1,
        o.temporal_frames,
        b.adapter,
        "motion",
        "method",
        "RMSE raw",
        "filtered",
        "ratio",
        "mean raw",
        "filt.",
        "SSIM raw",
        "filt.",
        "flick.raw",
        "filt."
    );
    let mut out = Out {
        per_frame,
        summary,
        report,
    };
    // Flicker bars (raw, filtered) per method, for the motions with static pixels.
    let mut flicker_bars: Vec<(String, Vec<plot::Bar>)> = Vec::new();
    for m in &motions {
        let t0 = std::time::Instant::now();
        let truths = sequence::ground_truths(&mut b.r, &b.base, m, |_| {})?;
        b.gpu_wall += t0.elapsed();
        if b.verbose {
            eprintln!(
                "[{}] temporal: {} ground truths of the {} in {:.1} s",
                b.scene,
                truths.len(),
                m.name,
                t0.elapsed().as_secs_f64()
            );
        }
        let mut plots = MotionPlots::default();
        for (ci, &(method, short)) in methods.iter().enumerate() {
            one_method(b, o, m, &truths, (ci, method, short), &mut out, &mut plots)?;
        }
        let file = m.name.replace([' ', '+'], "_").replace("__", "_");
        plot::lines(
            &dir.join(format!("temporal_rmse_{file}.png")),
            &format!("{}: filtered / raw GI RMSE per frame ({})", b.scene, m.name),
            "frame",
            "RMSE ratio (vs each frame's ground truth)",
            &plots.series,
            false,
            true,
        )?;
        if !plots.bars.is_empty() {
            flicker_bars.push((file, plots.bars));
        }
    }
    for (file, bars) in &flicker_bars {
        plot::bars(
            &dir.join(format!("temporal_flicker_{file}.png")),
            &format!(
                "{}: flicker, raw (grey) vs filtered ({})",
                b.scene,
                file.replace('_', " ")
            ),
            "sum |dI - dG| / sum G, static pixels",
            bars,
            true,
        )?;
    }
    out.per_frame.write(&dir.join("temporal.csv"))?;
    out.summary.write(&dir.join("temporal_summary.csv"))?;
    stage_timing(b, o, &methods, &motions[0], &mut out.report, dir)?;
    b.r.resize(o.size.0, o.size.1)?;
    Ok(out.report)
}

/// What the figure gathers over motions and methods.
struct Out {
    per_frame: Csv,
    summary: Csv,
    report: Report,
}

/// One motion's plots: per method its filtered / raw RMSE per frame and its flicker bars.
#[derive(Default)]
struct MotionPlots {
    bars: Vec<plot::Bar>,
    series: Vec<plot::Series>,
}

/// One method along one motion: its frames (CSV rows), their means (summary row, table line,
/// the thesis method's checks) and its plot series.
fn one_method(
    b: &mut Bench,
    o: &Opts,
    m: &Motion,
    truths: &[sequence::Truth],
    (ci, method, short): (usize, MethodId, &str),
    out: &mut Out,
    plots: &mut MotionPlots,
) -> anyhow::Result<()> {
    let s = stage(b, method);
    let (frames, rendering): (Vec<SeqFrame>, _) = sequence::measure(
        &mut b.r,
        &s,
        m,
        truths,
        b.gi_exposure,
        b.base.display.tonemap,
        |_, _| Ok(()),
    )?;
    b.gpu_wall += rendering;
    for (i, f) in frames.iter().enumerate() {
        out.per_frame.row(vec![
            b.scene.clone(),
            m.name.clone(),
            method.cli().into(),
            i.to_string(),
            num(f.rmse_raw),
            num(f.rmse_filtered),
            num(f.mean_ratio_raw),
            num(f.mean_ratio_filtered),
            num(f.ssim_raw),
            num(f.ssim_filtered),
            num(f.flicker_raw),
            num(f.flicker_filtered),
            f.static_pixels.to_string(),
        ]);
    }
    let avg = |g: fn(&SeqFrame) -> f64| mean_finite(frames.iter().map(g));
    let (rr, rf) = (avg(|f| f.rmse_raw), avg(|f| f.rmse_filtered));
    // The image-mean ratios averaged over the frames as the RMSEs are (each frame's
    // against its own truth: a mean of ratios, not the ratio of mean images).
    let (mr, mf) = (avg(|f| f.mean_ratio_raw), avg(|f| f.mean_ratio_filtered));
    // Flicker over the second half: the first frames are the history's warm-up (the
    // filter's variance estimate settling), not frame-to-frame instability.
    let late = |g: fn(&SeqFrame) -> f64| mean_finite(frames.iter().skip(frames.len() / 2).map(g));
    let (fr, ff) = (late(|f| f.flicker_raw), late(|f| f.flicker_filtered));
    out.summary.row(vec![
        b.scene.clone(),
        m.name.clone(),
        method.cli().into(),
        s.temporal.mode.cli().into(),
        frames.len().to_string(),
        num(rr),
        num(rf),
        num(rf / rr),
        num(mr),
        num(mf),
        num(avg(|f| f.ssim_raw)),
        num(avg(|f| f.ssim_filtered)),
        num(fr),
        num(ff),
    ]);
    out.report.table += &format!(
        "{:<22} {:<10} {:>10.3e} {:>10.3e} {:>6.3} {:>8.4} {:>8.4} {:>8.4} {:>8.4} {:>8.4} {:>8.4}\n",
        m.name,
        short,
        rr,
        rf,
        rf / rr,
        mr,
        mf,
        avg(|f| f.ssim_raw),
        avg(|f| f.ssim_filtered),
        fr,
        ff
    );
    // The claim, for the thesis's method: its error and flicker drop.
    if method == SLC && m.name != "still" {
        out.report.checks.push(check(
            b,
            &format!("temporal: {short} {} filtered/raw RMSE", m.name),
            rf / rr,
            1.0,
            false,
            format!(
                "mean over {} frames at {}x{}, vs each frame's ground truth",
                frames.len(),
                o.size.0,
                o.size.1
            ),
        ));
    }
    if method == SLC && fr.is_finite() && ff.is_finite() {
        out.report.checks.push(check(
            b,
            &format!("temporal: {short} {} filtered/raw flicker", m.name),
            ff / fr,
            1.0,
            false,
            "sum |dI - dG| / sum G over static pixels of consecutive frames, second half".into(),
        ));
    }
    if fr.is_finite() && ff.is_finite() {
        // The method's name under its filtered bar, the raw one grey beside it.
        for (label, v, c) in [(String::new(), fr, 8), (short.to_string(), ff, ci)] {
            plots.bars.push(plot::Bar {
                label,
                value: v,
                spread: 0.0,
                color: c,
            });
        }
    }
    plots.series.push(plot::Series {
        name: short.to_string(),
        color: ci,
        points: frames
            .iter()
            .enumerate()
            .map(|(i, f)| (i as f64, f.rmse_filtered / f.rmse_raw))
            .collect(),
    });
    Ok(())
}

/// GPU time of the stage's passes along the path at the timing size
/// (`temporal_timing.csv`).
fn stage_timing(
    b: &mut Bench,
    o: &Opts,
    methods: &[(MethodId, &str)],
    path: &Motion,
    report: &mut Report,
    dir: &Path,
) -> anyhow::Result<()> {
    let tsize = o.temporal_timing_size;
    b.r.resize(tsize.0, tsize.1)?;
    let mut timing = Csv::new(&[
        "scene",
        "method",
        "width",
        "height",
        "frames",
        "pass",
        "median_ms",
        "mean_ms",
        "min_ms",
        "max_ms",
    ]);
    report.table += &format!(
        "temporal stage GPU time (GPU timestamps, median of {} timed frames along the path at {}x{}, {}):\n",
        o.timing_frames.min(path.len() as u32),
        tsize.0,
        tsize.1,
        b.adapter
    );
    for (method, short) in methods {
        let s = stage(b, *method);
        let t0 = std::time::Instant::now();
        let timed = sequence::time(&mut b.r, &s, path, o.timing_frames as usize, 2)?;
        b.gpu_wall += t0.elapsed();
        if timed.is_empty() {
            report.table += "  timestamps not supported on this adapter\n";
            break;
        }
        let mut line = format!("  {short:<10}");
        let mut rows: Vec<(String, Vec<f64>)> = PASSES
            .iter()
            .map(|p| (p.to_string(), timed.iter().filter_map(|t| t.get(p)).collect()))
            .collect();
        rows.push((
            "temporal stage".into(),
            timed.iter().map(sequence::temporal_ms).collect(),
        ));
        rows.push((
            format!("{short} GI"),
            timed
                .iter()
                .map(|t| method.info().timed_passes.iter().filter_map(|p| t.get(p)).sum())
                .collect(),
        ));
        for (name, v) in &rows {
            if v.is_empty() {
                continue;
            }
            let (mean, _) = mean_std(v);
            let min = v.iter().copied().fold(f64::INFINITY, f64::min);
            let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            timing.row(vec![
                b.scene.clone(),
                method.cli().into(),
                tsize.0.to_string(),
                tsize.1.to_string(),
                v.len().to_string(),
                name.clone(),
                num(median(v)),
                num(mean),
                num(min),
                num(max),
            ]);
            line += &format!(" {name} {:.3}", median(v));
        }
        report.table += &line;
        report.table += " ms\n";
    }
    timing.write(&dir.join("temporal_timing.csv"))?;
    Ok(())
}

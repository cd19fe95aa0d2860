//! Issue 23's bounce-count figure: multi-bounce VPLs (`vpl.bounces`, light paths through the
//! BVH) at 1..=4 bounces (`results --bounce-counts`). Per depth: the light the ground truth of the frame's VPLs gathers
//! (its image mean, against one bounce), the light paths' GPU time, and every per-frame
//! method's GI time and error (RMSE, relative RMSE, the image-mean ratio) against the ground
//! truth of its own VPLs. Bounces 2..=N take `count / N` VPL slots each, so a method sees
//! fewer bounce-1 VPLs as N grows. Depths above 1 run twice: with paths started by flux (the
//! SST paper, `vpl.path_flux_mix = 1`) and mixed with the BRSM importance (0.1), the setting
//! measured against the faithful version.

use super::*;
use crate::harness::LIGHT_PATH_PASSES;

/// The path-start mixes at depths above 1: faithful first.
const MIXES: [f32; 2] = [1.0, 0.1];

fn image_mean(img: &crate::gpu::readback::ImageF32) -> f64 {
    let n = img.pixels.len().max(1) as f64;
    img.pixels
        .iter()
        .map(|p| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64)
        .sum::<f64>()
        / n
}

inventory::submit! {
    FigureDef {
        cli: "bounces",
        label: "Bounces",
        order: 90,
        doc: "Issue 23: multi-bounce VPLs at 1..=4 bounces: the light the ground truth gathers, the light paths' GPU time, every per-frame method's time and relative error.",
        make: bounces,
    }
}

pub fn bounces(b: &mut Bench, o: &Opts, dir: &Path) -> anyhow::Result<Report> {
    let mut csv = Csv::new(&[
        "scene",
        "bounces",
        "path_flux_mix",
        "method",
        "light_paths_gpu_ms",
        "gi_gpu_ms",
        "rmse",
        "rmse_std",
        "relative_rmse",
        "ssim",
        "mean_ratio",
        "gt_mean",
        "gt_mean_over_one_bounce",
        "path_vpls_alive",
    ]);
    let list: Vec<(MethodId, &str)> = methods(o)
        .into_iter()
        .filter(|(m, _)| m.per_frame() && m.refuses_bounces(2).is_none())
        .collect();
    let mut table = format!(
        "bounces {:?} ({} VPL slots; bounces 2..N take count/N each); light paths and GI: GPU timestamps; error vs the ground truth of the same VPLs:\n",
        o.bounces, b.base.vpl.count
    );
    let mut one_bounce_mean = f64::NAN;
    // Per (mix, method): (bounces, relative RMSE) for the plot.
    let mut series: Vec<plot::Series> = Vec::new();
    let mut gt_series: Vec<plot::Series> = Vec::new();
    for (xi, &mix) in MIXES.iter().enumerate() {
        let mut per_method: Vec<Vec<(f64, f64)>> = vec![Vec::new(); list.len()];
        let mut gt_points = Vec::new();
        for &n in &o.bounces {
            if n == 1 && xi > 0 {
                // One bounce has no paths: the faithful run's row stands for both.
                for (k, pts) in per_method.iter_mut().enumerate() {
                    if let Some(p) = series.get(k).and_then(|s| s.points.first()) {
                        pts.push(*p);
                    }
                }
                gt_points.push((1.0, 1.0));
                continue;
            }
            let base = with(b, |s| {
                s.vpl.bounces = n;
                s.vpl.path_flux_mix = mix;
            });
            let gt = b.ground_truth(&base, o.size)?;
            let gt_mean = image_mean(&gt);
            if n == 1 {
                one_bounce_mean = gt_mean;
            }
            let alive = if n > 1 { path_vpls_alive(b)? } else { 0 };
            let over_one = gt_mean / one_bounce_mean;
            gt_points.push((n as f64, over_one));
            for (k, &(method, label)) in list.iter().enumerate() {
                let s = with(b, |s| {
                    s.vpl.bounces = n;
                    s.vpl.path_flux_mix = mix;
                    s.gi.method = method;
                });
                let m = b.measure(&s, o.size, o.per_config(), true)?;
                let gi = m.gi_ms().0;
                // One bounce runs no light-path pass.
                let paths = if n > 1 {
                    m.pass_ms(&LIGHT_PATH_PASSES).0
                } else {
                    0.0
                };
                let (r, rs) = m.rmse();
                let rel = r / gt_mean.max(1e-30);
                let ratio = m.mean_ratio().0;
                csv.row(vec![
                    b.scene.clone(),
                    n.to_string(),
                    num(mix as f64),
                    label.to_string(),
                    num(paths),
                    num(gi),
                    num(r),
                    num(rs),
                    num(rel),
                    num(m.ssim().0),
                    num(ratio),
                    num(gt_mean),
                    num(over_one),
                    alive.to_string(),
                ]);
                eprintln!(
                    "[{}] {label}, {n} bounces (path flux mix {mix}): light paths {paths:.3} ms, GI {gi:.3} ms GPU, relative RMSE {rel:.4}, mean {ratio:.3}x GT; ground truth {over_one:.3}x one bounce",
                    b.scene
                );
                if k == 0 || n == 1 {
                    table.push_str(&format!(
                        "  {n} bounce(s), mix {mix}: ground truth {over_one:.3}x one bounce, {alive} path VPLs; light paths {paths:.3} ms; {label} GI {gi:.3} ms, relative RMSE {rel:.4}, mean {ratio:.3}x GT\n"
                    ));
                }
                per_method[k].push((n as f64, rel));
            }
        }
        for (k, pts) in per_method.into_iter().enumerate() {
            let label = list[k].1;
            let name = if xi == 0 {
                format!("{label} (paths by flux)")
            } else {
                format!("{label} (path flux mix {mix})")
            };
            series.push(plot::Series {
                name,
                color: if xi == 0 { k } else { k + list.len() },
                points: pts,
            });
        }
        gt_series.push(plot::Series {
            name: format!("ground truth / one bounce (path flux mix {mix})"),
            color: xi,
            points: gt_points,
        });
    }
    csv.write(&dir.join("bounces.csv"))?;
    write_plots(b, dir, &series, &gt_series)?;
    Ok(Report {
        table,
        checks: Vec::new(),
    })
}

/// The bounces' VPLs that their light paths kept (bounces 2..=N; Russian roulette and misses
/// leave slots empty).
fn path_vpls_alive(b: &Bench) -> anyhow::Result<usize> {
    let vpls = b.r.read_vpls()?;
    let first = b.r.vpl_frame().first_bounce as usize;
    Ok(vpls[first.min(vpls.len())..]
        .iter()
        .filter(|v| v.id != crate::gpu::gpu_data::VPL_NONE)
        .count())
}

/// The relative RMSE and the gathered light against the bounces.
fn write_plots(
    b: &Bench,
    dir: &Path,
    series: &[plot::Series],
    gt_series: &[plot::Series],
) -> anyhow::Result<()> {
    plot::lines(
        &dir.join("bounces_rmse.png"),
        &format!(
            "{}: relative RMSE vs bounces (error vs the same VPLs' ground truth)",
            b.scene
        ),
        "bounces (1 = the RSM's VPLs)",
        "RMSE / ground-truth mean",
        series,
        false,
        true,
    )?;
    plot::lines(
        &dir.join("bounces_light.png"),
        &format!(
            "{}: light gathered vs bounces (ground truth image mean / one bounce)",
            b.scene
        ),
        "bounces",
        "image mean / one bounce",
        gt_series,
        false,
        false,
    )?;
    Ok(())
}

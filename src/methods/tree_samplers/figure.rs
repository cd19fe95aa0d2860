//! Thesis figures of the sampler's choices: traversal steps (fig. 7.2), block sizes (7.4)
//! and cut blending / fallbacks (7.6).

use super::SLC;
use super::settings::{CutBlending, CutFallback, SamplingSettings};
use crate::harness::figures::prelude::*;

inventory::submit! {
    FigureDef {
        cli: "steps",
        label: "Steps",
        order: 20,
        doc: "Fig. 7.2: traversal steps per pixel of the three samplers, heat maps.",
        make: steps,
    }
}

/// Thesis fig. 7.2: traversal steps of the three samplers at the base settings: means,
/// per-pixel heat maps on one scale, the distribution over pixels.
pub fn steps(b: &mut Bench, o: &Opts, dir: &Path) -> anyhow::Result<Report> {
    let mut csv = Csv::new(&[
        "scene",
        "method",
        "spp",
        "steps_per_traversal",
        "steps_per_pixel",
        "pixel_median",
        "pixel_p90",
        "dead_branch_fraction",
        "fallback_fraction",
        "sample_pass_ms",
        "sample_pass_ms_no_shadow_rays",
        "shadow_ray_share",
        "sample_pass_ms_min",
    ]);
    let spp = SamplingSettings::of(&b.base).cut_size;
    let (ms, cost) = measure_samplers(b, o)?;
    let max = ms
        .iter()
        .filter_map(|m| m.steps.as_ref().map(|s| quant(&s.2, 0.99)))
        .fold(1.0f64, f64::max) as f32;
    let img = images(dir)?;
    let mut table = format!("traversal steps ({spp} spp):\n");
    let mut bars = Vec::new();
    let mut hist = Vec::new();
    for (i, ((m, (_, label)), (with_rays, no_rays, with_rays_min))) in
        ms.iter().zip(tree_methods(o)).zip(&cost).enumerate()
    {
        let (med, p90) = m
            .steps
            .as_ref()
            .map_or((f64::NAN, f64::NAN), |s| (quant(&s.2, 0.5), quant(&s.2, 0.9)));
        let dead = m
            .stats
            .map_or(f64::NAN, |s| s.dead as f64 / s.traversals.max(1) as f64);
        csv.row(vec![
            b.scene.clone(),
            label.to_string(),
            spp.to_string(),
            num(m.steps_per_traversal()),
            num(m.steps_per_pixel()),
            num(med),
            num(p90),
            num(dead),
            num(m.fallback_fraction()),
            num(*with_rays),
            num(*no_rays),
            num(1.0 - no_rays / with_rays),
            num(*with_rays_min),
        ]);
        table.push_str(&format!(
            "  {label:<6} {:>6.2} per traversal, {:>7.1} per pixel (median pixel {med:.2}, p90 {p90:.2}); \
             sampling pass {with_rays:.1} ms, {no_rays:.1} ms without shadow rays\n",
            m.steps_per_traversal(),
            m.steps_per_pixel()
        ));
        bars.push(plot::Bar {
            label: label.into(),
            value: m.steps_per_traversal(),
            spread: 0.0,
            color: i,
        });
        if let Some((w, h, v)) = &m.steps {
            plot::heatmap(
                &img.join(format!("steps_{}.png", label.to_lowercase())),
                &format!(
                    "{label}: traversal steps per traversal, mean {:.2}",
                    m.steps_per_traversal()
                ),
                *w,
                *h,
                v,
                max,
            )?;
            hist.push(plot::Series {
                name: label.into(),
                color: i,
                points: histogram(v, max),
            });
        }
    }
    csv.write(&dir.join("steps.csv"))?;
    plot::bars(
        &dir.join("steps.png"),
        &format!("{}: traversal steps per traversal ({spp} spp)", b.scene),
        "steps",
        &bars,
        false,
    )?;
    plot::lines(
        &dir.join("steps_hist.png"),
        &format!("{}: pixels by traversal steps per traversal", b.scene),
        "steps per traversal (bins of 0.5)",
        "fraction of pixels",
        &hist,
        false,
        false,
    )?;
    let v: Vec<f64> = ms.iter().map(|m| m.steps_per_traversal()).collect();
    let detail = format!("mean steps per traversal, {spp} spp each (= per pixel at equal samples)");
    Ok(Report {
        table,
        checks: vec![
            check(
                b,
                "traversal steps SLC / SST",
                v[0] / v[2],
                0.5,
                false,
                detail.clone(),
            ),
            check(b, "traversal steps SLC / RTSLC", v[0] / v[1], 0.35, false, detail),
        ],
    })
}

/// A sampler's sampling pass (ms): with shadow rays, without, the fastest frame's with.
type Cost = (f64, f64, f64);

/// The samplers measured at the base settings, and per sampler its sampling pass's GPU time
/// with shadow rays, without them (the same traversals and evaluations, every sample
/// visible) and its fastest frame's.
fn measure_samplers(b: &mut Bench, o: &Opts) -> anyhow::Result<(Vec<Measured>, Vec<Cost>)> {
    let mut ms: Vec<Measured> = Vec::new();
    let mut cost = Vec::new();
    for (method, _) in tree_methods(o) {
        let s = with(b, |s| s.gi.method = method);
        let m = b.measure(&s, o.size, o.per_config(), false)?;
        let mut no_rays = s.clone();
        no_rays.gi.shadow_rays = false;
        let open = b.measure(&no_rays, o.size, o.per_config(), false)?;
        cost.push((
            m.pass_ms(&SAMPLE_PASSES).0,
            open.pass_ms(&SAMPLE_PASSES).0,
            m.pass_ms_min(&SAMPLE_PASSES),
        ));
        ms.push(m);
    }
    Ok((ms, cost))
}

/// The `q`-quantile of the finite values (NaN without any).
fn quant(v: &[f32], q: f64) -> f64 {
    let mut f: Vec<f32> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if f.is_empty() {
        return f64::NAN;
    }
    f.sort_by(|a, b| a.total_cmp(b));
    f[((f.len() - 1) as f64 * q).round() as usize] as f64
}

/// The distribution of the finite values over bins of 0.5 steps up to `max`: (bin centre,
/// fraction of the values).
fn histogram(v: &[f32], max: f32) -> Vec<(f64, f64)> {
    let bins = (max / 0.5).ceil().max(1.0) as usize + 1;
    let mut c = vec![0usize; bins];
    let mut n = 0usize;
    for x in v.iter().filter(|x| x.is_finite()) {
        c[((x / 0.5) as usize).min(bins - 1)] += 1;
        n += 1;
    }
    c.iter()
        .enumerate()
        .map(|(k, c)| (k as f64 * 0.5 + 0.25, *c as f64 / n.max(1) as f64))
        .collect()
}

inventory::submit! {
    FigureDef {
        cli: "blocks",
        label: "Blocks",
        order: 100,
        doc: "Fig. 7.5: block size sweep (cut build time, frame time, RMSE).",
        make: blocks,
    }
}

/// Thesis fig. 7.5: SLC over block sizes k: cut-building and sampling GPU time (timed
/// frames), frame wall clock (a separate column), RMSE and the image-mean ratio against the
/// ground truth.
pub fn blocks(b: &mut Bench, o: &Opts, dir: &Path) -> anyhow::Result<Report> {
    let mut csv = Csv::new(&[
        "scene",
        "block",
        "cuts",
        "cuts_gpu_ms",
        "cuts_gpu_ms_std",
        "sample_gpu_ms",
        "gi_gpu_ms",
        "sample_gpu_ms_min",
        "frame_wall_ms",
        "frame_wall_ms_std",
        "rmse",
        "rmse_std",
        "mean_ratio",
        "ssim",
        "fallback_fraction",
    ]);
    let gt = b.ground_truth(&b.base.clone(), o.size)?;
    let img = images(dir)?;
    let mut rows = Vec::new();
    let mut table = "block size sweep (SLC):\n".to_string();
    for &k in &o.blocks {
        let s = with(b, |s| {
            s.gi.method = SLC;
            SamplingSettings::edit(s, |m| m.block_size = k);
        });
        let m = b.measure(&s, o.size, o.per_config(), true)?;
        let cuts = o.size.0.div_ceil(k) * o.size.1.div_ceil(k);
        let (c, cs) = m.pass_ms(&["slc_cuts"]);
        let (t, ts) = m.frame_ms();
        let (r, rs) = m.rmse();
        csv.row(vec![
            b.scene.clone(),
            k.to_string(),
            cuts.to_string(),
            num(c),
            num(cs),
            num(m.pass_ms(&["slc_sample"]).0),
            num(m.gi_ms().0),
            num(m.pass_ms_min(&["slc_sample"])),
            num(t),
            num(ts),
            num(r),
            num(rs),
            num(m.mean_ratio().0),
            num(m.ssim().0),
            num(m.fallback_fraction()),
        ]);
        table.push_str(&format!(
            "  k = {k:<3} {cuts:>6} cuts: {c:>9.3} ms to build, GI {:>8.3} ms (GPU), frame {t:>8.1} ms (wall), RMSE {r:.4e}, mean {:.3}x GT, SSIM {:.3}\n",
            m.gi_ms().0,
            m.mean_ratio().0,
            m.ssim().0
        ));
        if let Some(ind) = &m.indirect {
            b.write_gi_png(&img.join(format!("block_{k}.png")), ind)?;
            b.write_error_png(&img.join(format!("block_{k}_error.png")), ind, &gt)?;
        }
        rows.push((k, c, m.gi_ms().0, r));
    }
    csv.write(&dir.join("blocks.csv"))?;
    plot::lines(
        &dir.join("blocks_rmse.png"),
        &format!("{}: RMSE over the block size (SLC)", b.scene),
        "block size k (pixels)",
        "RMSE of one frame's GI",
        &[plot::Series {
            name: "SLC".into(),
            color: 0,
            points: rows.iter().map(|r| (r.0 as f64, r.3)).collect(),
        }],
        true,
        false,
    )?;
    plot::lines(
        &dir.join("blocks_time.png"),
        &format!("{}: time over the block size (SLC)", b.scene),
        "block size k (pixels)",
        "ms",
        &[
            plot::Series {
                name: "light cuts (GPU)".into(),
                color: 4,
                points: rows.iter().map(|r| (r.0 as f64, r.1)).collect(),
            },
            plot::Series {
                name: "GI: cuts + sampling (GPU)".into(),
                color: 0,
                points: rows.iter().map(|r| (r.0 as f64, r.2)).collect(),
            },
        ],
        true,
        true,
    )?;
    let mut checks = Vec::new();
    let k1 = rows.iter().find(|r| r.0 == 1);
    let k8 = rows.iter().find(|r| r.0 == 8);
    if let (Some(a), Some(c)) = (k1, k8) {
        checks.push(check(
            b,
            "cut build time k=1 / k=8",
            a.1 / c.1,
            20.0,
            true,
            "GPU time of the slc_cuts pass".into(),
        ));
        checks.push(check(
            b,
            "RMSE k=8 / k=1",
            c.3 / a.3,
            1.10,
            false,
            "mean per-frame RMSE of SLC's GI".into(),
        ));
    }
    Ok(Report { table, checks })
}

inventory::submit! {
    FigureDef {
        cli: "blending",
        label: "Blending",
        order: 110,
        doc: "Fig. 7.4 / 7.6: no blending vs blending; mock cut vs averaging vs root vs recomputed cut.",
        make: blending,
    }
}

/// Thesis fig. 7.4 and 7.6: no blending vs blending, and the fallbacks for pixels without a
/// similar cut (mock cut, averaging, root traversal, recomputed cut): images, error maps,
/// RMSE over the image and over the fallback pixels, the image-mean ratio, time.
pub fn blending(b: &mut Bench, o: &Opts, dir: &Path) -> anyhow::Result<Report> {
    let configs = [
        (
            "no blending",
            "no_blending",
            CutBlending::Off,
            CutFallback::MockCut,
        ),
        (
            "blending + mock cut",
            "mock_cut",
            CutBlending::Stochastic,
            CutFallback::MockCut,
        ),
        (
            "averaged cuts",
            "average",
            CutBlending::Stochastic,
            CutFallback::Average,
        ),
        (
            "root traversal",
            "root",
            CutBlending::Stochastic,
            CutFallback::Root,
        ),
        (
            "recomputed cut",
            "recompute",
            CutBlending::Stochastic,
            CutFallback::Recompute,
        ),
    ];
    let mut csv = Csv::new(&[
        "scene",
        "config",
        "blending",
        "fallback",
        "frame_wall_ms",
        "gi_gpu_ms",
        "rmse",
        "rmse_std",
        "mean_ratio",
        "rmse_fallback_pixels",
        "ssim",
        "fallback_fraction",
    ]);
    let gt = b.ground_truth(&b.base.clone(), o.size)?;
    let img = images(dir)?;
    let mut table = "cut blending and fallbacks (SLC):\n".to_string();
    let (mut rbars, mut tbars) = (Vec::new(), Vec::new());
    for (i, (label, file, blend, fb)) in configs.iter().enumerate() {
        let s = with(b, |s| {
            s.gi.method = SLC;
            SamplingSettings::edit(s, |m| m.blending = *blend);
            SamplingSettings::edit(s, |m| m.fallback = *fb);
        });
        let m = b.measure(&s, o.size, o.per_config(), true)?;
        let (r, rs) = m.rmse();
        let rf = mean_std(
            &m.rmse_fallback
                .iter()
                .copied()
                .filter(|v| v.is_finite())
                .collect::<Vec<_>>(),
        )
        .0;
        let gi = m.pass_ms(&gi_passes()).0;
        csv.row(vec![
            b.scene.clone(),
            label.to_string(),
            format!("{blend:?}"),
            format!("{fb:?}"),
            num(m.frame_ms().0),
            num(gi),
            num(r),
            num(rs),
            num(m.mean_ratio().0),
            num(rf),
            num(m.ssim().0),
            num(m.fallback_fraction()),
        ]);
        table.push_str(&format!(
            "  {label:<20} RMSE {r:.4e} (fallback pixels {rf:.4e}), mean {:.3}x GT, SSIM {:.3}, GI {gi:.1} ms (GPU), {:.1}% fallback\n",
            m.mean_ratio().0,
            m.ssim().0,
            100.0 * m.fallback_fraction()
        ));
        if let Some(ind) = &m.indirect {
            b.write_gi_png(&img.join(format!("blend_{file}.png")), ind)?;
            b.write_error_png(&img.join(format!("blend_{file}_error.png")), ind, &gt)?;
        }
        if i == 1
            && let Some(fbm) = &m.fallback
        {
            let ind = m.indirect.as_ref().map(|x| x.pixels.as_slice()).unwrap_or(&[]);
            let rgba: Vec<u8> = fbm
                .iter()
                .enumerate()
                .flat_map(|(k, f)| {
                    if *f {
                        [230, 40, 40, 255]
                    } else {
                        let l = ind.get(k).map_or(0.0, |p| (p[0] + p[1] + p[2]) / 3.0);
                        let g = (crate::base::display::linear_to_srgb(l * 2f32.powf(b.gi_exposure)).min(1.0)
                            * 200.0) as u8;
                        [g, g, g, 255]
                    }
                })
                .collect();
            crate::export::write_png(&img.join("fallback_pixels.png"), o.size.0, o.size.1, &rgba)?;
        }
        rbars.push(plot::Bar {
            label: label.to_string(),
            value: r,
            spread: rs,
            color: i,
        });
        tbars.push(plot::Bar {
            label: label.to_string(),
            value: gi,
            spread: m.pass_ms(&gi_passes()).1,
            color: i,
        });
    }
    csv.write(&dir.join("blending.csv"))?;
    plot::bars(
        &dir.join("blending_rmse.png"),
        &format!("{}: RMSE of blending and fallbacks", b.scene),
        "RMSE of one frame's GI",
        &rbars,
        false,
    )?;
    plot::bars(
        &dir.join("blending_time.png"),
        &format!("{}: GI GPU time of blending and fallbacks", b.scene),
        "ms (cuts + sampling)",
        &tbars,
        false,
    )?;
    Ok(Report {
        table,
        checks: Vec::new(),
    })
}

//! One function per figure of thesis chapter 7. Each measures on a [`Bench`], writes
//! `<figure>.csv`, PNG plots and images into the scene's results folder, and returns a
//! [`Report`]: a short text table and the ratio checks of issue 7 it covers.

use std::path::Path;

use anyhow::Context;

use super::{Bench, Csv, GI_PASSES, Measured, PASS_GROUPS, SAMPLE_PASSES, mean_std, num, plot};
use crate::renderer::settings::{CutBlending, CutFallback, GiMethod, RenderSettings};

/// What every figure needs besides the bench.
#[derive(Clone, Debug)]
pub struct Opts {
    /// Frame size of every figure but the scaling one.
    pub size: (u32, u32),
    /// Independent frames per configuration (the first is not timed when >= 2).
    pub frames: u32,
    /// Frames of the per-pass timing table.
    pub timing_frames: u32,
    /// Samples per pixel (cut size) of the equal-time sweep.
    pub spp: Vec<u32>,
    /// Block sizes k of the block sweep.
    pub blocks: Vec<u32>,
    /// log2 of the VPL counts of the scaling sweep.
    pub vpl_exponents: Vec<u32>,
    /// Frame size of the scaling sweep (a ground truth per VPL count).
    pub scaling_size: (u32, u32),
    /// Frame sizes of the upsampling table, as multiples of `size`.
    pub upsampling_scales: Vec<f32>,
}

/// A ratio the issue asks for: `value` must be <= `limit` (or >= it with `at_least`).
#[derive(Clone, Debug)]
pub struct Check {
    pub scene: String,
    pub name: String,
    pub value: f64,
    pub limit: f64,
    pub at_least: bool,
    /// How the value was measured.
    pub detail: String,
}

impl Check {
    pub fn pass(&self) -> bool {
        if self.at_least {
            self.value >= self.limit
        } else {
            self.value <= self.limit
        }
    }
    pub fn line(&self) -> String {
        format!(
            "{:<16} {:<44} {:>8.3} {} {:<6} {}",
            self.scene,
            self.name,
            self.value,
            if self.at_least { ">=" } else { "<=" },
            self.limit,
            if self.pass() { "met" } else { "MISSED" }
        )
    }
}

/// What a figure prints and checks.
#[derive(Default)]
pub struct Report {
    pub table: String,
    pub checks: Vec<Check>,
}

/// The three samplers, in the order (and colours) of every plot.
pub const METHODS: [(GiMethod, &str); 3] = [
    (GiMethod::Slc, "SLC"),
    (GiMethod::Rtslc, "RTSLC"),
    (GiMethod::Sst, "SST"),
];

fn with(b: &Bench, f: impl FnOnce(&mut RenderSettings)) -> RenderSettings {
    let mut s = b.base.clone();
    f(&mut s);
    s
}

fn images(dir: &Path) -> anyhow::Result<std::path::PathBuf> {
    let d = dir.join("images");
    std::fs::create_dir_all(&d).with_context(|| format!("cannot create {}", d.display()))?;
    Ok(d)
}

fn check(b: &Bench, name: &str, value: f64, limit: f64, at_least: bool, detail: String) -> Check {
    Check {
        scene: b.scene.clone(),
        name: name.into(),
        value,
        limit,
        at_least,
        detail,
    }
}

/// Thesis table 7.1: GPU time per pass group, mean and spread over `timing_frames` frames of
/// SLC at the base settings, plus the wall-clock frame time.
pub fn timings(b: &mut Bench, o: &Opts, dir: &Path) -> anyhow::Result<Report> {
    let s = with(b, |s| s.gi.method = GiMethod::Slc);
    let m = b.measure(&s, o.size, o.timing_frames.max(2), false)?;
    let mut csv = Csv::new(&[
        "scene", "group", "passes", "mean_ms", "std_ms", "min_ms", "max_ms", "frames",
    ]);
    let mut bars = Vec::new();
    let mut table = format!(
        "per-pass GPU time, {} frames of SLC at {}x{} ({}):\n",
        m.passes.len(),
        o.size.0,
        o.size.1,
        b.adapter
    );
    let mut rows: Vec<(String, String, Vec<f64>)> = PASS_GROUPS
        .iter()
        .map(|(g, names)| (g.to_string(), names.join("+"), m.pass_ms_per_frame(Some(names))))
        .collect();
    rows.push(("all passes (GPU)".into(), "sum".into(), m.pass_ms_per_frame(None)));
    rows.push((
        "frame (wall clock)".into(),
        "render+submit+wait".into(),
        m.frame_ms.clone(),
    ));
    for (i, (g, passes, v)) in rows.iter().enumerate() {
        let (mean, std) = mean_std(v);
        let min = v.iter().copied().fold(f64::INFINITY, f64::min);
        let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        csv.row(vec![
            b.scene.clone(),
            g.clone(),
            passes.clone(),
            num(mean),
            num(std),
            num(min),
            num(max),
            v.len().to_string(),
        ]);
        table.push_str(&format!("  {g:<20} {mean:>10.3} ms ± {std:>8.3}\n"));
        if i < PASS_GROUPS.len() {
            bars.push(plot::Bar {
                label: g.clone(),
                value: mean,
                spread: std,
                color: 0,
            });
        }
    }
    csv.write(&dir.join("timings.csv"))?;
    plot::bars(
        &dir.join("timings.png"),
        &format!("{}: GPU time per pass ({}x{})", b.scene, o.size.0, o.size.1),
        "ms (log)",
        &bars,
        true,
    )?;
    Ok(Report {
        table,
        checks: Vec::new(),
    })
}

/// Piecewise-linear interpolation of log(y) over log(x) through points sorted by x; outside
/// the range the nearest segment is extended. Returns (y, extrapolated).
pub fn interp_loglog(points: &[(f64, f64)], x: f64) -> (f64, bool) {
    let mut p: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(a, b)| *a > 0.0 && *b > 0.0 && a.is_finite() && b.is_finite())
        .map(|(a, b)| (a.ln(), b.ln()))
        .collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0));
    if p.is_empty() || x <= 0.0 {
        return (f64::NAN, true);
    }
    if p.len() == 1 {
        return (p[0].1.exp(), (p[0].0 - x.ln()).abs() > 1e-9);
    }
    let lx = x.ln();
    let outside = lx < p[0].0 || lx > p[p.len() - 1].0;
    let i = p
        .iter()
        .position(|q| q.0 >= lx)
        .unwrap_or(p.len() - 1)
        .clamp(1, p.len() - 1);
    let (a, c) = (p[i - 1], p[i]);
    let t = if (c.0 - a.0).abs() < 1e-12 {
        0.0
    } else {
        (lx - a.0) / (c.0 - a.0)
    };
    ((a.1 + t * (c.1 - a.1)).exp(), outside)
}

/// One point of the equal-time sweep: frame ms, RMSE, SSIM, samples per pixel.
type SweepPoint = (f64, f64, f64, u32);

/// Thesis fig. 7.1 and 7.3: every sampler over a sweep of samples per pixel; RMSE and SSIM
/// against the ground truth of the same VPLs over the frame time; the equal-time table
/// (each method's RMSE interpolated at SLC's frame time at the base cut size), and the
/// images and error maps of each method at its sample count for that time.
pub fn equal_time(b: &mut Bench, o: &Opts, dir: &Path) -> anyhow::Result<Report> {
    let base_spp = b.base.sampling.cut_size;
    let mut spp = o.spp.clone();
    if !spp.contains(&base_spp) {
        spp.push(base_spp);
    }
    spp.sort_unstable();
    spp.dedup();
    let mut csv = Csv::new(&[
        "scene",
        "method",
        "spp",
        "frame_ms",
        "frame_ms_std",
        "gi_gpu_ms",
        "rmse",
        "rmse_std",
        "ssim",
        "ssim_std",
        "flip",
        "mean_ratio",
        "bias_rmse",
        "noise_rmse",
        "steps_per_traversal",
        "steps_per_pixel",
    ]);
    let mut curves: Vec<Vec<SweepPoint>> = Vec::new();
    for (method, label) in METHODS.iter() {
        let mut pts = Vec::new();
        for &n in &spp {
            let s = with(b, |s| {
                s.gi.method = *method;
                s.sampling.cut_size = n;
            });
            let m = b.measure(&s, o.size, o.frames, true)?;
            let (t, ts) = m.frame_ms();
            let (r, rs) = m.rmse();
            let (q, qs) = m.ssim();
            csv.row(vec![
                b.scene.clone(),
                label.to_string(),
                n.to_string(),
                num(t),
                num(ts),
                num(m.pass_ms(&GI_PASSES).0),
                num(r),
                num(rs),
                num(q),
                num(qs),
                num(mean_std(&m.flip).0),
                num(mean_std(&m.mean_ratio).0),
                num(m.bias_rmse),
                num(m.noise_rmse),
                num(m.steps_per_traversal()),
                num(m.steps_per_pixel()),
            ]);
            eprintln!(
                "[{}] {label} {n} spp: {t:.1} ms, RMSE {r:.4e} (bias {:.2e}, noise {:.2e}, mean ratio {:.3}), SSIM {q:.3}",
                b.scene,
                m.bias_rmse,
                m.noise_rmse,
                mean_std(&m.mean_ratio).0
            );
            pts.push((t, r, q, n));
        }
        curves.push(pts);
    }
    csv.write(&dir.join("equal_time.csv"))?;
    let series = |f: &dyn Fn(&SweepPoint) -> (f64, f64)| -> Vec<plot::Series> {
        METHODS
            .iter()
            .enumerate()
            .map(|(i, (_, l))| plot::Series {
                name: l.to_string(),
                color: i,
                points: curves[i].iter().map(f).collect(),
            })
            .collect()
    };
    plot::lines(
        &dir.join("equal_time_rmse.png"),
        &format!("{}: RMSE vs frame time (spp {:?})", b.scene, spp),
        "frame time (ms, wall clock)",
        "RMSE of one frame's GI (W/(m² sr))",
        &series(&|p| (p.0, p.1)),
        true,
        true,
    )?;
    plot::lines(
        &dir.join("equal_time_ssim.png"),
        &format!("{}: SSIM vs frame time", b.scene),
        "frame time (ms, wall clock)",
        "SSIM of one frame's GI",
        &series(&|p| (p.0, p.2)),
        true,
        false,
    )?;
    // The matched time: SLC at the base cut size.
    let t_match = curves[0]
        .iter()
        .find(|p| p.3 == base_spp)
        .map_or(f64::NAN, |p| p.0);
    let mut table = format!("equal time: {t_match:.1} ms per frame (SLC at {base_spp} spp)\n");
    let mut at = Vec::new();
    let mut matched = Csv::new(&[
        "scene",
        "method",
        "matched_ms",
        "rmse_interpolated",
        "ssim_interpolated",
        "extrapolated",
        "spp_at_matched_time",
        "measured_frame_ms",
        "measured_rmse",
        "measured_ssim",
        "measured_mean_ratio",
        "measured_bias_rmse",
    ]);
    let gt = b.ground_truth(&b.base.clone(), o.size)?;
    let img = images(dir)?;
    b.write_gi_png(&img.join("ground_truth.png"), &gt)?;
    for (i, (method, label)) in METHODS.iter().enumerate() {
        let rt: Vec<(f64, f64)> = curves[i].iter().map(|p| (p.0, p.1)).collect();
        let qt: Vec<(f64, f64)> = curves[i].iter().map(|p| (p.0, p.2)).collect();
        let st: Vec<(f64, f64)> = curves[i].iter().map(|p| (p.0, p.3 as f64)).collect();
        let (r, ex) = interp_loglog(&rt, t_match);
        let (q, _) = interp_loglog(&qt, t_match);
        let (n, _) = interp_loglog(&st, t_match);
        let n = if n.is_finite() {
            (n.round() as u32).clamp(1, 64)
        } else {
            base_spp
        };
        let s = with(b, |s| {
            s.gi.method = *method;
            s.sampling.cut_size = n;
        });
        let m = b.measure(&s, o.size, o.frames, true)?;
        if let Some(ind) = &m.indirect {
            b.write_gi_png(&img.join(format!("equal_time_{}.png", label.to_lowercase())), ind)?;
            b.write_error_png(
                &img.join(format!("equal_time_{}_error.png", label.to_lowercase())),
                ind,
                &gt,
            )?;
        }
        matched.row(vec![
            b.scene.clone(),
            label.to_string(),
            num(t_match),
            num(r),
            num(q),
            ex.to_string(),
            n.to_string(),
            num(m.frame_ms().0),
            num(m.rmse().0),
            num(m.ssim().0),
            num(mean_std(&m.mean_ratio).0),
            num(m.bias_rmse),
        ]);
        table.push_str(&format!(
            "  {label:<6} RMSE {r:.4e}{} SSIM {q:.3} · {n} spp at that time (measured: {:.1} ms, RMSE {:.4e}, of it bias {:.2e}, mean {:.3}x GT)\n",
            if ex { " (extrapolated)" } else { "" },
            m.frame_ms().0,
            m.rmse().0,
            m.bias_rmse,
            mean_std(&m.mean_ratio).0
        ));
        at.push(r);
    }
    matched.write(&dir.join("equal_time_matched.csv"))?;
    let detail = format!("RMSE interpolated (log-log) at SLC's frame time with {base_spp} spp");
    let checks = vec![
        check(
            b,
            "equal-time RMSE SLC / RTSLC",
            at[0] / at[1],
            0.8,
            false,
            detail.clone(),
        ),
        check(b, "equal-time RMSE SLC / SST", at[0] / at[2], 0.6, false, detail),
    ];
    Ok(Report { table, checks })
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
    ]);
    // What each method spends: its sampling pass with shadow rays, and without them (the
    // same traversals and evaluations, every sample visible).
    let mut ms: Vec<Measured> = Vec::new();
    let mut cost = Vec::new();
    for (method, _) in METHODS {
        let s = with(b, |s| s.gi.method = method);
        let m = b.measure(&s, o.size, o.frames, false)?;
        let mut no_rays = s.clone();
        no_rays.gi.shadow_rays = false;
        let open = b.measure(&no_rays, o.size, o.frames, false)?;
        cost.push((m.pass_ms(&SAMPLE_PASSES).0, open.pass_ms(&SAMPLE_PASSES).0));
        ms.push(m);
    }
    let quant = |v: &[f32], q: f64| -> f64 {
        let mut f: Vec<f32> = v.iter().copied().filter(|x| x.is_finite()).collect();
        if f.is_empty() {
            return f64::NAN;
        }
        f.sort_by(|a, b| a.total_cmp(b));
        f[((f.len() - 1) as f64 * q).round() as usize] as f64
    };
    let max = ms
        .iter()
        .filter_map(|m| m.steps.as_ref().map(|s| quant(&s.2, 0.99)))
        .fold(1.0f64, f64::max) as f32;
    let img = images(dir)?;
    let mut table = format!("traversal steps ({} spp):\n", b.base.sampling.cut_size);
    let mut bars = Vec::new();
    let mut hist = Vec::new();
    for (i, ((m, (_, label)), (with_rays, no_rays))) in ms.iter().zip(METHODS).zip(&cost).enumerate() {
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
            b.base.sampling.cut_size.to_string(),
            num(m.steps_per_traversal()),
            num(m.steps_per_pixel()),
            num(med),
            num(p90),
            num(dead),
            num(m.fallback_fraction()),
            num(*with_rays),
            num(*no_rays),
            num(1.0 - no_rays / with_rays),
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
            // Distribution over pixels, in bins of 0.5 steps.
            let bins = (max / 0.5).ceil().max(1.0) as usize + 1;
            let mut c = vec![0usize; bins];
            let mut n = 0usize;
            for x in v.iter().filter(|x| x.is_finite()) {
                c[((x / 0.5) as usize).min(bins - 1)] += 1;
                n += 1;
            }
            hist.push(plot::Series {
                name: label.into(),
                color: i,
                points: c
                    .iter()
                    .enumerate()
                    .map(|(k, c)| (k as f64 * 0.5 + 0.25, *c as f64 / n.max(1) as f64))
                    .collect(),
            });
        }
    }
    csv.write(&dir.join("steps.csv"))?;
    plot::bars(
        &dir.join("steps.png"),
        &format!(
            "{}: traversal steps per traversal ({} spp)",
            b.scene, b.base.sampling.cut_size
        ),
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
    let detail = format!(
        "mean steps per traversal, {} spp each (= per pixel at equal samples)",
        b.base.sampling.cut_size
    );
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

/// Thesis fig. 7.5: SLC over block sizes k: cut-building GPU time, frame time, RMSE.
pub fn blocks(b: &mut Bench, o: &Opts, dir: &Path) -> anyhow::Result<Report> {
    let mut csv = Csv::new(&[
        "scene",
        "block",
        "cuts",
        "cuts_gpu_ms",
        "cuts_gpu_ms_std",
        "sample_gpu_ms",
        "frame_ms",
        "frame_ms_std",
        "rmse",
        "rmse_std",
        "ssim",
        "fallback_fraction",
    ]);
    let gt = b.ground_truth(&b.base.clone(), o.size)?;
    let img = images(dir)?;
    let mut rows = Vec::new();
    let mut table = "block size sweep (SLC):\n".to_string();
    for &k in &o.blocks {
        let s = with(b, |s| {
            s.gi.method = GiMethod::Slc;
            s.sampling.block_size = k;
        });
        let m = b.measure(&s, o.size, o.frames, true)?;
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
            num(t),
            num(ts),
            num(r),
            num(rs),
            num(m.ssim().0),
            num(m.fallback_fraction()),
        ]);
        table.push_str(&format!(
            "  k = {k:<3} {cuts:>6} cuts: {c:>9.3} ms to build, frame {t:>8.1} ms, RMSE {r:.4e}, SSIM {:.3}\n",
            m.ssim().0
        ));
        if let Some(ind) = &m.indirect {
            b.write_gi_png(&img.join(format!("block_{k}.png")), ind)?;
            b.write_error_png(&img.join(format!("block_{k}_error.png")), ind, &gt)?;
        }
        rows.push((k, c, t, r));
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
                name: "frame (wall clock)".into(),
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

/// Thesis fig. 7.4 and 7.6: no blending vs blending, and the fallbacks for pixels without a
/// similar cut (mock cut, averaging, root traversal, recomputed cut): images, error maps,
/// RMSE over the image and over the fallback pixels, time.
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
        "frame_ms",
        "gi_gpu_ms",
        "rmse",
        "rmse_std",
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
            s.gi.method = GiMethod::Slc;
            s.sampling.blending = *blend;
            s.sampling.fallback = *fb;
        });
        let m = b.measure(&s, o.size, o.frames, true)?;
        let (r, rs) = m.rmse();
        let rf = mean_std(
            &m.rmse_fallback
                .iter()
                .copied()
                .filter(|v| v.is_finite())
                .collect::<Vec<_>>(),
        )
        .0;
        let gi = m.pass_ms(&GI_PASSES).0;
        csv.row(vec![
            b.scene.clone(),
            label.to_string(),
            format!("{blend:?}"),
            format!("{fb:?}"),
            num(m.frame_ms().0),
            num(gi),
            num(r),
            num(rs),
            num(rf),
            num(m.ssim().0),
            num(m.fallback_fraction()),
        ]);
        table.push_str(&format!(
            "  {label:<20} RMSE {r:.4e} (fallback pixels {rf:.4e}), SSIM {:.3}, GI {gi:.1} ms (GPU), {:.1}% fallback\n",
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
                        let g = (crate::reference::display::linear_to_srgb(l * 2f32.powf(b.gi_exposure))
                            .min(1.0)
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
            spread: m.pass_ms(&GI_PASSES).1,
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

/// Thesis table 7.2: full vs half GI resolution at one or more frame sizes: RMSE, SSIM, frame
/// time and GI time (the frame's wall-clock time minus that of a frame without GI).
pub fn upsampling(b: &mut Bench, o: &Opts, dir: &Path) -> anyhow::Result<Report> {
    let mut csv = Csv::new(&[
        "scene",
        "width",
        "height",
        "gi_resolution",
        "rmse",
        "rmse_std",
        "ssim",
        "frame_ms",
        "gi_ms",
        "gi_gpu_ms",
    ]);
    let img = images(dir)?;
    let mut table = "upsampling (SLC):\n".to_string();
    let mut checks = Vec::new();
    let mut bars = Vec::new();
    for (si, &scale) in o.upsampling_scales.iter().enumerate() {
        let size = (
            ((o.size.0 as f32 * scale).round() as u32).max(8),
            ((o.size.1 as f32 * scale).round() as u32).max(8),
        );
        let off = with(b, |s| s.gi.method = GiMethod::Off);
        let base_ms = b.measure(&off, size, o.frames, false)?.frame_ms().0;
        let mut res = Vec::new();
        for half in [false, true] {
            let s = with(b, |s| {
                s.gi.method = GiMethod::Slc;
                s.sampling.half_resolution = half;
            });
            let m = b.measure(&s, size, o.frames, true)?;
            let (r, rs) = m.rmse();
            let t = m.frame_ms().0;
            let gi = t - base_ms;
            let label = if half { "half" } else { "full" };
            csv.row(vec![
                b.scene.clone(),
                size.0.to_string(),
                size.1.to_string(),
                label.into(),
                num(r),
                num(rs),
                num(m.ssim().0),
                num(t),
                num(gi),
                num(m.pass_ms(&GI_PASSES).0),
            ]);
            table.push_str(&format!(
                "  {}x{} {label:<4} GI: RMSE {r:.4e}, SSIM {:.3}, frame {t:.1} ms, GI {gi:.1} ms\n",
                size.0,
                size.1,
                m.ssim().0
            ));
            if si == 0
                && let Some(ind) = &m.indirect
            {
                b.write_gi_png(&img.join(format!("upsampling_{label}.png")), ind)?;
            }
            bars.push(plot::Bar {
                label: format!("{}x{} {label}", size.0, size.1),
                value: gi,
                spread: 0.0,
                color: half as usize,
            });
            res.push((r, gi));
        }
        if si == 0 {
            let detail = format!(
                "{}x{}: GI time = wall-clock frame time minus that of a frame without GI",
                size.0, size.1
            );
            checks.push(check(
                b,
                "half-res GI time / full",
                res[1].1 / res[0].1,
                0.4,
                false,
                detail,
            ));
            checks.push(check(
                b,
                "half-res RMSE / full",
                res[1].0 / res[0].0,
                1.05,
                false,
                "mean per-frame RMSE of the GI".into(),
            ));
        }
    }
    csv.write(&dir.join("upsampling.csv"))?;
    plot::bars(
        &dir.join("upsampling.png"),
        &format!("{}: GI time, full vs half GI resolution", b.scene),
        "GI ms (wall clock)",
        &bars,
        false,
    )?;
    Ok(Report { table, checks })
}

/// VPL count 2^10 .. 2^16: tree build GPU time (keys, sort, build, classify), GI GPU time and
/// RMSE against the ground truth of each count.
pub fn scaling(b: &mut Bench, o: &Opts, dir: &Path) -> anyhow::Result<Report> {
    let mut csv = Csv::new(&[
        "scene",
        "vpls",
        "sort_gpu_ms",
        "build_gpu_ms",
        "tree_gpu_ms",
        "gi_gpu_ms",
        "frame_ms",
        "rmse",
        "rmse_std",
        "ssim",
        "steps_per_traversal",
    ]);
    let mut table = format!("VPL scaling (SLC, {}x{}):\n", o.scaling_size.0, o.scaling_size.1);
    let mut rows = Vec::new();
    for &e in &o.vpl_exponents {
        let n = 1u32 << e;
        let s = with(b, |s| {
            s.gi.method = GiMethod::Slc;
            s.vpl.count = n;
        });
        let m = b.measure(&s, o.scaling_size, o.frames, true)?;
        let sort = m.pass_ms(&["sst_keys", "sst_sort"]).0;
        let build = m.pass_ms(&["sst_build", "sst_classify"]).0;
        let gi = m.pass_ms(&GI_PASSES).0;
        let (r, rs) = m.rmse();
        csv.row(vec![
            b.scene.clone(),
            n.to_string(),
            num(sort),
            num(build),
            num(sort + build),
            num(gi),
            num(m.frame_ms().0),
            num(r),
            num(rs),
            num(m.ssim().0),
            num(m.steps_per_traversal()),
        ]);
        table.push_str(&format!(
            "  {n:>6} VPLs: tree {:>8.3} ms (sort {sort:.3} + build {build:.3}), GI {gi:>8.1} ms, RMSE {r:.4e}\n",
            sort + build
        ));
        rows.push((n as f64, sort + build, gi, r));
    }
    csv.write(&dir.join("scaling.csv"))?;
    plot::lines(
        &dir.join("scaling_time.png"),
        &format!("{}: GPU time over the VPL count", b.scene),
        "VPLs",
        "ms",
        &[
            plot::Series {
                name: "tree (keys + sort + build + classify)".into(),
                color: 3,
                points: rows.iter().map(|r| (r.0, r.1)).collect(),
            },
            plot::Series {
                name: "GI (cuts + sampling)".into(),
                color: 0,
                points: rows.iter().map(|r| (r.0, r.2)).collect(),
            },
        ],
        true,
        true,
    )?;
    plot::lines(
        &dir.join("scaling_rmse.png"),
        &format!(
            "{}: RMSE over the VPL count (vs. each count's ground truth)",
            b.scene
        ),
        "VPLs",
        "RMSE of one frame's GI",
        &[plot::Series {
            name: "SLC".into(),
            color: 0,
            points: rows.iter().map(|r| (r.0, r.3)).collect(),
        }],
        true,
        false,
    )?;
    Ok(Report {
        table,
        checks: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::interp_loglog;

    #[test]
    fn loglog_interpolation() {
        // y = x^-0.5 is a line in log-log.
        let p: Vec<(f64, f64)> = [1.0f64, 4.0, 16.0].iter().map(|x| (*x, x.powf(-0.5))).collect();
        let (y, ex) = interp_loglog(&p, 8.0);
        assert!((y - 8f64.powf(-0.5)).abs() < 1e-12 && !ex);
        let (y, ex) = interp_loglog(&p, 64.0);
        assert!((y - 64f64.powf(-0.5)).abs() < 1e-12 && ex);
        assert!(interp_loglog(&[], 1.0).0.is_nan());
    }
}

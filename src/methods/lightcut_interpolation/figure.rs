//! Lightcut Interpolation's headline comparison (Rehfeld & Dachsbacher 2016, section 6,
//! Fig. 8 and 10): Lightcuts against Lightcut Interpolation with full and with interpolated
//! visibility, on the same VPLs, tree, representatives, threshold and cut limit: GPU time of
//! each method's GI passes (and per pass, the paper's performance breakdown), error (RMSE and
//! the image-mean ratio) against the ground truth of the VPLs and against Lightcuts' image
//! (the paper's difference images), the records and cut statistics. The paper's own ratios
//! are the checks. `interpolation.csv`'s `mean_ratio` is against the ground truth (mean over
//! the diagnostic frames), `mean_ratio_vs_lightcuts` against Lightcuts' last frame.

use crate::harness::figures::prelude::*;
use crate::methods::{
    lightcut_interpolation::{
        self as li,
        settings::{LiVisibility, LightcutInterpolationSettings},
    },
    lightcuts::{self, settings::LightcutsSettings},
};
use crate::metrics;

/// The paper's worst (largest) time ratios to Lightcuts over its diffuse scenes (section 6):
/// full visibility 40.4-56.4%, interpolated visibility 4.50-8.32%.
pub const PAPER_FULL_RATIO: (f64, f64) = (0.404, 0.564);
pub const PAPER_INTERP_RATIO: (f64, f64) = (0.045, 0.0832);

inventory::submit! {
    FigureDef {
        cli: "interpolation",
        label: "Interpolation",
        order: 40,
        doc: "Lightcut Interpolation's headline comparison (its paper's Fig. 8 / 10): Lightcuts vs interpolation with full and interpolated visibility, GPU time per pass and error.",
        make: interpolation,
    }
}

pub fn interpolation(b: &mut Bench, o: &Opts, dir: &Path) -> anyhow::Result<Report> {
    let li_base: LightcutInterpolationSettings = b.base.method(li::ID).map_err(|e| anyhow::anyhow!(e))?;
    let configs = configs(b, &li_base);
    let mut ms = Vec::new();
    for (label, s) in &configs {
        let m = b.measure(s, o.size, o.per_config(), true)?;
        eprintln!(
            "[{}] {label}: GI {:.2} ms GPU, RMSE {:.4e}, mean {:.3}x GT",
            b.scene,
            m.gi_ms().0,
            m.rmse().0,
            m.mean_ratio().0
        );
        ms.push(m);
    }
    let gt = b.ground_truth(&configs[0].1, o.size)?;
    let img = images(dir)?;
    b.write_gi_png(&img.join("interpolation_ground_truth.png"), &gt)?;
    let lc_img = ms[0].indirect.clone();
    let lc_ms = ms[0].gi_ms().0;
    let mut csv = Csv::new(&[
        "scene",
        "method",
        "relative_error",
        "max_cut",
        "vpls",
        "gi_gpu_ms",
        "gi_gpu_ms_std",
        "time_vs_lightcuts",
        "paper_time_vs_lightcuts",
        "rmse_vs_ground_truth",
        "relative_rmse_vs_ground_truth",
        "ssim_vs_ground_truth",
        "mean_ratio",
        "rmse_vs_lightcuts",
        "relative_rmse_vs_lightcuts",
        "mean_ratio_vs_lightcuts",
        "method_stats",
    ]);
    let mut passes = Csv::new(&["scene", "method", "pass", "median_ms", "share"]);
    let mut table = format!(
        "Lightcuts vs Lightcut Interpolation ({}x{}, {} VPLs, relative error {}, max cut {}; {}):\n",
        o.size.0, o.size.1, b.base.vpl.count, li_base.relative_error, li_base.max_cut, b.adapter
    );
    let mut bars = Vec::new();
    let mut checks = Vec::new();
    for (i, ((label, s), m)) in configs.iter().zip(&ms).enumerate() {
        let (t, ts) = m.gi_ms();
        let ratio = t / lc_ms;
        let paper = match i {
            0 => "1".to_string(),
            1 => format!("{}..{}", PAPER_FULL_RATIO.0, PAPER_FULL_RATIO.1),
            _ => format!("{}..{}", PAPER_INTERP_RATIO.0, PAPER_INTERP_RATIO.1),
        };
        let vs_gt = m
            .indirect
            .as_ref()
            .map(|x| metrics::compare_without_flip(x, &gt, b.gi_exposure, b.base.display.tonemap));
        let vs_lc = match (&m.indirect, &lc_img) {
            (Some(x), Some(l)) => Some(metrics::compare_without_flip(
                x,
                l,
                b.gi_exposure,
                b.base.display.tonemap,
            )),
            _ => None,
        };
        let stats: Vec<String> = m
            .method_stats
            .iter()
            .map(|(k, x)| format!("{k}={x:.4}"))
            .collect();
        csv.row(vec![
            b.scene.clone(),
            label.to_string(),
            li_base.relative_error.to_string(),
            li_base.max_cut.to_string(),
            s.vpl.count.to_string(),
            num(t),
            num(ts),
            num(ratio),
            paper,
            num(m.rmse().0),
            num(vs_gt.map_or(f64::NAN, |c| c.relative_rmse)),
            num(m.ssim().0),
            num(m.mean_ratio().0),
            num(vs_lc.map_or(f64::NAN, |c| c.rmse)),
            num(vs_lc.map_or(f64::NAN, |c| c.relative_rmse)),
            num(vs_lc.map_or(f64::NAN, |c| c.mean_ratio)),
            stats.join(" "),
        ]);
        table.push_str(&format!(
            "  {label:<16} GI {t:>9.3} ms GPU ({:>6.1}% of Lightcuts), RMSE vs GT {:.4e} (relative {:.3}, mean {:.3}x), vs Lightcuts relative {:.3} (mean {:.3}x)\n",
            100.0 * ratio,
            m.rmse().0,
            vs_gt.map_or(f64::NAN, |c| c.relative_rmse),
            m.mean_ratio().0,
            vs_lc.map_or(f64::NAN, |c| c.relative_rmse),
            vs_lc.map_or(f64::NAN, |c| c.mean_ratio),
        ));
        let method = s.gi.method;
        for p in method.info().timed_passes {
            let (pm, _) = m.pass_ms(&[p]);
            passes.row(vec![
                b.scene.clone(),
                label.to_string(),
                p.to_string(),
                num(pm),
                num(pm / t),
            ]);
        }
        bars.push(plot::Bar {
            label: label.to_string(),
            value: t,
            spread: ts,
            color: i,
        });
        if let Some(x) = &m.indirect {
            let stem = format!("interpolation_{}", ["lightcuts", "li_full", "li_interp"][i]);
            b.write_gi_png(&img.join(format!("{stem}.png")), x)?;
            b.write_error_png(&img.join(format!("{stem}_error.png")), x, &gt)?;
        }
        if i > 0 {
            checks.push(time_check(b, o, i, label, ratio));
        }
    }
    csv.write(&dir.join("interpolation.csv"))?;
    passes.write(&dir.join("interpolation_passes.csv"))?;
    plot::bars(
        &dir.join("interpolation.png"),
        &format!("{}: GI GPU time, Lightcuts vs Lightcut Interpolation", b.scene),
        "ms (log)",
        &bars,
        true,
    )?;
    Ok(Report { table, checks })
}

/// The three configurations: Lightcuts at Lightcut Interpolation's threshold and cut, and
/// the interpolation with full and with interpolated visibility.
fn configs(b: &Bench, li_base: &LightcutInterpolationSettings) -> Vec<(&'static str, RenderSettings)> {
    let lc_set = LightcutsSettings {
        relative_error: li_base.relative_error,
        max_cut: li_base.max_cut,
    };
    vec![
        (
            "Lightcuts",
            with(b, |s| {
                s.gi.method = lightcuts::ID;
                let _ = s.set_method(lightcuts::ID, &lc_set);
            }),
        ),
        (
            "LI full vis.",
            with(b, |s| {
                s.gi.method = li::ID;
                let _ = s.set_method(
                    li::ID,
                    &LightcutInterpolationSettings {
                        visibility: LiVisibility::Full,
                        ..li_base.clone()
                    },
                );
            }),
        ),
        (
            "LI interp. vis.",
            with(b, |s| {
                s.gi.method = li::ID;
                let _ = s.set_method(
                    li::ID,
                    &LightcutInterpolationSettings {
                        visibility: LiVisibility::Interpolated,
                        ..li_base.clone()
                    },
                );
            }),
        ),
    ]
}

/// The check of configuration `i`'s GI time against Lightcuts' (the paper's worst diffuse
/// scene's ratio as the limit).
fn time_check(b: &Bench, o: &Opts, i: usize, label: &str, ratio: f64) -> Check {
    let limit = if i == 1 {
        PAPER_FULL_RATIO.1
    } else {
        PAPER_INTERP_RATIO.1
    };
    check(
        b,
        &format!("{label} GI time / Lightcuts'"),
        ratio,
        limit,
        false,
        format!(
            "GI GPU time (timestamps of each method's timed passes), median of {} timed frames; the paper's worst diffuse scene as the limit",
            o.timing_frames
        ),
    )
}

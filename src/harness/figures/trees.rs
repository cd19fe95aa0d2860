//! Issue 23's tree comparison: every method that runs on either tree (SST, SLC, RTSLC,
//! Lightcuts) on the thesis's perfect binary tree and on the SST paper's radix tree (LBVH) over
//! the same VPLs and keys. Per method and tree: its quality sweep (the samplers' spp,
//! Lightcuts' relative error) with GPU time (the method's passes + the tree's build), RMSE,
//! SSIM, the image-mean ratio and traversal steps; the RMSE and the mean ratio of each tree
//! interpolated at equal GPU time (the perfect tree's time at the base value: the base spp,
//! the middle relative error). `bench tree` times the builds alone over 2^12 .. 2^20 VPLs
//! and `bench lightcuts` measures the trees' far-paired clusters.

use super::*;
use crate::methods::tree_samplers::settings::SamplingSettings;
use crate::settings::TreeKind;

/// One tree's sweep: (total ms, RMSE) and (total ms, image-mean ratio) points, and at the
/// base spp the steps per traversal, the build's ms and the total ms.
struct TreeCurve {
    points: Vec<(f64, f64)>,
    ratios: Vec<(f64, f64)>,
    steps: f64,
    build: f64,
    t_base: f64,
}

inventory::submit! {
    FigureDef {
        cli: "trees",
        label: "Trees",
        order: 80,
        doc: "Issue 23: the tree samplers and Lightcuts on the perfect binary tree and on the radix tree (LBVH): RMSE over GPU time (method + tree build), steps, and RMSE at equal time.",
        make: trees,
    }
}

pub fn trees(b: &mut Bench, o: &Opts, dir: &Path) -> anyhow::Result<Report> {
    let base_spp = SamplingSettings::of(&b.base).cut_size;
    let mut csv = Csv::new(&[
        "scene",
        "method",
        "tree",
        "setting",
        "value",
        "gi_gpu_ms",
        "tree_build_gpu_ms",
        "total_gpu_ms",
        "rmse",
        "rmse_std",
        "ssim",
        "mean_ratio",
        "steps_per_traversal",
        "steps_per_pixel",
    ]);
    let mut series = Vec::new();
    let mut table = format!(
        "perfect binary tree vs radix tree (LBVH), {} VPLs; time = the method's passes + the tree build (GPU timestamps):\n",
        b.base.vpl.count
    );
    let mut matched = Csv::new(&[
        "scene",
        "method",
        "matched_gpu_ms",
        "rmse_perfect",
        "rmse_lbvh",
        "rmse_ratio_lbvh_over_perfect",
        "mean_ratio_perfect",
        "mean_ratio_lbvh",
        "extrapolated",
        "steps_perfect",
        "steps_lbvh",
        "build_perfect_ms",
        "build_lbvh_ms",
    ]);
    let any: Vec<(MethodId, &str)> = methods(o)
        .into_iter()
        .filter(|(m, _)| m.any_tree() && m.per_frame())
        .collect();
    for (mi, (method, label)) in any.into_iter().enumerate() {
        let Some(sweep) = method.info().sweep else {
            continue;
        };
        let values = o.sweep_values(method, base_spp);
        if values.is_empty() {
            continue;
        }
        let base = matched_value(sweep, &values, base_spp);
        // Per tree: (total ms, RMSE) over the sweep, the base value's steps and build time.
        let mut curves: Vec<TreeCurve> = Vec::new();
        for (ki, kind) in TreeKind::ALL.into_iter().enumerate() {
            let run = SweepRun {
                method,
                label,
                kind,
                sweep,
                values: &values,
                base,
            };
            let curve = tree_curve(b, o, &mut csv, &run)?;
            series.push(plot::Series {
                name: format!("{label} {}", kind.name()),
                color: 2 * mi + ki,
                points: curve.points.clone(),
            });
            curves.push(curve);
        }
        let t = curves[0].t_base;
        let (r_p, ex_p) = interp_loglog(&curves[0].points, t);
        let (r_l, ex_l) = interp_loglog(&curves[1].points, t);
        // The image-mean ratios at the same time, interpolated as the RMSEs are.
        let (q_p, _) = interp_loglog(&curves[0].ratios, t);
        let (q_l, _) = interp_loglog(&curves[1].ratios, t);
        matched.row(vec![
            b.scene.clone(),
            label.to_string(),
            num(t),
            num(r_p),
            num(r_l),
            num(r_l / r_p),
            num(q_p),
            num(q_l),
            (ex_p || ex_l).to_string(),
            num(curves[0].steps),
            num(curves[1].steps),
            num(curves[0].build),
            num(curves[1].build),
        ]);
        table.push_str(&format!(
            "  {label:<6} at {t:.2} ms: RMSE perfect {r_p:.4e}, radix {r_l:.4e} ({:.2}x{}); mean vs GT perfect {q_p:.3}x, radix {q_l:.3}x; steps per traversal {:.2} vs {:.2}; build {:.3} vs {:.3} ms\n",
            r_l / r_p,
            if ex_l { ", extrapolated" } else { "" },
            curves[0].steps,
            curves[1].steps,
            curves[0].build,
            curves[1].build
        ));
    }
    csv.write(&dir.join("trees.csv"))?;
    matched.write(&dir.join("trees_equal_time.csv"))?;
    plot::lines(
        &dir.join("trees_rmse.png"),
        &format!(
            "{}: RMSE vs GPU time (method + tree build), perfect vs radix tree",
            b.scene
        ),
        "GPU time (ms: the method's passes + the tree build, timestamps)",
        "RMSE of one frame's GI (W/(m² sr))",
        &series,
        true,
        true,
    )?;
    Ok(Report {
        table,
        checks: Vec::new(),
    })
}

/// The matched point of a sweep: the swept spp nearest the base spp, else the sweep's middle
/// value.
fn matched_value(sweep: &crate::methods::Sweep, values: &[f64], base_spp: u32) -> f64 {
    if sweep.name == "spp" {
        values
            .iter()
            .copied()
            .min_by(|a, b| {
                (a - base_spp as f64)
                    .abs()
                    .total_cmp(&(b - base_spp as f64).abs())
            })
            .unwrap_or(values[0])
    } else {
        values[values.len() / 2]
    }
}

/// One method's sweep on one tree.
struct SweepRun<'a> {
    method: MethodId,
    label: &'a str,
    kind: TreeKind,
    sweep: &'static crate::methods::Sweep,
    values: &'a [f64],
    /// The matched value (its steps, build and total time are the curve's).
    base: f64,
}

/// Measures a method over its sweep on one tree (a CSV row per value): (total ms, RMSE) and
/// (total ms, mean ratio), sorted by time, and the base value's steps, build and total time.
fn tree_curve(b: &mut Bench, o: &Opts, csv: &mut Csv, run: &SweepRun<'_>) -> anyhow::Result<TreeCurve> {
    let SweepRun {
        method,
        label,
        kind,
        sweep,
        values,
        base,
    } = *run;
    let (mut pts, mut ratios) = (Vec::new(), Vec::new());
    let (mut steps, mut build, mut t_base) = (f64::NAN, f64::NAN, f64::NAN);
    for &v in values {
        let s = with(b, |s| {
            s.gi.method = method;
            s.tree.kind = kind;
            (sweep.apply)(s, v);
        });
        let m = b.measure(&s, o.size, o.per_config(), true)?;
        let gi = m.gi_ms().0;
        let tb = m.pass_ms(&TREE_BUILD_PASSES).0;
        let (r, rs) = m.rmse();
        let value = knob(v, sweep.integer);
        csv.row(vec![
            b.scene.clone(),
            label.to_string(),
            kind.name().to_string(),
            sweep.name.to_string(),
            value.clone(),
            num(gi),
            num(tb),
            num(gi + tb),
            num(r),
            num(rs),
            num(m.ssim().0),
            num(m.mean_ratio().0),
            num(m.steps_per_traversal()),
            num(m.steps_per_pixel()),
        ]);
        eprintln!(
            "[{}] {label} on the {} tree, {} {value}: GI {gi:.3} + build {tb:.3} ms GPU, RMSE {r:.4e}, mean {:.3}x GT, {:.2} steps per traversal",
            b.scene,
            kind.name(),
            sweep.name,
            m.mean_ratio().0,
            m.steps_per_traversal()
        );
        if v == base {
            steps = m.steps_per_traversal();
            build = tb;
            t_base = gi + tb;
        }
        pts.push((gi + tb, r));
        ratios.push((gi + tb, m.mean_ratio().0));
    }
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    ratios.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(TreeCurve {
        points: pts,
        ratios,
        steps,
        build,
        t_base,
    })
}

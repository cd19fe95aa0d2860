//! Thesis figures of resolution: half-resolution GI with upsampling (7.8) and VPL scaling.

use super::*;
use crate::methods::tree_samplers::settings::SamplingSettings;

inventory::submit! {
    FigureDef {
        cli: "upsampling",
        label: "Upsampling",
        order: 120,
        doc: "Table 7.2: full vs half GI resolution.",
        make: upsampling,
    }
}

/// Thesis table 7.2: full vs half GI resolution at one or more frame sizes: RMSE, the
/// image-mean ratio against the ground truth, SSIM, GI time (GPU timestamps of the GI
/// passes: cuts, sampling, down- and upsampling) and the frame's wall clock (a separate
/// column).
pub fn upsampling(b: &mut Bench, o: &Opts, dir: &Path) -> anyhow::Result<Report> {
    let mut csv = Csv::new(&[
        "scene",
        "width",
        "height",
        "gi_resolution",
        "rmse",
        "rmse_std",
        "mean_ratio",
        "ssim",
        "gi_gpu_ms",
        "gi_gpu_ms_std",
        "frame_wall_ms",
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
        let mut res = Vec::new();
        for half in [false, true] {
            let s = with(b, |s| {
                s.gi.method = SLC;
                SamplingSettings::edit(s, |m| m.half_resolution = half);
            });
            let m = b.measure(&s, size, o.per_config(), true)?;
            let (r, rs) = m.rmse();
            let t = m.frame_ms().0;
            let (gi, gi_s) = m.gi_ms();
            let label = if half { "half" } else { "full" };
            csv.row(vec![
                b.scene.clone(),
                size.0.to_string(),
                size.1.to_string(),
                label.into(),
                num(r),
                num(rs),
                num(m.mean_ratio().0),
                num(m.ssim().0),
                num(gi),
                num(gi_s),
                num(t),
            ]);
            table.push_str(&format!(
                "  {}x{} {label:<4} GI: RMSE {r:.4e}, mean {:.3}x GT, SSIM {:.3}, GI {gi:.2} ms (GPU), frame {t:.1} ms (wall)\n",
                size.0,
                size.1,
                m.mean_ratio().0,
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
                "{}x{}: GI time = GPU timestamps of the GI passes (cuts, sampling, down/upsampling)",
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
        "GI ms (GPU timestamps)",
        &bars,
        false,
    )?;
    Ok(Report { table, checks })
}

inventory::submit! {
    FigureDef {
        cli: "scaling",
        label: "Scaling",
        order: 130,
        doc: "VPL count sweep: tree build time, GI time, RMSE.",
        make: scaling,
    }
}

/// VPL count 2^10 .. 2^16: tree build GPU time (keys, sort, build, classify), GI GPU time,
/// RMSE and the image-mean ratio against the ground truth of each count.
pub fn scaling(b: &mut Bench, o: &Opts, dir: &Path) -> anyhow::Result<Report> {
    let mut csv = Csv::new(&[
        "scene",
        "vpls",
        "sort_gpu_ms",
        "build_gpu_ms",
        "tree_gpu_ms",
        "gi_gpu_ms",
        "frame_wall_ms",
        "rmse",
        "rmse_std",
        "mean_ratio",
        "ssim",
        "steps_per_traversal",
    ]);
    let mut table = format!("VPL scaling (SLC, {}x{}):\n", o.scaling_size.0, o.scaling_size.1);
    let mut rows = Vec::new();
    for &e in &o.vpl_exponents {
        let n = 1u32 << e;
        let s = with(b, |s| {
            s.gi.method = SLC;
            s.vpl.count = n;
        });
        let m = b.measure(&s, o.scaling_size, o.per_config(), true)?;
        let sort = m.pass_ms(&SORT_PASSES).0;
        let build = m.pass_ms(&TREE_BUILD_PASSES).0;
        let gi = m.pass_ms(&gi_passes()).0;
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
            num(m.mean_ratio().0),
            num(m.ssim().0),
            num(m.steps_per_traversal()),
        ]);
        table.push_str(&format!(
            "  {n:>6} VPLs: tree {:>8.3} ms (sort {sort:.3} + build {build:.3}), GI {gi:>8.3} ms (GPU), RMSE {r:.4e}, mean {:.3}x GT\n",
            sort + build,
            m.mean_ratio().0
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

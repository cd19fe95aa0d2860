//! Stochastic Light Culling's study (Tokuyoshi & Harada 2016, section 4.4, figures 4-6 and
//! Table 1) on our scenes: stochastic against clamped ranges (appendix A) over the VPL
//! count and over the error bound eps_max, without visibility (the paper's setting, against
//! the unshadowed ground truth) and with shadow rays (against the true one): GI GPU time,
//! VPLs per pixel, error (RMSE and the image-mean ratio against each truth), bias and
//! noise; the clamped ranges at the stochastic ones' GPU time (figure 4's comparison)
//! interpolated from the eps_max sweep; the paper's Table 1 beside our pass times. Section
//! 5's bounding-sphere-tree variant runs beside them on the same VPLs and bounds (per-pixel
//! culling, k-entry reservoir lists, one shadow ray). The stochastic ranges also run with
//! imperfect shadow maps (sections 4.3-4.4, against the true ground truth), and with the
//! maps' range culling off (figure 7: the maps' build time with and without it).

use crate::harness::figures::prelude::*;
use crate::methods::light_culling::{
    self as lcull,
    settings::{CullingVisibility, LightCullingSettings},
};
use crate::metrics;

/// The paper's Table 1 (AMD R9 290X, 1920 x 1152, 65,536 VPLs, no shadows), ms:
/// (our pass names, the paper's row, its time).
pub const PAPER_TABLE_1: [(&[&str], &str, f64); 3] = [
    (
        &["lcull_ranges"],
        "VPL sampling & light range computation (ours: ranges only)",
        0.05,
    ),
    (
        &["lcull_tiles", "lcull_shade"],
        "interleaved sampling & tiled lighting",
        3.98,
    ),
    (&["lcull_filter"], "geometry-aware filtering", 1.00),
];

/// A row's visibility: none, shadow rays, or imperfect shadow maps (with or without section
/// 4.3's range culling).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Vis {
    None,
    Rays,
    Ism,
    IsmUnculled,
}

impl Vis {
    fn label(self) -> &'static str {
        match self {
            Vis::None => "none",
            Vis::Rays => "rays",
            Vis::Ism => "ism",
            Vis::IsmUnculled => "ism-unculled",
        }
    }
    fn shadows(self) -> bool {
        self != Vis::None
    }
}

struct Row {
    mode: &'static str,
    vis: Vis,
    vpls: u32,
    eps: f64,
    gi_ms: f64,
    gi_std: f64,
    in_range: f64,
    rays: f64,
    rmse: f64,
    bias: f64,
    noise: f64,
    /// Image-mean ratio against the same visibility's truth (mean over the diagnostic frames).
    mean_ratio: f64,
    /// RMSE and image-mean ratio of the last diagnostic frame against the true ground truth
    /// (shadow rays).
    rmse_true: f64,
    mean_ratio_true: f64,
    passes: Vec<(&'static str, f64)>,
    /// The maps' build (`lcull_ism`; 0 without maps).
    ism_ms: f64,
    /// The frame's light-tree build (sst_keys, sst_sort, sst_build, sst_classify): every
    /// method's frame runs it, the tree variant needs it (the other variants do not).
    tree_build_ms: f64,
}

fn stat(m: &Measured, k: &str) -> f64 {
    m.method_stats
        .iter()
        .find(|(n, _)| *n == k)
        .map_or(f64::NAN, |(_, v)| *v)
}

inventory::submit! {
    FigureDef {
        cli: "culling",
        label: "Culling",
        order: 50,
        doc: "Stochastic Light Culling's study (its figs. 4-6, Table 1): stochastic vs clamped ranges over the VPL count (--vpl-exponents) and eps_max (--sweep light-culling=..), with and without visibility, GPU time and error.",
        make: culling,
    }
}

/// What every configuration of the study shares: the settings' light culling, its base
/// bound, the swept bounds and the images' folder.
struct Study {
    base: LightCullingSettings,
    base_eps: f64,
    eps_values: Vec<f64>,
    img: std::path::PathBuf,
}

/// The three variants: (method, ranges label).
const MODES: [(MethodId, &str); 3] = [
    (lcull::ID, "stochastic"),
    (lcull::CLAMPED, "clamped"),
    (lcull::TREE, "tree"),
];

/// Each variant's passes: ranges, culling, shading, filter (the CSV's four pass columns).
fn passes_of(mode: usize) -> [&'static str; 4] {
    if MODES[mode].0 == lcull::TREE {
        [
            "lcull_tree_leaves",
            "lcull_tree_traverse",
            "lcull_tree_shade",
            "lcull_filter",
        ]
    } else {
        ["lcull_ranges", "lcull_tiles", "lcull_shade", "lcull_filter"]
    }
}

/// The study (module doc). Its VPL counts are `--vpl-exponents`, its error bounds the
/// method's sweep (`--sweep light-culling=...`), its base bound the settings'.
pub fn culling(b: &mut Bench, o: &Opts, dir: &Path) -> anyhow::Result<Report> {
    let base: LightCullingSettings = b.base.method(lcull::ID).map_err(|e| anyhow::anyhow!(e))?;
    let base_eps = base.epsilon_max as f64;
    // For labels: the f32 setting as written (0.0005, not its f64 widening).
    let eps_label = base.epsilon_max;
    let mut eps_values = o.sweep_values(lcull::ID, 0);
    if !eps_values.iter().any(|&e| same_eps(e, base_eps)) {
        eps_values.push(base_eps);
    }
    eps_values.sort_by(f64::total_cmp);
    let st = Study {
        base,
        base_eps,
        eps_values,
        img: images(dir)?,
    };
    let rows = measure_rows(b, o, &st)?;
    write_rows(b, dir, &rows)?;
    write_plots(b, dir, &rows, base_eps, eps_label)?;
    let at_base_eps = |r: &Row| same_eps(r.eps, base_eps);
    let mut table = format!(
        "Stochastic vs clamped light culling, and the bounding-sphere tree ({}x{}, eps_max {eps_label}, {} x {} interleaving, {} filter radius; tree: k = {}, filter radius {}; {}):\n",
        o.size.0,
        o.size.1,
        st.base.interleave.n,
        st.base.interleave.n,
        st.base.interleave.filter_radius,
        st.base.reservoir_k,
        st.base.tree_filter_radius,
        b.adapter
    );
    for r in rows.iter().filter(|r| at_base_eps(r)) {
        table.push_str(&format!(
            "  {:<10} {:<12} {:>6} VPLs: GI {:>9.3} ms GPU{}, {:>6.1} VPLs in range/pixel, RMSE {:.4e} (bias {:.2e}), mean ratio {:.3}, RMSE vs true GT {:.4e} (mean ratio {:.3})\n",
            r.mode,
            r.vis.label(),
            r.vpls,
            r.gi_ms,
            if r.mode == "tree" {
                format!(" (+ {:.3} ms light-tree build)", r.tree_build_ms)
            } else if r.ism_ms > 0.0 {
                format!(" (of which {:.3} ms the maps)", r.ism_ms)
            } else {
                String::new()
            },
            r.in_range,
            r.rmse,
            r.bias,
            r.mean_ratio,
            r.rmse_true,
            r.mean_ratio_true,
        ));
    }
    let mut checks = Vec::new();
    paper_table_1(b, o, &rows, base_eps, &mut table, &mut checks, dir)?;
    figure_7(b, o, &rows, &st, &mut table, &mut checks);
    equal_time(b, &rows, base_eps, &mut table);
    Ok(Report { table, checks })
}

/// One configuration measured: a variant (`MODES[mode]`), a visibility, a VPL count and a
/// bound; its error against the same visibility's truth and the true one; at the base count
/// and bound without visibility, its images.
fn run(
    b: &mut Bench,
    o: &Opts,
    st: &Study,
    mode: usize,
    vis: Vis,
    vpls: u32,
    eps: f64,
) -> anyhow::Result<Row> {
    let shadows = vis.shadows();
    let s = with(b, |s| {
        s.gi.method = MODES[mode].0;
        s.gi.shadow_rays = shadows;
        s.vpl.count = vpls;
        let _ = s.set_method(
            lcull::ID,
            &LightCullingSettings {
                epsilon_max: eps as f32,
                visibility: if matches!(vis, Vis::Ism | Vis::IsmUnculled) {
                    CullingVisibility::Ism
                } else {
                    CullingVisibility::Rays
                },
                ism_range_culling: vis != Vis::IsmUnculled,
                ..st.base.clone()
            },
        );
    });
    let m = b.measure(&s, o.size, o.per_config(), true)?;
    // The true ground truth (shadow rays) for the image of the last diagnostic frame.
    let truth = b.ground_truth(
        &with(b, |t| {
            t.vpl.count = vpls;
            t.gi.shadow_rays = true;
        }),
        o.size,
    )?;
    let (rmse_true, mean_ratio_true) = m.indirect.as_ref().map_or((f64::NAN, f64::NAN), |x| {
        let c = metrics::compare_without_flip(x, &truth, b.gi_exposure, b.base.display.tonemap);
        (c.rmse, c.mean_ratio)
    });
    let (gi_ms, gi_std) = m.gi_ms();
    eprintln!(
        "[{}] {} {} VPLs eps {eps}, visibility {}: GI {gi_ms:.3} ms GPU, RMSE {:.4e}, mean {:.3}x",
        b.scene,
        MODES[mode].1,
        vpls,
        vis.label(),
        m.rmse().0,
        m.mean_ratio().0
    );
    if vpls == b.base.vpl.count
        && same_eps(eps, st.base_eps)
        && !shadows
        && let Some(x) = &m.indirect
    {
        let gt = b.ground_truth(&s, o.size)?;
        let stem = format!("culling_{}", MODES[mode].1);
        b.write_gi_png(&st.img.join(format!("{stem}.png")), x)?;
        b.write_error_png(&st.img.join(format!("{stem}_error.png")), x, &gt)?;
    }
    Ok(Row {
        mode: MODES[mode].1,
        vis,
        vpls,
        eps,
        gi_ms,
        gi_std,
        in_range: stat(&m, "vpls_in_range_per_pixel"),
        rays: stat(&m, "shadow_rays_per_pixel"),
        rmse: m.rmse().0,
        bias: m.bias_rmse,
        noise: m.noise_rmse,
        mean_ratio: m.mean_ratio().0,
        rmse_true,
        mean_ratio_true,
        passes: passes_of(mode)
            .into_iter()
            .map(|p| (p, m.pass_ms(&[p]).0))
            .collect(),
        ism_ms: if matches!(vis, Vis::Ism | Vis::IsmUnculled) {
            m.pass_ms(&["lcull_ism"]).0
        } else {
            0.0
        },
        // The light tree's keys, sort and build (shared frame work, in no GI time).
        tree_build_ms: m.pass_ms(&[&SORT_PASSES[..], &TREE_BUILD_PASSES[..]].concat()).0,
    })
}

/// Over the VPL count at the base bound, then over the bound at the base count.
fn measure_rows(b: &mut Bench, o: &Opts, st: &Study) -> anyhow::Result<Vec<Row>> {
    let mut rows: Vec<Row> = Vec::new();
    // The maps with the stochastic ranges (with and without their range culling over the
    // count).
    // More VPLs than the atlas holds maps: no ISM row (the count is named in the table).
    let maps = st.base.ism.capacity();
    for &e in &o.vpl_exponents {
        for vis in [Vis::None, Vis::Rays, Vis::Ism, Vis::IsmUnculled] {
            for mode in 0..MODES.len() {
                if matches!(vis, Vis::Ism | Vis::IsmUnculled) && (mode != 0 || 1 << e > maps) {
                    continue;
                }
                rows.push(run(b, o, st, mode, vis, 1 << e, st.base_eps)?);
            }
        }
    }
    for &eps in &st.eps_values {
        for vis in [Vis::None, Vis::Rays, Vis::Ism] {
            for mode in 0..MODES.len() {
                if same_eps(eps, st.base_eps) && o.vpl_exponents.iter().any(|&e| 1 << e == b.base.vpl.count) {
                    continue; // measured above
                }
                if vis == Vis::Ism && (mode != 0 || b.base.vpl.count > maps) {
                    continue;
                }
                rows.push(run(b, o, st, mode, vis, b.base.vpl.count, eps)?);
            }
        }
    }
    Ok(rows)
}

/// `culling.csv`: a row per configuration.
fn write_rows(b: &Bench, dir: &Path, rows: &[Row]) -> anyhow::Result<()> {
    let mut csv = Csv::new(&[
        "scene",
        "ranges",
        "visibility",
        "vpls",
        "epsilon_max",
        "gi_gpu_ms",
        "gi_gpu_ms_std",
        "vpls_in_range_per_pixel",
        "shadow_rays_per_pixel",
        "rmse_vs_same_visibility_truth",
        "bias_rmse",
        "noise_rmse",
        "mean_ratio",
        "rmse_vs_true_ground_truth",
        "mean_ratio_vs_true_ground_truth",
        // Tiled: lcull_ranges, lcull_tiles, lcull_shade; tree: lcull_tree_leaves,
        // lcull_tree_traverse, lcull_tree_shade; both lcull_filter.
        "ranges_ms",
        "culling_ms",
        "shade_ms",
        "filter_ms",
        // The frame's light-tree build (the tree variant needs it; in no variant's GI time).
        "tree_build_ms",
        // The imperfect shadow maps' build (lcull_ism, in the GI time; 0 without maps).
        "ism_ms",
    ]);
    for r in rows {
        let mut cells = vec![
            b.scene.clone(),
            r.mode.to_string(),
            r.vis.label().to_string(),
            r.vpls.to_string(),
            num(r.eps),
            num(r.gi_ms),
            num(r.gi_std),
            num(r.in_range),
            num(r.rays),
            num(r.rmse),
            num(r.bias),
            num(r.noise),
            num(r.mean_ratio),
            num(r.rmse_true),
            num(r.mean_ratio_true),
        ];
        cells.extend(r.passes.iter().map(|p| num(p.1)));
        cells.push(num(r.tree_build_ms));
        cells.push(num(r.ism_ms));
        csv.row(cells);
    }
    csv.write(&dir.join("culling.csv"))?;
    Ok(())
}

/// The plot's series: per variant and visibility, the points `pick` takes from its rows.
fn series(rows: &[Row], pick: &dyn Fn(&Row) -> Option<(f64, f64)>) -> Vec<plot::Series> {
    let mut v = Vec::new();
    for (c, (mode, vis)) in [
        ("stochastic", Vis::None),
        ("clamped", Vis::None),
        ("tree", Vis::None),
        ("stochastic", Vis::Rays),
        ("clamped", Vis::Rays),
        ("tree", Vis::Rays),
        ("stochastic", Vis::Ism),
    ]
    .into_iter()
    .enumerate()
    {
        let mut points: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.mode == mode && r.vis == vis)
            .filter_map(pick)
            .filter(|p| p.0.is_finite() && p.1.is_finite() && p.0 > 0.0 && p.1 > 0.0)
            .collect();
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        points.dedup_by(|a, b| a.0 == b.0);
        if !points.is_empty() {
            v.push(plot::Series {
                name: format!(
                    "{mode}, {}",
                    match vis {
                        Vis::None => "no visibility",
                        Vis::Rays => "shadow rays",
                        _ => "ISMs",
                    }
                ),
                color: c,
                points,
            });
        }
    }
    v
}

/// Time and RMSE over the VPL count and over the bound.
fn write_plots(b: &Bench, dir: &Path, rows: &[Row], base_eps: f64, eps_label: f32) -> anyhow::Result<()> {
    let at_base_eps = |r: &Row| same_eps(r.eps, base_eps);
    let at_base_n = |r: &Row| r.vpls == b.base.vpl.count;
    plot::lines(
        &dir.join("culling_time_vpls.png"),
        &format!(
            "{}: GI GPU time over the VPL count (eps_max {eps_label})",
            b.scene
        ),
        "VPLs",
        "ms (GPU timestamps of the culling passes)",
        &series(rows, &|r| at_base_eps(r).then_some((r.vpls as f64, r.gi_ms))),
        true,
        true,
    )?;
    plot::lines(
        &dir.join("culling_rmse_vpls.png"),
        &format!(
            "{}: RMSE over the VPL count (vs the same visibility's truth)",
            b.scene
        ),
        "VPLs",
        "RMSE of one frame's GI",
        &series(rows, &|r| at_base_eps(r).then_some((r.vpls as f64, r.rmse))),
        true,
        true,
    )?;
    plot::lines(
        &dir.join("culling_rmse_eps.png"),
        &format!("{}: RMSE over eps_max ({} VPLs)", b.scene, b.base.vpl.count),
        "eps_max",
        "RMSE of one frame's GI",
        &series(rows, &|r| at_base_n(r).then_some((r.eps, r.rmse))),
        true,
        true,
    )?;
    plot::lines(
        &dir.join("culling_time_eps.png"),
        &format!(
            "{}: GI GPU time over eps_max ({} VPLs)",
            b.scene, b.base.vpl.count
        ),
        "eps_max",
        "ms (GPU timestamps)",
        &series(rows, &|r| at_base_n(r).then_some((r.eps, r.gi_ms))),
        true,
        true,
    )?;
    Ok(())
}

/// The row of variant `mode`, visibility `vis` and `n` VPLs at the base bound.
fn find<'a>(rows: &'a [Row], mode: &str, vis: Vis, n: u32, base_eps: f64) -> Option<&'a Row> {
    rows.iter()
        .find(|r| r.mode == mode && r.vis == vis && r.vpls == n && same_eps(r.eps, base_eps))
}

/// The paper's Table 1 beside our passes, at the largest VPL count without visibility
/// (`culling_table1.csv`), and the stochastic / clamped time check.
fn paper_table_1(
    b: &Bench,
    o: &Opts,
    rows: &[Row],
    base_eps: f64,
    table: &mut String,
    checks: &mut Vec<Check>,
    dir: &Path,
) -> anyhow::Result<()> {
    let find = |mode: &str, vis: Vis, n: u32| find(rows, mode, vis, n, base_eps);
    let top = o.vpl_exponents.iter().max().map(|&e| 1u32 << e);
    let mut t1 = Csv::new(&["scene", "vpls", "paper_pass", "our_passes", "our_ms", "paper_ms"]);
    if let Some(n) = top
        && let Some(r) = find("stochastic", Vis::None, n)
    {
        table.push_str(&format!(
            "  Table 1 ({n} VPLs, no visibility; paper: R9 290X, 1920x1152, 65,536 VPLs):\n"
        ));
        for (ours, paper, pms) in PAPER_TABLE_1 {
            let t: f64 = r
                .passes
                .iter()
                .filter(|(p, _)| ours.contains(p))
                .map(|p| p.1)
                .sum();
            table.push_str(&format!("    {paper:<40} ours {t:>9.3} ms, paper {pms:.2} ms\n"));
            t1.row(vec![
                b.scene.clone(),
                n.to_string(),
                paper.to_string(),
                ours.join("+"),
                num(t),
                num(pms),
            ]);
        }
        if let Some(c) = find("clamped", Vis::None, n) {
            checks.push(check(
                b,
                "stochastic / clamped GI time, most VPLs",
                r.gi_ms / c.gi_ms,
                1.0,
                false,
                format!(
                    "GI GPU time (timestamps of the four culling passes), median of {} timed frames, {n} VPLs, no visibility (the paper's fig. 6)",
                    o.timing_frames
                ),
            ));
        }
    }
    t1.write(&dir.join("culling_table1.csv"))?;
    Ok(())
}

/// Figure 7: the maps' build with and without the range culling, at the largest count with
/// maps; the paper's 16,384 AISMs in about 22 ms (R9 290X) beside it.
fn figure_7(b: &Bench, o: &Opts, rows: &[Row], st: &Study, table: &mut String, checks: &mut Vec<Check>) {
    let maps = st.base.ism.capacity();
    let find = |mode: &str, vis: Vis, n: u32| find(rows, mode, vis, n, st.base_eps);
    let top_ism = o
        .vpl_exponents
        .iter()
        .map(|&e| 1u32 << e)
        .filter(|&n| n <= maps)
        .max();
    if let Some(n) = top_ism
        && let (Some(c), Some(u)) = (
            find("stochastic", Vis::Ism, n),
            find("stochastic", Vis::IsmUnculled, n),
        )
    {
        table.push_str(&format!(
            "  Figure 7 ({n} VPLs, {}^2 maps of {} points, front-face culling {}): the maps' build {:.3} ms with range culling, {:.3} ms without (paper: 16,384 AISMs in about 22 ms with it, R9 290X); with the maps RMSE vs the true GT {:.4e} (mean ratio {:.3}), with shadow rays {:.4e} (mean ratio {:.3})\n",
            st.base.ism.tile,
            st.base.ism.points_per_light,
            if st.base.ism.front_face_culling { "on" } else { "off" },
            c.ism_ms,
            u.ism_ms,
            c.rmse_true,
            c.mean_ratio_true,
            find("stochastic", Vis::Rays, n).map_or(f64::NAN, |r| r.rmse_true),
            find("stochastic", Vis::Rays, n).map_or(f64::NAN, |r| r.mean_ratio_true),
        ));
        checks.push(check(
            b,
            "ISM build with / without range culling, most VPLs",
            c.ism_ms / u.ism_ms,
            1.0,
            false,
            format!(
                "GPU timestamps of lcull_ism, median of {} timed frames, {n} VPLs (the paper's fig. 7)",
                o.timing_frames
            ),
        ));
    }
    if o.vpl_exponents.iter().any(|&e| 1u32 << e > maps) {
        table.push_str(&format!(
            "  (no ISM rows above {maps} VPLs: the atlas holds {maps} maps of {}^2; raise methods.light-culling.ism.atlas)\n",
            st.base.ism.tile
        ));
    }
}

/// Figure 4: the clamped ranges at the stochastic ones' time (log-log interpolation over the
/// eps_max sweep), error against the unshadowed truth.
fn equal_time(b: &Bench, rows: &[Row], base_eps: f64, table: &mut String) {
    let at_base_eps = |r: &Row| same_eps(r.eps, base_eps);
    let at_base_n = |r: &Row| r.vpls == b.base.vpl.count;
    for shadows in [false, true] {
        let vis = if shadows { Vis::Rays } else { Vis::None };
        let st = rows
            .iter()
            .find(|r| r.mode == "stochastic" && r.vis == vis && at_base_n(r) && at_base_eps(r));
        let mut cl: Vec<(f64, f64, f64)> = rows
            .iter()
            .filter(|r| r.mode == "clamped" && r.vis == vis && at_base_n(r))
            .map(|r| (r.gi_ms, r.rmse, r.mean_ratio))
            .collect();
        cl.sort_by(|a, b| a.0.total_cmp(&b.0));
        if let Some(st) = st
            && let Some((rmse, ratio)) = interpolate_at(&cl, st.gi_ms)
        {
            table.push_str(&format!(
                "  at equal GI time ({:.3} ms, {}): stochastic RMSE {:.4e} (mean ratio {:.3}), clamped RMSE {rmse:.4e} (mean ratio {ratio:.3})\n",
                st.gi_ms,
                if shadows { "shadow rays" } else { "no visibility" },
                st.rmse,
                st.mean_ratio
            ));
        }
    }
}

/// Whether two error bounds are the same setting (the base bound is an f32 widened to f64, a
/// sweep value an f64 as typed: 0.0005 is both).
fn same_eps(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-6 * a.abs().max(b.abs())
}

/// (rmse, mean ratio) at time `t` on the curve `pts` (time, rmse, ratio; sorted by time),
/// log-log between the neighbours; None outside the measured times.
fn interpolate_at(pts: &[(f64, f64, f64)], t: f64) -> Option<(f64, f64)> {
    let w = pts.windows(2).find(|w| w[0].0 <= t && t <= w[1].0)?;
    let (a, b) = (w[0], w[1]);
    if a.0 <= 0.0 || b.0 <= a.0 {
        return Some((a.1, a.2));
    }
    let f = (t.ln() - a.0.ln()) / (b.0.ln() - a.0.ln());
    let lerp_log = |x: f64, y: f64| {
        if x > 0.0 && y > 0.0 {
            (x.ln() + f * (y.ln() - x.ln())).exp()
        } else {
            x + f * (y - x)
        }
    };
    Some((lerp_log(a.1, b.1), a.2 + f * (b.2 - a.2)))
}

#[cfg(test)]
mod tests {
    #[test]
    fn interpolation_at_equal_time_is_log_log_and_bounded() {
        let pts = [(1.0, 1.0, 0.9), (4.0, 0.25, 1.0)];
        let (r, m) = super::interpolate_at(&pts, 2.0).unwrap();
        assert!((r - 0.5).abs() < 1e-12 && (m - 0.95).abs() < 1e-12);
        assert!(super::interpolate_at(&pts, 8.0).is_none());
    }

    #[test]
    fn a_typed_bound_is_the_same_as_its_f32_setting() {
        assert!(super::same_eps(0.0005, 0.0005f32 as f64));
        assert!(!super::same_eps(0.0005, 0.0004));
    }
}

//! The research harness (`results`) end to end at a tiny size: every figure's CSV has its
//! columns and finite values, the plots and images decode, the checks are written; bad
//! options give one clear line.

mod common;

use std::{path::Path, process::Command};

use common::read_csv;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lightcut-workbench"))
}

/// Asserts the columns exist, there are `min_rows` rows, and `finite` columns hold finite
/// numbers in every row.
fn check_csv(dir: &Path, file: &str, columns: &[&str], finite: &[&str], min_rows: usize) {
    let (header, rows) = read_csv(&dir.join(file));
    for c in columns.iter().chain(finite) {
        assert!(
            header.iter().any(|h| h == c),
            "{file}: no column {c} in {header:?}"
        );
    }
    assert!(
        rows.len() >= min_rows,
        "{file}: {} rows, expected >= {min_rows}",
        rows.len()
    );
    for r in &rows {
        for c in finite {
            let v: f64 = r[*c].parse().unwrap_or(f64::NAN);
            assert!(
                v.is_finite(),
                "{file}: {c} = {} is not a finite number ({r:?})",
                r[*c]
            );
        }
    }
}

fn decodes(path: &Path) {
    let img = image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(img.width() >= 32 && img.height() >= 24, "{}", path.display());
}

#[test]
fn every_figure_writes_csv_plots_and_images_at_a_tiny_size() {
    if common::gpu().is_none() {
        return;
    }
    let out = std::env::temp_dir().join(format!("lightcut-results-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    // The sweep as two shards run at once (`results --shard`, the figures dealt between
    // them; CI time), merged into `out` as one run writes it (`results merge`).
    let shard = |k: u32| {
        bin()
            .args(ARGS)
            .args(["--shard", &format!("{k}/2"), "--out"])
            .arg(out.with_extension(format!("shard{k}")))
            .output()
            .unwrap()
    };
    let (o1, o2) = std::thread::scope(|sc| {
        let a = sc.spawn(|| shard(1));
        let b = sc.spawn(|| shard(2));
        (a.join().unwrap(), b.join().unwrap())
    });
    for o in [&o1, &o2] {
        assert!(
            o.status.success(),
            "stdout: {}\nstderr: {}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let o = bin()
        .args(["results", "merge"])
        .arg(out.with_extension("shard1"))
        .arg(out.with_extension("shard2"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stdout = format!(
        "{}{}{}",
        String::from_utf8_lossy(&o1.stdout),
        String::from_utf8_lossy(&o2.stdout),
        String::from_utf8_lossy(&o.stdout)
    );
    assert!(
        o.status.success(),
        "stdout: {stdout}\nstderr: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    for k in [1, 2] {
        let _ = std::fs::remove_dir_all(out.with_extension(format!("shard{k}")));
    }
    let d = out.join("default");
    every_figure_checks(&out, &d, &stdout);
    let _ = std::fs::remove_dir_all(&out);
}

/// The options of the tiny sweep.
const ARGS: &[&str] = &[
    "results",
    "all",
    "--scenes",
    "default",
    "--width",
    "48",
    "--height",
    "32",
    "--frames",
    "2",
    "--timing-frames",
    "3",
    "--spp",
    "2,8",
    "--blocks",
    "1,8",
    "--vpl-exponents",
    "10,11",
    "--scaling-width",
    "32",
    "--scaling-height",
    "24",
    "--upsampling-scales",
    "1",
    "--vpls",
    "512",
    // Lightcuts and Lightcut Interpolation beside the three samplers, over two
    // thresholds and one record reach (tiny: CI time).
    "--methods",
    "slc,rtslc,sst,lightcuts,lightcut-interpolation",
    "--sweep",
    "lightcuts=0.2,0.05",
    "--sweep",
    "lightcut-interpolation=2",
    // The culling study's eps_max sweep: one bound beside the base one.
    "--sweep",
    "light-culling=0.005",
    // The interpolation figure's cuts small (and `--set` reaching `results`).
    "--set",
    "methods.lightcut-interpolation.max_cut=64",
    // The culling study at a looser base bound (shorter ranges: the sphere tree's
    // per-pixel walks stay short at this size).
    "--set",
    "methods.light-culling.epsilon_max=0.002",
    // The temporal figure: three frames per motion, timings at the frame size.
    // The bounce-count figure at 1 and 2 bounces (tiny: CI time).
    "--bounce-counts",
    "2",
    "--temporal-frames",
    "3",
    "--temporal-path-frames",
    "30",
    "--temporal-timing-width",
    "48",
    "--temporal-timing-height",
    "32",
];

/// What every figure of the tiny sweep wrote into `d` (and `out`), `stdout` the runs' output.
fn every_figure_checks(out: &Path, d: &Path, stdout: &str) {
    let d = d.to_path_buf();
    check_csv(
        &d,
        "timings.csv",
        &["scene", "group", "passes", "frames"],
        &["median_ms", "mean_ms", "std_ms", "min_ms", "max_ms"],
        10,
    );
    let (_, rows) = read_csv(&d.join("timings.csv"));
    let groups: Vec<&str> = rows.iter().map(|r| r["group"].as_str()).collect();
    for g in [
        "G-buffer",
        "shadow map",
        "VPL generation",
        "sort VPLs",
        "build SST",
        "light cuts",
        "GI",
        "direct light",
    ] {
        assert!(groups.contains(&g), "timings.csv lacks {g}: {groups:?}");
    }
    // 3 samplers x spp {2, 8, 32 (the base cut size is added)} + Lightcuts x 2 thresholds +
    // Lightcut Interpolation x 1 reach.
    check_csv(
        &d,
        "equal_time.csv",
        &["method", "spp", "setting", "value", "method_stats"],
        &[
            "gi_gpu_ms",
            "frame_wall_ms",
            "rmse",
            "ssim",
            "mean_ratio",
            "bias_rmse",
            "noise_rmse",
        ],
        12,
    );
    let (_, rows) = read_csv(&d.join("equal_time.csv"));
    for r in &rows {
        if r["method"] == "Lightcuts" {
            assert_eq!(r["setting"], "relative_error", "{r:?}");
            assert!(r["method_stats"].contains("mean_cut_size="), "{r:?}");
        } else if r["method"] == "LI" {
            assert_eq!(r["setting"], "record_reach_scale", "{r:?}");
            assert_eq!(r["value"], "2", "{r:?}");
            assert!(r["method_stats"].contains("records_per_pixel="), "{r:?}");
        } else {
            assert_eq!(r["setting"], "spp", "{r:?}");
            assert_eq!(r["spp"], r["value"], "{r:?}");
            for c in ["sample_gpu_ms", "steps_per_traversal", "steps_per_pixel"] {
                assert!(r[c].parse::<f64>().is_ok_and(f64::is_finite), "{c}: {r:?}");
            }
        }
    }
    let lc: Vec<&str> = rows
        .iter()
        .filter(|r| r["method"] == "Lightcuts")
        .map(|r| r["value"].as_str())
        .collect();
    assert_eq!(lc, ["0.2", "0.05"], "the Lightcuts sweep");
    check_csv(
        &d,
        "equal_time_matched.csv",
        &[
            "method",
            "extrapolated",
            "spp_at_matched_time",
            "setting",
            "value_at_matched_time",
        ],
        &[
            "matched_gi_gpu_ms",
            "rmse_interpolated",
            "measured_gi_gpu_ms",
            "measured_frame_wall_ms",
            "measured_rmse",
            "measured_flip",
            "measured_mean_ratio",
            "measured_bias_rmse",
        ],
        4,
    );
    check_csv(
        &d,
        "steps.csv",
        &["method"],
        &[
            "steps_per_traversal",
            "steps_per_pixel",
            "pixel_median",
            "pixel_p90",
            "sample_pass_ms",
            "sample_pass_ms_no_shadow_rays",
            "shadow_ray_share",
        ],
        3,
    );
    check_csv(
        &d,
        "blocks.csv",
        &["block", "cuts"],
        &[
            "cuts_gpu_ms",
            "sample_gpu_ms",
            "gi_gpu_ms",
            "frame_wall_ms",
            "rmse",
            "mean_ratio",
            "ssim",
        ],
        2,
    );
    check_csv(
        &d,
        "blending.csv",
        &["config", "blending", "fallback"],
        &[
            "frame_wall_ms",
            "gi_gpu_ms",
            "rmse",
            "mean_ratio",
            "ssim",
            "fallback_fraction",
        ],
        5,
    );
    check_csv(
        &d,
        "upsampling.csv",
        &["width", "height", "gi_resolution"],
        &["rmse", "mean_ratio", "ssim", "gi_gpu_ms", "frame_wall_ms"],
        2,
    );
    check_csv(
        &d,
        "scaling.csv",
        &["vpls"],
        &[
            "tree_gpu_ms",
            "gi_gpu_ms",
            "frame_wall_ms",
            "rmse",
            "mean_ratio",
            "ssim",
        ],
        2,
    );
    check_csv(
        &d,
        "interpolation.csv",
        &["method", "paper_time_vs_lightcuts", "method_stats", "max_cut"],
        &[
            "gi_gpu_ms",
            "time_vs_lightcuts",
            "rmse_vs_ground_truth",
            "relative_rmse_vs_ground_truth",
            "ssim_vs_ground_truth",
            "mean_ratio",
            "rmse_vs_lightcuts",
            "mean_ratio_vs_lightcuts",
        ],
        3,
    );
    // Stochastic vs clamped culling and the sphere tree: 2 VPL counts x 2 visibilities x 3
    // variants, then the second bound at the base count (--vpls) x 2 x 3; the stochastic
    // ranges with imperfect shadow maps, with and without their range culling, at both counts
    // (+ 4), and with them at the second bound (+ 1).
    check_csv(
        &d,
        "culling.csv",
        &["ranges", "visibility", "vpls", "epsilon_max"],
        &[
            "gi_gpu_ms",
            "vpls_in_range_per_pixel",
            "rmse_vs_same_visibility_truth",
            "mean_ratio",
            "rmse_vs_true_ground_truth",
            "mean_ratio_vs_true_ground_truth",
            "shade_ms",
            "ism_ms",
        ],
        23,
    );
    let (_, rows) = read_csv(&d.join("culling.csv"));
    assert!(
        rows.iter()
            .any(|r| r["ranges"] == "clamped" && r["visibility"] == "rays")
    );
    assert!(rows.iter().any(|r| r["epsilon_max"].starts_with("0.005")));
    assert!(
        rows.iter()
            .any(|r| r["ranges"] == "tree" && r["visibility"] == "rays")
    );
    for r in &rows {
        let rays: f64 = r["shadow_rays_per_pixel"].parse().unwrap();
        assert_eq!(rays == 0.0, r["visibility"] == "none", "{r:?}");
        let ism: f64 = r["ism_ms"].parse().unwrap();
        assert_eq!(ism > 0.0, r["visibility"].starts_with("ism"), "{r:?}");
    }
    assert_eq!(
        rows.iter()
            .filter(|r| r["visibility"] == "ism-unculled" && r["ranges"] == "stochastic")
            .count(),
        2
    );
    check_csv(
        &d,
        "culling_table1.csv",
        &["paper_pass"],
        &["our_ms", "paper_ms"],
        3,
    );
    // The VAL paper's Table 1: 64 and 512 VALs with rays, PCSS and simple lookups, and the
    // VPL-shading mode with rays.
    check_csv(
        &d,
        "val.csv",
        &["method", "vals", "visibility", "mean_ratio_vs_exact_visibility"],
        &[
            "clustering_ms",
            "indirect_ms",
            "ism_ms",
            "gi_gpu_ms",
            "rmse_vs_ground_truth",
            "mean_ratio_vs_ground_truth",
        ],
        10,
    );
    let (_, rows) = read_csv(&d.join("val.csv"));
    assert_eq!(rows.iter().filter(|r| r["clusters_carried"] == "true").count(), 2);
    for r in &rows {
        let ism: f64 = r["ism_ms"].parse().unwrap();
        let maps = r["visibility"] == "ism" || r["visibility"] == "pcss";
        assert_eq!(ism > 0.0, maps, "{r:?}");
        // Exact visibility is the disk's (VALs) or a ray (their point lights); carried
        // clusters have no exact-visibility twin.
        let exact: f64 = r["rmse_vs_exact_visibility"].parse().unwrap();
        if r["clusters_carried"] == "true" {
            assert!(exact.is_nan(), "{r:?}");
        } else {
            assert_eq!(exact == 0.0, !maps, "{r:?}");
        }
    }
    check_csv(
        &d,
        "val_table1.csv",
        &["row"],
        &["ours_64_pcss_ms", "ours_512_simple_ms", "paper_64_pcss_ms"],
        4,
    );
    // The whole configurations' error against the truth, the mean ratio beside the RMSE.
    let (_, rows) = read_csv(&d.join("val_table1.csv"));
    let complete = rows
        .iter()
        .find(|r| r["row"].starts_with("complete"))
        .expect("complete row");
    for k in [
        "ours_64_pcss_rmse_vs_ground_truth",
        "ours_64_pcss_mean_ratio_vs_ground_truth",
        "ours_512_simple_rmse_vs_ground_truth",
        "ours_512_simple_mean_ratio_vs_ground_truth",
    ] {
        let v: f64 = complete[k].parse().unwrap_or(f64::NAN);
        assert!(v.is_finite() && v > 0.0, "{k}: {complete:?}");
    }
    let (_, rows) = read_csv(&d.join("interpolation.csv"));
    let names: Vec<&str> = rows.iter().map(|r| r["method"].as_str()).collect();
    assert_eq!(names, ["Lightcuts", "LI full vis.", "LI interp. vis."]);
    for r in &rows {
        assert_eq!(r["max_cut"], "64", "--set reaches the figure: {r:?}");
    }
    assert!(
        rows[2]["method_stats"].contains("interpolation_rays_per_pixel=0.0000"),
        "{:?}",
        rows[2]
    );
    check_csv(
        &d,
        "interpolation_passes.csv",
        &["method", "pass"],
        &["median_ms", "share"],
        2 + 2 * 8,
    );
    check_csv(
        out,
        "checks.csv",
        &["scene", "check", "kind", "met"],
        &["value", "limit"],
        8,
    );
    for p in [
        "timings.png",
        "equal_time_rmse.png",
        "equal_time_ssim.png",
        "steps.png",
        "steps_hist.png",
        "blocks_rmse.png",
        "blocks_time.png",
        "blending_rmse.png",
        "blending_time.png",
        "upsampling.png",
        "scaling_time.png",
        "scaling_rmse.png",
        "images/ground_truth.png",
        "images/equal_time_slc.png",
        "images/equal_time_sst_error.png",
        "images/equal_time_lightcuts.png",
        "images/equal_time_li.png",
        "images/steps_rtslc.png",
        "images/block_1.png",
        "images/blend_no_blending.png",
        "images/blend_recompute_error.png",
        "images/fallback_pixels.png",
        "images/upsampling_half.png",
        "culling_time_vpls.png",
        "culling_rmse_vpls.png",
        "culling_rmse_eps.png",
        "culling_time_eps.png",
        "images/culling_stochastic.png",
        "images/culling_clamped_error.png",
        "interpolation.png",
        "images/interpolation_li_interp.png",
        "images/interpolation_li_full_error.png",
        "images/val_64_pcss.png",
        "images/val_512_ism_error.png",
    ] {
        decodes(&d.join(p));
    }
    // The temporal figure: a row per motion and method, a per-frame row each, GPU times of
    // the stage's passes, a plot per motion.
    let (_, rows) = common::read_csv(&d.join("temporal_summary.csv"));
    assert_eq!(rows.len(), 3 * 5, "{rows:?}");
    for r in &rows {
        let (raw, filt): (f64, f64) = (
            r["rmse_raw"].parse().unwrap(),
            r["rmse_filtered"].parse().unwrap(),
        );
        assert!(raw.is_finite() && filt.is_finite() && raw > 0.0, "{r:?}");
        for c in ["mean_ratio_raw", "mean_ratio_filtered"] {
            assert!(
                r[c].parse::<f64>().is_ok_and(|v| v.is_finite() && v > 0.0),
                "{c}: {r:?}"
            );
        }
        assert_eq!(r["temporal"], "svgf");
    }
    check_csv(
        &d,
        "temporal.csv",
        &["motion", "method", "frame"],
        &[
            "rmse_raw",
            "rmse_filtered",
            "mean_ratio_raw",
            "mean_ratio_filtered",
        ],
        3 * 5 * 3,
    );
    let (_, rows) = common::read_csv(&d.join("temporal.csv"));
    assert_eq!(rows.len(), 3 * 5 * 3);
    let (_, rows) = common::read_csv(&d.join("temporal_timing.csv"));
    assert!(
        rows.iter()
            .any(|r| r["pass"] == "temporal_atrous" && r["median_ms"].parse::<f64>().unwrap() > 0.0),
        "{rows:?}"
    );
    for p in [
        "temporal_rmse_camera_path.png",
        "temporal_rmse_sun_sweep.png",
        "temporal_rmse_still.png",
    ] {
        decodes(&d.join(p));
    }
    // The tree comparison: every method that runs on either tree (the three samplers and
    // Lightcuts, not Lightcut Interpolation) on both trees, and an equal-time row each.
    let (_, rows) = common::read_csv(&d.join("trees.csv"));
    for m in ["SLC", "RTSLC", "SST", "Lightcuts"] {
        for t in ["perfect", "lbvh"] {
            assert!(
                rows.iter().any(|r| r["method"] == m && r["tree"] == t),
                "{m} on {t}: {rows:?}"
            );
        }
    }
    assert!(rows.iter().all(|r| r["method"] != "LI"), "{rows:?}");
    for r in &rows {
        assert!(
            r["rmse"].parse::<f64>().is_ok_and(|v| v.is_finite() && v > 0.0),
            "{r:?}"
        );
        assert!(r["total_gpu_ms"].parse::<f64>().is_ok_and(|v| v > 0.0), "{r:?}");
    }
    // The bounce-count figure: the five methods at 1 bounce and at 2 bounces with paths by
    // flux and mixed (3 configurations); light-path time only above one bounce.
    let (_, rows) = common::read_csv(&d.join("bounces.csv"));
    assert_eq!(rows.len(), 5 * 3, "{rows:?}");
    for r in &rows {
        let n: u32 = r["bounces"].parse().unwrap();
        let paths: f64 = r["light_paths_gpu_ms"].parse().unwrap();
        assert!(if n == 1 { paths == 0.0 } else { paths > 0.0 }, "{r:?}");
        for c in [
            "gi_gpu_ms",
            "rmse",
            "relative_rmse",
            "gt_mean",
            "gt_mean_over_one_bounce",
        ] {
            assert!(
                r[c].parse::<f64>().is_ok_and(|v| v.is_finite() && v > 0.0),
                "{c}: {r:?}"
            );
        }
        if n > 1 {
            assert!(r["path_vpls_alive"].parse::<u32>().unwrap() > 0, "{r:?}");
        }
    }
    decodes(&d.join("bounces_rmse.png"));
    decodes(&d.join("bounces_light.png"));
    check_csv(
        &d,
        "trees_equal_time.csv",
        &["method", "extrapolated"],
        &[
            "rmse_perfect",
            "rmse_lbvh",
            "mean_ratio_perfect",
            "mean_ratio_lbvh",
        ],
        4,
    );
    let (_, rows) = common::read_csv(&d.join("trees_equal_time.csv"));
    assert_eq!(rows.len(), 4, "{rows:?}");
    decodes(&d.join("trees_rmse.png"));
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(run["width"], 48);
    // Each figure's wall time and the share of it outside rendering / GPU waits.
    let times = run["scenes"][0]["figure_times"].as_array().unwrap();
    assert_eq!(times.len(), 13, "{times:?}");
    for t in times {
        let share = t["share_outside_gpu"].as_f64().unwrap();
        assert!(
            (0.0..=1.0).contains(&share) && t["wall_s"].as_f64().unwrap() > 0.0,
            "{t}"
        );
    }
    assert!(
        run["scenes"][0]["adapter"]
            .as_str()
            .is_some_and(|a| !a.is_empty())
    );
    assert!(stdout.contains("checks"), "{stdout}");
    assert_eq!(run["merged_shards"], 2);
    assert_eq!(run["units"].as_array().map(Vec::len), Some(13));
}

#[test]
fn one_figure_alone_and_bad_options_give_one_clear_line() {
    if common::gpu().is_none() {
        return;
    }
    let out = std::env::temp_dir().join(format!("lightcut-results-steps-{}", std::process::id()));
    let o = bin()
        .args([
            "results", "steps", "--scenes", "default", "--width", "48", "--height", "32", "--frames", "1",
            "--vpls", "512", "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let d = out.join("default");
    assert!(d.join("steps.csv").exists());
    assert!(!d.join("timings.csv").exists(), "only the asked figure runs");
    let _ = std::fs::remove_dir_all(&out);
    for (args, needle) in [
        (vec!["results", "--spp", "0"], "--spp"),
        (vec!["results", "--blocks", "65"], "--blocks"),
        (vec!["results", "--width", "8"], "--width"),
        (
            vec!["results", "--scenes", "/nonexistent/x.gltf"],
            "/nonexistent/x.gltf",
        ),
    ] {
        let o = bin().args(&args).output().unwrap();
        assert!(!o.status.success(), "{args:?} should fail");
        let err = String::from_utf8_lossy(&o.stderr);
        let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("error")).collect();
        assert_eq!(lines.len(), 1, "{args:?}: {err}");
        assert!(lines[0].contains(needle), "{args:?}: {err}");
    }
}

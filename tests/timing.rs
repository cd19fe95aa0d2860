//! GPU-true measurement (issues 18 and 41): the figures of `results` time the same thing.
//! For one scene and settings, `timings`, `steps`, `equal-time` and `blocks` each measure SLC at
//! the base settings; `timing_agreement.csv` lists what each timed (the passes summed, every
//! pass of the frame, the frame mode, the number of frames) and they must be the same; the
//! equal-time sweep's work follows its sample count (traversals per pixel = spp). Nothing
//! here asserts a time: how far the figures' times agree is a check of `results --check`, for
//! a real GPU (on a shared CPU the adapter's speed wanders, and a test of it failed under load).

mod common;

use std::{collections::HashMap, path::Path, process::Command};

fn num(row: &HashMap<String, String>, col: &str) -> f64 {
    row.get(col)
        .unwrap_or_else(|| panic!("no column {col} in {row:?}"))
        .parse()
        .unwrap_or(f64::NAN)
}

fn run_figures(out: &Path) {
    let o = Command::new(env!("CARGO_BIN_EXE_lightcut-workbench"))
        .args([
            "results",
            "timings,steps,equal-time,blocks",
            "--scenes",
            "default",
            // Small, with a small shadow map, so that the sampling pass dominates the frame;
            // 20 timed frames per configuration, 1 diagnostic one.
            "--width",
            "64",
            "--height",
            "48",
            "--shadow-res",
            "256",
            "--frames",
            "1",
            "--timing-frames",
            "20",
            "--spp",
            "8,16",
            "--blocks",
            "8",
            "--vpls",
            "1024",
            // The thesis's samplers only (their sampling pass is what this test compares).
            "--methods",
            "slc,rtslc,sst",
            "--out",
        ])
        .arg(out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "stdout: {stdout}\nstderr: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn the_figures_time_the_same_passes_and_their_work_grows_with_spp() {
    if common::gpu().is_none() {
        return;
    }
    let out = std::env::temp_dir().join(format!("lightcut-timing-{}", std::process::id()));
    run_figures(&out);
    let d = out.join("default");
    let rows = common::read_csv(&d.join("timing_agreement.csv")).1;
    let mut figures: Vec<&str> = rows.iter().map(|r| r["figure"].as_str()).collect();
    figures.sort_unstable();
    assert_eq!(figures, ["Blocks", "EqualTime", "Steps", "Timings"], "{rows:?}");
    for r in &rows {
        for col in ["timed_passes", "frame_passes", "frame_kind", "timed_frames"] {
            assert_eq!(
                r[col], rows[0][col],
                "{}: {col} differs from {}'s",
                r["figure"], rows[0]["figure"]
            );
        }
        assert!(
            num(r, "sample_ms_min") > 0.0 && num(r, "sample_ms_median") >= num(r, "sample_ms_min"),
            "{r:?}"
        );
    }
    assert_eq!(rows[0]["timed_passes"], "slc_sample");
    assert_eq!(rows[0]["frame_kind"], "Timed");
    assert_eq!(rows[0]["timed_frames"], "20");
    assert!(
        rows[0]["frame_passes"].contains("+slc_sample+"),
        "{:?}",
        rows[0]["frame_passes"]
    );
    // The checks: the same passes met; the agreement measured (a number, not asserted).
    let checks = common::read_csv(&out.join("checks.csv")).1;
    let same = checks
        .iter()
        .find(|c| c["check"].starts_with("the figures time the same passes"))
        .expect("the same-passes check");
    assert_eq!(same["met"], "true", "{same:?}");
    let agree = checks
        .iter()
        .find(|c| c["check"].starts_with("the figures' fastest SLC sampling frames agree"))
        .expect("the agreement check");
    // Measured, not asserted (max / min of four positive times: finite, at least 1).
    assert!(num(agree, "value").is_finite(), "{agree:?}");
    // The equal-time sweep: the work each configuration timed follows its sample count
    // (traversals per pixel = steps per pixel / steps per traversal = spp: one traversal a
    // sample), where the test used to ask the time to grow with it.
    let sweep = common::read_csv(&d.join("equal_time.csv")).1;
    for method in ["SLC", "RTSLC", "SST"] {
        let rows: Vec<_> = sweep.iter().filter(|r| r["method"] == method).collect();
        let mut spps: Vec<u32> = rows.iter().map(|r| r["spp"].parse().unwrap()).collect();
        spps.sort_unstable();
        assert_eq!(spps, [8, 16, 32], "{method}");
        for r in rows {
            let spp: f64 = r["spp"].parse().unwrap();
            let traversals = num(r, "steps_per_pixel") / num(r, "steps_per_traversal");
            assert!(
                (traversals / spp - 1.0).abs() < 0.01,
                "{method} at {spp} spp: {traversals:.3} traversals per pixel"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// Issue 41's first screen: while the comparison's ground truth converges, the frames stay
/// timed (their timings are the method's passes; the truth's passes take no timestamps), and
/// the truth's composite shows the VPLs so far scaled to all of them, at about the final
/// image's brightness.
#[test]
fn frames_are_timed_while_the_comparison_truth_converges() {
    use lightcut::renderer::{Buffer, FrameMode};
    let Some(ctx) = common::gpu() else { return };
    let mut s = lightcut::renderer::settings::RenderSettings::default();
    s.vpl.count = 1024;
    // A few VPLs per frame: the truth takes many frames.
    s.gi.rays_per_frame = 48 * 32 * 64;
    let mut st = common::Setup::new(&ctx, s, (48, 32));
    if !st.r.timestamps_supported() {
        eprintln!("SKIPPED: no timestamps on this adapter");
        return;
    }
    st.r.set_frame_mode(FrameMode::Timed);
    st.r.set_compare_ground_truth(true);
    let mut timed = 0;
    let mut partial_means = Vec::new();
    for _ in 0..6 {
        st.frame();
        ctx.wait_idle().unwrap();
        if let Some(t) = st.r.wait_new_timings() {
            timed += 1;
            assert!(t.get("slc_sample").is_some(), "{:?}", t.passes);
            assert!(
                t.get("ground_truth").is_none(),
                "the truth was timed: {:?}",
                t.passes
            );
        }
        let p = st.r.compare_progress().expect("the comparison runs");
        assert!(!p.finished(), "the truth finished too early to test this");
        let gt = st.r.read(Buffer::GroundTruthIndirect).unwrap().mean_rgb();
        partial_means.push(gt[0] + gt[1] + gt[2]);
    }
    assert!(
        timed >= 4,
        "only {timed} of 6 frames timed while the truth converges"
    );
    // Run the truth to the end: its scaled partial images were near its final brightness.
    let mut n = 0;
    while !st.r.compare_progress().is_some_and(|p| p.finished()) && n < 400 {
        st.frame();
        n += 1;
    }
    let fin = st.r.read(Buffer::GroundTruthIndirect).unwrap().mean_rgb();
    let fin = fin[0] + fin[1] + fin[2];
    assert!(fin > 0.0);
    for (i, m) in partial_means.iter().enumerate().skip(1) {
        assert!(
            (m / fin - 1.0).abs() < 0.35,
            "frame {i}: the converging truth's mean is {:.3} of the final",
            m / fin
        );
    }
}

//! Every command example in README.md, run at a tiny size and checked to do what its comment
//! promises. The README's `cargo run --release` lines and the table below must match exactly
//! (a new example without a check, or a check of a removed example, fails the test). CLI
//! examples run the built binary (sizes, frame counts and output folders shrunk or moved to a
//! temporary folder); GUI examples build the app through `egui_kittest` from the same command
//! line (`cli::gui_options`), as `main` does.

mod common;

use lightcut::methods::tree_samplers::settings::SamplingSettings;
use std::path::{Path, PathBuf};
use std::process::Command;

use clap::Parser;
use egui_kittest::Harness;
use lightcut::app::WorkbenchApp;
use lightcut::cli::{Cli, gui_options};
use lightcut::methods::{Kind, REGISTRY, tree_samplers};
use lightcut::renderer::{Buffer, settings::ViewBuffer};

/// The README's command lines (after `cargo run --release`), exactly as written there.
const EXAMPLES: &[&str] = &[
    "",
    "-- fetch-scenes",
    "-- methods",
    "-- --scene scenes/sponza.toml",
    "-- --scene breakfast_room/BreakfastRoom.gltf --camera CameraMain",
    "-- render --scene scenes/breakfast_room.toml --width 1280 --height 720 --out out/",
    "-- render --scene default --width 320 --height 240 --method ground-truth --out out/gt",
    "-- render --scene default --width 320 --height 240 --method reference --samples 1024 --out out/ref",
    "-- export-scene --scene default --out out/scene",
    "-- bench rays --scene scenes/sponza.toml",
    "-- bench gbuffer --scene scenes/sponza.toml",
    "-- render --scene default --width 320 --height 240 --method slc --frames 16 --compare-gt --out out/slc",
    "-- compare out/slc/indirect.exr out/slc/ground_truth_indirect.exr --exposure 3",
    "-- bench tree",
    "-- render --scene default --width 320 --height 240 --method lightcuts --set methods.lightcuts.relative_error=0.02 --compare-gt --out out/lc",
    "-- render --scene default --width 320 --height 240 --method lightcut-interpolation --set methods.lightcut-interpolation.visibility=interpolated --compare-gt --out out/li",
    "-- render --scene default --width 320 --height 240 --method light-culling --visibility none --compare-gt --out out/lcull",
    "-- render --scene default --width 320 --height 240 --method val --visibility pcss --compare-gt --out out/val",
    "-- results val --scenes scenes/sponza.toml,scenes/breakfast_room.toml --out results",
    "-- render --scene default --width 320 --height 240 --method slc --temporal svgf --camera-path --path-frames 60 --compare-gt --out out/temporal",
    "-- results temporal --scenes scenes/sponza.toml,scenes/breakfast_room.toml --out results",
    "-- results interpolation --scenes scenes/sponza.toml,scenes/breakfast_room.toml --out results",
    "-- results trees --scenes scenes/sponza.toml,scenes/breakfast_room.toml --out results",
    "-- bench lightcuts --scene scenes/sponza.toml --width 160 --height 90",
    "-- --view albedo --settings docs/settings-example.toml --tree-stats",
    "-- --compare-gt --views \"final;GI only;traversal steps;A/B comparison\" --pin 150,70",
    "-- sheet --methods slc,rtslc,sst --frames 16 --out screenshots/comparison_sheet.png",
    "-- results --out docs/results",
    "-- render --scene default --width 320 --height 240 --method slc --bounces 3 --compare-gt --out out/slc3",
    "-- render --scene default --width 320 --height 240 --method reference --samples 1024 --bounces 3 --out out/ref3",
    "-- results bounces --scenes scenes/sponza.toml,scenes/breakfast_room.toml --out results",
    // Not `cargo run`: the independent check, run when Mitsuba 3 is importable.
    "python3 scripts/mitsuba_check.py --scene-dir out/scene --ours out/ref --width 320 --height 240 --indirect --out out/check",
    "python3 scripts/mitsuba_check.py --scene-dir out/scene --ours out/ref3 --width 320 --height 240 --indirect --bounces 3 --out out/check3",
];

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Words of a command line (double quotes group, as the shell does for these examples).
fn words(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut any = false;
    for c in line.chars() {
        match c {
            '"' => {
                quoted = !quoted;
                any = true;
            }
            c if c.is_whitespace() && !quoted => {
                if any {
                    out.push(std::mem::take(&mut cur));
                    any = false;
                }
            }
            c => {
                cur.push(c);
                any = true;
            }
        }
    }
    if any {
        out.push(cur);
    }
    out
}

/// The `cargo run --release ...` lines of the README's shell blocks (the part after it).
fn readme_examples() -> Vec<String> {
    let text = std::fs::read_to_string(repo().join("README.md")).expect("README.md");
    let mut in_sh = false;
    let mut v = Vec::new();
    for line in text.lines() {
        if line.starts_with("```") {
            in_sh = line.trim() == "```sh";
            continue;
        }
        if !in_sh {
            continue;
        }
        if let Some(i) = line.find("cargo run --release") {
            v.push(line[i + "cargo run --release".len()..].trim().to_string());
        } else if line.starts_with("python3 ") {
            v.push(line.trim().to_string());
        }
    }
    v
}

#[test]
fn the_readme_examples_are_the_checked_ones() {
    let mut found = readme_examples();
    found.sort();
    found.dedup();
    let mut want: Vec<String> = EXAMPLES.iter().map(|s| s.to_string()).collect();
    want.sort();
    assert_eq!(found, want, "README examples and the checked examples differ");
}

/// The example's arguments after `--`, with `(flag, value)` replaced and `extra` appended.
fn args(example: &str, replace: &[(&str, &str)], extra: &[&str]) -> Vec<String> {
    let mut w = words(example);
    if !w.is_empty() {
        assert_eq!(w[0], "--", "{example}");
        w.remove(0);
    }
    for (flag, value) in replace {
        let i = w
            .iter()
            .position(|x| x == flag)
            .unwrap_or_else(|| panic!("{flag} in {example}"));
        w[i + 1] = value.to_string();
    }
    w.extend(extra.iter().map(|s| s.to_string()));
    w
}

fn run_cli(a: &[String]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_lightcut-workbench"))
        .args(a)
        .current_dir(repo())
        .output()
        .expect("run the binary");
    let stdout = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        o.status.success(),
        "{a:?} failed\nstdout: {stdout}\nstderr: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    stdout
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("lightcut-readme-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn mean(path: &Path) -> [f64; 3] {
    lightcut::export::read_exr(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .mean_rgb()
}

/// The reference scenes on the scene search path (`fetch-scenes`, `LIGHTCUT_SCENES`,
/// `../shared/scenes`), as the presets find them.
fn shared_present() -> bool {
    lightcut::scene::scene_path::find(Path::new("sponza/Sponza.gltf"), Some(&repo().join("scenes"))).is_ok()
        && lightcut::scene::scene_path::find(Path::new("breakfast_room/BreakfastRoom.gltf"), None).is_ok()
}

fn setup() -> egui_wgpu::WgpuSetup {
    let mut s = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    s.instance_descriptor.backends = lightcut::renderer::context::BACKENDS;
    s.device_descriptor = std::sync::Arc::new(lightcut::renderer::context::device_descriptor);
    egui_wgpu::WgpuSetup::CreateNew(s)
}

/// The GUI of `example` (no subcommand) in a small window, after `steps` frames.
fn gui(example: &str, size: egui::Vec2, steps: usize) -> Harness<'static, WorkbenchApp> {
    let mut argv = vec!["lightcut-workbench".to_string()];
    argv.extend(args(example, &[], &[]));
    let cli = Cli::try_parse_from(&argv).unwrap_or_else(|e| panic!("{example}: {e}"));
    // A fresh app state (no saved layout), as on a clean checkout.
    let options = gui_options(&cli).expect("options");
    let mut h = Harness::builder()
        .with_size(size)
        .wgpu_setup(setup())
        .build_eframe(move |cc| WorkbenchApp::new(cc, options.clone()));
    h.run_steps(steps);
    assert!(
        h.state().errors().is_empty(),
        "{example}: {:?}",
        h.state().errors()
    );
    h
}

fn gi_mean(h: &Harness<'_, WorkbenchApp>) -> [f64; 3] {
    h.state()
        .renderer()
        .expect("renderer")
        .read(Buffer::Indirect)
        .expect("GI")
        .mean_rgb()
}

#[test]
fn gui_examples_open_what_they_promise() {
    if common::gpu().is_none() {
        return;
    }
    // `cargo run --release`: SLC, GI visible, the four first-screen views, the comparison's
    // ground truth running.
    let h = gui("", egui::vec2(900.0, 600.0), 4);
    let r = h.state().renderer().expect("renderer");
    assert_eq!(r.settings().gi.method, tree_samplers::SLC);
    let views: Vec<ViewBuffer> = h.state().layout().panes().iter().map(|p| p.spec.buffer).collect();
    assert_eq!(views, lightcut::app::first_screen());
    assert!(gi_mean(&h)[1] > 0.0, "GI is black");
    assert!(r.compare_progress().is_some(), "no ground truth beside SLC");
    drop(h);

    // The views, the ground truth and a pinned pixel's story with samples.
    let ex = "-- --compare-gt --views \"final;GI only;traversal steps;A/B comparison\" --pin 150,70";
    let h = gui(ex, egui::vec2(1440.0, 900.0), 5);
    assert_eq!(h.state().layout().view_count(), 4);
    assert!(gi_mean(&h)[1] > 0.0, "GI is black");
    let r = h.state().renderer().expect("renderer");
    assert!(
        r.compare_progress().is_some_and(|p| p.done > 0),
        "no ground truth"
    );
    let story = h.state().story();
    assert!(story.show, "the story is not open");
    assert!(
        h.state().docked_tools().contains(&lightcut::app::Tool::Story),
        "the story floats over the views instead of docking beside them"
    );
    let t = story.trace.as_ref().unwrap_or_else(|| {
        panic!(
            "no story at the pinned pixel (frame {:?}): {}",
            r.size(),
            story.note
        )
    });
    assert!(!t.samples.is_empty(), "a story without samples");
    drop(h);

    // A view and a settings file by name, the statistics window open.
    let h = gui(
        "-- --view albedo --settings docs/settings-example.toml --tree-stats",
        egui::vec2(700.0, 500.0),
        3,
    );
    assert_eq!(h.state().view(), ViewBuffer::Albedo);
    assert!(h.state().tree_stats_shown());
    let s = h.state().renderer().expect("renderer").settings();
    assert_eq!(
        (s.shadow.resolution, s.vpl.count, SamplingSettings::of(s).cut_size),
        (1024, 2048, 16)
    );
    drop(h);

    if !shared_present() {
        eprintln!(
            "SKIPPED the shared-scene GUI examples: the reference scenes are not fetched (fetch-scenes)"
        );
        return;
    }
    let h = gui("-- --scene scenes/sponza.toml", egui::vec2(400.0, 300.0), 1);
    assert_eq!(h.state().open().expect("a scene").scene.name, "Sponza");
    drop(h);
    let h = gui(
        "-- --scene breakfast_room/BreakfastRoom.gltf --camera CameraMain",
        egui::vec2(400.0, 300.0),
        1,
    );
    assert_eq!(h.state().open().expect("a scene").camera.name, "CameraMain");
}

#[test]
fn cli_examples_write_what_they_promise() {
    if common::gpu().is_none() {
        return;
    }
    // The method table lists every registered method.
    let out = run_cli(&args("-- methods", &[], &[]));
    for m in REGISTRY {
        let row = format!("{:<14} ", m.id.cli());
        assert!(
            out.lines().any(|l| l.starts_with(&row)),
            "{} missing from `methods`",
            m.id
        );
    }
    // The README's promise: each per-frame method's bias, and how to make it unbiased.
    let per_frame = REGISTRY.iter().filter(|m| m.kind == Kind::PerFrame).count();
    let biases = out
        .lines()
        .filter(|l| l.contains("against the ground truth of the same VPLs: "))
        .count();
    assert_eq!(biases, per_frame, "{out}");
    let unbiasable = REGISTRY.iter().filter(|m| m.unbiased.is_some()).count();
    assert_eq!(out.matches("unbiased with: ").count(), unbiasable, "{out}");
    assert!(
        out.contains("biased, within 2%") && out.contains("unbiased"),
        "{out}"
    );

    // Ground truth and reference: GI written, the promised summary printed.
    let gt = tmp("gt");
    let out = run_cli(&args(
        "-- render --scene default --width 320 --height 240 --method ground-truth --out out/gt",
        &[
            ("--width", "40"),
            ("--height", "30"),
            ("--out", gt.to_str().unwrap()),
        ],
        &["--vpls", "256"],
    ));
    assert!(out.contains("ground truth: 256 VPLs"), "{out}");
    assert!(mean(&gt.join("indirect.exr"))[1] > 0.0);
    let rf = tmp("ref");
    let out = run_cli(&args(
        "-- render --scene default --width 320 --height 240 --method reference --samples 1024 --out out/ref",
        &[
            ("--width", "40"),
            ("--height", "30"),
            ("--samples", "8"),
            ("--out", rf.to_str().unwrap()),
        ],
        &[],
    ));
    assert!(out.contains("reference: 8 samples per pixel"), "{out}");
    assert!(mean(&rf.join("indirect.exr"))[1] > 0.0);
    // Three bounces: the reference with light paths, SLC against its ground truth.
    let rf3 = tmp("ref3");
    let out = run_cli(&args(
        "-- render --scene default --width 320 --height 240 --method reference --samples 1024 --bounces 3 --out out/ref3",
        &[
            ("--width", "40"),
            ("--height", "30"),
            ("--samples", "8"),
            ("--out", rf3.to_str().unwrap()),
        ],
        &[],
    ));
    assert!(
        out.contains("light_paths") && out.contains("reference: 8 samples per pixel"),
        "{out}"
    );
    assert!(mean(&rf3.join("indirect.exr"))[1] > 0.0);
    let slc3 = tmp("slc3");
    let out = run_cli(&args(
        "-- render --scene default --width 320 --height 240 --method slc --bounces 3 --compare-gt --out out/slc3",
        &[
            ("--width", "40"),
            ("--height", "30"),
            ("--out", slc3.to_str().unwrap()),
        ],
        &["--vpls", "384"],
    ));
    assert!(
        out.contains("light_paths") && out.contains("ground truth (384 VPLs)"),
        "{out}"
    );
    assert!(slc3.join("ground_truth_indirect.exr").is_file());
    let _ = std::fs::remove_dir_all(&slc3);

    // The scene for an independent renderer.
    let sc = tmp("scene");
    run_cli(&args(
        "-- export-scene --scene default --out out/scene",
        &[("--out", sc.to_str().unwrap())],
        &[],
    ));
    assert!(sc.join("scene.json").is_file() && sc.join("mesh_0.ply").is_file());

    // The Mitsuba 3 check of the reference against the exported scene (docs/mitsuba_check.md),
    // where the `mitsuba` Python package is installed.
    let has_mitsuba = Command::new("python3")
        .args(["-c", "import mitsuba, numpy"])
        .output()
        .is_ok_and(|o| o.status.success());
    for (ex, ours) in [
        (
            "python3 scripts/mitsuba_check.py --scene-dir out/scene --ours out/ref --width 320 --height 240 --indirect --out out/check",
            &rf,
        ),
        (
            "python3 scripts/mitsuba_check.py --scene-dir out/scene --ours out/ref3 --width 320 --height 240 --indirect --bounces 3 --out out/check3",
            &rf3,
        ),
    ] {
        if !has_mitsuba {
            eprintln!("SKIPPED scripts/mitsuba_check.py: the mitsuba Python package is not installed");
            break;
        }
        let ck = tmp("check");
        let mut w = words(ex);
        for (flag, value) in [
            ("--scene-dir", sc.to_str().unwrap()),
            ("--ours", ours.to_str().unwrap()),
            ("--width", "40"),
            ("--height", "30"),
            ("--out", ck.to_str().unwrap()),
        ] {
            let i = w.iter().position(|x| x == flag).expect(flag);
            w[i + 1] = value.to_string();
        }
        let o = Command::new(&w[0])
            .args(&w[1..])
            .args(["--spp", "16", "--splits", "2"])
            .current_dir(repo())
            .output()
            .expect("python3");
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(
            o.status.success() && out.contains("Mitsuba"),
            "{out}\n{}",
            String::from_utf8_lossy(&o.stderr)
        );
        let _ = std::fs::remove_dir_all(ck);
    }
    let _ = std::fs::remove_dir_all(&rf3);

    // SLC with the ground truth of the same VPLs; then `compare` on its two EXRs.
    let slc = tmp("slc");
    let out = run_cli(&args(
        "-- render --scene default --width 320 --height 240 --method slc --frames 16 --compare-gt --out out/slc",
        &[
            ("--width", "40"),
            ("--height", "30"),
            ("--frames", "2"),
            ("--out", slc.to_str().unwrap()),
        ],
        &["--vpls", "256"],
    ));
    assert!(out.contains("vs ground truth"), "{out}");
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(slc.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(m["method"], "slc");
    // Exactly the frames asked for, however many views were drawn afterwards; the GPU times
    // are those of the timed frames (a warm-up frame not counted).
    assert_eq!(m["frames_averaged"], 2, "{m}");
    assert_eq!(m["timed_frames"], 2, "{m}");
    assert!(m["gpu_ms"]["slc_sample"].as_f64().is_some_and(|v| v > 0.0), "{m}");
    assert!(m["shadow_rays"].as_u64().is_some_and(|v| v > 0), "{m}");
    assert!(
        m["vs_ground_truth"]["rmse"]
            .as_f64()
            .is_some_and(|v| v.is_finite())
    );
    assert!(slc.join("traversal_steps.png").is_file());
    let a = slc.join("indirect.exr");
    let b = slc.join("ground_truth_indirect.exr");
    let ex = format!("-- compare {} {} --exposure 3", a.display(), b.display());
    let out = run_cli(&args(&ex, &[], &[]));
    assert!(out.contains("RMSE") && out.contains("SSIM"), "{out}");

    // The light-tree benchmark (two sizes here) prints a row per size and the slopes.
    let out = run_cli(&args("-- bench tree", &[], &["--max-log2", "13"]));
    assert!(
        out.contains("4096") && out.contains("8192") && out.contains("slope"),
        "{out}"
    );
    // Both variants, each size, in one run (issue 18's before / after).
    assert!(
        out.contains("baseline") && out.contains("parallel") && out.contains("speed-up"),
        "{out}"
    );
    // The radix tree: topology (equal to its CPU twin) and node data.
    assert!(
        out.contains("radix topology")
            && out.contains("node data")
            && out.contains("topology equals the CPU reference: yes"),
        "{out}"
    );

    // Lightcuts with a relative error set by --set, against the ground truth of its VPLs.
    let lc = tmp("lightcuts");
    run_cli(&args(
        "-- render --scene default --width 320 --height 240 --method lightcuts --set methods.lightcuts.relative_error=0.02 --compare-gt --out out/lc",
        &[
            ("--width", "32"),
            ("--height", "24"),
            ("--out", lc.to_str().unwrap()),
        ],
        &["--vpls", "256"],
    ));
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(lc.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(m["method"], "lightcuts");
    assert_eq!(m["method_stats"]["relative_error"].as_f64(), Some(0.02f32 as f64));
    assert!(
        m["method_stats"]["mean_cut_size"]
            .as_f64()
            .is_some_and(|v| v >= 1.0),
        "{m}"
    );
    assert!(
        m["vs_ground_truth"]["rmse"].as_f64().is_some_and(f64::is_finite),
        "{m}"
    );
    assert!(lc.join("lightcut_size.png").is_file() && lc.join("lightcut_at_max_cut.png").is_file());
    // Lightcut Interpolation with interpolated visibility: no ray of its own.
    let li = tmp("li");
    run_cli(&args(
        "-- render --scene default --width 320 --height 240 --method lightcut-interpolation --set methods.lightcut-interpolation.visibility=interpolated --compare-gt --out out/li",
        &[
            ("--width", "32"),
            ("--height", "24"),
            ("--out", li.to_str().unwrap()),
        ],
        &["--vpls", "256"],
    ));
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(li.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(m["method"], "lightcut-interpolation");
    assert_eq!(
        m["method_stats"]["interpolated_visibility"].as_f64(),
        Some(1.0),
        "{m}"
    );
    assert_eq!(
        m["method_stats"]["interpolation_rays_per_pixel"].as_f64(),
        Some(0.0),
        "{m}"
    );
    assert!(
        m["method_stats"]["records"].as_f64().is_some_and(|v| v >= 1.0),
        "{m}"
    );
    assert!(
        m["vs_ground_truth"]["rmse"].as_f64().is_some_and(f64::is_finite),
        "{m}"
    );
    assert!(li.join("li_records.png").is_file() && li.join("li_level_spread.png").is_file());
    // Stochastic Light Culling without visibility: no shadow ray, its views written.
    let lcull = tmp("lcull");
    run_cli(&args(
        "-- render --scene default --width 320 --height 240 --method light-culling --visibility none --compare-gt --out out/lcull",
        &[
            ("--width", "32"),
            ("--height", "24"),
            ("--out", lcull.to_str().unwrap()),
        ],
        &["--vpls", "256"],
    ));
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(lcull.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(m["method"], "light-culling");
    assert_eq!(
        m["method_stats"]["shadow_rays_per_pixel"].as_f64(),
        Some(0.0),
        "{m}"
    );
    assert!(
        m["method_stats"]["vpls_in_range_per_pixel"]
            .as_f64()
            .is_some_and(|v| v > 0.0),
        "{m}"
    );
    assert!(
        m["vs_ground_truth"]["mean_ratio"]
            .as_f64()
            .is_some_and(f64::is_finite),
        "{m}"
    );
    assert!(
        lcull.join("culling_lights_per_tile.png").is_file() && lcull.join("culling_pattern.png").is_file()
    );
    let _ = std::fs::remove_dir_all(&lcull);
    // Virtual Area Lights with PCSS lookups: its maps built, its views written.
    let val = tmp("val");
    run_cli(&args(
        "-- render --scene default --width 320 --height 240 --method val --visibility pcss --compare-gt --out out/val",
        &[
            ("--width", "32"),
            ("--height", "24"),
            ("--out", val.to_str().unwrap()),
        ],
        &["--vpls", "256", "--set", "methods.val.clusters=16"],
    ));
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(val.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(m["method"], "val");
    assert_eq!(m["method_stats"]["ism_maps"].as_f64(), Some(16.0), "{m}");
    assert!(
        m["method_stats"]["vals_lit"].as_f64().is_some_and(|v| v > 0.0),
        "{m}"
    );
    assert!(
        m["vs_ground_truth"]["rmse"].as_f64().is_some_and(f64::is_finite),
        "{m}"
    );
    for f in [
        "val_clusters.png",
        "val_disks.png",
        "val_ism_atlas.png",
        "val_penumbra_width.png",
    ] {
        assert!(val.join(f).is_file(), "{f}");
    }
    let _ = std::fs::remove_dir_all(&val);
    // The interpolation paper's comparison (the default scene, tiny, here).
    let lr = tmp("li-results");
    run_cli(&args(
        "-- results interpolation --scenes scenes/sponza.toml,scenes/breakfast_room.toml --out results",
        &[("--scenes", "default"), ("--out", lr.to_str().unwrap())],
        &[
            "--width",
            "32",
            "--height",
            "24",
            "--frames",
            "1",
            "--timing-frames",
            "2",
            "--vpls",
            "256",
            "--set",
            "methods.lightcut-interpolation.max_cut=32",
        ],
    ));
    let csv =
        std::fs::read_to_string(lr.join("default").join("interpolation.csv")).expect("interpolation.csv");
    assert_eq!(csv.lines().count(), 4, "{csv}");
    assert!(csv.contains("LI interp. vis."), "{csv}");
    for d in [li, lr] {
        let _ = std::fs::remove_dir_all(d);
    }
    // The VAL paper's Table 1 (the default scene, tiny: its 64 and 512 VALs on a 32 x 24
    // frame).
    let vr = tmp("val-results");
    run_cli(&args(
        "-- results val --scenes scenes/sponza.toml,scenes/breakfast_room.toml --out results",
        &[("--scenes", "default"), ("--out", vr.to_str().unwrap())],
        &[
            "--width",
            "32",
            "--height",
            "24",
            "--frames",
            "1",
            "--timing-frames",
            "2",
            "--vpls",
            "256",
        ],
    ));
    let csv = std::fs::read_to_string(vr.join("default").join("val_table1.csv")).expect("val_table1.csv");
    assert_eq!(csv.lines().count(), 5, "{csv}");
    let _ = std::fs::remove_dir_all(&vr);
    // SLC with SVGF along the default scene's camera path: per-frame errors of the raw and
    // filtered GI against each frame's ground truth, and the frames' PNGs.
    let tp = tmp("temporal");
    let out = run_cli(&args(
        "-- render --scene default --width 320 --height 240 --method slc --temporal svgf --camera-path --path-frames 60 --compare-gt --out out/temporal",
        &[
            ("--width", "32"),
            ("--height", "24"),
            ("--path-frames", "3"),
            ("--out", tp.to_str().unwrap()),
        ],
        &["--vpls", "256"],
    ));
    assert!(out.contains("RMSE raw") && out.contains("filtered"), "{out}");
    let (_, rows) = common::read_csv(&tp.join("sequence.csv"));
    assert_eq!(rows.len(), 3);
    for r in &rows {
        for k in [
            "rmse_raw",
            "rmse_filtered",
            "mean_ratio_raw",
            "mean_ratio_filtered",
            "ssim_filtered",
        ] {
            assert!(r[k].parse::<f64>().is_ok_and(f64::is_finite), "{k}: {r:?}");
        }
    }
    assert!(tp.join("frames").join("0002.png").is_file() && tp.join("indirect.exr").is_file());
    let _ = std::fs::remove_dir_all(&tp);
    // The temporal figure (the default scene, SLC, tiny).
    let tr = tmp("temporal-results");
    run_cli(&args(
        "-- results temporal --scenes scenes/sponza.toml,scenes/breakfast_room.toml --out results",
        &[("--scenes", "default"), ("--out", tr.to_str().unwrap())],
        &[
            "--width",
            "32",
            "--height",
            "24",
            "--temporal-frames",
            "2",
            "--temporal-timing-width",
            "32",
            "--temporal-timing-height",
            "24",
            "--timing-frames",
            "2",
            "--vpls",
            "256",
            "--methods",
            "slc",
        ],
    ));
    let (_, rows) = common::read_csv(&tr.join("default").join("temporal_summary.csv"));
    assert_eq!(rows.len(), 3, "{rows:?}");
    let _ = std::fs::remove_dir_all(&tr);
    // The tree comparison (the default scene, SLC, tiny): both trees, the equal-time table.
    let trr = tmp("trees-results");
    let out = run_cli(&args(
        "-- results trees --scenes scenes/sponza.toml,scenes/breakfast_room.toml --out results",
        &[("--scenes", "default"), ("--out", trr.to_str().unwrap())],
        &[
            "--width",
            "32",
            "--height",
            "24",
            "--frames",
            "1",
            "--timing-frames",
            "2",
            "--vpls",
            "256",
            "--spp",
            "4,16",
            "--methods",
            "slc",
        ],
    ));
    assert!(out.contains("RMSE perfect") && out.contains("radix"), "{out}");
    let (_, rows) = common::read_csv(&trr.join("default").join("trees.csv"));
    assert!(rows.iter().any(|r| r["tree"] == "perfect") && rows.iter().any(|r| r["tree"] == "lbvh"));
    for r in &rows {
        assert!(r["rmse"].parse::<f64>().is_ok_and(f64::is_finite), "{r:?}");
    }
    let (_, m) = common::read_csv(&trr.join("default").join("trees_equal_time.csv"));
    assert_eq!(m.len(), 1, "{m:?}");
    let _ = std::fs::remove_dir_all(&trr);
    // The bounce-count figure (the default scene, SLC, tiny): 1..=4 bounces.
    let br = tmp("bounces-results");
    let out = run_cli(&args(
        "-- results bounces --scenes scenes/sponza.toml,scenes/breakfast_room.toml --out results",
        &[("--scenes", "default"), ("--out", br.to_str().unwrap())],
        &[
            "--width",
            "32",
            "--height",
            "24",
            "--frames",
            "1",
            "--timing-frames",
            "2",
            "--vpls",
            "256",
            "--methods",
            "slc",
        ],
    ));
    assert!(out.contains("bounce(s)") && out.contains("light paths"), "{out}");
    let (_, rows) = common::read_csv(&br.join("default").join("bounces.csv"));
    assert_eq!(rows.len(), 7, "{rows:?}");
    let _ = std::fs::remove_dir_all(&br);
    // The tree's pairing and Lightcuts' cost per relative error (the default scene here).
    let out = run_cli(&args(
        "-- bench lightcuts --scene scenes/sponza.toml --width 160 --height 90",
        &[("--scene", "default"), ("--width", "24"), ("--height", "16")],
        &[
            "--vpls",
            "256",
            "--errors",
            "0.2",
            "--repeat",
            "1",
            "--cpu-pixels",
            "40",
        ],
    ));
    assert!(
        out.contains("far-paired") && out.contains("mean cut") && out.contains("0.2"),
        "{out}"
    );
    // The same VPLs in a radix tree (issue 23's LBVH, from its CPU reference).
    assert!(out.contains("radix tree (Karras 2012"), "{out}");

    // A comparison sheet of three methods.
    let sh = tmp("sheet");
    let png = sh.join("sheet.png");
    run_cli(&args(
        "-- sheet --methods slc,rtslc,sst --frames 16 --out screenshots/comparison_sheet.png",
        &[("--frames", "1"), ("--out", png.to_str().unwrap())],
        &["--width", "40", "--height", "30", "--vpls", "256"],
    ));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(sh.join("sheet.json")).unwrap()).unwrap();
    assert_eq!(json["columns"].as_array().map(Vec::len), Some(3));
    assert!(image::open(&png).is_ok());
    assert!(
        sh.join("sheet.capture.toml").is_file(),
        "the sheet's capture record"
    );

    // `results`: one figure at a tiny size (tests/harness.rs runs every figure).
    let rs = tmp("results");
    run_cli(&args(
        "-- results --out docs/results",
        &[("--out", rs.to_str().unwrap())],
        &[
            "timings",
            "--scenes",
            "default",
            "--width",
            "40",
            "--height",
            "30",
            "--frames",
            "1",
            "--timing-frames",
            "2",
        ],
    ));
    let csv = std::fs::read_dir(&rs)
        .expect("results folder")
        .filter_map(|e| e.ok())
        .map(|e| e.path().join("timings.csv"))
        .find(|p| p.is_file());
    assert!(csv.is_some(), "no timings.csv under {}", rs.display());

    // Per-frame methods all render headlessly too (the registry, not only SLC).
    for m in REGISTRY.iter().filter(|m| m.kind == Kind::PerFrame) {
        let d = tmp(m.id.cli());
        run_cli(
            &[
                "render",
                "--scene",
                "default",
                "--width",
                "32",
                "--height",
                "24",
                "--vpls",
                "256",
                "--output",
                "indirect",
                "--method",
                m.id.cli(),
                "--out",
                d.to_str().unwrap(),
            ]
            .map(String::from),
        );
        assert!(mean(&d.join("indirect.exr"))[1] > 0.0, "{}: black GI", m.id);
    }

    for d in [gt, rf, sc, slc, sh, rs] {
        let _ = std::fs::remove_dir_all(d);
    }

    if !shared_present() {
        eprintln!(
            "SKIPPED the shared-scene CLI examples: the reference scenes are not fetched (fetch-scenes)"
        );
        return;
    }
    // The reference scenes fetched (from the local copy as a mirror) into a folder of their
    // own, every file's checksum verified.
    let fetched = tmp("fetched");
    let shared = lightcut::scene::scene_path::find(Path::new("breakfast_room/BreakfastRoom.gltf"), None)
        .expect("found above");
    let mirror = shared.parent().and_then(|p| p.parent()).expect("scenes folder");
    let out = run_cli(&args(
        "-- fetch-scenes",
        &[],
        &[
            "--from",
            mirror.to_str().unwrap(),
            "--into",
            fetched.to_str().unwrap(),
            "--scenes",
            "breakfast_room",
        ],
    ));
    assert!(out.contains("6 file(s) ok"), "{out}");
    assert!(fetched.join("breakfast_room/BreakfastRoom.gltf").is_file());
    let _ = std::fs::remove_dir_all(fetched);
    // Breakfast Room headless, SLC by default: GI, SLC's views and its metrics.
    let br = tmp("breakfast");
    run_cli(&args(
        "-- render --scene scenes/breakfast_room.toml --width 1280 --height 720 --out out/",
        &[
            ("--width", "48"),
            ("--height", "27"),
            ("--out", br.to_str().unwrap()),
        ],
        &["--vpls", "256", "--max-texture", "64"],
    ));
    assert!(mean(&br.join("indirect.exr"))[1] > 0.0, "no GI");
    assert!(br.join("metrics.json").is_file() && br.join("cut_blocks.png").is_file());
    let _ = std::fs::remove_dir_all(br);
    // Shadow rays per second through Sponza's BVH.
    let out = run_cli(&args(
        "-- bench rays --scene scenes/sponza.toml",
        &[],
        &[
            "--rays", "4096", "--repeat", "1", "--width", "32", "--height", "24",
        ],
    ));
    assert!(out.contains("rays") && out.contains("Sponza"), "{out}");
    assert!(
        out.contains("in-frame shadow rays") && out.contains("Mrays/s"),
        "{out}"
    );
    // The G-buffer's fragments and bytes per pixel, without and with the depth pre-pass.
    let out = run_cli(&args(
        "-- bench gbuffer --scene scenes/sponza.toml",
        &[],
        &["--width", "64", "--height", "48", "--repeat", "1"],
    ));
    assert!(
        out.contains("depth complexity") && out.contains("pre-pass") && out.contains("bytes"),
        "{out}"
    );
}

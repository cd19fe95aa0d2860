//! The headless `render` command end to end, and clear one-line errors for bad input.

mod common;

use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lightcut-workbench"))
}

#[test]
fn render_default_scene_writes_exrs_pngs_and_timings() {
    if common::gpu().is_none() {
        return;
    }
    let out = std::env::temp_dir().join(format!("lightcut-cli-{}", std::process::id()));
    let o = bin()
        .args([
            "render", "--scene", "default", "--width", "96", "--height", "64", "--method", "off", "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "stdout: {stdout}\nstderr: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("adapter:"));
    assert!(
        stdout.contains("gbuffer") || stdout.contains("timestamps not supported"),
        "{stdout}"
    );
    for f in [
        "direct.exr",
        "final.exr",
        "position.exr",
        "normal.exr",
        "albedo.exr",
        "depth.exr",
        "final.png",
        "direct.png",
        "normal.png",
        "albedo.png",
        "depth.png",
        "shadow_map.png",
        "tree_distributions_level6.png",
        "tree_usable_level8.png",
        "tree_boxes_level4.png",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let direct = lightcut::export::read_exr(&out.join("direct.exr")).unwrap();
    assert_eq!((direct.width, direct.height), (96, 64));
    let mean = direct.mean_rgb();
    assert!(mean[0] > 0.0 && mean.iter().all(|v| v.is_finite()), "{mean:?}");
    let fin = lightcut::export::read_exr(&out.join("final.exr")).unwrap();
    assert_eq!(fin, direct, "with GI off, final = direct");
    let png = image::open(out.join("final.png")).unwrap();
    assert_eq!((png.width(), png.height()), (96, 64));
    let _ = std::fs::remove_dir_all(&out);
}

fn one_line_error(args: &[&str]) -> String {
    let o = bin().args(args).output().unwrap();
    assert!(!o.status.success(), "{args:?} should fail");
    let err = String::from_utf8_lossy(&o.stderr);
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("error")).collect();
    assert_eq!(lines.len(), 1, "expected one error line, got: {err}");
    lines[0].to_string()
}

#[test]
fn bad_input_gives_one_clear_line() {
    let e = one_line_error(&["render", "--scene", "/nonexistent/scene.gltf", "--out", "/tmp/x"]);
    assert!(e.contains("/nonexistent/scene.gltf"), "{e}");
    let e = one_line_error(&[
        "render",
        "--scene",
        "default",
        "--shadow-res",
        "3",
        "--out",
        "/tmp/x",
    ]);
    assert!(e.contains("shadow.resolution"), "{e}");
    let e = one_line_error(&[
        "render", "--scene", "default", "--camera", "Nope", "--out", "/tmp/x",
    ]);
    assert!(e.contains("Nope"), "{e}");
    // A visibility mode the method does not offer: refused with the modes it has.
    let e = one_line_error(&[
        "render",
        "--method",
        "lightcuts",
        "--visibility",
        "ism",
        "--out",
        "/tmp/x",
    ]);
    assert!(e.contains("--visibility ism") && e.contains("rays"), "{e}");
    let e = one_line_error(&[
        "render",
        "--method",
        "slc",
        "--visibility",
        "pcss",
        "--out",
        "/tmp/x",
    ]);
    assert!(e.contains("ism") && e.contains("not pcss"), "{e}");
    let e = one_line_error(&[
        "render",
        "--method",
        "val",
        "--visibility",
        "ism",
        "--val-visibility",
        "disk",
        "--out",
        "/tmp/x",
    ]);
    assert!(e.contains("--val-visibility"), "{e}");
    let e = one_line_error(&["bench", "tree", "--min-log2", "12", "--max-log2", "21"]);
    assert!(e.contains("--max-log2"), "{e}");
    let e = one_line_error(&[
        "render",
        "--scene",
        "default",
        "--width",
        "96",
        "--height",
        "64",
        "--method",
        "slc",
        "--cut-size",
        "65",
        "--out",
        "/tmp/x",
    ]);
    assert!(e.contains("methods.slc.cut_size"), "{e}");
    let e = one_line_error(&["--view", "nope", "--frames", "1"]);
    assert!(e.contains("unknown view 'nope'"), "{e}");
    // Temporal sequences: an unknown bookmark, a frame count without a sequence, a converging
    // method, a bad setting, each named.
    let e = one_line_error(&["render", "--camera-path", "Main,Nope", "--out", "/tmp/x"]);
    assert!(e.contains("no bookmark 'Nope'") && e.contains("Overview"), "{e}");
    let e = one_line_error(&["render", "--path-frames", "5", "--out", "/tmp/x"]);
    assert!(e.contains("--camera-path"), "{e}");
    let e = one_line_error(&[
        "render",
        "--method",
        "ground-truth",
        "--sun-sweep",
        "10",
        "--out",
        "/tmp/x",
    ]);
    assert!(e.contains("per-frame method"), "{e}");
    let e = one_line_error(&[
        "render",
        "--temporal",
        "svgf",
        "--set",
        "temporal.iterations=12",
        "--out",
        "/tmp/x",
    ]);
    assert!(e.contains("temporal.iterations"), "{e}");
    // The radix tree with a method that needs the perfect tree: refused, the method named.
    let e = one_line_error(&[
        "render",
        "--method",
        "light-culling-tree",
        "--tree",
        "lbvh",
        "--out",
        "/tmp/x",
    ]);
    assert!(
        e.contains("--tree lbvh") && e.contains("perfect tree only"),
        "{e}"
    );
    let e = one_line_error(&[
        "render",
        "--method",
        "lightcut-interpolation",
        "--set",
        "tree.kind=lbvh",
        "--out",
        "/tmp/x",
    ]);
    assert!(e.contains("tree lbvh") && e.contains("perfect tree only"), "{e}");
    let e = one_line_error(&["render", "--tree", "kd", "--out", "/tmp/x"]);
    assert!(e.contains("kd"), "{e}");
}

#[test]
fn bounces_out_of_range_and_one_bounce_methods_are_refused_in_one_line() {
    // The VALs cluster the RSM's texels (one bounce): --bounces or vpl.bounces above 1 is
    // refused, by `render` and by `sheet`.
    let e = one_line_error(&["render", "--method", "val", "--bounces", "3", "--out", "/tmp/x"]);
    assert!(e.contains("vpl.bounces 3") && e.contains("one bounce"), "{e}");
    let e = one_line_error(&[
        "render",
        "--method",
        "val-vpl",
        "--set",
        "vpl.bounces=2",
        "--out",
        "/tmp/x",
    ]);
    assert!(e.contains("vpl.bounces 2") && e.contains("one bounce"), "{e}");
    let e = one_line_error(&[
        "sheet",
        "--methods",
        "slc,val",
        "--bounces",
        "2",
        "--out",
        "/tmp/x.png",
    ]);
    assert!(e.contains("vpl.bounces 2"), "{e}");
    let e = one_line_error(&["render", "--bounces", "9", "--out", "/tmp/x"]);
    assert!(e.contains("vpl.bounces 9") && e.contains("1..=8"), "{e}");
    let e = one_line_error(&["render", "--bounces", "0", "--out", "/tmp/x"]);
    assert!(e.contains("vpl.bounces 0"), "{e}");
    let e = one_line_error(&["render", "--set", "vpl.path_flux_mix=0", "--out", "/tmp/x"]);
    assert!(e.contains("vpl.path_flux_mix"), "{e}");
}

#[test]
fn ggx_is_refused_by_methods_that_shade_with_lambert_only() {
    let e = one_line_error(&[
        "render",
        "--method",
        "lightcut-interpolation",
        "--brdf",
        "ggx",
        "--out",
        "/tmp/x",
    ]);
    assert!(e.contains("brdf GGX") && e.contains("Lambert only"), "{e}");
    assert!(
        e.contains("Lightcuts"),
        "the message names the glossy methods: {e}"
    );
    // Light culling shades GGX, but not through its geometry-aware filter.
    let e = one_line_error(&[
        "render",
        "--method",
        "light-culling",
        "--set",
        "gi.brdf=\"Ggx\"",
        "--out",
        "/tmp/x",
    ]);
    assert!(
        e.contains("methods.light-culling.interleave.filter_radius=0"),
        "{e}"
    );
    let e = one_line_error(&[
        "sheet",
        "--methods",
        "slc,val",
        "--brdf",
        "ggx",
        "--out",
        "/tmp/x.png",
    ]);
    assert!(e.contains("Lambert only"), "{e}");
    // The tree samplers shade with GGX, but not through their albedo-demodulated paths.
    let e = one_line_error(&[
        "render",
        "--method",
        "slc",
        "--brdf",
        "ggx",
        "--half-res",
        "--out",
        "/tmp/x",
    ]);
    assert!(
        e.contains("gi.brdf = Ggx with methods.slc.half_resolution"),
        "{e}"
    );
    let e = one_line_error(&["render", "--brdf", "phong", "--out", "/tmp/x"]);
    assert!(e.contains("phong"), "{e}");
    let e = one_line_error(&[
        "render",
        "--brdf",
        "ggx",
        "--glossy-weights",
        "mirror",
        "--out",
        "/tmp/x",
    ]);
    assert!(e.contains("mirror"), "{e}");
}

#[test]
fn bench_tree_prints_a_row_per_size_and_the_slopes() {
    if common::gpu().is_none() {
        return;
    }
    let o = bin()
        .args([
            "bench",
            "tree",
            "--min-log2",
            "8",
            "--max-log2",
            "10",
            "--repeat",
            "1",
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}
{}",
        String::from_utf8_lossy(&o.stderr)
    );
    for n in ["256", "512", "1024"] {
        let row = stdout
            .lines()
            .find(|l| l.trim_start().starts_with(n))
            .unwrap_or_else(|| panic!("no row for {n}: {stdout}"));
        // VPLs, keys, sort, build, classify, total, Mnode/s: all numbers, the times > 0.
        let cols: Vec<f64> = row.split_whitespace().filter_map(|c| c.parse().ok()).collect();
        assert_eq!(cols.len(), 7, "{row}");
        assert!(cols[1..6].iter().all(|t| *t > 0.0), "{row}");
        assert!(
            (cols[5] - cols[1..5].iter().sum::<f64>()).abs() < 0.01,
            "total = sum: {row}"
        );
    }
    assert!(stdout.contains("log-log slope of time vs N: keys"), "{stdout}");
}

#[test]
fn export_scene_writes_every_triangle_and_the_camera_and_sun() {
    let out = std::env::temp_dir().join(format!("lightcut-export-{}", std::process::id()));
    let o = bin()
        .args(["export-scene", "--scene", "default", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json = std::fs::read_to_string(out.join("scene.json")).unwrap();
    for key in [
        "\"camera\"",
        "\"sun\"",
        "\"materials\"",
        "\"yfov_deg\"",
        "\"irradiance\"",
    ] {
        assert!(json.contains(key), "scene.json lacks {key}");
    }
    let mut faces = 0usize;
    for e in std::fs::read_dir(&out).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "ply") {
            let bytes = std::fs::read(&p).unwrap();
            let end = bytes
                .windows(10)
                .position(|w| w == b"end_header")
                .expect("PLY header");
            let header = String::from_utf8_lossy(&bytes[..end]);
            let line = header
                .lines()
                .find(|l| l.starts_with("element face"))
                .expect("face element");
            faces += line.split_whitespace().last().unwrap().parse::<usize>().unwrap();
        }
    }
    let scene = lightcut::scene::default_scene::build();
    assert_eq!(faces, scene.triangle_count());
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn render_ground_truth_writes_indirect_and_final_is_direct_plus_indirect() {
    if common::gpu().is_none() {
        return;
    }
    let out = std::env::temp_dir().join(format!("lightcut-gt-{}", std::process::id()));
    let o = bin()
        .args([
            "render",
            "--scene",
            "default",
            "--width",
            "48",
            "--height",
            "32",
            "--method",
            "ground-truth",
        ])
        .args(["--vpls", "64", "--output", "direct,indirect,final", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("ground truth: 64 VPLs"), "{stdout}");
    assert!(!out.join("normal.exr").exists(), "--output limits the files");
    let read = |f: &str| lightcut::export::read_exr(&out.join(f)).unwrap();
    let (d, i, f) = (read("direct.exr"), read("indirect.exr"), read("final.exr"));
    assert!(i.mean_rgb()[0] > 0.0, "no indirect light");
    for k in 0..f.pixels.len() {
        for c in 0..3 {
            let want = d.pixels[k][c] + i.pixels[k][c];
            assert!(
                (f.pixels[k][c] - want).abs() <= 1e-6 * want.abs().max(1.0),
                "pixel {k}"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn sheet_writes_a_comparison_image_and_its_metrics() {
    if common::gpu().is_none() {
        return;
    }
    let out = std::env::temp_dir().join(format!("lightcut-sheet-{}", std::process::id()));
    let png = out.join("s.png");
    let o = bin()
        .args([
            "sheet",
            "--width",
            "48",
            "--height",
            "32",
            "--vpls",
            "256",
            "--methods",
            "slc,rtslc",
            "--frames",
            "2",
            "--out",
        ])
        .arg(&png)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "stdout: {stdout}\nstderr: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("SSIM") && stdout.contains("FLIP"), "{stdout}");
    let img = image::open(&png).expect("the sheet decodes");
    // Three columns (ground truth + 2 methods) of images scaled to >= 320 px.
    assert!(
        img.width() >= 3 * 320 && img.height() > 2 * 200,
        "{}x{}",
        img.width(),
        img.height()
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("s.json")).unwrap()).unwrap();
    let cols = json["columns"].as_array().unwrap();
    assert_eq!(cols.len(), 2);
    for c in cols {
        let m = &c["vs_ground_truth"];
        assert!(m["rmse"].as_f64().unwrap() >= 0.0);
        assert!(m["flip"].as_f64().unwrap() >= 0.0 && m["flip"].as_f64().unwrap() <= 1.0);
        assert!(m["ssim"].as_f64().unwrap() <= 1.0);
    }
    let _ = std::fs::remove_dir_all(&out);
    // A method that cannot be a column: one clear line, non-zero exit.
    let o = bin().args(["sheet", "--methods", "off"]).output().unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.trim().lines().count() == 1 && err.contains("cannot be a sheet column"),
        "{err}"
    );
}

#[test]
fn render_help_lists_every_registered_method() {
    let out = bin().args(["render", "--help"]).output().expect("run");
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for m in lightcut::methods::REGISTRY {
        assert!(
            text.contains(&format!("{} ({})", m.id.cli(), m.short)),
            "`render --help` lacks {}: {text}",
            m.id
        );
    }
}

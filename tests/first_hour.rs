//! Issue 41, a researcher's first hour: the reference scenes fetched from a local mirror and
//! found by the presets, a capture reproduced bit for bit from its record, and a two-shard
//! sweep merged into an unsharded run's numbers. Each runs the built binary as a user would.

mod common;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("lightcut-first-hour-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs the binary in `cwd` with `env` added (and the scene search path's variables cleared
/// unless given).
fn run(args: &[&str], cwd: &Path, env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_lightcut-workbench"));
    c.args(args).current_dir(cwd);
    for v in ["LIGHTCUT_SCENES", "LIGHTCUT_SHARED_SCENES"] {
        c.env_remove(v);
    }
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("run the binary")
}

fn ok(o: &Output, what: &str) -> String {
    let stdout = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        o.status.success(),
        "{what} failed\nstdout: {stdout}\nstderr: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    stdout
}

#[test]
fn scenes_are_fetched_from_a_mirror_checked_and_found_by_presets() {
    let root = tmp("fetch");
    let home = root.join("home");
    let cwd = root.join("elsewhere");
    std::fs::create_dir_all(&cwd).unwrap();
    let home_s = home.to_str().unwrap().to_string();
    let base_env = [("HOME", home_s.as_str()), ("XDG_DATA_HOME", "")];
    // A preset outside the repository, so `../shared/scenes` beside it does not exist.
    let preset = root.join("breakfast_room.toml");
    std::fs::copy(repo().join("scenes/breakfast_room.toml"), &preset).unwrap();
    let render = |env: &[(&str, &str)]| {
        run(
            &[
                "render",
                "--scene",
                preset.to_str().unwrap(),
                "--method",
                "off",
                "--width",
                "32",
                "--height",
                "18",
                "--timing-frames",
                "1",
                "--max-texture",
                "16",
                "--output",
                "final",
                "--out",
                root.join("out").to_str().unwrap(),
            ],
            &cwd,
            env,
        )
    };
    // Not fetched: one line naming the command that fetches it, exit status 1.
    let o = render(&base_env);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    let line = err
        .lines()
        .find(|l| l.starts_with("error:"))
        .expect("an error line");
    assert!(
        line.contains("breakfast_room/BreakfastRoom.gltf not found") && line.contains("fetch-scenes"),
        "{err}"
    );

    let Some(shared) = common::shared_scenes() else {
        return;
    };
    // `fetch-scenes` of the Breakfast Room with `extra` options, in `cwd`.
    let fetch = |extra: &[&str]| {
        let mut a = vec!["fetch-scenes", "--scenes", "breakfast_room"];
        a.extend(extra);
        run(&a, &cwd, &base_env)
    };
    let from = ["--from", shared.to_str().unwrap()];
    // Fetched from a local mirror into the user data folder (the default --into), every
    // file's SHA-256 checked against the manifest.
    let out = ok(&fetch(&from), "fetch-scenes");
    assert!(out.contains("6 file(s) ok (6 placed now"), "{out}");
    assert!(out.contains("presets find them now"), "{out}");
    let placed = home.join(".local/share/lightcut-workbench/scenes/breakfast_room/BreakfastRoom.gltf");
    assert!(placed.is_file());
    // The preset finds it there; a second fetch keeps every file.
    ok(&render(&base_env), "render after fetch-scenes");
    let again = ok(&fetch(&["--check"]), "fetch-scenes --check");
    assert!(again.contains("0 placed now, 6 already present"), "{again}");
    // A damaged file fails --check, naming it; fetching again repairs it.
    std::fs::write(&placed, "{}").unwrap();
    let o = fetch(&["--check"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("BreakfastRoom.gltf"));
    ok(&fetch(&from), "fetch-scenes repair");
    // Another folder through LIGHTCUT_SCENES.
    let other = root.join("other");
    ok(
        &fetch(&[from[0], from[1], "--into", other.to_str().unwrap()]),
        "fetch-scenes --into",
    );
    std::fs::remove_dir_all(home.join(".local")).unwrap();
    assert!(!render(&base_env).status.success());
    let other_s = other.to_str().unwrap().to_string();
    ok(
        &render(&[
            ("HOME", home_s.as_str()),
            ("XDG_DATA_HOME", ""),
            ("LIGHTCUT_SCENES", other_s.as_str()),
        ]),
        "render with LIGHTCUT_SCENES",
    );
    let _ = std::fs::remove_dir_all(&root);
}

/// Every EXR and PNG of two folders, byte for byte.
fn same_images(a: &Path, b: &Path) -> usize {
    let mut n = 0;
    for e in std::fs::read_dir(a).unwrap() {
        let name = e.unwrap().file_name();
        let s = name.to_string_lossy().to_string();
        if s.ends_with(".exr") || s.ends_with(".png") {
            let (x, y) = (
                std::fs::read(a.join(&name)).unwrap(),
                std::fs::read(b.join(&name)).unwrap(),
            );
            assert!(x == y, "{s} differs between the capture and its reproduction");
            n += 1;
        }
    }
    n
}

#[test]
fn a_render_capture_is_reproduced_bit_for_bit_from_its_record() {
    if common::gpu().is_none() {
        return;
    }
    let root = tmp("capture");
    for (method, extra) in [("slc", &["--frames", "3"][..]), ("lightcuts", &[][..])] {
        let first = root.join(format!("{method}-first"));
        let again = root.join(format!("{method}-again"));
        let mut args = vec![
            "render",
            "--scene",
            "default",
            "--method",
            method,
            "--width",
            "48",
            "--height",
            "32",
            "--vpls",
            "512",
            "--seed",
            "11",
            "--timing-frames",
            "2",
            "--output",
            "final,direct,indirect",
            "--out",
            first.to_str().unwrap(),
        ];
        args.extend(extra);
        ok(&run(&args, &repo(), &[]), "render");
        let record = first.join("capture.toml");
        let text = std::fs::read_to_string(&record).unwrap();
        for key in [
            "commit = ",
            "adapter = ",
            "driver = ",
            "scene_sha256 = \"builtin\"",
            "seed = 11",
            "frame_index = ",
            "[capture.camera]",
            "[[capture.lights]]",
            "count = 512",
        ] {
            assert!(text.contains(key), "{key} missing from the record:\n{text}");
        }
        // Only the record and an output folder: scene, camera, size, frames and settings
        // come from the record.
        let out = ok(
            &run(
                &[
                    "render",
                    "--settings",
                    record.to_str().unwrap(),
                    "--output",
                    "final,direct,indirect",
                    "--out",
                    again.to_str().unwrap(),
                ],
                &repo(),
                &[],
            ),
            "render --settings capture.toml",
        );
        assert!(out.contains("capture record"), "{out}");
        assert_eq!(same_images(&first, &again), 3, "{method}");
        // A flag on the command line wins over the record (and changes the image).
        let other = root.join(format!("{method}-seed"));
        ok(
            &run(
                &[
                    "render",
                    "--settings",
                    record.to_str().unwrap(),
                    "--seed",
                    "12",
                    "--output",
                    "indirect",
                    "--out",
                    other.to_str().unwrap(),
                ],
                &repo(),
                &[],
            ),
            "render --settings capture.toml --seed 12",
        );
        assert_ne!(
            std::fs::read(first.join("indirect.exr")).unwrap(),
            std::fs::read(other.join("indirect.exr")).unwrap()
        );
    }
    let _ = std::fs::remove_dir_all(&root);
}

/// The columns of a results CSV that do not depend on the machine's speed.
fn deterministic(path: &Path) -> Vec<HashMap<String, String>> {
    let (header, rows) = common::read_csv(path);
    let timing = |c: &str| c.contains("_ms") || c.contains("share") || c.contains("wall") || c == "value";
    rows.into_iter()
        .map(|r| {
            // A check of measured times: its outcome and detail (the times) are the machine's.
            let timed_check = r.get("check").is_some_and(|c| c.contains("fastest"));
            r.into_iter()
                .filter(|(k, _)| !timing(k) && header.contains(k))
                .filter(|(k, _)| !(timed_check && (k == "met" || k == "detail")))
                .collect()
        })
        .collect()
}

#[test]
fn a_two_shard_sweep_merges_into_the_unsharded_numbers() {
    if common::gpu().is_none() {
        return;
    }
    let root = tmp("shards");
    let base = [
        "results",
        "steps,temporal,blocks,blending",
        "--scenes",
        "default",
        "--width",
        "32",
        "--height",
        "24",
        "--frames",
        "1",
        "--timing-frames",
        "2",
        "--blocks",
        "1,4",
        "--vpls",
        "256",
        "--temporal-frames",
        "3",
        "--temporal-path-frames",
        "30",
        "--temporal-timing-width",
        "32",
        "--temporal-timing-height",
        "24",
    ];
    let go = |extra: &[&str], out: &Path| -> Vec<String> {
        let mut a: Vec<String> = base.iter().map(|s| s.to_string()).collect();
        a.extend(extra.iter().map(|s| s.to_string()));
        a.extend(["--out".to_string(), out.display().to_string()]);
        a
    };
    let (whole, s1, s2, merged) = (
        root.join("whole"),
        root.join("s1"),
        root.join("s2"),
        root.join("merged"),
    );
    // The two shards as two processes at once (as two nodes of a cluster would).
    let spawn = |args: Vec<String>| {
        Command::new(env!("CARGO_BIN_EXE_lightcut-workbench"))
            .args(args)
            .current_dir(repo())
            .output()
    };
    let (a1, a2) = (go(&["--shard", "1/2"], &s1), go(&["--shard", "2/2"], &s2));
    let (o1, o2) = std::thread::scope(|sc| {
        let h1 = sc.spawn(|| spawn(a1));
        let h2 = sc.spawn(|| spawn(a2));
        (h1.join().unwrap().unwrap(), h2.join().unwrap().unwrap())
    });
    ok(&o1, "shard 1/2");
    ok(&o2, "shard 2/2");
    let whole_args = go(&[], &whole);
    ok(
        &run(
            &whole_args.iter().map(String::as_str).collect::<Vec<_>>(),
            &repo(),
            &[],
        ),
        "unsharded",
    );
    // Each shard did only its units.
    let units = |d: &Path| -> Vec<String> {
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("run.json")).unwrap()).unwrap();
        v["units"]
            .as_array()
            .unwrap()
            .iter()
            .map(|u| u.as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(units(&s1), ["default/Steps", "default/Blocks"]);
    assert_eq!(units(&s2), ["default/Temporal", "default/Blending"]);
    // A merge with a shard missing is refused.
    let o = run(
        &[
            "results",
            "merge",
            s1.to_str().unwrap(),
            "--out",
            root.join("half").to_str().unwrap(),
        ],
        &repo(),
        &[],
    );
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("2/2 missing"));
    ok(
        &run(
            // In any order: the merge orders by shard, scene and figure.
            &[
                "results",
                "merge",
                s2.to_str().unwrap(),
                s1.to_str().unwrap(),
                "--out",
                merged.to_str().unwrap(),
            ],
            &repo(),
            &[],
        ),
        "results merge",
    );
    assert_eq!(units(&merged), units(&whole));
    // The same files, and every deterministic column the same as the unsharded run's.
    let list = |d: &Path| {
        let mut v: Vec<String> = walk(d)
            .iter()
            .map(|p| p.strip_prefix(d).unwrap().display().to_string())
            .collect();
        v.sort();
        v
    };
    assert_eq!(list(&whole), list(&merged));
    let mut csvs = 0;
    for rel in list(&whole).iter().filter(|f| f.ends_with(".csv")) {
        let (w, m) = (deterministic(&whole.join(rel)), deterministic(&merged.join(rel)));
        assert_eq!(w.len(), m.len(), "{rel}: rows");
        for (i, (a, b)) in w.iter().zip(&m).enumerate() {
            for (k, v) in a {
                assert_eq!(
                    Some(v),
                    b.get(k),
                    "{rel}: row {i} ({a:?}), column {k}: unsharded vs merged"
                );
            }
            assert_eq!(a.len(), b.len(), "{rel}: row {i}: columns");
        }
        csvs += 1;
    }
    assert!(csvs >= 5, "{csvs} CSVs compared");
    // The images of the configurations too.
    for rel in list(&whole).iter().filter(|f| f.starts_with("default/images/")) {
        assert!(
            std::fs::read(whole.join(rel)).unwrap() == std::fs::read(merged.join(rel)).unwrap(),
            "{rel} differs"
        );
    }
    let _ = std::fs::remove_dir_all(&root);
}

fn walk(d: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(d).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
}

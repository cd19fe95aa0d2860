//! Runs for hours (issue 42), checked at a tiny size: hundreds of frames through `render`
//! (still, and along a camera path with the temporal stage) leave the live GPU objects of
//! every kind as they were after 30 frames and the peak resident memory within 10% of a
//! 30-frame run; and the GUI, made to keep switching methods, scenes, render scale, the tree,
//! the BRDF and views, holds the same objects and memory in its third round as in its second.
//!
//! (On lavapipe the growth was ~2 MB a frame: Mesa 22.3 compiles a new shader whenever a
//! pipeline whose `var<uniform>` values steer control flow is bound, and never frees it;
//! `passes::uniforms_as_storage` reads parameters as storage buffers there. With
//! `LIGHTCUT_UNIFORMS=uniform` these tests fail as the issue measured.)

mod common;

use lightcut::methods::tree_samplers::settings::SamplingSettings;
use std::{path::Path, process::Command, sync::Arc};

use egui_kittest::Harness;
use lightcut::{
    app::{AppOptions, WorkbenchApp},
    methods::MethodId,
    renderer::{
        context::LiveObjects,
        settings::{RenderSettings, TreeKind, ViewBuffer},
        soak::{Snapshot, grown},
    },
};

/// The in-process tests of this binary one at a time: the GUI soak measures this process's
/// resident memory, which another test's renderer beside it would move.
static IN_PROCESS: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn in_process() -> std::sync::MutexGuard<'static, ()> {
    IN_PROCESS.lock().unwrap_or_else(|e| e.into_inner())
}

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lightcut-workbench"))
}

/// Runs `render` with `args` into a fresh folder; returns its resources.json.
fn render(name: &str, args: &[&str]) -> serde_json::Value {
    let out = std::env::temp_dir().join(format!("lightcut-soak-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let o = bin()
        .args([
            "render",
            "--width",
            "32",
            "--height",
            "24",
            "--vpls",
            "256",
            "--shadow-res",
            "128",
        ])
        .args(["--output", "final", "--timing-frames", "1", "--out"])
        .arg(&out)
        .args(args)
        .output()
        .expect("the binary runs");
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "render {args:?}\nstdout: {stdout}\nstderr: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        stdout.contains("resources: live GPU objects unchanged"),
        "{stdout}"
    );
    let json = read_json(&out.join("resources.json"));
    let _ = std::fs::remove_dir_all(&out);
    json
}

fn read_json(p: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).expect("resources.json written")).expect("valid JSON")
}

fn live(v: &serde_json::Value) -> LiveObjects {
    serde_json::from_value(v.clone()).expect("live objects")
}

/// A 300-frame run against a 30-frame one: objects after frame 30 equal at frame 300, peak
/// resident memory within 10%.
fn flat(name: &str, short: &[&str], long: &[&str]) {
    let a = render(&format!("{name}-30"), short);
    let b = render(&format!("{name}-300"), long);
    assert_eq!(b["warm"]["frame"], 30);
    assert!(b["end"]["frame"].as_u64().unwrap() >= 300, "{b}");
    let (warm, end) = (live(&b["warm"]["live"]), live(&b["end"]["live"]));
    // The counters count (wgpu's `counters` feature is on): a frame's worth of objects.
    assert!(warm.buffers > 10 && warm.pipelines > 10, "{name}: {warm:?}");
    assert!(grown(&warm, &end).is_empty(), "{name}: {:?}", grown(&warm, &end));
    // From frame 30 to frame 300 of the same run: the resident memory of the end within
    // 8 MiB of frame 30's (a leak of 30 kB a frame would show).
    let rss = |v: &serde_json::Value| v["host"]["rss"].as_f64();
    if let (Some(w), Some(e)) = (rss(&b["warm"]), rss(&b["end"])) {
        assert!(
            e <= w + 8.0 * 1048576.0,
            "{name}: resident memory {:.1} MiB at frame 30, {:.1} MiB at the end",
            w / 1048576.0,
            e / 1048576.0
        );
    }
    let peak = |v: &serde_json::Value| v["end"]["host"]["peak_rss"].as_f64();
    if let (Some(pa), Some(pb)) = (peak(&a), peak(&b)) {
        assert!(
            pb <= 1.1 * pa,
            "{name}: peak resident memory {:.0} MiB after 300 frames, {:.0} MiB after 30",
            pb / 1048576.0,
            pa / 1048576.0
        );
    }
}

#[test]
fn three_hundred_still_frames_hold_what_thirty_hold() {
    if common::gpu().is_none() {
        return;
    }
    flat(
        "still",
        &["--method", "slc", "--frames", "30"],
        &["--method", "slc", "--frames", "300"],
    );
}

#[test]
fn three_hundred_frames_of_a_camera_path_with_the_temporal_filter_hold_what_thirty_hold() {
    if common::gpu().is_none() {
        return;
    }
    // The default room has one bookmark: the sun sweeps instead (the VPLs and the tree are
    // rebuilt every frame), with SVGF's history in flight.
    let seq = |n: &'static str| {
        [
            "--method",
            "slc",
            "--temporal",
            "svgf",
            "--sun-sweep",
            "90",
            "--path-frames",
            n,
        ]
    };
    flat("sequence", &seq("30"), &seq("300"));
}

fn setup() -> egui_wgpu::WgpuSetup {
    let mut s = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    s.instance_descriptor.backends = lightcut::renderer::context::BACKENDS;
    s.device_descriptor = Arc::new(lightcut::renderer::context::device_descriptor);
    egui_wgpu::WgpuSetup::CreateNew(s)
}

/// One change the GUI soak makes, then a few frames.
#[derive(Clone, Copy, Debug)]
enum Step {
    Method(&'static str),
    Scene(&'static str),
    Scale(f32),
    Tree(TreeKind),
    Brdf(lightcut::base::brdf::Brdf),
    View(ViewBuffer),
}

#[test]
fn the_gui_switching_everything_holds_the_same_objects_and_memory_round_after_round() {
    let _serial = in_process();
    if common::gpu().is_none() {
        return;
    }
    let mut s = RenderSettings::default();
    s.gi.method = MethodId::parse("slc").unwrap();
    s.vpl.count = 256;
    SamplingSettings::edit(&mut s, |m| m.cut_size = 8);
    s.shadow.resolution = 128;
    let options = AppOptions {
        settings: Some(s),
        ..AppOptions::default()
    };
    let mut h = Harness::builder()
        .with_size(egui::vec2(520.0, 380.0))
        .wgpu_setup(setup())
        .build_eframe(move |cc| {
            WorkbenchApp::new(
                cc,
                AppOptions {
                    scene: "default".into(),
                    ..options.clone()
                },
            )
        });
    use Step::*;
    let round = [
        Scale(0.25),
        Method("lightcuts"),
        View(ViewBuffer::Indirect),
        Scene("window-box"),
        Method("light-culling"),
        Method("slc"),
        Brdf(lightcut::base::brdf::Brdf::Ggx),
        Tree(TreeKind::Lbvh),
        View(ViewBuffer::Final),
        Scene("glossy-thin"),
        Tree(TreeKind::Perfect),
        Brdf(lightcut::base::brdf::Brdf::Lambert),
        Method("val"),
        Scale(0.5),
        Scene("default"),
        Method("slc"),
        View(ViewBuffer::Albedo),
        Scale(0.25),
    ];
    let mut ends: Vec<(Snapshot, u64)> = Vec::new();
    for r in 0..3 {
        let mut max_rss = 0;
        for step in round {
            let app = h.state_mut();
            match step {
                Method(m) => {
                    let mut s = app.settings().clone();
                    s.gi.method = MethodId::parse(m).unwrap();
                    app.set_settings(s);
                }
                Scene(name) => app
                    .open_scene(name, None)
                    .unwrap_or_else(|e| panic!("{name}: {e}")),
                Scale(x) => app.set_render_scale(x),
                Tree(kind) => {
                    let mut s = app.settings().clone();
                    s.tree.kind = kind;
                    app.set_settings(s);
                }
                Brdf(b) => {
                    let mut s = app.settings().clone();
                    s.gi.brdf = b;
                    app.set_settings(s);
                }
                View(v) => app.set_view(v),
            }
            h.run_steps(4);
            assert!(
                h.state().errors().is_empty(),
                "after {step:?}: {:?}",
                h.state().errors()
            );
            let ctx = &h.state().renderer().expect("renderer").ctx;
            let snap = Snapshot::take(ctx, r);
            max_rss = max_rss.max(snap.host.map_or(0, |m| m.rss));
        }
        // Settled: the GPU idle, the app's readbacks collected, the GPU idle again (objects
        // held by work still in flight are not leaks).
        let ctx = h.state().renderer().expect("renderer").ctx.clone();
        ctx.wait_idle().unwrap();
        h.run_steps(2);
        ctx.wait_idle().unwrap();
        ends.push((Snapshot::take(&ctx, r), max_rss));
    }
    // The first round makes what the app keeps (pipelines, the scenes' buffers): rounds two
    // and three must end with the same live objects, and the same memory within 10% + 16 MiB.
    let ((second, rss2), (third, rss3)) = (ends[1], ends[2]);
    assert!(
        grown(&second.live, &third.live).is_empty(),
        "live GPU objects grew from round 2 to round 3: {:?}",
        grown(&second.live, &third.live)
    );
    if rss2 > 0 {
        assert!(
            (rss3 as f64) <= 1.1 * rss2 as f64 + 16.0 * 1048576.0,
            "resident memory {:.0} MiB in round 3, {:.0} MiB in round 2",
            rss3 as f64 / 1048576.0,
            rss2 as f64 / 1048576.0
        );
    }
}

#[test]
fn gpu_errors_name_their_pass_in_one_line_and_a_lost_device_is_reported() {
    let _serial = in_process();
    let Some(ctx) = common::gpu() else { return };
    // A bind group whose buffer lacks the usage its layout needs: a validation error on an
    // object labelled as our passes label theirs.
    let layout = lightcut::renderer::passes::bind_group_layout(
        &ctx.device,
        &wgpu::BindGroupLayoutDescriptor {
            label: Some("probe::layout"),
            entries: &[lightcut::renderer::passes::storage_entry(
                0,
                wgpu::ShaderStages::COMPUTE,
                true,
            )],
        },
    );
    let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("probe::params"),
        size: 16,
        usage: wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let _ = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("probe::bind_group"),
        layout: &layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: buffer.as_entire_binding(),
        }],
    });
    ctx.wait_idle().unwrap();
    let errors = ctx.errors.take();
    assert_eq!(errors.len(), 1, "{errors:?}");
    let e = &errors[0];
    assert!(
        e.starts_with(
            "GPU validation error in pass 'probe' (Device::create_bind_group, label 'probe::bind_group'): "
        ),
        "{e}"
    );
    assert!(!e.contains('\n') && e.contains("STORAGE"), "{e}");
    assert!(lightcut::renderer::context::first_gpu_error().is_some());
    assert!(!ctx.errors.device_lost());
    ctx.device.destroy();
    let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
    assert!(ctx.errors.device_lost(), "destroy() loses the device");
    assert!(
        ctx.errors
            .take()
            .iter()
            .any(|e| e.starts_with("GPU device lost (Destroyed)")),
        "the loss is reported"
    );
}

/// The default room scaled by `k` about the origin, its cameras' clip ranges kept as they
/// were and then fitted to the new bounds, as the glTF loader does.
fn scaled_room(k: f32) -> (lightcut::scene::Scene, Vec<String>) {
    let mut s = lightcut::scene::default_scene::build();
    for p in &mut s.positions {
        *p *= k;
    }
    s.recompute_bounds();
    let mut warnings = Vec::new();
    for c in &mut s.cameras {
        c.position *= k;
        warnings.extend(c.fit_clip_range(&s.bounds));
    }
    (s, warnings)
}

#[test]
fn the_room_scaled_by_a_million_or_a_millionth_keeps_its_direct_light_and_says_what_darkens_its_gi() {
    let _serial = in_process();
    let Some(ctx) = common::gpu() else { return };
    let size = (48, 32);
    // The room scaled by k, rendered with gi.ray_offset and gi.distance_epsilon scaled as its
    // load warnings ask: (direct mean, indirect mean, warnings). Its GI stays black at both
    // scales: the RSM's half-float flux under/overflows there, which a warning says (with
    // f32 flux it was within 1.06x at 10^-6, but VAL lost 15% on glossy-thin: left for later).
    let mean = |k: f32| {
        let (scene, mut warnings) = scaled_room(k);
        warnings.extend(scene.scale_warnings());
        let mut s = RenderSettings::default();
        s.gi.method = MethodId::parse("slc").unwrap();
        s.vpl.count = 256;
        s.shadow.resolution = 256;
        s.gi.ray_offset *= k;
        s.gi.distance_epsilon *= k;
        let mut f = common::Setup::with_scene(&ctx, scene, s, size);
        f.frame();
        f.r.ctx.wait_idle().unwrap();
        let errors = f.r.ctx.errors.take();
        assert!(errors.is_empty(), "{errors:?}");
        let direct = f.r.read(lightcut::renderer::Buffer::Direct).unwrap().mean_rgb();
        let indirect = f.indirect().mean_rgb();
        (direct[1], indirect[1], warnings)
    };
    let (d1, i1, w1) = mean(1.0);
    assert!(w1.is_empty() && d1 > 0.0 && i1 > 0.0, "{d1} {i1} {w1:?}");
    for (k, setting) in [(1e6f32, "gi.ray_offset"), (1e-6, "gi.distance_epsilon")] {
        let (d, i, w) = mean(k);
        // The camera's clip range (0.01..30 m) is refitted, and the warnings name the setting
        // to change and the RSM's half floats that this scale leaves.
        assert!(w.iter().any(|w| w.contains("misses the scene")), "{k}: {w:?}");
        assert!(w.iter().any(|w| w.contains(setting)), "{k}: {w:?}");
        assert!(w.iter().any(|w| w.contains("half floats")), "{k}: {w:?}");
        // Irradiance is per square metre: the same room at any scale is as bright.
        assert!(
            (d / d1 - 1.0).abs() < 0.02,
            "scale {k}: direct mean {d} against {d1}"
        );
        eprintln!("scale {k}: indirect mean {i} (unscaled {i1})");
    }
}

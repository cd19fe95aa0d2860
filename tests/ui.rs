//! The workbench UI, headless (egui_kittest + wgpu): switching the buffer selector changes the
//! shown texture; a snapshot of the main window.

mod common;

use lightcut::methods::tree_samplers::settings::SamplingSettings;
use lightcut::methods::tree_samplers::{RTSLC, SLC};
use std::sync::Arc;

use egui::accesskit::Role;
use egui_kittest::{Harness, kittest::Queryable};
use lightcut::{
    app::{AppOptions, WorkbenchApp},
    renderer::settings::{ChildProbability, TreeKind, ViewBuffer},
};

fn setup() -> egui_wgpu::WgpuSetup {
    let mut s = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    s.instance_descriptor.backends = lightcut::renderer::context::BACKENDS;
    s.device_descriptor = Arc::new(lightcut::renderer::context::device_descriptor);
    egui_wgpu::WgpuSetup::CreateNew(s)
}

/// The app on the default scene with `options` (scene set here), in a `size` window. Without
/// settings in `options`, direct light only: the app opens on SLC, which these tests of the
/// window's mechanics do not need (it would cost lavapipe seconds per frame).
fn harness_with(size: egui::Vec2, options: AppOptions) -> Option<Harness<'static, WorkbenchApp>> {
    common::gpu()?;
    let options = AppOptions {
        settings: options.settings.clone().or_else(|| {
            let mut s = lightcut::renderer::settings::RenderSettings::default();
            s.gi.method = lightcut::methods::direct_only::ID;
            Some(s)
        }),
        ..options
    };
    Some(
        Harness::builder()
            .with_size(size)
            .wgpu_setup(setup())
            .build_eframe(move |cc| {
                WorkbenchApp::new(
                    cc,
                    AppOptions {
                        scene: "default".into(),
                        ..options.clone()
                    },
                )
            }),
    )
}

fn harness() -> Option<Harness<'static, WorkbenchApp>> {
    harness_with(egui::vec2(1100.0, 700.0), AppOptions::default())
}

/// SLC with 1024 VPLs and cuts of 16.
fn slc_settings() -> lightcut::renderer::settings::RenderSettings {
    let mut s = lightcut::renderer::settings::RenderSettings::default();
    s.gi.method = SLC;
    s.vpl.count = 1024;
    SamplingSettings::edit(&mut s, |m| m.cut_size = 16);
    s
}

fn shown_pixels(h: &Harness<'_, WorkbenchApp>) -> Vec<u8> {
    let r = h.state().renderer().expect("renderer");
    r.read_view_rgba8().expect("readback").2
}

#[test]
fn buffer_selector_changes_the_shown_texture() {
    let Some(mut h) = harness() else { return };
    h.run_steps(3);
    assert!(h.state().errors().is_empty(), "errors: {:?}", h.state().errors());
    assert_eq!(h.state().view(), ViewBuffer::Final);
    let final_px = shown_pixels(&h);
    assert!(final_px.chunks(4).any(|p| p[0] > 20), "final image is black");

    // Open the buffer combo box and pick "normal".
    h.get_by_role_and_label(Role::ComboBox, "buffer").click();
    h.run_steps(2);
    h.get_by_label("normal").click();
    h.run_steps(3);
    assert_eq!(h.state().view(), ViewBuffer::Normal);
    let normal_px = shown_pixels(&h);
    assert_ne!(final_px, normal_px, "the shown texture did not change");

    // And the RSM flux (a square texture of the shadow-map resolution).
    h.get_by_role_and_label(Role::ComboBox, "buffer").click();
    h.run_steps(2);
    h.get_by_label("RSM flux").click();
    h.run_steps(3);
    assert_eq!(h.state().view(), ViewBuffer::RsmFlux);
    let (w, hh, _) = h.state().renderer().unwrap().read_view_rgba8().unwrap();
    assert_eq!((w, hh), (512, 512));
    assert!(h.state().frames() >= 8);
}

#[test]
fn main_window_snapshot() {
    let Some(mut h) = harness() else { return };
    h.run_steps(4);
    // The status line holds GPU timings, which change from run to run: mask it.
    let status = h.get_by_label_contains("GPU: ").rect();
    h.mask(egui::Rect::from_min_max(
        egui::pos2(0.0, status.min.y - 4.0),
        egui::pos2(1100.0, 700.0),
    ));
    h.snapshot("main_window");
}

#[test]
fn light_tree_overlay_and_statistics_window() {
    // Tall, so that the whole side panel (the light-tree section is near its end) is visible.
    let Some(mut h) = harness_with(egui::vec2(1100.0, 1700.0), AppOptions::default()) else {
        return;
    };
    h.run_steps(3);
    let before = shown_pixels(&h);
    h.get_by_role_and_label(Role::ComboBox, "tree overlay").click();
    h.run_steps(2);
    h.get_by_label("distributions").click();
    h.run_steps(3);
    assert_ne!(shown_pixels(&h), before, "the overlay drew nothing");
    // The level slider appears with the overlay; the statistics window opens from its checkbox.
    h.get_by_label("statistics").click();
    h.run_steps(4);
    // (get_by_* panics when no such node is shown.)
    h.get_by_label_contains("4096 VPLs in 4096 leaves, 13 levels; root flux");
    h.get_by_label_contains("usable = v ≥ 0.70");
    // Issue 23: the tree combo switches the frame to the radix tree (the statistics walk it:
    // deeper than 13 levels), and the overlay draws both trees side by side.
    let overlay_one = shown_pixels(&h);
    h.get_by_role_and_label(Role::ComboBox, "tree").click();
    h.run_steps(2);
    h.get_by_label(TreeKind::Lbvh.label()).click();
    h.run_steps(4);
    let r = h.state().renderer().expect("renderer");
    assert_eq!(r.settings().tree.kind, TreeKind::Lbvh);
    assert_eq!(r.tree_buffers().1.kind, TreeKind::Lbvh);
    h.get_by_label_contains("4096 VPLs in 4096 leaves,");
    assert!(
        h.query_by_label_contains("4096 VPLs in 4096 leaves, 13 levels")
            .is_none(),
        "the statistics still show the perfect tree"
    );
    h.get_by_label("both trees side by side").click();
    h.run_steps(4);
    h.get_by_label_contains("left: perfect binary tree · right: radix tree (LBVH)");
    assert!(
        h.state()
            .renderer()
            .expect("renderer")
            .settings()
            .display
            .tree_compare
    );
    assert_ne!(shown_pixels(&h), overlay_one, "the comparison drew nothing new");
    assert!(h.state().errors().is_empty(), "errors: {:?}", h.state().errors());
}

#[test]
fn clicking_a_block_in_the_cut_view_lists_its_cut() {
    let options = AppOptions {
        settings: Some(slc_settings()),
        view: Some(ViewBuffer::Method(lightcut::methods::tree_samplers::CUT_BLOCKS)),
        ..Default::default()
    };
    let Some(mut h) = harness_with(egui::vec2(1100.0, 700.0), options) else {
        return;
    };
    h.run_steps(3);
    assert!(h.state().errors().is_empty(), "errors: {:?}", h.state().errors());
    // Click the middle of the viewport (right of the side panel): the floor / wall.
    click(&mut h, egui::pos2(700.0, 420.0));
    h.run_steps(2);
    // The window names the block and lists a full cut (16 nodes) with levels and flags.
    h.get_by_label_contains("Cut of block (");
    h.get_by_label_contains("16 nodes; share of the root's flux");
    assert!(h.state().errors().is_empty(), "errors: {:?}", h.state().errors());
}

#[test]
fn hovering_a_pass_in_the_timings_window_shows_its_output() {
    let options = AppOptions {
        timings: true,
        ..Default::default()
    };
    let Some(mut h) = harness_with(egui::vec2(1100.0, 700.0), options) else {
        return;
    };
    h.run_steps(6);
    // The window lists the passes once timestamps came back.
    h.get_by_label_contains("ms GPU over");
    let final_px = shown_pixels(&h);
    // The pass rows are above the history plot (whose legend may name the pass too).
    let hover_row = |h: &Harness<'_, WorkbenchApp>, name: &str| {
        let node = h
            .get_all_by_label(name)
            .min_by(|a, b| a.rect().min.y.total_cmp(&b.rect().min.y))
            .expect("a timings row");
        node.hover();
    };
    hover_row(&h, "gbuffer");
    h.run_steps(3);
    let hovered_px = shown_pixels(&h);
    assert_eq!(
        h.state().view(),
        ViewBuffer::Final,
        "hovering does not change the selection"
    );
    // Leave the window; then show the albedo for real and compare.
    h.state_mut().set_view(ViewBuffer::Albedo);
    hover_row(&h, "composite");
    h.run_steps(1);
    h.input_mut().events.push(egui::Event::PointerGone);
    h.run_steps(3);
    let albedo_px = shown_pixels(&h);
    assert_ne!(hovered_px, final_px, "hovering gbuffer changed nothing");
    assert_eq!(hovered_px, albedo_px, "hovering gbuffer shows the albedo");
}

#[test]
fn the_pixel_values_window_lists_every_buffer_under_the_pointer() {
    let Some(mut h) = harness() else { return };
    h.run_steps(3);
    h.get_by_label("pixel values window").click();
    h.run_steps(1);
    let pos = egui::pos2(700.0, 420.0);
    h.input_mut().events.push(egui::Event::PointerMoved(pos));
    h.run_steps(3);
    h.get_by_label_contains("Pixel (");
    for row in [
        "final",
        "direct",
        "GI",
        "albedo",
        "normal",
        "position (w: material + 1)",
    ] {
        h.get_by_label(row);
    }
    assert!(h.state().errors().is_empty(), "errors: {:?}", h.state().errors());
}

fn slc_harness(views: Vec<ViewBuffer>, size: egui::Vec2) -> Option<Harness<'static, WorkbenchApp>> {
    let options = AppOptions {
        settings: Some(slc_settings()),
        views,
        reset_layout: true,
        ..Default::default()
    };
    harness_with(size, options)
}

fn click(h: &mut Harness<'_, WorkbenchApp>, pos: egui::Pos2) {
    for pressed in [true, false] {
        h.input_mut().events.push(egui::Event::PointerMoved(pos));
        h.input_mut().events.push(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: Default::default(),
        });
        h.run_steps(1);
    }
}

#[test]
fn clicking_a_view_pins_the_pixel_and_tells_its_story() {
    use lightcut::methods::tree_samplers::pass::StopReason;
    let Some(mut h) = slc_harness(vec![ViewBuffer::Final], egui::vec2(1100.0, 700.0)) else {
        return;
    };
    h.run_steps(3);
    h.get_by_label("pixel story window").click();
    h.run_steps(1);
    // The floor, between the side panel and the tool dock (where the story now docks).
    click(&mut h, egui::pos2(515.0, 560.0));
    h.run_steps(4);
    h.get_by_label_contains("last frame ·");
    h.get_by_label_contains("16 samples; their estimate");
    let story = h.state().story();
    let t = story.trace.as_ref().expect("a story");
    assert_eq!(
        t.samples.len(),
        16,
        "one sample per slot of the configured cut size"
    );
    let evaluated = t
        .samples
        .iter()
        .filter(|s| matches!(s.stop, StopReason::Usable | StopReason::Leaf))
        .count();
    assert!(evaluated > 0, "no sample reached a usable node or a leaf");
    for s in &t.samples {
        assert!(matches!(
            s.stop,
            StopReason::Usable | StopReason::Leaf | StopReason::Dead | StopReason::EmptySlot
        ),);
        if matches!(s.stop, StopReason::Usable | StopReason::Leaf) {
            assert_eq!(
                s.path.last().map_or(s.start, |p| p.0),
                s.end,
                "the path ends at its end node"
            );
        }
    }
    assert!(h.state().errors().is_empty(), "errors: {:?}", h.state().errors());
}

#[test]
fn raising_v_min_changes_the_traversal_steps_image() {
    let Some(mut h) = slc_harness(
        vec![ViewBuffer::Method(lightcut::methods::tree_samplers::STEPS)],
        egui::vec2(700.0, 500.0),
    ) else {
        return;
    };
    h.run_steps(4);
    let before = shown_pixels(&h);
    // Fewer usable nodes: traversals go deeper.
    let mut s = h.state().settings().clone();
    s.tree.v_min = 0.999;
    s.tree.sigma_max = 0.01;
    h.state_mut().set_settings(s);
    h.run_steps(4);
    let after = shown_pixels(&h);
    let mean = |p: &[u8]| {
        p.chunks(4)
            .map(|c| c[0] as f64 + c[1] as f64 + c[2] as f64)
            .sum::<f64>()
    };
    assert_ne!(before, after, "the traversal-steps image did not change");
    assert!(mean(&after) != mean(&before));
    assert!(h.state().errors().is_empty(), "errors: {:?}", h.state().errors());
}

/// A view exported from the window after some frames, rendered again headlessly from its
/// capture record alone: the same bytes (issue 41). Accumulation on, so the image averages
/// several frames that started after the window had rendered others.
#[test]
fn a_view_exported_from_the_gui_renders_again_bit_for_bit_from_its_record() {
    use lightcut::app::image_views::ExportKind;
    let mut settings = slc_settings();
    settings.frame.accumulate = true;
    let options = AppOptions {
        settings: Some(settings),
        views: vec![ViewBuffer::Final],
        reset_layout: true,
        ..Default::default()
    };
    let Some(mut h) = harness_with(egui::vec2(900.0, 600.0), options) else {
        return;
    };
    h.run_steps(6);
    let dir = std::env::temp_dir().join(format!("lightcut_ui_again_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    h.state_mut().set_export_dir(dir.to_str().unwrap());
    let spec = h.state().layout().panes()[0].spec;
    let exr = h.state_mut().export_view(0, &spec, ExportKind::Exr);
    assert!(h.state().errors().is_empty(), "errors: {:?}", h.state().errors());
    assert_eq!(exr.len(), 1);
    let rec = lightcut::capture::sidecar_path(&exr[0]);
    let (c, _) = lightcut::capture::split(&std::fs::read_to_string(&rec).unwrap()).unwrap();
    let c = c.expect("a [capture] table");
    let first = c.first_frame.expect("a per-frame method's first image frame");
    assert!(
        c.frames >= 2 && first > 0 && first + c.frames as u64 == c.frame_index,
        "{c:?}"
    );
    let again = dir.join("again");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_lightcut-workbench"))
        .args(["render", "--settings"])
        .arg(&rec)
        .args(["--output", "final", "--out"])
        .arg(&again)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "render --settings: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        std::fs::read(&exr[0]).unwrap() == std::fs::read(again.join("final.exr")).unwrap(),
        "the exported view and its render from the record differ"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn several_views_render_their_buffers_and_export_files_that_decode() {
    use lightcut::app::image_views::ExportKind;
    let Some(mut h) = slc_harness(
        vec![ViewBuffer::Final, ViewBuffer::Normal, ViewBuffer::AbCompare],
        egui::vec2(1200.0, 700.0),
    ) else {
        return;
    };
    h.run_steps(4);
    let r = h.state().renderer().unwrap();
    let images: Vec<Vec<u8>> = (0..3)
        .map(|i| r.read_view_rgba8_at(i).expect("a view").2)
        .collect();
    assert_ne!(images[0], images[1], "final and normal views are the same");
    assert_eq!(h.state().layout().view_count(), 3);
    let dir = std::env::temp_dir().join(format!("lightcut_ui_export_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    h.state_mut().set_export_dir(dir.to_str().unwrap());
    let specs: Vec<_> = h.state().layout().panes().iter().map(|p| p.spec).collect();
    let png = h.state_mut().export_view(0, &specs[0], ExportKind::Png);
    let exr = h.state_mut().export_view(1, &specs[1], ExportKind::Exr);
    // The A/B view (live GI vs the ground truth, which is off): A exists, B does not.
    let mut ab = specs[2];
    ab.ab.b = lightcut::renderer::views::AbSource::Direct;
    let ab_files = h.state_mut().export_view(2, &ab, ExportKind::Exr);
    assert!(h.state().errors().is_empty(), "errors: {:?}", h.state().errors());
    assert_eq!((png.len(), exr.len(), ab_files.len()), (1, 1, 2));
    let img = image::open(&png[0]).expect("the PNG decodes");
    let (w, hh) = h.state().renderer().unwrap().size();
    assert_eq!((img.width(), img.height()), (w, hh));
    for f in exr.iter().chain(&ab_files) {
        let e = lightcut::export::read_exr(f).expect("the EXR decodes");
        assert_eq!((e.width, e.height), (w, hh));
    }
    // Every export has its capture record beside it: the settings shown, the camera and
    // lights exactly, the render size and the frame index.
    for f in png.iter().chain(&exr).chain(&ab_files) {
        let rec = lightcut::capture::sidecar_path(f);
        let text = std::fs::read_to_string(&rec).unwrap_or_else(|e| panic!("{}: {e}", rec.display()));
        let (c, rest) = lightcut::capture::split(&text).expect("a record");
        let c = c.expect("a [capture] table");
        assert_eq!(c.what, "view export");
        assert_eq!((c.width, c.height), (w, hh));
        assert!(
            c.frame_index >= 4 && !c.lights.is_empty() && c.camera.yfov > 0.0,
            "{c:?}"
        );
        let s: lightcut::renderer::settings::RenderSettings = rest.try_into().expect("the settings");
        assert_eq!(&s, h.state().renderer().unwrap().settings());
    }
    // A preset whose scene file is not fetched: one line naming the command that fetches
    // it, and the open scene stays.
    let preset = dir.join("unfetched.toml");
    std::fs::write(&preset, "gltf = \"not-here/BreakfastRoom.gltf\"\n").unwrap();
    let before = h.state().open().unwrap().scene.name.clone();
    let e = h
        .state_mut()
        .open_scene(preset.to_str().unwrap(), None)
        .unwrap_err();
    assert!(e.contains("fetch-scenes") && !e.contains('\n'), "{e}");
    assert_eq!(h.state().open().unwrap().scene.name, before);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_comparison_sheet_runs_in_the_gui_and_can_be_cancelled() {
    let Some(mut h) = slc_harness(vec![ViewBuffer::Final], egui::vec2(700.0, 500.0)) else {
        return;
    };
    let mut s = h.state().settings().clone();
    s.gi.rays_per_frame = 1 << 26;
    h.state_mut().set_settings(s);
    h.run_steps(2);
    let dir = std::env::temp_dir().join(format!("lightcut_ui_sheet_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    h.state_mut().set_export_dir(dir.to_str().unwrap());
    // Cancelled: nothing is written, the settings are back.
    h.state_mut().start_sheet(vec![SLC, RTSLC], 2);
    h.run_steps(1);
    assert!(h.state().sheet_progress().is_some(), "the sheet shows progress");
    h.state_mut().cancel_sheet();
    h.run_steps(2);
    assert!(h.state().sheet_progress().is_none());
    assert!(!dir.exists(), "a cancelled sheet wrote files");
    assert_eq!(h.state().renderer().unwrap().settings().gi.method, SLC);
    // Run to the end.
    h.state_mut().start_sheet(vec![SLC, RTSLC], 2);
    let mut steps = 0;
    while h.state().sheet_progress().is_some() && steps < 200 {
        h.run_steps(1);
        steps += 1;
    }
    assert!(h.state().errors().is_empty(), "errors: {:?}", h.state().errors());
    let written = h.state().last_export().to_string();
    assert!(written.contains(".png") && written.contains(".json"), "{written}");
    let png = written.split(", ").next().unwrap();
    let img = image::open(png).expect("the sheet decodes");
    assert!(img.width() > 3 * 320);
    let rec = lightcut::capture::sidecar_path(std::path::Path::new(png));
    let text = std::fs::read_to_string(&rec).unwrap_or_else(|e| panic!("{}: {e}", rec.display()));
    assert!(text.contains("what = \"sheet\""), "{text}");
    assert_eq!(h.state().renderer().unwrap().settings().gi.method, SLC);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_sun_sweep_rebuilds_every_frame_and_pause_freezes_the_image() {
    let Some(mut h) = slc_harness(vec![ViewBuffer::RsmFlux], egui::vec2(700.0, 500.0)) else {
        return;
    };
    h.run_steps(3);
    let a = shown_pixels(&h);
    h.state_mut().animation_mut().sun_deg_per_frame = 5.0;
    h.run_steps(2);
    let b = shown_pixels(&h);
    assert_ne!(a, b, "the sun moved but the RSM did not change");
    h.state_mut().animation_mut().paused = true;
    h.run_steps(1);
    let c = shown_pixels(&h);
    h.run_steps(2);
    assert_eq!(c, shown_pixels(&h), "paused, yet the image changed");
    h.state_mut().animation_mut().step = true;
    h.run_steps(1);
    assert_ne!(c, shown_pixels(&h), "a step rendered nothing new");
    assert!(h.state().errors().is_empty(), "errors: {:?}", h.state().errors());
}

#[test]
fn four_view_layout_snapshot() {
    let options = AppOptions {
        views: vec![
            ViewBuffer::Final,
            ViewBuffer::Normal,
            ViewBuffer::Albedo,
            ViewBuffer::Depth,
        ],
        reset_layout: true,
        ..Default::default()
    };
    let Some(mut h) = harness_with(egui::vec2(1100.0, 700.0), options) else {
        return;
    };
    h.run_steps(4);
    assert_eq!(h.state().layout().view_count(), 4);
    let status = h.get_by_label_contains("GPU: ").rect();
    h.mask(egui::Rect::from_min_max(
        egui::pos2(0.0, status.min.y - 4.0),
        egui::pos2(1100.0, 700.0),
    ));
    h.snapshot("four_views");
}

fn key(h: &mut Harness<'_, WorkbenchApp>, key: egui::Key) {
    for pressed in [true, false] {
        h.input_mut().events.push(egui::Event::Key {
            key,
            physical_key: None,
            pressed,
            repeat: false,
            modifiers: Default::default(),
        });
    }
    h.run_steps(1);
}

#[test]
fn views_zoom_together_and_an_ab_view_measures_a_rectangle_and_toggles() {
    use lightcut::renderer::views::{AbMode, AbSource};
    let Some(mut h) = slc_harness(
        vec![ViewBuffer::Final, ViewBuffer::AbCompare],
        egui::vec2(1100.0, 700.0),
    ) else {
        return;
    };
    // A/B of two live buffers (no ground truth needed): final vs direct.
    for p in h.state_mut().layout_mut().panes_mut() {
        p.spec.ab.a = AbSource::Final;
        p.spec.ab.b = AbSource::Direct;
    }
    h.run_steps(3);
    // Ctrl + wheel over view 1 zooms every view; F fits again.
    let v1 = h.get_by_label("view 1").rect().center() + egui::vec2(0.0, 150.0);
    h.input_mut().events.push(egui::Event::PointerMoved(v1));
    h.input_mut().events.push(egui::Event::MouseWheel {
        unit: egui::MouseWheelUnit::Point,
        delta: egui::vec2(0.0, 60.0),
        phase: egui::TouchPhase::Move,
        source: egui::MouseWheelSource::Unknown,
        modifiers: egui::Modifiers::COMMAND,
    });
    h.run_steps(2);
    let zoom = h.state().layout().transform.zoom;
    assert!(zoom > 1.0, "ctrl + wheel did not zoom ({zoom})");
    key(&mut h, egui::Key::F);
    assert_eq!(h.state().layout().transform.zoom, 1.0, "F did not fit");
    // 1: one texel per screen pixel: zoom = render width / fitted width in pixels (software
    // adapters render at half the views' pixels, so about 0.5 there).
    key(&mut h, egui::Key::Num1);
    let z1 = h.state().layout().transform.zoom;
    let (rw, rh) = h.state().renderer().unwrap().size();
    let px = h.state().layout().panes()[0].rt.size_px.unwrap();
    let fit_x = px.x.min(px.y * rw as f32 / rh as f32);
    let want = rw as f32 / fit_x;
    assert!((z1 - want).abs() < 0.02 * want, "1 set zoom {z1}, want {want}");
    key(&mut h, egui::Key::F);
    // Shift + drag on the A/B view selects a rectangle; its metrics follow.
    let v2 = h.get_by_label("view 2").rect().center() + egui::vec2(0.0, 220.0);
    h.input_mut()
        .events
        .push(egui::Event::ModifiersChanged(egui::Modifiers::SHIFT));
    h.input_mut().events.push(egui::Event::PointerMoved(v2));
    h.input_mut().events.push(egui::Event::PointerButton {
        pos: v2,
        button: egui::PointerButton::Primary,
        pressed: true,
        modifiers: egui::Modifiers::SHIFT,
    });
    h.run_steps(1);
    for k in 1..=6 {
        h.input_mut().events.push(egui::Event::PointerMoved(
            v2 + egui::vec2(12.0 * k as f32, 8.0 * k as f32),
        ));
        h.run_steps(1);
    }
    let end = v2 + egui::vec2(72.0, 48.0);
    h.input_mut().events.push(egui::Event::PointerButton {
        pos: end,
        button: egui::PointerButton::Primary,
        pressed: false,
        modifiers: egui::Modifiers::SHIFT,
    });
    h.run_steps(1);
    h.input_mut()
        .events
        .push(egui::Event::ModifiersChanged(egui::Modifiers::NONE));
    h.run_steps(2);
    let ab = h
        .state()
        .layout()
        .panes()
        .into_iter()
        .find(|p| p.spec.buffer == ViewBuffer::AbCompare)
        .unwrap();
    let [x0, y0, x1, y1] = ab.rect.expect("shift + drag selected no rectangle");
    assert!(x1 > x0 + 4 && y1 > y0 + 4, "rectangle {:?}", ab.rect);
    let (whole, part) = ab.rt.metrics.expect("no A/B metrics");
    let part = part.expect("no metrics of the rectangle");
    // Final = direct + GI, so A is brighter than B on average.
    assert!(whole.mean_ratio >= 1.0, "{whole:?}");
    // The rectangle is measured on its own (it may be unlit: then the ratios are NaN).
    assert!(
        part.rmse.is_finite() && part.ssim.is_finite() && part.flip.is_finite(),
        "{part:?}"
    );
    assert_ne!(
        part.rmse, whole.rmse,
        "the rectangle's metrics are the whole image's"
    );
    // T over the view flips A and B.
    for p in h.state_mut().layout_mut().panes_mut() {
        p.spec.ab.mode = AbMode::A;
    }
    h.input_mut().events.push(egui::Event::PointerMoved(v2));
    h.run_steps(1);
    key(&mut h, egui::Key::T);
    let mode = |h: &Harness<'_, WorkbenchApp>| {
        h.state()
            .layout()
            .panes()
            .into_iter()
            .find(|p| p.spec.buffer == ViewBuffer::AbCompare)
            .unwrap()
            .spec
            .ab
            .mode
    };
    assert_eq!(mode(&h), AbMode::B, "T did not toggle");
    assert!(h.state().errors().is_empty(), "errors: {:?}", h.state().errors());
}

#[test]
fn tree_sampler_controls_reach_the_renderer() {
    // Tall, so that the global-illumination section's sampler controls are on screen; one
    // small view (the controls are what this tests, and SLC on lavapipe costs per pixel).
    let Some(mut h) = slc_harness(vec![ViewBuffer::Final], egui::vec2(600.0, 1700.0)) else {
        return;
    };
    h.run_steps(3);
    let settings = |h: &Harness<'_, WorkbenchApp>| h.state().renderer().expect("renderer").settings().clone();
    assert!(settings(&h).gi.shadow_rays);
    assert_eq!(SamplingSettings::of(&settings(&h)).near_field, 1.0);
    assert!(
        h.query_all_by_label("near-field refinement").next().is_some(),
        "no near-field slider for SLC"
    );
    assert_eq!(SamplingSettings::of(&settings(&h)).substitute_offset, 0.05);
    assert!(
        h.query_all_by_label("substitute ray offset").next().is_some(),
        "no substitute ray offset slider for SLC"
    );
    // The child-probability combo: open it, pick the thesis's.
    let want = ChildProbability::Mean;
    assert_ne!(SamplingSettings::of(&settings(&h)).child_probability, want);
    h.get_by_label("child probability").click();
    h.run_steps(2);
    // (get_by_* panics when no such node is shown, or several are.)
    h.get_by_label(want.name()).click();
    h.run_steps(3);
    assert_eq!(
        SamplingSettings::of(&settings(&h)).child_probability,
        want,
        "the child-probability combo did not reach the renderer"
    );
    h.get_by_label("shadow rays").click();
    h.run_steps(3);
    assert!(
        !settings(&h).gi.shadow_rays,
        "the shadow-ray checkbox did not reach the renderer"
    );
    assert!(h.state().errors().is_empty(), "errors: {:?}", h.state().errors());
}

#[test]
fn the_temporal_switch_and_the_camera_path_reach_the_renderer() {
    use lightcut::renderer::settings::{TemporalMode, TemporalView};
    // Tall, so that the GI section's temporal combo and the animation section are on screen;
    // one view: the disocclusion mask.
    let Some(mut h) = slc_harness(
        vec![ViewBuffer::Temporal(TemporalView::Disocclusion)],
        egui::vec2(600.0, 1700.0),
    ) else {
        return;
    };
    h.run_steps(3);
    let settings = |h: &Harness<'_, WorkbenchApp>| h.state().renderer().expect("renderer").settings().clone();
    assert_eq!(settings(&h).temporal.mode, TemporalMode::Off);
    h.get_by_label("temporal").click();
    h.run_steps(2);
    h.get_by_label(TemporalMode::Svgf.label()).click();
    h.run_steps(3);
    assert_eq!(
        settings(&h).temporal.mode,
        TemporalMode::Svgf,
        "the temporal combo did not reach the renderer"
    );
    let frame = h.state().renderer().and_then(|r| r.temporal().last_frame());
    assert!(frame.is_some_and(|f| f.iterations == 5), "{frame:?}");
    // A still view: every covered pixel keeps its four taps (white or black background only).
    let still = shown_pixels(&h);
    let partial = |px: &[u8]| {
        px.chunks(4)
            .filter(|p| p[0] != p[1] || (p[0] > 0 && p[0] < 250))
            .count()
    };
    assert_eq!(partial(&still), 0, "a still camera disoccluded pixels");
    // Play the path through the default scene's two bookmarks: the camera moves, the mask
    // shows disoccluded or partially kept pixels.
    h.state_mut().animation_mut().path.frames = 12;
    h.get_by_label("play path").click();
    h.run_steps(4);
    assert!(h.state().animation().path.at.is_some_and(|i| i >= 2));
    assert!(
        partial(&shown_pixels(&h)) > 0,
        "the path moved the camera but nothing was disoccluded"
    );
    assert!(h.state().errors().is_empty(), "errors: {:?}", h.state().errors());
}

#[test]
fn bounce_controls_reach_the_renderer_and_the_overlay_colours_by_bounce() {
    // Direct light only (the frame still makes VPLs, light paths and the tree), the VPL
    // overlay on; tall, so that the VPL section is on screen.
    let mut s = lightcut::renderer::settings::RenderSettings::default();
    s.gi.method = lightcut::methods::direct_only::ID;
    s.vpl.count = 1024;
    s.display.vpl_overlay = true;
    s.display.vpl_point_size = 2;
    let options = AppOptions {
        settings: Some(s),
        ..Default::default()
    };
    let Some(mut h) = harness_with(egui::vec2(1100.0, 1700.0), options) else {
        return;
    };
    h.run_steps(3);
    let settings = |h: &Harness<'_, WorkbenchApp>| h.state().renderer().expect("renderer").settings().clone();
    assert_eq!(settings(&h).vpl.bounces, 1);
    h.get_by_role_and_label(Role::Slider, "bounces")
        .set_value_accesskit(3.0);
    h.run_steps(3);
    assert_eq!(settings(&h).vpl.bounces, 3);
    let r = h.state().renderer().expect("renderer");
    assert_eq!((r.vpl_frame().bounces, r.vpl_frame().paths), (3, 341));
    h.get_by_label_contains("bounce 1: 342 RSM VPLs · bounces 2..3: 341 light paths");
    // Russian roulette and the path-start mix appear with more than one bounce.
    assert!(settings(&h).vpl.roulette);
    h.get_by_label("Russian roulette").click();
    h.run_steps(2);
    assert!(!settings(&h).vpl.roulette);
    h.get_by_role_and_label(Role::Slider, "path start flux mix")
        .set_value_accesskit(0.1);
    h.run_steps(2);
    assert!((settings(&h).vpl.path_flux_mix - 0.1).abs() < 1e-3);
    // The overlay's colour: by bounce, with a legend swatch per bounce.
    let by_flux = shown_pixels(&h);
    h.get_by_role_and_label(Role::ComboBox, "VPL colour").click();
    h.run_steps(2);
    h.get_by_label("bounce").click();
    h.run_steps(3);
    assert_eq!(
        settings(&h).display.vpl_color,
        lightcut::renderer::settings::VplColor::Bounce
    );
    h.get_by_label("bounce 3");
    assert_ne!(shown_pixels(&h), by_flux, "colouring by bounce changed nothing");
    assert!(h.state().errors().is_empty(), "errors: {:?}", h.state().errors());
}

#[test]
fn a_one_bounce_method_says_so_under_the_bounces_slider() {
    let mut s = lightcut::renderer::settings::RenderSettings::default();
    s.gi.method = lightcut::methods::val::ID;
    s.vpl.count = 256;
    s.vpl.bounces = 2;
    let options = AppOptions {
        settings: Some(s),
        view: Some(ViewBuffer::Albedo),
        ..Default::default()
    };
    let Some(mut h) = harness_with(egui::vec2(700.0, 1700.0), options) else {
        return;
    };
    h.run_steps(2);
    h.get_by_label_contains("lights the scene from the RSM's texels (one bounce)");
}

#[test]
fn the_brdf_combo_reaches_the_renderer_and_lambert_only_methods_say_so() {
    // Direct light only (GGX-capable): the combo switches the frame's BRDF, the direct light
    // changes.
    let Some(mut h) = harness_with(egui::vec2(1100.0, 1700.0), AppOptions::default()) else {
        return;
    };
    h.run_steps(3);
    let lambert = shown_pixels(&h);
    h.get_by_role_and_label(Role::ComboBox, "BRDF").click();
    h.run_steps(2);
    h.get_by_label("GGX (metallic-roughness)").click();
    h.run_steps(3);
    let r = h.state().renderer().expect("renderer");
    assert_eq!(r.settings().gi.brdf, lightcut::renderer::settings::Brdf::Ggx);
    assert_ne!(
        shown_pixels(&h),
        lambert,
        "GGX changed nothing in the direct light"
    );
    assert!(h.query_by_label_contains("Lambert only").is_none());
    assert!(h.state().errors().is_empty(), "errors: {:?}", h.state().errors());
    drop(h);
    // A Lambert-only method: the note under the combo.
    let mut s = slc_settings();
    s.gi.method = lightcut::methods::lightcut_interpolation::ID;
    s.vpl.count = 64;
    s.gi.brdf = lightcut::renderer::settings::Brdf::Ggx;
    let options = AppOptions {
        settings: Some(s),
        view: Some(ViewBuffer::Albedo),
        ..Default::default()
    };
    let Some(mut h) = harness_with(egui::vec2(500.0, 1700.0), options) else {
        return;
    };
    h.run_steps(1);
    h.get_by_label_contains("shades with Lambert only so far");
    drop(h);
    // SLC with GGX: the glossy walk's weights (the SST paper's material term) are a setting.
    let mut s = slc_settings();
    s.vpl.count = 64;
    s.gi.brdf = lightcut::renderer::settings::Brdf::Ggx;
    let options = AppOptions {
        settings: Some(s),
        view: Some(ViewBuffer::Albedo),
        ..Default::default()
    };
    let Some(mut h) = harness_with(egui::vec2(500.0, 1700.0), options) else {
        return;
    };
    h.run_steps(1);
    h.get_by_role_and_label(Role::ComboBox, "glossy walk weights")
        .click();
    h.run_steps(2);
    h.get_by_label("material term (SST paper)").click();
    h.run_steps(2);
    let r = h.state().renderer().expect("renderer");
    assert_eq!(
        SamplingSettings::of(r.settings()).glossy_weights,
        lightcut::base::sampling::GlossyWeights::Material
    );
    assert!(h.state().errors().is_empty(), "errors: {:?}", h.state().errors());
}

/// The built-in scenes (issue 37) are one click away: each button opens its scene, whose
/// name and triangle count the scene section shows, and the view changes.
#[test]
fn the_builtin_scene_buttons_open_their_scenes() {
    let Some(mut h) = harness() else { return };
    h.run_steps(2);
    let before = shown_pixels(&h);
    for (button, name) in [("corridor", "Corridor: "), ("window-box", "Window box: ")] {
        h.get_by_label(button).click();
        h.run_steps(3);
        assert!(
            h.state().errors().is_empty(),
            "{button}: {:?}",
            h.state().errors()
        );
        h.get_by_label_contains(name);
        assert_ne!(shown_pixels(&h), before, "{button}: the view did not change");
    }
}

/// A lost GPU device (issue 42): the window's app goes to the handover with its state, and a
/// new window on a new device resumes it; rendering goes on with the same settings, scene,
/// camera and views (as `run_gui` does between eframe windows). The device is lost again in
/// each new window (`--lose-device-at-frame` counts per window): after
/// `MAX_DEVICE_RECOVERIES` recoveries the handover holds the reason to stop instead.
#[test]
fn a_lost_device_is_recreated_and_the_app_resumes_in_a_new_window() {
    use lightcut::app::{Handover, MAX_DEVICE_RECOVERIES};
    if common::gpu().is_none() {
        return;
    }
    let handover = Handover::default();
    let mut s = lightcut::renderer::settings::RenderSettings::default();
    s.gi.method = lightcut::methods::direct_only::ID;
    s.display.exposure_ev = 1.5;
    let options = AppOptions {
        scene: "default".into(),
        settings: Some(s.clone()),
        views: vec![ViewBuffer::Final, ViewBuffer::Normal],
        lose_device_at_frame: Some(10),
        ..Default::default()
    };
    let h_in = handover.clone();
    let mut h = Harness::builder()
        .with_size(egui::vec2(900.0, 600.0))
        .wgpu_setup(setup())
        .build_eframe(move |cc| WorkbenchApp::new(cc, options).with_handover(h_in));
    // (The harness runs a few frames when it is built.)
    assert!(h.state().frames() < 10 && !h.state().handed_over());
    let before = shown_pixels(&h);
    let camera = h.state().open().expect("open scene").camera.position;
    for recovery in 1..=MAX_DEVICE_RECOVERIES + 1 {
        let old_errors = h.state().renderer().expect("renderer").ctx.errors.clone();
        for _ in 0..20 {
            if h.state().handed_over() {
                break;
            }
            h.step();
        }
        assert!(
            h.state().handed_over(),
            "the app left the window of the lost device"
        );
        assert!(old_errors.device_lost(), "the old device is lost");
        let next = handover.borrow_mut().take().expect("the handover is filled");
        if recovery > MAX_DEVICE_RECOVERIES {
            let stop = next.err().expect("no new window after the last recovery");
            assert!(
                stop.contains("GPU device lost (Destroyed)") && stop.contains("after 3 recoveries"),
                "{stop}"
            );
            break;
        }
        let app = next.expect("the app to resume");
        let frames = app.frames();
        drop(h);
        h = Harness::builder()
            .with_size(egui::vec2(900.0, 600.0))
            .wgpu_setup(setup())
            .build_eframe(move |cc| app.resume(cc));
        h.run_steps(3);
        let app = h.state();
        assert_eq!(app.recoveries(), recovery);
        let r = app.renderer().expect("a renderer on the new device");
        assert!(!r.ctx.errors.device_lost(), "the new device is not lost");
        assert_eq!(r.settings(), &s, "the settings went on");
        assert_eq!(app.open().expect("open scene").camera.position, camera);
        assert_eq!(
            app.layout()
                .panes()
                .iter()
                .map(|p| p.spec.buffer)
                .collect::<Vec<_>>(),
            vec![ViewBuffer::Final, ViewBuffer::Normal]
        );
        assert!(app.frames() > frames, "frames go on");
        assert!(
            app.errors()
                .iter()
                .any(|e| e.contains("GPU device lost (Destroyed)"))
                && app.errors().iter().any(|e| e.contains("was recreated")),
            "{:?}",
            app.errors()
        );
        // direct_only does not depend on the frame index: the same image on the new device.
        assert_eq!(shown_pixels(&h), before, "the same image as before the loss");
    }
}

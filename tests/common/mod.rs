//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

use lightcut::renderer::context::GpuContext;

/// A headless GPU context, or None (with a message) when this machine has no usable adapter.
/// With `LIGHTCUT_REQUIRE_GPU=1` (set by `.ci/run`) a missing adapter fails the test instead.
pub fn gpu() -> Option<GpuContext> {
    match GpuContext::new_headless() {
        Ok(ctx) => {
            eprintln!("adapter: {}", ctx.describe());
            Some(ctx)
        }
        Err(e) => {
            if std::env::var("LIGHTCUT_REQUIRE_GPU").is_ok_and(|v| v == "1") {
                panic!("LIGHTCUT_REQUIRE_GPU=1 but: {e}");
            }
            eprintln!("SKIPPED (no GPU adapter): {e}");
            None
        }
    }
}

/// The folder holding the reference scenes (`sponza/`, `breakfast_room/`), found through the
/// scene search path presets use (`LIGHTCUT_SCENES`, the user data folder `fetch-scenes`
/// fills, `../shared/scenes` beside the repository), if present.
pub fn shared_scenes() -> Option<PathBuf> {
    let presets = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes");
    match lightcut::scene::scene_path::find(std::path::Path::new("sponza/Sponza.gltf"), Some(&presets)) {
        Ok(p) => p.parent().and_then(|d| d.parent()).map(|d| d.to_path_buf()),
        Err(e) => {
            eprintln!("SKIPPED: {e}");
            None
        }
    }
}

/// Header and rows of a CSV written by the harness (no quoted cells in numeric columns).
pub fn read_csv(path: &std::path::Path) -> (Vec<String>, Vec<std::collections::HashMap<String, String>>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(str::to_string).collect();
    let rows = lines
        .map(|l| {
            // Split on commas outside quotes.
            let mut cells = Vec::new();
            let (mut cur, mut quoted) = (String::new(), false);
            for ch in l.chars() {
                match ch {
                    '"' => quoted = !quoted,
                    ',' if !quoted => cells.push(std::mem::take(&mut cur)),
                    c => cur.push(c),
                }
            }
            cells.push(cur);
            assert_eq!(cells.len(), header.len(), "{}: {l}", path.display());
            header.iter().cloned().zip(cells).collect()
        })
        .collect();
    (header, rows)
}

use lightcut::renderer::{
    Buffer, FrameInput, Renderer,
    readback::ImageF32,
    settings::{RenderSettings, ViewBuffer},
};
use lightcut::scene::{Camera, Scene, default_scene};

/// A renderer on the default scene and its camera, at `size` (the GPU tests' fixture).
pub struct Setup {
    pub r: Renderer,
    pub scene: Scene,
    pub cam: Camera,
}

impl Setup {
    pub fn new(ctx: &GpuContext, s: RenderSettings, size: (u32, u32)) -> Setup {
        Setup::with_scene(ctx, default_scene::build(), s, size)
    }
    /// The fixture on `scene` (the default scene's materials changed, say).
    #[allow(dead_code)]
    pub fn with_scene(ctx: &GpuContext, scene: Scene, s: RenderSettings, size: (u32, u32)) -> Setup {
        let cam = scene.camera_or_default(None).unwrap();
        let r = Renderer::new(ctx.clone(), &scene, size, s).unwrap();
        Setup { r, scene, cam }
    }
    pub fn frame(&mut self) {
        self.r.render(&FrameInput {
            camera: &self.cam,
            lights: &self.scene.lights,
            view: ViewBuffer::Final,
        });
    }
    pub fn set(&mut self, f: impl FnOnce(&mut RenderSettings)) {
        let mut s = self.r.settings().clone();
        f(&mut s);
        self.r.set_settings(s).unwrap();
    }
    pub fn indirect(&self) -> ImageF32 {
        self.r.read(Buffer::Indirect).unwrap()
    }
    /// Switches to the ground truth (all of a frame's VPL batches at once) and runs it to
    /// the end; the settings stay the ground truth's.
    pub fn ground_truth(&mut self) -> ImageF32 {
        self.set(|s| {
            s.gi.method = lightcut::methods::ground_truth::ID;
            s.gi.rays_per_frame = 1 << 26;
        });
        loop {
            self.frame();
            if self.r.gi_progress().is_some_and(|p| p.finished()) {
                break;
            }
        }
        self.indirect()
    }
    /// The ground truth of the current frame's VPLs (the tree frozen first, so that the
    /// VPLs stay), then the settings as they were.
    pub fn ground_truth_of_these_vpls(&mut self) -> ImageF32 {
        self.r.set_freeze_tree(true);
        let s = self.r.settings().clone();
        let gt = self.ground_truth();
        self.r.set_settings(s).unwrap();
        gt
    }
}

/// The default room with every material set to (metallic, roughness) (the GGX tests).
#[allow(dead_code)]
pub fn glossy_room(metallic: f32, roughness: f32) -> Scene {
    let mut scene = default_scene::build();
    for m in &mut scene.materials {
        (m.metallic, m.roughness) = (metallic, roughness);
    }
    scene
}

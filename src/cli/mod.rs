//! Headless commands sharing the renderer with the app: `render` and `bench`.

pub mod bench;
pub mod bench_lightcuts;
pub mod bench_soak;
pub mod compare;
pub mod export_scene;
pub mod fetch_scenes;
pub mod method_flags;
pub mod methods;
pub mod render;
mod render_sequence;
pub mod results;
pub mod sheet;

use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

/// lightcut-workbench: real-time many-light GI research workbench.
#[derive(Parser, Debug)]
#[command(name = "lightcut-workbench", version, about)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Scene to open in the GUI: `default` or another built-in scene (`window-box`, `corridor`,
    /// `glossy-thin`), a .gltf/.glb file, or a preset .toml under scenes/.
    #[arg(long, default_value = "default")]
    pub scene: String,
    /// Camera name from the scene file (default: the preset's, else the first).
    #[arg(long)]
    pub camera: Option<String>,
    /// Exit after rendering this many frames (smoke tests, CI).
    #[arg(long)]
    pub frames: Option<u64>,
    /// Save a screenshot of the whole window (PNG) just before exiting (with --frames).
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// GUI start-up settings: a TOML file with `RenderSettings` (as `render --settings`);
    /// its exposure replaces the preset's.
    #[arg(long)]
    pub settings: Option<PathBuf>,
    /// Open the light-tree statistics window at start.
    #[arg(long)]
    pub tree_stats: bool,
    /// The buffer shown at start, by its name in the buffer selector (e.g. "albedo").
    #[arg(long)]
    pub view: Option<String>,
    /// Start with "compare with the ground truth" on (tree samplers).
    #[arg(long)]
    pub compare_gt: bool,
    /// Open the GPU timings window at start.
    #[arg(long)]
    pub timings: bool,
    /// Start with several docked views, by buffer name, separated by ';'
    /// (e.g. "final;GI only;traversal steps"); the saved layout is not used then.
    #[arg(long)]
    pub views: Option<String>,
    /// Ignore the saved view layout (the first screen: final, GI, ground truth, traversal
    /// steps; or the views of --view / --views).
    #[arg(long)]
    pub reset_layout: bool,
    /// Pin a frame pixel "X,Y" and open its pixel story (tree samplers).
    #[arg(long, value_parser = parse_pixel)]
    pub pin: Option<(u32, u32)>,
    /// Testing the recovery from a lost GPU device: destroy the device after this many frames
    /// of each window; the workbench recreates it and goes on, and stops after three
    /// recoveries (`.ci/run`'s lost-device runs).
    #[arg(long, hide = true)]
    pub lose_device_at_frame: Option<u64>,
}

/// The GUI's start-up options from the command line (no subcommand): the settings file, the
/// views by name, the first screen ([`crate::app::first_screen`]) when no view is named and
/// no layout is saved.
pub fn gui_options(cli: &Cli) -> anyhow::Result<crate::app::AppOptions> {
    use crate::settings::ViewBuffer;
    let settings = cli
        .settings
        .as_ref()
        .map(|p| {
            SettingsArgs {
                settings: Some(p.clone()),
                ..Default::default()
            }
            .resolve(0.0)
        })
        .transpose()?;
    let view = cli
        .view
        .as_deref()
        .map(ViewBuffer::from_name)
        .transpose()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let views = cli
        .views
        .as_deref()
        .unwrap_or("")
        .split(';')
        .filter(|s| !s.trim().is_empty())
        .map(|s| ViewBuffer::from_name(s).map_err(|e| anyhow::anyhow!("{e}")))
        .collect::<anyhow::Result<Vec<_>>>()?;
    Ok(crate::app::AppOptions {
        scene: cli.scene.clone(),
        camera: cli.camera.clone(),
        exit_after_frames: cli.frames,
        screenshot: cli.screenshot.clone(),
        settings,
        tree_stats: cli.tree_stats,
        view,
        compare_gt: cli.compare_gt,
        timings: cli.timings,
        views,
        default_views: crate::app::first_screen(),
        reset_layout: cli.reset_layout,
        pin: cli.pin,
        lose_device_at_frame: cli.lose_device_at_frame,
    })
}

/// "X,Y" as two pixel coordinates.
fn parse_pixel(s: &str) -> Result<(u32, u32), String> {
    let (x, y) = s
        .split_once(',')
        .ok_or_else(|| format!("'{s}' is not a pixel; write X,Y (e.g. 120,80)"))?;
    let p = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{s}' is not a pixel; write X,Y with whole numbers"))
    };
    Ok((p(x)?, p(y)?))
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render headlessly and write linear EXRs, tonemapped PNGs and per-pass timings.
    Render(render::RenderArgs),
    /// Benchmarks (BVH shadow rays per second, ...).
    Bench(bench::BenchArgs),
    /// Write a scene as PLY meshes + JSON (camera, sun, albedos) for independent renderers
    /// (scripts/mitsuba_check.py).
    ExportScene(export_scene::ExportSceneArgs),
    /// Error metrics of an image against a reference: RMSE, relative RMSE, SSIM, FLIP, mean ratio.
    Compare(compare::CompareArgs),
    /// A comparison sheet: methods side by side on the same VPLs, their error maps against
    /// the ground truth, and captions (method, settings, RMSE, SSIM, FLIP, GPU time).
    Sheet(sheet::SheetArgs),
    /// Thesis chapter 7's evaluation and every method's own study, one figure per name
    /// (`results --help` lists them): CSV, PNG plots and images per scene, the ratio checks in
    /// checks.csv.
    Results(results::ResultsArgs),
    /// Download the reference scenes (Sponza, Breakfast Room) from AMD's CapsaicinTestMedia
    /// (CC BY 3.0), check every file's SHA-256 against the files the measurements used, and
    /// put them where presets find them (the user data folder by default).
    FetchScenes(fetch_scenes::FetchScenesArgs),
    /// The GI methods this build knows (`render --method`, `sheet --methods`): name, kind,
    /// views, timed GPU passes and the tests that check each.
    Methods,
}

/// Settings flags shared by the commands (override a settings file, which overrides defaults).
#[derive(Args, Debug, Clone, Default)]
pub struct SettingsArgs {
    /// TOML file with `RenderSettings` (see ARCHITECTURE.md for the fields).
    #[arg(long)]
    pub settings: Option<PathBuf>,
    /// Shadow-map resolution per light.
    #[arg(long)]
    pub shadow_res: Option<u32>,
    /// PCF radius in shadow-map texels (0 = hard).
    #[arg(long)]
    pub pcf: Option<u32>,
    /// Exposure in EV for the PNGs (EXRs are never scaled).
    #[arg(long)]
    pub exposure: Option<f32>,
    /// Largest base-colour texture size uploaded.
    #[arg(long)]
    pub max_texture: Option<u32>,
    /// Anisotropic texture filtering, 1..=16.
    #[arg(long)]
    pub anisotropy: Option<u16>,
    /// Sets one settings field by its TOML path, e.g. `--set methods.lightcuts.max_cut=512`
    /// or `--set gi.distance_epsilon=0.02` (repeatable; applied after the settings file).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

impl SettingsArgs {
    pub fn resolve(&self, preset_exposure: f32) -> anyhow::Result<crate::settings::RenderSettings> {
        let mut s = match &self.settings {
            Some(p) => {
                let text = std::fs::read_to_string(p)
                    .map_err(|e| anyhow::anyhow!("cannot read settings file {}: {e}", p.display()))?;
                // A capture record is a settings file with a `[capture]` table (read by
                // `render`, ignored here).
                let (_, rest) = crate::capture::split(&text)
                    .map_err(|e| anyhow::anyhow!("bad settings file {}: {e}", p.display()))?;
                rest.try_into().map_err(|e: toml::de::Error| {
                    anyhow::anyhow!("bad settings file {}: {}", p.display(), e.message())
                })?
            }
            None => {
                let mut s = crate::settings::RenderSettings::default();
                s.display.exposure_ev = preset_exposure;
                s
            }
        };
        for kv in &self.set {
            let (k, v) = kv
                .split_once('=')
                .ok_or_else(|| anyhow::anyhow!("--set {kv}: expected KEY=VALUE"))?;
            s.set_path(k.trim(), v.trim())
                .map_err(|e| anyhow::anyhow!("{e}"))?;
        }
        if let Some(v) = self.shadow_res {
            s.shadow.resolution = v;
        }
        if let Some(v) = self.pcf {
            s.shadow.pcf_radius = v;
        }
        if let Some(v) = self.exposure {
            s.display.exposure_ev = v;
        }
        if let Some(v) = self.max_texture {
            s.textures.max_size = v;
        }
        if let Some(v) = self.anisotropy {
            s.textures.anisotropy = v;
        }
        s.validate().map_err(|e| anyhow::anyhow!("{e}"))?;
        Ok(s)
    }
}

//! `lightcut-workbench`: the GUI by default, headless commands as subcommands.

use clap::Parser;
use lightcut::{
    app::{AppOptions, run_gui},
    cli::{Cli, Command, bench, compare, export_scene, render, results, sheet},
};

fn main() {
    env_logger::Builder::from_env(
        env_logger::Env::default()
            .default_filter_or("info,wgpu_core=warn,wgpu_hal=warn,naga=warn,eframe=warn,egui_wgpu=warn"),
    )
    .init();
    let cli = Cli::parse();
    let result = match &cli.command {
        Some(Command::Render(args)) => render::run(args),
        Some(Command::Bench(args)) => bench::run(args),
        Some(Command::ExportScene(args)) => export_scene::run(args),
        Some(Command::Compare(args)) => compare::run(args),
        Some(Command::Sheet(args)) => sheet::run(args),
        Some(Command::Results(args)) => results::run(args),
        None => {
            let settings = cli.settings.as_ref().map(|p| {
                lightcut::cli::SettingsArgs {
                    settings: Some(p.clone()),
                    ..Default::default()
                }
                .resolve(0.0)
            });
            let view = cli
                .view
                .as_deref()
                .map(lightcut::renderer::settings::ViewBuffer::from_name)
                .transpose()
                .map_err(|e| anyhow::anyhow!("{e}"));
            let views: anyhow::Result<Vec<_>> = cli
                .views
                .as_deref()
                .unwrap_or("")
                .split(';')
                .filter(|s| !s.trim().is_empty())
                .map(|s| {
                    lightcut::renderer::settings::ViewBuffer::from_name(s).map_err(|e| anyhow::anyhow!("{e}"))
                })
                .collect();
            match (settings.transpose(), view, views) {
                (Err(e), _, _) | (_, Err(e), _) | (_, _, Err(e)) => Err(e),
                (Ok(settings), Ok(view), Ok(views)) => run_gui(AppOptions {
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
                    reset_layout: cli.reset_layout,
                    pin: cli.pin,
                }),
            }
        }
    };
    if let Err(e) = result {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

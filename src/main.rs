//! `lightcut-workbench`: the GUI by default, headless commands as subcommands.

use clap::Parser;
use lightcut::{
    app::{AppOptions, run_gui},
    cli::{Cli, Command, bench, export_scene, render},
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
        None => run_gui(AppOptions {
            scene: cli.scene.clone(),
            camera: cli.camera.clone(),
            exit_after_frames: cli.frames,
            screenshot: cli.screenshot.clone(),
        }),
    };
    if let Err(e) = result {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

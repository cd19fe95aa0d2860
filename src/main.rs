//! `lightcut-workbench`: the GUI by default, headless commands as subcommands.

use lightcut::{
    app::run_gui,
    cli::{Cli, Command, bench, compare, export_scene, fetch_scenes, methods, render, results, sheet},
};

fn main() {
    env_logger::Builder::from_env(
        env_logger::Env::default()
            .default_filter_or("info,wgpu_core=warn,wgpu_hal=warn,naga=warn,eframe=warn,egui_wgpu=warn"),
    )
    .init();
    // The BVH layout frames trace (`scene_gpu::BvhLayout`): LIGHTCUT_BVH=wide|binary.
    match std::env::var("LIGHTCUT_BVH").as_deref() {
        Err(_) | Ok("") => {}
        Ok(v) => match lightcut::renderer::scene_gpu::BvhLayout::parse(v) {
            Some(l) => lightcut::renderer::scene_gpu::set_frame_bvh_layout(l),
            None => {
                eprintln!("error: LIGHTCUT_BVH={v}: expected `wide` or `binary`");
                std::process::exit(2);
            }
        },
    }
    let matches = <Cli as clap::CommandFactory>::command().get_matches();
    let mut cli = <Cli as clap::FromArgMatches>::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    // `render --settings <capture record>`: the record fills what the command line leaves out.
    if let Some(Command::Render(a)) = &mut cli.command
        && let Some(m) = matches.subcommand_matches("render")
    {
        a.explicit = m
            .ids()
            .filter(|id| m.value_source(id.as_str()) == Some(clap::parser::ValueSource::CommandLine))
            .map(|id| id.to_string())
            .collect();
    }
    let result = match &cli.command {
        Some(Command::Render(args)) => render::run(args),
        Some(Command::Bench(args)) => bench::run(args),
        Some(Command::ExportScene(args)) => export_scene::run(args),
        Some(Command::Compare(args)) => compare::run(args),
        Some(Command::Sheet(args)) => sheet::run(args),
        Some(Command::Results(args)) => results::run(args),
        Some(Command::FetchScenes(args)) => fetch_scenes::run(args),
        Some(Command::Methods) => methods::run(),
        None => lightcut::cli::gui_options(&cli).and_then(run_gui),
    };
    if let Err(e) = result {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
    // A GPU error (validation, out of memory, device lost) met anywhere in a command fails
    // it, with the pass named, even where the command's own loop did not look.
    if cli.command.is_some()
        && let Some(e) = lightcut::renderer::context::first_gpu_error()
    {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

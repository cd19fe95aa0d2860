//! `results`: thesis chapter 7's evaluation, one figure per name (`crate::harness::figures`),
//! on one or more scenes, into `<out>/<scene>/` (CSV, PNG plots, images), with the issue's
//! ratio checks in `<out>/checks.csv` and a `<out>/run.json` of the machine and settings.

mod merge;
pub use merge::*;

use std::path::PathBuf;

use anyhow::{Context, anyhow, bail};
use clap::Args;

use super::SettingsArgs;
use crate::{
    harness::{
        Bench, Csv,
        figures::{self, Check, FigureDef, Opts},
        num,
    },
    renderer::{Renderer, context::GpuContext},
    scene::preset::{SceneSource, open_scene},
};

/// A `results` figure argument: `all`, or a registered figure by its CLI name
/// (`crate::harness::figures::all`: the harness's and the methods' own figures).
#[derive(Clone, Copy, Debug)]
pub enum FigureArg {
    All,
    One(&'static FigureDef),
}

/// A figure's CLI name, or `all`.
pub fn parse_figure(name: &str) -> Result<FigureArg, String> {
    if name == "all" {
        return Ok(FigureArg::All);
    }
    figures::find(name).map(FigureArg::One).ok_or_else(|| {
        let names: Vec<&str> = figures::all().iter().map(|f| f.cli).collect();
        format!("'{name}' is no figure; figures: all, {}", names.join(", "))
    })
}

/// The figures' short help: their CLI names in a run's order.
pub fn figure_help() -> String {
    let names: Vec<&str> = figures::all().iter().map(|f| f.cli).collect();
    format!("Figures to make (comma-separated): all, {}", names.join(", "))
}

/// The figures' long help: each with its description.
pub fn figure_long_help() -> String {
    let mut s = String::from(
        "Figures to make (comma-separated), in the order a run makes them:\n- all: every figure below",
    );
    for f in figures::all() {
        s.push_str(&format!("\n- {}: {}", f.cli, f.doc));
    }
    s
}

/// The figures `args` chose, in the order a run makes them.
fn chosen(args: &[FigureArg]) -> Vec<&'static FigureDef> {
    let all = args.iter().any(|a| matches!(a, FigureArg::All));
    figures::all()
        .into_iter()
        .filter(|f| {
            all || args
                .iter()
                .any(|a| matches!(a, FigureArg::One(g) if std::ptr::eq(*g, *f)))
        })
        .collect()
}

/// A figure label's place in a run's order (unknown labels last).
fn figure_rank(label: &str) -> usize {
    figures::all()
        .iter()
        .position(|f| f.label == label)
        .unwrap_or(usize::MAX)
}

/// The K-th of N shards of a sweep (`--shard K/N`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Shard {
    pub k: u32,
    pub n: u32,
}

/// `K/N` with 1 <= K <= N.
pub fn parse_shard(s: &str) -> Result<Shard, String> {
    let (k, n) = s
        .split_once('/')
        .ok_or_else(|| format!("'{s}': write K/N, e.g. 2/4 (the second of four shards)"))?;
    let p = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{s}': K and N must be whole numbers"))
    };
    let (k, n) = (p(k)?, p(n)?);
    if n == 0 || k == 0 || k > n {
        return Err(format!("'{s}': K must be 1..=N and N at least 1"));
    }
    Ok(Shard { k, n })
}

impl Shard {
    /// Whether work unit `unit` (0-based, in the order an unsharded run does them) is this
    /// shard's: units are dealt round-robin.
    pub fn owns(&self, unit: usize) -> bool {
        unit % self.n as usize == (self.k - 1) as usize
    }
}

#[derive(clap::Subcommand, Debug)]
pub enum ResultsCommand {
    /// Join the folders of `results --shard K/N` runs into one, as an unsharded run writes it:
    /// every figure's files, checks.csv (the timing-agreement checks recomputed over all
    /// shards), run.json.
    Merge(MergeArgs),
}

#[derive(Args, Debug)]
pub struct MergeArgs {
    /// The shard folders (each a `results --shard K/N --out DIR`).
    #[arg(required = true, num_args = 1..)]
    pub shards: Vec<PathBuf>,
    /// The merged results folder (created; must not hold another run).
    #[arg(long)]
    pub out: PathBuf,
}

#[derive(Args, Debug)]
#[command(args_conflicts_with_subcommands = true)]
pub struct ResultsArgs {
    #[command(subcommand)]
    pub command: Option<ResultsCommand>,
    #[arg(
        value_parser = parse_figure,
        value_delimiter = ',',
        default_value = "all",
        help = figure_help(),
        long_help = figure_long_help()
    )]
    pub figures: Vec<FigureArg>,
    /// Scenes, comma-separated: presets (.toml), glTF files or `default`.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "scenes/sponza.toml,scenes/breakfast_room.toml"
    )]
    pub scenes: Vec<String>,
    #[arg(long, default_value_t = 192)]
    pub width: u32,
    #[arg(long, default_value_t = 108)]
    pub height: u32,
    /// Diagnostic frames per configuration: per-frame errors against the ground truth and
    /// sampler statistics (their means reported), after the timed frames. docs/measurement.md.
    #[arg(long, default_value_t = 4)]
    pub frames: u32,
    /// Timed frames per configuration, back to back after a warm-up (GPU timestamps: the
    /// median reported; also the per-pass timing table's frames).
    #[arg(long, default_value_t = 20)]
    pub timing_frames: u32,
    /// Samples per pixel of the equal-time sweep (the base cut size is always added).
    #[arg(long, value_delimiter = ',', default_value = "2,4,8,16,32,64")]
    pub spp: Vec<u32>,
    /// Block sizes of the block sweep.
    #[arg(long, value_delimiter = ',', default_value = "1,2,4,8,16,32")]
    pub blocks: Vec<u32>,
    /// log2 of the VPL counts of the scaling sweep.
    #[arg(long, value_delimiter = ',', default_value = "10,11,12,13,14,15,16")]
    pub vpl_exponents: Vec<u32>,
    /// Frame size of the scaling sweep (it needs a ground truth per VPL count).
    #[arg(long, default_value_t = 80)]
    pub scaling_width: u32,
    #[arg(long, default_value_t = 45)]
    pub scaling_height: u32,
    /// Frame sizes of the upsampling table, as multiples of --width/--height.
    #[arg(long, value_delimiter = ',', default_value = "1,1.5")]
    pub upsampling_scales: Vec<f32>,
    /// Results folder (one sub-folder per scene).
    #[arg(long, default_value = "results")]
    pub out: PathBuf,
    /// Exit non-zero when a check is not met (the thesis's ratios, and the figures' agreement
    /// on SLC's sampling time: a measurement for a real GPU, not a test).
    #[arg(long)]
    pub check: bool,
    /// The per-frame methods the sweeps compare, by CLI name (default: every per-frame method
    /// of the registry; the thesis's checks need slc, rtslc and sst).
    #[arg(long, value_delimiter = ',', value_parser = crate::cli::render::parse_method)]
    pub methods: Vec<crate::methods::MethodId>,
    /// A method's quality-knob values for the equal-time sweep, replacing its registry sweep:
    /// `--sweep lightcuts=0.1,0.02` (relative error), `--sweep sst=4,16` (spp). Repeatable.
    #[arg(long = "sweep", value_name = "METHOD=V1,V2,..")]
    pub sweeps: Vec<String>,
    /// The temporal figure's frames per motion (camera path, sun sweep, still view).
    #[arg(long, default_value_t = 30)]
    pub temporal_frames: u32,
    /// The camera path's length in frames from the first bookmark to the last (its first
    /// --temporal-frames are measured: a few pixels of motion per frame).
    #[arg(long, default_value_t = 240)]
    pub temporal_path_frames: u32,
    /// Degrees the sun's azimuth turns over the temporal figure's sun sweep.
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    pub sun_sweep_deg: f32,
    /// The bounce counts of the bounce-count figure (1 is always added: the others are
    /// measured against it).
    #[arg(long, value_delimiter = ',', default_value = "1,2,3,4")]
    pub bounce_counts: Vec<u32>,
    /// Frame size of the temporal stage's GPU timings.
    #[arg(long, default_value_t = 1280)]
    pub temporal_timing_width: u32,
    #[arg(long, default_value_t = 720)]
    pub temporal_timing_height: u32,
    /// Run only the K-th of N disjoint shards of the work: the (scene, figure) pairs, dealt
    /// round-robin in the order an unsharded run does them. Each shard writes its own --out;
    /// `results merge` joins them (docs/results.md: a Slurm job array).
    #[arg(long, value_name = "K/N", value_parser = parse_shard)]
    pub shard: Option<Shard>,
    /// Number of VPLs (default 4096, as the thesis).
    #[arg(long)]
    pub vpls: Option<u32>,
    #[arg(long)]
    pub seed: Option<u32>,
    #[command(flatten)]
    pub settings: SettingsArgs,
}

impl ResultsArgs {
    fn opts(&self) -> anyhow::Result<Opts> {
        if !(16..=4096).contains(&self.width) || !(16..=4096).contains(&self.height) {
            bail!(
                "--width/--height must be 16..=4096 (got {}x{})",
                self.width,
                self.height
            );
        }
        if !(8..=4096).contains(&self.scaling_width) || !(8..=4096).contains(&self.scaling_height) {
            bail!("--scaling-width/--scaling-height must be 8..=4096");
        }
        if !(1..=1000).contains(&self.frames) || !(1..=10000).contains(&self.timing_frames) {
            bail!("--frames must be 1..=1000 and --timing-frames 1..=10000");
        }
        if self.spp.is_empty() || self.spp.iter().any(|n| !(1..=64).contains(n)) {
            bail!("--spp: samples per pixel must be 1..=64 (the cut size limit)");
        }
        if self.blocks.is_empty() || self.blocks.iter().any(|k| !(1..=64).contains(k)) {
            bail!("--blocks: block sizes must be 1..=64");
        }
        if self.vpl_exponents.is_empty() || self.vpl_exponents.iter().any(|e| !(4..=20).contains(e)) {
            bail!("--vpl-exponents must be 4..=20 (16 .. 2^20 VPLs)");
        }
        if self.upsampling_scales.is_empty()
            || self.upsampling_scales.iter().any(|s| !(0.25..=8.0).contains(s))
        {
            bail!("--upsampling-scales must be 0.25..=8");
        }
        let methods = self.methods.clone();
        if let Some(m) = methods.iter().find(|m| !m.per_frame()) {
            bail!("--methods: {m} is not a per-frame method (the sweeps compare per-frame methods)");
        }
        let mut sweeps = Vec::new();
        for arg in &self.sweeps {
            let (name, values) = arg
                .split_once('=')
                .ok_or_else(|| anyhow::anyhow!("--sweep {arg}: expected METHOD=V1,V2,..."))?;
            let m =
                crate::methods::MethodId::parse(name.trim()).map_err(|e| anyhow::anyhow!("--sweep: {e}"))?;
            if m.info().sweep.is_none() {
                bail!("--sweep: {m} has no quality knob to sweep");
            }
            let v: Vec<f64> = values
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| anyhow::anyhow!("--sweep {arg}: the values must be numbers"))?;
            if v.is_empty() || v.iter().any(|x| !x.is_finite() || *x < 0.0) {
                bail!("--sweep {arg}: the values must be finite and >= 0");
            }
            // Each value must be a valid setting of the method.
            for &x in &v {
                let mut s = crate::settings::RenderSettings::default();
                (m.info().sweep.map(|sw| sw.apply).unwrap_or(|_, _| ()))(&mut s, x);
                (m.info().validate)(&s).map_err(|e| anyhow::anyhow!("--sweep {arg}: {e}"))?;
            }
            sweeps.push((m, v));
        }
        if !(2..=10_000).contains(&self.temporal_frames) || self.temporal_path_frames < 2 {
            bail!("--temporal-frames must be 2..=10000 and --temporal-path-frames at least 2");
        }
        if !self.sun_sweep_deg.is_finite() {
            bail!("--sun-sweep-deg must be a number of degrees");
        }
        if !(16..=8192).contains(&self.temporal_timing_width)
            || !(16..=8192).contains(&self.temporal_timing_height)
        {
            bail!("--temporal-timing-width/--temporal-timing-height must be 16..=8192");
        }
        let max_b = crate::gpu::passes::light_paths::MAX_BOUNCES;
        if self.bounce_counts.iter().any(|n| !(1..=max_b).contains(n)) {
            bail!("--bounce-counts must be 1..={max_b}");
        }
        let mut bounces = self.bounce_counts.clone();
        bounces.push(1);
        bounces.sort_unstable();
        bounces.dedup();
        Ok(Opts {
            bounces,
            temporal_frames: self.temporal_frames,
            temporal_path_frames: self.temporal_path_frames,
            sun_sweep_deg: self.sun_sweep_deg,
            temporal_timing_size: (self.temporal_timing_width, self.temporal_timing_height),
            methods,
            sweeps,
            size: (self.width, self.height),
            frames: self.frames,
            timing_frames: self.timing_frames,
            spp: self.spp.clone(),
            blocks: self.blocks.clone(),
            vpl_exponents: self.vpl_exponents.clone(),
            scaling_size: (self.scaling_width, self.scaling_height),
            upsampling_scales: self.upsampling_scales.clone(),
        })
    }
}

/// The folder name of a scene argument.
fn scene_label(arg: &str) -> String {
    std::path::Path::new(arg)
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("scene")
        .to_string()
}

pub fn run(args: &ResultsArgs) -> anyhow::Result<()> {
    if let Some(ResultsCommand::Merge(m)) = &args.command {
        return merge(m);
    }
    let o = args.opts()?;
    let figures = chosen(&args.figures);
    // Open every scene first, so that a broken one fails before hours of work.
    let mut opened = Vec::new();
    for s in &args.scenes {
        let sc = open_scene(&SceneSource::from_arg(s)).map_err(|e| anyhow!("{s}: {e}"))?;
        opened.push((s.clone(), sc));
    }
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    // Each check with the figure that made it ("agreement": the timing agreement).
    let mut checks: Vec<(String, Check)> = Vec::new();
    let mut run_info = Vec::new();
    let started = std::time::Instant::now();
    // The work units, (scene, figure) in the order of an unsharded run; a shard takes every
    // N-th.
    let mut unit = 0usize;
    let mut units_done: Vec<String> = Vec::new();
    for (arg, sc) in opened {
        let label = scene_label(&arg);
        let all_figures = &figures;
        let figures: Vec<&FigureDef> = all_figures
            .iter()
            .copied()
            .filter(|_| {
                let mine = args.shard.is_none_or(|s| s.owns(unit));
                unit += 1;
                mine
            })
            .collect();
        if figures.is_empty() {
            continue;
        }
        units_done.extend(figures.iter().map(|f| format!("{label}/{}", f.label)));
        let dir = args.out.join(&label);
        std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let (mut b, camera_name, adapter) = open_bench(args, &o, &label, &sc)?;
        let mut figure_times = Vec::new();
        for f in &figures {
            let (rep, time) = run_figure(&mut b, f, &o, &dir)?;
            figure_times.push(time);
            checks.extend(rep.checks.into_iter().map(|c| (f.label.to_string(), c)));
        }
        checks.extend(
            timing_agreement(&b, o.size, &dir)?
                .into_iter()
                .map(|c| (AGREEMENT_FIGURE.to_string(), c)),
        );
        run_info.push(serde_json::json!({
            "scene": label,
            "scene_arg": arg,
            "camera": camera_name,
            "triangles": sc.scene.triangle_count(),
            "adapter": adapter,
            "settings": b.base,
            "gi_exposure_ev": b.gi_exposure,
            "figure_times": figure_times,
        }));
    }
    let mut csv = Csv::new(&CHECKS_HEADER);
    for (f, c) in &checks {
        csv.row(check_row(f, c));
    }
    if !checks.is_empty() {
        csv.write(&args.out.join("checks.csv"))?;
        println!("== checks (value vs limit):");
        for (_, c) in &checks {
            println!("  {}", c.line());
        }
    }
    let info = serde_json::json!({
        // The program's own path is left out (it names a folder of this machine).
        "command": std::iter::once("lightcut-workbench".to_string())
            .chain(std::env::args().skip(1))
            .collect::<Vec<_>>()
            .join(" "),
        "width": o.size.0,
        "height": o.size.1,
        "frames": o.frames,
        "timing_frames": o.timing_frames,
        "spp": o.spp,
        "methods": figures::methods(&o).iter().map(|(m, _)| m.cli()).collect::<Vec<_>>(),
        "sweeps": o.sweeps.iter().map(|(m, v)| (m.cli().to_string(), v.clone())).collect::<std::collections::BTreeMap<_, _>>(),
        "blocks": o.blocks,
        "vpl_exponents": o.vpl_exponents,
        "scaling_size": [o.scaling_size.0, o.scaling_size.1],
        "upsampling_scales": o.upsampling_scales,
        "seconds": started.elapsed().as_secs_f64(),
        "scenes": run_info,
        "units": units_done,
        "shard": args.shard,
        // What a merge compares between shards: every option but the shard and the output.
        "options": options_key(args),
        "scene_order": args.scenes.iter().map(|s| scene_label(s)).collect::<Vec<_>>(),
        "figures": figures.iter().map(|f| f.label).collect::<Vec<_>>(),
    });
    let p = args.out.join("run.json");
    std::fs::write(&p, serde_json::to_string_pretty(&info)?)
        .with_context(|| format!("cannot write {}", p.display()))?;
    println!(
        "wrote {} ({:.0} s)",
        args.out.display(),
        started.elapsed().as_secs_f64()
    );
    // After everything is written: an unmet check fails the command (--check).
    let unmet: Vec<String> = checks
        .iter()
        .filter(|(_, c)| !c.pass())
        .map(|(_, c)| c.line())
        .collect();
    if args.check && !unmet.is_empty() {
        return Err(anyhow!("{} check(s) not met: {}", unmet.len(), unmet.join("; ")));
    }
    Ok(())
}

/// Runs figure `f` on the bench from frame index 0 (its numbers do not depend on the figures
/// run before it in this process: a shard runs other ones), prints its table and checks, and
/// returns its report with its `figure_times` entry of run.json.
fn run_figure(
    b: &mut Bench,
    f: &FigureDef,
    o: &Opts,
    dir: &std::path::Path,
) -> anyhow::Result<(figures::Report, serde_json::Value)> {
    let t = std::time::Instant::now();
    let gpu0 = b.gpu_wall;
    b.figure = f.label.to_string();
    // The temporal figure's sequences set their settings without `Bench::apply`, so the frame
    // index is restarted here.
    b.r.restart_frame_index();
    let rep = (f.make)(b, o, dir)?;
    print!("{}", rep.table);
    for c in &rep.checks {
        println!("  check: {}", c.line());
    }
    // Wall time of the figure and the share of it not spent rendering / waiting for the GPU
    // (readbacks, metrics, plots, PNGs: the CPU side).
    let wall = t.elapsed().as_secs_f64();
    let gpu = (b.gpu_wall - gpu0).as_secs_f64();
    let outside = if wall > 0.0 {
        (1.0 - gpu / wall).max(0.0)
    } else {
        0.0
    };
    println!(
        "  ({} took {wall:.1} s wall, {:.0}% of it outside rendering and GPU waits)",
        f.label,
        100.0 * outside
    );
    let time = serde_json::json!({
        "figure": f.label,
        "wall_s": wall,
        "rendering_and_gpu_wait_s": gpu,
        "share_outside_gpu": outside,
    });
    Ok((rep, time))
}

/// A bench on scene `sc` (argument `label`) with the run's settings (`--vpls`, `--seed`
/// applied) at the figures' size, its camera, and the adapter's description.
fn open_bench(
    args: &ResultsArgs,
    o: &Opts,
    label: &str,
    sc: &crate::scene::preset::OpenedScene,
) -> anyhow::Result<(Bench, String, String)> {
    let mut settings = args.settings.resolve(sc.exposure_ev)?;
    if let Some(v) = args.vpls {
        settings.vpl.count = v;
    }
    if let Some(v) = args.seed {
        settings.vpl.seed = v;
    }
    settings.validate().map_err(|e| anyhow!("{e}"))?;
    let camera = sc
        .scene
        .camera_or_default(sc.camera_name.as_deref())
        .map_err(|e| anyhow!("{e}"))?;
    let ctx = GpuContext::new_headless()?;
    let adapter = ctx.describe();
    println!(
        "== {label}: {}x{}, camera '{}', adapter {adapter}",
        o.size.0, o.size.1, camera.name
    );
    let r = Renderer::new(ctx, &sc.scene, o.size, settings.clone())?;
    let camera_name = camera.name.clone();
    let mut b = Bench::new(
        r,
        camera,
        sc.scene.lights.clone(),
        settings,
        label.to_string(),
        adapter.clone(),
    );
    b.bookmarks = sc.scene.cameras.clone();
    b.scene_radius = sc.scene.bounds.radius().max(1e-30);
    Ok((b, camera_name, adapter))
}

/// The columns of checks.csv.
const CHECKS_HEADER: [&str; 8] = [
    "scene", "figure", "check", "value", "limit", "kind", "met", "detail",
];
/// The `figure` of the timing-agreement checks (a scene's last rows).
const AGREEMENT_FIGURE: &str = "agreement";

/// A row of checks.csv: `c` made by `figure`.
fn check_row(figure: &str, c: &Check) -> Vec<String> {
    vec![
        c.scene.clone(),
        figure.to_string(),
        c.name.clone(),
        num(c.value),
        num(c.limit),
        if c.at_least { "at least" } else { "at most" }.into(),
        c.pass().to_string(),
        c.detail.clone(),
    ]
}

/// Every option of a `results` run but `--shard` and `--out` (shards of one sweep agree on it).
fn options_key(args: &ResultsArgs) -> String {
    let mut s = format!("{args:?}");
    for (field, value) in [
        ("shard: ", format!("{:?}", args.shard)),
        ("out: ", format!("{:?}", args.out)),
    ] {
        s = s.replace(&format!("{field}{value}"), field);
    }
    s
}

const AGREEMENT_SAME: &str = "the figures time the same passes of the same frames (SLC, base settings)";
const AGREEMENT_FASTEST: &str = "the figures' fastest SLC sampling frames agree (max / min)";

/// The figures' measurements of the same configuration (SLC at the base settings and size)
/// side by side in `timing_agreement.csv`: the sampling pass's fastest and median GPU time and
/// what was timed (the passes summed, every pass of the frame, the frame mode, the frame
/// count). Two checks when two or more figures measured it: that they timed the same thing
/// (machine-independent), and how far their fastest frames agree (max / min, at most 1.15;
/// on a shared CPU adapter the speed itself wanders, so this one is for a real GPU).
fn timing_agreement(b: &Bench, size: (u32, u32), dir: &std::path::Path) -> anyhow::Result<Vec<Check>> {
    let mut rows: Vec<&crate::harness::BaseTiming> = Vec::new();
    for t in b.base_timings.iter().filter(|t| t.size == size) {
        if !rows.iter().any(|r| r.figure == t.figure) {
            rows.push(t);
        }
    }
    if rows.is_empty() {
        return Ok(Vec::new());
    }
    let mut csv = Csv::new(&[
        "scene",
        "figure",
        "sample_ms_min",
        "sample_ms_median",
        "timed_passes",
        "frame_passes",
        "frame_kind",
        "timed_frames",
    ]);
    for r in &rows {
        csv.row(vec![
            b.scene.clone(),
            r.figure.clone(),
            num(r.sample_ms_min),
            num(r.sample_ms_median),
            r.timed_passes.clone(),
            r.frame_passes.clone(),
            r.frame_kind.clone(),
            r.timed_frames.to_string(),
        ]);
    }
    csv.write(&dir.join("timing_agreement.csv"))?;
    Ok(agreement_checks(&b.scene, &b.adapter, &rows))
}

/// The two timing-agreement checks over the figures' rows (none with fewer than two).
fn agreement_checks(scene: &str, adapter: &str, rows: &[&crate::harness::BaseTiming]) -> Vec<Check> {
    if rows.len() < 2 {
        return Vec::new();
    }
    let same = |f: fn(&crate::harness::BaseTiming) -> String| rows.iter().all(|r| f(r) == f(rows[0]));
    let same_all = same(|r| r.timed_passes.clone())
        && same(|r| r.frame_passes.clone())
        && same(|r| r.frame_kind.clone())
        && same(|r| r.timed_frames.to_string());
    let figures: Vec<&str> = rows.iter().map(|r| r.figure.as_str()).collect();
    let lo = rows.iter().map(|r| r.sample_ms_min).fold(f64::INFINITY, f64::min);
    let hi = rows.iter().map(|r| r.sample_ms_min).fold(0.0, f64::max);
    vec![
        Check {
            scene: scene.to_string(),
            name: AGREEMENT_SAME.into(),
            value: if same_all { 1.0 } else { 0.0 },
            limit: 1.0,
            at_least: true,
            detail: format!(
                "{}: {} of {} timed frames, summing {}",
                figures.join(", "),
                rows[0].frame_kind,
                rows[0].timed_frames,
                rows[0].timed_passes
            ),
        },
        Check {
            scene: scene.to_string(),
            name: AGREEMENT_FASTEST.into(),
            value: hi / lo,
            limit: 1.15,
            at_least: false,
            detail: format!(
                "GPU timestamps of {} on {}; {}",
                rows[0].timed_passes,
                adapter,
                rows.iter()
                    .map(|r| format!("{} {:.3} ms", r.figure, r.sample_ms_min))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_deal_units_round_robin_and_parse() {
        assert_eq!(parse_shard("2/3"), Ok(Shard { k: 2, n: 3 }));
        for bad in ["0/3", "4/3", "1/0", "x/2", "3"] {
            assert!(parse_shard(bad).is_err(), "{bad}");
        }
        let shards: Vec<Shard> = (1..=3).map(|k| Shard { k, n: 3 }).collect();
        for unit in 0..20 {
            assert_eq!(shards.iter().filter(|s| s.owns(unit)).count(), 1, "unit {unit}");
        }
    }

    #[test]
    fn csv_cells_undo_the_writers_quoting() {
        assert_eq!(
            csv_cells(r#"a,"b, c","say ""hi""",4"#),
            ["a", "b, c", "say \"hi\"", "4"]
        );
        assert_eq!(csv_cells(""), [""]);
    }
}

//! `bench rays`: BVH shadow rays (and closest-hit rays) per second on the current adapter,
//! binary against wide BVH, with machine-independent counters (nodes, bytes, tests per ray).
//! `bench tree`: SST sort keys, bitonic sort, tree build and classify times (GPU timestamps)
//! for 2^12 .. 2^20 VPLs, with the log-log slope of time against N.
//! `bench gbuffer`: fragments and bytes per pixel with and without the depth pre-pass.
//! `bench lightcuts`: `bench_lightcuts.rs`.
//! `bench soak`: `bench_soak.rs`.

mod rays;
use rays::*;

use anyhow::anyhow;
use clap::{Args, ValueEnum};
use glam::Vec3;

use wgpu::util::DeviceExt;

use crate::{
    renderer::{
        FrameInput, FrameMode, Renderer,
        bvh_trace::{BvhTracer, TraceMode, to_gpu_ray},
        context::GpuContext,
        frame::GbufferTargets,
        gpu_data::{GpuCamera, GpuRay, GpuVpl},
        passes::{
            gbuffer::{COLOR_BYTES_PER_FRAGMENT, DEPTH_BYTES, GbufferPass, OverdrawCounter},
            lbvh::{LbvhPass, LeafSource, read_topology},
            sst_build::{BuildInputs, BuildPass, TreeBuffers, UsableThresholds},
            sst_sort::{SORT_TILE, SortBuffers, SortPass, SortVariant},
        },
        scene_gpu::{BvhLayout, SceneGpu, set_frame_bvh_layout, upload_bvh, upload_wide_bvh},
        settings::{RenderSettings, ViewBuffer},
        timing::GpuTimer,
    },
    scene::{
        Scene,
        bvh::{Bvh, Pcg32, Ray, TraceCounters, WideBvh, wide},
        preset::{SceneSource, open_scene},
    },
};

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum BenchKind {
    /// Shadow rays between random surface points (any-hit) and rays from surfaces in random
    /// directions (closest hit) through the scene BVH.
    Rays,
    /// SST stages 8-10 (keys, bitonic sort, tree build, usable flags) for VPL counts
    /// 2^min-log2 .. 2^max-log2: GPU time per stage and the log-log slope against N, for the
    /// baseline and the parallel keys / sort.
    Tree,
    /// The G-buffer raster: fragments per pixel (depth complexity, written without and with
    /// the depth pre-pass; machine-independent), bytes written per pixel, and GPU time of the
    /// single pass and of pre-pass + shading.
    Gbuffer,
    /// Lightcuts on a scene's frame: the light tree's far-paired nodes per level, and per
    /// relative error (--errors) the GPU time, cut size, shadow rays, max-cut pixels and the
    /// share of refinements on far-paired nodes (docs/lightcuts.md).
    Lightcuts,
    /// A long run (`--minutes`) that moves the camera and switches methods, printing frames
    /// per second, resident and GPU memory and live GPU objects, with a verdict on growth
    /// (`bench_soak.rs`).
    Soak,
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    #[arg(value_enum, default_value = "rays")]
    pub kind: BenchKind,
    /// `default` or another built-in scene (`window-box`, `corridor`, `glossy-thin`), a
    /// .gltf/.glb file, or a preset .toml (e.g. scenes/sponza.toml).
    #[arg(long, default_value = "default")]
    pub scene: String,
    /// Rays per dispatch (at most 4194240, the default: enough to fill a large GPU).
    #[arg(long, default_value_t = MAX_RAYS)]
    pub rays: u32,
    /// `bench rays`: rays of each batch traced on the CPU with counters (nodes, bytes, box
    /// and triangle tests per ray, binary against wide BVH).
    #[arg(long, default_value_t = 262144)]
    pub proxy_rays: u32,
    /// `bench rays`: about this many pixels (every k-th of --width x --height) draw SLC's
    /// shadow rays on the CPU for the in-frame counters.
    #[arg(long, default_value_t = 16384)]
    pub proxy_pixels: u32,
    /// `bench gbuffer` / the in-frame ray rate of `bench rays`: frame width.
    #[arg(long, default_value_t = 1280)]
    pub width: u32,
    /// `bench gbuffer` / the in-frame ray rate of `bench rays`: frame height.
    #[arg(long, default_value_t = 720)]
    pub height: u32,
    /// Timed repetitions (the median is reported).
    #[arg(long, default_value_t = 5)]
    pub repeat: u32,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// `bench tree`: smallest VPL count, as a power of two.
    #[arg(long, default_value_t = 12)]
    pub min_log2: u32,
    /// `bench tree`: largest VPL count, as a power of two (at most 20).
    #[arg(long, default_value_t = 20)]
    pub max_log2: u32,
    /// `bench lightcuts`: relative errors.
    #[arg(long, value_delimiter = ',', default_value = "0.2,0.1,0.05,0.02,0.01")]
    pub errors: Vec<f32>,
    /// `bench lightcuts`: the max cut size.
    #[arg(long, default_value_t = 1024)]
    pub max_cut: u32,
    /// `bench lightcuts`: VPLs (default: the settings' 4096).
    #[arg(long)]
    pub vpls: Option<u32>,
    /// `bench lightcuts`: pixels the CPU reference refines (a regular subset).
    #[arg(long, default_value_t = 400)]
    pub cpu_pixels: u32,
    /// `bench soak`: how long to run, minutes.
    #[arg(long, default_value_t = 1.0)]
    pub minutes: f64,
    /// `bench soak`: the methods it cycles through (`all`: every per-frame method).
    #[arg(long, default_value = "slc,lightcuts,light-culling,val")]
    pub methods: String,
    /// `bench soak`: seconds each method renders before the next.
    #[arg(long, default_value_t = 10.0)]
    pub switch_seconds: f64,
    /// `bench soak`: seconds between printed samples.
    #[arg(long, default_value_t = 1.0)]
    pub sample_seconds: f64,
    /// `bench soak`: folder for soak.csv and the plots.
    #[arg(long, default_value = "soak")]
    pub out: std::path::PathBuf,
    /// `bench soak`: exit non-zero when live objects or resident memory grew.
    #[arg(long)]
    pub check: bool,
}

/// Area-weighted random points on the scene's triangles, with their geometric normals.
pub fn surface_points(scene: &Scene, n: usize, seed: u64) -> Vec<(Vec3, Vec3)> {
    let mut cdf = Vec::with_capacity(scene.triangle_count());
    let mut total = 0.0f64;
    for t in 0..scene.triangle_count() {
        let [a, b, c] = scene.triangle(t);
        total += 0.5 * (b - a).cross(c - a).length() as f64;
        cdf.push(total);
    }
    let mut rng = Pcg32::new(seed);
    (0..n)
        .map(|_| {
            let x = rng.next_f32() as f64 * total;
            let t = cdf.partition_point(|&c| c < x).min(cdf.len() - 1);
            let [a, b, c] = scene.triangle(t);
            let (mut u, mut v) = (rng.next_f32(), rng.next_f32());
            if u + v > 1.0 {
                u = 1.0 - u;
                v = 1.0 - v;
            }
            let p = a + u * (b - a) + v * (c - a);
            let nrm = (b - a).cross(c - a).normalize_or(Vec3::Y);
            (p, nrm)
        })
        .collect()
}

/// Shadow rays between random pairs of surface points (offset along their normals, towards
/// each other), as the GI passes will cast them.
pub fn shadow_rays(scene: &Scene, n: usize, seed: u64) -> Vec<Ray> {
    let eps = 1e-4 * scene.bounds.radius().max(1e-3);
    let a = surface_points(scene, n, seed);
    let b = surface_points(scene, n, seed ^ 0xABCD_EF01);
    a.iter()
        .zip(&b)
        .map(|(&(p, np), &(q, nq))| {
            let d = q - p;
            let o = p + np * eps * np.dot(d).signum();
            let t = q + nq * eps * nq.dot(-d).signum();
            Ray {
                origin: o,
                dir: t - o,
                tmin: 1e-4,
                tmax: 1.0 - 1e-4,
            }
        })
        .collect()
}

/// Rays from random surface points in random directions (closest hit).
pub fn probe_rays(scene: &Scene, n: usize, seed: u64) -> Vec<Ray> {
    let eps = 1e-4 * scene.bounds.radius().max(1e-3);
    let mut rng = Pcg32::new(seed ^ 0x5555_5555);
    surface_points(scene, n, seed ^ 0x1234)
        .into_iter()
        .map(|(p, nrm)| {
            let z = 2.0 * rng.next_f32() - 1.0;
            let phi = std::f32::consts::TAU * rng.next_f32();
            let r = (1.0 - z * z).max(0.0).sqrt();
            let mut d = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            if d.dot(nrm) < 0.0 {
                d = -d;
            }
            Ray {
                origin: p + nrm * eps,
                dir: d,
                tmin: 0.0,
                tmax: 3.0e38,
            }
        })
        .collect()
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    Some(v[v.len() / 2])
}

/// Records `record` into a fresh encoder `repeat + 1` times back to back, each submitted and
/// its timestamps waited for; returns the timings of all but the first (pipeline warm-up).
fn time_back_to_back(
    ctx: &GpuContext,
    timer: &mut GpuTimer,
    repeat: u32,
    mut record: impl FnMut(&mut wgpu::CommandEncoder, &mut GpuTimer),
) -> anyhow::Result<Vec<crate::gpu::timing::PassTimings>> {
    let mut out = Vec::new();
    for rep in 0..=repeat {
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        timer.begin_frame(true);
        record(&mut enc, timer);
        timer.resolve(&mut enc);
        ctx.queue.submit([enc.finish()]);
        timer.after_submit();
        let t = timer
            .collect_new_blocking(&ctx.device)
            .ok_or_else(|| anyhow!("no timestamps came back"))?;
        if rep > 0 {
            out.push(t);
        }
    }
    Ok(out)
}

/// The most rays of one `bench rays` dispatch (65535 workgroups of 64).
pub const MAX_RAYS: u32 = 65535 * 64;

pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    if !(1..=8192).contains(&args.width) || !(1..=8192).contains(&args.height) {
        return Err(anyhow!(
            "--width {} / --height {}: each must be 1..=8192",
            args.width,
            args.height
        ));
    }
    match args.kind {
        BenchKind::Rays => run_rays(args),
        BenchKind::Tree => run_tree(args),
        BenchKind::Gbuffer => run_gbuffer(args),
        BenchKind::Lightcuts => super::bench_lightcuts::run(args),
        BenchKind::Soak => super::bench_soak::run(args),
    }
}

fn run_gbuffer(args: &BenchArgs) -> anyhow::Result<()> {
    let opened = open_scene(&SceneSource::from_arg(&args.scene)).map_err(|e| anyhow!("{e}"))?;
    let scene = &opened.scene;
    let camera = scene
        .camera_or_default(opened.camera_name.as_deref())
        .map_err(|e| anyhow!("{e}"))?;
    let size = (args.width, args.height);
    let ctx = GpuContext::new_headless()?;
    println!("adapter: {}", ctx.describe());
    let device = &ctx.device;
    let tex = crate::settings::RenderSettings::default().textures;
    let gpu_scene = SceneGpu::new(device, &ctx.queue, scene, tex.max_size, tex.anisotropy);
    let camera_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("bench::camera"),
        contents: bytemuck::bytes_of(&GpuCamera::new(&camera, size.0, size.1)),
        usage: crate::gpu::passes::PARAMS_USAGE,
    });
    println!(
        "scene: {} ({} triangles, one draw in file order), camera '{}', {}x{}",
        scene.name,
        scene.triangle_count(),
        camera.name,
        size.0,
        size.1
    );
    let c = OverdrawCounter::new(device)?.count(&ctx, &camera_buf, &gpu_scene, size)?;
    let per = |n: u64| n as f64 / c.covered.max(1) as f64;
    println!(
        "fragments (machine-independent: rasterisation rules and draw order), per covered pixel; {} of {} pixels covered",
        c.covered, c.pixels
    );
    println!(
        "  depth complexity (every rasterised fragment):        {:>10} ({:.2} per covered pixel)",
        c.rasterised,
        per(c.rasterised)
    );
    println!(
        "  written without pre-pass (depth Less, draw order):   {:>10} ({:.2})",
        c.written_single_pass,
        per(c.written_single_pass)
    );
    println!(
        "  written after the depth pre-pass (depth Equal):      {:>10} ({:.2})",
        c.written_after_prepass,
        per(c.written_after_prepass)
    );
    println!(
        "G-buffer bytes written per frame pixel ({COLOR_BYTES_PER_FRAGMENT} B of colour targets per shaded fragment, {DEPTH_BYTES} B per depth write): \
         without pre-pass {:.1}, with {:.1}",
        c.bytes_per_pixel_single_pass(),
        c.bytes_per_pixel_prepass()
    );
    let mut pass = GbufferPass::new(device)?;
    let targets = GbufferTargets::new(device, size);
    let mut timer = GpuTimer::new(device, &ctx.queue);
    if !timer.supported() {
        println!("GPU time: timestamps not supported on this adapter");
        return Ok(());
    }
    let mut ms = [f64::NAN; 2];
    for (i, prepass) in [false, true].into_iter().enumerate() {
        pass.prepass = prepass;
        // Back to back; the first repetition (pipelines) is dropped.
        let samples = time_back_to_back(&ctx, &mut timer, args.repeat, |enc, timer| {
            pass.record(device, enc, timer, &camera_buf, &gpu_scene, &targets)
        })?
        .iter()
        .map(|t| t.get("gbuffer_depth").unwrap_or(0.0) + t.get("gbuffer").unwrap_or(0.0))
        .collect();
        ms[i] = median(samples).unwrap_or(f64::NAN);
    }
    println!(
        "GPU time (median of {}): single pass {:.3} ms, depth pre-pass + shading {:.3} ms ({:.2}x)",
        args.repeat,
        ms[0],
        ms[1],
        ms[0] / ms[1]
    );
    if let Some(e) = ctx.errors.take().into_iter().next() {
        return Err(anyhow!("GPU error: {e}"));
    }
    Ok(())
}

/// Least-squares slope of ln(y) against ln(x).
pub fn log_log_slope(points: &[(f64, f64)]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = pts.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = pts.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// VPLs on the scene's surfaces (area-weighted), with random RGB flux.
pub fn surface_vpls(scene: &Scene, n: usize, seed: u64) -> Vec<GpuVpl> {
    let mut rng = Pcg32::new(seed ^ 0x7777);
    surface_points(scene, n, seed)
        .into_iter()
        .enumerate()
        .map(|(i, (p, nrm))| GpuVpl {
            position: p.extend(1.0).to_array(),
            normal: nrm.to_array(),
            id: i as u32,
            flux: [rng.next_f32(), rng.next_f32(), rng.next_f32(), 1.0],
        })
        .collect()
}

const TREE_STAGES: [&str; 4] = ["sst_keys", "sst_sort", "sst_build", "sst_classify"];

fn run_tree(args: &BenchArgs) -> anyhow::Result<()> {
    if args.min_log2 > args.max_log2 || args.max_log2 > 20 || args.min_log2 < 1 {
        return Err(anyhow!(
            "--min-log2 {} / --max-log2 {}: need 1 <= min <= max <= 20",
            args.min_log2,
            args.max_log2
        ));
    }
    let opened = open_scene(&SceneSource::from_arg(&args.scene)).map_err(|e| anyhow!("{e}"))?;
    let scene = &opened.scene;
    if scene.triangle_count() == 0 {
        return Err(anyhow!("scene {} has no triangles to put VPLs on", scene.name));
    }
    let ctx = GpuContext::new_headless()?;
    println!("adapter: {}", ctx.describe());
    println!(
        "scene: {} (VPLs area-weighted on its surfaces); median of {} timed repetitions",
        scene.name, args.repeat
    );
    let device = &ctx.device;
    let mut sort = SortPass::new(device)?;
    let build = BuildPass::new(device)?;
    let lbvh = LbvhPass::new(device)?;
    let limit = device.limits().max_storage_buffer_binding_size;
    let mut timer = GpuTimer::new(device, &ctx.queue);
    if !timer.supported() {
        return Err(anyhow!(
            "this adapter has no timestamp queries: nothing to measure"
        ));
    }
    println!(
        "variants: baseline = bounds by one 64-thread workgroup + one global dispatch per bitonic step \
         (before issue 18); parallel = bounds as a reduction + bitonic steps below {SORT_TILE} in workgroup memory (in use)"
    );
    println!(
        "{:>9} {:>9} {:>11} {:>11} {:>11} {:>11} {:>11} {:>12}",
        "VPLs", "variant", "keys ms", "sort ms", "build ms", "classify ms", "total ms", "build Mnode/s"
    );
    let variants = [
        (SortVariant::Baseline, "baseline"),
        (SortVariant::Parallel, "parallel"),
    ];
    let mut rows: Vec<(f64, [[f64; 4]; 2])> = Vec::new();
    for log2 in args.min_log2..=args.max_log2 {
        let n = 1u32 << log2;
        let need = TreeBuffers::largest_binding(n);
        if need > limit {
            println!(
                "{n:>9} skipped: the tree needs a {} MiB binding, this device allows {} MiB",
                need >> 20,
                limit >> 20
            );
            continue;
        }
        let vpls = surface_vpls(scene, n as usize, args.seed);
        let buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("bench::vpls"),
            contents: bytemuck::cast_slice(&vpls),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let sb = SortBuffers::new(device, n);
        let tb = TreeBuffers::new(device, n, crate::base::sst_node::TreeKind::Perfect);
        let mut both = [[f64::NAN; 4]; 2];
        for (vi, (variant, name)) in variants.iter().enumerate() {
            sort.variant = *variant;
            // The first repetition includes pipeline warm-up: dropped. Repetitions run back
            // to back (no CPU work between them but the timestamp readback).
            let d = crate::settings::TreeSettings::default();
            let inputs = BuildInputs {
                vpls: &buf,
                sort: &sb,
                tree: &tb,
                usable: UsableThresholds {
                    v_min: d.v_min,
                    sigma_max: d.sigma_max,
                },
            };
            let timed = time_back_to_back(&ctx, &mut timer, args.repeat, |enc, timer| {
                sort.record(device, &ctx.queue, enc, timer, &buf, &sb);
                build.record(device, &ctx.queue, enc, timer, &inputs);
            })?;
            let samples: [Vec<f64>; 4] = std::array::from_fn(|k| {
                timed
                    .iter()
                    .map(|t| t.get(TREE_STAGES[k]).unwrap_or(f64::NAN))
                    .collect()
            });
            let m = samples.map(|v| median(v).unwrap_or(f64::NAN));
            println!(
                "{n:>9} {name:>9} {:>11.3} {:>11.3} {:>11.3} {:>11.3} {:>11.3} {:>12.2}",
                m[0],
                m[1],
                m[2],
                m[3],
                m.iter().sum::<f64>(),
                (2 * tb.leaves - 1) as f64 / (m[2] * 1e-3) / 1e6
            );
            both[vi] = m;
        }
        println!(
            "{n:>9} {:>9} keys {:.2}x, sort {:.2}x, total {:.2}x faster than the baseline",
            "speed-up",
            both[0][0] / both[1][0],
            both[0][1] / both[1][1],
            both[0].iter().sum::<f64>() / both[1].iter().sum::<f64>()
        );
        radix_tree(
            &ctx,
            &mut timer,
            (&mut sort, &lbvh),
            (&buf, &sb),
            (n, args.repeat),
            both[1][2],
        )?;
        rows.push((n as f64, both));
    }
    print_slopes(&rows, &variants);
    if let Some(e) = ctx.errors.take().into_iter().next() {
        return Err(anyhow!("GPU error: {e}"));
    }
    Ok(())
}

/// The radix tree over the same sorted keys (Karras 2012; issue 23): its topology, checked
/// against its CPU twin, and its node data bottom-up, timed against the perfect tree's build
/// (whose topology is implicit). `size`: the VPL count and the timed repetitions.
fn radix_tree(
    ctx: &GpuContext,
    timer: &mut GpuTimer,
    passes: (&mut SortPass, &LbvhPass),
    inputs: (&wgpu::Buffer, &SortBuffers),
    size: (u32, u32),
    perfect_build_ms: f64,
) -> anyhow::Result<()> {
    let (sort, lbvh) = passes;
    let (buf, sb) = inputs;
    let (n, repeat) = size;
    let device = &ctx.device;
    sort.variant = SortVariant::Parallel;
    let lb = TreeBuffers::new(device, n, crate::base::sst_node::TreeKind::Lbvh);
    let timed = time_back_to_back(ctx, timer, repeat, |enc, timer| {
        sort.record(device, &ctx.queue, enc, timer, buf, sb);
        lbvh.record(device, &ctx.queue, enc, timer, sb, &lb);
        let leaves = LeafSource { keys: sb, vpls: buf };
        lbvh.record_node_data(device, &ctx.queue, enc, timer, leaves, &lb);
    })?;
    let med = |name: &str| {
        median(timed.iter().map(|t| t.get(name).unwrap_or(f64::NAN)).collect()).unwrap_or(f64::NAN)
    };
    let (ms, nodes_ms) = (med("lbvh_build"), med("lbvh_nodes"));
    let keys: Vec<[u32; 4]> =
        bytemuck::pod_collect_to_vec(&crate::gpu::readback::read_storage_buffer(ctx, &sb.keys)?);
    let keys: Vec<u64> = keys[..n as usize]
        .iter()
        .map(|k| (k[0] as u64) << 32 | k[1] as u64)
        .collect();
    let same = read_topology(ctx, &lb)? == crate::reference::lbvh::build(&keys);
    println!(
        "{n:>9} {:>9} topology {ms:.3} ms + node data {nodes_ms:.3} ms = {:.3} ms (the perfect tree's build {:.3} ms); topology equals the CPU reference: {}",
        "radix",
        ms + nodes_ms,
        perfect_build_ms,
        if same { "yes" } else { "NO" }
    );
    if !same {
        return Err(anyhow!(
            "the radix tree of {n} keys differs from its CPU reference"
        ));
    }
    Ok(())
}

/// Per variant, the log-log slope of each stage's time over N.
fn print_slopes(rows: &[(f64, [[f64; 4]; 2])], variants: &[(SortVariant, &str); 2]) {
    for (vi, (_, name)) in variants.iter().enumerate() {
        let slope = |k: usize| {
            log_log_slope(&rows.iter().map(|(n, m)| (*n, m[vi][k])).collect::<Vec<_>>())
                .map_or("n/a".to_string(), |s| format!("{s:.2}"))
        };
        let total = log_log_slope(
            &rows
                .iter()
                .map(|(n, m)| (*n, m[vi].iter().sum()))
                .collect::<Vec<_>>(),
        )
        .map_or("n/a".to_string(), |s| format!("{s:.2}"));
        println!(
            "{name}: log-log slope of time vs N: keys {}, sort {}, build {}, classify {}, total {} \
             (1 = linear; a bitonic sort is N log^2 N of work)",
            slope(0),
            slope(1),
            slope(2),
            slope(3),
            total
        );
    }
}

#[cfg(test)]
mod tests {
    use super::log_log_slope;

    #[test]
    fn slope_of_power_laws() {
        let lin: Vec<(f64, f64)> = (1..6).map(|i| (i as f64, 3.0 * i as f64)).collect();
        assert!((log_log_slope(&lin).unwrap() - 1.0).abs() < 1e-12);
        let quad: Vec<(f64, f64)> = (1..6).map(|i| (i as f64, 0.5 * (i * i) as f64)).collect();
        assert!((log_log_slope(&quad).unwrap() - 2.0).abs() < 1e-12);
        assert!(log_log_slope(&[(1.0, 1.0)]).is_none());
    }
}

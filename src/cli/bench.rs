//! `bench rays`: BVH shadow rays (and closest-hit rays) per second on the current adapter.
//! `bench tree`: SST sort keys, bitonic sort, tree build and classify times (GPU timestamps)
//! for 2^12 .. 2^20 VPLs, with the log-log slope of time against N.

use anyhow::anyhow;
use clap::{Args, ValueEnum};
use glam::Vec3;

use wgpu::util::DeviceExt;

use crate::{
    renderer::{
        bvh_trace::{BvhTracer, TraceMode, to_gpu_ray},
        context::GpuContext,
        gpu_data::{GpuRay, GpuVpl},
        passes::{
            sst_build::{BuildPass, TreeBuffers},
            sst_sort::{SortBuffers, SortPass},
        },
        scene_gpu::upload_bvh,
        timing::GpuTimer,
    },
    scene::{
        Scene,
        bvh::{Bvh, Pcg32, Ray},
        preset::{SceneSource, open_scene},
    },
};

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum BenchKind {
    /// Shadow rays between random surface points (any-hit) and rays from surfaces in random
    /// directions (closest hit) through the scene BVH.
    Rays,
    /// SST stages 8-10 (keys, bitonic sort, tree build, usable flags) for VPL counts
    /// 2^min-log2 .. 2^max-log2: GPU time per stage and the log-log slope against N.
    Tree,
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    #[arg(value_enum, default_value = "rays")]
    pub kind: BenchKind,
    /// `default`, a .gltf/.glb file, or a preset .toml (e.g. scenes/sponza.toml).
    #[arg(long, default_value = "default")]
    pub scene: String,
    /// Rays per dispatch (at most 4194240).
    #[arg(long, default_value_t = 1 << 18)]
    pub rays: u32,
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

pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    match args.kind {
        BenchKind::Rays => run_rays(args),
        BenchKind::Tree => run_tree(args),
    }
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
    let sort = SortPass::new(device)?;
    let build = BuildPass::new(device)?;
    let limit = device.limits().max_storage_buffer_binding_size;
    let mut timer = GpuTimer::new(device, &ctx.queue);
    if !timer.supported() {
        return Err(anyhow!(
            "this adapter has no timestamp queries: nothing to measure"
        ));
    }
    println!(
        "{:>9} {:>11} {:>11} {:>11} {:>11} {:>11} {:>12}",
        "VPLs", "keys ms", "sort ms", "build ms", "classify ms", "total ms", "build Mnode/s"
    );
    let mut rows: Vec<(f64, [f64; 4])> = Vec::new();
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
        let tb = TreeBuffers::new(device, n);
        let mut samples: [Vec<f64>; 4] = Default::default();
        // The first repetition includes pipeline warm-up: dropped.
        for rep in 0..=args.repeat {
            let mut enc = device.create_command_encoder(&Default::default());
            timer.begin_frame();
            sort.record(device, &ctx.queue, &mut enc, &mut timer, &buf, &sb);
            let d = crate::renderer::settings::TreeSettings::default();
            build.record(
                device,
                &ctx.queue,
                &mut enc,
                &mut timer,
                &buf,
                &sb,
                &tb,
                d.v_min,
                d.sigma_max,
            );
            timer.resolve(&mut enc);
            ctx.queue.submit([enc.finish()]);
            timer.after_submit();
            let t = timer
                .collect_blocking(device)
                .cloned()
                .ok_or_else(|| anyhow!("no timestamps came back"))?;
            if rep > 0 {
                for (k, stage) in TREE_STAGES.iter().enumerate() {
                    samples[k].push(t.get(stage).unwrap_or(f64::NAN));
                }
            }
        }
        let m = samples.map(|v| median(v).unwrap_or(f64::NAN));
        println!(
            "{n:>9} {:>11.3} {:>11.3} {:>11.3} {:>11.3} {:>11.3} {:>12.2}",
            m[0],
            m[1],
            m[2],
            m[3],
            m.iter().sum::<f64>(),
            (2 * tb.leaves - 1) as f64 / (m[2] * 1e-3) / 1e6
        );
        rows.push((n as f64, m));
    }
    let slope = |k: usize| {
        log_log_slope(&rows.iter().map(|(n, m)| (*n, m[k])).collect::<Vec<_>>())
            .map_or("n/a".to_string(), |s| format!("{s:.2}"))
    };
    let total = log_log_slope(&rows.iter().map(|(n, m)| (*n, m.iter().sum())).collect::<Vec<_>>())
        .map_or("n/a".to_string(), |s| format!("{s:.2}"));
    println!(
        "log-log slope of time vs N: keys {}, sort {}, build {}, classify {}, total {} \
         (1 = linear; a bitonic sort is N log^2 N of work)",
        slope(0),
        slope(1),
        slope(2),
        slope(3),
        total
    );
    if let Some(e) = ctx.errors.take().into_iter().next() {
        return Err(anyhow!("GPU error: {e}"));
    }
    Ok(())
}

fn run_rays(args: &BenchArgs) -> anyhow::Result<()> {
    let opened = open_scene(&SceneSource::from_arg(&args.scene)).map_err(|e| anyhow!("{e}"))?;
    let scene = &opened.scene;
    let n = args.rays.clamp(1, 65535 * 64) as usize;
    let ctx = GpuContext::new_headless()?;
    println!("adapter: {}", ctx.describe());
    let t0 = std::time::Instant::now();
    let bvh = Bvh::build(&scene.positions, &scene.indices);
    let build_ms = t0.elapsed().as_secs_f64() * 1e3;
    println!(
        "scene: {} ({} triangles); BVH: {} nodes, depth {}, built in {:.1} ms on the CPU",
        scene.name,
        scene.triangle_count(),
        bvh.nodes.len(),
        bvh.stats.depth,
        build_ms
    );
    let (nodes, tris) = upload_bvh(&ctx.device, &bvh);
    let tracer = BvhTracer::new(&ctx.device)?;
    for (label, rays, mode) in [
        (
            "shadow rays (any hit)",
            shadow_rays(scene, n, args.seed),
            TraceMode::AnyHit,
        ),
        (
            "random rays (closest hit)",
            probe_rays(scene, n, args.seed),
            TraceMode::ClosestHit,
        ),
    ] {
        let gpu: Vec<GpuRay> = rays.iter().map(to_gpu_ray).collect();
        let (hits, times) = tracer.trace(&ctx, &nodes, &tris, &gpu, mode, args.repeat + 1)?;
        let frac = match mode {
            TraceMode::AnyHit => hits.iter().filter(|h| h.triangle == 1).count(),
            TraceMode::ClosestHit => hits.iter().filter(|h| h.triangle != u32::MAX).count(),
        } as f64
            / n as f64;
        // The first repetition includes pipeline warm-up: drop it.
        match median(times.into_iter().skip(1).collect()) {
            Some(ms) => println!(
                "{label:<26} {n} rays: {ms:>9.3} ms (median of {}), {:>8.2} Mrays/s, {:.1}% hit",
                args.repeat,
                n as f64 / (ms * 1e-3) / 1e6,
                100.0 * frac
            ),
            None => println!(
                "{label:<26} {n} rays: timestamps not supported on this adapter, {:.1}% hit",
                100.0 * frac
            ),
        }
    }
    if let Some(e) = ctx.errors.take().into_iter().next() {
        return Err(anyhow!("GPU error: {e}"));
    }
    Ok(())
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

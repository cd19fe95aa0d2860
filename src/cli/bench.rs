//! `bench rays`: BVH shadow rays (and closest-hit rays) per second on the current adapter.

use anyhow::anyhow;
use clap::{Args, ValueEnum};
use glam::Vec3;

use crate::{
    renderer::{
        bvh_trace::{BvhTracer, TraceMode, to_gpu_ray},
        context::GpuContext,
        gpu_data::GpuRay,
        scene_gpu::upload_bvh,
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
    let BenchKind::Rays = args.kind;
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

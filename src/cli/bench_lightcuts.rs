//! `bench lightcuts`: what the light tree's pairing costs Lightcuts on a scene's frame. The
//! tree is a perfect binary tree over the VPLs in Morton order, so a node's two children are
//! adjacent Morton ranges, which can lie far apart (a jump of the curve). Per level: how many
//! nodes pair children whose boxes are disjoint, and "far" (the gap between them more than
//! half the node's diagonal: its box is mostly empty space), and the mean node diagonal. Per relative error: the GPU
//! time of the Lightcuts passes (timed frames), the cut size, shadow rays and max-cut pixels
//! (a diagnostic frame's counters), and, from the CPU reference on a pixel subset, the share of
//! the refinements spent on far-paired nodes against their share of the tree's nodes.

use anyhow::anyhow;
use glam::Vec3;

use super::bench::BenchArgs;
use crate::{
    base::sst_node::SstNode,
    methods::lightcuts::{self, Lightcuts, settings::LightcutsSettings},
    reference::lightcuts::{CutParams, lightcut},
    renderer::{
        Buffer, FrameInput, FrameMode, Renderer,
        context::GpuContext,
        readback::read_storage_buffer,
        settings::{RenderSettings, ViewBuffer},
    },
    scene::{
        bvh::Bvh,
        preset::{SceneSource, open_scene},
    },
};

/// The gap between two boxes (0 when they overlap).
fn box_gap(a: &SstNode, b: &SstNode) -> f32 {
    let d = (a.bbox_min - b.bbox_max)
        .max(b.bbox_min - a.bbox_max)
        .max(Vec3::ZERO);
    d.length()
}

fn diagonal(n: &SstNode) -> f32 {
    (n.bbox_max - n.bbox_min).length()
}

/// Whether inner node `i` pairs two non-empty clusters (inner nodes, not single VPLs) whose
/// gap is more than half the node's diagonal (its box is mostly the empty space between
/// them). Two distinct VPLs are always that far apart, so the last inner level is left out.
pub fn far_paired(nodes: &[SstNode], i: usize) -> bool {
    let (a, b) = (&nodes[2 * i], &nodes[2 * i + 1]);
    4 * i < nodes.len() && !a.is_empty() && !b.is_empty() && box_gap(a, b) > 0.5 * diagonal(&nodes[i])
}

/// The same VPLs in a binary radix tree (Karras 2012, the SST paper's construction; CPU
/// reference `reference::lbvh`) over the same 64-bit keys: its far-paired clusters (the same
/// test as the perfect tree's) and its leaf depths.
fn radix_tree_pairing(vpls: &[crate::base::gpu_layout::GpuVpl], perfect_leaves: usize) {
    use crate::reference::lbvh::{self, Child};
    let (keys, sorted) = lbvh::sorted_keys(vpls);
    if keys.len() < 2 {
        return;
    }
    let tree = lbvh::build(&keys);
    let leaves: Vec<SstNode> = sorted.iter().map(SstNode::leaf).collect();
    let data = lbvh::node_data(&tree, &leaves);
    let (mut clusters, mut far) = (0usize, 0usize);
    for (i, n) in tree.iter().enumerate() {
        if let (Child::Internal(a), Child::Internal(b)) = (n.left, n.right) {
            let (a, b) = (&data[a as usize], &data[b as usize]);
            if a.is_empty() || b.is_empty() {
                continue;
            }
            clusters += 1;
            far += (box_gap(a, b) > 0.5 * diagonal(&data[i])) as usize;
        }
    }
    let depths = lbvh::leaf_depths(&tree);
    let mean = depths.iter().map(|&d| d as f64).sum::<f64>() / depths.len() as f64;
    println!(
        "radix tree (Karras 2012, CPU reference) over the same keys: far-paired nodes over clusters: {far} of {clusters} ({:.1}%); leaf depth mean {mean:.1}, max {} (perfect tree: {})",
        100.0 * far as f64 / clusters.max(1) as f64,
        depths.iter().max().copied().unwrap_or(0),
        perfect_leaves.trailing_zeros()
    );
}

pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    let opened = open_scene(&SceneSource::from_arg(&args.scene)).map_err(|e| anyhow!("{e}"))?;
    let scene = &opened.scene;
    let camera = scene
        .camera_or_default(opened.camera_name.as_deref())
        .map_err(|e| anyhow!("{e}"))?;
    let size = (args.width, args.height);
    if args.errors.is_empty() || args.errors.iter().any(|e| !(0.0..=1.0).contains(e)) {
        return Err(anyhow!("--errors: relative errors must be 0..=1"));
    }
    let ctx = GpuContext::new_headless()?;
    println!("adapter: {}", ctx.describe());
    let mut s = RenderSettings::default();
    s.display.exposure_ev = opened.exposure_ev;
    s.gi.method = lightcuts::ID;
    s.frame.accumulate = false;
    s.frame.fixed_seed = true;
    if let Some(n) = args.vpls {
        s.vpl.count = n;
    }
    let lc = |e: f32| LightcutsSettings {
        relative_error: e,
        max_cut: args.max_cut,
    };
    s.set_method(lightcuts::ID, &lc(args.errors[0]))
        .map_err(|e| anyhow!("{e}"))?;
    s.validate().map_err(|e| anyhow!("{e}"))?;
    let mut r = Renderer::new(ctx, scene, size, s.clone())?;
    let lights = scene.lights.clone();
    let input = FrameInput {
        camera: &camera,
        lights: &lights,
        view: ViewBuffer::Final,
    };
    r.render(&input);
    r.wait_idle();
    r.set_freeze_tree(true);
    let (nodes, _) = r.read_tree()?;
    let leaves = nodes.len() / 2;
    println!(
        "scene: {}, camera '{}', {}x{}, {} VPLs ({} leaves); max cut {}",
        scene.name,
        camera.name,
        size.0,
        size.1,
        r.vpl_frame().count,
        leaves,
        args.max_cut
    );
    let far_share = print_tree_pairing(&nodes, leaves);
    radix_tree_pairing(&r.read_vpls()?, leaves);
    // The frame's G-buffer and sorted VPLs for the CPU reference.
    let bvh = Bvh::build(&scene.positions, &scene.indices);
    let pos = r.read(Buffer::Position)?;
    let nrm = r.read(Buffer::Normal)?;
    let (_, tree) = r.tree_buffers();
    let sorted: Vec<crate::base::gpu_layout::GpuVpl> =
        bytemuck::pod_collect_to_vec(&read_storage_buffer(&r.ctx, &tree.sorted_vpls)?);
    let pixels: Vec<usize> = {
        let all = (size.0 * size.1) as usize;
        let step = (all / args.cpu_pixels.max(1) as usize).max(1);
        (0..all)
            .step_by(step)
            .filter(|&k| pos.pixels[k][3] > 0.0)
            .collect()
    };
    println!(
        "per relative error: GPU time of lightcuts_build + lightcuts (median of {} timed frames), a diagnostic frame's counters, and the CPU reference's refinements on {} pixels",
        args.repeat,
        pixels.len()
    );
    println!("  rel. error  GPU ms  mean cut  rays/pixel  at max cut  refinements on far-paired nodes");
    for &e in &args.errors {
        let mut si = s.clone();
        si.set_method(lightcuts::ID, &lc(e)).map_err(|e| anyhow!("{e}"))?;
        r.set_settings(si.clone())?;
        let gpu_ms = median_gpu_ms(&mut r, &input, args.repeat);
        r.set_frame_mode(FrameMode::Diagnostic);
        r.render(&input);
        r.wait_idle();
        let stats = r.method_stats_blocking();
        let get = |k: &str| stats.iter().find(|(n, _)| *n == k).map_or(f64::NAN, |(_, v)| *v);
        let build = r
            .method_module::<Lightcuts>()
            .ok_or_else(|| anyhow!("lightcuts is not registered"))?
            .read_build(&r.ctx)?;
        let p = CutParams {
            relative_error: e,
            max_cut: args.max_cut,
            eps: si.gi.distance_epsilon,
            shadow_rays: si.gi.shadow_rays.then_some(si.gi.ray_offset),
            trace_every_node: false,
        };
        let cpu = CpuCuts::of(&pixels, (&pos, &nrm), (&nodes, &build, &sorted), &bvh, &p);
        let (refined, refined_far, cpu_cut, cpu_max) = (cpu.refined, cpu.refined_far, cpu.cut, cpu.at_max);
        let np = pixels.len().max(1) as f64;
        println!(
            "  {e:>10}  {gpu_ms:>6.2}  {:>8.1}  {:>10.1}  {:>9.2}%  {:>6.1}% (of {refined} refinements of clusters; of the tree's nodes over clusters: {:.1}%); CPU subset: mean cut {:.1}, {:.2}% at max cut",
            get("mean_cut_size"),
            get("shadow_rays_per_pixel"),
            100.0 * get("max_cut_pixel_fraction"),
            100.0 * refined_far as f64 / refined.max(1) as f64,
            100.0 * far_share,
            cpu_cut as f64 / np,
            100.0 * cpu_max as f64 / np
        );
    }
    if let Some(e) = r.ctx.errors.take().into_iter().next() {
        return Err(anyhow!("GPU error: {e}"));
    }
    Ok(())
}

/// Prints the tree's pairing per level (inner nodes with two non-empty children: mean
/// diagonal, disjoint children, far-paired ones); returns the far-paired share over clusters.
fn print_tree_pairing(nodes: &[SstNode], leaves: usize) -> f64 {
    println!("the tree's pairing per level (inner nodes with two non-empty children):");
    println!(
        "  level  nodes  mean diagonal (m)  disjoint children  far-paired (gap > half the node's diagonal)"
    );
    let mut far_total = (0usize, 0usize);
    let mut level_start = 1usize;
    while level_start < leaves {
        let range = level_start..2 * level_start;
        let pairs: Vec<usize> = range
            .filter(|&i| !nodes[2 * i].is_empty() && !nodes[2 * i + 1].is_empty())
            .collect();
        if !pairs.is_empty() {
            let n = pairs.len();
            let diag = pairs.iter().map(|&i| diagonal(&nodes[i]) as f64).sum::<f64>() / n as f64;
            let disjoint = pairs
                .iter()
                .filter(|&&i| box_gap(&nodes[2 * i], &nodes[2 * i + 1]) > 0.0)
                .count();
            let far = pairs.iter().filter(|&&i| far_paired(nodes, i)).count();
            let clusters = 4 * level_start < nodes.len();
            if clusters {
                far_total.0 += far;
                far_total.1 += n;
            }
            println!(
                "  {:>5}  {n:>5}  {diag:>17.3}  {:>16.1}%  {:>7}",
                level_start.trailing_zeros(),
                100.0 * disjoint as f64 / n as f64,
                if clusters {
                    format!("{:.1}%", 100.0 * far as f64 / n as f64)
                } else {
                    "(VPLs)".into()
                }
            );
        }
        level_start *= 2;
    }
    let far_share = far_total.0 as f64 / far_total.1.max(1) as f64;
    println!(
        "far-paired nodes over clusters: {} of {} ({:.1}%)",
        far_total.0,
        far_total.1,
        100.0 * far_share
    );
    far_share
}

/// The median GPU time of `lightcuts_build` + `lightcuts` over `repeat` timed frames after
/// two warm-up ones (NaN without timestamps).
fn median_gpu_ms(r: &mut Renderer, input: &FrameInput<'_>, repeat: u32) -> f64 {
    if r.timestamps_supported() {
        r.set_frame_mode(FrameMode::Timed);
        let mut v = Vec::new();
        for i in 0..repeat + 2 {
            r.render(input);
            if let Some(t) = r.wait_new_timings()
                && i >= 2
            {
                v.push(t.get("lightcuts").unwrap_or(0.0) + t.get("lightcuts_build").unwrap_or(0.0));
            }
        }
        v.sort_by(|a, b| a.total_cmp(b));
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    } else {
        f64::NAN
    }
}

/// The CPU reference's cuts on a subset of pixels: refinements of clusters (inner nodes
/// above each pixel's cut, clusters of clusters) and those of far-paired nodes, the summed cut
/// sizes and the pixels at the maximum cut.
struct CpuCuts {
    refined: u64,
    refined_far: u64,
    cut: u64,
    at_max: u64,
}

impl CpuCuts {
    fn of(
        pixels: &[usize],
        gbuffer: (&crate::base::image::ImageF32, &crate::base::image::ImageF32),
        tree: (
            &[SstNode],
            &crate::reference::lightcuts::LcTree,
            &[crate::base::gpu_layout::GpuVpl],
        ),
        bvh: &Bvh,
        p: &CutParams,
    ) -> Self {
        let (pos, nrm) = gbuffer;
        let (nodes, build, sorted) = tree;
        // Refined nodes = the inner nodes above each pixel's cut.
        let (mut refined, mut refined_far) = (0u64, 0u64);
        let (mut cpu_cut, mut cpu_max) = (0u64, 0u64);
        for &k in pixels {
            let g = pos.pixels[k];
            let x = Vec3::new(g[0], g[1], g[2]);
            let n = Vec3::from_slice(&nrm.pixels[k][..3]).normalize();
            let cut = lightcut(nodes, build, sorted, bvh, x, n, p);
            cpu_cut += cut.cut.len() as u64;
            cpu_max += cut.hit_max_cut(p) as u64;
            let mut seen = std::collections::HashSet::new();
            for c in &cut.cut {
                let mut a = c.node / 2;
                while a >= 1 && seen.insert(a) {
                    // Refinements of clusters of clusters (as the far-pairing counts).
                    if 4 * a < nodes.len() as u32 {
                        refined += 1;
                        refined_far += far_paired(nodes, a as usize) as u64;
                    }
                    a /= 2;
                }
            }
        }
        Self {
            refined,
            refined_far,
            cut: cpu_cut,
            at_max: cpu_max,
        }
    }
}

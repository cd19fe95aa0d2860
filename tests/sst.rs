//! SST stages 8-9: GPU sort keys and bitonic sort against the CPU reference.

mod common;

use glam::Vec3;
use lightcut::{
    reference::sst::sort_key,
    renderer::{
        FrameInput, Renderer,
        gpu_data::VPL_NONE,
        passes::sst_sort::{SortBuffers, SortPass, SortVariant, read_pairs},
        settings::{RenderSettings, ViewBuffer},
        timing::GpuTimer,
    },
    scene::{Aabb, default_scene},
};

/// xorshift64*.
fn rng(seed: u64) -> impl FnMut() -> u64 {
    let mut s = seed | 1;
    move || {
        s ^= s >> 12;
        s ^= s << 25;
        s ^= s >> 27;
        s.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
}

fn check_sorted(gpu: &[(u64, u32)], input: &[u64]) {
    let mut want = input.to_vec();
    want.sort_unstable();
    let got: Vec<u64> = gpu.iter().map(|p| p.0).collect();
    assert_eq!(got, want, "keys not sorted like sort_unstable");
    let mut seen = vec![false; input.len()];
    for &(k, i) in gpu {
        assert_eq!(input[i as usize], k, "index {i} does not carry its key");
        assert!(!seen[i as usize], "index {i} twice");
        seen[i as usize] = true;
    }
}

#[test]
fn gpu_bitonic_sort_equals_sort_unstable() {
    let Some(ctx) = common::gpu() else { return };
    let mut pass = SortPass::new(&ctx.device).unwrap();
    // Both variants: the parallel one (workgroup-memory tiles of 512, global steps above)
    // and the baseline (one global dispatch per step).
    for variant in [SortVariant::Parallel, SortVariant::Baseline] {
        pass.variant = variant;
        let mut next = rng(42);
        // Random keys (power of two and not, below, at and above the tile size), then
        // already sorted and reverse sorted inputs, and many duplicates.
        for n in [1usize, 2, 3, 300, 512, 1000, 4096, 5000] {
            let keys: Vec<u64> = (0..n).map(|_| next()).collect();
            check_sorted(&pass.sort_keys(&ctx, &keys).unwrap(), &keys);
        }
        let sorted: Vec<u64> = (0..3000u64).map(|i| i * 7919 + (i << 40)).collect();
        check_sorted(&pass.sort_keys(&ctx, &sorted).unwrap(), &sorted);
        let reversed: Vec<u64> = sorted.iter().rev().copied().collect();
        check_sorted(&pass.sort_keys(&ctx, &reversed).unwrap(), &reversed);
        let dups: Vec<u64> = (0..2100).map(|_| next() % 7).collect();
        check_sorted(&pass.sort_keys(&ctx, &dups).unwrap(), &dups);
    }
    assert!(ctx.errors.take().is_empty());
}

#[test]
fn gpu_keys_of_the_frame_vpls_equal_the_cpu_keys() {
    let Some(ctx) = common::gpu() else { return };
    let scene = default_scene::build();
    let cam = scene.camera_or_default(None).unwrap();
    let mut r = Renderer::new(ctx.clone(), &scene, (64, 40), RenderSettings::default()).unwrap();
    r.render(&FrameInput {
        camera: &cam,
        lights: &scene.lights,
        view: ViewBuffer::Final,
    });
    let vpls = r.read_vpls().unwrap();
    let mut pass = SortPass::new(&ctx.device).unwrap();
    let out = SortBuffers::new(&ctx.device, vpls.len() as u32);
    let mut run = |variant| {
        pass.variant = variant;
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        let mut timer = GpuTimer::new(&ctx.device, &ctx.queue);
        pass.record(
            &ctx.device,
            &ctx.queue,
            &mut enc,
            &mut timer,
            &r.vpl_buffers().vpls,
            &out,
        );
        ctx.queue.submit([enc.finish()]);
        read_pairs(&ctx, &out).unwrap()
    };
    // The baseline (serial bounds, global steps) and the parallel variant give the same
    // bounds, so the same keys, and the same sorted pairs.
    let baseline = run(SortVariant::Baseline);
    let pairs = run(SortVariant::Parallel);
    assert_eq!(
        pairs, baseline,
        "the parallel keys / sort differ from the baseline's"
    );
    let mut bounds = Aabb::EMPTY;
    for v in vpls.iter().filter(|v| v.id != VPL_NONE) {
        bounds.grow(Vec3::from_slice(&v.position[..3]));
    }
    let cpu: Vec<u64> = vpls
        .iter()
        .enumerate()
        .map(|(i, v)| {
            if v.id == VPL_NONE {
                u64::MAX
            } else {
                sort_key(
                    Vec3::from_slice(&v.position[..3]),
                    Vec3::from_array(v.normal),
                    i as u32,
                    &bounds,
                )
            }
        })
        .collect();
    // Sorted, every VPL once, each carrying the CPU's key (float quantisation may differ by
    // one step at a cell boundary for a handful of VPLs).
    let mut same = 0;
    for w in pairs.windows(2) {
        assert!(w[0].0 <= w[1].0, "not sorted");
    }
    for &(k, i) in pairs.iter().take(vpls.len()) {
        same += (cpu[i as usize] == k) as usize;
    }
    assert!(
        same * 1000 >= 999 * vpls.len(),
        "only {same} of {} keys equal the CPU's",
        vpls.len()
    );
    let mut idx: Vec<u32> = pairs.iter().take(vpls.len()).map(|p| p.1).collect();
    idx.sort_unstable();
    assert_eq!(idx, (0..vpls.len() as u32).collect::<Vec<_>>());
    assert!(ctx.errors.take().is_empty());
}

// ---- Stage 10: the tree ----

use lightcut::{
    reference::sst_tree::{self, SstNode, build_with_leaves, classify},
    renderer::{
        gpu_data::GpuVpl,
        passes::sst_build::{
            BuildInputs, BuildPass, TreeBuffers, UsableThresholds, read_flags, read_nodes, read_sorted_vpls,
        },
    },
};
use wgpu::util::DeviceExt;

fn f01(next: &mut impl FnMut() -> u64) -> f32 {
    (next() >> 40) as f32 / (1u64 << 24) as f32
}

/// Synthetic VPLs: clusters on a few planes (floor, wall, a tilted panel) plus a scatter of
/// random ones, with some empty VPLs at the end like a frame that did not fill its budget.
fn synthetic_vpls(n: usize, seed: u64) -> Vec<GpuVpl> {
    let mut next = rng(seed);
    (0..n)
        .map(|i| {
            let (u, v, w) = (f01(&mut next), f01(&mut next), f01(&mut next));
            let (p, nrm) = match i % 4 {
                0 => (Vec3::new(u * 8.0, 0.0, v * 6.0), Vec3::Y),
                1 => (Vec3::new(u * 8.0, v * 3.0, 0.0), Vec3::Z),
                2 => (
                    Vec3::new(2.0 + u, 1.0 + v, 3.0 + u),
                    Vec3::new(-1.0, 0.0, 1.0).normalize(),
                ),
                _ => (
                    Vec3::new(u * 8.0, v * 3.0, w * 6.0),
                    Vec3::new(u - 0.5, v - 0.5, w - 0.5)
                        .try_normalize()
                        .unwrap_or(Vec3::X),
                ),
            };
            let empty = n > 8 && i >= n - n / 50;
            GpuVpl {
                position: p.extend(1.0).to_array(),
                normal: nrm.to_array(),
                id: if empty { VPL_NONE } else { i as u32 },
                flux: [
                    f01(&mut next) * 0.01,
                    f01(&mut next) * 0.01,
                    f01(&mut next) * 0.01,
                    1.0,
                ],
            }
        })
        .collect()
}

struct GpuTree {
    nodes: Vec<SstNode>,
    flags: Vec<u32>,
    sorted: Vec<GpuVpl>,
    leaves: usize,
}

/// Keys, sort and build of `vpls` on the GPU (v_min / sigma_max for the flags).
fn gpu_tree(
    ctx: &lightcut::renderer::context::GpuContext,
    vpls: &[GpuVpl],
    v_min: f32,
    sigma_max: f32,
) -> GpuTree {
    gpu_tree_of(
        ctx,
        vpls,
        v_min,
        sigma_max,
        lightcut::renderer::settings::TreeKind::Perfect,
    )
}

/// [`gpu_tree`] of either kind (the frame's build pass).
fn gpu_tree_of(
    ctx: &lightcut::renderer::context::GpuContext,
    vpls: &[GpuVpl],
    v_min: f32,
    sigma_max: f32,
    kind: lightcut::renderer::settings::TreeKind,
) -> GpuTree {
    let buf = ctx.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("test::vpls"),
        contents: bytemuck::cast_slice(vpls),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let sort = SortPass::new(&ctx.device).unwrap();
    let build = BuildPass::new(&ctx.device).unwrap();
    let sb = SortBuffers::new(&ctx.device, vpls.len() as u32);
    let tb = TreeBuffers::new(&ctx.device, vpls.len() as u32, kind);
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    let mut timer = GpuTimer::new(&ctx.device, &ctx.queue);
    sort.record(&ctx.device, &ctx.queue, &mut enc, &mut timer, &buf, &sb);
    let inputs = BuildInputs {
        vpls: &buf,
        sort: &sb,
        tree: &tb,
        usable: UsableThresholds { v_min, sigma_max },
    };
    build.record(&ctx.device, &ctx.queue, &mut enc, &mut timer, &inputs);
    ctx.queue.submit([enc.finish()]);
    GpuTree {
        nodes: read_nodes(ctx, &tb)
            .unwrap()
            .iter()
            .map(SstNode::decode)
            .collect(),
        flags: read_flags(ctx, &tb).unwrap(),
        sorted: read_sorted_vpls(ctx, &tb).unwrap(),
        leaves: tb.leaves as usize,
    }
}

/// Compares a GPU tree with the CPU build of the same sorted VPLs. Tolerances: bounds and
/// sums exact up to float summation order (bounds exactly), positions 1e-5 of the scene
/// size, normals 2e-4 (16-bit octahedral codes may differ by one step), v 1e-4, variances
/// 3e-3 relative to the node's trace (f16 tangent variances) + 1e-7 m^2.
fn compare_trees(gpu: &[SstNode], cpu: &[SstNode], scale: f32) {
    assert_eq!(gpu.len(), cpu.len());
    for (i, (g, c)) in gpu.iter().zip(cpu).enumerate().skip(1) {
        assert_eq!(g.is_empty(), c.is_empty(), "node {i} emptiness");
        if c.is_empty() {
            assert_eq!(g.intensity, Vec3::ZERO, "node {i}");
            continue;
        }
        assert_eq!(
            (g.bbox_min, g.bbox_max),
            (c.bbox_min, c.bbox_max),
            "node {i} bounds"
        );
        let tol_i = 1e-5 * c.intensity.max_element().max(1e-20);
        assert!(
            (g.intensity - c.intensity).abs().max_element() <= tol_i,
            "node {i} intensity"
        );
        assert!(
            (g.position - c.position).length() <= 1e-5 * scale,
            "node {i} position {} vs {}",
            g.position,
            c.position
        );
        assert!(
            (g.normal - c.normal).length() <= 2e-4,
            "node {i} normal {} vs {}",
            g.normal,
            c.normal
        );
        assert!((g.v - c.v).abs() <= 1e-4, "node {i} v {} vs {}", g.v, c.v);
        let tr = c.variance.x + c.variance.y + c.variance.z;
        assert!(
            (g.variance - c.variance).abs().max_element() <= 3e-3 * tr + 1e-7,
            "node {i} variance {} vs {}",
            g.variance,
            c.variance
        );
    }
}

#[test]
fn gpu_tree_equals_the_cpu_build_of_the_same_sorted_vpls() {
    let Some(ctx) = common::gpu() else { return };
    for (n, seed) in [(1usize, 1u64), (2, 2), (3, 3), (1000, 4), (4096, 5)] {
        let vpls = synthetic_vpls(n, seed);
        let g = gpu_tree(&ctx, &vpls, 0.7, 0.3);
        assert_eq!(g.leaves, sst_tree::leaf_count(n as u32) as usize);
        // The permuted VPLs are the input in key order, padded with empty VPLs.
        let mut sorted_cpu = sst_tree::sort_vpls(&vpls);
        sorted_cpu.resize(g.leaves, g.sorted[g.leaves - 1]);
        let valid = vpls.iter().filter(|v| v.id != VPL_NONE).count();
        assert_eq!(
            g.sorted[..valid].iter().map(|v| v.id).collect::<Vec<_>>().len(),
            valid
        );
        assert!(g.sorted[valid..].iter().all(|v| v.id == VPL_NONE), "n = {n}");
        let mut ids: Vec<u32> = g.sorted[..valid].iter().map(|v| v.id).collect();
        ids.sort_unstable();
        let mut want: Vec<u32> = vpls.iter().filter(|v| v.id != VPL_NONE).map(|v| v.id).collect();
        want.sort_unstable();
        assert_eq!(ids, want, "every valid VPL once (n = {n})");
        // CPU build of the GPU's order.
        let cpu = build_with_leaves(&g.sorted[..n.min(g.leaves)], g.leaves);
        compare_trees(&g.nodes, &cpu, 10.0);
        // Flags: identical to the CPU's classification of the same tree.
        assert_eq!(g.flags[..], classify(&cpu, 0.7, 0.3)[..], "flags, n = {n}");
    }
    assert!(ctx.errors.take().is_empty());
}

#[test]
fn gpu_tree_invariants_and_reclassification() {
    let Some(ctx) = common::gpu() else { return };
    let vpls = synthetic_vpls(4096, 9);
    let g = gpu_tree(&ctx, &vpls, 0.7, 0.3);
    let t = &g.nodes;
    let leaves = g.leaves;
    for n in 1..leaves {
        let (a, b, p) = (&t[2 * n], &t[2 * n + 1], &t[n]);
        if a.is_empty() && b.is_empty() {
            assert!(p.is_empty());
            continue;
        }
        let sum = a.intensity + b.intensity;
        assert!((p.intensity - sum).abs().max_element() <= 1e-6 * sum.max_element());
        for c in [a, b].into_iter().filter(|c| !c.is_empty()) {
            assert!(p.bbox_min.cmple(c.bbox_min).all() && p.bbox_max.cmpge(c.bbox_max).all());
            assert!(p.v <= c.v, "v grows towards the root at node {n}");
        }
    }
    // The root holds all the flux.
    let total: Vec3 = vpls
        .iter()
        .filter(|v| v.id != VPL_NONE)
        .map(|v| Vec3::from_slice(&v.flux[..3]))
        .sum();
    assert!((t[1].intensity - total).abs().max_element() < 1e-4 * total.max_element());
    // Other thresholds: the same flags as the CPU classification of the GPU's nodes.
    let ctx2 = ctx.clone();
    for (v_min, sigma_max) in [(0.0, 1000.0), (0.95, 0.05), (0.5, 0.1), (1.0, 0.0)] {
        let g2 = gpu_tree(&ctx2, &vpls, v_min, sigma_max);
        assert_eq!(
            g2.flags,
            classify(&g2.nodes, v_min, sigma_max),
            "{v_min} {sigma_max}"
        );
        let on: u32 = g2.flags.iter().map(|w| w.count_ones()).sum();
        if v_min == 0.0 {
            // Everything non-empty is usable.
            let nonempty = g2.nodes.iter().skip(1).filter(|n| !n.is_empty()).count() as u32;
            assert_eq!(on, nonempty);
        }
    }
    assert!(ctx.errors.take().is_empty());
}

#[test]
fn frame_tree_reclassifies_without_rebuilding() {
    let Some(ctx) = common::gpu() else { return };
    let scene = default_scene::build();
    let cam = scene.camera_or_default(None).unwrap();
    let mut r = Renderer::new(ctx.clone(), &scene, (64, 40), RenderSettings::default()).unwrap();
    r.render(&FrameInput {
        camera: &cam,
        lights: &scene.lights,
        view: ViewBuffer::Final,
    });
    let (nodes, flags) = r.read_tree().unwrap();
    let leaves = r.tree_buffers().1.leaves as usize;
    assert_eq!(nodes.len(), 2 * leaves);
    assert_eq!(flags, classify(&nodes, 0.7, 0.3));
    // Reading some nodes alone (the pixel story) gives the same nodes; ids past the tree are
    // empty.
    let ids = [1u32, 7, 2, (2 * leaves - 1) as u32, (2 * leaves) as u32, 300];
    let (some, some_flags) = r.read_tree_nodes(&ids).unwrap();
    assert_eq!(some_flags, flags);
    for (&i, n) in ids.iter().zip(&some) {
        match nodes.get(i as usize) {
            Some(want) => assert_eq!(n, want, "node {i}"),
            None => assert!(n.is_empty(), "node {i} past the tree"),
        }
    }
    // The frame's tree equals the CPU build of its own sorted VPLs.
    let sorted = read_sorted_vpls(&ctx, r.tree_buffers().1).unwrap();
    let cpu = build_with_leaves(&sorted, leaves);
    compare_trees(&nodes, &cpu, scene.bounds.radius() * 2.0);
    // New thresholds: only the flags change.
    r.reclassify(0.95, 0.01);
    let (nodes2, flags2) = r.read_tree().unwrap();
    assert_eq!(nodes2, nodes);
    assert_eq!(flags2, classify(&nodes, 0.95, 0.01));
    assert_ne!(flags2, flags, "stricter thresholds change some flags");
    assert!(ctx.errors.take().is_empty());
}

/// The radix tree (issue 23): the GPU's node data over its own topology, in the samplers'
/// numbering (root 1, leaf k at n + k), equals the CPU twin (`reference::lbvh::sampler_layout`
/// over `reference::lbvh::build` of the same sorted keys) with the perfect tree's tolerances,
/// links included; its root holds the same flux and bounds as the perfect tree's root.
#[test]
fn gpu_radix_tree_node_data_equals_the_cpu_twin() {
    use lightcut::reference::lbvh;
    use lightcut::renderer::passes::lbvh::{LbvhPass, read_links, read_topology};
    use lightcut::renderer::settings::TreeKind;
    let Some(ctx) = common::gpu() else { return };
    for n in [2usize, 3, 600, 3000] {
        let vpls = synthetic_vpls(n, 7 + n as u64);
        let buf = ctx.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("test::vpls"),
            contents: bytemuck::cast_slice(&vpls),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let sort = SortPass::new(&ctx.device).unwrap();
        let pass = LbvhPass::new(&ctx.device).unwrap();
        let sb = SortBuffers::new(&ctx.device, n as u32);
        let lb = TreeBuffers::new(&ctx.device, n as u32, TreeKind::Lbvh);
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        let mut timer = GpuTimer::new(&ctx.device, &ctx.queue);
        sort.record(&ctx.device, &ctx.queue, &mut enc, &mut timer, &buf, &sb);
        pass.record(&ctx.device, &ctx.queue, &mut enc, &mut timer, &sb, &lb);
        let leaves = lightcut::renderer::passes::lbvh::LeafSource {
            keys: &sb,
            vpls: &buf,
        };
        pass.record_node_data(&ctx.device, &ctx.queue, &mut enc, &mut timer, leaves, &lb);
        ctx.queue.submit([enc.finish()]);
        let pairs = read_pairs(&ctx, &sb).unwrap();
        let keys: Vec<u64> = pairs.iter().take(n).map(|p| p.0).collect();
        let topology = lbvh::build(&keys);
        assert_eq!(read_topology(&ctx, &lb).unwrap(), topology, "{n} VPLs: topology");
        let leaves: Vec<SstNode> = pairs
            .iter()
            .take(n)
            .map(|&(_, i)| vpls.get(i as usize).map(SstNode::leaf).unwrap_or(SstNode::EMPTY))
            .collect();
        let (cpu, links) = lbvh::sampler_layout(&topology, &leaves);
        assert_eq!(read_links(&ctx, &lb).unwrap()[1..], links[1..], "{n} VPLs: links");
        let gpu: Vec<SstNode> = read_nodes(&ctx, &lb)
            .unwrap()
            .iter()
            .map(SstNode::decode)
            .collect();
        assert_eq!(gpu.len(), 2 * n);
        // The frame's build pass on the radix tree: the same nodes, and the usable flags of
        // the twin's classification.
        let framed = gpu_tree_of(&ctx, &vpls, 0.9, 0.1, TreeKind::Lbvh);
        assert_eq!(framed.nodes.len(), 2 * n);
        compare_trees(&framed.nodes, &cpu, 10.0);
        assert_eq!(
            framed.flags[..(2 * n).div_ceil(32)],
            lightcut::reference::sst_tree::classify(&framed.nodes, 0.9, 0.1)[..],
            "{n} VPLs: usable flags"
        );
        compare_trees(&gpu, &cpu, 10.0);
        // The root sums every VPL as the perfect tree's does.
        let perfect = gpu_tree(&ctx, &vpls, 0.9, 0.1);
        let (a, b) = (&gpu[1], &perfect.nodes[1]);
        assert_eq!(
            (a.bbox_min, a.bbox_max),
            (b.bbox_min, b.bbox_max),
            "{n} VPLs: root bounds"
        );
        assert!((a.intensity - b.intensity).abs().max_element() <= 1e-4 * b.intensity.max_element());
    }
    assert!(ctx.errors.take().is_empty());
}

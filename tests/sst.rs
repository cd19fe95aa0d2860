//! SST stages 8-9: GPU sort keys and bitonic sort against the CPU reference.

mod common;

use glam::Vec3;
use lightcut::{
    reference::sst::sort_key,
    renderer::{
        FrameInput, Renderer,
        gpu_data::VPL_NONE,
        passes::sst_sort::{SortBuffers, SortPass, read_pairs},
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
    let pass = SortPass::new(&ctx.device).unwrap();
    let mut next = rng(42);
    // Random keys (power of two and not), then already sorted and reverse sorted inputs.
    for n in [1usize, 2, 3, 1000, 4096, 5000] {
        let keys: Vec<u64> = (0..n).map(|_| next()).collect();
        check_sorted(&pass.sort_keys(&ctx, &keys).unwrap(), &keys);
    }
    let sorted: Vec<u64> = (0..3000u64).map(|i| i * 7919 + (i << 40)).collect();
    check_sorted(&pass.sort_keys(&ctx, &sorted).unwrap(), &sorted);
    let reversed: Vec<u64> = sorted.iter().rev().copied().collect();
    check_sorted(&pass.sort_keys(&ctx, &reversed).unwrap(), &reversed);
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
    let pass = SortPass::new(&ctx.device).unwrap();
    let out = SortBuffers::new(&ctx.device, vpls.len() as u32);
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
    let pairs = read_pairs(&ctx, &out).unwrap();
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

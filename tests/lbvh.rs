//! The radix tree's GPU build (`renderer::passes::lbvh`, Karras 2012) against its CPU twin
//! (`reference::lbvh::build`): random 64-bit keys with runs of duplicates and few distinct
//! keys, topology and parents node for node. (`bench tree` checks it on sorted VPL keys at
//! every size it times.)

mod common;

use lightcut::reference::lbvh::{self, Child};
use lightcut::renderer::{
    passes::{
        lbvh::{LbvhPass, read_parents, read_topology},
        sst_build::TreeBuffers,
        sst_sort::SortBuffers,
    },
    settings::TreeKind,
    timing::GpuTimer,
};

fn keys(n: usize, seed: u64, dup_every: usize, bits: u32) -> Vec<u64> {
    let mut s = seed;
    let mut v: Vec<u64> = Vec::new();
    for i in 0..n {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        if dup_every > 0 && i % dup_every == 1 {
            v.push(v[i - 1]);
        } else {
            v.push(s >> (64 - bits));
        }
    }
    v.sort_unstable();
    v
}

#[test]
fn the_gpu_radix_tree_equals_karras_on_the_cpu() {
    let Some(ctx) = common::gpu() else { return };
    let device = &ctx.device;
    let pass = LbvhPass::new(device).unwrap();
    let mut timer = GpuTimer::new(device, &ctx.queue);
    for (n, seed, dup, bits) in [
        (2, 1, 0, 64),
        (3, 2, 0, 64),
        (1000, 3, 0, 64),
        (777, 4, 2, 64),
        (500, 5, 0, 4),
        (64, 6, 0, 1),
    ] {
        let k = keys(n, seed, dup, bits);
        let sb = SortBuffers::new(device, n as u32);
        let words: Vec<[u32; 4]> = (0..sb.padded as usize)
            .map(|i| match k.get(i) {
                Some(&key) => [(key >> 32) as u32, key as u32, i as u32, 0],
                None => [u32::MAX, u32::MAX, i as u32, 0],
            })
            .collect();
        ctx.queue.write_buffer(&sb.keys, 0, bytemuck::cast_slice(&words));
        let out = TreeBuffers::new(device, n as u32, TreeKind::Lbvh);
        let mut enc = device.create_command_encoder(&Default::default());
        timer.begin_frame(false);
        pass.record(device, &ctx.queue, &mut enc, &mut timer, &sb, &out);
        ctx.queue.submit([enc.finish()]);
        let gpu = read_topology(&ctx, &out).unwrap();
        let cpu = lbvh::build(&k);
        assert_eq!(
            gpu, cpu,
            "{n} keys (seed {seed}, duplicates every {dup}, {bits} bits)"
        );
        // Parents: the root has none; every other node and every leaf its twin's parent.
        let parents = read_parents(&ctx, &out).unwrap();
        let (ip, lp) = lbvh::parents(&cpu);
        assert_eq!(parents[0], u32::MAX);
        for (i, p) in ip.iter().enumerate().skip(1) {
            assert_eq!(Some(parents[i]), *p, "internal node {i}");
        }
        for (k, p) in lp.iter().enumerate() {
            assert_eq!(Some(parents[n - 1 + k]), *p, "leaf {k}");
        }
        // Not vacuous: internal children below the root.
        if n > 3 {
            assert!(matches!(cpu[0].left, Child::Internal(_)) || matches!(cpu[0].right, Child::Internal(_)));
        }
    }
}

//! SST stages 8-9 (SST paper 3.3, thesis 4.2.1): VPL bounds, 64-bit sort keys (Morton |
//! normal code | id) and a bitonic sort of (key, index) pairs padded to a power of two. Only
//! the pairs move; the VPLs are permuted once afterwards (by the tree build). Two variants
//! ([`SortVariant`]): the parallel one runs in every frame, the baseline stays for `bench
//! tree`'s before / after.
//! Reads: the VPL array. Writes: [`SortBuffers`].

use crate::gpu::kernel::{Kernel, KernelOptions, buf};
use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use crate::gpu::context::{GpuContext, GpuError};
use crate::gpu::readback;
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;

use super::WG_1D;

/// Twin: `SortParams` in `shaders/sst_sort.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuSortParams {
    pub count: u32,
    pub padded: u32,
    pub j: u32,
    pub k: u32,
}

/// Dynamic-offset stride of the per-step uniforms, and the most steps (2^22 padded pairs).
const STRIDE: u64 = 256;
const MAX_STEPS: u64 = 22 * 23 / 2 + 1;
/// Elements per workgroup-memory tile of the parallel sort (twin of `SORT_TILE`).
pub const SORT_TILE: u32 = 512;
/// Workgroup size of the parallel variant's kernels (twin of their `@workgroup_size`).
pub const SORT_WG: u32 = 256;
/// The entry points with that size.
pub const SORT_WG_ENTRIES: [&str; 3] = ["vpl_bounds_parallel", "bitonic_pairs", "bitonic_tile"];
/// VPLs per thread of the parallel bounds reduction (twin of `BOUNDS_PER_THREAD`).
const BOUNDS_PER_THREAD: u32 = 8;

/// How the bounds and the sort run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SortVariant {
    /// Bounds by one 64-thread workgroup looping over every VPL; one global dispatch per
    /// bitonic step (the workbench before issue 18; `bench tree` measures it beside).
    Baseline,
    /// Bounds as a parallel reduction; bitonic steps below the tile size in workgroup memory.
    #[default]
    Parallel,
}

/// One dispatch of the sort: a global step (`tile = false`, distance j in sequences of k) or
/// a workgroup-memory one (`tile = true`: j = 0 sorts each tile, else steps j .. 1 of k).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SortDispatch {
    pub tile: bool,
    pub j: u32,
    pub k: u32,
}

/// The dispatches of the parallel sort of `padded` elements, in order.
pub fn parallel_dispatches(padded: u32) -> Vec<SortDispatch> {
    let mut v = vec![SortDispatch {
        tile: true,
        j: 0,
        k: 0,
    }];
    let mut k = 2 * SORT_TILE;
    while k <= padded {
        let mut j = k / 2;
        while j >= SORT_TILE {
            v.push(SortDispatch { tile: false, j, k });
            j /= 2;
        }
        v.push(SortDispatch {
            tile: true,
            j: SORT_TILE / 2,
            k,
        });
        k *= 2;
    }
    v
}

/// CPU twin of the parallel sort's schedule: applies each dispatch's compare-exchanges in
/// order (the tile dispatches step by step), to check that it sorts.
pub fn parallel_sort_cpu(keys: &mut [u64]) {
    let padded = keys.len();
    assert!(padded.is_power_of_two() || padded == 0);
    let step = |keys: &mut [u64], j: usize, k: usize| {
        for i in 0..padded {
            let l = i ^ j;
            if l > i {
                let asc = i & k == 0;
                if (asc && keys[l] < keys[i]) || (!asc && keys[i] < keys[l]) {
                    keys.swap(i, l);
                }
            }
        }
    };
    for d in parallel_dispatches(padded as u32) {
        let (j, k) = (d.j as usize, d.k as usize);
        match (d.tile, j) {
            (true, 0) => {
                let mut kk = 2;
                while kk <= (SORT_TILE as usize).min(padded) {
                    let mut jj = kk / 2;
                    while jj > 0 {
                        step(keys, jj, kk);
                        jj /= 2;
                    }
                    kk *= 2;
                }
            }
            (true, _) => {
                let mut jj = j;
                while jj > 0 {
                    step(keys, jj, k);
                    jj /= 2;
                }
            }
            (false, _) => step(keys, j, k),
        }
    }
}

/// The (key, index) pairs (vec4<u32>: key high word, key low word, index, 0) and the bounds.
pub struct SortBuffers {
    pub keys: wgpu::Buffer,
    pub bounds: wgpu::Buffer,
    pub count: u32,
    pub padded: u32,
}

impl SortBuffers {
    pub fn new(device: &wgpu::Device, count: u32) -> Self {
        let padded = count.max(1).next_power_of_two();
        Self {
            keys: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("sst_sort::keys"),
                size: 16 * padded as u64,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            bounds: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("sst_sort::bounds"),
                size: 32,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            count,
            padded,
        }
    }
}

/// The bitonic steps (j, k) for `padded` elements, in order.
pub fn bitonic_steps(padded: u32) -> Vec<(u32, u32)> {
    let mut steps = Vec::new();
    let mut k = 2;
    while k <= padded {
        let mut j = k / 2;
        while j > 0 {
            steps.push((j, k));
            j /= 2;
        }
        k *= 2;
    }
    steps
}

pub struct SortPass {
    bounds: wgpu::ComputePipeline,
    bounds_parallel: wgpu::ComputePipeline,
    keys: wgpu::ComputePipeline,
    step: wgpu::ComputePipeline,
    pairs: wgpu::ComputePipeline,
    tile: wgpu::ComputePipeline,
    kernel: Kernel,
    params: wgpu::Buffer,
    pub variant: SortVariant,
}

impl SortPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(device, "sst_sort.wgsl", &[], KernelOptions { dynamic: &["sp"] })?;
        Ok(Self {
            bounds: kernel.compute(device, "sst_sort::bounds", "vpl_bounds"),
            bounds_parallel: kernel.compute(device, "sst_sort::bounds_parallel", "vpl_bounds_parallel"),
            keys: kernel.compute(device, "sst_sort::keys", "make_keys"),
            step: kernel.compute(device, "sst_sort::bitonic", "bitonic_step"),
            pairs: kernel.compute(device, "sst_sort::bitonic_pairs", "bitonic_pairs"),
            tile: kernel.compute(device, "sst_sort::bitonic_tile", "bitonic_tile"),
            variant: SortVariant::default(),
            params: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("sst_sort::params"),
                size: STRIDE * MAX_STEPS,
                usage: wgpu::BufferUsages::UNIFORM
                    | wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            kernel,
        })
    }

    fn bind(&self, device: &wgpu::Device, vpls: &wgpu::Buffer, out: &SortBuffers) -> wgpu::BindGroup {
        self.kernel.bind(
            device,
            0,
            &[
                (
                    "sp",
                    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &self.params,
                        offset: 0,
                        size: wgpu::BufferSize::new(16),
                    }),
                ),
                ("vpls", buf(vpls)),
                ("keys", buf(&out.keys)),
                ("bounds", buf(&out.bounds)),
            ],
        )
    }

    /// Records bounds + keys of the first `out.count` VPLs, then the sort.
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        vpls: &wgpu::Buffer,
        out: &SortBuffers,
    ) {
        let bind = self.bind(device, vpls, out);
        let base = GpuSortParams {
            count: out.count,
            padded: out.padded,
            j: 0,
            k: 0,
        };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&base));
        encoder.push_debug_group("sst_keys");
        // The bounds reduce by atomic max from zero.
        encoder.clear_buffer(&out.bounds, 0, None);
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("sst_keys"),
                timestamp_writes: timer.compute_pass("sst_keys"),
            });
            pass.set_bind_group(0, &bind, &[0]);
            match self.variant {
                SortVariant::Baseline => {
                    pass.set_pipeline(&self.bounds);
                    pass.dispatch_workgroups(1, 1, 1);
                }
                SortVariant::Parallel => {
                    pass.set_pipeline(&self.bounds_parallel);
                    pass.dispatch_workgroups(out.count.max(1).div_ceil(SORT_WG * BOUNDS_PER_THREAD), 1, 1);
                }
            }
            pass.set_pipeline(&self.keys);
            pass.dispatch_workgroups(out.padded.div_ceil(WG_1D), 1, 1);
        }
        encoder.pop_debug_group();
        self.record_sort_only(queue, encoder, timer, &bind, out);
    }

    fn record_sort_only(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        bind: &wgpu::BindGroup,
        out: &SortBuffers,
    ) {
        // Every dispatch's (j, k) at its own dynamic offset; (pipeline, workgroups) each.
        let steps: Vec<(GpuSortParams, &wgpu::ComputePipeline, u32)> = match self.variant {
            SortVariant::Baseline => bitonic_steps(out.padded)
                .into_iter()
                .map(|(j, k)| {
                    let p = GpuSortParams {
                        count: out.count,
                        padded: out.padded,
                        j,
                        k,
                    };
                    (p, &self.step, out.padded.div_ceil(WG_1D))
                })
                .collect(),
            SortVariant::Parallel if out.padded < 2 => Vec::new(),
            SortVariant::Parallel => parallel_dispatches(out.padded)
                .into_iter()
                .map(|d| {
                    let p = GpuSortParams {
                        count: out.count,
                        padded: out.padded,
                        j: d.j,
                        k: d.k,
                    };
                    if d.tile {
                        (p, &self.tile, out.padded.div_ceil(SORT_TILE))
                    } else {
                        (p, &self.pairs, (out.padded / 2).div_ceil(SORT_WG))
                    }
                })
                .collect(),
        };
        for (n, (p, _, _)) in steps.iter().enumerate() {
            queue.write_buffer(&self.params, (n as u64 + 1) * STRIDE, bytemuck::bytes_of(p));
        }
        encoder.push_debug_group("sst_sort");
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("sst_sort"),
                timestamp_writes: timer.compute_pass("sst_sort"),
            });
            for (n, (_, pipeline, groups)) in steps.iter().enumerate() {
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, bind, &[((n as u64 + 1) * STRIDE) as u32]);
                pass.dispatch_workgroups(*groups, 1, 1);
            }
        }
        encoder.pop_debug_group();
    }

    /// Sorts arbitrary 64-bit keys on the GPU (tests): returns (key, original index) pairs.
    pub fn sort_keys(&self, ctx: &GpuContext, keys: &[u64]) -> Result<Vec<(u64, u32)>, GpuError> {
        let device = &ctx.device;
        let mut out = SortBuffers::new(device, keys.len() as u32);
        let mut data: Vec<[u32; 4]> = keys
            .iter()
            .enumerate()
            .map(|(i, k)| [(k >> 32) as u32, *k as u32, i as u32, 0])
            .collect();
        data.resize(out.padded as usize, [u32::MAX, u32::MAX, u32::MAX, 0]);
        out.keys = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("sst_sort::test_keys"),
            contents: bytemuck::cast_slice(&data),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        });
        let dummy = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sst_sort::no_vpls"),
            size: 48,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let bind = self.bind(device, &dummy, &out);
        let mut timer = GpuTimer::new(device, &ctx.queue);
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("sst_sort::test"),
        });
        self.record_sort_only(&ctx.queue, &mut enc, &mut timer, &bind, &out);
        ctx.queue.submit([enc.finish()]);
        read_pairs(ctx, &out).map(|mut v| {
            v.truncate(keys.len());
            v
        })
    }
}

/// Reads the (key, index) pairs back.
pub fn read_pairs(ctx: &GpuContext, out: &SortBuffers) -> Result<Vec<(u64, u32)>, GpuError> {
    let bytes = readback::read_storage_buffer(ctx, &out.keys)?;
    let words: &[[u32; 4]] = bytemuck::cast_slice(&bytes);
    Ok(words
        .iter()
        .map(|w| (((w[0] as u64) << 32) | w[1] as u64, w[2]))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::bitonic_steps;

    #[test]
    fn the_parallel_schedule_sorts_like_sort_unstable() {
        use super::{SORT_TILE, parallel_dispatches, parallel_sort_cpu};
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        for n in [1usize, 2, 8, 512, 1024, 4096, 16384] {
            let mut keys: Vec<u64> = (0..n)
                .map(|_| {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    state % 1000
                })
                .collect();
            let mut want = keys.clone();
            want.sort_unstable();
            parallel_sort_cpu(&mut keys);
            assert_eq!(keys, want, "n = {n}");
        }
        // 2^20: 1 tile sort + per k > 512 its global steps j >= 512 and one tile merge.
        let d = parallel_dispatches(1 << 20);
        assert_eq!(d.len(), 1 + 11 + (1..=11).sum::<usize>());
        assert!(d.iter().all(|d| d.tile || d.j >= SORT_TILE));
    }

    #[test]
    fn bitonic_step_count() {
        assert_eq!(bitonic_steps(1).len(), 0);
        assert_eq!(bitonic_steps(8).len(), 6);
        assert_eq!(bitonic_steps(1 << 20).len(), 210);
    }
}

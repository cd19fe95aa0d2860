//! The binary radix tree (LBVH) over the sorted VPL keys, Karras 2012 (`shaders/lbvh.wgsl`):
//! the topology of issue 23's second light tree, one thread per internal node. Reads: the
//! keys `sst_sort` sorted. Writes: internal nodes (children, leaf range) and parents. Timer:
//! `lbvh_build`; then the SST node data bottom-up (`lbvh_nodes`: one thread per leaf, the
//! second arrival at a node merges, as `sst_build`) into the frame's [`TreeBuffers`] (kind
//! `Lbvh`), numbered as the samplers read both trees. Twins: `reference::lbvh::{build,
//! sampler_layout}`. `sst_build::BuildPass` runs it when `tree.kind` is `lbvh`; `bench tree`
//! times both trees and checks the topology against the twin.

use crate::gpu::kernel::{Kernel, KernelOptions, buf};
use bytemuck::{Pod, Zeroable};

use super::{WG_1D, run_compute, uniform_buffer};
use crate::gpu::context::{GpuContext, GpuError};
use crate::gpu::passes::{sst_build::TreeBuffers, sst_sort::SortBuffers};
use crate::gpu::readback::read_storage_buffer;
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;
use crate::reference::lbvh::{Child, Internal};

/// Twin: `LbvhParams` in `shaders/lbvh.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuLbvhParams {
    pub count: u32,
    pub _pad: [u32; 3],
}

/// The radix tree as the GPU stores it in a [`TreeBuffers`] of kind `Lbvh` (the samplers'
/// numbering, `base::sst_node::Topology`): Karras's internal node i is node i + 1, leaf k is
/// node n + k; `links[i + 1]` = (left, right, first, last leaf), `parents[node]`.
/// The internal nodes in Karras's numbering, as the twin writes them.
pub fn read_topology(ctx: &GpuContext, tree: &TreeBuffers) -> Result<Vec<Internal>, GpuError> {
    let bytes = read_storage_buffer(ctx, &tree.links)?;
    let raw: Vec<[u32; 4]> = bytemuck::pod_collect_to_vec(&bytes);
    let n = tree.leaves;
    let child = |c: u32| {
        if c >= n {
            Child::Leaf(c - n)
        } else {
            Child::Internal(c - 1)
        }
    };
    Ok(raw
        .iter()
        .skip(1)
        .take(tree.count.saturating_sub(1) as usize)
        .map(|r| Internal {
            left: child(r[0]),
            right: child(r[1]),
            first: r[2],
            last: r[3],
        })
        .collect())
}

/// The links (`links[0]` unused) for `base::sst_node::Topology::radix`.
pub fn read_links(ctx: &GpuContext, tree: &TreeBuffers) -> Result<Vec<[u32; 4]>, GpuError> {
    let bytes = read_storage_buffer(ctx, &tree.links)?;
    let raw: Vec<[u32; 4]> = bytemuck::pod_collect_to_vec(&bytes);
    Ok(raw[..(tree.leaves as usize).min(raw.len())].to_vec())
}

/// The parents in Karras's numbering: internal nodes' (root: u32::MAX), then the leaves'.
pub fn read_parents(ctx: &GpuContext, tree: &TreeBuffers) -> Result<Vec<u32>, GpuError> {
    let bytes = read_storage_buffer(ctx, &tree.parents)?;
    let all: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
    let n = tree.leaves as usize;
    Ok(all[1..2 * n]
        .iter()
        // Unwritten (one leaf: the root is that leaf) or the root's: none.
        .map(|&p| if p == u32::MAX || p == 0 { u32::MAX } else { p - 1 })
        .collect())
}

/// Where the radix tree's leaves come from: the sorted keys and the VPL buffer they index.
#[derive(Clone, Copy)]
pub struct LeafSource<'a> {
    pub keys: &'a SortBuffers,
    pub vpls: &'a wgpu::Buffer,
}

pub struct LbvhPass {
    pipeline: wgpu::ComputePipeline,
    kernel: Kernel,
    node_pipeline: wgpu::ComputePipeline,
    node_kernel: Kernel,
    params: wgpu::Buffer,
}

impl LbvhPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        // The two entry points read different parts of group 0: a kernel each.
        let mut kernels = Kernel::per_entry(
            device,
            "lbvh.wgsl",
            &["build", "node_data"],
            KernelOptions::default(),
        )?
        .into_iter();
        let (Some(kernel), Some(node_kernel)) = (kernels.next(), kernels.next()) else {
            unreachable!("one kernel per entry point")
        };
        Ok(Self {
            pipeline: kernel.compute(device, "lbvh::build", "build"),
            node_pipeline: node_kernel.compute(device, "lbvh::node_data", "node_data"),
            params: uniform_buffer::<GpuLbvhParams>(device, "lbvh::params"),
            kernel,
            node_kernel,
        })
    }

    /// The leaf count (the first `out.count` of `keys`) into the uniform both passes read.
    fn write_params(&self, queue: &wgpu::Queue, keys: &SortBuffers, out: &TreeBuffers) -> GpuLbvhParams {
        let p = GpuLbvhParams {
            count: out.count.min(keys.count),
            _pad: [0; 3],
        };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        p
    }

    /// Records the build over the first `out.count` keys of `keys` (sorted) into `out` (of
    /// kind `Lbvh`).
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        keys: &SortBuffers,
        out: &TreeBuffers,
    ) {
        let p = self.write_params(queue, keys, out);
        let bind = self.kernel.bind(
            device,
            0,
            &[
                ("params", buf(&self.params)),
                ("keys", buf(&keys.keys)),
                ("links", buf(&out.links)),
                ("parents", buf(&out.parents)),
            ],
        );
        run_compute(
            encoder,
            timer,
            "lbvh_build",
            &self.pipeline,
            &bind,
            (p.count.saturating_sub(1).div_ceil(WG_1D).max(1), 1, 1),
        );
    }

    /// Records the node data of the tree `record` built over `leaves.keys`, the leaves from
    /// `leaves.vpls` (the buffer the keys index).
    pub fn record_node_data(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        leaves: LeafSource<'_>,
        out: &TreeBuffers,
    ) {
        let LeafSource { keys, vpls } = leaves;
        let p = self.write_params(queue, keys, out);
        encoder.clear_buffer(&out.counters, 0, None);
        let bind = self.node_kernel.bind(
            device,
            0,
            &[
                ("params", buf(&self.params)),
                ("keys", buf(&keys.keys)),
                ("links", buf(&out.links)),
                ("parents", buf(&out.parents)),
                ("vpls", buf(vpls)),
                ("nodes", buf(&out.nodes)),
                ("counters", buf(&out.counters)),
                ("sorted_vpls", buf(&out.sorted_vpls)),
            ],
        );
        run_compute(
            encoder,
            timer,
            "lbvh_nodes",
            &self.node_pipeline,
            &bind,
            (p.count.div_ceil(WG_1D).max(1), 1, 1),
        );
    }
}

//! The binary radix tree (LBVH) over the sorted VPL keys, Karras 2012 (`shaders/lbvh.wgsl`):
//! the topology of issue 23's second light tree, one thread per internal node. Reads: the
//! keys `sst_sort` sorted. Writes: internal nodes (children, leaf range) and parents. Timer:
//! `lbvh_build`; then the SST node data bottom-up (`lbvh_nodes`: one thread per leaf, the
//! second arrival at a node merges, as `sst_build`). Twins: `reference::lbvh::{build,
//! node_data}`. The samplers on it are still to come; `bench tree` times both and checks the
//! topology against the twin.

use bytemuck::{Pod, Zeroable};

use super::{
    WG_1D, bind_group_seq, compute_pipeline, run_compute, storage_buffer, storage_entry, uniform_buffer,
    uniform_entry,
};
use crate::reference::lbvh::{Child, Internal};
use crate::renderer::{
    context::{GpuContext, GpuError},
    passes::sst_sort::SortBuffers,
    readback::read_storage_buffer,
    shaders,
    timing::GpuTimer,
};

/// Twin: `LbvhParams` in `shaders/lbvh.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuLbvhParams {
    pub count: u32,
    pub _pad: [u32; 3],
}

/// Bit 31 of a stored child: a leaf.
pub const LEAF_BIT: u32 = 0x8000_0000;

/// The tree of `count` leaves: `count - 1` internal nodes (16 bytes each), the parents of
/// every node (internal nodes, then leaves), and the SST node data of every node (64 bytes:
/// internal node i at i, leaf k at count - 1 + k) with the build's arrival counters.
pub struct LbvhBuffers {
    pub count: u32,
    pub nodes: wgpu::Buffer,
    pub parents: wgpu::Buffer,
    pub sst_nodes: wgpu::Buffer,
    pub counters: wgpu::Buffer,
}

impl LbvhBuffers {
    pub fn new(device: &wgpu::Device, count: u32) -> Self {
        let n = count.max(2) as u64;
        Self {
            count,
            nodes: storage_buffer(device, "lbvh::nodes", 16 * (n - 1)),
            parents: storage_buffer(device, "lbvh::parents", 4 * (2 * n - 1)),
            sst_nodes: storage_buffer(
                device,
                "lbvh::sst_nodes",
                std::mem::size_of::<crate::base::gpu_layout::GpuSstNode>() as u64 * (2 * n - 1),
            ),
            counters: storage_buffer(device, "lbvh::counters", 4 * (n - 1)),
        }
    }

    /// The SST node data, decoded: internal nodes 0 .. count - 1, then the leaves.
    pub fn read_node_data(&self, ctx: &GpuContext) -> Result<Vec<crate::base::sst_node::SstNode>, GpuError> {
        let bytes = read_storage_buffer(ctx, &self.sst_nodes)?;
        let all: Vec<crate::base::gpu_layout::GpuSstNode> = bytemuck::pod_collect_to_vec(&bytes);
        Ok(all[..(2 * self.count.max(1) - 1) as usize]
            .iter()
            .map(crate::base::sst_node::SstNode::decode)
            .collect())
    }

    /// The internal nodes as the twin writes them.
    pub fn read(&self, ctx: &GpuContext) -> Result<Vec<Internal>, GpuError> {
        let bytes = read_storage_buffer(ctx, &self.nodes)?;
        let raw: Vec<[u32; 4]> = bytemuck::pod_collect_to_vec(&bytes);
        let child = |c: u32| {
            if c & LEAF_BIT != 0 {
                Child::Leaf(c & !LEAF_BIT)
            } else {
                Child::Internal(c)
            }
        };
        Ok(raw
            .iter()
            .take(self.count.saturating_sub(1) as usize)
            .map(|r| Internal {
                left: child(r[0]),
                right: child(r[1]),
                first: r[2],
                last: r[3],
            })
            .collect())
    }

    /// The parents: internal nodes' (root: u32::MAX), then the leaves'.
    pub fn read_parents(&self, ctx: &GpuContext) -> Result<Vec<u32>, GpuError> {
        let bytes = read_storage_buffer(ctx, &self.parents)?;
        let all: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        Ok(all[..(2 * self.count.max(1) - 1) as usize].to_vec())
    }
}

pub struct LbvhPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    node_pipeline: wgpu::ComputePipeline,
    node_layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
}

impl LbvhPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let module = shaders::create_module(device, "lbvh.wgsl")?;
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lbvh::layout"),
            entries: &[
                uniform_entry(0, c),
                storage_entry(1, c, true),
                storage_entry(2, c, false),
                storage_entry(3, c, false),
            ],
        });
        let node_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lbvh::node_layout"),
            entries: &[
                uniform_entry(0, c),
                storage_entry(1, c, true),
                storage_entry(2, c, false),
                storage_entry(3, c, false),
                storage_entry(4, c, true),
                storage_entry(5, c, false),
                storage_entry(6, c, false),
            ],
        });
        Ok(Self {
            pipeline: compute_pipeline(device, "lbvh::build", &[Some(&layout)], &module, "build"),
            node_pipeline: compute_pipeline(
                device,
                "lbvh::node_data",
                &[Some(&node_layout)],
                &module,
                "node_data",
            ),
            params: uniform_buffer::<GpuLbvhParams>(device, "lbvh::params"),
            layout,
            node_layout,
        })
    }

    /// The leaf count (the first `out.count` of `keys`) into the uniform both passes read.
    fn write_params(&self, queue: &wgpu::Queue, keys: &SortBuffers, out: &LbvhBuffers) -> GpuLbvhParams {
        let p = GpuLbvhParams {
            count: out.count.min(keys.count),
            _pad: [0; 3],
        };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        p
    }

    /// Records the build over the first `out.count` keys of `keys` (sorted).
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        keys: &SortBuffers,
        out: &LbvhBuffers,
    ) {
        let p = self.write_params(queue, keys, out);
        let bind = bind_group_seq(
            device,
            "lbvh::bind_group",
            &self.layout,
            &[
                self.params.as_entire_binding(),
                keys.keys.as_entire_binding(),
                out.nodes.as_entire_binding(),
                out.parents.as_entire_binding(),
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

    /// Records the node data of the tree `record` built over `keys`, the leaves from `vpls`
    /// (the buffer the keys index).
    #[allow(clippy::too_many_arguments)]
    pub fn record_node_data(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        keys: &SortBuffers,
        vpls: &wgpu::Buffer,
        out: &LbvhBuffers,
    ) {
        let p = self.write_params(queue, keys, out);
        encoder.clear_buffer(&out.counters, 0, None);
        let bind = bind_group_seq(
            device,
            "lbvh::node_bind_group",
            &self.node_layout,
            &[
                self.params.as_entire_binding(),
                keys.keys.as_entire_binding(),
                out.nodes.as_entire_binding(),
                out.parents.as_entire_binding(),
                vpls.as_entire_binding(),
                out.sst_nodes.as_entire_binding(),
                out.counters.as_entire_binding(),
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

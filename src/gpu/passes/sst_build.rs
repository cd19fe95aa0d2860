//! SST stage 10 (thesis 4.2.2): the perfect binary tree over the sorted VPLs, built with one
//! thread per leaf pair and per-node atomic counters, then the per-node "usable" flags
//! (separate pass, so a change of v_min / sigma_max costs one tiny dispatch, not a rebuild).
//! Reads: the VPLs and the sorted (key, index) pairs. Writes: [`TreeBuffers`].

use crate::gpu::kernel::{Kernel, KernelOptions, buf};
use bytemuck::{Pod, Zeroable};

use crate::{
    base::sst_node::{TreeKind, leaf_count, level_count},
    gpu::{
        context::{GpuContext, GpuError},
        gpu_data::{GpuSstNode, GpuVpl},
        readback, shaders,
        timing::GpuTimer,
    },
};

use super::{WG_1D, lbvh::LbvhPass, run_compute, sst_sort::SortBuffers};

/// Twin: `TreeParams` in `shaders/sst_build.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuTreeParams {
    pub count: u32,
    pub leaves: u32,
    pub _pad: [u32; 2],
}

/// Twin: `ClassifyParams` in `shaders/sst_classify.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuClassifyParams {
    pub nodes: u32,
    pub v_min: f32,
    pub sigma_max: f32,
    pub _pad: u32,
}

/// The tree of one frame, either kind, numbered as the samplers read both
/// (`base::sst_node::Topology`): node 1 the root, leaf k at `leaves + k`, 2 x leaves nodes
/// (node 0 unused); the usable bits, the per-node arrival counters of the build and the VPLs
/// permuted into leaf order. The perfect tree pads the leaves to a power of two; the radix
/// tree has one leaf per VPL and its links (children, leaf ranges) and parents.
pub struct TreeBuffers {
    pub nodes: wgpu::Buffer,
    pub flags: wgpu::Buffer,
    pub counters: wgpu::Buffer,
    pub sorted_vpls: wgpu::Buffer,
    /// The radix tree's inner nodes (left, right, first leaf, last leaf), `links[0]` unused; a
    /// 16-byte dummy for the perfect tree.
    pub links: wgpu::Buffer,
    /// The radix tree's parent of every node (the root's u32::MAX); a dummy for the perfect tree.
    pub parents: wgpu::Buffer,
    /// This tree's classify uniform (one per tree: a frame may classify two trees, the
    /// overlay's comparison, and queue writes land before either dispatch).
    pub classify_params: wgpu::Buffer,
    pub count: u32,
    pub leaves: u32,
    pub kind: TreeKind,
}

impl TreeBuffers {
    /// Bytes the tree of `count` VPLs needs in its largest single binding (the nodes).
    pub fn largest_binding(count: u32) -> u64 {
        2 * leaf_count(count) as u64 * std::mem::size_of::<GpuSstNode>() as u64
    }

    /// Leaves of the tree of `count` VPLs.
    pub fn leaves_of(count: u32, kind: TreeKind) -> u32 {
        match kind {
            TreeKind::Perfect => leaf_count(count),
            TreeKind::Lbvh => count.max(1),
        }
    }

    pub fn new(device: &wgpu::Device, count: u32, kind: TreeKind) -> Self {
        let leaves = Self::leaves_of(count, kind);
        let buf = |label: &str, size: u64| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(16),
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let nodes = 2 * leaves as u64;
        let radix = kind == TreeKind::Lbvh;
        Self {
            nodes: buf(
                "sst_build::nodes",
                nodes * std::mem::size_of::<GpuSstNode>() as u64,
            ),
            flags: buf("sst_build::flags", 4 * nodes.div_ceil(32).max(1)),
            counters: buf("sst_build::counters", 4 * leaves as u64),
            sorted_vpls: buf(
                "sst_build::sorted_vpls",
                leaves as u64 * std::mem::size_of::<GpuVpl>() as u64,
            ),
            links: buf("lbvh::links", if radix { 16 * leaves as u64 } else { 16 }),
            parents: buf("lbvh::parents", if radix { 4 * nodes } else { 16 }),
            classify_params: super::uniform_buffer::<GpuClassifyParams>(device, "sst_classify::params"),
            count,
            leaves,
            kind,
        }
    }

    /// Levels of the perfect tree; the radix tree has no levels of equal nodes, and this is
    /// the perfect tree's for as many VPLs (the mock cut's level bound, the steps view's
    /// scale; its depth varies per leaf: `reference::lbvh::leaf_depths`).
    pub fn levels(&self) -> u32 {
        level_count(leaf_count(self.count))
    }

    /// A bound on the depth (root 0) of any leaf: the perfect tree's leaf level; the radix
    /// tree's prefixes of the 64-bit keys augmented with 32-bit indices grow by at least one
    /// bit per level, so its depth is at most 96.
    pub fn depth_bound(&self) -> u32 {
        match self.kind {
            TreeKind::Perfect => self.levels(),
            TreeKind::Lbvh => 96,
        }
    }

    /// Whether it is the tree of `count` VPLs of `kind`.
    pub fn matches(&self, count: u32, kind: TreeKind) -> bool {
        self.count == count && self.kind == kind
    }
}

/// The classify pass's thresholds (`tree.v_min`, `tree.sigma_max`): a node is usable where
/// v >= v_min and sigma_z < sigma_max.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UsableThresholds {
    pub v_min: f32,
    pub sigma_max: f32,
}

/// What a build reads and writes: the VPLs and their sorted keys in, the tree out, with the
/// thresholds of its usable flags.
#[derive(Clone, Copy)]
pub struct BuildInputs<'a> {
    pub vpls: &'a wgpu::Buffer,
    pub sort: &'a SortBuffers,
    pub tree: &'a TreeBuffers,
    pub usable: UsableThresholds,
}

pub struct BuildPass {
    lbvh: LbvhPass,
    build: wgpu::ComputePipeline,
    build_kernel: Kernel,
    classify: wgpu::ComputePipeline,
    classify_kernel: Kernel,
    build_params: wgpu::Buffer,
}

impl BuildPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let build_kernel = Kernel::new(device, "sst_build.wgsl", &["build"], KernelOptions::default())?;
        let classify_kernel = Kernel::new(
            device,
            "sst_classify.wgsl",
            &["classify"],
            KernelOptions::default(),
        )?;
        Ok(Self {
            lbvh: LbvhPass::new(device)?,
            build: build_kernel.compute(device, "sst_build", "build"),
            classify: classify_kernel.compute(device, "sst_classify", "classify"),
            build_params: super::uniform_buffer::<GpuTreeParams>(device, "sst_build::params"),
            build_kernel,
            classify_kernel,
        })
    }

    /// Records the build of `tree`'s kind over `sort`'s first `tree.count` sorted pairs
    /// (the perfect tree: `sst_build`; the radix tree: `lbvh_build` + `lbvh_nodes`), then the
    /// flags.
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        b: &BuildInputs<'_>,
    ) {
        let BuildInputs {
            vpls,
            sort,
            tree,
            usable,
        } = *b;
        if tree.kind == TreeKind::Lbvh {
            self.lbvh.record(device, queue, encoder, timer, sort, tree);
            let leaves = super::lbvh::LeafSource { keys: sort, vpls };
            self.lbvh
                .record_node_data(device, queue, encoder, timer, leaves, tree);
            self.record_classify(device, queue, encoder, timer, tree, usable);
            return;
        }
        let p = GpuTreeParams {
            count: tree.count.min(sort.count),
            leaves: tree.leaves,
            _pad: [0; 2],
        };
        queue.write_buffer(&self.build_params, 0, bytemuck::bytes_of(&p));
        let bind = self.build_kernel.bind(
            device,
            0,
            &[
                ("tp", buf(&self.build_params)),
                ("vpls", buf(vpls)),
                ("keys", buf(&sort.keys)),
                ("nodes", buf(&tree.nodes)),
                ("counters", buf(&tree.counters)),
                ("sorted_vpls", buf(&tree.sorted_vpls)),
            ],
        );
        encoder.clear_buffer(&tree.counters, 0, None);
        run_compute(
            encoder,
            timer,
            "sst_build",
            &self.build,
            &bind,
            ((tree.leaves / 2).div_ceil(WG_1D), 1, 1),
        );
        self.record_classify(device, queue, encoder, timer, tree, usable);
    }

    /// Recomputes only the usable flags (v >= v_min and sigma_z < sigma_max).
    pub fn record_classify(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        tree: &TreeBuffers,
        usable: UsableThresholds,
    ) {
        let UsableThresholds { v_min, sigma_max } = usable;
        let nodes = 2 * tree.leaves;
        let p = GpuClassifyParams {
            nodes,
            v_min,
            sigma_max,
            _pad: 0,
        };
        queue.write_buffer(&tree.classify_params, 0, bytemuck::bytes_of(&p));
        let bind = self.classify_kernel.bind(
            device,
            0,
            &[
                ("cp", buf(&tree.classify_params)),
                ("tree", buf(&tree.nodes)),
                ("flags", buf(&tree.flags)),
            ],
        );
        run_compute(
            encoder,
            timer,
            "sst_classify",
            &self.classify,
            &bind,
            (nodes.div_ceil(32).div_ceil(WG_1D), 1, 1),
        );
    }
}

/// Reads every node back (2 x leaves, node 0 unused).
pub fn read_nodes(ctx: &GpuContext, tree: &TreeBuffers) -> Result<Vec<GpuSstNode>, GpuError> {
    let bytes = readback::read_storage_buffer(ctx, &tree.nodes)?;
    let all: &[GpuSstNode] = bytemuck::cast_slice(&bytes);
    Ok(all[..(2 * tree.leaves as usize).min(all.len())].to_vec())
}

/// Reads the usable bits back (word w holds nodes 32w .. 32w+31).
pub fn read_flags(ctx: &GpuContext, tree: &TreeBuffers) -> Result<Vec<u32>, GpuError> {
    let bytes = readback::read_storage_buffer(ctx, &tree.flags)?;
    let all: &[u32] = bytemuck::cast_slice(&bytes);
    Ok(all[..((2 * tree.leaves as usize).div_ceil(32)).min(all.len())].to_vec())
}

/// Reads the VPLs in leaf order back.
pub fn read_sorted_vpls(ctx: &GpuContext, tree: &TreeBuffers) -> Result<Vec<GpuVpl>, GpuError> {
    let bytes = readback::read_storage_buffer(ctx, &tree.sorted_vpls)?;
    Ok(bytemuck::cast_slice(&bytes).to_vec())
}

//! The `#[repr(C)]` records that the GPU, the renderer and the CPU references share: a VPL
//! and a light-tree node. Their WGSL twins are checked by the naga layout test in
//! `renderer::gpu_data`.

use bytemuck::{Pod, Zeroable};

/// Twin: `Vpl` in `shaders/common/vpl.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuVpl {
    /// xyz = position, w = pmf of its texel.
    pub position: [f32; 4],
    pub normal: [f32; 3],
    /// light layer << 24 | texel index, a light-path id ([`vpl_path_id`]), or `VPL_NONE`.
    pub id: u32,
    /// rgb = flux (W), w = 1 when valid.
    pub flux: [f32; 4],
}

pub const VPL_NONE: u32 = u32::MAX;
/// The bit that marks a light-path VPL's id (bounce >= 2): `PATH_BIT | bounce << 24 | path`.
/// Twin: `VPL_PATH_BIT` in `shaders/common/vpl.wgsl`.
pub const VPL_PATH_BIT: u32 = 0x8000_0000;

/// The id of light path `path`'s VPL at `bounce` (>= 2).
pub fn vpl_path_id(bounce: u32, path: u32) -> u32 {
    VPL_PATH_BIT | (bounce << 24) | path
}

/// The diffuse bounce a VPL's light has made: 1 for an RSM VPL (`layer << 24 | texel`), 2..
/// for a light-path VPL, 0 for `VPL_NONE`.
pub fn vpl_bounce(id: u32) -> u32 {
    if id == VPL_NONE {
        0
    } else if id & VPL_PATH_BIT != 0 {
        (id >> 24) & 0x7f
    } else {
        1
    }
}

/// A node of the Stochastic Substitute Tree, 64 bytes (one cache line; the SST paper's node
/// is 96 B, RTSLC's 32 B). Twin: `SstNode` in `shaders/common/sst_node.wgsl`; decoded by
/// `reference::sst_tree::SstNode::decode`.
///
/// | bytes | field |
/// |---|---|
/// | 0-11 | intensity-weighted position (eq. 4.1), f32 x 3 |
/// | 12-15 | normal similarity v (eq. 4.3), f32 |
/// | 16-27 | summed RGB flux of the cluster (W), f32 x 3 |
/// | 28-31 | normal, octahedral, 2 x 16 bits (x low; u = round(32767 v) + 32767) |
/// | 32-43 | bounding box min, f32 x 3 (+f32::MAX for an empty node) |
/// | 44-47 | variance along the normal sigma_z^2 (eq. 4.2), f32 |
/// | 48-59 | bounding box max, f32 x 3 (-f32::MAX for an empty node) |
/// | 60-63 | variances along tangent and bitangent, 2 x f16 (x low) |
///
/// The "usable for sampling" flag lives outside the node, one bit per node in a separate
/// word array, so that a change of v_min / sigma_max only re-runs the classify pass.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuSstNode {
    pub position: [f32; 3],
    pub v: f32,
    pub intensity: [f32; 3],
    pub normal: u32,
    pub bbox_min: [f32; 3],
    pub var_z: f32,
    pub bbox_max: [f32; 3],
    pub var_xy: u32,
}

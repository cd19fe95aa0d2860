//! Plain-Rust CPU references of the GPU kernels (the "twins"), written for clarity, not speed.
//! Only tests use them (they live in the library so that integration tests can reach them);
//! they stand on `crate::base` alone. The CPU pieces the running workbench shares (display
//! encoding, colour maps, the node layout) live in `crate::base`, which is also the twin of
//! the display and visualise passes.
//!
//! | GPU kernel | reference |
//! |---|---|
//! | `gbuffer.wgsl` (raster) | [`gbuffer::raycast`]: a BVH ray through each pixel centre |
//! | `direct.wgsl` | [`direct::radiance`] with exact ray-traced visibility |
//! | `display.wgsl` | `base::display::encode` |
//! | `visualise.wgsl` (`vis_uint`) | `base::colormap::{id_color, false_color}` |
//! | `methods/lightcuts/{lc_build, lightcuts}.wgsl` | [`lightcuts::build`], [`lightcuts::lightcut`] (and the error bound) |
//! | `common/bvh_binary.wgsl` (`common/bvh.wgsl`) | `scene::bvh::Bvh::{closest_hit, any_hit}` (and brute force) |
//! | `common/bvh_wide.wgsl` | `scene::bvh::WideBvh::{closest_hit, any_hit}` |

pub mod brdf;
pub mod direct;
pub mod gbuffer;
pub mod gi;
pub mod interleave;
pub mod ism;
pub mod lbvh;
pub mod light_culling;
pub mod light_paths;
pub mod lightcut_interpolation;
pub mod lightcuts;
pub mod slc;
pub mod sst;
pub mod sst_tree;
pub mod surface;
pub mod temporal;
pub mod val;
pub mod vpl;

//! Plain-Rust CPU references of the GPU kernels, written for clarity, not speed. Only tests use
//! them (they live in the library so that integration tests can reach them).
//!
//! | GPU kernel | reference |
//! |---|---|
//! | `gbuffer.wgsl` (raster) | [`gbuffer::raycast`]: a BVH ray through each pixel centre |
//! | `direct.wgsl` | [`direct::radiance`] with exact ray-traced visibility |
//! | `display.wgsl` | [`display::encode`] |
//! | `visualise.wgsl` (`vis_uint`) | [`visualise::id_color`], [`visualise::false_color`] |
//! | `common/bvh.wgsl` | `scene::bvh::Bvh::{closest_hit, any_hit}` (and brute force) |

pub mod direct;
pub mod display;
pub mod gbuffer;
pub mod gi;
pub mod slc;
pub mod sst;
pub mod sst_tree;
pub mod visualise;
pub mod vpl;

//! The GPU layer below the methods: the device and its errors ([`context`]), WGSL sources and
//! their includes ([`shaders`]), kernels bound by name ([`kernel`]), the GPU records shared with
//! WGSL ([`gpu_data`]), the scene on the GPU ([`scene_gpu`]), the frame's shared passes
//! ([`passes`]) and targets ([`frame`]), readbacks, timestamps, the BVH tracer and the BRDF
//! probe, and the view descriptors ([`views`]). The methods and the orchestration
//! (`crate::renderer`) build on it; it names neither (`tests/method_coupling.rs` counts).

pub mod brdf_probe;
pub mod bvh_trace;
pub mod context;
pub mod frame;
pub mod gpu_data;
pub mod kernel;
pub mod passes;
pub mod readback;
pub mod scene_gpu;
pub mod shaders;
pub mod soak;
pub mod timing;
pub mod views;

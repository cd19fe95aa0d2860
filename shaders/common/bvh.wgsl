// The frames' BVH traversal: an alias. Shaders that trace rays through the scene include this
// file; it stands for common/bvh_binary.wgsl (the default layout: the faster one measured on an
// NVIDIA H200, docs/measurements/h200-2026-11-27-wide-bvh) or, with LIGHTCUT_BVH=wide, for
// common/bvh_wide.wgsl (`scene_gpu::BvhLayout`; `shaders::expand` picks the file, and
// `SceneGpu::new` uploads the matching buffers). Both have the same include contract.
#include "common/bvh_binary.wgsl"

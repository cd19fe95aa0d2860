// Visibility between a VPL (or RSM texel) and a surface point through the scene BVH.
// Contract: as common/bvh.wgsl (the includer declares `bvh_nodes` and `bvh_triangles`).
#include "common/bvh.wgsl"

// True when nothing blocks the segment between x and the VPL at pv, both end points moved
// `offset` along their normals (nx, nv) off their surfaces.
fn vpl_visible(pv: vec3<f32>, nv: vec3<f32>, x: vec3<f32>, nx: vec3<f32>, offset: f32) -> bool {
    return segment_visible(x + nx * offset, pv + nv * offset);
}

// True when nothing blocks the segment from o to e (end points already offset).
fn segment_visible(o: vec3<f32>, e: vec3<f32>) -> bool {
    return !bvh_any_hit(o, e - o, 1e-4, 1.0 - 1e-4);
}

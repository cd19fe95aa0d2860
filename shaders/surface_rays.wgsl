// Traces a buffer of rays and describes the surface each hit (common/surface.wgsl): the
// GPU-vs-CPU test of the light paths' hit surfaces. Rays as bvh_rays.wgsl's; a miss writes
// valid = 0 and material = 0xffffffff.
#include "common/bvh.wgsl"
#include "common/material.wgsl"
#include "common/surface.wgsl"

struct ProbeParams {
    lod: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(0) @binding(0) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(1) var<storage, read> bvh_triangles: array<BvhTriangle>;
// (origin, tmin, dir, tmax): `GpuRay`'s layout, as bvh_rays.wgsl's RayIn.
@group(0) @binding(2) var<storage, read> rays: array<BvhRay>;
@group(0) @binding(3) var<storage, read_write> out: array<Surface>;
@group(0) @binding(4) var<storage, read> scene_vertices: array<u32>;
@group(0) @binding(5) var<storage, read> scene_indices: array<u32>;
@group(0) @binding(6) var<storage, read> materials: array<MaterialGpu>;
@group(0) @binding(7) var textures: texture_2d_array<f32>;
@group(0) @binding(8) var<uniform> pp: ProbeParams;
// material.wgsl's fragment-shader sampling names it; this shader never samples.
@group(0) @binding(9) var tex_sampler: sampler;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i >= arrayLength(&rays) {
        return;
    }
    let r = rays[i];
    let h = bvh_closest_hit_ray(r);
    var s: Surface;
    s.material = 0xffffffffu;
    s.valid = 0u;
    if h.triangle != BVH_NO_HIT {
        s = surface_at(h.triangle, h.u, h.v, r.dir, pp.lod);
    }
    out[i] = s;
}

// The entry points of bvh_rays.wgsl and bvh_rays_wide.wgsl (their bindings and kernels):
// the including file first includes one BVH traversal.
struct RayIn {
    origin: vec4<f32>, // xyz origin, w tmin
    dir: vec4<f32>,    // xyz direction, w tmax
};

struct HitOut {
    t: f32,
    triangle: u32,
    u: f32,
    v: f32,
};

@group(0) @binding(0) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(1) var<storage, read> bvh_triangles: array<BvhTriangle>;
@group(0) @binding(2) var<storage, read> rays: array<RayIn>;
@group(0) @binding(3) var<storage, read_write> hits: array<HitOut>;

// Any-hit (shadow rays): triangle = 1 when occluded, 0 otherwise.
@compute @workgroup_size(64, 1, 1)
fn any_hit_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i >= arrayLength(&rays) {
        return;
    }
    let r = rays[i];
    let occluded = bvh_any_hit(r.origin.xyz, r.dir.xyz, r.origin.w, r.dir.w);
    hits[i] = HitOut(0.0, select(0u, 1u, occluded), 0.0, 0.0);
}

@compute @workgroup_size(64, 1, 1)
fn closest_hit_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i >= arrayLength(&rays) {
        return;
    }
    let r = rays[i];
    let h = bvh_closest_hit(r.origin.xyz, r.dir.xyz, r.origin.w, r.dir.w);
    hits[i] = HitOut(h.t, h.triangle, h.u, h.v);
}

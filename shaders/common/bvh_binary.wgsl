// The BINARY BVH traversal (Aila & Laine 2009 style, 32-byte nodes): the frames' default layout
// (common/bvh.wgsl is its alias); common/bvh_wide.wgsl is the compressed 8-wide alternative.
//
// INCLUDE CONTRACT
// ----------------
// This is an include file: it declares no bindings. The INCLUDING shader must declare, at
// module scope and with bindings of its choice, exactly these two storage arrays:
//
//     @group(G) @binding(B0) var<storage, read> bvh_nodes: array<BvhNode>;
//     @group(G) @binding(B1) var<storage, read> bvh_triangles: array<BvhTriangle>;
//
// filled with the bytes of `Bvh::nodes` / `Bvh::triangles` (src/scene/bvh/mod.rs, `bytemuck::cast_slice`).
// WGSL allows module-scope declarations to be used before they appear, so the declarations may
// come before or after this file's text. Every name declared here starts with `bvh_`, `Bvh` or
// `BVH_`.
//
// Functions:
//     fn bvh_any_hit(origin: vec3<f32>, dir: vec3<f32>, tmin: f32, tmax: f32) -> bool
//     fn bvh_closest_hit(origin: vec3<f32>, dir: vec3<f32>, tmin: f32, tmax: f32) -> BvhHit
//     fn bvh_intersect_triangle(tri: BvhTriangle, origin: vec3<f32>, dir: vec3<f32>,
//                               tmin: f32, tmax: f32) -> vec4<f32>
// Hits count only for tmin < t < tmax; `dir` need not be normalised (shadow rays: dir = to - from,
// tmin = eps, tmax = 1 - eps). There is no infinity literal in WGSL: pass e.g. 3.0e38 for an
// unbounded ray. bvh_closest_hit returns the hit with the smallest (t, original triangle index);
// BvhHit.triangle is the ORIGINAL triangle index, or BVH_NO_HIT (0xffffffffu) with t = tmax.
//
// The algorithm and the triangle arithmetic mirror `Bvh::traverse` / `intersect_triangle` in
// bvh.rs op for op (a GPU compiler may still fuse multiply-adds).
//
// LAYOUTS (byte for byte the Rust #[repr(C)] structs)
//   BvhNode (32 B) = GpuBvhNode: bmin.xyz, left_or_first | bmax.xyz, count_axis
//     count_axis & 3u == 3u  -> leaf with triangles [left_or_first, left_or_first + (count_axis >> 2u))
//     otherwise              -> interior, split axis = count_axis & 3u, left child = index + 1,
//                               right child = left_or_first
//   BvhTriangle (48 B) = GpuTriangle: v0.xyz, id | e1.xyz, pad | e2.xyz, pad   (e1 = v1 - v0, e2 = v2 - v0)

#include "common/bvh_triangle.wgsl"

struct BvhNode {
    bmin: vec3<f32>,
    left_or_first: u32,
    bmax: vec3<f32>,
    count_axis: u32,
}

// Must equal bvh::BVH_STACK_SIZE (the builder bounds the tree depth by it).
const BVH_STACK_SIZE: u32 = 32u;
const BVH_LEAF_TAG: u32 = 3u;

// Shared traversal; any_hit = true returns at the first hit (BvhHit.triangle != BVH_NO_HIT).
fn bvh_traverse(origin: vec3<f32>, dir: vec3<f32>, tmin: f32, tmax: f32, any_hit: bool) -> BvhHit {
    var best = BvhHit(tmax, BVH_NO_HIT, 0.0, 0.0);
    let inv = bvh_safe_inv(dir);
    let root = bvh_nodes[0];
    let rs = bvh_slab(root.bmin, root.bmax, origin, inv, tmin, tmax);
    if (!(rs.x <= rs.y)) {
        return best;
    }
    var stack: array<u32, BVH_STACK_SIZE>;
    var sp = 0u;
    var node = 0u;
    loop {
        let n = bvh_nodes[node];
        if ((n.count_axis & 3u) == BVH_LEAF_TAG) {
            let first = n.left_or_first;
            let end = first + (n.count_axis >> 2u);
            for (var i = first; i < end; i += 1u) {
                let tri = bvh_triangles[i];
                let h = bvh_intersect_triangle(tri, origin, dir, tmin, tmax);
                if (h.w != 0.0) {
                    if (any_hit) {
                        return BvhHit(h.x, tri.id, h.y, h.z);
                    }
                    if (h.x < best.t || (h.x == best.t && tri.id < best.triangle)) {
                        best = BvhHit(h.x, tri.id, h.y, h.z);
                    }
                }
            }
            if (sp == 0u) {
                break;
            }
            sp -= 1u;
            node = stack[sp];
            continue;
        }
        let li = node + 1u;
        let ri = n.left_or_first;
        let l = bvh_nodes[li];
        let r = bvh_nodes[ri];
        let ls = bvh_slab(l.bmin, l.bmax, origin, inv, tmin, best.t);
        let rs2 = bvh_slab(r.bmin, r.bmax, origin, inv, tmin, best.t);
        let hit_l = ls.x <= ls.y;
        let hit_r = rs2.x <= rs2.y;
        if (hit_l && hit_r) {
            if (rs2.x < ls.x) {
                stack[sp] = li;
                node = ri;
            } else {
                stack[sp] = ri;
                node = li;
            }
            sp += 1u;
        } else if (hit_l) {
            node = li;
        } else if (hit_r) {
            node = ri;
        } else {
            if (sp == 0u) {
                break;
            }
            sp -= 1u;
            node = stack[sp];
        }
    }
    return best;
}

// Occlusion test for shadow rays: any hit with tmin < t < tmax.
fn bvh_any_hit(origin: vec3<f32>, dir: vec3<f32>, tmin: f32, tmax: f32) -> bool {
    return bvh_traverse(origin, dir, tmin, tmax, true).triangle != BVH_NO_HIT;
}

// Closest hit with tmin < t < tmax; triangle == BVH_NO_HIT (and t == tmax) when nothing is hit.
fn bvh_closest_hit(origin: vec3<f32>, dir: vec3<f32>, tmin: f32, tmax: f32) -> BvhHit {
    return bvh_traverse(origin, dir, tmin, tmax, false);
}

// Convenience overload-style wrappers taking a BvhRay.
fn bvh_any_hit_ray(ray: BvhRay) -> bool {
    return bvh_any_hit(ray.origin, ray.dir, ray.tmin, ray.tmax);
}

fn bvh_closest_hit_ray(ray: BvhRay) -> BvhHit {
    return bvh_closest_hit(ray.origin, ray.dir, ray.tmin, ray.tmax);
}

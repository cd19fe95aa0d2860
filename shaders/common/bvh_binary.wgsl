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

struct BvhNode {
    bmin: vec3<f32>,
    left_or_first: u32,
    bmax: vec3<f32>,
    count_axis: u32,
}

struct BvhTriangle {
    v0: vec3<f32>,
    id: u32,
    e1: vec3<f32>,
    pad1: u32,
    e2: vec3<f32>,
    pad2: u32,
}

struct BvhRay {
    origin: vec3<f32>,
    tmin: f32,
    dir: vec3<f32>,
    tmax: f32,
}

struct BvhHit {
    t: f32,
    triangle: u32,
    u: f32,
    v: f32,
}

// Must equal bvh::BVH_STACK_SIZE (the builder bounds the tree depth by it).
const BVH_STACK_SIZE: u32 = 32u;
const BVH_NO_HIT: u32 = 0xffffffffu;
const BVH_LEAF_TAG: u32 = 3u;
const BVH_MIN_DIR: f32 = 1e-20;

// Moller-Trumbore; returns (t, u, v, 1.0) on a hit with tmin < t < tmax, else w = 0.0.
fn bvh_intersect_triangle(tri: BvhTriangle, origin: vec3<f32>, dir: vec3<f32>, tmin: f32, tmax: f32) -> vec4<f32> {
    let dx = dir.x;
    let dy = dir.y;
    let dz = dir.z;
    let e1x = tri.e1.x;
    let e1y = tri.e1.y;
    let e1z = tri.e1.z;
    let e2x = tri.e2.x;
    let e2y = tri.e2.y;
    let e2z = tri.e2.z;
    // pvec = cross(dir, e2)
    let px = dy * e2z - dz * e2y;
    let py = dz * e2x - dx * e2z;
    let pz = dx * e2y - dy * e2x;
    let det = e1x * px + e1y * py + e1z * pz;
    if (det == 0.0) {
        return vec4<f32>(0.0);
    }
    let inv_det = 1.0 / det;
    // tvec = origin - v0
    let tx = origin.x - tri.v0.x;
    let ty = origin.y - tri.v0.y;
    let tz = origin.z - tri.v0.z;
    let u = (tx * px + ty * py + tz * pz) * inv_det;
    if (!(u >= 0.0 && u <= 1.0)) {
        return vec4<f32>(0.0);
    }
    // qvec = cross(tvec, e1)
    let qx = ty * e1z - tz * e1y;
    let qy = tz * e1x - tx * e1z;
    let qz = tx * e1y - ty * e1x;
    let v = (dx * qx + dy * qy + dz * qz) * inv_det;
    if (!(v >= 0.0 && u + v <= 1.0)) {
        return vec4<f32>(0.0);
    }
    let t = (e2x * qx + e2y * qy + e2z * qz) * inv_det;
    if (!(t > tmin && t < tmax)) {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(t, u, v, 1.0);
}

// Inverse direction with components |d| < 1e-20 replaced by +-1e-20 (no inf/NaN in slab tests).
fn bvh_safe_inv(d: vec3<f32>) -> vec3<f32> {
    let s = select(vec3<f32>(BVH_MIN_DIR), vec3<f32>(-BVH_MIN_DIR), d < vec3<f32>(0.0));
    return vec3<f32>(1.0) / select(d, s, abs(d) < vec3<f32>(BVH_MIN_DIR));
}

// Slab test: (t_enter, t_exit) clipped to [tmin, tmax]; hit iff x <= y.
fn bvh_slab(bmin: vec3<f32>, bmax: vec3<f32>, origin: vec3<f32>, inv: vec3<f32>, tmin: f32, tmax: f32) -> vec2<f32> {
    let t0 = (bmin - origin) * inv;
    let t1 = (bmax - origin) * inv;
    let lo = min(t0, t1);
    let hi = max(t0, t1);
    let near = max(max(lo.x, lo.y), max(lo.z, tmin));
    let far = min(min(hi.x, hi.y), min(hi.z, tmax));
    return vec2<f32>(near, far);
}

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

// BVH traversal for shadow rays and ray casts (software ray tracing in compute shaders): the
// compressed 8-wide BVH of Ylitie, Karras & Laine 2017 (80-byte nodes with child boxes
// quantised to 8 bits per axis on a power-of-two grid, children ordered by ray octant),
// src/scene/bvh/wide.rs (`WideBvh`, whose CPU traversal this mirrors op for op).
//
// INCLUDE CONTRACT
// ----------------
// This is an include file: it declares no bindings. The INCLUDING shader must declare, at
// module scope and with bindings of its choice, exactly these two storage arrays:
//
//     @group(G) @binding(B0) var<storage, read> bvh_nodes: array<BvhNode>;
//     @group(G) @binding(B1) var<storage, read> bvh_triangles: array<BvhTriangle>;
//
// filled with the bytes of `WideBvh::nodes` / `WideBvh::triangles` (`SceneGpu::bvh_nodes` /
// `bvh_triangles`). WGSL allows module-scope declarations to be used before they appear, so the
// declarations may come before or after this file's text. Every name declared here starts with
// `bvh_`, `Bvh` or `BVH_`. common/bvh_binary.wgsl has the same contract over the binary BVH.
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
// LAYOUTS (byte for byte the Rust #[repr(C)] structs)
//   BvhNode (80 B) = GpuWideNode, read as five vec4<u32>:
//     w0 = origin.xyz (f32 bits), exponent bytes ex | ey << 8 | ez << 16 | imask << 24
//     w1 = child_base, tri_base, meta[0..4], meta[4..8]
//     w2 = qlo.x[0..4], qlo.x[4..8], qlo.y[0..4], qlo.y[4..8]
//     w3 = qlo.z[0..4], qlo.z[4..8], qhi.x[0..4], qhi.x[4..8]
//     w4 = qhi.y[0..4], qhi.y[4..8], qhi.z[0..4], qhi.z[4..8]
//   slot s: interior iff imask bit s (node child_base + popcount(imask below s)); else a leaf
//   iff meta[s] != 0 (triangles [tri_base + (meta & 31), + (meta >> 5))); else empty. Its box is
//   origin + q * 2^(e - 127) per axis (exact product, one rounding).
//   BvhTriangle (48 B) = GpuTriangle: v0.xyz, id | e1.xyz, pad | e2.xyz, pad   (e1 = v1 - v0, e2 = v2 - v0)

#include "common/bvh_triangle.wgsl"

struct BvhNode {
    w0: vec4<u32>,
    w1: vec4<u32>,
    w2: vec4<u32>,
    w3: vec4<u32>,
    w4: vec4<u32>,
}

// Must equal bvh::BVH_STACK_SIZE: one entry per level of the tree (the builder checks the depth).
const BVH_STACK_SIZE: u32 = 32u;

// Byte k (0..8) of a pair of words (lo = bytes 0..4, hi = bytes 4..8).
fn bvh_byte8(lo: u32, hi: u32, k: u32) -> u32 {
    return (select(lo, hi, k >= 4u) >> (8u * (k & 3u))) & 0xffu;
}

// Shared traversal; any_hit = true returns at the first hit (BvhHit.triangle != BVH_NO_HIT).
fn bvh_traverse(origin: vec3<f32>, dir: vec3<f32>, tmin: f32, tmax: f32, any_hit: bool) -> BvhHit {
    var best = BvhHit(tmax, BVH_NO_HIT, 0.0, 0.0);
    let inv = bvh_safe_inv(dir);
    let oct = select(0u, 1u, dir.x < 0.0) | select(0u, 2u, dir.y < 0.0) | select(0u, 4u, dir.z < 0.0);
    // (node << 8) | pending positions of its children: one entry per node on the current path.
    var stack: array<u32, BVH_STACK_SIZE>;
    var sp = 0u;
    var node = 0u;
    loop {
        let n = bvh_nodes[node];
        let grid = bitcast<vec3<f32>>(n.w0.xyz);
        let e = n.w0.w;
        let scale = vec3<f32>(
            bitcast<f32>((e & 0xffu) << 23u),
            bitcast<f32>(((e >> 8u) & 0xffu) << 23u),
            bitcast<f32>(((e >> 16u) & 0xffu) << 23u),
        );
        let imask = e >> 24u;
        var pending = 0u;
        // Triangles of the hit leaf children, as bits relative to tri_base (at most 32).
        var tris = 0u;
        for (var i = 0u; i < 8u; i += 1u) {
            let s = i ^ oct;
            let mbyte = bvh_byte8(n.w1.z, n.w1.w, s);
            let interior = ((imask >> s) & 1u) == 1u;
            if (!interior && mbyte == 0u) {
                continue;
            }
            let qlo = vec3<u32>(bvh_byte8(n.w2.x, n.w2.y, s), bvh_byte8(n.w2.z, n.w2.w, s), bvh_byte8(n.w3.x, n.w3.y, s));
            let qhi = vec3<u32>(bvh_byte8(n.w3.z, n.w3.w, s), bvh_byte8(n.w4.x, n.w4.y, s), bvh_byte8(n.w4.z, n.w4.w, s));
            let lo = grid + vec3<f32>(qlo) * scale;
            let hi = grid + vec3<f32>(qhi) * scale;
            let sl = bvh_slab(lo, hi, origin, inv, tmin, best.t);
            if (!(sl.x <= sl.y)) {
                continue;
            }
            if (interior) {
                pending |= 1u << i;
            } else {
                tris |= ((1u << (mbyte >> 5u)) - 1u) << (mbyte & 31u);
            }
        }
        // One flat loop over the node's hit triangles (threads of a subgroup stay together).
        loop {
            if (tris == 0u) {
                break;
            }
            let t = n.w1.y + firstTrailingBit(tris);
            tris &= tris - 1u;
            let tri = bvh_triangles[t];
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
        if (pending != 0u) {
            let i = firstTrailingBit(pending);
            let rest = pending & (pending - 1u);
            if (rest != 0u) {
                stack[sp] = (node << 8u) | rest;
                sp += 1u;
            }
            node = n.w1.x + countOneBits(imask & ((1u << (i ^ oct)) - 1u));
            continue;
        }
        if (sp == 0u) {
            break;
        }
        let top = stack[sp - 1u];
        let mask = top & 0xffu;
        let i = firstTrailingBit(mask);
        let rest = mask & (mask - 1u);
        if (rest == 0u) {
            sp -= 1u;
        } else {
            stack[sp - 1u] = (top & 0xffffff00u) | rest;
        }
        let parent = top >> 8u;
        let pimask = bvh_nodes[parent].w0.w >> 24u;
        node = bvh_nodes[parent].w1.x + countOneBits(pimask & ((1u << (i ^ oct)) - 1u));
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

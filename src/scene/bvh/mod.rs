//! Bounding volume hierarchy over world-space triangles, for shadow rays and ray casts.
//!
//! Hardware ray queries are not available, so the GPU traverses this BVH in a compute shader
//! (`shaders/common/bvh_binary.wgsl`, or the wide collapse of [`wide`]); this module builds it on the CPU, flattens it into GPU-ready
//! buffers and provides a CPU traversal that mirrors the WGSL one (plus brute-force references
//! for tests).
//!
//! # Build
//! Top-down binned SAH ([`SAH_BINS`] bins per axis over the centroid bounds, all three axes),
//! O(n log n). Leaves hold at most [`MAX_LEAF_TRIS`] triangles. The tree depth never exceeds
//! [`BVH_STACK_SIZE`]: once the SAH recursion gets close to that budget the builder switches to
//! object-median splits, which halve the triangle count per level.
//!
//! # Layout
//! * Nodes ([`GpuBvhNode`], 32 bytes) are in depth-first order: the left child of an interior
//!   node `i` is `i + 1`, the right child index is stored in the node. Node 0 is the root.
//! * Triangles ([`GpuTriangle`], 48 bytes) are reordered into leaf order so that every leaf
//!   references a contiguous range `[first, first + count)`; each carries its original index.
//! * Node boxes are padded outwards by a tiny scene-relative margin ([`BOX_PAD_REL`]) so that the
//!   (differently rounded) slab test can never reject a box whose triangle the triangle test
//!   hits. The BVH therefore returns exactly what a brute-force loop over
//!   [`intersect_triangle`] returns.
//!
//! # Traversal (CPU and WGSL, identical algorithm)
//! Root box test, then a loop with a fixed-size stack of [`BVH_STACK_SIZE`] node indices: at an
//! interior node both child boxes are slab-tested (inverse direction precomputed; direction
//! components with |d| < 1e-20 are replaced by +-1e-20 so no NaN can appear); the nearer hit
//! child is visited next, the farther is pushed. Closest-hit keeps the hit with the smallest
//! `(t, original triangle index)` pair (so ties are resolved independently of the traversal
//! order) and culls boxes against the current best `t` (inclusively); any-hit returns at the
//! first hit with `tmin < t < tmax`.

// The negated comparisons are deliberate: they reject NaN, exactly as the WGSL code does.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::manual_range_contains)]

mod build;
pub mod wide;

use build::*;
use std::time::Instant;
pub use wide::{GpuWideNode, TraceCounters, WideBvh};

use glam::{UVec3, Vec3, Vec3A};

use super::Aabb;

/// Capacity of the traversal stack (in node indices), shared with `bvh.wgsl`
/// (`const BVH_STACK_SIZE: u32`). The builder guarantees that the depth of every leaf (root =
/// depth 0) is at most this, and the traversal pushes at most one entry per level, so the stack
/// can never overflow.
pub const BVH_STACK_SIZE: usize = 32;
/// Maximum number of triangles in a leaf.
pub const MAX_LEAF_TRIS: usize = 4;
/// Number of SAH bins per axis.
pub const SAH_BINS: usize = 16;
/// Node boxes are padded by `BOX_PAD_REL * max |coordinate|` of the scene bounds (see module docs).
pub const BOX_PAD_REL: f32 = 4.0e-6;
/// Value of [`Hit::triangle`]-like fields (and of `BvhHit.triangle` in WGSL) meaning "no hit".
pub const NO_TRIANGLE: u32 = u32::MAX;

/// SAH cost of one traversal step (relative to one triangle test).
const SAH_TRAVERSAL_COST: f32 = 2.0;
/// SAH cost of one ray/triangle test.
const SAH_TRIANGLE_COST: f32 = 1.0;
/// Low two bits of [`GpuBvhNode::count_axis`] equal to this mark a leaf.
const LEAF_TAG: u32 = 3;
/// Directions components smaller than this in magnitude are replaced by +-this before inversion.
const MIN_DIR_COMPONENT: f32 = 1.0e-20;

/// One BVH node as stored in the GPU buffer (and used by the CPU traversal). 32 bytes:
///
/// | bytes  | field           | meaning                                                        |
/// |--------|-----------------|----------------------------------------------------------------|
/// | 0..12  | `min`           | box minimum (f32 x3)                                           |
/// | 12..16 | `left_or_first` | interior: index of the right child; leaf: first triangle index |
/// | 16..28 | `max`           | box maximum (f32 x3)                                           |
/// | 28..32 | `count_axis`    | bits 0..2: split axis 0/1/2, or 3 = leaf; bits 2..32: leaf triangle count |
///
/// Interior nodes: the left child is the next node (`index + 1`); `count_axis >> 2 == 0`.
/// Leaves: triangles `[left_or_first, left_or_first + (count_axis >> 2))` of
/// [`Bvh::triangles`]. An empty BVH is a single leaf with count 0.
///
/// WGSL: `struct BvhNode { bmin: vec3<f32>, left_or_first: u32, bmax: vec3<f32>, count_axis: u32 }`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable, Debug, PartialEq)]
pub struct GpuBvhNode {
    pub min: [f32; 3],
    pub left_or_first: u32,
    pub max: [f32; 3],
    pub count_axis: u32,
}

impl GpuBvhNode {
    pub fn leaf(b: &Aabb, first: u32, count: u32) -> Self {
        Self {
            min: b.min.to_array(),
            left_or_first: first,
            max: b.max.to_array(),
            count_axis: (count << 2) | LEAF_TAG,
        }
    }
    pub fn interior(b: &Aabb, right_child: u32, axis: u32) -> Self {
        debug_assert!(axis < 3);
        Self {
            min: b.min.to_array(),
            left_or_first: right_child,
            max: b.max.to_array(),
            count_axis: axis,
        }
    }
    #[inline(always)]
    pub fn is_leaf(&self) -> bool {
        self.count_axis & 3 == LEAF_TAG
    }
    /// Number of triangles of a leaf (0 for interior nodes).
    #[inline(always)]
    pub fn tri_count(&self) -> u32 {
        self.count_axis >> 2
    }
    /// Split axis of an interior node (3 for leaves).
    pub fn axis(&self) -> u32 {
        self.count_axis & 3
    }
    pub fn aabb(&self) -> Aabb {
        Aabb {
            min: Vec3::from_array(self.min),
            max: Vec3::from_array(self.max),
        }
    }
}

/// One triangle in leaf order, precomputed for Moller-Trumbore. 48 bytes:
///
/// | bytes  | field   | meaning                                    |
/// |--------|---------|--------------------------------------------|
/// | 0..12  | `v0`    | first vertex (f32 x3)                      |
/// | 12..16 | `id`    | original triangle index (u32)              |
/// | 16..28 | `e1`    | `v1 - v0` (f32 x3)                         |
/// | 28..32 | `_pad1` | zero (reserved)                            |
/// | 32..44 | `e2`    | `v2 - v0` (f32 x3)                         |
/// | 44..48 | `_pad2` | zero (reserved)                            |
///
/// WGSL: `struct BvhTriangle { v0: vec3<f32>, id: u32, e1: vec3<f32>, pad1: u32, e2: vec3<f32>, pad2: u32 }`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable, Debug, PartialEq)]
pub struct GpuTriangle {
    pub v0: [f32; 3],
    pub id: u32,
    pub e1: [f32; 3],
    pub _pad1: u32,
    pub e2: [f32; 3],
    pub _pad2: u32,
}

impl GpuTriangle {
    pub fn new(v0: Vec3, v1: Vec3, v2: Vec3, id: u32) -> Self {
        Self {
            v0: v0.to_array(),
            id,
            e1: (v1 - v0).to_array(),
            _pad1: 0,
            e2: (v2 - v0).to_array(),
            _pad2: 0,
        }
    }
    /// Triangle `t` of an indexed mesh.
    pub fn from_mesh(positions: &[Vec3], indices: &[u32], t: usize) -> Self {
        let i = &indices[3 * t..3 * t + 3];
        Self::new(
            positions[i[0] as usize],
            positions[i[1] as usize],
            positions[i[2] as usize],
            t as u32,
        )
    }
    /// The three corners (`v0 + e1`, `v0 + e2` recomputed, so possibly rounded).
    pub fn vertices(&self) -> [Vec3; 3] {
        let v0 = Vec3::from_array(self.v0);
        [v0, v0 + Vec3::from_array(self.e1), v0 + Vec3::from_array(self.e2)]
    }
}

/// A ray (or segment): points `origin + t * dir` with `tmin < t < tmax`. `dir` need not be
/// normalised.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
    pub tmin: f32,
    pub tmax: f32,
}

impl Ray {
    pub fn new(origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Self {
        Self {
            origin,
            dir,
            tmin,
            tmax,
        }
    }
    /// Shadow-ray style segment from `from` to `to`: `dir = to - from`, `tmin = eps`,
    /// `tmax = 1 - eps`.
    pub fn segment(from: Vec3, to: Vec3, eps: f32) -> Self {
        Self::new(from, to - from, eps, 1.0 - eps)
    }
}

/// A ray hit: parameter `t`, ORIGINAL triangle index and barycentrics (`u` weights `v1`, `v`
/// weights `v2`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub triangle: u32,
    pub u: f32,
    pub v: f32,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct BvhStats {
    pub nodes: usize,
    pub leaves: usize,
    /// Depth of the deepest leaf (root = 0); always `<= BVH_STACK_SIZE`.
    pub depth: usize,
    pub max_leaf_tris: usize,
    /// SAH cost of the tree: sum over interior nodes of `area * C_trav` plus sum over leaves of
    /// `area * count * C_tri`, divided by the root area (C_trav = 2, C_tri = 1).
    pub sah_cost: f32,
    pub build_ms: f64,
}

/// A ray as a GPU buffer element (WGSL `struct BvhRay { origin: vec3<f32>, tmin: f32,
/// dir: vec3<f32>, tmax: f32 }`, 32 bytes), for tests and benchmarks that feed rays to shaders.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable, Debug, PartialEq)]
pub struct GpuRay {
    pub origin: [f32; 3],
    pub tmin: f32,
    pub dir: [f32; 3],
    pub tmax: f32,
}

impl From<&Ray> for GpuRay {
    fn from(r: &Ray) -> Self {
        Self {
            origin: r.origin.to_array(),
            tmin: r.tmin,
            dir: r.dir.to_array(),
            tmax: r.tmax,
        }
    }
}

/// WGSL `struct BvhHit { t: f32, triangle: u32, u: f32, v: f32 }` (16 bytes) as read back from
/// a GPU buffer; `triangle == NO_TRIANGLE` means no hit (then `t` is the ray's `tmax`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable, Debug, PartialEq)]
pub struct GpuBvhHit {
    pub t: f32,
    pub triangle: u32,
    pub u: f32,
    pub v: f32,
}

impl GpuBvhHit {
    pub fn to_hit(&self) -> Option<Hit> {
        (self.triangle != NO_TRIANGLE).then_some(Hit {
            t: self.t,
            triangle: self.triangle,
            u: self.u,
            v: self.v,
        })
    }
}

/// The flattened BVH: GPU-ready node and triangle arrays plus build statistics.
#[derive(Clone, Debug)]
pub struct Bvh {
    pub nodes: Vec<GpuBvhNode>,
    pub triangles: Vec<GpuTriangle>,
    pub stats: BvhStats,
    bounds: Aabb,
}

// ------------------------------------------------------------------------------------------
// Intersection primitives (mirrored op for op in bvh.wgsl)
// ------------------------------------------------------------------------------------------

/// Ray/triangle intersection (Moller-Trumbore), returning `(t, u, v)` for a hit with
/// `tmin < t < tmax`. Exactly the arithmetic of `bvh_intersect_triangle` in `bvh.wgsl`, in the
/// same order (no fused multiply-adds on the CPU; a GPU compiler may still contract).
/// Degenerate triangles and rays parallel to the plane (`det == 0`) never hit; NaNs never hit.
#[inline(always)]
pub fn intersect_triangle(tri: &GpuTriangle, ray: &Ray) -> Option<(f32, f32, f32)> {
    let (dx, dy, dz) = (ray.dir.x, ray.dir.y, ray.dir.z);
    let [e1x, e1y, e1z] = tri.e1;
    let [e2x, e2y, e2z] = tri.e2;
    // pvec = cross(dir, e2)
    let px = dy * e2z - dz * e2y;
    let py = dz * e2x - dx * e2z;
    let pz = dx * e2y - dy * e2x;
    let det = e1x * px + e1y * py + e1z * pz;
    if det == 0.0 {
        return None;
    }
    let inv_det = 1.0 / det;
    // tvec = origin - v0
    let tx = ray.origin.x - tri.v0[0];
    let ty = ray.origin.y - tri.v0[1];
    let tz = ray.origin.z - tri.v0[2];
    let u = (tx * px + ty * py + tz * pz) * inv_det;
    if !(u >= 0.0 && u <= 1.0) {
        return None;
    }
    // qvec = cross(tvec, e1)
    let qx = ty * e1z - tz * e1y;
    let qy = tz * e1x - tx * e1z;
    let qz = tx * e1y - ty * e1x;
    let v = (dx * qx + dy * qy + dz * qz) * inv_det;
    if !(v >= 0.0 && u + v <= 1.0) {
        return None;
    }
    let t = (e2x * qx + e2y * qy + e2z * qz) * inv_det;
    if !(t > ray.tmin && t < ray.tmax) {
        return None;
    }
    Some((t, u, v))
}

/// Inverse direction for slab tests, with tiny components replaced by +-1e-20 (no inf, no NaN).
#[inline(always)]
fn safe_inv(d: Vec3) -> Vec3 {
    let f = |x: f32| {
        let s = if x < 0.0 {
            -MIN_DIR_COMPONENT
        } else {
            MIN_DIR_COMPONENT
        };
        1.0 / if x.abs() < MIN_DIR_COMPONENT { s } else { x }
    };
    Vec3::new(f(d.x), f(d.y), f(d.z))
}

/// Slab test: `(t_enter, t_exit)` clipped to `[tmin, tmax]`; the box is hit iff `enter <= exit`.
/// Same per-component arithmetic as `bvh_slab` in WGSL (min/max are exact, so the SIMD
/// evaluation order gives identical values).
#[inline(always)]
fn slab(n: &GpuBvhNode, o: Vec3A, inv: Vec3A, tmin: f32, tmax: f32) -> (f32, f32) {
    slab_box(
        Vec3A::from_array(n.min),
        Vec3A::from_array(n.max),
        o,
        inv,
        tmin,
        tmax,
    )
}

/// [`slab`] on a box's corners (`bvh_slab` in `common/bvh_triangle.wgsl`; the wide BVH's
/// decoded child boxes).
#[inline(always)]
fn slab_box(lo: Vec3A, hi: Vec3A, o: Vec3A, inv: Vec3A, tmin: f32, tmax: f32) -> (f32, f32) {
    let t0 = (lo - o) * inv;
    let t1 = (hi - o) * inv;
    let near = t0.min(t1).max_element().max(tmin);
    let far = t0.max(t1).min_element().min(tmax);
    (near, far)
}

/// `a` is a better closest hit than `b` (smaller `t`, ties broken by smaller original index).
#[inline(always)]
fn better(t: f32, id: u32, best_t: f32, best_id: u32) -> bool {
    t < best_t || (t == best_t && id < best_id)
}

impl GpuBvhNode {
    fn zeroed_node() -> Self {
        bytemuck::Zeroable::zeroed()
    }
}

impl Bvh {
    /// Builds a BVH over the triangles `indices[3i..3i+3]` (a trailing partial triangle is
    /// ignored). Handles 0 triangles (a single empty leaf) and degenerate triangles (they are
    /// stored but never hit). Panics on out-of-range indices.
    pub fn build(positions: &[Vec3], indices: &[u32]) -> Bvh {
        let t0 = Instant::now();
        let tri_count = indices.len() / 3;
        assert!(
            tri_count < (1usize << 30),
            "too many triangles for the BVH encoding"
        );

        let mut scene = Aabb::EMPTY;
        let prims: Vec<PrimRef> = indices
            .chunks_exact(3)
            .enumerate()
            .map(|(i, tri)| {
                let a = Vec3A::from(positions[tri[0] as usize]);
                let b = Vec3A::from(positions[tri[1] as usize]);
                let c = Vec3A::from(positions[tri[2] as usize]);
                PrimRef {
                    min: a.min(b).min(c),
                    max: a.max(b).max(c),
                    id: i as u32,
                }
            })
            .collect();
        for p in &prims {
            scene.grow(p.min.into());
            scene.grow(p.max.into());
        }

        let mut b = Builder {
            prims,
            nodes: Vec::with_capacity((2 * tri_count).div_ceil(MAX_LEAF_TRIS).max(1) * 2),
            leaves: 0,
            depth: 0,
            max_leaf: 0,
        };
        b.build_node(0, tri_count, 0);

        let triangles: Vec<GpuTriangle> = b
            .prims
            .iter()
            .map(|p| GpuTriangle::from_mesh(positions, indices, p.id as usize))
            .collect();

        // SAH cost of the unpadded tree.
        let mut sah = 0.0f64;
        let root_area = b.nodes[0].aabb().surface_area() as f64;
        if root_area > 0.0 {
            for n in &b.nodes {
                let a = n.aabb().surface_area() as f64;
                sah += if n.is_leaf() {
                    a * n.tri_count() as f64 * SAH_TRIANGLE_COST as f64
                } else {
                    a * SAH_TRAVERSAL_COST as f64
                };
            }
            sah /= root_area;
        }

        // Pad every box by one global, scene-relative margin (keeps parents containing children).
        if !scene.is_empty() {
            let pad = BOX_PAD_REL * scene.min.abs().max(scene.max.abs()).max_element();
            for n in &mut b.nodes {
                for k in 0..3 {
                    n.min[k] -= pad;
                    n.max[k] += pad;
                }
            }
        }

        let stats = BvhStats {
            nodes: b.nodes.len(),
            leaves: b.leaves,
            depth: b.depth,
            max_leaf_tris: b.max_leaf,
            sah_cost: sah as f32,
            build_ms: t0.elapsed().as_secs_f64() * 1e3,
        };
        Bvh {
            nodes: b.nodes,
            triangles,
            stats,
            bounds: scene,
        }
    }

    /// Bounds of all triangles (unpadded; `Aabb::EMPTY` for an empty BVH).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Closest hit with `tmin < t < tmax` (ties in `t` go to the smaller original index).
    pub fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.traverse::<false, false>(ray, &mut TraceCounters::default())
    }

    /// Occlusion test for shadow rays: is there any hit with `tmin < t < tmax`?
    pub fn any_hit(&self, ray: &Ray) -> bool {
        self.traverse::<true, false>(ray, &mut TraceCounters::default())
            .is_some()
    }

    /// [`Self::any_hit`] / [`Self::closest_hit`] counting what the traversal reads: every
    /// visit reads its node (32 bytes), an interior visit also both children's boxes (64
    /// bytes), a leaf its triangles (48 bytes each) — what `bvh_binary.wgsl` loads.
    pub fn trace_counted(&self, ray: &Ray, any: bool, c: &mut TraceCounters) -> Option<Hit> {
        if any {
            self.traverse::<true, true>(ray, c)
        } else {
            self.traverse::<false, true>(ray, c)
        }
    }

    /// The traversal loop of `bvh_binary.wgsl` (`bvh_closest_hit` / `bvh_any_hit`).
    #[inline(always)]
    fn traverse<const ANY: bool, const COUNT: bool>(&self, ray: &Ray, c: &mut TraceCounters) -> Option<Hit> {
        let nodes = &self.nodes[..];
        if COUNT {
            c.rays += 1;
            c.boxes += 1;
            c.bytes += wide::BINARY_NODE_BYTES as u64;
        }
        let o = Vec3A::from(ray.origin);
        let inv = Vec3A::from(safe_inv(ray.dir));
        let mut best = Hit {
            t: ray.tmax,
            triangle: NO_TRIANGLE,
            u: 0.0,
            v: 0.0,
        };
        let (near, far) = slab(&nodes[0], o, inv, ray.tmin, ray.tmax);
        if !(near <= far) {
            return None;
        }
        let mut stack = [0u32; BVH_STACK_SIZE];
        let mut sp = 0usize;
        let mut node = 0usize;
        loop {
            let n = &nodes[node];
            if COUNT {
                c.nodes += 1;
                c.bytes += wide::BINARY_NODE_BYTES as u64;
            }
            if n.is_leaf() {
                let first = n.left_or_first as usize;
                let end = first + n.tri_count() as usize;
                for tri in &self.triangles[first..end] {
                    if COUNT {
                        c.triangles += 1;
                        c.bytes += wide::TRIANGLE_BYTES as u64;
                    }
                    if let Some((t, u, v)) = intersect_triangle(tri, ray) {
                        if ANY {
                            return Some(Hit {
                                t,
                                triangle: tri.id,
                                u,
                                v,
                            });
                        }
                        if better(t, tri.id, best.t, best.triangle) {
                            best = Hit {
                                t,
                                triangle: tri.id,
                                u,
                                v,
                            };
                        }
                    }
                }
                if sp == 0 {
                    break;
                }
                sp -= 1;
                node = stack[sp] as usize;
                continue;
            }
            let li = node + 1;
            let ri = n.left_or_first as usize;
            if COUNT {
                c.boxes += 2;
                c.bytes += 2 * wide::BINARY_NODE_BYTES as u64;
            }
            let (ln, lf) = slab(&nodes[li], o, inv, ray.tmin, best.t);
            let (rn, rf) = slab(&nodes[ri], o, inv, ray.tmin, best.t);
            let hit_l = ln <= lf;
            let hit_r = rn <= rf;
            if hit_l && hit_r {
                let (first, second) = if rn < ln { (ri, li) } else { (li, ri) };
                stack[sp] = second as u32;
                sp += 1;
                if COUNT {
                    c.max_stack = c.max_stack.max(sp as u64);
                }
                node = first;
            } else if hit_l {
                node = li;
            } else if hit_r {
                node = ri;
            } else {
                if sp == 0 {
                    break;
                }
                sp -= 1;
                node = stack[sp] as usize;
            }
        }
        (best.triangle != NO_TRIANGLE).then_some(best)
    }
}

// ------------------------------------------------------------------------------------------
// References and shared test rays
// ------------------------------------------------------------------------------------------

/// Closest hit by testing every triangle (same tie rule as [`Bvh::closest_hit`]).
pub fn brute_force_closest(positions: &[Vec3], indices: &[u32], ray: &Ray) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    for t in 0..indices.len() / 3 {
        let tri = GpuTriangle::from_mesh(positions, indices, t);
        if let Some((th, u, v)) = intersect_triangle(&tri, ray)
            && best.is_none_or(|b| better(th, tri.id, b.t, b.triangle))
        {
            best = Some(Hit {
                t: th,
                triangle: tri.id,
                u,
                v,
            });
        }
    }
    best
}

/// Any hit with `tmin < t < tmax`, by testing every triangle.
pub fn brute_force_any(positions: &[Vec3], indices: &[u32], ray: &Ray) -> bool {
    (0..indices.len() / 3)
        .any(|t| intersect_triangle(&GpuTriangle::from_mesh(positions, indices, t), ray).is_some())
}

/// Small deterministic PCG32 generator (the main crate has `rand` only as a dev-dependency).
#[derive(Clone, Debug)]
pub struct Pcg32 {
    state: u64,
    inc: u64,
}

impl Pcg32 {
    pub fn new(seed: u64) -> Self {
        let mut r = Self {
            state: 0,
            inc: (seed << 1) | 1,
        };
        r.next_u32();
        r.state = r.state.wrapping_add(seed ^ 0x853c_49e6_748f_ea9b);
        r.next_u32();
        r
    }
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        xorshifted.rotate_right((old >> 59) as u32)
    }
    /// Uniform in `[0, 1)`.
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }
    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next_f32()
    }
    /// Uniform point in the box.
    pub fn point_in(&mut self, b: &Aabb) -> Vec3 {
        Vec3::new(
            self.range(b.min.x, b.max.x),
            self.range(b.min.y, b.max.y),
            self.range(b.min.z, b.max.z),
        )
    }
}

/// `n` deterministic shadow-ray segments between two uniform random points of `bounds`
/// (`dir = to - from` unnormalised, `tmin = 1e-4`, `tmax = 1 - 1e-4`). Shared by the
/// GPU-vs-CPU tests and the rays/second benchmark. An empty `bounds` gives segments inside the
/// unit cube.
pub fn random_shadow_rays(bounds: &Aabb, n: usize, seed: u64) -> Vec<Ray> {
    let b = if bounds.is_empty() {
        Aabb {
            min: Vec3::ZERO,
            max: Vec3::ONE,
        }
    } else {
        *bounds
    };
    let mut rng = Pcg32::new(seed);
    (0..n)
        .map(|_| {
            let from = rng.point_in(&b);
            let to = rng.point_in(&b);
            Ray::segment(from, to, 1.0e-4)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Mesh {
        positions: Vec<Vec3>,
        indices: Vec<u32>,
    }

    impl Mesh {
        fn new() -> Self {
            Self {
                positions: Vec::new(),
                indices: Vec::new(),
            }
        }
        fn tri(&mut self, a: Vec3, b: Vec3, c: Vec3) {
            let n = self.positions.len() as u32;
            self.positions.extend([a, b, c]);
            self.indices.extend([n, n + 1, n + 2]);
        }
        fn quad(&mut self, a: Vec3, b: Vec3, c: Vec3, d: Vec3) {
            self.tri(a, b, c);
            self.tri(a, c, d);
        }
        /// Axis-aligned box (12 triangles); `lo == hi` on an axis gives a flat box.
        fn cuboid(&mut self, lo: Vec3, hi: Vec3) {
            let p = |x: bool, y: bool, z: bool| {
                Vec3::new(
                    if x { hi.x } else { lo.x },
                    if y { hi.y } else { lo.y },
                    if z { hi.z } else { lo.z },
                )
            };
            let (f, t) = (false, true);
            self.quad(p(f, f, f), p(t, f, f), p(t, t, f), p(f, t, f));
            self.quad(p(f, f, t), p(f, t, t), p(t, t, t), p(t, f, t));
            self.quad(p(f, f, f), p(f, t, f), p(f, t, t), p(f, f, t));
            self.quad(p(t, f, f), p(t, f, t), p(t, t, t), p(t, t, f));
            self.quad(p(f, f, f), p(f, f, t), p(t, f, t), p(t, f, f));
            self.quad(p(f, t, f), p(t, t, f), p(t, t, t), p(f, t, t));
        }
        fn bounds(&self) -> Aabb {
            let mut b = Aabb::EMPTY;
            for &p in &self.positions {
                b.grow(p);
            }
            b
        }
    }

    fn random_dir(rng: &mut Pcg32) -> Vec3 {
        loop {
            let d = Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
            let l = d.length_squared();
            if l > 1e-4 && l <= 1.0 {
                return d / l.sqrt();
            }
        }
    }

    fn random_soup(n: usize, seed: u64) -> Mesh {
        let mut rng = Pcg32::new(seed);
        let mut m = Mesh::new();
        for i in 0..n {
            let c = Vec3::new(
                rng.range(-10.0, 10.0),
                rng.range(-10.0, 10.0),
                rng.range(-10.0, 10.0),
            );
            // Mostly small triangles, some large ones.
            let s = if i % 50 == 0 {
                rng.range(2.0, 8.0)
            } else {
                rng.range(0.05, 1.0)
            };
            let a = c + s * random_dir(&mut rng);
            let b = c + s * random_dir(&mut rng);
            let d = c + s * random_dir(&mut rng);
            m.tri(a, b, d);
        }
        m
    }

    /// Floors, walls, boxes, coplanar overlapping layers, flat boxes and slivers: lots of
    /// axis-aligned and coplanar triangles with shared edges at integer coordinates.
    fn grid_scene() -> Mesh {
        let mut m = Mesh::new();
        let v = Vec3::new;
        // Floor y = 0: 16x16 unit quads.
        for x in -8..8 {
            for z in -8..8 {
                let (x, z) = (x as f32, z as f32);
                m.quad(
                    v(x, 0.0, z),
                    v(x + 1.0, 0.0, z),
                    v(x + 1.0, 0.0, z + 1.0),
                    v(x, 0.0, z + 1.0),
                );
            }
        }
        // A coplanar, overlapping second floor layer with 2x2 quads offset by 0.5.
        for x in -4..3 {
            for z in -4..3 {
                let (x, z) = (2.0 * x as f32 + 0.5, 2.0 * z as f32 + 0.5);
                m.quad(
                    v(x, 0.0, z),
                    v(x, 0.0, z + 2.0),
                    v(x + 2.0, 0.0, z + 2.0),
                    v(x + 2.0, 0.0, z),
                );
            }
        }
        // Walls x = -8 and z = 8, and a ceiling y = 6 made of long thin strips.
        for i in -8..8 {
            let i = i as f32;
            m.quad(
                v(-8.0, 0.0, i),
                v(-8.0, 6.0, i),
                v(-8.0, 6.0, i + 1.0),
                v(-8.0, 0.0, i + 1.0),
            );
            m.quad(
                v(i, 0.0, 8.0),
                v(i + 1.0, 0.0, 8.0),
                v(i + 1.0, 6.0, 8.0),
                v(i, 6.0, 8.0),
            );
            m.quad(
                v(-8.0, 6.0, i),
                v(8.0, 6.0, i),
                v(8.0, 6.0, i + 0.5),
                v(-8.0, 6.0, i + 0.5),
            );
        }
        // Boxes on integer coordinates (some touching each other and the floor).
        for (lo, hi) in [
            (v(-2.0, 0.0, -2.0), v(0.0, 2.0, 0.0)),
            (v(0.0, 0.0, -2.0), v(1.0, 1.0, -1.0)),
            (v(3.0, 0.0, 3.0), v(5.0, 4.0, 4.0)),
            (v(-6.0, 1.0, 2.0), v(-5.0, 3.0, 6.0)),
            (v(2.0, 0.0, -6.0), v(2.0, 3.0, -3.0)), // flat (zero thickness in x)
            (v(-4.0, 2.5, -5.0), v(-1.0, 2.5, -4.0)), // flat (zero thickness in y)
            (v(0.0, 0.0, -2.0), v(1.0, 1.0, -1.0)), // exact duplicate
        ] {
            m.cuboid(lo, hi);
        }
        // Slivers and needles.
        for i in 0..40 {
            let x = -7.5 + 0.37 * i as f32;
            m.tri(v(x, 0.5, -7.0), v(x + 1e-4, 0.5, -7.0), v(x, 3.5, -6.0));
            m.tri(v(x, 1.0, 7.0), v(x + 3.0, 1.0 + 1e-5, 7.0), v(x + 6.0, 1.0, 7.0));
            m.tri(v(x, 4.0, 0.0), v(x + 2.0, 4.0, 0.0), v(x + 1.0, 4.0, 1e-3));
        }
        // Degenerate triangles mixed in (a point and a line).
        m.tri(v(1.0, 1.0, 1.0), v(1.0, 1.0, 1.0), v(1.0, 1.0, 1.0));
        m.tri(v(0.0, 1.0, 0.0), v(1.0, 2.0, 3.0), v(2.0, 3.0, 6.0));
        m
    }

    /// A mix of ray kinds: random unit directions, exactly axis-aligned directions, directions
    /// with one or two zero components, grid-snapped origins, finite `tmax`, and shadow-ray
    /// segments between two points.
    fn test_rays(bounds: &Aabb, n: usize, seed: u64) -> Vec<Ray> {
        let mut rng = Pcg32::new(seed);
        let b = if bounds.is_empty() {
            Aabb {
                min: Vec3::splat(-1.0),
                max: Vec3::splat(1.0),
            }
        } else {
            *bounds
        };
        let margin = 0.1 * b.extent().max_element().max(1e-3);
        let outer = Aabb {
            min: b.min - Vec3::splat(margin),
            max: b.max + Vec3::splat(margin),
        };
        let axes = [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z];
        (0..n)
            .map(|i| {
                let mut o = rng.point_in(&outer);
                match i % 7 {
                    0 => Ray::new(o, random_dir(&mut rng), 0.0, f32::INFINITY),
                    1 => {
                        let d = axes[(rng.next_u32() % 6) as usize];
                        Ray::new(o, d, 0.0, f32::INFINITY)
                    }
                    2 => {
                        // One or two exactly-zero components.
                        let mut d = random_dir(&mut rng);
                        let k = (rng.next_u32() % 3) as usize;
                        d[k] = 0.0;
                        if rng.next_u32().is_multiple_of(2) {
                            d[(k + 1) % 3] = -0.0;
                        }
                        if d == Vec3::ZERO {
                            d = Vec3::Y;
                        }
                        Ray::new(o, d, 0.0, f32::INFINITY)
                    }
                    3 => {
                        // Grid-snapped origin (on planes/edges of the grid scene).
                        o = (o * 2.0).round() * 0.5;
                        let d = if rng.next_u32().is_multiple_of(2) {
                            axes[(rng.next_u32() % 6) as usize]
                        } else {
                            Vec3::new(
                                (rng.next_u32() % 3) as f32 - 1.0,
                                (rng.next_u32() % 3) as f32 - 1.0,
                                (rng.next_u32() % 3) as f32 - 1.0,
                            )
                        };
                        Ray::new(o, d, 1e-4, f32::INFINITY)
                    }
                    4 => {
                        let d = random_dir(&mut rng);
                        let tmax = rng.range(0.0, b.extent().max_element().max(1.0));
                        Ray::new(o, d, 0.0, tmax)
                    }
                    _ => {
                        let from = rng.point_in(&b);
                        let to = rng.point_in(&b);
                        Ray::segment(from, to, 1e-4)
                    }
                }
            })
            .collect()
    }

    /// Asserts BVH == brute force for every ray; returns (closest hits, any hits).
    /// The binary BVH and its wide collapse against brute force: identical hits, bit for bit.
    fn check_against_brute_force(m: &Mesh, bvh: &Bvh, rays: &[Ray]) -> (usize, usize) {
        let wide = WideBvh::from_binary(bvh);
        check_wide_structure(bvh, &wide);
        let (mut closest_hits, mut any_hits) = (0, 0);
        for (i, ray) in rays.iter().enumerate() {
            let got = bvh.closest_hit(ray);
            let want = brute_force_closest(&m.positions, &m.indices, ray);
            assert_eq!(wide.closest_hit(ray), want, "wide, ray {i} {ray:?}");
            assert_eq!(wide.any_hit(ray), want.is_some(), "wide any-hit, ray {i} {ray:?}");
            let mut c = TraceCounters::default();
            assert_eq!(wide.trace_counted(ray, false, &mut c), want, "counted, ray {i}");
            assert_eq!(bvh.trace_counted(ray, false, &mut c), want, "counted, ray {i}");
            assert_eq!(wide.trace_counted(ray, true, &mut c).is_some(), want.is_some());
            assert_eq!(bvh.trace_counted(ray, true, &mut c).is_some(), want.is_some());
            assert!(c.max_stack as usize <= BVH_STACK_SIZE);
            match (got, want) {
                (None, None) => {}
                (Some(g), Some(w)) => {
                    assert_eq!(g.triangle, w.triangle, "ray {i} {ray:?}: {g:?} vs {w:?}");
                    assert_eq!(g.t.to_bits(), w.t.to_bits(), "ray {i} {ray:?}");
                    assert_eq!((g.u, g.v), (w.u, w.v), "ray {i} {ray:?}");
                    closest_hits += 1;
                }
                _ => panic!("ray {i} {ray:?}: bvh {got:?} vs brute force {want:?}"),
            }
            let any = bvh.any_hit(ray);
            let want_any = brute_force_any(&m.positions, &m.indices, ray);
            assert_eq!(any, want_any, "any-hit ray {i} {ray:?}");
            assert_eq!(any, want.is_some(), "ray {i}: any-hit vs closest-hit");
            any_hits += any as usize;
        }
        (closest_hits, any_hits)
    }

    /// Every triangle once; every binary node's box inside the decoded box of the wide slot
    /// that stands for it (checked through the leaves: each leaf child's box contains its
    /// triangles); depth within the stack; children inside the parent's grid.
    fn check_wide_structure(bvh: &Bvh, wide: &WideBvh) {
        let mut ids: Vec<u32> = wide.triangles.iter().map(|t| t.id).collect();
        ids.sort_unstable();
        let mut want: Vec<u32> = bvh.triangles.iter().map(|t| t.id).collect();
        want.sort_unstable();
        assert_eq!(ids, want, "the wide BVH holds every triangle once");
        assert!(wide.stats.depth <= BVH_STACK_SIZE);
        let mut reached = vec![0u32; wide.nodes.len()];
        reached[0] = 1;
        for (i, n) in wide.nodes.iter().enumerate() {
            for s in 0..wide::WIDE {
                if !n.occupied(s) {
                    continue;
                }
                let (lo, hi) = n.child_box(s);
                assert!(lo.cmple(hi).all(), "node {i} slot {s}: inverted box");
                if (n.imask() >> s) & 1 == 1 {
                    let c = n.child_index(s as u32) as usize;
                    assert!(c > i && c < wide.nodes.len());
                    reached[c] += 1;
                } else {
                    let m = n.meta[s] as usize;
                    let first = n.tri_base as usize + (m & 31);
                    for t in &wide.triangles[first..first + (m >> 5)] {
                        for v in t.vertices() {
                            let v = Vec3A::from(v);
                            let slack = 1e-5 * v.abs().max_element().max(1.0);
                            assert!(
                                (lo - slack).cmple(v).all() && v.cmple(hi + slack).all(),
                                "node {i} slot {s}: triangle {} outside its box",
                                t.id
                            );
                        }
                    }
                }
            }
        }
        assert!(reached.iter().all(|&r| r == 1), "every node has one parent");
    }

    fn check_structure(m: &Mesh, bvh: &Bvh) {
        let n_tris = m.indices.len() / 3;
        assert_eq!(bvh.triangles.len(), n_tris);
        assert!(!bvh.nodes.is_empty());
        assert!(bvh.stats.depth <= BVH_STACK_SIZE, "depth {}", bvh.stats.depth);
        assert!(bvh.stats.max_leaf_tris <= MAX_LEAF_TRIS);
        assert_eq!(bvh.stats.nodes, bvh.nodes.len());

        let contains =
            |outer: &Aabb, inner: &Aabb| outer.min.cmple(inner.min).all() && inner.max.cmple(outer.max).all();
        let mut seen_tri = vec![0u32; n_tris];
        let mut seen_node = vec![0u32; bvh.nodes.len()];
        let (mut leaves, mut max_depth) = (0, 0);
        // Walk from the root; every node must be reached exactly once.
        let mut stack = vec![(0usize, 0usize)];
        while let Some((i, depth)) = stack.pop() {
            seen_node[i] += 1;
            let n = &bvh.nodes[i];
            let b = n.aabb();
            if n.is_leaf() {
                leaves += 1;
                max_depth = max_depth.max(depth);
                let count = n.tri_count() as usize;
                assert!(count <= MAX_LEAF_TRIS);
                assert!(count > 0 || n_tris == 0, "empty leaf in a non-empty tree");
                let first = n.left_or_first as usize;
                for tri in &bvh.triangles[first..first + count] {
                    let id = tri.id as usize;
                    seen_tri[id] += 1;
                    // Stored triangle equals the input one, and lies in the leaf box.
                    assert_eq!(*tri, GpuTriangle::from_mesh(&m.positions, &m.indices, id));
                    for k in 0..3 {
                        let p = m.positions[m.indices[3 * id + k] as usize];
                        assert!(contains(&b, &Aabb { min: p, max: p }), "node {i} tri {id}");
                    }
                }
            } else {
                assert!(n.axis() < 3);
                let (l, r) = (i + 1, n.left_or_first as usize);
                assert!(r > l && r < bvh.nodes.len(), "node {i}: children {l}, {r}");
                assert!(contains(&b, &bvh.nodes[l].aabb()), "node {i} left");
                assert!(contains(&b, &bvh.nodes[r].aabb()), "node {i} right");
                stack.push((r, depth + 1));
                stack.push((l, depth + 1));
            }
        }
        assert!(seen_node.iter().all(|&c| c == 1), "unreachable or shared nodes");
        assert!(
            seen_tri.iter().all(|&c| c == 1),
            "triangle not referenced exactly once"
        );
        assert_eq!(leaves, bvh.stats.leaves);
        assert_eq!(max_depth, bvh.stats.depth);
        if n_tris > 0 {
            let root = bvh.nodes[0].aabb();
            assert!(contains(&root, &bvh.bounds()));
            assert!(contains(&root, &m.bounds()));
        }
    }

    fn check_scene(m: &Mesh, n_rays: usize, seed: u64) -> (Bvh, usize, usize) {
        let bvh = Bvh::build(&m.positions, &m.indices);
        check_structure(m, &bvh);
        let mut rays = test_rays(&m.bounds(), n_rays, seed);
        rays.extend(random_shadow_rays(&m.bounds(), n_rays / 4, seed + 1));
        let (closest, any) = check_against_brute_force(m, &bvh, &rays);
        (bvh, closest, any)
    }

    #[test]
    fn gpu_struct_layouts() {
        assert_eq!(std::mem::size_of::<GpuBvhNode>(), 32);
        assert_eq!(std::mem::size_of::<GpuTriangle>(), 48);
        assert_eq!(std::mem::size_of::<GpuRay>(), 32);
        assert_eq!(std::mem::size_of::<GpuBvhHit>(), 16);
        assert_eq!(std::mem::offset_of!(GpuBvhNode, left_or_first), 12);
        assert_eq!(std::mem::offset_of!(GpuBvhNode, max), 16);
        assert_eq!(std::mem::offset_of!(GpuBvhNode, count_axis), 28);
        assert_eq!(std::mem::offset_of!(GpuTriangle, id), 12);
        assert_eq!(std::mem::offset_of!(GpuTriangle, e1), 16);
        assert_eq!(std::mem::offset_of!(GpuTriangle, e2), 32);
    }

    #[test]
    fn random_soup_matches_brute_force() {
        let m = random_soup(3000, 7);
        let (bvh, closest, any) = check_scene(&m, 4000, 11);
        assert!(bvh.stats.depth > 5 && bvh.stats.leaves > 500, "{:?}", bvh.stats);
        // Not vacuous: a good share of rays hit and a good share miss.
        assert!(closest > 1000 && any < 4500, "closest {closest} any {any}");
    }

    #[test]
    fn grid_scene_matches_brute_force() {
        let m = grid_scene();
        let (_bvh, closest, any) = check_scene(&m, 6000, 5);
        assert!(closest > 1000 && any < 6500, "closest {closest} any {any}");
    }

    #[test]
    fn tiny_and_degenerate_inputs() {
        // 0 triangles.
        let empty = Mesh::new();
        let bvh = Bvh::build(&empty.positions, &empty.indices);
        assert_eq!(bvh.nodes.len(), 1);
        assert!(bvh.nodes[0].is_leaf() && bvh.nodes[0].tri_count() == 0);
        assert!(bvh.bounds().is_empty());
        check_structure(&empty, &bvh);
        for ray in test_rays(&Aabb::EMPTY, 200, 1) {
            assert!(bvh.closest_hit(&ray).is_none());
            assert!(!bvh.any_hit(&ray));
        }

        // 1 triangle.
        let mut one = Mesh::new();
        one.tri(Vec3::ZERO, Vec3::X, Vec3::Y);
        let (bvh, closest, _) = check_scene(&one, 3000, 2);
        assert_eq!(bvh.nodes.len(), 1);
        assert!(closest > 10, "{closest}");
        let hit = bvh
            .closest_hit(&Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z, 0.0, 10.0))
            .unwrap();
        assert_eq!(hit.triangle, 0);
        assert!((hit.t - 1.0).abs() < 1e-6 && (hit.u - 0.25).abs() < 1e-6);

        // Many identical triangles: all centroids equal, the ties go to the smallest index.
        let mut same = Mesh::new();
        for _ in 0..300 {
            same.tri(
                Vec3::new(-1.0, 0.0, -1.0),
                Vec3::new(1.0, 0.0, -1.0),
                Vec3::new(0.0, 0.0, 1.0),
            );
        }
        let (bvh, closest, _) = check_scene(&same, 2000, 3);
        assert!(closest > 10);
        let hit = bvh
            .closest_hit(&Ray::new(Vec3::new(0.0, 1.0, 0.0), -Vec3::Y, 0.0, 10.0))
            .unwrap();
        assert_eq!(hit.triangle, 0);

        // Only degenerate triangles: never hit.
        let mut degen = Mesh::new();
        for i in 0..50 {
            let p = Vec3::splat(i as f32 * 0.1);
            degen.tri(p, p, p);
            degen.tri(p, p + Vec3::X, p + 2.0 * Vec3::X);
        }
        let (_, closest, any) = check_scene(&degen, 500, 4);
        assert_eq!((closest, any), (0, 0));

        // A trailing partial triangle is ignored.
        let bvh = Bvh::build(&[Vec3::ZERO, Vec3::X, Vec3::Y], &[0, 1, 2, 0]);
        assert_eq!(bvh.triangles.len(), 1);
    }

    /// Exponentially spaced triangles drive binned SAH towards very unbalanced splits; the
    /// depth bound must still hold and the traversal (fixed stack) must stay exact.
    #[test]
    fn depth_bound_on_adversarial_input() {
        let mut m = Mesh::new();
        let mut x = 1.0f32;
        for i in 0..4000 {
            x *= 1.02;
            let y = (i % 7) as f32 * 0.1;
            m.tri(
                Vec3::new(x, y, 0.0),
                Vec3::new(x * 1.001, y, 0.0),
                Vec3::new(x, y + 0.05, 0.1),
            );
        }
        let bvh = Bvh::build(&m.positions, &m.indices);
        check_structure(&m, &bvh);
        assert!(bvh.stats.depth <= BVH_STACK_SIZE);
        let rays = test_rays(&m.bounds(), 1000, 9);
        check_against_brute_force(&m, &bvh, &rays);
    }

    #[test]
    fn median_levels_and_sah_quality() {
        assert_eq!(median_levels(1), 0);
        assert_eq!(median_levels(4), 0);
        assert_eq!(median_levels(5), 1);
        assert_eq!(median_levels(8), 1);
        assert_eq!(median_levels(9), 2);
        // SAH beats a naive bound: a random soup of n tris should cost far less than n.
        let m = random_soup(20000, 3);
        let bvh = Bvh::build(&m.positions, &m.indices);
        assert!(bvh.stats.sah_cost < 0.02 * 20000.0, "{:?}", bvh.stats);
        assert!(bvh.stats.sah_cost > 1.0);
    }

    #[test]
    fn random_shadow_rays_are_deterministic() {
        let b = Aabb {
            min: Vec3::new(-1.0, 0.0, 2.0),
            max: Vec3::new(3.0, 5.0, 4.0),
        };
        let a = random_shadow_rays(&b, 100, 42);
        assert_eq!(a, random_shadow_rays(&b, 100, 42));
        assert_ne!(a, random_shadow_rays(&b, 100, 43));
        for r in &a {
            assert!(b.min.cmple(r.origin).all() && r.origin.cmple(b.max).all());
            let end = r.origin + r.dir;
            assert!(b.min.cmple(end + 1e-5).all() && (end - 1e-5).cmple(b.max).all());
            assert!(r.tmin > 0.0 && r.tmin < 1e-3 && r.tmax < 1.0 && r.tmax > 0.999);
        }
    }

    /// Build time and CPU any-hit throughput on a 100k-triangle soup (run with
    /// `cargo test --release bvh_bench -- --ignored --nocapture`).
    #[test]
    #[ignore]
    fn bvh_bench_soup_100k() {
        let m = random_soup(100_000, 1);
        let bvh = Bvh::build(&m.positions, &m.indices);
        println!("{:?}", bvh.stats);
        let rays = random_shadow_rays(&bvh.bounds(), 200_000, 1);
        let t = Instant::now();
        let occluded = rays.iter().filter(|r| bvh.any_hit(r)).count();
        let dt = t.elapsed().as_secs_f64();
        println!(
            "any-hit: {:.2} Mrays/s (1 thread), {:.1}% occluded",
            rays.len() as f64 / dt / 1e6,
            100.0 * occluded as f64 / rays.len() as f64
        );
    }

    const TEST_SHADER: &str = r#"
@group(0) @binding(0) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(1) var<storage, read> bvh_triangles: array<BvhTriangle>;
@group(0) @binding(2) var<storage, read> rays: array<BvhRay>;
@group(0) @binding(3) var<storage, read_write> out_hits: array<BvhHit>;
@group(0) @binding(4) var<storage, read_write> out_any: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= arrayLength(&rays)) {
        return;
    }
    let r = rays[i];
    out_hits[i] = bvh_closest_hit(r.origin, r.dir, r.tmin, r.tmax);
    out_any[i] = select(0u, 1u, bvh_any_hit(r.origin, r.dir, r.tmin, r.tmax));
    let tri = bvh_intersect_triangle(bvh_triangles[0], r.origin, r.dir, r.tmin, r.tmax);
    if (tri.w != 0.0 && bvh_any_hit_ray(r) && bvh_closest_hit_ray(r).triangle == 0u) {
        out_any[i] = 2u;
    }
}
"#;

    const BVH_WGSL: &str = include_str!("../../../shaders/common/bvh_wide.wgsl");
    const BVH_BINARY_WGSL: &str = include_str!("../../../shaders/common/bvh_binary.wgsl");
    const BVH_TRIANGLE_WGSL: &str = include_str!("../../../shaders/common/bvh_triangle.wgsl");

    fn struct_layout(module: &naga::Module, name: &str) -> (u32, Vec<u32>) {
        let (_, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no struct {name}"));
        match &ty.inner {
            naga::TypeInner::Struct { members, span } => (*span, members.iter().map(|m| m.offset).collect()),
            other => panic!("{name} is not a struct: {other:?}"),
        }
    }

    #[test]
    fn wgsl_validates_and_layouts_match() {
        for (file, wide) in [(BVH_WGSL, true), (BVH_BINARY_WGSL, false)] {
            check_wgsl(file, wide);
        }
    }

    fn check_wgsl(file: &str, wide: bool) {
        // The shared part, included as the shader preprocessor would.
        let file = &file.replace("#include \"common/bvh_triangle.wgsl\"", BVH_TRIANGLE_WGSL);
        assert!(!file.contains("#include"));
        // No bindings and no `enable` directives outside comments.
        let code: Vec<&str> = file.lines().map(|l| l.split("//").next().unwrap()).collect();
        assert!(code.iter().all(|l| !l.contains('@')), "bindings in bvh.wgsl");
        assert!(!code.iter().any(|l| l.trim_start().starts_with("enable")));
        // Declarations before and after the include must both work.
        for src in [format!("{TEST_SHADER}\n{file}"), format!("{file}\n{TEST_SHADER}")] {
            let module =
                naga::front::wgsl::parse_str(&src).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&src)));
            naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::all(),
            )
            .validate(&module)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&src)));

            let mut layouter = naga::proc::Layouter::default();
            layouter.update(module.to_ctx()).unwrap();
            let node = module
                .types
                .iter()
                .find(|(_, t)| t.name.as_deref() == Some("BvhNode"));
            let (size, offsets) = struct_layout(&module, "BvhNode");
            if wide {
                assert_eq!(layouter[node.unwrap().0].size, 80);
                assert_eq!(size as usize, std::mem::size_of::<GpuWideNode>());
                assert_eq!(offsets, [0, 16, 32, 48, 64]);
            } else {
                assert_eq!(layouter[node.unwrap().0].size, 32);
                assert_eq!(size as usize, std::mem::size_of::<GpuBvhNode>());
                assert_eq!(offsets, [0, 12, 16, 28]);
            }
            let (size, offsets) = struct_layout(&module, "BvhTriangle");
            assert_eq!(size as usize, std::mem::size_of::<GpuTriangle>());
            assert_eq!(offsets, [0, 12, 16, 28, 32, 44]);
            let (size, offsets) = struct_layout(&module, "BvhRay");
            assert_eq!(size as usize, std::mem::size_of::<GpuRay>());
            assert_eq!(offsets, [0, 12, 16, 28]);
            let (size, offsets) = struct_layout(&module, "BvhHit");
            assert_eq!(size as usize, std::mem::size_of::<GpuBvhHit>());
            assert_eq!(offsets, [0, 4, 8, 12]);

            // The WGSL stack size is the Rust one.
            let c = module
                .constants
                .iter()
                .find(|(_, c)| c.name.as_deref() == Some("BVH_STACK_SIZE"))
                .expect("BVH_STACK_SIZE constant")
                .1;
            assert!(matches!(
                module.global_expressions[c.init],
                naga::Expression::Literal(naga::Literal::U32(n)) if n as usize == BVH_STACK_SIZE
            ));
        }
    }
}

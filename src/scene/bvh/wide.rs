//! The compressed 8-wide BVH the GPU traverses (Ylitie, Karras & Laine 2017, "Efficient
//! Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs", sections 3-4), collapsed
//! from the binned-SAH binary BVH, and its CPU twin (`shaders/common/bvh_wide.wgsl` op for op).
//!
//! # Collapse
//! Every wide node starts from one binary node and opens, greedily, the interior child of the
//! largest surface area until it has 8 children or only leaves (the binary leaves, at most
//! [`MAX_LEAF_TRIS`] triangles, become leaf children). The paper's optimal SAH collapse is a
//! later refinement; the greedy one keeps every binary leaf, so the answers are the binary
//! BVH's by construction.
//!
//! # Child order (paper section 4.1)
//! A child's slot is chosen so that a ray of direction octant `o` visits slot `i ^ o` in step
//! `i`: slot `s` stands for the direction `d_s` with signs (-1 where bit k of `s` is set), and
//! children are assigned greedily to the slots where their centroid lies furthest back along
//! `d_s` (the smallest `dot(c - c_parent, d_s)` first), so the first visited child is the one
//! nearest the ray's origin side.
//!
//! # Node layout (80 bytes, [`GpuWideNode`], WGSL `struct BvhNode { w: array<vec4<u32>, 5> }`)
//! | bytes  | field        | meaning                                                          |
//! |--------|--------------|------------------------------------------------------------------|
//! | 0..12  | `origin`     | the quantisation grid's origin: the node box's minimum (f32 x3)  |
//! | 12..15 | `exp_imask`  | per axis, the biased exponent `e` of the grid step `2^(e - 127)` |
//! | 15     | `exp_imask`  | `imask`: bit `s` set where slot `s` holds an interior child      |
//! | 16..20 | `child_base` | index of the first interior child; slot `s`'s child is           |
//! |        |              | `child_base + popcount(imask & ((1 << s) - 1))`                  |
//! | 20..24 | `tri_base`   | index of the first triangle of this node's leaf children         |
//! | 24..32 | `meta`       | per slot: 0 = empty or interior; leaf: `count << 5 \| offset`,   |
//! |        |              | triangles `[tri_base + offset, + count)`                         |
//! | 32..56 | `qlo`        | per axis, per slot: the child box's lower corner on the grid     |
//! | 56..80 | `qhi`        | per axis, per slot: the upper corner (rounded up)                |
//!
//! A child box decodes as `origin + q * 2^(e - 127)` per axis: the product is exact (a power of
//! two times an 8-bit integer), the sum rounds once, so CPU and GPU decode the same floats
//! (a fused multiply-add rounds the same exact sum once). The quantised boxes contain the
//! (padded) binary boxes: the builder checks every decoded corner and widens the grid step
//! where rounding would cut a box.
//!
//! # Traversal (CPU and WGSL, identical algorithm)
//! A node visit slab-tests its children in the ray's order (`i ^ octant`), then tests the
//! triangles of every hit leaf child in one flat loop over a 32-bit mask (threads of a
//! subgroup stay in step; any-hit returns at the first hit), and descends into the first hit
//! interior child; the remaining hit interior children go on the stack as one entry (the
//! node's index and the pending mask; the parent's `imask` and `child_base` are read again on
//! a pop), popped in order. An entry stands for one node
//! on the current path, so the stack never holds more than the tree's depth
//! ([`BVH_STACK_SIZE`]). Closest-hit keeps the smallest `(t, original index)` and culls boxes
//! against the current best `t`, like the binary traversal.

// The negated comparisons are deliberate: they reject NaN, exactly as the WGSL code does.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::*;

/// Children per wide node.
pub const WIDE: usize = 8;
/// Bytes of one wide node.
pub const WIDE_NODE_BYTES: usize = 80;
/// Bytes of one binary node.
pub const BINARY_NODE_BYTES: usize = 32;
/// Bytes of one triangle.
pub const TRIANGLE_BYTES: usize = 48;

// A node's leaf triangles are bits of one u32 (at most 8 leaves of MAX_LEAF_TRIS).
const _: () = assert!(MAX_LEAF_TRIS <= 7 && WIDE * MAX_LEAF_TRIS <= 32);

/// One wide node as stored in the GPU buffer (see the module's table).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable, Debug, PartialEq)]
pub struct GpuWideNode {
    pub origin: [f32; 3],
    pub exp_imask: [u8; 4],
    pub child_base: u32,
    pub tri_base: u32,
    pub meta: [u8; 8],
    pub qlo: [[u8; 8]; 3],
    pub qhi: [[u8; 8]; 3],
}

const _: () = assert!(std::mem::size_of::<GpuWideNode>() == WIDE_NODE_BYTES);

impl GpuWideNode {
    #[inline(always)]
    pub fn imask(&self) -> u32 {
        self.exp_imask[3] as u32
    }
    /// The grid step of axis `a`: `2^(e - 127)` built from its bits (a normal float).
    #[inline(always)]
    pub fn scale(&self, a: usize) -> f32 {
        f32::from_bits((self.exp_imask[a] as u32) << 23)
    }
    /// Whether slot `s` holds a child (interior or leaf).
    #[inline(always)]
    pub fn occupied(&self, s: usize) -> bool {
        (self.imask() >> s) & 1 == 1 || self.meta[s] != 0
    }
    /// The decoded box of slot `s` (meaningful when occupied).
    #[inline(always)]
    pub fn child_box(&self, s: usize) -> (Vec3A, Vec3A) {
        let f = |a: usize, q: u8| self.origin[a] + q as f32 * self.scale(a);
        (
            Vec3A::new(f(0, self.qlo[0][s]), f(1, self.qlo[1][s]), f(2, self.qlo[2][s])),
            Vec3A::new(f(0, self.qhi[0][s]), f(1, self.qhi[1][s]), f(2, self.qhi[2][s])),
        )
    }
    /// The node index of interior slot `s`.
    #[inline(always)]
    pub fn child_index(&self, s: u32) -> u32 {
        self.child_base + (self.imask() & ((1u32 << s) - 1)).count_ones()
    }
}

/// What one traversal fetched and tested: the machine-independent cost of a ray.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TraceCounters {
    pub rays: u64,
    /// Nodes whose data a traversal step read (binary: every visited node; wide: every node).
    pub nodes: u64,
    /// Bytes of node and triangle data read (binary: a visit to an interior node reads both
    /// children's 32-byte boxes; wide: 80 bytes per node; 48 bytes per triangle test).
    pub bytes: u64,
    /// Ray-box tests.
    pub boxes: u64,
    /// Ray-triangle tests.
    pub triangles: u64,
    /// Deepest stack use (entries).
    pub max_stack: u64,
}

impl TraceCounters {
    pub fn add(&mut self, o: &TraceCounters) {
        self.rays += o.rays;
        self.nodes += o.nodes;
        self.bytes += o.bytes;
        self.boxes += o.boxes;
        self.triangles += o.triangles;
        self.max_stack = self.max_stack.max(o.max_stack);
    }
    /// Per-ray means: (nodes, bytes, boxes, triangles).
    pub fn per_ray(&self) -> (f64, f64, f64, f64) {
        let n = self.rays.max(1) as f64;
        (
            self.nodes as f64 / n,
            self.bytes as f64 / n,
            self.boxes as f64 / n,
            self.triangles as f64 / n,
        )
    }
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct WideStats {
    pub nodes: usize,
    /// Depth of the deepest node (root = 0).
    pub depth: usize,
    /// Mean occupied slots per node.
    pub mean_children: f32,
    pub build_ms: f64,
}

/// The compressed 8-wide BVH: GPU-ready nodes and triangles (in wide leaf order, each with its
/// original index), and build statistics.
#[derive(Clone, Debug)]
pub struct WideBvh {
    pub nodes: Vec<GpuWideNode>,
    pub triangles: Vec<GpuTriangle>,
    pub stats: WideStats,
}

/// Decodes grid coordinate `q` on an axis: exactly the WGSL arithmetic.
#[inline(always)]
fn decode(origin: f32, q: u32, scale: f32) -> f32 {
    origin + q as f32 * scale
}

/// Quantises child boxes on one axis: (biased exponent, lo codes, hi codes), every decoded
/// box containing its input. `origin` is the minimum of the inputs.
fn quantise_axis(origin: f32, hi: f32, boxes: &[(f32, f32)]) -> (u8, Vec<u8>, Vec<u8>) {
    let extent = hi - origin;
    let mut e = if extent > 0.0 {
        ((extent / 255.0).log2().ceil() as i32).clamp(-126, 127)
    } else {
        -126
    };
    loop {
        let scale = f32::from_bits(((e + 127) as u32) << 23);
        let mut ok = true;
        let mut los = Vec::with_capacity(boxes.len());
        let mut his = Vec::with_capacity(boxes.len());
        for &(lo, hi) in boxes {
            let mut ql = (((lo - origin) / scale).floor().max(0.0) as u32).min(255);
            while ql > 0 && decode(origin, ql, scale) > lo {
                ql -= 1;
            }
            let mut qh = (((hi - origin) / scale).ceil().max(0.0) as u32).min(255);
            while qh < 255 && decode(origin, qh, scale) < hi {
                qh += 1;
            }
            ok &= decode(origin, ql, scale) <= lo && decode(origin, qh, scale) >= hi;
            los.push(ql as u8);
            his.push(qh as u8);
        }
        if ok || e >= 127 {
            assert!(ok, "a box cannot be quantised (non-finite coordinates?)");
            return ((e + 127) as u8, los, his);
        }
        e += 1;
    }
}

/// Greedy slot assignment of the paper's section 4.1: `centroids` relative to the parent's.
fn assign_slots(centroids: &[Vec3]) -> [Option<usize>; WIDE] {
    let dir = |s: usize| {
        Vec3::new(
            if s & 1 != 0 { -1.0 } else { 1.0 },
            if s & 2 != 0 { -1.0 } else { 1.0 },
            if s & 4 != 0 { -1.0 } else { 1.0 },
        )
    };
    let mut pairs: Vec<(f32, usize, usize)> = Vec::with_capacity(centroids.len() * WIDE);
    for (c, p) in centroids.iter().enumerate() {
        for s in 0..WIDE {
            pairs.push((p.dot(dir(s)), c, s));
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let mut slots = [None; WIDE];
    let mut placed = vec![false; centroids.len()];
    for (_, c, s) in pairs {
        if !placed[c] && slots[s].is_none() {
            slots[s] = Some(c);
            placed[c] = true;
        }
    }
    slots
}

impl WideBvh {
    /// Collapses a binary BVH (its leaves and padded boxes) into the compressed 8-wide layout.
    pub fn from_binary(bvh: &Bvh) -> WideBvh {
        let t0 = Instant::now();
        let bin = &bvh.nodes;
        let mut nodes: Vec<GpuWideNode> = vec![bytemuck::Zeroable::zeroed()];
        let mut triangles: Vec<GpuTriangle> = Vec::with_capacity(bvh.triangles.len());
        let mut queue = std::collections::VecDeque::from([(0usize, 0usize, 0usize)]);
        let (mut depth, mut occupied) = (0usize, 0usize);
        while let Some((wi, bi, d)) = queue.pop_front() {
            depth = depth.max(d);
            let mut kids: Vec<usize> = if bin[bi].is_leaf() {
                vec![bi]
            } else {
                vec![bi + 1, bin[bi].left_or_first as usize]
            };
            while kids.len() < WIDE {
                let open = kids
                    .iter()
                    .enumerate()
                    .filter(|(_, k)| !bin[**k].is_leaf())
                    .max_by(|a, b| {
                        let (x, y) = (bin[*a.1].aabb().surface_area(), bin[*b.1].aabb().surface_area());
                        x.total_cmp(&y).then(b.0.cmp(&a.0))
                    })
                    .map(|(i, _)| i);
                let Some(i) = open else { break };
                let k = kids[i];
                kids[i] = k + 1;
                kids.push(bin[k].left_or_first as usize);
            }
            kids.retain(|&k| !(bin[k].is_leaf() && bin[k].tri_count() == 0));
            occupied += kids.len();
            let mut node: GpuWideNode = bytemuck::Zeroable::zeroed();
            if kids.is_empty() {
                nodes[wi] = node;
                continue;
            }
            let mut lo = Vec3::splat(f32::INFINITY);
            let mut hi = Vec3::splat(f32::NEG_INFINITY);
            for &k in &kids {
                lo = lo.min(Vec3::from_array(bin[k].min));
                hi = hi.max(Vec3::from_array(bin[k].max));
            }
            let centre = (lo + hi) * 0.5;
            let cents: Vec<Vec3> = kids.iter().map(|&k| bin[k].aabb().center() - centre).collect();
            let slots = assign_slots(&cents);
            node.origin = lo.to_array();
            for a in 0..3 {
                let boxes: Vec<(f32, f32)> = slots
                    .iter()
                    .map(|s| s.map_or((lo[a], lo[a]), |c| (bin[kids[c]].min[a], bin[kids[c]].max[a])))
                    .collect();
                let (e, ql, qh) = quantise_axis(lo[a], hi[a], &boxes);
                node.exp_imask[a] = e;
                for s in 0..WIDE {
                    if slots[s].is_some() {
                        node.qlo[a][s] = ql[s];
                        node.qhi[a][s] = qh[s];
                    }
                }
            }
            node.child_base = nodes.len() as u32;
            node.tri_base = triangles.len() as u32;
            let mut imask = 0u8;
            for (s, slot) in slots.iter().enumerate() {
                let Some(c) = *slot else { continue };
                let k = kids[c];
                if bin[k].is_leaf() {
                    let first = bin[k].left_or_first as usize;
                    let count = bin[k].tri_count() as usize;
                    let offset = triangles.len() - node.tri_base as usize;
                    debug_assert!(offset < 32 && count <= 7);
                    node.meta[s] = ((count << 5) | offset) as u8;
                    triangles.extend_from_slice(&bvh.triangles[first..first + count]);
                } else {
                    imask |= 1 << s;
                    let child = nodes.len();
                    nodes.push(bytemuck::Zeroable::zeroed());
                    queue.push_back((child, k, d + 1));
                }
            }
            node.exp_imask[3] = imask;
            nodes[wi] = node;
        }
        assert!(depth <= BVH_STACK_SIZE, "wide BVH deeper than the stack");
        assert!(
            nodes.len() < 1 << 24,
            "too many wide nodes for the stack encoding"
        );
        let stats = WideStats {
            nodes: nodes.len(),
            depth,
            mean_children: occupied as f32 / nodes.len() as f32,
            build_ms: t0.elapsed().as_secs_f64() * 1e3,
        };
        WideBvh {
            nodes,
            triangles,
            stats,
        }
    }

    /// Closest hit with `tmin < t < tmax` (ties in `t` go to the smaller original index).
    pub fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.traverse::<false, false>(ray, &mut TraceCounters::default())
    }

    /// Occlusion test for shadow rays.
    pub fn any_hit(&self, ray: &Ray) -> bool {
        self.traverse::<true, false>(ray, &mut TraceCounters::default())
            .is_some()
    }

    /// [`Self::any_hit`] / [`Self::closest_hit`] counting what the traversal fetched.
    pub fn trace_counted(&self, ray: &Ray, any: bool, c: &mut TraceCounters) -> Option<Hit> {
        if any {
            self.traverse::<true, true>(ray, c)
        } else {
            self.traverse::<false, true>(ray, c)
        }
    }

    /// The traversal loop of `bvh_wide.wgsl` (`bvh_traverse`).
    #[inline(always)]
    fn traverse<const ANY: bool, const COUNT: bool>(&self, ray: &Ray, c: &mut TraceCounters) -> Option<Hit> {
        if COUNT {
            c.rays += 1;
        }
        let o = Vec3A::from(ray.origin);
        let inv = Vec3A::from(safe_inv(ray.dir));
        let oct =
            (ray.dir.x < 0.0) as u32 | ((ray.dir.y < 0.0) as u32) << 1 | ((ray.dir.z < 0.0) as u32) << 2;
        let mut best = Hit {
            t: ray.tmax,
            triangle: NO_TRIANGLE,
            u: 0.0,
            v: 0.0,
        };
        // (node << 8) | pending positions of its children
        let mut stack = [0u32; BVH_STACK_SIZE];
        let mut sp = 0usize;
        let mut node = 0u32;
        loop {
            let n = &self.nodes[node as usize];
            if COUNT {
                c.nodes += 1;
                c.bytes += WIDE_NODE_BYTES as u64;
            }
            let imask = n.imask();
            let mut pending = 0u32;
            let mut tris = 0u32;
            for i in 0..WIDE as u32 {
                let s = (i ^ oct) as usize;
                if !n.occupied(s) {
                    continue;
                }
                let (lo, hi) = n.child_box(s);
                let (near, far) = slab_box(lo, hi, o, inv, ray.tmin, best.t);
                if COUNT {
                    c.boxes += 1;
                }
                if !(near <= far) {
                    continue;
                }
                if (imask >> s) & 1 == 1 {
                    pending |= 1 << i;
                } else {
                    let m = n.meta[s] as u32;
                    tris |= ((1u32 << (m >> 5)) - 1) << (m & 31);
                }
            }
            while tris != 0 {
                let tri = &self.triangles[n.tri_base as usize + tris.trailing_zeros() as usize];
                tris &= tris - 1;
                if COUNT {
                    c.triangles += 1;
                    c.bytes += TRIANGLE_BYTES as u64;
                }
                if let Some((t, u, v)) = intersect_triangle(tri, ray) {
                    let h = Hit {
                        t,
                        triangle: tri.id,
                        u,
                        v,
                    };
                    if ANY {
                        return Some(h);
                    }
                    if better(t, tri.id, best.t, best.triangle) {
                        best = h;
                    }
                }
            }
            if pending != 0 {
                let i = pending.trailing_zeros();
                let rest = pending & (pending - 1);
                if rest != 0 {
                    stack[sp] = (node << 8) | rest;
                    sp += 1;
                    if COUNT {
                        c.max_stack = c.max_stack.max(sp as u64);
                    }
                }
                node = n.child_index(i ^ oct);
                continue;
            }
            if sp == 0 {
                break;
            }
            let top = stack[sp - 1];
            let mask = top & 0xff;
            let i = mask.trailing_zeros();
            let rest = mask & (mask - 1);
            if rest == 0 {
                sp -= 1;
            } else {
                stack[sp - 1] = (top & !0xff) | rest;
            }
            if COUNT {
                // The parent's imask and child_base (8 bytes, read again).
                c.bytes += 8;
            }
            node = self.nodes[(top >> 8) as usize].child_index(i ^ oct);
        }
        (best.triangle != NO_TRIANGLE).then_some(best)
    }
}

// Lightcuts (Walter et al. 2005) per pixel on the frame's light tree: from the root, refine
// the cut node with the largest error bound (lc_common.wgsl) until that bound is at most
// relative_error x the luminance of the current estimate or the cut holds max_cut nodes.
// A cluster is evaluated with its representative VPL (lc_build.wgsl) carrying the cluster's
// luminance, and one BVH shadow ray; a child that shares its parent's representative reuses
// the parent's evaluation. Nodes of bound 0 (leaves: exact; empty; behind the receiver) are
// final at once and never enter the heap. The per-thread max-heap holds the refinable nodes
// (node id with the representative's visibility bit, bound); a popped node's estimate is
// recomputed from its representative and that bit (no second shadow ray). The heaps live in
// a scratch buffer, slot-major (slot i of thread t at i x slice + t, coalesced): the image
// runs in slices of `slice` pixels (one dispatch each) so that the scratch stays
// slice x max_cut entries; arrays in function memory would do on a GPU, but lavapipe turns
// their dynamic indexing into compare-and-select ladders (a 256-entry heap took minutes).
// Writes the estimate (or adds it) and, in diagnostic frames only (DIAGNOSTICS), the
// per-pixel diagnostics, the frame counters and the pinned pixel's cut. CPU twin: `lightcut`
// in src/reference/lightcuts.rs.
//
// Lightcut Interpolation runs the same kernel in two more modes (MODE): 1 computes the cache
// records' cuts (thread = record, its pixel in `lanes`; nodes whose bound is 0 are kept at the
// top of the thread's scratch, and a last dispatch with `steps` 0 sorts the whole cut left to
// right into `record_cuts`, node | visibility bit, its length into `rec_meta`); 2 computes
// full lightcuts for the pixels the interpolation left (`lanes` is its selection, 8 words per
// pixel, word 3 the records used; 0 = fallback) and marks them in the diagnostics (y = -1).
// STATS_BASE moves the counters (modes 1 and 2 add to the interpolation's).
#include "common/math.wgsl"
#include "common/color.wgsl"
#include "common/vpl.wgsl"
#include "common/vpl_visibility.wgsl"
#include "common/sst_node.wgsl"
#include "methods/lightcuts/lc_common.wgsl"
#include "common/brdf.wgsl"
#include "methods/lightcuts/lc_brdf_bound.wgsl"
#include "common/stats64.wgsl"
#include "common/tree_links.wgsl"

override DIAGNOSTICS: bool = true;
override MODE: u32 = 0u;
override STATS_BASE: u32 = 0u;

// Largest cut (src/reference/lightcuts.rs MAX_CUT; the trace's capacity).
const LC_MAX_CUT: u32 = 1024u;
const LC_VISIBLE: u32 = 0x80000000u;
// Trace: 8 header words, then 8 words per cut node (node, rep, bound, estimate rgb, 0, 0).
const LC_TRACE_HEADER: u32 = 8u;
const LC_TRACE_RECORD: u32 = 8u;
const LC_NO_TRACE: u32 = 0xffffffffu;

struct LcParams {
    width: u32,
    height: u32,
    leaves: u32,
    max_cut: u32,
    relative_error: f32,
    epsilon: f32,
    ray_offset: f32,
    shadow_rays: u32,
    accumulate: u32,
    trace_pixel: u32, // x | y << 16, or LC_NO_TRACE
    first_pixel: u32, // this slice's first pixel (row-major)
    slice: u32,       // pixels (threads) per slice, the scratch's stride
    first: u32,       // 1: this dispatch starts the slice's cuts
    last: u32,        // 1: this dispatch finishes them and writes the outputs
    steps: u32,       // refinements per dispatch at most
    radix: u32,       // 1: the radix tree (children from tree_links; mode 0 only), 0: the perfect tree
    brdf: u32,        // BRDF_LAMBERT / BRDF_GGX (mode 0 only; Lightcut Interpolation is Lambert)
    pad0: u32,
    pad1: u32,
    pad2: u32,
    eye: vec4<f32>,   // xyz the camera's position (the glossy BRDF's view direction)
};

// The shading point's material (gi.brdf = GGX): set per pixel before the refinement.
var<private> glossy: bool;
var<private> sh_v: vec3<f32>;
var<private> sh_base: vec3<f32>;
var<private> sh_metallic: f32;
var<private> sh_roughness: f32;

// A pixel's refinement between dispatches.
struct LcState {
    sum: vec3<f32>,
    size: u32,
    settled: u32,
    refinements: u32,
    rays: u32,
    done: u32,
};

@group(0) @binding(0) var<uniform> lp: LcParams;
@group(0) @binding(1) var<storage, read> tree: array<SstNode>;
@group(0) @binding(2) var<storage, read> sorted_vpls: array<Vpl>;
@group(0) @binding(3) var<storage, read> cones: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> reps: array<u32>;
@group(0) @binding(5) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(6) var<storage, read> bvh_triangles: array<BvhTriangle>;
@group(0) @binding(7) var gb_position: texture_2d<f32>;
@group(0) @binding(8) var gb_normal: texture_2d<f32>;
@group(0) @binding(9) var gb_albedo: texture_2d<f32>;
@group(0) @binding(10) var<storage, read_write> accum: array<vec4<f32>>;
// Per pixel: cut size, refinements, largest bound left / estimate, shadow rays.
@group(0) @binding(11) var<storage, read_write> diag: array<vec4<f32>>;
// pixels, pixels at max_cut, cut nodes (64 bit), refinements (64 bit), shadow rays (64 bit).
@group(0) @binding(12) var<storage, read_write> stats: array<atomic<u32>>;
@group(0) @binding(13) var<storage, read_write> trace: array<u32>;
// The heaps: (node | LC_VISIBLE if its representative is visible, bound bits).
@group(0) @binding(14) var<storage, read_write> scratch: array<vec2<u32>>;
@group(0) @binding(15) var<storage, read_write> state: array<LcState>;
@group(0) @binding(16) var<storage, read> lanes: array<u32>;
@group(0) @binding(17) var<storage, read_write> record_cuts: array<u32>;
// Word 0: records; word 8 + r: record r's cut length (li_common.wgsl).
@group(0) @binding(18) var<storage, read_write> rec_meta: array<u32>;
// The radix tree's links (a dummy on the perfect tree): common/tree_links.wgsl.
@group(0) @binding(19) var<storage, read> tree_links: array<vec4<u32>>;

fn tree_radix() -> bool {
    return lp.radix != 0u;
}

var<private> rays: u32;

fn heap_get(lane: u32, i: u32) -> vec2<u32> {
    return scratch[i * lp.slice + lane];
}

fn heap_set(lane: u32, i: u32, e: vec2<u32>) {
    scratch[i * lp.slice + lane] = e;
}

fn heap_bound(e: vec2<u32>) -> f32 {
    return bitcast<f32>(e.y);
}

fn add64(i: u32, v: u32) {
    stats_add64(STATS_BASE + i, v);
}

// A node final at once (bound 0): counted; records keep it at the top of the scratch.
fn settle(lane: u32, settled: ptr<function, u32>, node: u32, vis: bool) {
    if MODE == 1u {
        heap_set(lane, lp.max_cut - 1u - *settled, vec2<u32>(node | select(0u, LC_VISIBLE, vis), 0u));
    }
    *settled += 1u;
}

// First leaf under a node (the left-to-right order of a cut).
fn first_leaf(e: u32) -> u32 {
    return tree_node_range(e & ~LC_VISIBLE, lp.leaves).x;
}

fn sift_down(base: u32, start: u32, end: u32) {
    var i = start;
    loop {
        var c = 2u * i + 1u;
        if c >= end {
            break;
        }
        if c + 1u < end && first_leaf(record_cuts[base + c + 1u]) > first_leaf(record_cuts[base + c]) {
            c += 1u;
        }
        let ci = record_cuts[base + c];
        let ii = record_cuts[base + i];
        if first_leaf(ci) <= first_leaf(ii) {
            break;
        }
        record_cuts[base + c] = ii;
        record_cuts[base + i] = ci;
        i = c;
    }
}

// Mode 1: the record's cut (heap [0, size), settled nodes at the top) into record_cuts, left
// to right (heap sort).
fn write_record(lane: u32, item: u32, size: u32, settled: u32) {
    let n = size + settled;
    let base = item * lp.max_cut;
    for (var i = 0u; i < size; i++) {
        record_cuts[base + i] = heap_get(lane, i).x;
    }
    for (var i = 0u; i < settled; i++) {
        record_cuts[base + size + i] = heap_get(lane, lp.max_cut - 1u - i).x;
    }
    if n > 1u {
        for (var s = n / 2u; s > 0u; s--) {
            sift_down(base, s - 1u, n);
        }
        for (var end = n - 1u; end > 0u; end--) {
            let t = record_cuts[base];
            record_cuts[base] = record_cuts[base + end];
            record_cuts[base + end] = t;
            sift_down(base, 0u, end);
        }
    }
    rec_meta[8u + item] = n;
}

fn heap_push(lane: u32, size: ptr<function, u32>, e: vec2<u32>) {
    var i = *size;
    *size = i + 1u;
    let b = heap_bound(e);
    loop {
        if i == 0u {
            break;
        }
        let p = (i - 1u) / 2u;
        let pe = heap_get(lane, p);
        if heap_bound(pe) >= b {
            break;
        }
        heap_set(lane, i, pe);
        i = p;
    }
    heap_set(lane, i, e);
}

// Removes the top (the caller read it first).
fn heap_pop(lane: u32, size: ptr<function, u32>) {
    let n = *size - 1u;
    *size = n;
    let last = heap_get(lane, n);
    let lb = heap_bound(last);
    var i = 0u;
    loop {
        let l = 2u * i + 1u;
        if l >= n {
            break;
        }
        var c = l;
        var ce = heap_get(lane, l);
        if l + 1u < n {
            let re = heap_get(lane, l + 1u);
            if heap_bound(re) > heap_bound(ce) {
                c = l + 1u;
                ce = re;
            }
        }
        if heap_bound(ce) <= lb {
            break;
        }
        heap_set(lane, i, ce);
        i = c;
    }
    heap_set(lane, i, last);
}

fn error_bound(node: u32, x: vec3<f32>, n: vec3<f32>) -> f32 {
    let c = tree[node];
    if node >= lp.leaves || sst_is_empty(c) {
        return 0.0;
    }
    if glossy {
        return lc_geometry_brdf_bound(x, n, sh_v, c.bbox_min, c.bbox_max, cones[node], lp.epsilon,
            sh_base, sh_metallic, sh_roughness, c.intensity) / PI;
    }
    return luminance(c.intensity) / PI * lc_geometry_bound(x, n, c.bbox_min, c.bbox_max, cones[node], lp.epsilon);
}

// The cluster's unshadowed estimate: its representative's flux / pi x G with the cluster's
// luminance (Lambert: irradiance-like, the albedo / pi applied at the end); with the glossy
// BRDF times f(v, l) towards the representative (radiance).
fn estimate(node: u32, x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let rep = reps[node];
    if rep == LC_NONE {
        return vec3<f32>(0.0);
    }
    let v = sorted_vpls[rep];
    let e = lc_estimate(v, luminance(tree[node].intensity), x, n, lp.epsilon);
    if glossy && any(e != vec3<f32>(0.0)) {
        let l = normalize(v.position.xyz - x);
        return e * brdf_eval(lp.brdf, n, sh_v, l, sh_base, sh_metallic, sh_roughness);
    }
    return e;
}

// Whether the node's representative is visible from x (one shadow ray when the estimate is
// not 0 and shadow rays are on).
fn visible(node: u32, e: vec3<f32>, x: vec3<f32>, n: vec3<f32>) -> bool {
    // Records (MODE 1) trace every node: their bits are interpolated to pixels where the
    // node contributes (`trace_every_node` in the CPU twin).
    if all(e == vec3<f32>(0.0)) && MODE != 1u {
        return false;
    }
    if lp.shadow_rays == 0u {
        return true;
    }
    rays += 1u;
    let v = sorted_vpls[reps[node]];
    return vpl_visible(v.position.xyz, v.normal, x, n, lp.ray_offset);
}

fn trace_node(slot: u32, node: u32, e: vec4<f32>) {
    if slot >= LC_MAX_CUT {
        return;
    }
    let o = LC_TRACE_HEADER + slot * LC_TRACE_RECORD;
    trace[o] = node;
    trace[o + 1u] = reps[node];
    trace[o + 2u] = bitcast<u32>(e.w);
    trace[o + 3u] = bitcast<u32>(e.x);
    trace[o + 4u] = bitcast<u32>(e.y);
    trace[o + 5u] = bitcast<u32>(e.z);
}

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let lane = gid.x;
    let item = lp.first_pixel + gid.x;
    if gid.x >= lp.slice {
        return;
    }
    var k = item;
    if MODE == 1u {
        if item >= rec_meta[0] {
            return;
        }
        k = lanes[item];
    } else {
        if item >= lp.width * lp.height {
            return;
        }
        if MODE == 2u && lanes[8u * item + 3u] != 0u {
            return;
        }
    }
    let px = vec2<i32>(i32(k % lp.width), i32(k / lp.width));
    let g = textureLoad(gb_position, px, 0);
    if g.w == 0.0 {
        if MODE == 1u {
            if lp.last != 0u {
                rec_meta[8u + item] = 0u;
            }
            return;
        }
        if lp.accumulate == 0u {
            accum[k] = vec4<f32>(0.0);
        }
        if DIAGNOSTICS {
            diag[k] = vec4<f32>(0.0);
        }
        return;
    }
    let x = g.xyz;
    let nr = textureLoad(gb_normal, px, 0);
    let n = normalize(nr.xyz);
    glossy = MODE == 0u && lp.brdf != BRDF_LAMBERT;
    if glossy {
        let a = textureLoad(gb_albedo, px, 0);
        sh_v = normalize(lp.eye.xyz - x);
        sh_base = a.rgb;
        sh_metallic = a.a;
        sh_roughness = nr.w;
    }
    let traced = DIAGNOSTICS && MODE == 0u && (u32(px.x) | (u32(px.y) << 16u)) == lp.trace_pixel;
    var size = 0u;     // heap entries
    var settled = 0u;  // final nodes outside the heap
    var refinements = 0u;
    var sum = vec3<f32>(0.0);
    var done = 0u;
    rays = 0u;
    if lp.first != 0u {
        if !sst_is_empty(tree[1]) {
            let b = error_bound(1u, x, n);
            if b > 0.0 {
                let e = estimate(1u, x, n);
                let vis = visible(1u, e, x, n);
                sum += select(vec3<f32>(0.0), e, vis);
                heap_push(lane, &size, vec2<u32>(1u | select(0u, LC_VISIBLE, vis), bitcast<u32>(b)));
            } else {
                if traced {
                    trace_node(settled, 1u, vec4<f32>(0.0));
                }
                settle(lane, &settled, 1u, MODE == 1u && visible(1u, estimate(1u, x, n), x, n));
            }
        }
    } else {
        let st = state[lane];
        sum = st.sum;
        size = st.size;
        settled = st.settled;
        refinements = st.refinements;
        rays = st.rays;
        done = st.done;
    }
    // At most `steps` refinements in this dispatch (lavapipe ends a shader invocation after
    // 65535 loop iterations in all, shadow-ray traversals included: docs/lightcuts.md).
    var step = 0u;
    loop {
        if done != 0u || step >= lp.steps {
            break;
        }
        let top = heap_get(lane, 0u);
        let tb = heap_bound(top);
        if size == 0u || tb <= lp.relative_error * luminance(sum) || size + settled >= lp.max_cut {
            done = 1u;
            break;
        }
        step += 1u;
        heap_pop(lane, &size);
        let node = top.x & ~LC_VISIBLE;
        let top_vis = (top.x & LC_VISIBLE) != 0u;
        if top_vis {
            sum -= estimate(node, x, n);
        }
        refinements += 1u;
        let rep = reps[node];
        for (var c = 0u; c < 2u; c++) {
            let child = select(tree_right(node), tree_left(node), c == 0u);
            if !sst_is_empty(tree[child]) {
                let b = error_bound(child, x, n);
                var vis = false;
                var e = vec3<f32>(0.0);
                if reps[child] == rep {
                    // The parent's representative: its shadow ray's answer.
                    vis = top_vis;
                    e = estimate(child, x, n);
                } else if b > 0.0 || child >= lp.leaves || MODE == 1u {
                    e = estimate(child, x, n);
                    vis = visible(child, e, x, n);
                }
                if vis {
                    sum += e;
                }
                if b > 0.0 {
                    heap_push(lane, &size, vec2<u32>(child | select(0u, LC_VISIBLE, vis), bitcast<u32>(b)));
                } else {
                    if traced {
                        trace_node(settled, child, vec4<f32>(select(vec3<f32>(0.0), e, vis), 0.0));
                    }
                    settle(lane, &settled, child, vis);
                }
            }
        }
    }
    if lp.last == 0u {
        state[lane] = LcState(sum, size, settled, refinements, rays, done);
        return;
    }
    if MODE == 1u {
        write_record(lane, item, size, settled);
        if DIAGNOSTICS {
            var lmax = 0.0;
            if size > 0u {
                lmax = heap_bound(heap_get(lane, 0u));
            }
            atomicAdd(&stats[STATS_BASE], 1u);
            if lmax > lp.relative_error * luminance(sum) {
                atomicAdd(&stats[STATS_BASE + 1u], 1u);
            }
            add64(2u, size + settled);
            add64(4u, refinements);
            add64(6u, rays);
        }
        return;
    }
    let albedo = textureLoad(gb_albedo, px, 0).rgb;
    // With the glossy BRDF the estimates carry it already.
    let radiance = select(albedo / PI * sum, sum, glossy);
    if lp.accumulate != 0u {
        accum[k] += vec4<f32>(radiance, 0.0);
    } else {
        accum[k] = vec4<f32>(radiance, 0.0);
    }
    if DIAGNOSTICS {
        var lmax = 0.0;
        if size > 0u {
            lmax = heap_bound(heap_get(lane, 0u));
        }
        let ls = luminance(sum);
        var rel = 0.0;
        if lmax > 0.0 {
            rel = select(3.0e38, lmax / ls, ls > 0.0);
        }
        let cut = size + settled;
        if MODE == 2u {
            diag[k] = vec4<f32>(f32(cut), -1.0, rel, f32(rays));
        } else {
            diag[k] = vec4<f32>(f32(cut), f32(refinements), rel, f32(rays));
        }
        atomicAdd(&stats[STATS_BASE], 1u);
        if rel > lp.relative_error {
            atomicAdd(&stats[STATS_BASE + 1u], 1u);
        }
        add64(2u, cut);
        add64(4u, refinements);
        add64(6u, rays);
        if traced {
            for (var i = 0u; i < size; i++) {
                let h = heap_get(lane, i);
                let hn = h.x & ~LC_VISIBLE;
                let he = select(vec3<f32>(0.0), estimate(hn, x, n), (h.x & LC_VISIBLE) != 0u);
                trace_node(settled + i, hn, vec4<f32>(he, heap_bound(h)));
            }
            trace[0] = cut;
            trace[1] = refinements;
            trace[2] = bitcast<u32>(rel);
            trace[3] = rays;
            trace[4] = k + 1u;
        }
    }
}

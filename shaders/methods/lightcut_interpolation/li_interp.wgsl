// Lightcut Interpolation's cut interpolation and shading (Rehfeld & Dachsbacher 2016, section
// 3.3, Listings 1 and 2): per pixel with records (li_select.wgsl), the records' cuts (left to
// right, node | visibility bit) are walked along their lowest edge; each step adds width x
// the weighted input level to an accumulator; at a sync position (a boundary at least two
// input cuts share; every boundary for one cut) nodes are emitted at the accumulated average
// level (rounded), lowered until aligned (Fig. 7) and deferred when they would reach past the
// sync position (Fig. 6). An emitted node is shaded at once: its representative's estimate
// (lc_estimate) x a shadow ray (full visibility) or x the width-weighted average of the input
// nodes' visibility bits (interpolated visibility). Gaps of empty nodes are walked as empty
// "virtual" nodes and never emitted. On a CPU adapter the walk is split over dispatches of
// `steps` units (a step or an emitted node) with the walk's state in `state` (lavapipe's
// 65535-iteration limit, docs/lightcuts.md). CPU twin: `interpolate` and `shade` in
// src/reference/lightcut_interpolation.rs.
#include "common/math.wgsl"
#include "common/color.wgsl"
#include "common/vpl.wgsl"
#include "common/vpl_visibility.wgsl"
#include "common/sst_node.wgsl"
#include "methods/lightcuts/lc_common.wgsl"
#include "methods/lightcut_interpolation/li_common.wgsl"
#include "common/stats64.wgsl"

override DIAGNOSTICS: bool = true;

// Trace: 16 header words, then (node, visibility bits) per node.
const LI_TRACE_HEADER: u32 = 16u;
const LI_TRACE_NODES: u32 = 4096u;

struct LiSel {
    ids: vec4<u32>,
    w: vec4<f32>,
};

// The walk between dispatches.
struct LiState {
    next: vec4<u32>,  // next stored node per input cut; w: walk position
    end: vec4<u32>,   // current node's end per input cut; w: output position
    level: vec4<u32>, // current node's level per input cut; w: cut size
    vis: vec4<f32>,   // current node's visibility per input cut; w: level spread sum
    acc: vec4<f32>,   // accumulated width, width x level, width x visibility; w: steps
    sum: vec4<f32>,   // estimate; w: shadow rays (bits)
};

@group(0) @binding(0) var<uniform> lp: LiParams;
@group(0) @binding(1) var gb_position: texture_2d<f32>;
@group(0) @binding(2) var gb_normal: texture_2d<f32>;
@group(0) @binding(3) var gb_albedo: texture_2d<f32>;
@group(0) @binding(4) var<storage, read> rec_meta: array<u32>;
@group(0) @binding(5) var<storage, read> record_cuts: array<u32>;
@group(0) @binding(6) var<storage, read> sel: array<LiSel>;
@group(0) @binding(7) var<storage, read> tree: array<SstNode>;
@group(0) @binding(8) var<storage, read> sorted_vpls: array<Vpl>;
@group(0) @binding(9) var<storage, read> reps: array<u32>;
@group(0) @binding(10) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(11) var<storage, read> bvh_triangles: array<BvhTriangle>;
@group(0) @binding(12) var<storage, read_write> accum: array<vec4<f32>>;
// Per pixel: cut size, level spread (y = -1: fallback, from lightcuts.wgsl), records used,
// shadow rays.
@group(0) @binding(13) var<storage, read_write> diag: array<vec4<f32>>;
// Words 0 interpolated pixels, 1 unfinished walks, 2 cut nodes (64 bit), 4 shadow rays
// (64 bit), 6 walk steps (64 bit); 8..16 the records' lightcuts, 16..24 the fallback's
// (lightcuts.wgsl with STATS_BASE).
@group(0) @binding(14) var<storage, read_write> stats: array<atomic<u32>>;
@group(0) @binding(15) var<storage, read_write> trace: array<u32>;
@group(0) @binding(16) var<storage, read_write> state: array<LiState>;

fn first_leaf(node: u32) -> u32 {
    return (node << (lp.levels - firstLeadingBit(node))) - lp.leaves;
}

// The largest aligned node starting at leaf x that ends at or before `limit`: its level.
fn aligned_level(x: u32, limit: u32) -> u32 {
    var l = 0u;
    if x != 0u {
        l = lp.levels - min(countTrailingZeros(x), lp.levels);
    }
    loop {
        if l >= lp.levels || x + (1u << (lp.levels - l)) <= limit {
            break;
        }
        l += 1u;
    }
    return l;
}

struct Cursor {
    next: u32,
    end: u32,
    level: u32,
    vis: f32,
};

// Input cut `r`'s node starting at leaf x (twin: `load`).
fn load(r: u32, next: u32, x: u32) -> Cursor {
    var c = Cursor(next, 0u, 0u, 0.0);
    let len = rec_meta[LI_META_HEADER + r];
    var limit = lp.leaves;
    if next < len {
        let e = record_cuts[r * lp.max_cut + next];
        let node = e & ~LI_VISIBLE;
        let f = first_leaf(node);
        if f == x {
            c.next = next + 1u;
            c.level = firstLeadingBit(node);
            c.end = x + (1u << (lp.levels - c.level));
            c.vis = select(0.0, 1.0, (e & LI_VISIBLE) != 0u);
            return c;
        }
        limit = f;
    }
    c.level = aligned_level(x, limit);
    c.end = x + (1u << (lp.levels - c.level));
    return c;
}

// level.w's top bit: the walk stopped inside a sync position's emission (resume there).
const LI_PENDING: u32 = 0x80000000u;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let k = gid.x + gid.y * groups.x * 64u;
    if k >= lp.width * lp.height {
        return;
    }
    let s = sel[k];
    let m = s.ids.w;
    if m == 0u {
        return; // no geometry, or the fallback (lightcuts.wgsl, MODE 2)
    }
    let px = vec2<i32>(i32(k % lp.width), i32(k / lp.width));
    let x = textureLoad(gb_position, px, 0).xyz;
    let n = normalize(textureLoad(gb_normal, px, 0).xyz);
    let traced = DIAGNOSTICS && (u32(px.x) | (u32(px.y) << 16u)) == lp.trace_pixel;
    var cur: array<Cursor, 3>;
    var pos = 0u;
    var out = 0u;
    var size = 0u;
    var spread = 0.0;
    var acc = vec4<f32>(0.0);
    var sum = vec3<f32>(0.0);
    var rays = 0u;
    var pending = false;
    if lp.first != 0u {
        for (var j = 0u; j < m; j++) {
            cur[j] = load(s.ids[j], 0u, 0u);
        }
    } else {
        let st = state[k];
        for (var j = 0u; j < m; j++) {
            cur[j] = Cursor(st.next[j], st.end[j], st.level[j], st.vis[j]);
        }
        pos = st.next.w;
        out = st.end.w;
        size = st.level.w & ~LI_PENDING;
        pending = (st.level.w & LI_PENDING) != 0u;
        spread = st.vis.w;
        acc = st.acc;
        sum = st.sum.xyz;
        rays = bitcast<u32>(st.sum.w);
    }
    var units = 0u;
    loop {
        if (pos >= lp.leaves && !pending) || units >= lp.steps {
            break;
        }
        if !pending {
            // One lowest-edge step.
            var e = 0xffffffffu;
            var lavg = 0.0;
            var vavg = 0.0;
            var lo = 0xffffffffu;
            var hi = 0u;
            for (var j = 0u; j < m; j++) {
                e = min(e, cur[j].end);
                lavg += s.w[j] * f32(cur[j].level);
                vavg += s.w[j] * cur[j].vis;
                lo = min(lo, cur[j].level);
                hi = max(hi, cur[j].level);
            }
            let width = f32(e - pos);
            acc.x += width;
            acc.y += width * lavg;
            acc.z += width * vavg;
            acc.w += 1.0;
            spread += width * f32(hi - lo);
            units += 1u;
            pos = e;
            var ended = 0u;
            for (var j = 0u; j < m; j++) {
                if cur[j].end == e {
                    ended += 1u;
                    if e < lp.leaves {
                        cur[j] = load(s.ids[j], cur[j].next, e);
                    }
                }
            }
            if ended < min(m, 2u) {
                continue;
            }
        }
        // A sync position: emit what the accumulator allows (at most the dispatch's budget;
        // `pending` resumes here).
        pending = true;
        loop {
            if out >= pos {
                pending = false;
                break;
            }
            if units >= lp.steps {
                break;
            }
            let want = u32(clamp(i32(floor(acc.y / acc.x + 0.5)), 0, i32(lp.levels)));
            let l = max(want, aligned_level(out, lp.leaves));
            let w = 1u << (lp.levels - l);
            if out + w > pos {
                pending = false;
                break;
            }
            let node = (lp.leaves + out) >> (lp.levels - l);
            if !sst_is_empty(tree[node]) {
                let vis_i = acc.z / acc.x;
                var est = vec3<f32>(0.0);
                let rep = reps[node];
                if rep != LC_NONE {
                    est = lc_estimate(sorted_vpls[rep], luminance(tree[node].intensity), x, n, lp.distance_epsilon);
                }
                if any(est != vec3<f32>(0.0)) {
                    var v = 1.0;
                    if lp.interp_visibility != 0u {
                        v = vis_i;
                    } else if lp.shadow_rays != 0u {
                        rays += 1u;
                        let vp = sorted_vpls[rep];
                        v = select(0.0, 1.0, vpl_visible(vp.position.xyz, vp.normal, x, n, lp.ray_offset));
                    }
                    sum += est * v;
                }
                if traced && size < LI_TRACE_NODES {
                    trace[LI_TRACE_HEADER + 2u * size] = node;
                    trace[LI_TRACE_HEADER + 2u * size + 1u] = bitcast<u32>(vis_i);
                }
                size += 1u;
            }
            let wf = f32(w);
            if wf >= acc.x {
                acc = vec4<f32>(0.0, 0.0, 0.0, acc.w);
            } else {
                let keep = 1.0 - wf / acc.x;
                acc.y *= keep;
                acc.z *= keep;
                acc.x -= wf;
            }
            out += w;
            units += 1u;
        }
    }
    if lp.last == 0u {
        var st: LiState;
        for (var j = 0u; j < 3u; j++) {
            st.next[j] = cur[j].next;
            st.end[j] = cur[j].end;
            st.level[j] = cur[j].level;
            st.vis[j] = cur[j].vis;
        }
        st.next.w = pos;
        st.end.w = out;
        st.level.w = size | select(0u, LI_PENDING, pending);
        st.vis.w = spread;
        st.acc = acc;
        st.sum = vec4<f32>(sum, bitcast<f32>(rays));
        state[k] = st;
        return;
    }
    let albedo = textureLoad(gb_albedo, px, 0).rgb;
    let radiance = albedo / PI * sum;
    if lp.accumulate != 0u {
        accum[k] += vec4<f32>(radiance, 0.0);
    } else {
        accum[k] = vec4<f32>(radiance, 0.0);
    }
    if DIAGNOSTICS {
        let level_spread = spread / f32(lp.leaves);
        diag[k] = vec4<f32>(f32(size), level_spread, f32(m), f32(rays));
        atomicAdd(&stats[0], 1u);
        if pos < lp.leaves || out < lp.leaves || pending {
            atomicAdd(&stats[1], 1u);
        }
        stats_add64(2u, size);
        stats_add64(4u, rays);
        stats_add64(6u, u32(acc.w));
        if traced {
            trace[0] = size;
            trace[1] = m;
            trace[2] = s.ids.x;
            trace[3] = s.ids.y;
            trace[4] = s.ids.z;
            trace[5] = bitcast<u32>(s.w.x);
            trace[6] = bitcast<u32>(s.w.y);
            trace[7] = bitcast<u32>(s.w.z);
            trace[8] = k + 1u;
            trace[9] = bitcast<u32>(level_spread);
            trace[10] = rays;
            trace[11] = u32(acc.w);
        }
    }
}

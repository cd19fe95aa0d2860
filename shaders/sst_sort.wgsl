// SST stage 8-9 (SST paper 3.3, thesis 4.2.1): VPL bounds, 64-bit sort keys
// (30-bit Morton | 9-bit normal code | 25-bit id, stored as two u32: x = high word, y = low
// word, z = VPL index) and a bitonic sort of the (key, index) pairs padded to a power of two.
// CPU twin: src/reference/sst.rs.
//
// Two variants (`SortVariant` in src/renderer/passes/sst_sort.rs), kept side by side so that
// `bench tree` measures both in one run:
// - baseline: the bounds by one 64-thread workgroup looping over every VPL (serial on a GPU)
//   and one global compare-exchange dispatch per bitonic step (j, k);
// - parallel (default): the bounds as a reduction over all VPLs (a workgroup reduces 2048,
//   then one atomic max per component on order-preserving integer codes), and the bitonic
//   steps with j < SORT_TILE / 2 done in workgroup memory (one dispatch sorts every 512-pair
//   tile, one dispatch per k > 512 finishes its small steps), only j >= 512 globally.
// Both give the same bounds (min / max are exact) and the same sorted keys.
#include "common/vpl.wgsl"

struct SortParams {
    count: u32,   // VPLs
    padded: u32,  // power of two >= count
    j: u32,       // bitonic step distance
    k: u32,       // bitonic sequence size
};

@group(0) @binding(0) var<uniform> sp: SortParams;
@group(0) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(2) var<storage, read_write> keys: array<vec4<u32>>;
// The VPL bounds as order-preserving codes (`float_order`): [0..3) the complement of the
// code of min xyz, [4..7) the code of max xyz, so that both reduce by atomicMax from a
// cleared (zero) buffer.
@group(0) @binding(3) var<storage, read_write> bounds: array<atomic<u32>>;

// An unsigned code with the order of the float (finite values; -0 just below +0).
fn float_order(f: f32) -> u32 {
    let u = bitcast<u32>(f);
    return select(u | 0x80000000u, ~u, (u & 0x80000000u) != 0u);
}

fn float_from_order(o: u32) -> f32 {
    return bitcast<f32>(select(~o, o & 0x7fffffffu, (o & 0x80000000u) != 0u));
}

fn bounds_lo() -> vec3<f32> {
    return vec3<f32>(float_from_order(~atomicLoad(&bounds[0])),
        float_from_order(~atomicLoad(&bounds[1])), float_from_order(~atomicLoad(&bounds[2])));
}

fn bounds_hi() -> vec3<f32> {
    return vec3<f32>(float_from_order(atomicLoad(&bounds[4])),
        float_from_order(atomicLoad(&bounds[5])), float_from_order(atomicLoad(&bounds[6])));
}

fn merge_bounds(lo: vec3<f32>, hi: vec3<f32>) {
    for (var c = 0u; c < 3u; c++) {
        atomicMax(&bounds[c], ~float_order(lo[c]));
        atomicMax(&bounds[4u + c], float_order(hi[c]));
    }
}

var<workgroup> wg_lo: array<vec3<f32>, 256>;
var<workgroup> wg_hi: array<vec3<f32>, 256>;

// The workgroup's box (each of its `threads` invocations brings one) reduced in workgroup
// memory, then merged into the buffer by invocation 0 (a workgroup without VPLs merges none).
fn reduce_and_merge(li: u32, lo: vec3<f32>, hi: vec3<f32>, threads: u32) {
    wg_lo[li] = lo;
    wg_hi[li] = hi;
    workgroupBarrier();
    for (var s = threads / 2u; s > 0u; s >>= 1u) {
        if li < s {
            wg_lo[li] = min(wg_lo[li], wg_lo[li + s]);
            wg_hi[li] = max(wg_hi[li], wg_hi[li + s]);
        }
        workgroupBarrier();
    }
    if li == 0u && wg_lo[0].x <= wg_hi[0].x {
        merge_bounds(wg_lo[0], wg_hi[0]);
    }
}

// Baseline: one workgroup of 64 loops over every VPL (serial on a GPU).
@compute @workgroup_size(64, 1, 1)
fn vpl_bounds(@builtin(local_invocation_index) li: u32) {
    var lo = vec3<f32>(3.0e38);
    var hi = vec3<f32>(-3.0e38);
    for (var i = li; i < sp.count; i += 64u) {
        let v = vpls[i];
        if v.id != VPL_NONE {
            lo = min(lo, v.position.xyz);
            hi = max(hi, v.position.xyz);
        }
    }
    reduce_and_merge(li, lo, hi, 64u);
}

// VPLs per thread of the parallel bounds (twin of `BOUNDS_PER_THREAD`).
const BOUNDS_PER_THREAD: u32 = 8u;

// Parallel: each workgroup reduces 256 x BOUNDS_PER_THREAD VPLs (coalesced, a stride of 256
// between a thread's VPLs) in workgroup memory, then merges its box into the buffer with one
// atomic max per component.
@compute @workgroup_size(256, 1, 1)
fn vpl_bounds_parallel(@builtin(workgroup_id) wg: vec3<u32>,
    @builtin(local_invocation_index) li: u32) {
    var lo = vec3<f32>(3.0e38);
    var hi = vec3<f32>(-3.0e38);
    let first = wg.x * 256u * BOUNDS_PER_THREAD + li;
    for (var r = 0u; r < BOUNDS_PER_THREAD; r++) {
        let i = first + r * 256u;
        if i < sp.count {
            let v = vpls[i];
            if v.id != VPL_NONE {
                lo = min(lo, v.position.xyz);
                hi = max(hi, v.position.xyz);
            }
        }
    }
    reduce_and_merge(li, lo, hi, 256u);
}

fn expand_bits_10(v: u32) -> u32 {
    var x = v & 0x3ffu;
    x = (x | (x << 16u)) & 0x030000ffu;
    x = (x | (x << 8u)) & 0x0300f00fu;
    x = (x | (x << 4u)) & 0x030c30c3u;
    x = (x | (x << 2u)) & 0x09249249u;
    return x;
}

fn quantise_axis(v: f32, lo: f32, e: f32) -> u32 {
    if e > 0.0 {
        return u32(clamp((v - lo) / e, 0.0, 1.0) * 1023.0);
    }
    return 0u;
}

fn normal_code(n: vec3<f32>) -> u32 {
    var code = (select(0u, 4u, n.x < 0.0)) | (select(0u, 2u, n.y < 0.0)) | (select(0u, 1u, n.z < 0.0));
    let a = abs(n);
    let s = a.x + a.y + a.z;
    var b = vec3<f32>(1.0, 0.0, 0.0);
    if s > 0.0 {
        b = a / s;
    }
    for (var level = 0u; level < 3u; level++) {
        var child = 3u;
        if b.x > 0.5 {
            b = vec3<f32>(2.0 * b.x - 1.0, 2.0 * b.y, 2.0 * b.z);
            child = 0u;
        } else if b.y > 0.5 {
            b = vec3<f32>(2.0 * b.x, 2.0 * b.y - 1.0, 2.0 * b.z);
            child = 1u;
        } else if b.z > 0.5 {
            b = vec3<f32>(2.0 * b.x, 2.0 * b.y, 2.0 * b.z - 1.0);
            child = 2u;
        } else {
            b = vec3<f32>(1.0 - 2.0 * b.x, 1.0 - 2.0 * b.y, 1.0 - 2.0 * b.z);
        }
        code = (code << 2u) | child;
    }
    return code;
}

// Keys of every VPL; padding and empty VPLs get the largest key (they sort last).
@compute @workgroup_size(64, 1, 1)
fn make_keys(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i >= sp.padded {
        return;
    }
    if i >= sp.count || vpls[i].id == VPL_NONE {
        keys[i] = vec4<u32>(0xffffffffu, 0xffffffffu, i, 0u);
        return;
    }
    let v = vpls[i];
    let lo = bounds_lo();
    let e = bounds_hi() - lo;
    let p = v.position.xyz;
    let m = (expand_bits_10(quantise_axis(p.x, lo.x, e.x)) << 2u)
        | (expand_bits_10(quantise_axis(p.y, lo.y, e.y)) << 1u)
        | expand_bits_10(quantise_axis(p.z, lo.z, e.z));
    let nc = normal_code(v.normal);
    // 64-bit key = m << 34 | nc << 25 | i (25 bits).
    let hi = (m << 2u) | (nc >> 7u);
    let lw = ((nc & 0x7fu) << 25u) | (i & 0x1ffffffu);
    keys[i] = vec4<u32>(hi, lw, i, 0u);
}

fn key_less(a: vec4<u32>, b: vec4<u32>) -> bool {
    return a.x < b.x || (a.x == b.x && a.y < b.y);
}

// Baseline: one bitonic compare-exchange step (distance j within sequences of size k), a
// thread per element (half of them idle).
@compute @workgroup_size(64, 1, 1)
fn bitonic_step(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    let l = i ^ sp.j;
    if i >= sp.padded || l <= i {
        return;
    }
    let a = keys[i];
    let b = keys[l];
    let ascending = (i & sp.k) == 0u;
    if (ascending && key_less(b, a)) || (!ascending && key_less(a, b)) {
        keys[i] = b;
        keys[l] = a;
    }
}

// Parallel variant: elements per workgroup-memory tile (two per thread).
const SORT_TILE: u32 = 512u;
var<workgroup> tile: array<vec4<u32>, 512>;

// The t-th compare-exchange pair of a step with distance j: (i, i + j), bit j of i clear.
fn bitonic_pair_of(t: u32, j: u32) -> u32 {
    return 2u * j * (t / j) + (t % j);
}

// One global step with j >= SORT_TILE / 2, a thread per pair.
@compute @workgroup_size(256, 1, 1)
fn bitonic_pairs(@builtin(global_invocation_id) gid: vec3<u32>) {
    let t = gid.x;
    if t >= sp.padded / 2u {
        return;
    }
    let i = bitonic_pair_of(t, sp.j);
    let l = i + sp.j;
    let a = keys[i];
    let b = keys[l];
    let ascending = (i & sp.k) == 0u;
    if (ascending && key_less(b, a)) || (!ascending && key_less(a, b)) {
        keys[i] = b;
        keys[l] = a;
    }
}

fn tile_exchange(t: u32, j: u32, k: u32, base: u32) {
    let i = bitonic_pair_of(t, j);
    let l = i + j;
    let a = tile[i];
    let b = tile[l];
    let ascending = ((base + i) & k) == 0u;
    if (ascending && key_less(b, a)) || (!ascending && key_less(a, b)) {
        tile[i] = b;
        tile[l] = a;
    }
}

// Workgroup-memory steps on one 512-element tile: sp.j == 0 sorts it completely (every k up
// to min(512, padded)); otherwise the steps j = sp.j .. 1 of sequences of size sp.k.
@compute @workgroup_size(256, 1, 1)
fn bitonic_tile(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let base = wg.x * SORT_TILE;
    for (var e = li; e < SORT_TILE; e += 256u) {
        var v = vec4<u32>(0xffffffffu, 0xffffffffu, 0xffffffffu, 0u);
        if base + e < sp.padded {
            v = keys[base + e];
        }
        tile[e] = v;
    }
    workgroupBarrier();
    if sp.j == 0u {
        let top = min(SORT_TILE, sp.padded);
        for (var k = 2u; k <= top; k <<= 1u) {
            for (var j = k >> 1u; j > 0u; j >>= 1u) {
                tile_exchange(li, j, k, base);
                workgroupBarrier();
            }
        }
    } else {
        for (var j = sp.j; j > 0u; j >>= 1u) {
            tile_exchange(li, j, sp.k, base);
            workgroupBarrier();
        }
    }
    for (var e = li; e < SORT_TILE; e += 256u) {
        if base + e < sp.padded {
            keys[base + e] = tile[e];
        }
    }
}

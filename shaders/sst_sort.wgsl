// SST stage 8-9 (SST paper 3.3, thesis 4.2.1): VPL bounds, 64-bit sort keys
// (30-bit Morton | 9-bit normal code | 25-bit id, stored as two u32: x = high word, y = low
// word, z = VPL index) and a bitonic sort of the (key, index) pairs padded to a power of two.
// CPU twin: src/reference/sst.rs.
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
@group(0) @binding(3) var<storage, read_write> bounds: array<vec4<f32>>;

var<workgroup> wg_lo: array<vec3<f32>, 64>;
var<workgroup> wg_hi: array<vec3<f32>, 64>;

// One workgroup: min/max of the valid VPLs' positions -> bounds[0], bounds[1].
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
    wg_lo[li] = lo;
    wg_hi[li] = hi;
    workgroupBarrier();
    for (var s = 32u; s > 0u; s >>= 1u) {
        if li < s {
            wg_lo[li] = min(wg_lo[li], wg_lo[li + s]);
            wg_hi[li] = max(wg_hi[li], wg_hi[li + s]);
        }
        workgroupBarrier();
    }
    if li == 0u {
        bounds[0] = vec4<f32>(wg_lo[0], 0.0);
        bounds[1] = vec4<f32>(wg_hi[0], 0.0);
    }
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
    let lo = bounds[0].xyz;
    let e = bounds[1].xyz - lo;
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

// One bitonic compare-exchange step (distance j within sequences of size k).
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

// A Stochastic Substitute Tree node: storage layout (64 B) and decoding. Twin of `GpuSstNode`
// (src/renderer/gpu_data.rs) and `SstNode` (src/reference/sst_tree.rs, which documents the
// merge). Implicit indexing: root 1, children of n at 2n and 2n+1, leaf i at leaves + i.

struct SstNode {
    position: vec3<f32>, // intensity-weighted position (thesis eq. 4.1)
    v: f32,              // normal similarity (eq. 4.3)
    intensity: vec3<f32>,// summed RGB flux (W)
    normal: u32,         // octahedral, 2 x 16 bits (x low)
    bbox_min: vec3<f32>, // +3.4e38 when empty
    var_z: f32,          // variance along the normal (eq. 4.2)
    bbox_max: vec3<f32>, // -3.4e38 when empty
    var_xy: u32,         // variances along tangent / bitangent, 2 x f16
};

const SST_EMPTY_MIN: f32 = 3.40282347e38;

fn sign_not_zero(v: vec2<f32>) -> vec2<f32> {
    return select(vec2<f32>(-1.0), vec2<f32>(1.0), v >= vec2<f32>(0.0));
}

// u = round(32767 v) + 32767 per axis, so that 0 and +-1 are exact.
fn oct_encode(n: vec3<f32>) -> u32 {
    let s = abs(n.x) + abs(n.y) + abs(n.z);
    var p = vec2<f32>(0.0);
    if s > 0.0 {
        p = n.xy / s;
    }
    if n.z < 0.0 {
        p = (1.0 - abs(p.yx)) * sign_not_zero(p);
    }
    let q = vec2<u32>(floor(clamp(p, vec2<f32>(-1.0), vec2<f32>(1.0)) * 32767.0 + 32767.5));
    return q.x | (q.y << 16u);
}

fn oct_decode(e: u32) -> vec3<f32> {
    let p = (vec2<f32>(f32(e & 0xffffu), f32(e >> 16u)) - 32767.0) / 32767.0;
    var n = vec3<f32>(p, 1.0 - abs(p.x) - abs(p.y));
    if n.z < 0.0 {
        n = vec3<f32>((1.0 - abs(n.yx)) * sign_not_zero(n.xy), n.z);
    }
    return normalize(n);
}

// Orthonormal tangent frame of a unit normal (Duff et al. 2017): (tangent, bitangent).
fn sst_basis(n: vec3<f32>) -> mat2x3<f32> {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return mat2x3<f32>(
        vec3<f32>(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        vec3<f32>(b, sign + n.y * n.y * a, -n.y),
    );
}

fn sst_is_empty(node: SstNode) -> bool {
    return node.bbox_min.x > node.bbox_max.x;
}

// Variance in the node's frame (tangent, bitangent, normal).
fn sst_variance(node: SstNode) -> vec3<f32> {
    return vec3<f32>(unpack2x16float(node.var_xy), node.var_z);
}

// SST paper eq. 3: usable for sampling (sigma bound strict, so that sigma_max = 0 turns
// substitutes off; see src/reference/sst_tree.rs).
fn sst_usable(node: SstNode, v_min: f32, sigma_max: f32) -> bool {
    return !sst_is_empty(node) && node.v >= v_min && node.var_z < sigma_max * sigma_max;
}

// What both BVH traversals share (common/bvh_binary.wgsl, common/bvh_wide.wgsl include it):
// the triangle, ray and hit layouts, the triangle test, the safe inverse direction and the slab
// test, mirrored op for op by `scene::bvh::{intersect_triangle, safe_inv, slab_box}`. Declares no
// bindings; every name starts with `bvh_`, `Bvh` or `BVH_`.
//
//   BvhTriangle (48 B) = GpuTriangle: v0.xyz, id | e1.xyz, pad | e2.xyz, pad   (e1 = v1 - v0, e2 = v2 - v0)

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

const BVH_NO_HIT: u32 = 0xffffffffu;
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

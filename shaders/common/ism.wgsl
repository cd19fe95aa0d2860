// Imperfect shadow maps (Ritschel et al. 2008; the VAL paper's section 5): the paraboloid
// projection around a light's normal (Brabec et al. 2002) and the lookup. A shader that
// includes this declares `ism: IsmParams` and `ism_depth: array<f32>` (the resolved atlas).
// Twins: reference::ism::{basis, project, texel_of, visible}.

// Twin: `GpuIsmParams` in src/renderer/passes/ism.rs.
struct IsmParams {
    atlas: u32,      // atlas edge (texels)
    tile: u32,       // one map's edge
    per_row: u32,    // maps per atlas row
    lights: u32,     // maps in use
    points: u32,
    level: u32,      // the pull / push pass's level
    bias: f32,       // relative depth bias of the lookup
    level_base: u32, // offset of `level` in the pyramid buffer (pull / push)
    per_light: u32,  // 0: point k to map k mod lights; else map m takes per_light points spread over the cloud
    threads: u32,    // splat threads: points, or lights x per_light
    front_cull: u32, // 1: points whose normal faces the light are left out
    point_radius: f32, // a point's world radius (m): its splat covers the texels within it; 0: one texel
};

// A point's splat reaches at most this many texels from its own (a (2k + 1)^2 square).
const ISM_MAX_POINT_TEXELS: f32 = 8.0;

const ISM_EMPTY: f32 = 1e30;

// Duff et al. 2017. Twin: reference::ism::basis.
fn ism_basis(n: vec3<f32>) -> mat2x3<f32> {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return mat2x3<f32>(
        vec3<f32>(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        vec3<f32>(b, sign + n.y * n.y * a, -n.y));
}

// Map coordinates in [0, 1]^2 (xy) and distance (z) of p seen from a light at c with unit
// normal n; z < 0: behind the hemisphere. Twin: reference::ism::project.
fn ism_project(c: vec3<f32>, n: vec3<f32>, p: vec3<f32>) -> vec3<f32> {
    let d = p - c;
    let dist = length(d);
    if dist <= 1e-6 {
        return vec3<f32>(0.0, 0.0, -1.0);
    }
    let w = d / dist;
    let z = dot(w, n);
    if z <= 0.0 {
        return vec3<f32>(0.0, 0.0, -1.0);
    }
    let f = ism_basis(n);
    let q = vec2<f32>(dot(w, f[0]), dot(w, f[1])) / (1.0 + z);
    return vec3<f32>(q * 0.5 + 0.5, dist);
}

// The atlas index of map m's texel (u, v). Twin: IsmLayout::texel.
fn ism_index(m: u32, u: u32, v: u32) -> u32 {
    let mx = m % ism.per_row;
    let my = m / ism.per_row;
    return (my * ism.tile + v) * ism.atlas + mx * ism.tile + u;
}

// The atlas index of map m's texel at map coordinates uv. Twin: IsmLayout::texel(texel_of).
fn ism_texel(m: u32, uv: vec2<f32>) -> u32 {
    let t = i32(ism.tile);
    let u = u32(clamp(i32(uv.x * f32(ism.tile)), 0, t - 1));
    let v = u32(clamp(i32(uv.y * f32(ism.tile)), 0, t - 1));
    let mx = m % ism.per_row;
    let my = m / ism.per_row;
    return (my * ism.tile + v) * ism.atlas + mx * ism.tile + u;
}

// Whether map m (light at c, normal n) sees x. Twin: reference::ism::visible.
fn ism_visible(m: u32, c: vec3<f32>, n: vec3<f32>, x: vec3<f32>) -> bool {
    let p = ism_project(c, n, x);
    if p.z < 0.0 {
        return true;
    }
    return p.z * (1.0 - ism.bias) <= ism_depth[ism_texel(m, p.xy)];
}

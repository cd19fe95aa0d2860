// Imperfect shadow maps, built each frame for a set of oriented point lights (the VAL
// paper's section 5, after Ritschel et al. 2008):
//   splat_main: each light's points (point k into map k mod lights; or, with per_light,
//     per_light points spread over the cloud: Stochastic Light Culling's adaptive ISMs), those
//     within the light's range (and, with front_cull, facing away from it), one texel each, the nearest distance kept (atomicMax of
//     ~bits: positive floats order as their bits);
//   resolve_main: the keys into distances (ISM_EMPTY where no point landed);
//   pull_main: level l of each map = the mean of the filled texels of its 2 x 2 block below;
//   push_main: level l's empty texels from level l + 1, coarsest first.
// Twins: reference::ism::{splat, pull_push}.
#include "common/ism.wgsl"

@group(0) @binding(0) var<uniform> ism: IsmParams;
// Per point: position, then its surface normal (zero: never culled).
@group(0) @binding(1) var<storage, read> points: array<vec4<f32>>;
// Per light: position (xyz) and squared range (w; +inf: none), then unit normal (xyz).
@group(0) @binding(2) var<storage, read> lights: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> keys: array<atomic<u32>>;
@group(0) @binding(4) var<storage, read_write> ism_depth: array<f32>;
// Levels 1.. of every map in use, map-major (level_base + m s^2 + y s + x).
@group(0) @binding(5) var<storage, read_write> pyramid: array<f32>;

@compute @workgroup_size(64, 1, 1)
fn splat_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nw: vec3<u32>) {
    let k = gid.x + gid.y * nw.x * 64u;
    if k >= ism.threads || ism.lights == 0u {
        return;
    }
    // Map m's j-th point: m + j x max(cloud / per_light, 1), wrapping (round-robin: k).
    var m = k % ism.lights;
    var idx = k;
    if ism.per_light != 0u {
        m = k / ism.per_light;
        let j = k % ism.per_light;
        idx = (m + j * max(ism.points / ism.per_light, 1u)) % ism.points;
    }
    let c = lights[2u * m];
    let x = points[2u * idx].xyz;
    let d = x - c.xyz;
    if dot(d, d) >= c.w {
        return;
    }
    // Front-face culling (Stochastic Light Culling's Program 1).
    if ism.front_cull != 0u && dot(points[2u * idx + 1u].xyz, d) < 0.0 {
        return;
    }
    let nl = lights[2u * m + 1u].xyz;
    let p = ism_project(c.xyz, nl, x);
    if p.z < 0.0 {
        return;
    }
    let key = 0xffffffffu - bitcast<u32>(p.z);
    if ism.point_radius <= 0.0 {
        atomicMax(&keys[ism_texel(m, p.xy)], key);
        return;
    }
    // A sized point (the VAL paper's point sprites): the texels within its radius as seen
    // from the light, a square of (2k + 1)^2 around its own. Map coordinates per radian at
    // cosine z to the normal: 0.5 / (1 + z). Twin: reference::ism::splat_sized.
    let z = dot(d / p.z, nl);
    let r = ism.point_radius / p.z * 0.5 / (1.0 + z) * f32(ism.tile);
    let reach = i32(min(r, ISM_MAX_POINT_TEXELS));
    let t = i32(ism.tile);
    let u0 = clamp(i32(p.x * f32(ism.tile)), 0, t - 1);
    let v0 = clamp(i32(p.y * f32(ism.tile)), 0, t - 1);
    for (var dv = -reach; dv <= reach; dv++) {
        let v = v0 + dv;
        if v < 0 || v >= t {
            continue;
        }
        for (var du = -reach; du <= reach; du++) {
            let u = u0 + du;
            if u < 0 || u >= t {
                continue;
            }
            atomicMax(&keys[ism_index(m, u32(u), u32(v))], key);
        }
    }
}

// The texel (x, y) of map m at level l (0: the atlas).
fn level_index(m: u32, x: u32, y: u32, l: u32, base: u32) -> u32 {
    if l == 0u {
        let mx = m % ism.per_row;
        let my = m / ism.per_row;
        return (my * ism.tile + y) * ism.atlas + mx * ism.tile + x;
    }
    let s = ism.tile >> l;
    return base + m * s * s + y * s + x;
}

fn read_level(m: u32, x: u32, y: u32, l: u32, base: u32) -> f32 {
    if l == 0u {
        return ism_depth[level_index(m, x, y, 0u, 0u)];
    }
    return pyramid[level_index(m, x, y, l, base)];
}

@compute @workgroup_size(8, 8, 1)
fn resolve_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    // One map per workgroup row of the dispatch's z.
    let m = gid.z;
    if gid.x >= ism.tile || gid.y >= ism.tile || m >= ism.lights {
        return;
    }
    let i = level_index(m, gid.x, gid.y, 0u, 0u);
    let key = atomicLoad(&keys[i]);
    ism_depth[i] = select(bitcast<f32>(0xffffffffu - key), ISM_EMPTY, key == 0u);
}

// ism.level = l >= 1; ism.level_base: l's offset; the level below at `below_base` =
// level_base - lights x (2s)^2 (level 1's below is the atlas).
@compute @workgroup_size(8, 8, 1)
fn pull_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let l = ism.level;
    let s = ism.tile >> l;
    let m = gid.z;
    if gid.x >= s || gid.y >= s || m >= ism.lights {
        return;
    }
    let below_base = ism.level_base - select(ism.lights * 4u * s * s, 0u, l == 1u);
    var sum = 0.0;
    var w = 0.0;
    for (var j = 0u; j < 4u; j++) {
        let v = read_level(m, 2u * gid.x + (j & 1u), 2u * gid.y + (j >> 1u), l - 1u, below_base);
        if v < ISM_EMPTY {
            sum += v;
            w += 1.0;
        }
    }
    pyramid[level_index(m, gid.x, gid.y, l, ism.level_base)] = select(ISM_EMPTY, sum / w, w > 0.0);
}

// ism.level = l >= 0 (the level filled); ism.level_base: level l + 1's offset.
@compute @workgroup_size(8, 8, 1)
fn push_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let l = ism.level;
    let s = ism.tile >> l;
    let m = gid.z;
    if gid.x >= s || gid.y >= s || m >= ism.lights {
        return;
    }
    let above = pyramid[level_index(m, gid.x / 2u, gid.y / 2u, l + 1u, ism.level_base)];
    if l == 0u {
        let i = level_index(m, gid.x, gid.y, 0u, 0u);
        if ism_depth[i] >= ISM_EMPTY {
            ism_depth[i] = above;
        }
    } else {
        let below_base = ism.level_base - ism.lights * s * s;
        let i = level_index(m, gid.x, gid.y, l, below_base);
        if pyramid[i] >= ISM_EMPTY {
            pyramid[i] = above;
        }
    }
}

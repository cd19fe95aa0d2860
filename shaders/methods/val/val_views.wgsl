// The VAL method's views; each also writes its linear data (EXR export) to `data`:
//   mode 0, the clusters over the RSM (res^2): each lit texel in its cluster's colour (the last
//           step's keys), the clusters' centre texels white, texels without flux black;
//           data (cluster or -1, 1 at a centre, the cluster's pixels, 1);
//   mode 1, the VALs as disks in the camera view: the grey final, and where the pixel's camera
//           ray meets a VAL's disk (radius sqrt(A / pi) around its centre, in its plane) before
//           the visible surface, the nearest such disk's colour over it, its rim white; data
//           (VAL or -1, distance from the centre / radius, distance along the ray, 1);
//   mode 2, the PCSS penumbra width (eq. 3, metres on the receiver, averaged over the
//           pixel's lookups that found blockers), log scale lo .. hi; lookups without blockers
//           dark blue; data: the shading's diagnostics (width, lookups with blockers, VALs
//           with a non-zero term, 1);
//   mode 3, VAL `inspect`'s imperfect shadow map (left) beside its true paraboloid depth map
//           traced through the BVH from the same point (right), distance on a log scale lo ..
//           hi, holes / misses black; data (ISM depth, true depth, 0, 1), 0 where empty.
#include "common/math.wgsl"
#include "common/camera.wgsl"
#include "common/color.wgsl"
#include "common/bvh.wgsl"
#include "common/ism.wgsl"
#include "methods/val/val_common.wgsl"

struct ValViewParams {
    mode: u32,
    clusters: u32,
    exposure: f32,
    tonemap: u32,
    lo: f32,
    hi: f32,
    inspect: u32,
    gap: u32,
    ray_offset: f32,
    res: u32,
    _pad0: u32,
    _pad1: u32,
};

@group(0) @binding(0) var<uniform> vp: ValViewParams;
@group(0) @binding(1) var final_image: texture_2d<f32>;
@group(0) @binding(2) var gb_position: texture_2d<f32>;
@group(0) @binding(3) var<storage, read> diag: array<vec4<f32>>;
@group(0) @binding(4) var dst: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(5) var<storage, read> vals: array<Val>;
@group(0) @binding(6) var<storage, read> keys: array<u32>;
@group(0) @binding(7) var<uniform> ism: IsmParams;
@group(0) @binding(8) var<storage, read> ism_depth: array<f32>;
@group(0) @binding(9) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(10) var<storage, read> bvh_triangles: array<BvhTriangle>;
@group(0) @binding(11) var<storage, read_write> data: array<vec4<f32>>;
@group(0) @binding(12) var<uniform> camera: Camera;

// The direction of map coordinates uv of a paraboloid map around n (the inverse of
// ism_project); w = 0 outside the hemisphere's disk.
fn ism_direction(n: vec3<f32>, uv: vec2<f32>) -> vec4<f32> {
    let q = uv * 2.0 - 1.0;
    let q2 = dot(q, q);
    if q2 > 1.0 {
        return vec4<f32>(0.0);
    }
    let z = (1.0 - q2) / (1.0 + q2);
    let f = ism_basis(n);
    let w = f[0] * (q.x * (1.0 + z)) + f[1] * (q.y * (1.0 + z)) + n * z;
    return vec4<f32>(normalize(w), 1.0);
}

fn depth_color(d: f32) -> vec3<f32> {
    if d >= ISM_EMPTY || d <= 0.0 {
        return vec3<f32>(0.0);
    }
    return false_color(log_scale(d, vp.lo, vp.hi));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(dst);
    if gid.x >= size.x || gid.y >= size.y {
        return;
    }
    let k = gid.y * size.x + gid.x;
    var c = vec3<f32>(0.0);
    var out = vec4<f32>(0.0);
    switch vp.mode {
        case 0u: {
            out = vec4<f32>(-1.0, 0.0, 0.0, 1.0);
            let key = keys[gid.y * vp.res + gid.x];
            if key != 0u {
                let ci = (~key) & 1023u;
                c = id_color(ci);
                out = vec4<f32>(f32(ci), 0.0, f32(vals[ci].pixels), 1.0);
            }
            let packed = gid.x | (gid.y << 16u);
            for (var i = 0u; i < vp.clusters; i++) {
                if vals[i].pixels > 0u && vals[i].texel == packed {
                    c = vec3<f32>(1.0);
                    out.y = 1.0;
                }
            }
        }
        case 1u: {
            let g = textureLoad(gb_position, vec2<i32>(gid.xy), 0);
            out = vec4<f32>(-1.0, 0.0, 0.0, 1.0);
            let o = camera.position.xyz;
            let d = normalize(camera_ray_dir(camera, gid.xy));
            var t_max = 3.0e38;
            if g.w > 0.0 {
                c = vec3<f32>(display_grey(textureLoad(final_image, vec2<i32>(gid.xy), 0).rgb, vp.exposure, vp.tonemap)) * 0.6;
                // Disks just behind the surface they lie on still show.
                t_max = dot(g.xyz - o, d) * 1.001 + 1e-3;
            }
            var best = t_max;
            for (var i = 0u; i < vp.clusters; i++) {
                let v = vals[i];
                if v.pixels == 0u {
                    continue;
                }
                let den = dot(d, v.normal);
                if abs(den) < 1e-6 {
                    continue;
                }
                let t = dot(v.position - o, v.normal) / den;
                if t <= 0.0 || t >= best {
                    continue;
                }
                let r = sqrt(v.area / PI);
                let q = length(o + t * d - v.position) / max(r, 1e-6);
                if q < 1.0 {
                    best = t;
                    out = vec4<f32>(f32(i), q, t, 1.0);
                }
            }
            if out.x >= 0.0 {
                let grey = c;
                c = mix(grey, id_color(u32(out.x)), 0.75);
                if out.y > 0.93 {
                    c = vec3<f32>(1.0);
                }
            }
        }
        case 2u: {
            let d = diag[k];
            out = d;
            let g = textureLoad(gb_position, vec2<i32>(gid.xy), 0);
            if g.w > 0.0 {
                if d.y > 0.0 {
                    c = false_color(log_scale(d.x, vp.lo, vp.hi));
                } else {
                    c = vec3<f32>(0.05, 0.07, 0.25);
                }
            }
        }
        default: {
            let t = ism.tile;
            c = vec3<f32>(0.15);
            if gid.x < t || gid.x >= t + vp.gap {
                let right = gid.x >= t + vp.gap;
                let u = select(gid.x, gid.x - t - vp.gap, right);
                let uv = (vec2<f32>(f32(u), f32(gid.y)) + 0.5) / f32(t);
                let v = vals[min(vp.inspect, max(vp.clusters, 1u) - 1u)];
                let dir = ism_direction(v.normal, uv);
                if dir.w > 0.0 && v.pixels > 0u {
                    var depth = ISM_EMPTY;
                    if right {
                        let o = v.position + v.normal * vp.ray_offset;
                        let hit = bvh_closest_hit(o, dir.xyz, 1e-4, 3.0e38);
                        if hit.triangle != BVH_NO_HIT {
                            depth = length(o + dir.xyz * hit.t - v.position);
                        }
                        out = vec4<f32>(0.0, select(0.0, depth, depth < ISM_EMPTY), 0.0, 1.0);
                    } else {
                        let m = min(vp.inspect, max(vp.clusters, 1u) - 1u);
                        depth = ism_depth[ism_texel(m, uv)];
                        out = vec4<f32>(select(0.0, depth, depth < ISM_EMPTY), 0.0, 0.0, 1.0);
                    }
                    c = depth_color(depth);
                }
            }
        }
    }
    data[k] = out;
    textureStore(dst, vec2<i32>(gid.xy), vec4<f32>(c, 1.0));
}

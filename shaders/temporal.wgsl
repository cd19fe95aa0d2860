// The temporal stage after a per-frame GI method (renderer::passes::temporal): SVGF (Schied
// et al. 2017, "Spatiotemporal Variance-Guided Filtering: Real-Time Reconstruction for
// Path-Traced Global Illumination"), on the GI demodulated by the G-buffer albedo.
//   reproject  : motion from the G-buffer's world position and the previous camera (the
//                scene is static), bilinear history taps kept if same material, normal and
//                tangent plane (section 4.1), else a 3x3 fallback, else disoccluded
//   accumulate : exponential history, alpha = max(alpha, 1 / length); moments of the
//                luminance; optional A-SVGF-style reset from window means
//   variance   : temporal variance from the moments, or a 7x7 bilateral spatial estimate
//                while the history is short (boosted by 4 / length) (section 4.2)
//   atrous     : one iteration of the 5x5 B3-spline a-trous wavelet with SVGF's depth,
//                normal and variance-scaled luminance weights, variance filtered with the
//                squared weights (section 4.3); iteration `feedback` feeds the history
//   atrous_prep, atrous_weight, atrous_conserving : the light-conserving iteration
//                (temporal.atrous = conserving): symmetric weights e(p, q) = e(q, p), each
//                pixel's weight sum W, then out_p = X_p + sum s_pq r_pq (X_q - X_p) with
//                s_pq = k e / max(W_p, W_q) and the albedo share r_pq = min(a_p, a_q) / a_p:
//                the radiance p takes from q, q gives (docs/temporal.md)
//   modulate   : x albedo -> radiance for the composite
//   view_*     : the stage's views
// CPU twin: reference::temporal (every entry point).
#include "common/color.wgsl"
#include "common/camera.wgsl"

// Twin: `GpuTemporalParams` in src/renderer/passes/temporal.rs.
struct TemporalParams {
    width: u32,
    height: u32,
    first: u32,            // 1: no history (first frame, reset)
    gradient: u32,         // 1: the history reset
    scale: f32,            // the method's accumulation scale
    alpha: f32,
    moments_alpha: f32,
    max_history: f32,
    normal_cos: f32,
    depth_tolerance: f32,
    sigma_l: f32,
    sigma_n: f32,
    sigma_z: f32,
    gradient_scale: f32,
    spatial_frames: f32,
    step: u32,             // a-trous step (pixels)
    iteration: u32,        // a-trous iteration, 1-based
    feedback: u32,         // the iteration whose output becomes the history (0: none)
    view_iteration: u32,   // the iteration copied for its view
    view_mode: u32,
    view_lo: f32,
    view_hi: f32,
    conserving: u32,       // 1: the variance pass keeps the colour (conserving a-trous)
    _pad1: u32,
};

@group(0) @binding(0) var<uniform> p: TemporalParams;
@group(0) @binding(1) var<uniform> camera: Camera;
@group(0) @binding(2) var<uniform> prev_camera: Camera;
@group(0) @binding(3) var gb_position: texture_2d<f32>;
@group(0) @binding(4) var gb_normal: texture_2d<f32>;
@group(0) @binding(5) var gb_albedo: texture_2d<f32>;
@group(0) @binding(6) var<storage, read> accum: array<vec4<f32>>;
// 2 vec4 per pixel: position (w = material id + 1), normal.
@group(0) @binding(7) var<storage, read> prev_gb: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> next_gb: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read> hist_color_prev: array<vec4<f32>>;    // demod rgb, length
@group(0) @binding(10) var<storage, read> hist_moments_prev: array<vec4<f32>>; // m1, m2
@group(0) @binding(11) var<storage, read_write> current: array<vec4<f32>>;     // demod rgb, luminance
@group(0) @binding(12) var<storage, read_write> reproj: array<vec4<f32>>;      // demod rgb, length
@group(0) @binding(13) var<storage, read_write> reproj_moments: array<vec4<f32>>;
@group(0) @binding(14) var<storage, read_write> motion: array<vec4<f32>>;      // dx, dy, mask, reset
@group(0) @binding(15) var<storage, read_write> hist_color_next: array<vec4<f32>>;
@group(0) @binding(16) var<storage, read_write> hist_moments_next: array<vec4<f32>>;
@group(0) @binding(17) var<storage, read_write> integrated: array<vec4<f32>>;  // demod rgb, length
@group(0) @binding(18) var<storage, read> src: array<vec4<f32>>;               // demod rgb, variance
@group(0) @binding(19) var<storage, read_write> dst: array<vec4<f32>>;
@group(0) @binding(20) var<storage, read_write> out_radiance: array<vec4<f32>>;
@group(0) @binding(21) var<storage, read_write> raw: array<vec4<f32>>;         // radiance
@group(0) @binding(22) var<storage, read_write> iter_copy: array<vec4<f32>>;
@group(0) @binding(23) var view_radiance_out: texture_storage_2d<rgba32float, write>;
@group(0) @binding(24) var view_out: texture_storage_2d<rgba8unorm, write>;
// The conserving a-trous: per pixel (view depth, depth derivative, luminance, prefiltered
// variance; w = -1 uncovered), and its weight sum W.
@group(0) @binding(25) var<storage, read_write> aux: array<vec4<f32>>;
@group(0) @binding(26) var<storage, read_write> weight: array<f32>;

const EMPTY: vec4<f32> = vec4<f32>(0.0);
// fwidth(z)'s floor relative to the depth (a plane facing the camera has a zero depth
// gradient, and the G-buffer's positions carry float noise SVGF's 1e-8 would amplify).
const DEPTH_FLOOR: f32 = 1e-4;

fn idx(q: vec2<i32>) -> u32 {
    return u32(q.y) * p.width + u32(q.x);
}

fn inside(q: vec2<i32>) -> bool {
    return q.x >= 0 && q.y >= 0 && q.x < i32(p.width) && q.y < i32(p.height);
}

fn view_depth(x: vec3<f32>) -> f32 {
    return dot(x - camera.position.xyz, camera.forward.xyz);
}

// Radiance / albedo per channel (0 where the albedo is below 1e-3: no diffuse GI there).
fn demodulate(c: vec3<f32>, a: vec3<f32>) -> vec3<f32> {
    return select(vec3<f32>(0.0), c / max(a, vec3<f32>(1e-3)), a > vec3<f32>(1e-3));
}

// The continuous pixel coordinates (pixel centres at integers) of world point x in the
// previous camera; z <= 0: behind it. Inverse of camera_ray_dir.
fn prev_pixel(x: vec3<f32>) -> vec3<f32> {
    let d = x - prev_camera.position.xyz;
    let z = dot(d, prev_camera.forward.xyz);
    let r = prev_camera.right.xyz;
    let u = prev_camera.up.xyz;
    let sx = dot(d, r) / (z * dot(r, r));
    let sy = dot(d, u) / (z * dot(u, u));
    return vec3<f32>(
        (sx + 1.0) * 0.5 * f32(p.width) - 0.5,
        (1.0 - sy) * 0.5 * f32(p.height) - 0.5,
        z
    );
}

// Whether the previous frame's pixel q shows the current pixel's surface (same material,
// normal within normal_cos, within depth_tolerance x view depth of its tangent plane).
fn tap_ok(q: vec2<i32>, g: vec4<f32>, n: vec3<f32>, tol: f32) -> bool {
    if !inside(q) {
        return false;
    }
    let k = idx(q);
    let pg = prev_gb[2u * k];
    let pn = prev_gb[2u * k + 1u].xyz;
    return pg.w == g.w && dot(pn, n) >= p.normal_cos && abs(dot(n, pg.xyz - g.xyz)) <= tol;
}

@compute @workgroup_size(8, 8, 1)
fn reproject(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= p.width || gid.y >= p.height {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let k = idx(px);
    let g = textureLoad(gb_position, px, 0);
    let n = normalize(textureLoad(gb_normal, px, 0).xyz);
    let radiance = accum[k].rgb * p.scale;
    raw[k] = vec4<f32>(radiance, 1.0);
    next_gb[2u * k] = g;
    next_gb[2u * k + 1u] = vec4<f32>(select(vec3<f32>(0.0), n, g.w != 0.0), 0.0);
    if g.w == 0.0 {
        current[k] = EMPTY;
        reproj[k] = EMPTY;
        reproj_moments[k] = EMPTY;
        motion[k] = EMPTY;
        return;
    }
    let c = demodulate(radiance, textureLoad(gb_albedo, px, 0).rgb);
    current[k] = vec4<f32>(c, luminance(c));
    var hist = EMPTY;
    var mom = EMPTY;
    var mask = 0.0;
    var mv = vec2<f32>(0.0);
    if p.first == 0u {
        let pp = prev_pixel(g.xyz);
        mv = pp.xy - vec2<f32>(px);
        let tol = p.depth_tolerance * max(view_depth(g.xyz), 1e-6);
        // In front of the previous camera and not absurdly far off its image (a point on its
        // plane would overflow the integer taps).
        if pp.z > 0.0 && all(abs(pp.xy) < vec2<f32>(1e6)) {
            let base = vec2<i32>(floor(pp.xy));
            let f = pp.xy - floor(pp.xy);
            var wsum = 0.0;
            for (var j = 0; j < 4; j++) {
                let o = vec2<i32>(j & 1, j >> 1u);
                let q = base + o;
                let w = select(1.0 - f.x, f.x, o.x == 1) * select(1.0 - f.y, f.y, o.y == 1);
                if w > 0.0 && tap_ok(q, g, n, tol) {
                    hist += w * hist_color_prev[idx(q)];
                    mom += w * hist_moments_prev[idx(q)];
                    wsum += w;
                }
            }
            if wsum > 1e-3 {
                hist /= wsum;
                mom /= wsum;
                mask = wsum;
            } else {
                // SVGF's fallback: the valid pixels of the 3x3 around the reprojected one.
                hist = EMPTY;
                mom = EMPTY;
                var cnt = 0.0;
                let centre = vec2<i32>(floor(pp.xy + 0.5));
                for (var j = 0; j < 9; j++) {
                    let q = centre + vec2<i32>(j % 3 - 1, j / 3 - 1);
                    if tap_ok(q, g, n, tol) {
                        hist += hist_color_prev[idx(q)];
                        mom += hist_moments_prev[idx(q)];
                        cnt += 1.0;
                    }
                }
                if cnt > 0.0 {
                    hist /= cnt;
                    mom /= cnt;
                    mask = -1.0;
                } else {
                    hist = EMPTY;
                    mom = EMPTY;
                }
            }
        }
    }
    reproj[k] = hist;
    reproj_moments[k] = mom;
    motion[k] = vec4<f32>(mv, mask, 0.0);
}

// Same-surface test of the reset's window (the reprojection's normal and plane test).
fn same_surface(g: vec4<f32>, n: vec3<f32>, q: vec2<i32>, tol: f32) -> bool {
    let gq = textureLoad(gb_position, q, 0);
    let nq = normalize(textureLoad(gb_normal, q, 0).xyz);
    return gq.w != 0.0 && dot(nq, n) >= p.normal_cos && abs(dot(n, gq.xyz - g.xyz)) <= tol;
}

@compute @workgroup_size(8, 8, 1)
fn accumulate(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= p.width || gid.y >= p.height {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let k = idx(px);
    let g = textureLoad(gb_position, px, 0);
    if g.w == 0.0 {
        hist_color_next[k] = EMPTY;
        hist_moments_next[k] = EMPTY;
        integrated[k] = EMPTY;
        return;
    }
    let cur = current[k];
    let r = reproj[k];
    let len_prev = r.w;
    let len = min(len_prev + 1.0, p.max_history);
    var a = max(p.alpha, 1.0 / len);
    var am = max(p.moments_alpha, 1.0 / len);
    var reset = 0.0;
    if p.gradient == 1u && len_prev > 0.0 {
        // Window means (7x7, same surface, reprojected pixels) of the new luminance and the
        // history's; the difference beyond two standard errors of the new mean, relative.
        let n = normalize(textureLoad(gb_normal, px, 0).xyz);
        let tol = p.depth_tolerance * max(view_depth(g.xyz), 1e-6);
        var sc = 0.0;
        var sc2 = 0.0;
        var sh = 0.0;
        var cnt = 0.0;
        for (var dy = -3; dy <= 3; dy++) {
            for (var dx = -3; dx <= 3; dx++) {
                let q = px + vec2<i32>(dx, dy);
                if !inside(q) || reproj[idx(q)].w <= 0.0 || !same_surface(g, n, q, tol) {
                    continue;
                }
                let lc = current[idx(q)].w;
                sc += lc;
                sc2 += lc * lc;
                sh += luminance(reproj[idx(q)].rgb);
                cnt += 1.0;
            }
        }
        let mc = sc / cnt;
        let mh = sh / cnt;
        let var_c = max(sc2 / cnt - mc * mc, 0.0);
        let se = sqrt(var_c / cnt);
        let delta = max(abs(mc - mh) - 2.0 * se, 0.0) / max(max(mc, mh), 1e-6);
        reset = clamp(p.gradient_scale * delta, 0.0, 1.0);
        a = mix(a, 1.0, reset);
        am = mix(am, 1.0, reset);
    }
    let color = mix(r.rgb, cur.rgb, a);
    let l = cur.w;
    let m = mix(reproj_moments[k].xy, vec2<f32>(l, l * l), am);
    hist_color_next[k] = vec4<f32>(color, len);
    hist_moments_next[k] = vec4<f32>(m, len, 0.0);
    integrated[k] = vec4<f32>(color, len);
    motion[k].w = reset;
}

// Screen-space derivative of the view depth at px: max(|dz/dx|, |dz/dy|), each the smaller
// one-sided difference to a covered neighbour (the derivative the SVGF reference code keeps
// beside its linear z).
fn depth_fwidth(px: vec2<i32>, z: f32) -> f32 {
    var fw = 0.0;
    for (var axis = 0; axis < 2; axis++) {
        var best = 1e30;
        for (var s = -1; s <= 1; s += 2) {
            let q = px + select(vec2<i32>(0, s), vec2<i32>(s, 0), axis == 0);
            if inside(q) {
                let gq = textureLoad(gb_position, q, 0);
                if gq.w != 0.0 {
                    best = min(best, abs(view_depth(gq.xyz) - z));
                }
            }
        }
        if best < 1e30 {
            fw = max(fw, best);
        }
    }
    return fw;
}

// SVGF's edge-stopping weight of q seen from p (without the kernel): depth (phi_z: sigma_z x
// fwidth(z_p) x step x |offset|), normal (power sigma_n) and luminance (phi_l: sigma_l x the
// filtered standard deviation).
fn edge_weight(zp: f32, zq: f32, phi_z: f32, np: vec3<f32>, nq: vec3<f32>, lp: f32, lq: f32, phi_l: f32) -> f32 {
    let wz = select(abs(zp - zq) / phi_z, 0.0, phi_z == 0.0);
    let wl = abs(lp - lq) / phi_l;
    let wn = pow(clamp(dot(np, nq), 0.0, 1.0), p.sigma_n);
    return exp(-max(wl, 0.0) - max(wz, 0.0)) * wn;
}

@compute @workgroup_size(8, 8, 1)
fn variance(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= p.width || gid.y >= p.height {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let k = idx(px);
    let g = textureLoad(gb_position, px, 0);
    if g.w == 0.0 {
        dst[k] = EMPTY;
        return;
    }
    let it = integrated[k];
    let len = it.w;
    let m = hist_moments_next[k].xy;
    if len >= p.spatial_frames {
        dst[k] = vec4<f32>(it.rgb, max(m.y - m.x * m.x, 0.0));
        return;
    }
    // Short history: 7x7 bilateral estimate of the moments (and the colour), depth and
    // normal weights, luminance weight with phi_l = sigma_l (SVGF's filterMoments).
    let n = normalize(textureLoad(gb_normal, px, 0).xyz);
    let z = view_depth(g.xyz);
    let fw = max(depth_fwidth(px, z), DEPTH_FLOOR * z);
    let lp = luminance(it.rgb);
    var wsum = 0.0;
    var c = vec3<f32>(0.0);
    var mm = vec2<f32>(0.0);
    for (var dy = -3; dy <= 3; dy++) {
        for (var dx = -3; dx <= 3; dx++) {
            let q = px + vec2<i32>(dx, dy);
            if !inside(q) {
                continue;
            }
            let gq = textureLoad(gb_position, q, 0);
            if gq.w == 0.0 {
                continue;
            }
            let nq = normalize(textureLoad(gb_normal, q, 0).xyz);
            let iq = integrated[idx(q)];
            // The reference code's moments filter widens the depth test threefold.
            let phi_z = 3.0 * p.sigma_z * fw * length(vec2<f32>(f32(dx), f32(dy)));
            let w = edge_weight(z, view_depth(gq.xyz), phi_z, n, nq, lp, luminance(iq.rgb), p.sigma_l);
            wsum += w;
            c += w * iq.rgb;
            mm += w * hist_moments_next[idx(q)].xy;
        }
    }
    wsum = max(wsum, 1e-10);
    c /= wsum;
    mm /= wsum;
    let v = max(mm.y - mm.x * mm.x, 0.0) * 4.0 / max(len, 1.0);
    // The conserving choice keeps the pixel's colour (a normalised bilateral blur moves light).
    dst[k] = vec4<f32>(select(c, it.rgb, p.conserving == 1u), v);
}

// The variance of src prefiltered by a 3x3 Gaussian over the covered pixels (SVGF's g(var)).
fn prefiltered_variance(px: vec2<i32>) -> f32 {
    var gv = 0.0;
    var gw = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = px + vec2<i32>(dx, dy);
            if inside(q) && textureLoad(gb_position, q, 0).w != 0.0 {
                let w = select(0.5, 0.25, dx != 0) * select(0.5, 0.25, dy != 0);
                gv += w * src[idx(q)].w;
                gw += w;
            }
        }
    }
    return max(gv / gw, 0.0);
}

// Writes an iteration's output: the next buffer, the history (feedback), the view's copy.
fn store_iteration(k: u32, o: vec4<f32>) {
    dst[k] = o;
    if p.iteration == p.feedback {
        hist_color_next[k] = vec4<f32>(o.rgb, hist_color_next[k].w);
    }
    if p.iteration == p.view_iteration {
        iter_copy[k] = o;
    }
}

const B3 = array<f32, 3>(3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0);

// SVGF's iteration: each output normalised by its own weight sum, the luminance scale from
// the pixel's own variance.
@compute @workgroup_size(8, 8, 1)
fn atrous(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= p.width || gid.y >= p.height {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let k = idx(px);
    let g = textureLoad(gb_position, px, 0);
    if g.w == 0.0 {
        dst[k] = EMPTY;
        if p.iteration == p.view_iteration {
            iter_copy[k] = EMPTY;
        }
        return;
    }
    let c = src[k];
    let n = normalize(textureLoad(gb_normal, px, 0).xyz);
    let z = view_depth(g.xyz);
    let fw = max(depth_fwidth(px, z), DEPTH_FLOOR * z);
    let phi_l = p.sigma_l * sqrt(prefiltered_variance(px) + 1e-10);
    let lp = luminance(c.rgb);
    var h = B3;
    var wsum = h[0] * h[0];
    var sc = wsum * c.rgb;
    var sv = wsum * wsum * c.w;
    let step = i32(p.step);
    for (var dy = -2; dy <= 2; dy++) {
        for (var dx = -2; dx <= 2; dx++) {
            if dx == 0 && dy == 0 {
                continue;
            }
            let q = px + vec2<i32>(dx, dy) * step;
            if !inside(q) {
                continue;
            }
            let gq = textureLoad(gb_position, q, 0);
            if gq.w == 0.0 {
                continue;
            }
            let sq = src[idx(q)];
            let nq = normalize(textureLoad(gb_normal, q, 0).xyz);
            let phi_z = p.sigma_z * fw * f32(step) * length(vec2<f32>(f32(dx), f32(dy)));
            let w = h[abs(dx)] * h[abs(dy)] * edge_weight(z, view_depth(gq.xyz), phi_z, n, nq, lp, luminance(sq.rgb), phi_l);
            wsum += w;
            sc += w * sq.rgb;
            sv += w * w * sq.w;
        }
    }
    store_iteration(k, vec4<f32>(sc / wsum, sv / (wsum * wsum)));
}

// The conserving iteration, pass 1: what the symmetric weights read of each pixel.
@compute @workgroup_size(8, 8, 1)
fn atrous_prep(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= p.width || gid.y >= p.height {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let k = idx(px);
    let g = textureLoad(gb_position, px, 0);
    if g.w == 0.0 {
        aux[k] = vec4<f32>(0.0, 0.0, 0.0, -1.0);
        return;
    }
    let z = view_depth(g.xyz);
    let fw = max(depth_fwidth(px, z), DEPTH_FLOOR * z);
    aux[k] = vec4<f32>(z, fw, luminance(src[k].rgb), prefiltered_variance(px));
}

// The symmetric edge-stopping weight of pixels a and b (their aux records and normals) at
// `dist` steps: SVGF's functions with the depth scale from the larger depth derivative and
// the luminance scale from the larger variance, so that e(a, b) = e(b, a).
fn symmetric_weight(a: vec4<f32>, b: vec4<f32>, na: vec3<f32>, nb: vec3<f32>, dist: f32) -> f32 {
    let phi_z = p.sigma_z * max(a.y, b.y) * f32(p.step) * dist;
    let phi_l = p.sigma_l * sqrt(max(a.w, b.w) + 1e-10);
    return edge_weight(a.x, b.x, phi_z, na, nb, a.z, b.z, phi_l);
}

// The covered tap (dx, dy) of pixel px (its index, or -1).
fn conserving_tap(px: vec2<i32>, dx: i32, dy: i32) -> i32 {
    let q = px + vec2<i32>(dx, dy) * i32(p.step);
    if !inside(q) || aux[idx(q)].w < 0.0 {
        return -1;
    }
    return i32(idx(q));
}

// Pass 2: each pixel's weight sum W (the centre's kernel weight and every covered tap's).
@compute @workgroup_size(8, 8, 1)
fn atrous_weight(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= p.width || gid.y >= p.height {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let k = idx(px);
    let a = aux[k];
    if a.w < 0.0 {
        weight[k] = 0.0;
        return;
    }
    let n = normalize(textureLoad(gb_normal, px, 0).xyz);
    var h = B3;
    var w = h[0] * h[0];
    for (var dy = -2; dy <= 2; dy++) {
        for (var dx = -2; dx <= 2; dx++) {
            let q = conserving_tap(px, dx, dy);
            if (dx == 0 && dy == 0) || q < 0 {
                continue;
            }
            let nq = normalize(textureLoad(gb_normal, px + vec2<i32>(dx, dy) * i32(p.step), 0).xyz);
            let e = symmetric_weight(a, aux[q], n, nq, length(vec2<f32>(f32(dx), f32(dy))));
            w += h[abs(dx)] * h[abs(dy)] * e;
        }
    }
    weight[k] = w;
}

// The share of a conserving transfer to a pixel of albedo a from one of albedo b, per channel:
// min(a, b) / a (a x share = b x its share: radiance given is radiance taken); 0 where either
// albedo is at most 1e-3 (no demodulated GI there).
fn albedo_share(a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    let ok = a > vec3<f32>(1e-3) & b > vec3<f32>(1e-3);
    return select(vec3<f32>(0.0), min(a, b) / max(a, vec3<f32>(1e-3)), ok);
}

// Pass 3: out_p = X_p + sum_q s_pq r_pq (X_q - X_p) per channel, s_pq = k e_pq / max(W_p, W_q)
// symmetric and r_pq the albedo share: the remodulated image's sum stays. Variance
// (1 - sum s l(r))^2 var_p + sum (s l(r))^2 var_q (l: the luminance weights).
@compute @workgroup_size(8, 8, 1)
fn atrous_conserving(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= p.width || gid.y >= p.height {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let k = idx(px);
    let a = aux[k];
    if a.w < 0.0 {
        dst[k] = EMPTY;
        if p.iteration == p.view_iteration {
            iter_copy[k] = EMPTY;
        }
        return;
    }
    let c = src[k];
    let wp = weight[k];
    let n = normalize(textureLoad(gb_normal, px, 0).xyz);
    let ap = textureLoad(gb_albedo, px, 0).rgb;
    var h = B3;
    var d = vec3<f32>(0.0);
    var ssum = 0.0;
    var sv = 0.0;
    for (var dy = -2; dy <= 2; dy++) {
        for (var dx = -2; dx <= 2; dx++) {
            let q = conserving_tap(px, dx, dy);
            if (dx == 0 && dy == 0) || q < 0 {
                continue;
            }
            let tq = px + vec2<i32>(dx, dy) * i32(p.step);
            let nq = normalize(textureLoad(gb_normal, tq, 0).xyz);
            let e = symmetric_weight(a, aux[q], n, nq, length(vec2<f32>(f32(dx), f32(dy))));
            let s = h[abs(dx)] * h[abs(dy)] * e / max(wp, weight[q]);
            let r = s * albedo_share(ap, textureLoad(gb_albedo, tq, 0).rgb);
            let sq = src[q];
            d += r * (sq.rgb - c.rgb);
            let rl = luminance(r);
            ssum += rl;
            sv += rl * rl * sq.w;
        }
    }
    store_iteration(k, vec4<f32>(c.rgb + d, (1.0 - ssum) * (1.0 - ssum) * c.w + sv));
}

@compute @workgroup_size(8, 8, 1)
fn modulate(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= p.width || gid.y >= p.height {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let k = idx(px);
    let a = textureLoad(gb_albedo, px, 0).rgb;
    let on = textureLoad(gb_position, px, 0).w != 0.0;
    out_radiance[k] = vec4<f32>(select(vec3<f32>(0.0), src[k].rgb * a, on), 1.0);
}

// Radiance views into an rgba32float texture the display pass then draws with the view's
// look: 0 raw (radiance), 1 demodulated buffer x albedo.
@compute @workgroup_size(8, 8, 1)
fn view_radiance(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= p.width || gid.y >= p.height {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let k = idx(px);
    var c = src[k].rgb;
    if p.view_mode == 1u {
        c *= textureLoad(gb_albedo, px, 0).rgb;
    }
    textureStore(view_radiance_out, px, vec4<f32>(c, 1.0));
}

fn hue(h: f32) -> vec3<f32> {
    let x = fract(h) * 6.0;
    return clamp(vec3<f32>(abs(x - 3.0) - 1.0, 2.0 - abs(x - 2.0), 2.0 - abs(x - 4.0)), vec3<f32>(0.0), vec3<f32>(1.0));
}

// Diagnostic views straight to the view texture: 0 motion (src = motion: hue = direction,
// brightness = length / view_hi pixels), 1 disocclusion mask (src = motion.z), 2 history
// length (src.w / view_hi), 3 relative standard deviation of the luminance (src = the
// filter's input: sqrt(var) / l, log10 over view_lo .. view_hi), 4 reset (motion.w).
@compute @workgroup_size(8, 8, 1)
fn view_heat(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= p.width || gid.y >= p.height {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let k = idx(px);
    let on = textureLoad(gb_position, px, 0).w != 0.0;
    let v = src[k];
    var c = vec3<f32>(0.0);
    if on {
        switch p.view_mode {
            case 0u: {
                let len = length(v.xy);
                c = hue(atan2(v.y, v.x) / 6.2831853 + 0.5) * clamp(len / p.view_hi, 0.0, 1.0);
                if v.z == 0.0 {
                    c = vec3<f32>(0.25, 0.0, 0.0);
                }
            }
            case 1u: {
                if v.z < 0.0 {
                    c = vec3<f32>(1.0, 0.85, 0.1);
                } else if v.z == 0.0 {
                    c = vec3<f32>(0.9, 0.1, 0.1);
                } else {
                    c = vec3<f32>(0.15 + 0.85 * v.z);
                }
            }
            case 2u: {
                c = false_color(v.w / p.view_hi);
            }
            case 3u: {
                let l = luminance(v.rgb);
                if l > 0.0 {
                    let rel = sqrt(max(v.w, 0.0)) / l;
                    c = false_color((log2(max(rel, 1e-8)) * 0.30103 - p.view_lo) / (p.view_hi - p.view_lo));
                }
            }
            default: {
                c = false_color(v.w);
            }
        }
    }
    textureStore(view_out, px, vec4<f32>(c, 1.0));
}

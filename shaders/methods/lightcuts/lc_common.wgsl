// Lightcuts' per-node data and error bound (Walter et al. 2005, 3.1 and 4.1). CPU twin:
// src/reference/lightcuts.rs (which documents the choices). Needs common/math.wgsl and
// common/sst_node.wgsl.

// Added to a cone's half-angle in the bound (radians): f32 rounding of the merges.
const LC_CONE_MARGIN: f32 = 1e-3;
const LC_NONE: u32 = 0xffffffffu;

// The same frame as `basis` in src/base/sst_node.rs (Duff et al. 2017).
// Upper bound of max(0, cos(angle between unit `axis` and p - x)) over p in [lo, hi]: the
// box's extent along the frame (t, b, axis); for h.z > 0 at most h.z / sqrt(dx^2 + dy^2 +
// h.z^2), dx, dy the smallest |coordinates| of the extent.
fn lc_cos_bound(axis: vec3<f32>, x: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>) -> f32 {
    let tb = sst_basis(axis);
    let c = 0.5 * (lo + hi) - x;
    let r = 0.5 * (hi - lo);
    let mz = dot(axis, c);
    let hz = mz + dot(abs(axis), r);
    if hz <= 0.0 {
        return 0.0;
    }
    let mx = dot(tb[0], c);
    let sx = dot(abs(tb[0]), r);
    let my = dot(tb[1], c);
    let sy = dot(abs(tb[1]), r);
    var d2 = 0.0;
    if !(mx - sx <= 0.0 && mx + sx >= 0.0) {
        d2 += min((mx - sx) * (mx - sx), (mx + sx) * (mx + sx));
    }
    if !(my - sy <= 0.0 && my + sy >= 0.0) {
        d2 += min((my - sy) * (my - sy), (my + sy) * (my + sy));
    }
    if d2 <= 0.0 {
        return 1.0;
    }
    return min(hz / sqrt(d2 + hz * hz), 1.0);
}

fn lc_box_distance2(x: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>) -> f32 {
    let d = max(max(lo - x, vec3<f32>(0.0)), x - hi);
    return dot(d, d);
}

// Upper bound of cos_x x cos_v / max(d^2, eps^2) over VPLs in [lo, hi] with normals in the
// cone (xyz axis, w half-angle; w < 0 = empty).
fn lc_geometry_bound(x: vec3<f32>, n: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>, cone: vec4<f32>, eps: f32) -> f32 {
    let c = lc_cosines(x, n, lo, hi, cone);
    if c.x <= 0.0 {
        return 0.0;
    }
    return c.x * c.y / max(lc_box_distance2(x, lo, hi), eps * eps);
}

// The receiver's and the emitter's cosine bounds (cos_x, cos_v) of a cluster; cos_x = 0 when
// the cone is empty or the box lies behind the receiver (the bound is then 0).
fn lc_cosines(x: vec3<f32>, n: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>, cone: vec4<f32>) -> vec2<f32> {
    if cone.w < 0.0 {
        return vec2<f32>(0.0);
    }
    let cx = lc_cos_bound(n, x, lo, hi);
    if cx <= 0.0 {
        return vec2<f32>(0.0);
    }
    return vec2<f32>(cx, lc_emitter_cos_bound(x, lo, hi, cone));
}

// Upper bound of the emitter's cosine (its normal m against x - p) over VPLs in [lo, hi] with
// normals in the cone: the angle is at least the angle between the cone's axis and x - p
// minus the half-angle.
fn lc_emitter_cos_bound(x: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>, cone: vec4<f32>) -> f32 {
    let c_axis = lc_cos_bound(-cone.xyz, x, lo, hi);
    let phi = acos(clamp(c_axis, 0.0, 1.0));
    let theta = cone.w + LC_CONE_MARGIN;
    var cv = 1.0;
    if phi > theta {
        if phi - theta >= 0.5 * PI {
            cv = 0.0;
        } else {
            cv = cos(phi - theta);
        }
    }
    return cv;
}

// A cluster's unshadowed estimate at (x, n) from its representative `v` (flux / pi x G with
// the cluster's luminance `lum_cluster`). Twin: `cluster_estimate` in
// src/reference/lightcuts.rs. Needs common/vpl.wgsl and common/color.wgsl.
fn lc_estimate(v: Vpl, lum_cluster: f32, x: vec3<f32>, n: vec3<f32>, eps: f32) -> vec3<f32> {
    let lf = luminance(v.flux.rgb);
    let g = vpl_geometry(v.position.xyz, v.normal, x, n, eps);
    if g <= 0.0 || lf <= 0.0 {
        return vec3<f32>(0.0);
    }
    return v.flux.rgb * (lum_cluster / lf) / PI * g;
}

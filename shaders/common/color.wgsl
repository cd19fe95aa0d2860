// Colour helpers: sRGB transfer function, luminance, tonemaps.

fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

fn linear_to_srgb(c: vec3<f32>) -> vec3<f32> {
    let x = clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    let lo = x * 12.92;
    let hi = 1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, x <= vec3<f32>(0.0031308));
}

// An image's displayed grey (sRGB of the tonemapped luminance at `exposure`): the
// background the method views draw their marks on.
fn display_grey(linear: vec3<f32>, exposure: f32, mode: u32) -> f32 {
    let t = tonemap(max(linear * exposure, vec3<f32>(0.0)), mode);
    return linear_to_srgb(vec3<f32>(luminance(t))).x;
}

// 0 = clamp, 1 = Reinhard on luminance, 2 = ACES filmic (Narkowicz 2015 fit).
fn tonemap(c: vec3<f32>, mode: u32) -> vec3<f32> {
    if mode == 1u {
        let l = luminance(c);
        return c / (1.0 + l);
    }
    if mode == 2u {
        let a = 2.51;
        let b = 0.03;
        let cc = 2.43;
        let d = 0.59;
        let e = 0.14;
        return clamp((c * (a * c + b)) / (c * (cc * c + d) + e), vec3<f32>(0.0), vec3<f32>(1.0));
    }
    return clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
}

// A stable pseudo-random colour for an integer id (ids, clusters, cuts).
fn id_color(id: u32) -> vec3<f32> {
    var h = id * 747796405u + 2891336453u;
    h = ((h >> ((h >> 28u) + 4u)) ^ h) * 277803737u;
    h = (h >> 22u) ^ h;
    return vec3<f32>(f32(h & 255u), f32((h >> 8u) & 255u), f32((h >> 16u) & 255u)) / 255.0 * 0.8 + 0.2;
}

// The VPL overlay's colour of diffuse bounce b (1 = RSM VPLs). Twin: base::colormap::bounce_color.
fn bounce_color(b: u32) -> vec3<f32> {
    var palette = array<vec3<f32>, 8>(
        vec3<f32>(1.0, 0.6, 0.1), vec3<f32>(0.2, 0.8, 1.0), vec3<f32>(1.0, 0.3, 0.8),
        vec3<f32>(0.4, 1.0, 0.3), vec3<f32>(1.0, 1.0, 0.3), vec3<f32>(0.6, 0.5, 1.0),
        vec3<f32>(1.0, 1.0, 1.0), vec3<f32>(0.6, 0.6, 0.6));
    return palette[clamp(b, 1u, 8u) - 1u];
}

// Viridis-like false colour for t in [0, 1].
fn false_color(t: f32) -> vec3<f32> {
    let x = clamp(t, 0.0, 1.0);
    let c0 = vec3<f32>(0.2777, 0.0054, 0.3340);
    let c1 = vec3<f32>(0.1050, 1.4046, 1.3845);
    let c2 = vec3<f32>(-0.3308, 0.2148, 0.0950);
    let c3 = vec3<f32>(-4.6342, -5.7991, -19.3324);
    let c4 = vec3<f32>(6.2283, 14.1799, 56.6905);
    let c5 = vec3<f32>(4.7764, -13.7451, -65.3530);
    let c6 = vec3<f32>(-5.4355, 4.6459, 26.3124);
    return clamp(c0 + x * (c1 + x * (c2 + x * (c3 + x * (c4 + x * (c5 + x * c6))))), vec3<f32>(0.0), vec3<f32>(1.0));
}

// v on a log scale from lo (0) to hi (1), clamped: the heat-map views' scale.
fn log_scale(v: f32, lo: f32, hi: f32) -> f32 {
    return clamp(log2(max(v, lo) / lo) / log2(hi / lo), 0.0, 1.0);
}

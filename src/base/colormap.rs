//! Reference of the id and heat colour maps of `shaders/common/color.wgsl`.

/// Stable pseudo-random colour of an integer id (components in [0.2, 1]).
pub fn id_color(id: u32) -> [f32; 3] {
    let mut h = id.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    h = ((h >> ((h >> 28) + 4)) ^ h).wrapping_mul(277_803_737);
    h ^= h >> 22;
    [h & 255, (h >> 8) & 255, (h >> 16) & 255].map(|v| v as f32 / 255.0 * 0.8 + 0.2)
}

/// The VPL overlay's colour of diffuse bounce `b` (1 = the RSM's VPLs): orange, cyan,
/// magenta, green, yellow, violet, white, grey for 1..=8. Twin: `bounce_color` in
/// `shaders/common/color.wgsl`.
pub fn bounce_color(b: u32) -> [f32; 3] {
    const PALETTE: [[f32; 3]; 8] = [
        [1.0, 0.6, 0.1],
        [0.2, 0.8, 1.0],
        [1.0, 0.3, 0.8],
        [0.4, 1.0, 0.3],
        [1.0, 1.0, 0.3],
        [0.6, 0.5, 1.0],
        [1.0, 1.0, 1.0],
        [0.6, 0.6, 0.6],
    ];
    PALETTE[(b.clamp(1, 8) - 1) as usize]
}

/// Viridis-like polynomial false colour of t in [0, 1].
pub fn false_color(t: f32) -> [f32; 3] {
    let x = t.clamp(0.0, 1.0);
    let c: [[f32; 3]; 7] = [
        [0.2777, 0.0054, 0.3340],
        [0.1050, 1.4046, 1.3845],
        [-0.3308, 0.2148, 0.0950],
        [-4.6342, -5.7991, -19.3324],
        [6.2283, 14.1799, 56.6905],
        [4.7764, -13.7451, -65.3530],
        [-5.4355, 4.6459, 26.3124],
    ];
    let mut out = [0.0; 3];
    for k in 0..3 {
        let mut v = c[6][k];
        for i in (0..6).rev() {
            v = c[i][k] + x * v;
        }
        out[k] = v.clamp(0.0, 1.0);
    }
    out
}

pub fn to_unorm8(c: [f32; 3]) -> [u8; 4] {
    let q = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    [q(c[0]), q(c[1]), q(c[2]), 255]
}

/// A heat-map view's colour scale, as the GUI draws its legend.
#[derive(Clone, Debug, PartialEq)]
pub struct Legend {
    pub title: String,
    /// The scale's ends: values, or with `log` their log10 (-4 and 0 for 1e-4 .. 1).
    pub lo: f32,
    pub hi: f32,
    /// log10 scale (else linear).
    pub log: bool,
}

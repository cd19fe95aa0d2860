// Lightcut Interpolation's parameters and weight function (Rehfeld & Dachsbacher 2016,
// section 3.2). CPU twin: src/reference/lightcut_interpolation.rs (`weight`,
// `record_radius`). Twin of the parameters: `GpuLiParams` in
// src/methods/lightcut_interpolation/pass.rs.

const LI_TILE: u32 = 16u;
const LI_TILE_CAP: u32 = 64u;
const LI_VISIBLE: u32 = 0x80000000u;
const LI_NONE: u32 = 0xffffffffu;
// rec_meta: word 0 the record count, 1 records dropped (capacity), 2 tiles at their cap;
// word LI_META_HEADER + r the length of record r's cut.
const LI_META_HEADER: u32 = 8u;

struct LiParams {
    width: u32,
    height: u32,
    tiles_x: u32,
    tiles_y: u32,
    leaves: u32,
    levels: u32,
    max_cut: u32,
    capacity: u32,      // records at most
    r_min_px: f32,
    r_max_px: f32,
    one_minus_cos_max: f32,
    epsilon: f32,       // fallback below this best weight
    coverage: f32,
    radius_rays: u32,
    ray_offset: f32,
    shadow_rays: u32,
    interp_visibility: u32,
    accumulate: u32,
    trace_pixel: u32,   // x | y << 16, or LI_NONE
    steps: u32,         // walk steps per dispatch
    first: u32,         // 1: the dispatch starts the walks
    last: u32,          // 1: it finishes them and writes the outputs
    distance_epsilon: f32,
    _pad: u32,
};

// Tabellion and Lamorlette's weight of the record at (pr, nr) with reach `radius` at the
// shading point (p, n); negative when rejected.
fn li_weight(p: vec3<f32>, n: vec3<f32>, pr: vec3<f32>, nr: vec3<f32>, radius: f32, one_minus_cos_max: f32) -> f32 {
    if dot(p - pr, n + nr) < 0.0 {
        return -1.0;
    }
    let dp = length(p - pr) / max(radius, 1e-12);
    let dn = sqrt(max(1.0 - dot(n, nr), 0.0) / one_minus_cos_max);
    return 1.0 - max(dp, dn);
}

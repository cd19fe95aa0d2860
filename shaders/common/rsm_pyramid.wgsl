// RSM pyramids (importance, flux, bounds) and the VPL-stage parameters that describe them.
// Contract: a shader including this file declares `params: VplParams` (a uniform).
struct VplParams {
    res: u32,             // RSM resolution (power of two)
    levels: u32,          // pyramid levels (log2(res) + 1)
    light_count: u32,
    vpl_count: u32,
    samples: u32,         // importance samples per texel
    filter_radius: u32,
    mode: u32,            // 0 BRSM, 1 RSM (uniform)
    seed: u32,
    sample_radius: f32,   // metres
    n_min: f32,
    d_max: f32,           // metres
    flux_mix: f32,
    epsilon: f32,         // distance bound (metres)
    per_layer: u32,       // pyramid floats per light layer
    _pad0: u32,
    _pad1: u32,
    ranges: array<vec4<u32>, 4>,       // per light: x first VPL, y VPL count
    level_offsets: array<vec4<u32>, 4>, // offset of pyramid level l in a layer: [l / 4][l % 4]
};

fn level_offset(l: u32) -> u32 {
    return params.level_offsets[l / 4u][l % 4u];
}

fn pyr_index(layer: u32, level: u32, x: u32, y: u32) -> u32 {
    let r = params.res >> level;
    return layer * params.per_layer + level_offset(level) + y * r + x;
}

// Index of node (x, y) of `level` >= 1 in the bounds pyramid, which stores no level 0 (a
// level-0 node's box is its texel's position in the RSM). Two vec4 per node: min, max.
fn bounds_index(layer: u32, level: u32, x: u32, y: u32) -> u32 {
    let r = params.res >> level;
    let level0 = params.res * params.res;
    return layer * (params.per_layer - level0) + (level_offset(level) - level0) + y * r + x;
}

// Hierarchical warping (Clarberg et al. 2005) through the RSM pyramids: the VPL stage's
// texel choice (vpl_gen.wgsl) and the light paths' starts (light_paths.wgsl). CPU twin:
// `reference::vpl::warp`.
// Contract: the includer includes common/rsm_pyramid.wgsl and declares
// `importance_pyramid` and `flux_pyramid` (storage arrays of f32, read or read_write).

// Selection weight of a pyramid node: (1 - m) importance share + m flux share.
fn node_weight(layer: u32, level: u32, x: u32, y: u32, wi: f32, wf: f32) -> f32 {
    let k = pyr_index(layer, level, x, y);
    return wi * importance_pyramid[k] + wf * flux_pyramid[k];
}

// Hierarchical warping of point `uv` through the pyramids of `layer`, top level down, each
// level first vertically then horizontally. Returns (texel x, texel y, pmf bits).
fn warp(layer: u32, uv_in: vec2<f32>, wi: f32, wf: f32) -> vec3<u32> {
    var uv = uv_in;
    var x = 0u;
    var y = 0u;
    let one_minus = 0.99999994;
    for (var l = params.levels - 1u; l > 0u; l--) {
        let cl = l - 1u;
        let a = node_weight(layer, cl, 2u * x, 2u * y, wi, wf);
        let b = node_weight(layer, cl, 2u * x + 1u, 2u * y, wi, wf);
        let c = node_weight(layer, cl, 2u * x, 2u * y + 1u, wi, wf);
        let d = node_weight(layer, cl, 2u * x + 1u, 2u * y + 1u, wi, wf);
        let top = a + b;
        let bottom = c + d;
        let pt = top / (top + bottom);
        var row = 0u;
        if uv.y < pt {
            uv.y = min(uv.y / pt, one_minus);
        } else {
            uv.y = min((uv.y - pt) / (1.0 - pt), one_minus);
            row = 1u;
        }
        let left = select(a, c, row == 1u);
        let right = select(b, d, row == 1u);
        let pl = left / (left + right);
        var col = 0u;
        if uv.x < pl {
            uv.x = min(uv.x / pl, one_minus);
        } else {
            uv.x = min((uv.x - pl) / (1.0 - pl), one_minus);
            col = 1u;
        }
        x = 2u * x + col;
        y = 2u * y + row;
    }
    let total = node_weight(layer, params.levels - 1u, 0u, 0u, wi, wf);
    let pmf = node_weight(layer, 0u, x, y, wi, wf) / total;
    return vec3<u32>(x, y, bitcast<u32>(pmf));
}

// The light whose budget range (x = first index, y = count) holds index i: the VPLs' and the
// light paths' split between the lights.
fn range_layer(i: u32, ranges: array<vec4<u32>, 4>, count: u32) -> u32 {
    var layer = 0u;
    for (var l = 0u; l < count; l++) {
        if i >= ranges[l].x && i < ranges[l].x + ranges[l].y {
            layer = l;
        }
    }
    return layer;
}

// Warps `uv` through light `layer`'s mixed PDF: (1 - m) importance share + m flux share,
// each normalised by its pyramid's total (flux only where the layer has no importance).
// Returns (texel x, texel y, pmf bits); pmf 0 where the layer reflects no flux.
fn warp_mixed(layer: u32, uv: vec2<f32>, flux_mix: f32) -> vec3<u32> {
    let total_flux = flux_pyramid[pyr_index(layer, params.levels - 1u, 0u, 0u)];
    if !(total_flux > 0.0) {
        return vec3<u32>(0u, 0u, bitcast<u32>(0.0));
    }
    let total_imp = importance_pyramid[pyr_index(layer, params.levels - 1u, 0u, 0u)];
    var m = flux_mix;
    if !(total_imp > 0.0) {
        m = 1.0;
    }
    let wi = select(0.0, (1.0 - m) / total_imp, total_imp > 0.0);
    return warp(layer, uv, wi, m / total_flux);
}

// Draws the frame's VPLs as discs over the view texture (after display/visualise), coloured by
// flux on a log scale relative to the mean VPL flux (false colour: 1/100 of the mean -> 0,
// 100x the mean -> 1) or by the bounce their light has made (`color_mode` 1). Space 0: the camera view (projected; hidden VPLs drawn at half
// brightness); space 1: RSM texel space of light `layer` (views of the RSM and its maps).
#include "common/camera.wgsl"
#include "common/color.wgsl"
#include "common/vpl.wgsl"

struct SplatParams {
    count: u32,
    space: u32,
    radius: u32,       // disc radius in view pixels
    layer: u32,
    rsm_res: u32,
    light_count: u32,
    per_layer: u32,    // floats per light layer of the flux pyramid
    top_offset: u32,   // offset of the pyramid's top level within a layer
    color_mode: u32,   // 0 flux, 1 bounce
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(0) @binding(0) var<uniform> sp: SplatParams;
@group(0) @binding(1) var<uniform> camera: Camera;
@group(0) @binding(2) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(3) var gb_position: texture_2d<f32>;
@group(0) @binding(4) var dst: texture_storage_2d<rgba8unorm, write>;
// Flux-luminance pyramid: the tops summed over lights / count = the mean VPL flux's
// expected luminance.
@group(0) @binding(5) var<storage, read> flux_pyramid: array<f32>;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i >= sp.count {
        return;
    }
    let v = vpls[i];
    if v.id == VPL_NONE {
        return;
    }
    let size = vec2<f32>(textureDimensions(dst));
    var centre = vec2<f32>(0.0);
    var shade = 1.0;
    if sp.space == 1u {
        if (v.id >> 24u) != sp.layer {
            return;
        }
        let t = v.id & 0xffffffu;
        let texel = vec2<f32>(f32(t % sp.rsm_res), f32(t / sp.rsm_res)) + 0.5;
        centre = texel / f32(sp.rsm_res) * size;
    } else {
        let clip = camera.view_proj * vec4<f32>(v.position.xyz, 1.0);
        if clip.w <= 0.0 {
            return;
        }
        let ndc = clip.xyz / clip.w;
        centre = vec2<f32>(0.5 * ndc.x + 0.5, 0.5 - 0.5 * ndc.y) * size;
        if any(centre < vec2<f32>(0.0)) || any(centre >= size) {
            return;
        }
        // Hidden behind the G-buffer surface at that pixel: draw dimmer.
        let gsize = vec2<f32>(textureDimensions(gb_position));
        let g = textureLoad(gb_position, vec2<i32>(centre / size * gsize), 0);
        let dv = distance(camera.position.xyz, v.position.xyz);
        let dg = distance(camera.position.xyz, g.xyz);
        if g.w > 0.0 && dv > dg * 1.01 + 0.01 {
            shade = 0.45;
        }
    }
    var total = 0.0;
    for (var l = 0u; l < sp.light_count; l++) {
        total += flux_pyramid[l * sp.per_layer + sp.top_offset];
    }
    let mean_flux = total / f32(sp.count);
    let lum = luminance(v.flux.rgb);
    let t = (log2(max(lum, 1e-30) / max(mean_flux, 1e-30)) * 0.30103 + 2.0) / 4.0;
    var rgb = false_color(t);
    if sp.color_mode == 1u {
        rgb = bounce_color(vpl_bounce(v.id));
    }
    let c = vec4<f32>(rgb * shade, 1.0);
    let r = i32(sp.radius);
    let ci = vec2<i32>(centre);
    for (var dy = -r; dy <= r; dy++) {
        for (var dx = -r; dx <= r; dx++) {
            if dx * dx + dy * dy > r * r {
                continue;
            }
            let p = ci + vec2<i32>(dx, dy);
            if all(p >= vec2<i32>(0)) && all(p < vec2<i32>(size)) {
                textureStore(dst, p, c);
            }
        }
    }
}

// Display: exposure, tonemap and sRGB encoding of a linear-radiance buffer into the Rgba8Unorm
// texture the UI shows (and the PNG exports use), with the view's look: channel isolation,
// log10 false colour of the (isolated) value, NaN/Inf highlight. CPU twin:
// `base::display::encode_look`.
#include "common/color.wgsl"

struct DisplayParams {
    exposure: f32,
    tonemap: u32,
    // 0 rgb, 1 r, 2 g, 3 b, 4 luminance
    channel: u32,
    // bit 0: false colour over log10 [lo, hi] (no exposure); bit 1: NaN/Inf magenta
    flags: u32,
    lo: f32,
    hi: f32,
    _pad: vec2<u32>,
};

@group(0) @binding(0) var<uniform> params: DisplayParams;
@group(0) @binding(1) var src: texture_2d<f32>;
@group(0) @binding(2) var dst: texture_storage_2d<rgba8unorm, write>;

fn isolate(c: vec3<f32>, channel: u32) -> vec3<f32> {
    switch channel {
        case 1u: { return vec3<f32>(c.r); }
        case 2u: { return vec3<f32>(c.g); }
        case 3u: { return vec3<f32>(c.b); }
        case 4u: { return vec3<f32>(luminance(c)); }
        default: { return c; }
    }
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(dst);
    if gid.x >= size.x || gid.y >= size.y {
        return;
    }
    let raw = isolate(textureLoad(src, vec2<i32>(gid.xy), 0).rgb, params.channel);
    // NaN/inf (tested on the bits: compilers may fold `x != x` away) shows as magenta so it
    // cannot hide, or as black when the highlight is off.
    let exp_bits = bitcast<vec3<u32>>(raw) & vec3<u32>(0x7f800000u);
    if any(exp_bits == vec3<u32>(0x7f800000u)) {
        let bad = select(vec4<f32>(0.0, 0.0, 0.0, 1.0), vec4<f32>(1.0, 0.0, 1.0, 1.0), (params.flags & 2u) != 0u);
        textureStore(dst, vec2<i32>(gid.xy), bad);
        return;
    }
    if (params.flags & 1u) != 0u {
        // The isolated channel (luminance for rgb) in radiance units; zero stays black.
        let v = select(raw.r, luminance(raw), params.channel == 0u);
        var out = vec3<f32>(0.0);
        if v > 0.0 {
            out = false_color((log2(v) * 0.30103 - params.lo) / max(params.hi - params.lo, 1e-6));
        }
        textureStore(dst, vec2<i32>(gid.xy), vec4<f32>(out, 1.0));
        return;
    }
    let c = raw * params.exposure;
    let t = tonemap(max(c, vec3<f32>(0.0)), params.tonemap);
    textureStore(dst, vec2<i32>(gid.xy), vec4<f32>(linear_to_srgb(t), 1.0));
}

// The VAL method's clustering RSM: layer `layer` of light 0's RSM summed down by `factor`
// (each coarse texel: its block's lit texels' summed flux, mean position, normalised summed
// normal and summed surface area in the flux's alpha; position.w 1 when any is lit, else all
// zero). Twin: reference::val::downsample.

struct DownParams {
    res: u32,          // the coarse resolution
    factor: u32,       // fine texels per coarse texel edge
    layer: u32,
    _pad0: u32,
    light_dir: vec3<f32>,
    texel_area: f32,   // a fine texel's area perpendicular to the light
};

@group(0) @binding(0) var<uniform> dp: DownParams;
@group(0) @binding(1) var rsm_position: texture_2d_array<f32>;
@group(0) @binding(2) var rsm_normal: texture_2d_array<f32>;
@group(0) @binding(3) var rsm_flux: texture_2d_array<f32>;
@group(0) @binding(4) var out_position: texture_storage_2d<rgba32float, write>;
@group(0) @binding(5) var out_normal: texture_storage_2d<rgba32float, write>;
@group(0) @binding(6) var out_flux: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= dp.res || gid.y >= dp.res {
        return;
    }
    let l = i32(dp.layer);
    var n = 0u;
    var pos = vec3<f32>(0.0);
    var nrm = vec3<f32>(0.0);
    var flux = vec3<f32>(0.0);
    var area = 0.0;
    for (var dy = 0u; dy < dp.factor; dy++) {
        for (var dx = 0u; dx < dp.factor; dx++) {
            let c = vec2<i32>(gid.xy * dp.factor + vec2<u32>(dx, dy));
            let p = textureLoad(rsm_position, c, l, 0);
            let f = textureLoad(rsm_flux, c, l, 0).rgb;
            if p.w <= 0.0 || max(f.r, max(f.g, f.b)) <= 0.0 {
                continue;
            }
            let nn = textureLoad(rsm_normal, c, l, 0).xyz;
            n += 1u;
            pos += p.xyz;
            nrm += nn;
            flux += f;
            // Twin: Rsm::surface_area.
            area += dp.texel_area / max(dot(nn, -dp.light_dir), 0.05);
        }
    }
    let t = vec2<i32>(gid.xy);
    if n == 0u {
        textureStore(out_position, t, vec4<f32>(0.0));
        textureStore(out_normal, t, vec4<f32>(0.0));
        textureStore(out_flux, t, vec4<f32>(0.0));
        return;
    }
    var normal = vec3<f32>(0.0, 0.0, 1.0);
    if dot(nrm, nrm) > 0.0 {
        normal = normalize(nrm);
    }
    textureStore(out_position, t, vec4<f32>(pos / f32(n), 1.0));
    textureStore(out_normal, t, vec4<f32>(normal, 0.0));
    textureStore(out_flux, t, vec4<f32>(flux, area));
}

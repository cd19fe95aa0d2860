// Composite: indirect = the GI method's accumulation buffer x scale (1 / frames or samples
// accumulated); final = direct + indirect. Both linear radiance.

struct CompositeParams {
    width: u32,
    height: u32,
    indirect_scale: f32,
    _pad: u32,
};

@group(0) @binding(0) var<uniform> params: CompositeParams;
@group(0) @binding(1) var direct: texture_2d<f32>;
@group(0) @binding(2) var<storage, read> accum: array<vec4<f32>>;
@group(0) @binding(3) var out_indirect: texture_storage_2d<rgba32float, write>;
@group(0) @binding(4) var out_final: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= params.width || gid.y >= params.height {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let ind = accum[gid.y * params.width + gid.x].rgb * params.indirect_scale;
    let d = textureLoad(direct, px, 0).rgb;
    textureStore(out_indirect, px, vec4<f32>(ind, 1.0));
    textureStore(out_final, px, vec4<f32>(d + ind, 1.0));
}

// Algorithm 1, step 1: each VPL's fall-off parameters and range (lcull_light.wgsl).
// Output per VPL: lights[2i] = (position, range), lights[2i + 1] = (threshold, floor, 0, 0);
// with ISM visibility also its map's light (lcull_ism_light) into ism_lights.
// Twin: reference::light_culling::light_range.
#include "common/math.wgsl"
#include "common/vpl.wgsl"
#include "methods/light_culling/lcull_common.wgsl"
#include "methods/light_culling/lcull_light.wgsl"

@group(0) @binding(0) var<uniform> params: LcullParams;
@group(0) @binding(1) var<storage, read> vpls: array<Vpl>;
@group(0) @binding(2) var<storage, read_write> lights: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> ism_lights: array<vec4<f32>>;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if i >= params.count {
        return;
    }
    let l = lcull_light(params, vpls[i], i);
    lights[2u * i] = l.position_range;
    lights[2u * i + 1u] = l.falloff;
    if (params.ism_flags & 1u) != 0u && 2u * i + 1u < arrayLength(&ism_lights) {
        let m = lcull_ism_light(params, l.position_range.xyz, vpls[i].normal, l.position_range.w);
        ism_lights[2u * i] = m[0];
        ism_lights[2u * i + 1u] = m[1];
    }
}

// Fragment counting for `bench gbuffer` (src/renderer/passes/gbuffer.rs, OverdrawCounter):
// the G-buffer's vertex stage (same vertex format, same transform, same invariant position)
// and a fragment stage that adds 1 to an Rgba16Float counter (additive blending) for every
// fragment that reaches it.
#include "common/camera.wgsl"
#include "common/vertex.wgsl"

@group(0) @binding(0) var<uniform> camera: Camera;

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    return transform_vertex(v, camera.view_proj);
}

@fragment
fn fs_count() -> @location(0) vec4<f32> {
    return vec4<f32>(1.0, 0.0, 0.0, 1.0);
}

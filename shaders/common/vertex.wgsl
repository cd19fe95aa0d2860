// The scene's vertex format (twin of `GpuVertex` in src/renderer/gpu_data.rs and
// `VERTEX_ATTRIBUTES` in src/renderer/passes/gbuffer.rs) and what raster passes interpolate.

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) material: u32,
};

struct VertexOut {
    // Invariant: the G-buffer's depth pre-pass and its shading pass (depth test Equal) must
    // compute bit-identical depths from the same vertex.
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) @interpolate(flat) material: u32,
};

// Transforms a scene vertex by `view_proj`, passing the world attributes through.
fn transform_vertex(v: VertexIn, view_proj: mat4x4<f32>) -> VertexOut {
    var o: VertexOut;
    o.clip = view_proj * vec4<f32>(v.position, 1.0);
    o.world = v.position;
    o.normal = v.normal;
    o.uv = v.uv;
    o.material = v.material;
    return o;
}

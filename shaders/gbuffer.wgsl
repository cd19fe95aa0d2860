// G-buffer pass: rasterise the scene from the camera.
// Outputs (see src/renderer/frame.rs):
//   0 position: Rgba32Float, xyz world position, w = material id + 1 (0 = no geometry)
//   1 normal:   Rgba16Float, xyz unit shading normal facing the camera, w = roughness (glTF factor x texture G)
//   2 albedo:   Rgba16Float, rgb linear base colour = baseColorFactor x texture, a = metallic (factor x texture B)
// (roughness and metallic: the GGX BRDF's, `common/brdf.wgsl`; Lambert reads rgb only)
#include "common/camera.wgsl"
#include "common/material.wgsl"
#include "common/vertex.wgsl"

@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var<storage, read> materials: array<MaterialGpu>;
@group(0) @binding(2) var textures: texture_2d_array<f32>;
@group(0) @binding(3) var tex_sampler: sampler;



// VertexOut plus the metallic-roughness textures' UVs (`material_mr_uv`, per vertex).
struct GbufferVertexOut {
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) @interpolate(flat) material: u32,
    @location(4) uv_mr: vec2<f32>,
};

@vertex
fn vs_main(v: VertexIn) -> GbufferVertexOut {
    let o = transform_vertex(v, camera.view_proj);
    return GbufferVertexOut(o.clip, o.world, o.normal, o.uv, o.material, material_mr_uv(o.material, o.uv));
}

struct GbufferOut {
    @location(0) position: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) albedo: vec4<f32>,
};

@fragment
fn fs_main(i: GbufferVertexOut, @builtin(front_facing) front: bool) -> GbufferOut {
    let albedo = material_albedo(i.material, i.uv);
    // Two-sided: shade the side the camera sees.
    var n = normalize(i.normal);
    if !front {
        n = -n;
    }
    var o: GbufferOut;
    o.position = vec4<f32>(i.world, f32(i.material + 1u));
    let mr = material_metal_rough(i.material, i.uv_mr);
    o.normal = vec4<f32>(n, mr.y);
    o.albedo = vec4<f32>(albedo.rgb, mr.x);
    return o;
}

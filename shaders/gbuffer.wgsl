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



@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    return transform_vertex(v, camera.view_proj);
}

struct GbufferOut {
    @location(0) position: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) albedo: vec4<f32>,
};

@fragment
fn fs_main(i: VertexOut, @builtin(front_facing) front: bool) -> GbufferOut {
    let albedo = material_albedo(i.material, i.uv);
    // Two-sided: shade the side the camera sees.
    var n = normalize(i.normal);
    if !front {
        n = -n;
    }
    var o: GbufferOut;
    o.position = vec4<f32>(i.world, f32(i.material + 1u));
    let mr = material_metal_rough(i.material, i.uv);
    o.normal = vec4<f32>(n, mr.y);
    o.albedo = vec4<f32>(albedo.rgb, mr.x);
    return o;
}

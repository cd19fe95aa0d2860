// Reflective shadow map (Dachsbacher & Stamminger 2005) of one directional light: an
// orthographic raster from the light (one array layer per light) writing depth (the shadow
// map) and, per texel, what the potential VPL there needs:
//   0 position: Rgba32Float, xyz world position, w = 1 (0 = empty texel)
//   1 normal:   Rgba16Float, xyz unit normal of the side the light sees
//   2 flux:     Rgba16Float, rgb reflected flux (W) = albedo x E x texel area
// The texel area is measured perpendicular to the light, so E x area is the power the
// texel's surface receives whatever its inclination (no cosine).
#include "common/material.wgsl"
#include "common/vertex.wgsl"

struct RsmLight {
    view_proj: mat4x4<f32>,
    irradiance: vec4<f32>, // rgb E (W/m^2), w = texel area (m^2)
};

@group(0) @binding(0) var<uniform> light: RsmLight;
@group(0) @binding(1) var<storage, read> materials: array<MaterialGpu>;
@group(0) @binding(2) var textures: texture_2d_array<f32>;
@group(0) @binding(3) var tex_sampler: sampler;



@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    return transform_vertex(v, light.view_proj);
}

struct RsmOut {
    @location(0) position: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) flux: vec4<f32>,
};

@fragment
fn fs_main(i: VertexOut, @builtin(front_facing) front: bool) -> RsmOut {
    let albedo = material_albedo(i.material, i.uv).rgb;
    var n = normalize(i.normal);
    if !front {
        n = -n;
    }
    var o: RsmOut;
    o.position = vec4<f32>(i.world, 1.0);
    o.normal = vec4<f32>(n, 1.0);
    o.flux = vec4<f32>(albedo * light.irradiance.rgb * light.irradiance.w, 1.0);
    return o;
}

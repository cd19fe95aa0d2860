// Materials: albedo = baseColorFactor x sRGB-decoded base colour texture; metallic and
// roughness = glTF's factors x the metallic-roughness texture's B and G (stored sRGB-encoded,
// so the sampler returns the linear data).
// Twin of `GpuMaterial` in src/renderer/gpu_data.rs.
//
// Contract: a shader including this file declares `materials: array<MaterialGpu>` (storage),
// `textures: texture_2d_array<f32>` and `tex_sampler: sampler` with its own bindings.

struct MaterialGpu {
    base_color: vec4<f32>,
    texture: vec4<i32>, // layers in `textures` or -1: x base colour, y roughness (G), z metallic (B)
    params: vec4<f32>,  // x = metallic, y = roughness (glTF factors)
    // The metallic-roughness textures' UVs from the vertex UVs: u' = dot(mr_uv[0].xyz, (u, v, 1)),
    // v' = dot(mr_uv[1].xyz, (u, v, 1)) (KHR_texture_transform; the identity by default).
    mr_uv: array<vec4<f32>, 2>,
};

// Implicit-derivative sampling: fragment shaders only.
fn material_albedo(material: u32, uv: vec2<f32>) -> vec4<f32> {
    let m = materials[material];
    var albedo = m.base_color;
    if m.texture.x >= 0 {
        // Rgba8UnormSrgb layers: the sampler returns linear values.
        albedo *= textureSample(textures, tex_sampler, uv, m.texture.x);
    }
    return albedo;
}

// The metallic-roughness textures' UVs from the vertex UVs (`mr_uv`). Call it in the vertex
// stage and interpolate the result: the map is affine, so that is exact. (Mapped in the
// fragment shader from the storage buffer, lavapipe read blurred texels in the 2x2 quads along
// triangle edges, with implicit or explicit derivatives alike, and exact ones with the same map
// as a constant: the likely cause is helper invocations that do not load storage data.)
fn material_mr_uv(material: u32, uv: vec2<f32>) -> vec2<f32> {
    let m = materials[material];
    let h = vec3<f32>(uv, 1.0);
    return vec2<f32>(dot(m.mr_uv[0].xyz, h), dot(m.mr_uv[1].xyz, h));
}

// (metallic, roughness) at `uv_mr` (`material_mr_uv` of the vertex UVs, interpolated): the
// factors x the texture channels (fragment shaders only).
fn material_metal_rough(material: u32, uv_mr: vec2<f32>) -> vec2<f32> {
    let m = materials[material];
    var mr = m.params.xy;
    if m.texture.z >= 0 {
        mr.x *= textureSample(textures, tex_sampler, uv_mr, m.texture.z).b;
    }
    if m.texture.y >= 0 {
        mr.y *= textureSample(textures, tex_sampler, uv_mr, m.texture.y).g;
    }
    return mr;
}

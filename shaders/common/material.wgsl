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

// (metallic, roughness) at uv: the factors x the texture channels (fragment shaders only).
fn material_metal_rough(material: u32, uv: vec2<f32>) -> vec2<f32> {
    let m = materials[material];
    var mr = m.params.xy;
    if m.texture.z >= 0 {
        mr.x *= textureSample(textures, tex_sampler, uv, m.texture.z).b;
    }
    if m.texture.y >= 0 {
        mr.y *= textureSample(textures, tex_sampler, uv, m.texture.y).g;
    }
    return mr;
}

// Diffuse materials: albedo = baseColorFactor x sRGB-decoded base colour texture.
// Twin of `GpuMaterial` in src/renderer/gpu_data.rs.
//
// Contract: a shader including this file declares `materials: array<MaterialGpu>` (storage),
// `textures: texture_2d_array<f32>` and `tex_sampler: sampler` with its own bindings.

struct MaterialGpu {
    base_color: vec4<f32>,
    texture: vec4<i32>, // x = layer in `textures` or -1
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

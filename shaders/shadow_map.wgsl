// Directional shadow map: depth-only orthographic raster from the light, one array layer per
// light. The light's view-projection comes in as a uniform per layer (dynamic offset).

struct LightPass {
    view_proj: mat4x4<f32>,
};

@group(0) @binding(0) var<uniform> light: LightPass;

@vertex
fn vs_main(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return light.view_proj * vec4<f32>(position, 1.0);
}

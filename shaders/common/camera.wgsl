// Camera parameters. Twin of `GpuCamera` in src/renderer/gpu_data.rs.
struct Camera {
    view_proj: mat4x4<f32>,
    position: vec4<f32>,   // xyz eye, w near
    forward: vec4<f32>,    // xyz unit forward, w far
    right: vec4<f32>,      // xyz right * tan(yfov/2) * aspect
    up: vec4<f32>,         // xyz up * tan(yfov/2)
    resolution: vec4<f32>, // w, h, 1/w, 1/h
};

// Unnormalised direction through the centre of pixel (i, j):
// x = 2(i+0.5)/W - 1, y = 1 - 2(j+0.5)/H, dir = fwd + x right + y up.
fn camera_ray_dir(cam: Camera, pixel: vec2<u32>) -> vec3<f32> {
    let p = (vec2<f32>(pixel) + 0.5) * cam.resolution.zw;
    let x = 2.0 * p.x - 1.0;
    let y = 1.0 - 2.0 * p.y;
    return cam.forward.xyz + x * cam.right.xyz + y * cam.up.xyz;
}

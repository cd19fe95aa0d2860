//! The G-buffer raster: the depth pre-pass writes exactly what the single pass writes, and the
//! fragment counter of `bench gbuffer` counts what it should on a scene whose overdraw is
//! known (stacked quads drawn back to front and front to back).

mod common;

use glam::{Vec2, Vec3};
use lightcut::{
    renderer::{
        context::GpuContext,
        frame::GbufferTargets,
        gpu_data::GpuCamera,
        passes::gbuffer::{GbufferPass, OverdrawCounter},
        readback::read_texture_f32,
        scene_gpu::SceneGpu,
        settings::RenderSettings,
        timing::GpuTimer,
    },
    scene::{Camera, Material, Scene, default_scene},
};
use wgpu::util::DeviceExt;

fn camera_buffer(ctx: &GpuContext, cam: &Camera, size: (u32, u32)) -> wgpu::Buffer {
    ctx.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("test::camera"),
        contents: bytemuck::bytes_of(&GpuCamera::new(cam, size.0, size.1)),
        usage: lightcut::renderer::passes::PARAMS_USAGE,
    })
}

fn gpu_scene(ctx: &GpuContext, scene: &Scene) -> SceneGpu {
    let t = RenderSettings::default().textures;
    SceneGpu::new(&ctx.device, &ctx.queue, scene, t.max_size, t.anisotropy)
}

/// The G-buffer's position / normal / albedo with the pre-pass on or off.
fn gbuffer(
    ctx: &GpuContext,
    scene: &SceneGpu,
    camera: &wgpu::Buffer,
    size: (u32, u32),
    prepass: bool,
) -> Vec<Vec<[f32; 4]>> {
    let mut pass = GbufferPass::new(&ctx.device).unwrap();
    pass.prepass = prepass;
    let targets = GbufferTargets::new(&ctx.device, size);
    let mut timer = GpuTimer::new(&ctx.device, &ctx.queue);
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    pass.record(&ctx.device, &mut enc, &mut timer, camera, scene, &targets);
    ctx.queue.submit([enc.finish()]);
    [&targets.position, &targets.normal, &targets.albedo]
        .iter()
        .map(|t| read_texture_f32(ctx, t, 0).unwrap().pixels)
        .collect()
}

#[test]
fn the_depth_prepass_writes_the_same_gbuffer() {
    let Some(ctx) = common::gpu() else { return };
    let scene = default_scene::build();
    let cam = scene.camera_or_default(None).unwrap();
    let size = (96, 64);
    let g = gpu_scene(&ctx, &scene);
    let camera = camera_buffer(&ctx, &cam, size);
    let single = gbuffer(&ctx, &g, &camera, size, false);
    let prepass = gbuffer(&ctx, &g, &camera, size, true);
    let covered = single[0].iter().filter(|p| p[3] > 0.0).count();
    assert!(covered > size.0 as usize * size.1 as usize / 2, "{covered}");
    for (name, (a, b)) in ["position", "normal", "albedo"]
        .iter()
        .zip(single.iter().zip(&prepass))
    {
        let differ = a
            .iter()
            .zip(b)
            .filter(|(x, y)| x.map(f32::to_bits) != y.map(f32::to_bits))
            .count();
        assert_eq!(
            differ, 0,
            "{name}: {differ} pixels differ with the depth pre-pass"
        );
    }
    assert!(ctx.errors.take().is_empty());
}

/// `n` 2x2 m quads facing the camera at distances 2, 3, ... (in draw order far to near when
/// `back_to_front`), each covering the whole view.
fn stacked_quads(n: usize, back_to_front: bool) -> Scene {
    let mut s = Scene {
        name: "stacked quads".into(),
        ..Default::default()
    };
    s.materials.push(Material {
        name: "grey".into(),
        base_color_factor: [0.5, 0.5, 0.5, 1.0],
        base_color_texture: None,
        ..Default::default()
    });
    let mut order: Vec<usize> = (0..n).collect();
    if back_to_front {
        order.reverse();
    }
    for i in order {
        let z = -2.0 - i as f32;
        let base = s.positions.len() as u32;
        for (x, y) in [(-4.0, -4.0), (4.0, -4.0), (4.0, 4.0), (-4.0, 4.0)] {
            s.positions.push(Vec3::new(x, y, z));
            s.normals.push(Vec3::Z);
            s.uvs.push(Vec2::ZERO);
        }
        for t in [[0, 1, 2], [0, 2, 3]] {
            s.indices.extend(t.map(|k| base + k));
            s.triangle_materials.push(0);
        }
    }
    s.recompute_bounds();
    s
}

#[test]
fn fragment_counts_of_stacked_quads() {
    let Some(ctx) = common::gpu() else { return };
    let size = (40, 30);
    let cam = Camera::look_at("front", Vec3::ZERO, -Vec3::Z, 0.8, 0.1, 100.0);
    let camera = camera_buffer(&ctx, &cam, size);
    let counter = OverdrawCounter::new(&ctx.device).unwrap();
    let pixels = (size.0 * size.1) as u64;
    // Back to front: every quad passes the depth test in turn (4 writes per pixel) unless
    // the pre-pass settles depth first (1); front to back: 1 either way. 4 fragments are
    // rasterised per pixel in every order.
    for (back_to_front, single) in [(true, 4), (false, 1)] {
        let scene = stacked_quads(4, back_to_front);
        let c = counter
            .count(&ctx, &camera, &gpu_scene(&ctx, &scene), size)
            .unwrap();
        assert_eq!(c.pixels, pixels);
        assert_eq!(c.covered, pixels, "{c:?}");
        assert_eq!(c.rasterised, 4 * pixels, "{c:?}");
        assert_eq!(c.written_single_pass, single * pixels, "{c:?}");
        assert_eq!(c.written_after_prepass, pixels, "{c:?}");
        assert!(c.bytes_per_pixel_prepass() <= c.bytes_per_pixel_single_pass());
    }
    assert!(ctx.errors.take().is_empty());
}

/// KHR_texture_transform on the metallic-roughness texture (`Material::metal_rough_uv`, the
/// map from the vertex UVs, applied per vertex): the quad's UVs are all 0, so the roughness it
/// reads is the texel column at the map's offset: columns [A x 8, B x 8] give A at u = 0.25
/// and B at u = 0.75, at every pixel (2x2 quads along the triangles' shared edge included).
#[test]
fn metallic_roughness_texture_reads_through_its_uv_transform() {
    let Some(ctx) = common::gpu() else { return };
    let mut scene = stacked_quads(1, true);
    let (ga, gb) = (40u8, 200u8);
    let mut rgba = Vec::new();
    for _ in 0..16 {
        for x in 0..16 {
            let g = if x < 8 { ga } else { gb };
            rgba.extend_from_slice(&[255, g, 255, 255]);
        }
    }
    let mut tex = lightcut::scene::TextureImage {
        name: "columns".into(),
        width: 16,
        height: 16,
        rgba8: rgba,
    };
    tex.encode_linear_as_srgb();
    scene.textures.push(tex);
    let size = (16, 16);
    let cam = Camera {
        position: Vec3::new(0.0, 0.0, 0.0),
        forward: Vec3::NEG_Z,
        up: Vec3::Y,
        ..scene.camera_or_default(None).unwrap()
    };
    let camera = camera_buffer(&ctx, &cam, size);
    for (u, g) in [(0.25f32, ga), (0.75, gb)] {
        let m = &mut scene.materials[0];
        (m.metallic, m.roughness) = (1.0, 1.0);
        m.roughness_texture = Some(0);
        m.metal_rough_uv = [[1.0, 0.0, u], [0.0, 1.0, 0.5]];
        let gs = gpu_scene(&ctx, &scene);
        let out = gbuffer(&ctx, &gs, &camera, size, false);
        let want = g as f32 / 255.0;
        let mut covered = 0;
        for (i, (p, (n, a))) in out[0].iter().zip(out[1].iter().zip(&out[2])).enumerate() {
            if p[3] > 0.0 {
                covered += 1;
                assert!(
                    (n[3] - want).abs() < 4e-3,
                    "u = {u}, pixel {i}: roughness {} vs {want}",
                    n[3]
                );
                assert!((a[3] - 1.0).abs() < 4e-3, "u = {u}, pixel {i}: metallic {}", a[3]);
            }
        }
        assert_eq!(covered, size.0 * size.1);
    }
    assert!(ctx.errors.take().is_empty());
}

/// Metallic and roughness in the G-buffer are glTF's factors times the metallic-roughness
/// texture's B and G (stored sRGB-encoded, sampled back to linear), beside an untextured
/// material that keeps its factors.
#[test]
fn metallic_roughness_textures_reach_the_gbuffer() {
    let Some(ctx) = common::gpu() else { return };
    let mut scene = stacked_quads(1, true);
    let (g_byte, b_byte) = (140u8, 60u8);
    let mut tex = lightcut::scene::TextureImage {
        name: "mr".into(),
        width: 4,
        height: 4,
        rgba8: [255, g_byte, b_byte, 255].repeat(16),
    };
    tex.encode_linear_as_srgb();
    scene.textures.push(tex);
    let size = (32, 32);
    let cam = Camera {
        position: Vec3::new(0.0, 0.0, 0.0),
        forward: Vec3::NEG_Z,
        up: Vec3::Y,
        ..scene.camera_or_default(None).unwrap()
    };
    let camera = camera_buffer(&ctx, &cam, size);
    for textured in [true, false] {
        let m = &mut scene.materials[0];
        (m.metallic, m.roughness) = (0.5, 0.8);
        (m.roughness_texture, m.metallic_texture) = if textured {
            (Some(0), Some(0))
        } else {
            (None, None)
        };
        let g = gpu_scene(&ctx, &scene);
        let out = gbuffer(&ctx, &g, &camera, size, false);
        let (want_r, want_m) = if textured {
            (0.8 * g_byte as f32 / 255.0, 0.5 * b_byte as f32 / 255.0)
        } else {
            (0.8, 0.5)
        };
        let mut covered = 0;
        for (p, (n, a)) in out[0].iter().zip(out[1].iter().zip(&out[2])) {
            if p[3] <= 0.0 {
                continue;
            }
            covered += 1;
            assert!((n[3] - want_r).abs() < 4e-3, "roughness {} vs {want_r}", n[3]);
            assert!((a[3] - want_m).abs() < 4e-3, "metallic {} vs {want_m}", a[3]);
            assert!((a[0] - 0.5).abs() < 1e-3, "albedo unchanged");
        }
        assert_eq!(covered, size.0 * size.1, "the quad fills the view");
    }
    assert!(ctx.errors.take().is_empty());
}

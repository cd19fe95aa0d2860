//! Direct light in absolute units: a lit quad renders rho/pi * E * cos(theta) within 0.5% per
//! pixel, and the region a blocker shadows is exactly 0.

mod common;

use glam::{Vec2, Vec3};
use lightcut::{
    renderer::{
        Buffer, FrameInput, Renderer,
        settings::{RenderSettings, ViewBuffer},
    },
    scene::{
        Camera, DirectionalLight, Material, Scene,
        bvh::{Bvh, Ray},
    },
};

fn quad(scene: &mut Scene, corners: [Vec3; 4], material: u32) {
    let base = scene.positions.len() as u32;
    let n = (corners[1] - corners[0])
        .cross(corners[2] - corners[0])
        .normalize();
    for c in corners {
        scene.positions.push(c);
        scene.normals.push(n);
        scene.uvs.push(Vec2::ZERO);
    }
    for t in [[0, 1, 2], [0, 2, 3]] {
        scene.indices.extend(t.map(|k| base + k));
        scene.triangle_materials.push(material);
    }
}

/// A 4x4 m ground quad (albedo `rho`) and a 1x1 m blocker 1 m above it.
fn test_scene(rho: [f32; 3], sun: &DirectionalLight) -> Scene {
    let mut s = Scene {
        name: "direct-test".into(),
        ..Default::default()
    };
    s.materials.push(Material {
        name: "ground".into(),
        base_color_factor: [rho[0], rho[1], rho[2], 1.0],
        base_color_texture: None,
        ..Default::default()
    });
    s.materials.push(Material {
        name: "blocker".into(),
        base_color_factor: [0.2, 0.2, 0.2, 1.0],
        base_color_texture: None,
        ..Default::default()
    });
    // CCW seen from +Y.
    quad(
        &mut s,
        [
            Vec3::new(-2.0, 0.0, -2.0),
            Vec3::new(-2.0, 0.0, 2.0),
            Vec3::new(2.0, 0.0, 2.0),
            Vec3::new(2.0, 0.0, -2.0),
        ],
        0,
    );
    quad(
        &mut s,
        [
            Vec3::new(-0.5, 1.0, -0.5),
            Vec3::new(-0.5, 1.0, 0.5),
            Vec3::new(0.5, 1.0, 0.5),
            Vec3::new(0.5, 1.0, -0.5),
        ],
        1,
    );
    s.lights.push(sun.clone());
    s.recompute_bounds();
    s
}

#[test]
fn lit_quad_matches_rho_over_pi_e_cos_and_shadow_is_zero() {
    let Some(ctx) = common::gpu() else { return };
    let rho = [0.5, 0.7, 0.25];
    let e = 7.5f32;
    let sun = DirectionalLight::from_angles("sun", 30.0, 55.0, Vec3::new(e, e * 0.9, e * 0.8));
    let scene = test_scene(rho, &sun);
    let cos_t = (-sun.direction).dot(Vec3::Y);
    // Straight down, seeing the whole ground quad.
    let mut cam = Camera::look_at(
        "top",
        Vec3::new(0.0, 6.0, 0.0),
        Vec3::ZERO,
        50f32.to_radians(),
        0.1,
        20.0,
    );
    cam.up = Vec3::NEG_Z;
    let (w, h) = (160, 160);
    let mut settings = RenderSettings::default();
    settings.shadow.resolution = 1024;
    let texel = 4.0 * 1.5 / 1024.0; // generous bound of one shadow texel on the ground (m)
    let mut r = Renderer::new(ctx, &scene, (w, h), settings).expect("renderer");
    r.render(&FrameInput {
        camera: &cam,
        lights: &scene.lights,
        view: ViewBuffer::Final,
    });
    let direct = r.read(Buffer::Direct).unwrap();
    let pos = r.read(Buffer::Position).unwrap();
    assert!(r.ctx.errors.take().is_empty());

    let bvh = Bvh::build(&scene.positions, &scene.indices);
    let to_light = -sun.direction;
    let visible = |p: Vec3| {
        !bvh.any_hit(&Ray {
            origin: p + 1e-4 * Vec3::Y,
            dir: to_light,
            tmin: 1e-4,
            tmax: 100.0,
        })
    };
    let (mut lit, mut shadowed) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let p = pos.get(x, y);
            if p[3] == 0.0 || p[1].abs() > 1e-3 {
                continue; // background or the blocker
            }
            let p = Vec3::new(p[0], p[1], p[2]);
            // Skip the penumbra band: 4 shadow texels around the shadow edge.
            let m = 4.0 * texel;
            let v = visible(p);
            let clear = [Vec3::X, Vec3::NEG_X, Vec3::Z, Vec3::NEG_Z]
                .iter()
                .all(|d| visible(p + *d * m) == v);
            if !clear {
                continue;
            }
            let got = direct.get(x, y);
            for c in 0..3 {
                let want = if v {
                    rho[c] / std::f32::consts::PI * sun.irradiance[c] * cos_t
                } else {
                    0.0
                };
                if v {
                    let rel = (got[c] - want).abs() / want;
                    assert!(
                        rel < 0.005,
                        "pixel ({x},{y}) channel {c}: {} vs {want} ({:.3}%)",
                        got[c],
                        rel * 100.0
                    );
                } else {
                    assert_eq!(got[c], 0.0, "pixel ({x},{y}) channel {c} should be in shadow");
                }
            }
            if v { lit += 1 } else { shadowed += 1 }
        }
    }
    assert!(lit > 5000, "only {lit} lit pixels tested");
    assert!(shadowed > 200, "only {shadowed} shadowed pixels tested");
}

#[test]
fn irradiance_scales_linearly_and_back_faces_of_the_sun_are_dark() {
    let Some(ctx) = common::gpu() else { return };
    let sun = DirectionalLight::from_angles("sun", 0.0, 40.0, Vec3::splat(2.0));
    let scene = test_scene([0.6; 3], &sun);
    let mut cam = Camera::look_at(
        "top",
        Vec3::new(0.0, 6.0, 0.0),
        Vec3::ZERO,
        50f32.to_radians(),
        0.1,
        20.0,
    );
    cam.up = Vec3::NEG_Z;
    let mut r = Renderer::new(ctx, &scene, (64, 64), RenderSettings::default()).unwrap();
    let mean = |r: &mut Renderer, lights: &[DirectionalLight]| {
        r.render(&FrameInput {
            camera: &cam,
            lights,
            view: ViewBuffer::Final,
        });
        r.read(Buffer::Direct).unwrap().mean_rgb()[0]
    };
    let a = mean(&mut r, std::slice::from_ref(&sun));
    let mut sun2 = sun.clone();
    sun2.irradiance *= 3.0;
    let b = mean(&mut r, &[sun2]);
    assert!(a > 0.0);
    assert!((b / a - 3.0).abs() < 1e-4, "ratio {}", b / a);
    // Sun below the horizon: nothing is lit.
    let below = DirectionalLight::from_angles("sun", 0.0, -30.0, Vec3::splat(2.0));
    assert_eq!(mean(&mut r, &[below]), 0.0);
}

#[test]
fn a_method_without_ggx_keeps_the_whole_frame_lambert() {
    // The default room made glossy. With gi.brdf = Ggx the direct light changes under a method
    // that shades with GGX ("off" here), and stays Lambert's under one that refuses GGX
    // (Lightcut Interpolation): the frame's BRDF is the method's (`MethodId::brdf`).
    let Some(ctx) = common::gpu() else { return };
    let mut scene = lightcut::scene::default_scene::build();
    for m in &mut scene.materials {
        (m.metallic, m.roughness) = (0.5, 0.3);
    }
    let cam = scene.camera_or_default(None).unwrap();
    let mut s = RenderSettings::default();
    s.vpl.count = 64;
    let mut r = Renderer::new(ctx, &scene, (32, 24), s.clone()).expect("renderer");
    let mut direct = |method, brdf| {
        let mut s = s.clone();
        s.gi.method = method;
        s.gi.brdf = brdf;
        r.set_settings(s).expect("settings");
        r.render(&FrameInput {
            camera: &cam,
            lights: &scene.lights,
            view: ViewBuffer::Final,
        });
        r.read(Buffer::Direct).expect("direct").pixels
    };
    use lightcut::renderer::settings::Brdf;
    let (off, lc) = (
        lightcut::methods::direct_only::ID,
        lightcut::methods::lightcut_interpolation::ID,
    );
    let lambert = direct(off, Brdf::Lambert);
    assert_ne!(direct(off, Brdf::Ggx), lambert, "GGX changed nothing");
    assert_eq!(
        direct(lc, Brdf::Ggx),
        lambert,
        "a Lambert-only method's frame shaded with GGX"
    );
    assert_eq!(direct(lc, Brdf::Lambert), lambert);
}

//! BVH against brute force on real scenes (CPU), and the GPU traversal against the CPU BVH on
//! the same rays (identical answers).

mod common;

use lightcut::{
    cli::bench::{probe_rays, shadow_rays},
    renderer::{
        bvh_trace::{BvhTracer, TraceMode, to_gpu_ray},
        scene_gpu::{upload_bvh, upload_wide_bvh},
    },
    scene::{
        Scene,
        bvh::{Bvh, Ray, WideBvh, brute_force_any, brute_force_closest, random_shadow_rays},
        default_scene,
        gltf_load::load_gltf,
    },
};

fn sponza() -> Option<Scene> {
    let dir = common::shared_scenes()?;
    Some(load_gltf(&dir.join("sponza/Sponza.gltf")).expect("Sponza loads"))
}

/// Rays of three kinds: surface-to-surface shadow rays, surface probes, and random segments.
fn test_rays(scene: &Scene, n: usize, seed: u64) -> Vec<Ray> {
    let mut rays = shadow_rays(scene, n, seed);
    rays.extend(probe_rays(scene, n, seed + 1));
    rays.extend(random_shadow_rays(&scene.bounds, n, seed + 2));
    rays
}

fn check_cpu_against_brute_force(scene: &Scene, n: usize) {
    let bvh = Bvh::build(&scene.positions, &scene.indices);
    let wide = WideBvh::from_binary(&bvh);
    let rays = test_rays(scene, n, 7);
    let mut hits = 0;
    for (i, r) in rays.iter().enumerate() {
        let bf = brute_force_closest(&scene.positions, &scene.indices, r);
        let got = bvh.closest_hit(r);
        assert_eq!(wide.closest_hit(r), got, "ray {i}: the wide BVH's closest hit");
        assert_eq!(wide.any_hit(r), bf.is_some(), "ray {i}: the wide BVH's any hit");
        match (bf, got) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                hits += 1;
                assert_eq!(a.triangle, b.triangle, "ray {i}: closest triangle");
                assert_eq!(a.t, b.t, "ray {i}: closest t");
            }
            _ => panic!("ray {i}: brute force {bf:?} vs BVH {got:?}"),
        }
        assert_eq!(
            brute_force_any(&scene.positions, &scene.indices, r),
            bvh.any_hit(r),
            "ray {i}: any hit"
        );
    }
    assert!(
        hits > rays.len() / 10,
        "too few hits ({hits}) to be a meaningful test"
    );
}

#[test]
fn cpu_bvh_matches_brute_force_on_default_scene() {
    check_cpu_against_brute_force(&default_scene::build(), 1500);
}

#[test]
fn cpu_bvh_matches_brute_force_on_sponza() {
    let Some(s) = sponza() else { return };
    // Brute force over 86k triangles is slow: a few hundred rays of each kind.
    check_cpu_against_brute_force(&s, 150);
}

/// Both GPU layouts (the binary BVH, `common/bvh_binary.wgsl`, and the compressed 8-wide one,
/// `common/bvh_wide.wgsl`) against the CPU's binary traversal.
fn check_gpu_against_cpu(scene: &Scene, n: usize) {
    let Some(ctx) = common::gpu() else { return };
    let bvh = Bvh::build(&scene.positions, &scene.indices);
    let rays = test_rays(scene, n, 11);
    let wide = WideBvh::from_binary(&bvh);
    let (nodes, tris) = upload_wide_bvh(&ctx.device, &wide);
    let tracer = BvhTracer::new_wide(&ctx.device).expect("shader");
    check_layout(&ctx, &bvh, &rays, &tracer, &nodes, &tris);
    let (nodes, tris) = upload_bvh(&ctx.device, &bvh);
    let tracer = BvhTracer::new(&ctx.device).expect("shader");
    check_layout(&ctx, &bvh, &rays, &tracer, &nodes, &tris);
}

fn check_layout(
    ctx: &lightcut::renderer::context::GpuContext,
    bvh: &Bvh,
    rays: &[Ray],
    tracer: &BvhTracer,
    nodes: &wgpu::Buffer,
    tris: &wgpu::Buffer,
) {
    let gpu_rays: Vec<_> = rays.iter().map(to_gpu_ray).collect();
    let (any, _) = tracer
        .trace(ctx, nodes, tris, &gpu_rays, TraceMode::AnyHit, 1)
        .unwrap();
    let (closest, _) = tracer
        .trace(ctx, nodes, tris, &gpu_rays, TraceMode::ClosestHit, 1)
        .unwrap();
    assert!(ctx.errors.take().is_empty());
    let mut occluded = 0;
    for (i, r) in rays.iter().enumerate() {
        let cpu_any = bvh.any_hit(r);
        occluded += cpu_any as usize;
        assert_eq!(any[i].triangle == 1, cpu_any, "ray {i} {r:?}: any hit");
        let c = bvh.closest_hit(r);
        match c {
            Some(h) => {
                assert_eq!(closest[i].triangle, h.triangle, "ray {i}: closest triangle");
                let tol = 1e-5 * h.t.abs().max(1.0);
                assert!(
                    (closest[i].t - h.t).abs() <= tol,
                    "ray {i}: t {} vs {}",
                    closest[i].t,
                    h.t
                );
            }
            None => assert_eq!(closest[i].triangle, u32::MAX, "ray {i}: GPU hit, CPU missed"),
        }
    }
    assert!(
        occluded > 0 && occluded < rays.len(),
        "degenerate ray set ({occluded} occluded)"
    );
}

#[test]
fn gpu_traversal_matches_cpu_on_default_scene() {
    check_gpu_against_cpu(&default_scene::build(), 4096);
}

#[test]
fn gpu_traversal_matches_cpu_on_sponza() {
    let Some(s) = sponza() else { return };
    check_gpu_against_cpu(&s, 4096);
}

/// Issue 23's light paths: the surface a ray hit (`common/surface.wgsl`: position, normals,
/// uv, material, albedo at an explicit mip level) equals the CPU twin
/// (`reference::surface::surface_at`) on the CPU BVH's hit of the same ray.
fn check_surfaces(scene: &Scene, n: usize) {
    use lightcut::reference::surface::surface_at;
    use lightcut::renderer::{
        bvh_trace::SurfaceProbe,
        scene_gpu::{SceneGpu, texture_mips},
    };
    let Some(ctx) = common::gpu() else { return };
    let gpu_scene = SceneGpu::new(&ctx.device, &ctx.queue, scene, 256, 1);
    let size = gpu_scene.textures.width();
    let mips: Vec<Vec<Vec<u8>>> = scene.textures.iter().map(|t| texture_mips(t, size)).collect();
    let probe = SurfaceProbe::new(&ctx.device).expect("shader");
    let bvh = Bvh::build(&scene.positions, &scene.indices);
    let rays = probe_rays(scene, n, 23);
    let gpu_rays: Vec<_> = rays.iter().map(to_gpu_ray).collect();
    let close =
        |a: glam::Vec3, b: [f32; 3], tol: f32| (a - glam::Vec3::from_array(b)).abs().max_element() <= tol;
    for lod in [0u32, 2] {
        let gpu = probe.run(&ctx, &gpu_scene, &gpu_rays, lod).expect("probe");
        let (mut hits, mut textured, mut albedo_equal) = (0, 0, 0);
        for (i, (r, g)) in rays.iter().zip(&gpu).enumerate() {
            let Some(h) = bvh.closest_hit(r) else {
                assert_eq!(g.material, u32::MAX, "ray {i}: the GPU hit something");
                continue;
            };
            hits += 1;
            let c = surface_at(scene, &mips, size, &h, r.dir, lod);
            let scale = scene.bounds.radius().max(1.0);
            assert_eq!(g.valid, 1, "ray {i}");
            assert_eq!(g.material, c.material, "ray {i}: material");
            assert!(
                close(c.position, g.position, 1e-5 * scale),
                "ray {i}: {c:?} vs {g:?}"
            );
            assert!(
                close(c.geometric_normal, g.geometric_normal, 1e-4),
                "ray {i}: {c:?} vs {g:?}"
            );
            assert!(close(c.normal, g.normal, 1e-4), "ray {i}: {c:?} vs {g:?}");
            assert!(c.geometric_normal.dot(r.dir) <= 0.0 && c.normal.dot(c.geometric_normal) >= 0.0);
            assert!(
                (c.uv - glam::Vec2::from_array(g.uv)).abs().max_element() <= 1e-4,
                "ray {i}"
            );
            let m = &scene.materials[c.material as usize];
            textured += m.base_color_texture.is_some() as u32;
            // The nearest texel: a uv on a texel edge may round to the neighbour (float
            // interpolation order); count, do not require every one.
            albedo_equal += close(c.albedo, g.albedo, 2e-3) as u32;
        }
        eprintln!("lod {lod}: {hits} hits, {textured} textured, {albedo_equal} equal albedos");
        assert!(hits > rays.len() / 2, "{hits} hits");
        assert!(
            albedo_equal as usize * 100 >= hits * 99,
            "lod {lod}: {albedo_equal} of {hits} albedos equal"
        );
        if !scene.textures.is_empty() {
            assert!(textured > 0, "no ray hit a textured material");
        }
    }
    assert!(ctx.errors.take().is_empty());
}

#[test]
fn gpu_hit_surfaces_equal_the_cpu_twin_on_default_scene() {
    check_surfaces(&default_scene::build(), 2000);
}

#[test]
fn gpu_hit_surfaces_equal_the_cpu_twin_on_sponza() {
    let Some(s) = sponza() else { return };
    check_surfaces(&s, 2000);
}

fn breakfast_room() -> Option<Scene> {
    let dir = common::shared_scenes()?;
    Some(load_gltf(&dir.join("breakfast_room/BreakfastRoom.gltf")).expect("the Breakfast Room loads"))
}

/// Issue 40: the wide BVH answers every ray as the binary BVH does (hit/miss; closest
/// triangle and t bit for bit, the same triangle arithmetic), on the reference scenes and the
/// test scenes, for surface-to-surface shadow rays, probes and random segments.
fn check_wide_against_binary(scene: &Scene, n: usize) {
    let bvh = Bvh::build(&scene.positions, &scene.indices);
    let wide = WideBvh::from_binary(&bvh);
    let rays = test_rays(scene, n, 40);
    let (mut hits, mut occluded) = (0, 0);
    for (i, r) in rays.iter().enumerate() {
        let b = bvh.closest_hit(r);
        assert_eq!(wide.closest_hit(r), b, "ray {i} {r:?}: closest hit");
        let any = bvh.any_hit(r);
        assert_eq!(wide.any_hit(r), any, "ray {i} {r:?}: any hit");
        hits += b.is_some() as usize;
        occluded += any as usize;
    }
    assert!(hits > rays.len() / 10 && occluded > 0 && occluded < rays.len());
}

#[test]
fn wide_bvh_matches_binary_on_the_test_scenes() {
    use lightcut::scene::test_scenes;
    check_wide_against_binary(&default_scene::build(), 4000);
    for s in [
        test_scenes::window_box(),
        test_scenes::corridor(),
        test_scenes::glossy_thin(),
    ] {
        check_wide_against_binary(&s, 4000);
    }
}

#[test]
fn wide_bvh_matches_binary_on_the_reference_scenes() {
    for s in [sponza(), breakfast_room()].into_iter().flatten() {
        check_wide_against_binary(&s, 20000);
    }
}

#[test]
fn gpu_traversal_matches_cpu_on_breakfast_room() {
    let Some(s) = breakfast_room() else { return };
    check_gpu_against_cpu(&s, 4096);
}

/// The frames trace either layout (`LIGHTCUT_BVH`): SLC's and Lightcuts' images are the same
/// bytes with the wide BVH as with the binary one (every shadow ray answered alike), and a bad
/// value is refused in one line. Runs the binary, since the layout is process-wide.
#[test]
fn frames_are_identical_with_either_bvh_layout() {
    if common::gpu().is_none() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("lightcut-bvh-layout-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let render = |method: &str, layout: &str| {
        let out = dir.join(format!("{method}-{layout}"));
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_lightcut-workbench"))
            .args([
                "render", "--method", method, "--width", "48", "--height", "32", "--out",
            ])
            .arg(&out)
            .env("LIGHTCUT_BVH", layout)
            .output()
            .expect("run the binary");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        out
    };
    for method in ["slc", "lightcuts"] {
        let (a, b) = (render(method, "binary"), render(method, "wide"));
        for f in ["indirect.exr", "final.exr"] {
            let (x, y) = (
                std::fs::read(a.join(f)).unwrap(),
                std::fs::read(b.join(f)).unwrap(),
            );
            assert!(x == y, "{method}: {f} differs between the BVH layouts");
        }
    }
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_lightcut-workbench"))
        .args(["render", "--width", "8", "--height", "8"])
        .env("LIGHTCUT_BVH", "octree")
        .output()
        .expect("run the binary");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        err.contains("LIGHTCUT_BVH=octree") && err.lines().count() == 1,
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

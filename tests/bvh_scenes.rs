//! BVH against brute force on real scenes (CPU), and the GPU traversal against the CPU BVH on
//! the same rays (identical answers).

mod common;

use lightcut::{
    cli::bench::{probe_rays, shadow_rays},
    renderer::{
        bvh_trace::{BvhTracer, TraceMode, to_gpu_ray},
        scene_gpu::upload_bvh,
    },
    scene::{
        Scene,
        bvh::{Bvh, Ray, brute_force_any, brute_force_closest, random_shadow_rays},
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
    let rays = test_rays(scene, n, 7);
    let mut hits = 0;
    for (i, r) in rays.iter().enumerate() {
        let bf = brute_force_closest(&scene.positions, &scene.indices, r);
        let got = bvh.closest_hit(r);
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

fn check_gpu_against_cpu(scene: &Scene, n: usize) {
    let Some(ctx) = common::gpu() else { return };
    let bvh = Bvh::build(&scene.positions, &scene.indices);
    let (nodes, tris) = upload_bvh(&ctx.device, &bvh);
    let tracer = BvhTracer::new(&ctx.device).expect("shader");
    let rays = test_rays(scene, n, 11);
    let gpu_rays: Vec<_> = rays.iter().map(to_gpu_ray).collect();
    let (any, _) = tracer
        .trace(&ctx, &nodes, &tris, &gpu_rays, TraceMode::AnyHit, 1)
        .unwrap();
    let (closest, _) = tracer
        .trace(&ctx, &nodes, &tris, &gpu_rays, TraceMode::ClosestHit, 1)
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

//! Multi-bounce VPLs (`vpl.bounces`, issue 23): the light-path kernels against their CPU twin,
//! the energy balance per bounce (a closed box gives the geometric series), the path starts'
//! flux, and the frame's bounce layout.

mod common;

use glam::{Vec2, Vec3};
use lightcut::{
    base::gpu_layout::{vpl_bounce, vpl_path_id},
    reference::{
        self,
        light_paths::{PathRules, RsmTexel, path_start, trace_path},
    },
    renderer::{
        Buffer, FrameInput, Renderer,
        gpu_data::{GpuVpl, VPL_NONE},
        passes::{
            light_paths::{LightPathPass, PathJob, split_bounces},
            vpl_gen::pyramid_layout,
        },
        scene_gpu::{SceneGpu, texture_mips},
        settings::{RenderSettings, ViewBuffer},
    },
    scene::{Bvh, Material, Scene, default_scene},
};

fn frame(r: &mut Renderer, scene: &Scene) {
    let cam = scene.camera_or_default(None).expect("camera");
    r.render(&FrameInput {
        camera: &cam,
        lights: &scene.lights,
        view: ViewBuffer::Final,
    });
}

fn lum(c: &[f32]) -> f64 {
    0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64
}

/// A closed box [0, 1]^3 of one albedo, faces (flat normals) towards the inside.
fn closed_box(albedo: [f32; 3]) -> Scene {
    let mut s = Scene {
        name: "closed box".into(),
        ..Default::default()
    };
    s.materials = vec![Material {
        name: "box".into(),
        base_color_factor: [albedo[0], albedo[1], albedo[2], 1.0],
        base_color_texture: None,
        ..Default::default()
    }];
    for axis in 0..3 {
        for side in [0.0f32, 1.0] {
            let n = {
                let mut n = Vec3::ZERO;
                n[axis] = if side == 0.0 { 1.0 } else { -1.0 };
                n
            };
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = s.positions.len() as u32;
            for (a, b) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                let mut p = Vec3::ZERO;
                p[axis] = side;
                p[u] = a;
                p[v] = b;
                s.positions.push(p);
                s.normals.push(n);
                s.uvs.push(Vec2::new(a, b));
            }
            for t in [[0, 1, 2], [0, 2, 3]] {
                s.indices.extend(t.iter().map(|k| base + k));
                s.triangle_materials.push(0);
            }
        }
    }
    s.recompute_bounds();
    s
}

/// `n` starts on the box's floor (y = 0, normal up), total flux `phi`.
fn floor_starts(n: u32, phi: Vec3, seed: u32) -> Vec<GpuVpl> {
    let mut rng = reference::light_paths::Rng::new(seed, 7, 11);
    (0..n)
        .map(|i| GpuVpl {
            position: [0.05 + 0.9 * rng.next_f32(), 0.0, 0.05 + 0.9 * rng.next_f32(), 1.0],
            normal: [0.0, 1.0, 0.0],
            id: i,
            flux: (phi / n as f32).extend(1.0).to_array(),
        })
        .collect()
}

/// Sum of the flux (rgb) of each bounce 2..=bounces in a `(bounces - 1) x paths` layout.
fn bounce_sums(vpls: &[GpuVpl], paths: usize, bounces: u32) -> Vec<Vec3> {
    (0..(bounces - 1) as usize)
        .map(|k| {
            vpls[k * paths..(k + 1) * paths]
                .iter()
                .filter(|v| v.id != VPL_NONE)
                .map(|v| Vec3::from_slice(&v.flux[..3]))
                .sum()
        })
        .collect()
}

fn job(bounces: u32, roulette: bool, seed: u32) -> PathJob {
    PathJob {
        paths: 0,
        first: 0,
        bounces,
        roulette,
        seed,
        ray_offset: 1e-4,
        lod: 0,
        flux_scale: 1.0,
        flux_mix: 1.0,
    }
}

#[test]
fn a_closed_box_returns_the_geometric_series_per_bounce() {
    let Some(ctx) = common::gpu() else { return };
    let rho = [0.8f32, 0.5, 0.2];
    let scene = closed_box(rho);
    let gpu_scene = SceneGpu::new(&ctx.device, &ctx.queue, &scene, 16, 1);
    let mut pass = LightPathPass::new(&ctx.device).expect("shader");
    let (paths, bounces) = (2048u32, 5u32);
    let phi = Vec3::new(1.0, 2.0, 3.0);
    let rho = Vec3::from_array(rho);
    // Without roulette every ray stays in the box: bounce b carries phi x rho^(b-1) exactly
    // (up to f32 sums) in every frame.
    let starts = floor_starts(paths, phi, 1);
    let out = pass
        .trace_starts(&ctx, &gpu_scene, &starts, &job(bounces, false, 3))
        .expect("trace");
    for (k, s) in bounce_sums(&out, paths as usize, bounces).iter().enumerate() {
        let want = phi * rho.powf(k as f32 + 1.0);
        assert!(
            (*s - want).abs().max_element() <= 1e-4 * want.max_element(),
            "no roulette, bounce {}: {s} vs {want}",
            k + 2
        );
    }
    assert!(out.iter().all(|v| v.id != VPL_NONE), "a ray left the closed box");
    // With roulette (q = max(rho) = 0.8) each bounce's sum is a scaled binomial: over frames
    // its mean converges to phi x rho^(b-1) with the binomial's standard error.
    let frames = 24;
    let mut sums = vec![Vec3::ZERO; (bounces - 1) as usize];
    let mut alive = vec![0u64; (bounces - 1) as usize];
    for f in 0..frames {
        let out = pass
            .trace_starts(
                &ctx,
                &gpu_scene,
                &floor_starts(paths, phi, 100 + f),
                &job(bounces, true, 200 + f),
            )
            .expect("trace");
        for (k, s) in bounce_sums(&out, paths as usize, bounces).iter().enumerate() {
            sums[k] += *s;
            alive[k] += out[k * paths as usize..(k + 1) * paths as usize]
                .iter()
                .filter(|v| v.id != VPL_NONE)
                .count() as u64;
        }
    }
    let q = 0.8f64;
    for k in 0..(bounces - 1) as usize {
        let want = phi * rho.powf(k as f32 + 1.0);
        let mean = sums[k] / frames as f32;
        // Survivors ~ Binomial(N, q^(k+1)), N = frames x paths; each carries
        // phi / paths x (rho / q)^(k+1).
        let p = q.powi(k as i32 + 1);
        let n = (frames * paths) as f64;
        let rel_se = ((1.0 - p) / (n * p)).sqrt();
        let rel = (mean / want - Vec3::ONE).abs().max_element() as f64;
        eprintln!(
            "roulette bounce {}: mean {mean} vs {want}, survivors {:.4} vs {p:.4}, rel {rel:.4} (se {rel_se:.4})",
            k + 2,
            alive[k] as f64 / n
        );
        assert!(rel < 4.0 * rel_se + 1e-4, "bounce {}: {mean} vs {want}", k + 2);
    }
    assert!(ctx.errors.take().is_empty());
}

#[test]
fn gpu_light_paths_equal_the_cpu_twin_on_the_default_scene() {
    let Some(ctx) = common::gpu() else { return };
    let scene = default_scene::build();
    let gpu_scene = SceneGpu::new(&ctx.device, &ctx.queue, &scene, 256, 1);
    let size = gpu_scene.textures.width();
    let mips: Vec<Vec<Vec<u8>>> = scene.textures.iter().map(|t| texture_mips(t, size)).collect();
    let bvh = Bvh::build(&scene.positions, &scene.indices);
    let mut pass = LightPathPass::new(&ctx.device).expect("shader");
    // Starts spread over the room's surfaces: the first hits of rays from the room's centre.
    let centre = scene.bounds.center();
    let mut rng = reference::light_paths::Rng::new(5, 6, 7);
    let mut starts = Vec::new();
    while starts.len() < 512 {
        let d = reference::light_paths::cosine_direction(
            Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, rng.next_f32() - 0.5).normalize_or(Vec3::Y),
            rng.next_f32(),
            rng.next_f32(),
        );
        let ray = lightcut::scene::bvh::Ray::new(centre, d, 0.0, 1e30);
        if let Some(h) = bvh.closest_hit(&ray) {
            let s = reference::surface::surface_at(&scene, &mips, size, &h, d, 0);
            starts.push(GpuVpl {
                position: s.position.extend(0.5).to_array(),
                normal: s.normal.to_array(),
                id: starts.len() as u32,
                flux: [0.1, 0.2, 0.3, 1.0],
            });
        }
    }
    for roulette in [false, true] {
        let j = PathJob {
            ray_offset: 1e-3,
            ..job(4, roulette, 9)
        };
        let gpu = pass.trace_starts(&ctx, &gpu_scene, &starts, &j).expect("trace");
        let rules = PathRules {
            bounces: 4,
            roulette,
            seed: 9,
            ray_offset: 1e-3,
            lod: 0,
            flux_scale: 1.0,
        };
        let n = starts.len();
        let (mut same, mut valid) = (0, 0);
        for (p, s) in starts.iter().enumerate() {
            let cpu = trace_path(&scene, &bvh, &mips, size, s, p as u32, &rules);
            // A path whose ray grazes an edge may take another triangle on one side and
            // diverge from there: compare whole paths. Albedos agree to 2e-3 (lavapipe's
            // sRGB decode, tests/bvh_scenes.rs), so the flux to 2% after three bounces.
            let equal = cpu.iter().enumerate().all(|(k, c)| {
                let g = &gpu[k * n + p];
                g.id == c.id
                    && (c.id == VPL_NONE
                        || (Vec3::from_slice(&g.position[..3]) - Vec3::from_slice(&c.position[..3]))
                            .abs()
                            .max_element()
                            < 1e-3
                            && (Vec3::from_slice(&g.flux[..3]) - Vec3::from_slice(&c.flux[..3]))
                                .abs()
                                .max_element()
                                <= 2e-2 * Vec3::from_slice(&c.flux[..3]).max_element()
                            && (Vec3::from_array(g.normal) - Vec3::from_array(c.normal))
                                .abs()
                                .max_element()
                                < 1e-3)
            });
            same += equal as usize;
            valid += cpu.iter().filter(|c| c.id != VPL_NONE).count();
            for (k, c) in cpu.iter().enumerate() {
                if c.id != VPL_NONE {
                    assert_eq!(c.id, vpl_path_id(k as u32 + 2, p as u32));
                    assert_eq!(vpl_bounce(c.id), k as u32 + 2);
                }
            }
        }
        eprintln!("roulette {roulette}: {same}/{n} paths equal, {valid} CPU VPLs");
        assert!(valid > n, "too few VPLs ({valid}) to compare");
        assert!(same * 100 >= n * 99, "only {same}/{n} paths equal the CPU twin's");
    }
    assert!(ctx.errors.take().is_empty());
}

#[test]
fn the_frame_lays_out_bounces_and_starts_carry_the_reflected_power() {
    let mut settings = RenderSettings::default();
    settings.shadow.resolution = 128;
    settings.vpl.count = 3000;
    settings.vpl.bounces = 3;
    let Some(ctx) = common::gpu() else { return };
    let scene = default_scene::build();
    let mut r = Renderer::new(ctx, &scene, (64, 48), settings.clone()).expect("renderer");
    frame(&mut r, &scene);
    let (first, paths) = split_bounces(3000, 3);
    let vf = r.vpl_frame().clone();
    assert_eq!(
        (vf.count, vf.first_bounce, vf.paths, vf.bounces),
        (3000, first, paths, 3)
    );
    let vpls = r.read_vpls().expect("vpls");
    assert_eq!(vpls.len(), 3000);
    for (i, v) in vpls.iter().enumerate() {
        let b = vpl_bounce(v.id);
        if (i as u32) < first {
            assert_eq!(b, 1, "slot {i}");
        } else if v.id != VPL_NONE {
            let k = (i as u32 - first) / paths;
            assert_eq!(v.id, vpl_path_id(k + 2, (i as u32 - first) % paths), "slot {i}");
        }
    }
    let per_bounce: Vec<usize> = (0..2)
        .map(|k| {
            vpls[(first + k * paths) as usize..(first + (k + 1) * paths) as usize]
                .iter()
                .filter(|v| v.id != VPL_NONE)
                .count()
        })
        .collect();
    eprintln!(
        "bounce 2: {} VPLs, bounce 3: {} of {paths} slots",
        per_bounce[0], per_bounce[1]
    );
    // Drawn by flux, most paths start on the sunlit roof and leave the scene.
    assert!(per_bounce[0] > 0 && per_bounce[1] > 0);
    // The starts: each on the texel the CPU warp of the flux pyramid picks, with the texel's
    // position and flux / (n x pmf); their luminance sums to the RSM's reflected power.
    let res = 128u32;
    let n = (res * res) as usize;
    let flux_pyr = r.read_f32_buffer(&r.vpl_buffers().flux_pyramid).expect("pyramid");
    let pyr = reference::vpl::pyramid(&flux_pyr[..n], res);
    let (_, offsets) = pyramid_layout(res);
    assert!((pyr.last().expect("top")[0] - flux_pyr[*offsets.last().expect("top") as usize]).abs() < 1e-3);
    let pos = r.read(Buffer::RsmPosition(0)).expect("rsm");
    let nrm = r.read(Buffer::RsmNormal(0)).expect("rsm");
    let flux = r.read(Buffer::RsmFlux(0)).expect("rsm");
    let texels: Vec<RsmTexel> = (0..n)
        .map(|k| RsmTexel {
            position: (pos.pixels[k][3] > 0.0).then(|| Vec3::from_slice(&pos.pixels[k][..3])),
            normal: Vec3::from_slice(&nrm.pixels[k][..3]),
            flux: Vec3::from_slice(&flux.pixels[k][..3]),
        })
        .collect();
    let starts_f32 = r.read_f32_buffer(r.light_paths().starts()).expect("starts");
    let starts: Vec<GpuVpl> = bytemuck::pod_collect_to_vec(&starts_f32[..paths as usize * 12]);
    let (mut same, mut sum) = (0, 0.0f64);
    for (p, s) in starts.iter().enumerate() {
        let c = path_start(0, p as u32, paths, settings.vpl.seed, res, &texels, &pyr);
        same += (c.id == s.id) as usize;
        if c.id == s.id && c.id != VPL_NONE {
            for k in 0..3 {
                assert!(
                    (c.flux[k] - s.flux[k]).abs() <= 1e-3 * c.flux[k].abs().max(1e-6),
                    "start {p}: {c:?} vs {s:?}"
                );
                assert!((c.position[k] - s.position[k]).abs() <= 1e-5, "start {p}");
            }
        }
        sum += lum(&s.flux);
    }
    let total: f64 = (0..n)
        .filter(|&k| texels[k].position.is_some())
        .map(|k| lum(&flux.pixels[k]))
        .sum();
    eprintln!("starts: {same}/{paths} on the CPU's texel; luminance {sum:.5} vs RSM {total:.5}");
    assert!(same as f64 >= 0.995 * paths as f64);
    // Drawn by flux, each start carries total / n luminance: the sum is the total in every frame.
    assert!((sum - total).abs() <= 1e-3 * total, "{sum} vs {total}");
    // Mixed with the BRSM importance, more paths start where the camera looks (inside the
    // room), and the starts stay an unbiased estimate of the reflected power: their mean
    // over frames converges to the RSM's total.
    let mut mixed = settings.clone();
    mixed.vpl.path_flux_mix = 0.1;
    let frames = 24;
    let (mut sums, mut inside) = (Vec::new(), 0usize);
    for f in 0..frames {
        mixed.vpl.seed = 500 + f;
        r.set_settings(mixed.clone()).expect("settings");
        frame(&mut r, &scene);
        let vpls = r.read_vpls().expect("vpls");
        inside += vpls[first as usize..(first + paths) as usize]
            .iter()
            .filter(|v| v.id != VPL_NONE)
            .count();
        let starts_f32 = r.read_f32_buffer(r.light_paths().starts()).expect("starts");
        let starts: Vec<GpuVpl> = bytemuck::pod_collect_to_vec(&starts_f32[..paths as usize * 12]);
        sums.push(starts.iter().map(|s| lum(&s.flux)).sum::<f64>());
    }
    let mean = sums.iter().sum::<f64>() / frames as f64;
    let var = sums.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (frames as f64 - 1.0);
    let se = (var / frames as f64).sqrt();
    let inside = inside as f64 / frames as f64;
    eprintln!(
        "path_flux_mix 0.1: {inside:.0} bounce-2 VPLs per frame (flux only: {}); start luminance {mean:.5} +- {se:.5} vs {total:.5}",
        per_bounce[0]
    );
    assert!(inside > 3.0 * per_bounce[0] as f64);
    assert!(
        (mean - total).abs() < 4.0 * se + 1e-3 * total,
        "{mean} vs {total} (se {se})"
    );
    assert!(r.ctx.errors.take().is_empty());
}

/// Image mean luminance of the indirect light.
fn indirect_mean(r: &Renderer) -> f64 {
    let ind = r.read(Buffer::Indirect).expect("indirect");
    ind.pixels.iter().map(|p| lum(&p[..3])).sum::<f64>() / ind.pixels.len() as f64
}

fn mean_se(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, (var / n).sqrt())
}

#[test]
fn the_n_bounce_reference_converges_to_the_mean_ground_truth_of_fresh_vpls() {
    // The converged reference with vpl.bounces = 3 (every RSM texel for bounce 1, fresh light
    // paths every frame for bounces 2-3) and the ground truth of one frame's VPLs averaged
    // over fresh VPL seeds estimate the same 3-bounce light.
    let mut settings = RenderSettings::default();
    settings.shadow.resolution = 64;
    settings.vpl.count = 1024;
    settings.vpl.bounces = 3;
    settings.vpl.path_flux_mix = 0.2;
    let (w, h) = (40u32, 30u32);
    let Some(ctx) = common::gpu() else { return };
    let scene = default_scene::build();
    let mut r = Renderer::new(ctx, &scene, (w, h), settings.clone()).expect("renderer");
    let run = |r: &mut Renderer, s: &RenderSettings| -> f64 {
        r.set_settings(s.clone()).expect("settings");
        for _ in 0..64 {
            frame(r, &scene);
            if r.gi_progress().is_some_and(|p| p.finished()) {
                break;
            }
        }
        assert!(r.gi_progress().is_some_and(|p| p.finished()));
        indirect_mean(r)
    };
    let mut gt = settings.clone();
    gt.gi.method = lightcut::methods::ground_truth::ID;
    let gts: Vec<f64> = (0..96)
        .map(|k| {
            gt.vpl.seed = 300 + k;
            run(&mut r, &gt)
        })
        .collect();
    let mut rf = settings.clone();
    rf.gi.method = lightcut::methods::reference::ID;
    rf.gi.reference_samples = 256;
    rf.gi.reference_spp_per_frame = 32;
    rf.gi.reference_paths_per_sample = 8;
    let refs: Vec<f64> = (0..8)
        .map(|k| {
            rf.vpl.seed = 700 + k;
            run(&mut r, &rf)
        })
        .collect();
    rf.vpl.bounces = 1;
    let one: Vec<f64> = (0..4)
        .map(|k| {
            rf.vpl.seed = 700 + k;
            run(&mut r, &rf)
        })
        .collect();
    let ((g, gse), (m, mse), (o, ose)) = (mean_se(&gts), mean_se(&refs), mean_se(&one));
    let tol = 4.0 * (gse * gse + mse * mse).sqrt();
    eprintln!(
        "3 bounces: reference {m:.6} +- {mse:.6}, mean ground truth {g:.6} +- {gse:.6}; one bounce {o:.6} +- {ose:.6}"
    );
    assert!(
        (m - g).abs() < tol + 1e-3 * g,
        "reference {m} vs ground truth {g} (tolerance {tol})"
    );
    // Bounces 2-3 add light, well beyond the tolerance.
    assert!(m - o > 3.0 * tol, "bounces 2-3 add {} (tolerance {tol})", m - o);
    assert!(r.ctx.errors.take().is_empty());
}

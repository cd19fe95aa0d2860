//! VPL generation and the ground truth on the GPU against the CPU references and statistics.

mod common;

use glam::Vec3;
use lightcut::{
    reference,
    renderer::{
        Buffer, FrameInput, Renderer,
        gpu_data::{GpuVpl, VPL_NONE},
        passes::vpl_gen::pyramid_layout,
        settings::{RenderSettings, ViewBuffer, VplMode},
    },
    scene::{Bvh, Scene, default_scene},
};

fn lum(c: [f32; 3]) -> f64 {
    (0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]) as f64
}

fn setup(settings: RenderSettings, size: (u32, u32)) -> Option<(Renderer, Scene)> {
    let ctx = common::gpu()?;
    let scene = default_scene::build();
    let r = Renderer::new(ctx, &scene, size, settings).expect("renderer");
    Some((r, scene))
}

fn frame(r: &mut Renderer, scene: &Scene) {
    let cam = scene.camera_or_default(None).unwrap();
    r.render(&FrameInput {
        camera: &cam,
        lights: &scene.lights,
        view: ViewBuffer::Final,
    });
}

/// The mean over frames of the VPLs' total flux equals the RSM's total reflected flux.
fn check_unbiased(mode: VplMode) {
    let mut settings = RenderSettings::default();
    settings.vpl.mode = mode;
    settings.vpl.count = 1024;
    settings.shadow.resolution = 256;
    let Some((mut r, scene)) = setup(settings.clone(), (96, 64)) else {
        return;
    };
    frame(&mut r, &scene);
    let rsm = r.read(Buffer::RsmFlux(0)).unwrap();
    let pos = r.read(Buffer::RsmPosition(0)).unwrap();
    let total: f64 = rsm
        .pixels
        .iter()
        .zip(&pos.pixels)
        .filter(|(_, p)| p[3] > 0.0)
        .map(|(f, _)| lum([f[0], f[1], f[2]]))
        .sum();
    assert!(total > 0.0);
    let frames = 40;
    let mut sums = Vec::new();
    for seed in 0..frames {
        settings.vpl.seed = 1000 + seed;
        r.set_settings(settings.clone()).unwrap();
        frame(&mut r, &scene);
        let vpls = r.read_vpls().unwrap();
        assert_eq!(vpls.len(), 1024);
        sums.push(
            vpls.iter()
                .map(|v| lum([v.flux[0], v.flux[1], v.flux[2]]))
                .sum::<f64>(),
        );
    }
    let mean = sums.iter().sum::<f64>() / frames as f64;
    let var = sums.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (frames as f64 - 1.0);
    let se = (var / frames as f64).sqrt();
    eprintln!(
        "{mode:?}: RSM total {total:.6}, VPL mean {mean:.6} +- {se:.6} (per-frame sd {:.6})",
        var.sqrt()
    );
    // 4 standard errors, plus f32 rounding of the per-VPL division.
    assert!(
        (mean - total).abs() < 4.0 * se + 1e-4 * total,
        "mean {mean} vs total {total} (se {se})"
    );
    assert!(r.ctx.errors.take().is_empty());
}

#[test]
fn vpl_flux_is_unbiased_with_brsm_selection() {
    check_unbiased(VplMode::Brsm);
}

#[test]
fn vpl_flux_is_unbiased_with_uniform_rsm_selection() {
    check_unbiased(VplMode::Rsm);
}

#[test]
fn gpu_filter_pyramid_and_warping_match_the_cpu_reference() {
    let mut settings = RenderSettings::default();
    settings.shadow.resolution = 128;
    settings.vpl.count = 20_000;
    let Some((mut r, scene)) = setup(settings.clone(), (160, 100)) else {
        return;
    };
    frame(&mut r, &scene);
    let res = 128u32;
    let n = (res * res) as usize;
    let bufs = r.vpl_buffers();
    let raw = r.read_f32_buffer(&bufs.importance_raw).unwrap();
    let imp = r.read_f32_buffer(&bufs.importance_pyramid).unwrap();
    let flux = r.read_f32_buffer(&bufs.flux_pyramid).unwrap();
    let pos = r.read(Buffer::RsmPosition(0)).unwrap();
    let nrm = r.read(Buffer::RsmNormal(0)).unwrap();
    let nrm: Vec<Vec3> = nrm
        .pixels
        .iter()
        .map(|p| Vec3::new(p[0], p[1], p[2]).normalize_or_zero())
        .collect();
    // Filter: GPU level 0 = CPU filter of the GPU's raw importance.
    let radius = scene.bounds.radius();
    let cpu = reference::vpl::filter(
        &raw[..n],
        &pos.pixels,
        &nrm,
        res,
        settings.vpl.filter_radius,
        settings.vpl.n_min,
        settings.vpl.d_max * radius,
    );
    // A neighbour whose similarity sits exactly at n_min / d_max may be decided differently
    // after float rounding: allow a handful of texels, not more.
    let mut nonzero = 0;
    let mut differ = 0;
    for k in 0..n {
        let tol = 1e-4 * cpu[k].abs().max(1e-12);
        differ += ((imp[k] - cpu[k]).abs() > tol) as usize;
        nonzero += (cpu[k] > 0.0) as usize;
    }
    assert!(
        differ * 1000 <= nonzero,
        "{differ} of {nonzero} filtered texels differ from the CPU filter"
    );
    assert!(
        nonzero > 50,
        "importance is zero almost everywhere ({nonzero} texels)"
    );
    // Pyramids: the GPU's levels equal the CPU's sums of the GPU's level 0.
    let (_, offsets) = pyramid_layout(res);
    for (pyr_gpu, name) in [(&imp, "importance"), (&flux, "flux")] {
        let cpu = reference::vpl::pyramid(&pyr_gpu[..n], res);
        for (l, level) in cpu.iter().enumerate() {
            let o = offsets[l] as usize;
            for (k, v) in level.iter().enumerate() {
                let g = pyr_gpu[o + k];
                assert!(
                    (g - v).abs() <= 1e-5 * v.abs().max(1e-12),
                    "{name} level {l} node {k}: {g} vs {v}"
                );
            }
        }
    }
    // Warping: each VPL's pmf is its texel's share of the mixed PDF, and the CPU warp of the
    // same Hammersley point picks the same texel (division rounding may differ at a few
    // cell boundaries).
    let m = settings.vpl.flux_mix;
    let top = *offsets.last().unwrap() as usize;
    let (it, ft) = (imp[top], flux[top]);
    let mixed: Vec<f32> = (0..n)
        .map(|k| (1.0 - m) / it * imp[k] + m / ft * flux[k])
        .collect();
    let pyr = reference::vpl::pyramid(&mixed, res);
    let vpls: Vec<GpuVpl> = r.read_vpls().unwrap();
    let count = vpls.len() as u32;
    let seed = settings.vpl.seed;
    let rot = [
        reference::vpl::u01(reference::vpl::pcg_hash(seed * 2)),
        reference::vpl::u01(reference::vpl::pcg_hash(seed * 2 + 1)),
    ];
    let mut same = 0;
    for (i, v) in vpls.iter().enumerate() {
        assert_ne!(v.id, VPL_NONE, "VPL {i} is empty");
        let texel = (v.id & 0xff_ffff) as usize;
        let want_pmf = mixed[texel] / pyr.last().unwrap()[0];
        assert!(
            (v.position[3] - want_pmf).abs() <= 1e-3 * want_pmf,
            "VPL {i}: pmf {} vs {want_pmf}",
            v.position[3]
        );
        let (x, y, _) = reference::vpl::warp(&pyr, res, reference::vpl::hammersley(i as u32, count, rot));
        same += ((y * res + x) as usize == texel) as usize;
    }
    assert!(
        same as f64 >= 0.995 * count as f64,
        "only {same}/{count} VPLs on the CPU warp's texel"
    );
    // Chi-square of the chosen texels against the mixed PDF (coarse 16x16 cells).
    let cells = 16u32;
    let mut counts = vec![0f64; (cells * cells) as usize];
    let mut expected = vec![0f64; (cells * cells) as usize];
    let total: f64 = mixed.iter().map(|&v| v as f64).sum();
    for (k, &w) in mixed.iter().enumerate() {
        let (x, y) = (k as u32 % res, k as u32 / res);
        expected[((y * cells / res) * cells + x * cells / res) as usize] += w as f64 / total * count as f64;
    }
    for v in &vpls {
        let k = v.id & 0xff_ffff;
        let (x, y) = (k % res, k / res);
        counts[((y * cells / res) * cells + x * cells / res) as usize] += 1.0;
    }
    let (mut chi2, mut dof) = (0.0, 0);
    for (c, e) in counts.iter().zip(&expected) {
        if *e >= 5.0 {
            chi2 += (c - e).powi(2) / e;
            dof += 1;
        }
    }
    let limit = dof as f64 + 4.4 * (2.0 * dof as f64).sqrt();
    assert!(chi2 < limit, "chi2 {chi2:.1} with {dof} cells (limit {limit:.1})");
}

#[test]
fn ground_truth_on_the_gpu_equals_a_cpu_evaluation_of_the_same_vpls() {
    // With shadow rays, and without (every VPL visible: more light where something occludes).
    let Some(shadowed) = ground_truth_against_cpu(true) else {
        return;
    };
    let Some(open) = ground_truth_against_cpu(false) else {
        return;
    };
    let brighter = shadowed
        .iter()
        .zip(&open)
        .filter(|(s, o)| o.max_element() > 1.01 * s.max_element() + 1e-6)
        .count();
    assert!(
        shadowed.iter().zip(&open).all(|(s, o)| o.cmpge(*s - 1e-5).all()),
        "no shadow ray can add light"
    );
    assert!(
        brighter > 10,
        "only {brighter} pixels gain light without shadow rays"
    );
}

/// The GPU ground truth against `reference::gi::exact_indirect` at every 7th pixel; returns
/// the GPU's checked pixels (None without a GPU).
fn ground_truth_against_cpu(shadow_rays: bool) -> Option<Vec<Vec3>> {
    let mut settings = RenderSettings::default();
    settings.gi.shadow_rays = shadow_rays;
    let c = ground_truth_vs_cpu(default_scene::build(), settings, 1e-3)?;
    assert!(
        c.checked > 100 && c.lit > 50,
        "checked {}, lit {}",
        c.checked,
        c.lit
    );
    Some(c.got)
}

/// What [`ground_truth_vs_cpu`] compared.
struct GtCheck {
    r: Renderer,
    scene: Scene,
    settings: RenderSettings,
    /// The GPU's checked pixels.
    got: Vec<Vec3>,
    checked: usize,
    lit: usize,
    /// Checked pixels with roughness below 0.5.
    glossy: usize,
}

/// The ground truth of 256 VPLs (`settings.gi.brdf`, `settings.gi.shadow_rays`) on `scene`,
/// 64 x 40, against the CPU sum at every 7th pixel (Lambert: `exact_indirect`; GGX:
/// `exact_indirect_brdf` with the G-buffer's material): each within `tol` x the CPU value.
fn ground_truth_vs_cpu(scene: Scene, mut settings: RenderSettings, tol: f32) -> Option<GtCheck> {
    let ctx = common::gpu()?;
    settings.vpl.count = 256;
    settings.shadow.resolution = 256;
    settings.gi.method = lightcut::methods::ground_truth::ID;
    let (w, h) = (64u32, 40u32);
    let mut r = Renderer::new(ctx, &scene, (w, h), settings.clone()).expect("renderer");
    for _ in 0..4 {
        frame(&mut r, &scene);
        if r.gi_progress().is_some_and(|p| p.finished()) {
            break;
        }
    }
    assert!(r.gi_progress().unwrap().finished());
    let cam = scene.camera_or_default(None).unwrap();
    let ind = r.read(Buffer::Indirect).unwrap();
    let pos = r.read(Buffer::Position).unwrap();
    let nrm = r.read(Buffer::Normal).unwrap();
    let alb = r.read(Buffer::Albedo).unwrap();
    let vpls = r.read_vpls().unwrap();
    let bvh = Bvh::build(&scene.positions, &scene.indices);
    // The VPLs as the CPU reference's emitters (empty VPLs contribute nothing).
    let emitters: Vec<reference::gi::Texel> = vpls
        .iter()
        .filter(|v| v.id != VPL_NONE)
        .map(|v| reference::gi::Texel {
            position: Vec3::from_slice(&v.position[..3]),
            normal: Vec3::from_array(v.normal),
            flux: Vec3::from_slice(&v.flux[..3]),
        })
        .collect();
    let g = &settings.gi;
    let shadow = g.shadow_rays.then_some(g.ray_offset);
    let em = reference::gi::Emitters {
        texels: &emitters,
        bvh: &bvh,
        eps: g.distance_epsilon,
        shadow_rays: shadow,
    };
    let (mut got, mut checked, mut lit, mut glossy) = (Vec::new(), 0, 0, 0);
    for k in (0..(w * h) as usize).step_by(7) {
        let p = pos.pixels[k];
        if p[3] == 0.0 {
            continue;
        }
        let x = Vec3::new(p[0], p[1], p[2]);
        let n = Vec3::from_slice(&nrm.pixels[k][..3]).normalize();
        // The G-buffer's w channels: roughness (normal.w), metallic (albedo.a), f16.
        let s = reference::brdf::Surface {
            base: Vec3::from_slice(&alb.pixels[k][..3]),
            metallic: alb.pixels[k][3],
            roughness: nrm.pixels[k][3],
        };
        let want = match g.brdf {
            reference::brdf::Brdf::Lambert => reference::gi::exact_indirect(&em, x, n, s.base),
            brdf => {
                let sh = reference::brdf::Shading {
                    v: (cam.position - x).normalize(),
                    surface: s,
                };
                reference::gi::exact_indirect_brdf(&em, x, n, brdf, &sh)
            }
        };
        let v = Vec3::from_slice(&ind.pixels[k][..3]);
        assert!(
            (v - want).abs().max_element() <= tol * want.max_element().max(1e-6),
            "pixel {k} ({s:?}): GPU {v} CPU {want}"
        );
        got.push(v);
        checked += 1;
        lit += (want.max_element() > 0.0) as usize;
        glossy += (s.roughness < 0.5) as usize;
    }
    assert!(r.ctx.errors.take().is_empty());
    Some(GtCheck {
        r,
        scene,
        settings,
        got,
        checked,
        lit,
        glossy,
    })
}

#[test]
fn converged_reference_converges_to_the_exact_sum_over_all_texels() {
    converged_reference_against_exact(
        default_scene::build(),
        lightcut::renderer::settings::Brdf::Lambert,
    );
}

#[test]
fn converged_reference_with_ggx_converges_to_the_exact_brdf_sum() {
    // The default room made glossy (rough dielectrics, a satin metal); the exact sum with the
    // BRDF twin at every pixel.
    let mut scene = default_scene::build();
    for (i, m) in scene.materials.iter_mut().enumerate() {
        (m.metallic, m.roughness) = if i % 2 == 0 { (0.0, 0.4) } else { (1.0, 0.5) };
    }
    converged_reference_against_exact(scene, lightcut::renderer::settings::Brdf::Ggx);
}

fn converged_reference_against_exact(scene: Scene, brdf: lightcut::renderer::settings::Brdf) {
    // A small RSM (64 x 64 texels) so that the exact CPU sum is affordable.
    let mut settings = RenderSettings::default();
    settings.shadow.resolution = 64;
    settings.gi.method = lightcut::methods::reference::ID;
    settings.gi.reference_samples = 256;
    settings.gi.reference_spp_per_frame = 64;
    settings.gi.brdf = brdf;
    let (w, h) = (48u32, 32u32);
    let Some(ctx) = common::gpu() else { return };
    let mut r = Renderer::new(ctx, &scene, (w, h), settings.clone()).expect("renderer");
    let cam = scene.camera_or_default(None).unwrap();
    // Independent estimates: different seeds (the importance changes too; the estimator is
    // unbiased for any importance because the PDF keeps a flux share).
    let seeds = 6;
    let mut means = Vec::new();
    let mut image = vec![Vec3::ZERO; (w * h) as usize];
    for seed in 0..seeds {
        settings.vpl.seed = 100 + seed;
        r.set_settings(settings.clone()).unwrap();
        for _ in 0..8 {
            frame(&mut r, &scene);
            if r.gi_progress().is_some_and(|p| p.finished()) {
                break;
            }
        }
        assert!(r.gi_progress().unwrap().finished());
        let ind = r.read(Buffer::Indirect).unwrap();
        let lum_sum: f64 = ind.pixels.iter().map(|p| lum([p[0], p[1], p[2]])).sum();
        means.push(lum_sum / ind.pixels.len() as f64);
        for (k, p) in ind.pixels.iter().enumerate() {
            image[k] += Vec3::new(p[0], p[1], p[2]) / seeds as f32;
        }
    }
    let mean = means.iter().sum::<f64>() / seeds as f64;
    let se =
        (means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (seeds as f64 - 1.0) / seeds as f64).sqrt();
    // Exact: every texel of the (seed-independent) RSM at every pixel.
    let pos = r.read(Buffer::Position).unwrap();
    let nrm = r.read(Buffer::Normal).unwrap();
    let alb = r.read(Buffer::Albedo).unwrap();
    let rp = r.read(Buffer::RsmPosition(0)).unwrap();
    let rn = r.read(Buffer::RsmNormal(0)).unwrap();
    let rf = r.read(Buffer::RsmFlux(0)).unwrap();
    let texels: Vec<reference::gi::Texel> = (0..rp.pixels.len())
        .filter(|&k| rp.pixels[k][3] > 0.0)
        .map(|k| reference::gi::Texel {
            position: Vec3::from_slice(&rp.pixels[k][..3]),
            normal: Vec3::from_slice(&rn.pixels[k][..3]).normalize(),
            flux: Vec3::from_slice(&rf.pixels[k][..3]),
        })
        .collect();
    let bvh = Bvh::build(&scene.positions, &scene.indices);
    let em = reference::gi::Emitters {
        texels: &texels,
        bvh: &bvh,
        eps: settings.gi.distance_epsilon,
        shadow_rays: Some(settings.gi.ray_offset),
    };
    let mut exact_sum = 0.0;
    for k in 0..(w * h) as usize {
        let p = pos.pixels[k];
        if p[3] == 0.0 {
            continue;
        }
        let x = Vec3::from_slice(&p[..3]);
        let surface = reference::brdf::Surface {
            base: Vec3::from_slice(&alb.pixels[k][..3]),
            metallic: alb.pixels[k][3],
            roughness: nrm.pixels[k][3],
        };
        let sh = reference::brdf::Shading {
            v: (cam.position - x).normalize(),
            surface,
        };
        let e = reference::gi::exact_indirect_brdf(
            &em,
            x,
            Vec3::from_slice(&nrm.pixels[k][..3]).normalize(),
            brdf,
            &sh,
        );
        exact_sum += lum(e.to_array());
    }
    let exact = exact_sum / (w * h) as f64;
    eprintln!("{brdf:?}: reference image mean {mean:.6} +- {se:.6} (6 x 256 spp), exact {exact:.6}");
    assert!(exact > 0.0);
    assert!(
        (mean - exact).abs() < 4.0 * se + 1e-3 * exact,
        "reference {mean} +- {se} vs exact {exact}"
    );
    assert!(r.ctx.errors.take().is_empty());
}

#[test]
fn two_lights_split_the_budget_by_brightness_and_each_light_stays_unbiased() {
    let mut settings = RenderSettings::default();
    settings.vpl.count = 1024;
    settings.shadow.resolution = 128;
    let Some(ctx) = common::gpu() else { return };
    let mut scene = default_scene::build();
    let mut second = scene.lights[0].clone();
    second.name = "second sun".into();
    second.direction = Vec3::new(0.4, -0.8, 0.45).normalize();
    second.irradiance = scene.lights[0].irradiance / 3.0;
    scene.lights.push(second);
    let mut r = Renderer::new(ctx, &scene, (64, 40), settings.clone()).unwrap();
    frame(&mut r, &scene);
    assert_eq!(r.vpl_frame().ranges, vec![(0, 768), (768, 256)]);
    let totals: Vec<f64> = (0..2)
        .map(|l| {
            let f = r.read(Buffer::RsmFlux(l)).unwrap();
            let p = r.read(Buffer::RsmPosition(l)).unwrap();
            f.pixels
                .iter()
                .zip(&p.pixels)
                .filter(|(_, p)| p[3] > 0.0)
                .map(|(f, _)| lum([f[0], f[1], f[2]]))
                .sum()
        })
        .collect();
    let frames = 24;
    let mut sums = [Vec::new(), Vec::new()];
    for seed in 0..frames {
        settings.vpl.seed = 500 + seed;
        r.set_settings(settings.clone()).unwrap();
        frame(&mut r, &scene);
        let vpls = r.read_vpls().unwrap();
        for (i, v) in vpls.iter().enumerate() {
            let light = if i < 768 { 0 } else { 1 };
            assert_eq!(v.id >> 24, light, "VPL {i} belongs to light {}", v.id >> 24);
        }
        for (l, range) in [(0usize, 0..768), (1, 768..1024)] {
            sums[l].push(
                vpls[range]
                    .iter()
                    .map(|v| lum([v.flux[0], v.flux[1], v.flux[2]]))
                    .sum::<f64>(),
            );
        }
    }
    for l in 0..2 {
        let n = sums[l].len() as f64;
        let mean = sums[l].iter().sum::<f64>() / n;
        let se = (sums[l].iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
        eprintln!("light {l}: RSM {:.4}, VPL mean {mean:.4} +- {se:.4}", totals[l]);
        assert!(
            (mean - totals[l]).abs() < 4.0 * se + 1e-4 * totals[l],
            "light {l}: {mean} vs {}",
            totals[l]
        );
    }
    assert!(r.ctx.errors.take().is_empty());
}

#[test]
fn raising_the_reference_target_continues_and_a_view_change_restarts() {
    let mut settings = RenderSettings::default();
    settings.shadow.resolution = 64;
    settings.gi.method = lightcut::methods::reference::ID;
    settings.gi.reference_samples = 64;
    settings.gi.reference_spp_per_frame = 32;
    let Some((mut r, scene)) = setup(settings.clone(), (32, 24)) else {
        return;
    };
    frame(&mut r, &scene);
    frame(&mut r, &scene);
    frame(&mut r, &scene);
    assert_eq!(r.gi_progress().map(|p| (p.done, p.total)), Some((64, 64)));
    settings.gi.reference_samples = 128;
    r.set_settings(settings.clone()).unwrap();
    frame(&mut r, &scene);
    assert_eq!(r.gi_progress().map(|p| (p.done, p.total)), Some((96, 128)));
    // Another camera: the sums restart.
    let cam = scene.cameras[1].clone();
    r.render(&FrameInput {
        camera: &cam,
        lights: &scene.lights,
        view: ViewBuffer::Final,
    });
    assert_eq!(r.gi_progress().map(|p| p.done), Some(32));
}

#[test]
fn ground_truth_with_ggx_equals_a_cpu_evaluation_with_the_brdf() {
    // The default room made glossy (a rough floor, a polished metal sphere, satin walls) and
    // shaded with gi.brdf = ggx: every checked pixel equals the CPU sum with the BRDF twin.
    let mut scene = default_scene::build();
    for (i, m) in scene.materials.iter_mut().enumerate() {
        (m.metallic, m.roughness) = match i % 4 {
            0 => (0.0, 0.3),
            1 => (1.0, 0.2),
            2 => (0.5, 0.6),
            _ => (0.0, 0.05),
        };
    }
    let mut settings = RenderSettings::default();
    settings.gi.brdf = lightcut::renderer::settings::Brdf::Ggx;
    let Some(mut c) = ground_truth_vs_cpu(scene, settings, 2e-3) else {
        return;
    };
    assert!(
        c.checked > 100 && c.glossy > 20,
        "checked {}, glossy {}",
        c.checked,
        c.glossy
    );
    // Lambert on the same scene differs (the BRDF is in use).
    let ind = c.r.read(Buffer::Indirect).unwrap();
    let ggx_mean: f64 = ind.pixels.iter().map(|p| lum([p[0], p[1], p[2]])).sum();
    let lambert_mean: f64 = {
        let mut s = c.settings.clone();
        s.gi.brdf = lightcut::renderer::settings::Brdf::Lambert;
        c.r.set_settings(s).unwrap();
        for _ in 0..4 {
            frame(&mut c.r, &c.scene);
        }
        let l = c.r.read(Buffer::Indirect).unwrap();
        l.pixels.iter().map(|p| lum([p[0], p[1], p[2]])).sum::<f64>()
    };
    assert!(
        (ggx_mean / lambert_mean - 1.0).abs() > 0.01,
        "{ggx_mean} vs {lambert_mean}"
    );
    assert!(c.r.ctx.errors.take().is_empty());
}

//! Stochastic Light Culling (`methods::light_culling`): the GPU's ranges and tile lists
//! against the CPU reference (`reference::light_culling`), no VPL in range missing from its
//! pixel's tile, the shading and the geometry-aware filter against the CPU, overflowing tiles
//! counted and shaded the same, and the estimator's unbiasedness over frames (the clamped
//! baseline's darkening beside it). Tiny sizes: 250 VPLs, 48 x 32 pixels.

mod common;

use common::Setup;

use glam::Vec3;
use lightcut::{
    base::gpu_layout::{GpuVpl, VPL_NONE},
    methods::light_culling::{self, LightCulling, settings::LightCullingSettings},
    metrics,
    reference::light_culling::{
        Interleave, LightRange, RangeMode, RangeParams, ShadeVpl, TileCamera, filter_pixel, light_range,
        shade, tile_lists,
    },
    renderer::{
        Buffer,
        readback::read_storage_buffer,
        settings::{RenderSettings, Tonemap},
    },
    scene::bvh::{Bvh, Ray},
};

const W: u32 = 48;
const H: u32 = 32;

fn settings(lc: LightCullingSettings) -> RenderSettings {
    let mut s = RenderSettings::default();
    s.gi.method = light_culling::ID;
    // Not a multiple of the interleaving's blocks (stride x n^2): subsets of unequal size.
    s.vpl.count = 250;
    s.shadow.resolution = 256;
    s.set_method(light_culling::ID, &lc).unwrap();
    s
}

/// Small tiles and a 2 x 2 pattern so that the tiny frame has many tiles of each subset.
fn small(epsilon_max: f32) -> LightCullingSettings {
    LightCullingSettings {
        epsilon_max,
        tile_size: 4,
        interleave: 2,
        filter_radius: 2,
        ..Default::default()
    }
}

fn lc_of(st: &Setup) -> &LightCulling {
    st.r.method_module::<LightCulling>()
        .expect("light culling is registered")
}

fn gpu_lights(st: &Setup, n: usize) -> Vec<LightRange> {
    let bytes = read_storage_buffer(&st.r.ctx, &lc_of(st).buffers().lights).unwrap();
    let f: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
    (0..n)
        .map(|i| LightRange {
            position: Vec3::from_slice(&f[2 * i][..3]),
            range: f[2 * i][3],
            falloff: lightcut::reference::light_culling::Falloff {
                threshold: f[2 * i + 1][0],
                floor: f[2 * i + 1][1],
            },
        })
        .collect()
}

fn gpu_u32(st: &Setup, b: &wgpu::Buffer) -> Vec<u32> {
    bytemuck::pod_collect_to_vec(&read_storage_buffer(&st.r.ctx, b).unwrap())
}

fn flux_max(v: &GpuVpl) -> f32 {
    if v.id == VPL_NONE {
        0.0
    } else {
        v.flux[0].max(v.flux[1]).max(v.flux[2])
    }
}

fn range_params(s: &RenderSettings, lc: &LightCullingSettings, mode: RangeMode, count: u32) -> RangeParams {
    RangeParams {
        mode,
        epsilon_max: lc.epsilon_max,
        exposure: s.display.exposure_ev.exp2(),
        count,
        seed: LightCulling::seed(s, 0),
        eps: s.gi.distance_epsilon,
    }
}

fn positions(st: &Setup) -> Vec<Option<Vec3>> {
    let pos = st.r.read(Buffer::Position).unwrap();
    pos.pixels
        .iter()
        .map(|g| (g[3] != 0.0).then(|| Vec3::new(g[0], g[1], g[2])))
        .collect()
}

fn scaled(lights: &[LightRange], k: f32) -> Vec<LightRange> {
    lights
        .iter()
        .map(|l| LightRange {
            range: l.range * k,
            ..*l
        })
        .collect()
}

/// One frame at eps_max 0.002 with a fixed seed: its settings, renderer and VPLs.
fn fixed_frame(
    ctx: &lightcut::renderer::context::GpuContext,
) -> (LightCullingSettings, RenderSettings, Setup, Vec<GpuVpl>) {
    let lc = small(0.002);
    let mut s = settings(lc.clone());
    s.sampling.fixed_seed = true;
    let mut st = Setup::new(ctx, s.clone(), (W, H));
    st.frame();
    let vpls = st.r.read_vpls().unwrap();
    (lc, s, st, vpls)
}

/// The GPU's ranges and fall-offs against the CPU's for `mode`; the finite ranges.
fn check_ranges(
    s: &RenderSettings,
    lc: &LightCullingSettings,
    mode: RangeMode,
    vpls: &[GpuVpl],
    gl: &[LightRange],
) -> Vec<f32> {
    let rp = range_params(s, lc, mode, vpls.len() as u32);
    let close = |a: f32, b: f32| (a - b).abs() <= 1e-5 * a.abs().max(b.abs()) + 1e-30;
    let mut finite = Vec::new();
    for (i, v) in vpls.iter().enumerate() {
        let c = light_range(&rp, i as u32, Vec3::from_slice(&v.position[..3]), flux_max(v));
        let g = gl[i];
        assert_eq!(g.position, c.position, "{mode:?} VPL {i}");
        assert!(
            close(g.range, c.range),
            "{mode:?} VPL {i}: range {} vs {}",
            g.range,
            c.range
        );
        assert!(
            close(g.falloff.threshold, c.falloff.threshold),
            "{mode:?} VPL {i}: {g:?} vs {c:?}"
        );
        assert!(
            close(g.falloff.floor, c.falloff.floor),
            "{mode:?} VPL {i}: {g:?} vs {c:?}"
        );
        if c.range > 0.0 {
            finite.push(c.range);
        }
    }
    finite
}

#[test]
fn gpu_ranges_and_tile_lists_equal_the_cpu_reference() {
    let Some(ctx) = common::gpu() else { return };
    let (lc, s, mut st, vpls) = fixed_frame(&ctx);
    let n = vpls.len();
    let gl = gpu_lights(&st, n);
    // Ranges: eq. 6 and eq. 3 on the CPU from the same VPLs and seed.
    let mut finite = check_ranges(&s, &lc, RangeMode::Stochastic, &vpls, &gl);
    finite.sort_by(f32::total_cmp);
    let median = finite[finite.len() / 2];
    eprintln!(
        "{} VPLs, {} with a range, median range {median} m",
        n,
        finite.len()
    );
    assert!(
        finite.len() > n / 2 && median > 0.1 && median < 20.0,
        "ranges: median {median}"
    );

    // Tile lists: the CPU's, with every range 1e-4 smaller, is contained in the GPU's, which is
    // contained in the CPU's with every range 1e-4 larger (float rounding at the boundary).
    let cam = TileCamera::new(&st.cam, W, H);
    let grid = LightCulling::grid(&lc, (W, H));
    let il = Interleave::new(lc.interleave, n as u32, LightCulling::seed(&s, 0));
    let pos = positions(&st);
    let inner = tile_lists(&cam, grid, il, &pos, &scaled(&gl, 1.0 - 1e-4));
    let outer = tile_lists(&cam, grid, il, &pos, &scaled(&gl, 1.0 + 1e-4));
    let b = lc_of(&st).buffers();
    let count = gpu_u32(&st, &b.tile_count);
    let lists = gpu_u32(&st, &b.tile_lists);
    let cap = lc.max_lights_per_tile as usize;
    let (mut entries, mut candidates) = (0usize, 0usize);
    for t in 0..grid.count() as usize {
        let c = count[t] as usize;
        assert!(c <= cap, "tile {t} overflowed at cap {cap}");
        let g = &lists[t * cap..t * cap + c];
        assert!(
            g.windows(2).all(|w| w[0] < w[1]),
            "tile {t}: increasing VPL order"
        );
        assert!(
            inner[t].iter().all(|i| g.contains(i)),
            "tile {t}: {g:?} misses some of {:?}",
            inner[t]
        );
        assert!(
            g.iter().all(|i| outer[t].contains(i)),
            "tile {t}: {g:?} not within {:?}",
            outer[t]
        );
        entries += c;
        if !outer[t].is_empty() || c > 0 {
            candidates += n / il.cells() as usize;
        }
    }
    eprintln!("tile lists: {entries} entries of {candidates} candidates");
    assert!(
        entries > 0 && entries < candidates * 9 / 10,
        "the lists cull: {entries} of {candidates}"
    );

    // Conservative: each pixel's tile holds every VPL of its subset within range of the pixel.
    for y in 0..H {
        for x in 0..W {
            let Some(p) = pos[(y * W + x) as usize] else {
                continue;
            };
            let t = grid.tile_of(x, y) as usize;
            let g = &lists[t * cap..t * cap + count[t] as usize];
            for i in il.subset(il.pixel_subset(x, y), n as u32) {
                let l = gl[i as usize];
                if (l.position - p).length() < l.range * (1.0 - 1e-4) {
                    assert!(
                        g.contains(&i),
                        "pixel ({x}, {y}): VPL {i} in range, not in tile {t}"
                    );
                }
            }
        }
    }

    // A cap of 2: tiles over it are counted (diagnostics), their true counts kept.
    let over = count.iter().filter(|&&c| c > 2).count() as f64;
    st.set(|s| {
        let mut l: LightCullingSettings = s.method(light_culling::ID).unwrap();
        l.max_lights_per_tile = 2;
        s.set_method(light_culling::ID, &l).unwrap();
    });
    st.frame();
    let stats = st.r.method_stats_blocking();
    let get = |k: &str| stats.iter().find(|(n, _)| *n == k).unwrap().1;
    eprintln!("cap 2: {stats:?}");
    assert!(over > 0.0);
    assert_eq!(get("overflow_tiles"), over);
    assert_eq!(gpu_u32(&st, &lc_of(&st).buffers().tile_count), count);

    // The clamped ranges (appendix A) against the CPU's: no Russian roulette (floor 0).
    st.set(|s| s.gi.method = light_culling::CLAMPED);
    st.frame();
    let gl = gpu_lights(&st, n);
    check_ranges(&s, &lc, RangeMode::Clamped, &vpls, &gl);
    assert!(
        gl.iter().all(|g| g.falloff.floor == 0.0),
        "clamped: no Russian roulette"
    );
    assert!(ctx.errors.take().is_empty());
}

#[test]
fn gpu_shading_and_filter_equal_the_cpu_reference_and_overflow_changes_nothing() {
    let Some(ctx) = common::gpu() else { return };
    let (lc, s, mut st, vpls) = fixed_frame(&ctx);
    let n = vpls.len();
    let gl = gpu_lights(&st, n);
    let cam = TileCamera::new(&st.cam, W, H);
    let grid = LightCulling::grid(&lc, (W, H));
    let il = Interleave::new(lc.interleave, n as u32, LightCulling::seed(&s, 0));
    let b = lc_of(&st).buffers();
    let count = gpu_u32(&st, &b.tile_count);
    let lists = gpu_u32(&st, &b.tile_lists);
    let raw: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&read_storage_buffer(&ctx, &b.raw).unwrap());
    let cap = lc.max_lights_per_tile as usize;
    let sv: Vec<ShadeVpl> = vpls
        .iter()
        .map(|v| ShadeVpl {
            position: Vec3::from_slice(&v.position[..3]),
            normal: Vec3::from_array(v.normal),
            flux: if v.id == VPL_NONE {
                Vec3::ZERO
            } else {
                Vec3::from_slice(&v.flux[..3])
            },
        })
        .collect();
    let bvh = Bvh::build(&st.scene.positions, &st.scene.indices);
    let pos = st.r.read(Buffer::Position).unwrap();
    let nrm = st.r.read(Buffer::Normal).unwrap();
    let alb = st.r.read(Buffer::Albedo).unwrap();
    let ind = st.indirect();
    let off = s.gi.ray_offset;
    let (mut lit, mut close) = (0, 0);
    let mut surf = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let k = (y * W + x) as usize;
            let g = pos.pixels[k];
            if g[3] == 0.0 {
                surf.push(None);
                continue;
            }
            let p = Vec3::new(g[0], g[1], g[2]);
            let nx = Vec3::from_slice(&nrm.pixels[k][..3]).normalize();
            surf.push(Some((p, nx)));
            let t = grid.tile_of(x, y) as usize;
            let list = &lists[t * cap..t * cap + count[t] as usize];
            let cpu = shade(p, nx, list, &sv, &gl, il, s.gi.distance_epsilon, |i| {
                let v = sv[i as usize];
                let o = p + nx * off;
                let e = v.position + v.normal * off;
                !bvh.any_hit(&Ray {
                    origin: o,
                    dir: e - o,
                    tmin: 1e-4,
                    tmax: 1.0 - 1e-4,
                })
            });
            let gpu = Vec3::from_slice(&raw[k][..3]);
            if cpu.max_element() > 1e-6 {
                lit += 1;
                // A shadow ray grazing an edge may differ between the BVH traversals.
                if (gpu - cpu).abs().max_element() <= 1e-3 * cpu.max_element() {
                    close += 1;
                }
            }
        }
    }
    eprintln!("shading: {close} of {lit} lit pixels within 1e-3 of the CPU");
    assert!(lit > 200 && close >= lit * 98 / 100, "{close} of {lit}");
    // The filter (from the GPU's raw estimates) x albedo / pi is the indirect image.
    let raw3: Vec<Vec3> = raw.iter().map(|r| Vec3::from_slice(&r[..3])).collect();
    let mut worst = 0.0f32;
    for y in 0..H {
        for x in 0..W {
            let k = (y * W + x) as usize;
            let f = filter_pixel(
                x,
                y,
                W,
                H,
                lc.filter_radius,
                lc.filter_normal_cos,
                lc.filter_plane_tolerance,
                &cam,
                &surf,
                &raw3,
            );
            let want = Vec3::from_slice(&alb.pixels[k][..3]) / std::f32::consts::PI * f;
            let got = Vec3::from_slice(&ind.pixels[k][..3]);
            worst = worst.max((got - want).abs().max_element() / want.max_element().max(1e-4));
        }
    }
    eprintln!("filter: worst relative difference {worst:e}");
    assert!(worst < 1e-3, "filter {worst}");

    // Lists capped at 3: overflowing tiles test every VPL of their subset: the same image.
    st.set(|s| {
        let mut l: LightCullingSettings = s.method(light_culling::ID).unwrap();
        l.max_lights_per_tile = 3;
        s.set_method(light_culling::ID, &l).unwrap();
    });
    st.frame();
    let capped = st.indirect();
    let stats = st.r.method_stats_blocking();
    let get = |k: &str| stats.iter().find(|(n, _)| *n == k).unwrap().1;
    assert!(get("overflow_tiles") > 0.0, "{stats:?}");
    let m = metrics::compare(&capped, &ind, 3.0, Tonemap::Aces);
    assert!(
        m.rmse <= 1e-6 * m.mean_ratio.max(1.0),
        "capped vs uncapped: {m:?}"
    );
    for (a, b) in capped.pixels.iter().zip(&ind.pixels) {
        for c in 0..3 {
            assert!(
                (a[c] - b[c]).abs() <= 1e-5 * b[c].abs().max(1e-6),
                "{a:?} vs {b:?}"
            );
        }
    }
    assert!(ctx.errors.take().is_empty());
}

#[test]
fn the_mean_over_frames_converges_to_the_unshadowed_ground_truth_and_clamping_darkens() {
    let Some(ctx) = common::gpu() else { return };
    // No visibility (the paper's figures 1 and 4): the truth is the unshadowed sum over the
    // VPLs. Interleaving on (its per-frame offset keeps the estimate unbiased), no filter.
    let lc = LightCullingSettings {
        filter_radius: 0,
        ..small(0.01)
    };
    let mut s = settings(lc);
    s.gi.shadow_rays = false;
    let mut st = Setup::new(&ctx, s, (W, H));
    st.frame();
    let gt = st.ground_truth_of_these_vpls();
    st.set(|s| s.sampling.accumulate = true);
    let mut errs = Vec::new();
    for target in [16u32, 256] {
        while st.r.sampling_frames() < target {
            st.frame();
        }
        let m = metrics::compare(&st.indirect(), &gt, 3.0, Tonemap::Aces);
        errs.push((target, m.rmse, m.mean_ratio));
    }
    let stats = st.r.method_stats_blocking();
    eprintln!("stochastic vs unshadowed ground truth (frames, RMSE, mean ratio): {errs:?}; {stats:?}");
    let ratio = errs[0].1 / errs[1].1;
    // 16x the frames: the RMSE falls 4x; allow 2.5x..6.5x.
    assert!(ratio > 2.5 && ratio < 6.5, "RMSE ratio {ratio}");
    assert!(
        (errs[1].2 - 1.0).abs() < 0.02,
        "mean ratio after 256 frames {}",
        errs[1].2
    );
    // It culls: fewer VPLs in range per pixel than its subset holds.
    let in_range = stats
        .iter()
        .find(|(n, _)| *n == "vpls_in_range_per_pixel")
        .unwrap()
        .1;
    assert!(in_range < 0.5 * 250.0 / 4.0, "in range per pixel {in_range}");

    // The clamped ranges for the same bound (appendix A), without interleaving: one frame is
    // the clamped sum. Every pixel is darker than the truth (each VPL counts fully or not at
    // all), by at most eps_max / E (appendix A's bound, albedo <= 1), and the image measurably.
    st.set(|s| {
        s.gi.method = light_culling::CLAMPED;
        s.sampling.accumulate = false;
        let mut l: LightCullingSettings = s.method(light_culling::ID).unwrap();
        l.interleave = 1;
        s.set_method(light_culling::ID, &l).unwrap();
    });
    let mut darkening = Vec::new();
    for eps_max in [0.01f32, 0.05] {
        st.set(|s| {
            let mut l: LightCullingSettings = s.method(light_culling::ID).unwrap();
            l.epsilon_max = eps_max;
            s.set_method(light_culling::ID, &l).unwrap();
        });
        st.frame();
        let clamped = st.indirect();
        let bound = eps_max / st.r.settings().display.exposure_ev.exp2();
        let (mut dark, mut truth) = (0.0f64, 0.0f64);
        for (c, g) in clamped.pixels.iter().zip(&gt.pixels) {
            for k in 0..3 {
                let d = g[k] - c[k];
                assert!(
                    d >= -1e-5 * g[k].abs().max(1e-6),
                    "clamped brighter than the truth: {c:?} vs {g:?}"
                );
                assert!(
                    d <= bound * 1.001 + 1e-6,
                    "darkening {d} above eps_max / E = {bound}"
                );
                dark += d as f64;
                truth += g[k] as f64;
            }
        }
        darkening.push(dark / truth);
    }
    eprintln!("clamped: mean darkening at eps_max 0.01, 0.05: {darkening:?}");
    assert!(
        darkening[0] > 0.001,
        "the clamped image is measurably darker: {darkening:?}"
    );
    assert!(
        darkening[1] > 2.0 * darkening[0],
        "more darkening for a looser bound: {darkening:?}"
    );
    assert!(ctx.errors.take().is_empty());
}

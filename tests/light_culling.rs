//! Stochastic Light Culling (`methods::light_culling`): the GPU's ranges and tile lists
//! against the CPU reference (`reference::light_culling`), no VPL in range missing from its
//! pixel's tile, the shading and the geometry-aware filter against the CPU, overflowing tiles
//! counted and shaded the same, and the estimator's unbiasedness over frames (the clamped
//! baseline's darkening beside it, and the clamped-vs-stochastic difference view's data); the
//! bounding-sphere-tree variant (section 5) against the CPU and its unbiasedness; ISM
//! visibility (4.3-4.4): the maps and the shading against the CPU, their agreement with
//! shadow rays. Tiny sizes: 250 VPLs, 48 x 32 pixels.

mod common;

use common::Setup;

use glam::Vec3;
use lightcut::{
    base::gpu_layout::{GpuVpl, VPL_NONE},
    methods::light_culling::{
        self, LightCulling,
        settings::{CullingVisibility, InterleaveSettings, IsmSettings, LightCullingSettings},
    },
    methods::overlay::Prim,
    metrics,
    reference::interleave::{FilterImage, filter_pixel},
    reference::ism::{self, EMPTY, IsmLayout, IsmLight},
    reference::light_culling::{
        Interleave, LightRange, RangeMode, RangeParams, Reservoir, ShadeInputs, ShadeVpl, SphereTree,
        TREE_STREAM_RESERVOIR, TREE_STREAM_RIS, TileCamera, light_range, shade, tile_lists, tree_max_ranges,
        tree_rng, tree_shade, tree_traverse,
    },
    reference::vpl::{pcg_hash, u01},
    renderer::{
        Buffer, FrameInput,
        passes::ism::cloud_of_bvh,
        readback::read_storage_buffer,
        settings::{RenderSettings, Tonemap, ViewBuffer},
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
        interleave: InterleaveSettings::pattern(2),
        ..Default::default()
    }
}

fn lc_of(st: &Setup) -> &LightCulling {
    st.r.method_module::<LightCulling>()
        .expect("light culling is registered")
}

fn gpu_lights(st: &Setup, n: usize) -> Vec<LightRange> {
    lights_of(st, &lc_of(st).buffers().lights, n)
}

fn lights_of(st: &Setup, buffer: &wgpu::Buffer, n: usize) -> Vec<LightRange> {
    let bytes = read_storage_buffer(&st.r.ctx, buffer).unwrap();
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

fn shade_vpls(vpls: &[GpuVpl]) -> Vec<ShadeVpl> {
    vpls.iter()
        .map(|v| ShadeVpl {
            position: Vec3::from_slice(&v.position[..3]),
            normal: Vec3::from_array(v.normal),
            flux: if v.id == VPL_NONE {
                Vec3::ZERO
            } else {
                Vec3::from_slice(&v.flux[..3])
            },
        })
        .collect()
}

/// Counts a lit pixel (the CPU's value above 1e-6) and whether the GPU's is within 1e-3 of it.
fn tally(lit: &mut usize, close: &mut usize, gpu: Vec3, cpu: Vec3) {
    if cpu.max_element() > 1e-6 {
        *lit += 1;
        *close += ((gpu - cpu).abs().max_element() <= 1e-3 * cpu.max_element()) as usize;
    }
}

/// The CPU shadow ray from surface point p (normal nx) to VPL i, both ends offset `off`.
fn visible<'a>(
    bvh: &'a Bvh,
    sv: &'a [ShadeVpl],
    p: Vec3,
    nx: Vec3,
    off: f32,
) -> impl FnMut(u32) -> bool + 'a {
    move |i| {
        let v = sv[i as usize];
        let o = p + nx * off;
        let e = v.position + v.normal * off;
        !bvh.any_hit(&Ray {
            origin: o,
            dir: e - o,
            tmin: 1e-4,
            tmax: 1.0 - 1e-4,
        })
    }
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
    s.frame.fixed_seed = true;
    let mut st = Setup::new(ctx, s.clone(), (W, H));
    st.frame();
    let vpls = st.r.read_vpls().unwrap();
    (lc, s, st, vpls)
}

/// Accumulates the method's frames and checks that the mean converges to `gt` at
/// 1 / sqrt(frames): 16x the frames (16 -> 256) cut the RMSE 4x (2.5x..6.5x allowed), and
/// the mean ratio after 256 frames is within `ratio_tol` of 1. Returns the method's stats.
fn converges(
    st: &mut Setup,
    gt: &lightcut::renderer::readback::ImageF32,
    what: &str,
    ratio_tol: f64,
) -> Vec<(&'static str, f64)> {
    st.set(|s| s.frame.accumulate = true);
    let mut errs = Vec::new();
    for target in [16u32, 256] {
        while st.r.sampling_frames() < target {
            st.frame();
        }
        let m = metrics::compare(&st.indirect(), gt, 3.0, Tonemap::Aces);
        errs.push((target, m.rmse, m.mean_ratio));
    }
    let stats = st.r.method_stats_blocking();
    eprintln!("{what} vs unshadowed ground truth (frames, RMSE, mean ratio): {errs:?}; {stats:?}");
    let ratio = errs[0].1 / errs[1].1;
    assert!(ratio > 2.5 && ratio < 6.5, "{what}: RMSE ratio {ratio}");
    assert!(
        (errs[1].2 - 1.0).abs() < ratio_tol,
        "{what}: mean ratio after 256 frames {}",
        errs[1].2
    );
    stats
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
    let il = Interleave::new(lc.interleave.n, n as u32, LightCulling::seed(&s, 0));
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

    // The pinned pixel's overlay: the range spheres of its tile's list, those holding its
    // point first (green), and the pixel itself.
    let (px, py) = (W / 2, H / 2);
    let pin = pos[(py * W + px) as usize].expect("geometry at the centre");
    st.r.set_trace_pixel(Some((px, py)));
    let ov = st.r.read_method_overlay().unwrap().expect("an overlay");
    let t = grid.tile_of(px, py) as usize;
    let listed = &lists[t * cap..t * cap + count[t] as usize];
    let spheres: Vec<(Vec3, f32)> = ov
        .prims
        .iter()
        .filter_map(|p| match *p {
            Prim::Sphere { center, radius, .. } => Some((center, radius)),
            _ => None,
        })
        .collect();
    assert_eq!(spheres.len(), listed.len().min(light_culling::OVERLAY_SPHERES));
    let holds = |c: Vec3, r: f32| c.distance(pin) < r;
    let inside = listed
        .iter()
        .filter(|&&i| holds(gl[i as usize].position, gl[i as usize].range))
        .count();
    for (k, &(c, r)) in spheres.iter().enumerate() {
        let l = listed
            .iter()
            .map(|&i| gl[i as usize])
            .find(|l| l.position == c)
            .expect("a sphere of a listed VPL");
        assert_eq!(r, l.range);
        assert_eq!(
            holds(c, r),
            k < inside,
            "the spheres holding the pixel come first"
        );
    }
    assert!(
        ov.rows
            .iter()
            .any(|(k, v)| k.contains("holding") && v.starts_with(&format!("{inside} of {}", listed.len()))),
        "{:?}",
        ov.rows
    );
    st.r.set_trace_pixel(None);

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
    let il = Interleave::new(lc.interleave.n, n as u32, LightCulling::seed(&s, 0));
    let b = lc_of(&st).buffers();
    let count = gpu_u32(&st, &b.tile_count);
    let lists = gpu_u32(&st, &b.tile_lists);
    let raw: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&read_storage_buffer(&ctx, &b.raw).unwrap());
    let cap = lc.max_lights_per_tile as usize;
    let sv = shade_vpls(&vpls);
    let bvh = Bvh::build(&st.scene.positions, &st.scene.indices);
    let pos = st.r.read(Buffer::Position).unwrap();
    let nrm = st.r.read(Buffer::Normal).unwrap();
    let alb = st.r.read(Buffer::Albedo).unwrap();
    let ind = st.indirect();
    let off = s.gi.ray_offset;
    let inputs = ShadeInputs {
        vpls: &sv,
        lights: &gl,
        eps: s.gi.distance_epsilon,
    };
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
            let cpu = shade(p, nx, list, &inputs, il, visible(&bvh, &sv, p, nx, off));
            let gpu = Vec3::from_slice(&raw[k][..3]);
            // A shadow ray grazing an edge may differ between the BVH traversals.
            tally(&mut lit, &mut close, gpu, cpu);
        }
    }
    eprintln!("shading: {close} of {lit} lit pixels within 1e-3 of the CPU");
    assert!(lit > 200 && close >= lit * 98 / 100, "{close} of {lit}");
    // The filter (from the GPU's raw estimates) x albedo / pi is the indirect image.
    let raw3: Vec<Vec3> = raw.iter().map(|r| Vec3::from_slice(&r[..3])).collect();
    let img = FilterImage {
        width: W,
        height: H,
        eye: cam.eye,
        forward: cam.forward,
        surf: &surf,
        raw: &raw3,
    };
    let mut worst = 0.0f32;
    for y in 0..H {
        for x in 0..W {
            let k = (y * W + x) as usize;
            let f = filter_pixel(
                &img,
                x,
                y,
                lc.interleave.filter_radius,
                lc.interleave.filter_normal_cos,
                lc.interleave.filter_plane_tolerance,
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
    let mut lc = small(0.01);
    lc.interleave.filter_radius = 0;
    let mut s = settings(lc);
    s.gi.shadow_rays = false;
    let mut st = Setup::new(&ctx, s, (W, H));
    st.frame();
    let gt = st.ground_truth_of_these_vpls();
    let stats = converges(&mut st, &gt, "stochastic", 0.02);
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
        s.frame.accumulate = false;
        let mut l: LightCullingSettings = s.method(light_culling::ID).unwrap();
        l.interleave.n = 1;
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

    // The difference view: kept for drawing, the stochastic method's frames also run the
    // clamped companion (deterministic without interleaving: its mean is the clamped image).
    // Its data: both means' luminances and their relative difference (the sign is not
    // asserted: 16 frames of the stochastic image share each frame's xi over all pixels).
    let clamped = st.indirect();
    st.r.keep_views(vec![light_culling::DIFFERENCE]);
    st.set(|s| {
        s.gi.method = light_culling::ID;
        s.frame.accumulate = true;
    });
    while st.r.sampling_frames() < 16 {
        st.frame();
    }
    let view = ViewBuffer::Method(light_culling::DIFFERENCE);
    st.r.redraw_view(&FrameInput {
        camera: &st.cam,
        lights: &st.scene.lights,
        view,
    });
    let d =
        st.r.read_view_buffer(view)
            .unwrap()
            .expect("the difference view's data");
    let own = st.indirect();
    let lum = |p: &[f32; 4]| lightcut::base::display::luminance(Vec3::from_slice(&p[..3]));
    let (mut cl, mut sto, mut rel, mut px) = (0.0f64, 0.0f64, 0.0f64, 0);
    for k in 0..d.pixels.len() {
        let v = d.pixels[k];
        let (want_c, want_s) = (lum(&clamped.pixels[k]), lum(&own.pixels[k]));
        assert!(
            (v[1] - want_c).abs() <= 1e-4 * want_c.abs().max(1e-4),
            "pixel {k}: clamped {} vs {want_c}",
            v[1]
        );
        assert!(
            (v[2] - want_s).abs() <= 1e-4 * want_s.abs().max(1e-4),
            "pixel {k}: stochastic {} vs {want_s}",
            v[2]
        );
        let mean = 0.5 * (v[1] + v[2]);
        let want_rel = if mean > 0.0 { (v[1] - v[2]) / mean } else { 0.0 };
        assert!(
            (v[0] - want_rel).abs() <= 1e-4 * want_rel.abs().max(1.0),
            "pixel {k}: {v:?}"
        );
        cl += v[1] as f64;
        sto += v[2] as f64;
        if v[3] > 0.0 {
            rel += v[0] as f64;
            px += 1;
        }
    }
    eprintln!(
        "difference view: clamped / stochastic {:.4}, mean relative difference {:.4}",
        cl / sto,
        rel / px as f64
    );
    assert!(cl > 0.0 && sto > 0.0 && px > 0);
    assert!(ctx.errors.take().is_empty());
}

/// The bounding-sphere tree over the frame's VPLs (section 5) against the CPU (leaf ranges,
/// node bounds, the traversal's lists with the same reservoir stream, the one-ray shading),
/// then its unbiasedness without visibility.
#[test]
fn the_tree_variant_equals_the_cpu_and_its_mean_converges_to_the_unshadowed_truth() {
    let Some(ctx) = common::gpu() else { return };
    // k = 4: most pixels have more VPLs in range (the reservoir and min(k / m, 1) work).
    let lc = LightCullingSettings {
        reservoir_k: 4,
        ..small(0.002)
    };
    let mut s = settings(lc.clone());
    s.gi.method = light_culling::TREE;
    s.frame.fixed_seed = true;
    let mut st = Setup::new(&ctx, s.clone(), (W, H));
    st.frame();
    let (_, tb) = st.r.tree_buffers();
    let leaves = tb.leaves;
    let sorted: Vec<GpuVpl> =
        bytemuck::pod_collect_to_vec(&read_storage_buffer(&ctx, &tb.sorted_vpls).unwrap());
    let nodes = lightcut::renderer::passes::sst_build::read_nodes(&ctx, tb).unwrap();
    let t = lc_of(&st).tree_buffers().expect("the tree variant's buffers");
    assert_eq!(t.leaves, leaves);
    let gl = lights_of(&st, &t.lights, leaves as usize);
    // Leaf ranges: eqs. 3 and 6 with xi of the leaf index.
    check_ranges(&s, &lc, RangeMode::Stochastic, &sorted[..leaves as usize], &gl);
    // Node bounds: the largest range below each node.
    let bits = gpu_u32(&st, &t.max_range);
    let ranges: Vec<f32> = gl.iter().map(|l| l.range).collect();
    let cpu_max = tree_max_ranges(leaves, &ranges);
    for n in 1..leaves as usize {
        assert_eq!(f32::from_bits(bits[n]), cpu_max[n], "node {n}");
    }
    // The traversal, pixel by pixel, with the same reservoir stream.
    let boxes: Vec<(Vec3, Vec3)> = nodes
        .iter()
        .map(|n| (Vec3::from_array(n.bbox_min), Vec3::from_array(n.bbox_max)))
        .collect();
    let list = gpu_u32(&st, &t.list);
    let mv = gpu_u32(&st, &t.m);
    let raw: Vec<[f32; 4]> =
        bytemuck::pod_collect_to_vec(&read_storage_buffer(&ctx, &lc_of(&st).buffers().raw).unwrap());
    let sv = shade_vpls(&sorted);
    let bvh = Bvh::build(&st.scene.positions, &st.scene.indices);
    let pos = st.r.read(Buffer::Position).unwrap();
    let nrm = st.r.read(Buffer::Normal).unwrap();
    let seed = LightCulling::seed(&s, 0);
    let (eps, off, k) = (s.gi.distance_epsilon, s.gi.ray_offset, lc.reservoir_k);
    let tree = SphereTree {
        leaves,
        boxes: &boxes,
        max_range: &cpu_max,
        lights: &gl,
    };
    let inputs = ShadeInputs {
        vpls: &sv,
        lights: &gl,
        eps,
    };
    let (mut px, mut same, mut over_k, mut lit, mut close) = (0, 0, 0, 0, 0);
    for y in 0..H {
        for x in 0..W {
            let p = (y * W + x) as usize;
            let g = pos.pixels[p];
            if g[3] == 0.0 {
                continue;
            }
            px += 1;
            let xp = Vec3::new(g[0], g[1], g[2]);
            let cpu = tree_traverse(&tree, xp, eps, k, tree_rng(seed, p as u32, TREE_STREAM_RESERVOIR));
            let (m, visited) = (mv[2 * p], mv[2 * p + 1]);
            let gpu_list = &list[p * k as usize..p * k as usize + m.min(k) as usize];
            if cpu.m == m && cpu.visited == visited && cpu.list == gpu_list {
                same += 1;
            }
            over_k += (m > k) as u32;
            // The shading from the GPU's list, with the same resampling number.
            let nx = Vec3::from_slice(&nrm.pixels[p][..3]).normalize();
            let u = u01(pcg_hash(tree_rng(seed, p as u32, TREE_STREAM_RIS)));
            let r = Reservoir { list: gpu_list, m, k };
            let (want, _) = tree_shade(xp, nx, r, &inputs, u, visible(&bvh, &sv, xp, nx, off));
            let got = Vec3::from_slice(&raw[p][..3]);
            tally(&mut lit, &mut close, got, want);
        }
    }
    eprintln!(
        "tree: {same} of {px} pixels' traversals equal the CPU's ({over_k} over k = {k}); {close} of {lit} lit \
         pixels' shading within 1e-3"
    );
    assert!(same >= px * 99 / 100, "{same} of {px}");
    // The pinned pixel's overlay: the range spheres of its list (all hold its point).
    let (cx, cy) = (W / 2, H / 2);
    let p = (cy * W + cx) as usize;
    st.r.set_trace_pixel(Some((cx, cy)));
    let ov = st.r.read_method_overlay().unwrap().expect("an overlay");
    let want: Vec<(Vec3, f32)> = list[p * k as usize..p * k as usize + mv[2 * p].min(k) as usize]
        .iter()
        .map(|&j| (gl[j as usize].position, gl[j as usize].range))
        .collect();
    let got: Vec<(Vec3, f32)> = ov
        .prims
        .iter()
        .filter_map(|q| match *q {
            Prim::Sphere { center, radius, .. } => Some((center, radius)),
            _ => None,
        })
        .collect();
    assert_eq!(got.len(), want.len());
    assert!(got.iter().all(|g| want.contains(g)), "{got:?} vs {want:?}");
    st.r.set_trace_pixel(None);
    assert!(over_k > px / 4, "the reservoir is exercised: {over_k} of {px}");
    assert!(lit > 100 && close >= lit * 98 / 100, "{close} of {lit}");

    // Unbiased: without visibility the mean over frames converges to the unshadowed truth.
    st.set(|s| {
        s.gi.shadow_rays = false;
        s.frame.fixed_seed = false;
    });
    st.frame();
    let gt = st.ground_truth_of_these_vpls();
    let stats = converges(&mut st, &gt, "tree", 0.03);
    let get = |name: &str| stats.iter().find(|(n, _)| *n == name).unwrap().1;
    assert!(get("shadow_rays_per_pixel") == 0.0);
    // The walk skips subtrees: well under the tree's 2 leaves - 1 nodes (0.47 on lavapipe).
    assert!(
        get("tree_nodes_visited_per_pixel") < 0.75 * (2 * leaves - 1) as f64,
        "the tree culls: {stats:?}"
    );
    assert!(ctx.errors.take().is_empty());
}

/// The GPU's atlas after the last frame against the CPU twin's from the same lights (`gl`:
/// positions and ranges, `sv`: normals), with (`range_culling`) or without the ranges; at most
/// 0.5% of the texels may differ (a point on a texel boundary may land on either side).
/// Returns the GPU's atlas.
fn atlas_matches(
    st: &Setup,
    lc: &LightCullingSettings,
    gl: &[LightRange],
    sv: &[ShadeVpl],
    range_culling: bool,
) -> Vec<f32> {
    let layout = IsmLayout {
        atlas: lc.ism.atlas,
        tile: lc.ism.tile,
    };
    let (targets, maps) = lc_of(st).ism_targets().expect("maps built");
    let n = maps as usize;
    assert_eq!(n, gl.len(), "a map per light");
    let gpu: Vec<f32> =
        bytemuck::pod_collect_to_vec(&read_storage_buffer(&st.r.ctx, &targets.depth).unwrap());
    let cloud = cloud_of_bvh(
        &st.r.scene_gpu().bvh,
        lc.ism.points,
        light_culling::ISM_CLOUD_SEED,
    );
    let (points, normals): (Vec<Vec3>, Vec<Vec3>) = cloud.into_iter().unzip();
    let lights: Vec<IsmLight> = (0..n)
        .map(|i| IsmLight {
            // Without range culling a VPL of range 0 (it lights nothing) still splats nothing.
            range: if range_culling || gl[i].range <= 0.0 {
                gl[i].range
            } else {
                EMPTY
            },
            ..IsmLight::new(gl[i].position, sv[i].normal)
        })
        .collect();
    let mut cpu = ism::splat_culled(layout, &lights, &points, Some(&normals), lc.ism.points_per_light);
    let filled = cpu.iter().filter(|&&d| d < EMPTY).count();
    ism::pull_push(layout, &mut cpu, n as u32, lc.ism.levels());
    let texels = n * (lc.ism.tile * lc.ism.tile) as usize;
    let same = (0..n as u32)
        .flat_map(|m| (0..lc.ism.tile).flat_map(move |v| (0..lc.ism.tile).map(move |u| (m, u, v))))
        .filter(|&(m, u, v)| {
            let k = layout.texel(m, u, v);
            let (a, b) = (gpu[k], cpu[k]);
            a == b || (a - b).abs() <= 1e-5 * b.abs()
        })
        .count();
    eprintln!(
        "ISM (range culling {range_culling}): {same} of {texels} texels equal the CPU's ({filled} \
         filled by the splat)"
    );
    assert!(filled > texels / 20, "the maps hold points");
    assert!(same * 1000 >= texels * 995, "{same} of {texels}");
    gpu
}

/// ISM visibility (`visibility = "ism"`, section 4.4's adaptive maps with 4.3's range culling)
/// on the fixed frame: 250 VPLs, 256 maps of 32^2 texels (a 512^2 atlas), 8192 points each
/// from a cloud of 2^18.
fn ism_small() -> LightCullingSettings {
    LightCullingSettings {
        visibility: CullingVisibility::Ism,
        ism: IsmSettings {
            points: 1 << 18,
            points_per_light: 8192,
            atlas: 512,
            tile: 32,
            ..Default::default()
        },
        ..small(0.002)
    }
}

#[test]
fn ism_visibility_equals_the_cpu_lookups_and_agrees_with_shadow_rays() {
    let Some(ctx) = common::gpu() else { return };
    let lc = ism_small();
    let mut s = settings(lc.clone());
    s.frame.fixed_seed = true;
    let mut st = Setup::new(&ctx, s.clone(), (W, H));
    st.frame();
    assert!(ctx.errors.take().is_empty());
    let vpls = st.r.read_vpls().unwrap();
    let n = vpls.len();
    let gl = gpu_lights(&st, n);
    let sv = shade_vpls(&vpls);
    let layout = IsmLayout {
        atlas: lc.ism.atlas,
        tile: lc.ism.tile,
    };

    // The maps: the CPU twin's splat of the same cloud (one map per VPL, each its points
    // within the VPL's range and facing away from it) and pull-push, against the GPU's atlas.
    assert!(lc.ism.front_face_culling, "the paper's culling is on by default");
    let gpu_atlas = atlas_matches(&st, &lc, &gl, &sv, true);
    // Shading: the CPU's sum with the CPU lookup in the GPU's atlas as visibility.
    let grid = LightCulling::grid(&lc, (W, H));
    let il = Interleave::new(lc.interleave.n, n as u32, LightCulling::seed(&s, 0));
    let b = lc_of(&st).buffers();
    let count = gpu_u32(&st, &b.tile_count);
    let lists = gpu_u32(&st, &b.tile_lists);
    let raw: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&read_storage_buffer(&ctx, &b.raw).unwrap());
    let cap = lc.max_lights_per_tile as usize;
    let bvh = Bvh::build(&st.scene.positions, &st.scene.indices);
    let pos = st.r.read(Buffer::Position).unwrap();
    let nrm = st.r.read(Buffer::Normal).unwrap();
    let inputs = ShadeInputs {
        vpls: &sv,
        lights: &gl,
        eps: s.gi.distance_epsilon,
    };
    let (mut lit, mut close, mut pairs, mut agree, mut false_shadow, mut ray_lit) = (0, 0, 0, 0, 0, 0usize);
    for y in 0..H {
        for x in 0..W {
            let k = (y * W + x) as usize;
            let g = pos.pixels[k];
            if g[3] == 0.0 {
                continue;
            }
            let p = Vec3::new(g[0], g[1], g[2]);
            let nx = Vec3::from_slice(&nrm.pixels[k][..3]).normalize();
            let t = grid.tile_of(x, y) as usize;
            let list = &lists[t * cap..t * cap + count[t] as usize];
            let ism_visible = |i: u32| {
                ism::visible(
                    layout,
                    &gpu_atlas,
                    i,
                    sv[i as usize].position,
                    sv[i as usize].normal,
                    p,
                    lc.ism.bias,
                )
            };
            let cpu = shade(p, nx, list, &inputs, il, ism_visible);
            let gpu = Vec3::from_slice(&raw[k][..3]);
            tally(&mut lit, &mut close, gpu, cpu);
            // How often the map's answer is the shadow ray's, over the VPLs in range that
            // face the pixel.
            let mut ray = visible(&bvh, &sv, p, nx, s.gi.ray_offset);
            for &i in list {
                let v = sv[i as usize];
                let d = v.position - p;
                let w = d.normalize_or_zero();
                if gl[i as usize]
                    .falloff
                    .eval(d.length_squared(), s.gi.distance_epsilon)
                    <= 0.0
                    || nx.dot(w) <= 0.0
                    || -v.normal.dot(w) <= 0.0
                {
                    continue;
                }
                pairs += 1;
                let (a, r) = (ism_visible(i), ray(i));
                ray_lit += r as usize;
                if a == r {
                    agree += 1;
                } else if r {
                    false_shadow += 1;
                }
            }
        }
    }
    let agreement = agree as f64 / pairs.max(1) as f64;
    eprintln!(
        "ISM shading: {close} of {lit} lit pixels within 1e-3 of the CPU; the maps agree with \
         shadow rays on {agree} of {pairs} VPL-pixel pairs ({:.1}%; of the others {false_shadow} \
         shadowed by the map, lit by the ray; {ray_lit} lit by the ray)",
        100.0 * agreement
    );
    assert!(lit > 200 && close >= lit * 98 / 100, "{close} of {lit}");
    // The maps add what a ray sees: they agree with the rays more often than "all lit" does
    // (lit by the ray: the agreement of no visibility).
    let base = ray_lit as f64 / pairs.max(1) as f64;
    assert!(
        pairs > 1000 && agreement > base + 0.02,
        "agreement {agreement}, all lit {base}"
    );

    // The images: with the same seed the variants shade the same VPLs whatever the visibility
    // (the tree variant: a map per leaf, its VPL resampled as with rays), so the maps' image
    // is nearer the rays' than the unshadowed one is.
    let image = |st: &mut Setup, method, vis: Option<bool>| {
        st.set(|s| {
            s.gi.method = method;
            s.gi.shadow_rays = vis.is_some();
            (light_culling::VISIBILITY.set)(s, if vis == Some(true) { "ism" } else { "rays" });
        });
        st.frame();
        st.indirect()
    };
    for method in [light_culling::ID, light_culling::TREE] {
        let with_ism = image(&mut st, method, Some(true));
        let maps = lc_of(&st).ism_targets().map(|(_, m)| m);
        if method == light_culling::TREE {
            tree_shading_with_maps_matches(&st, &lc, &s);
        }
        let with_rays = image(&mut st, method, Some(false));
        let unshadowed = image(&mut st, method, None);
        let e_ism = metrics::compare(&with_ism, &with_rays, 3.0, Tonemap::Aces);
        let e_none = metrics::compare(&unshadowed, &with_rays, 3.0, Tonemap::Aces);
        eprintln!(
            "{method}: vs shadow rays, maps RMSE {:.3e} (mean ratio {:.3}), unshadowed RMSE {:.3e} \
             (mean ratio {:.3}); {maps:?} maps",
            e_ism.rmse, e_ism.mean_ratio, e_none.rmse, e_none.mean_ratio
        );
        assert_eq!(
            maps,
            Some(if method == light_culling::TREE {
                256
            } else {
                n as u32
            })
        );
        // Closer per pixel, and at least half the light the rays remove removed.
        assert!(
            e_ism.rmse < e_none.rmse
                && (e_ism.mean_ratio - 1.0).abs() < 0.5 * (e_none.mean_ratio - 1.0).abs(),
            "{method}: {e_ism:?} vs {e_none:?}"
        );
    }
    assert!(ctx.errors.take().is_empty());

    // Without the range culling (figure 7's comparison) the maps hold every point of their
    // share that faces away from their VPL: still the CPU twin's.
    st.set(|s| {
        s.gi.method = light_culling::ID;
        s.gi.shadow_rays = true;
        let mut l: LightCullingSettings = s.method(light_culling::ID).unwrap();
        l.visibility = CullingVisibility::Ism;
        l.ism_range_culling = false;
        s.set_method(light_culling::ID, &l).unwrap();
    });
    st.frame();
    atlas_matches(&st, &lc, &gpu_lights(&st, n), &sv, false);
    assert!(ctx.errors.take().is_empty());

    // More VPLs than maps: refused with a message naming the atlas, nothing drawn.
    st.set(|s| {
        s.gi.method = light_culling::ID;
        s.gi.shadow_rays = true;
        (light_culling::VISIBILITY.set)(s, "ism");
        s.vpl.count = 300;
    });
    st.frame();
    let errors = ctx.errors.take();
    assert!(
        errors
            .iter()
            .any(|e| e.contains("methods.light-culling.ism.atlas")),
        "{errors:?}"
    );
    assert_eq!(
        lc_of(&st).ism_targets().map(|(_, m)| m),
        Some(0),
        "no maps counted"
    );
}

/// The tree variant's one-ray shading with its leaves' maps against the CPU's (the GPU's list
/// and atlas, the same resampling number, `reference::ism::visible` as visibility).
fn tree_shading_with_maps_matches(st: &Setup, lc: &LightCullingSettings, s: &RenderSettings) {
    let ctx = &st.r.ctx;
    let (_, tb) = st.r.tree_buffers();
    let leaves = tb.leaves;
    let sorted: Vec<GpuVpl> =
        bytemuck::pod_collect_to_vec(&read_storage_buffer(ctx, &tb.sorted_vpls).unwrap());
    let t = lc_of(st).tree_buffers().expect("the tree variant's buffers");
    let gl = lights_of(st, &t.lights, leaves as usize);
    let sv = shade_vpls(&sorted[..leaves as usize]);
    // The maps of the leaves, as the tiled variant's of the VPLs.
    let atlas = atlas_matches(st, lc, &gl, &sv, true);
    let layout = IsmLayout {
        atlas: lc.ism.atlas,
        tile: lc.ism.tile,
    };
    let list = gpu_u32(st, &t.list);
    let mv = gpu_u32(st, &t.m);
    let raw: Vec<[f32; 4]> =
        bytemuck::pod_collect_to_vec(&read_storage_buffer(ctx, &lc_of(st).buffers().raw).unwrap());
    let pos = st.r.read(Buffer::Position).unwrap();
    let nrm = st.r.read(Buffer::Normal).unwrap();
    let seed = LightCulling::seed(s, 0);
    let k = lc.reservoir_k as usize;
    let inputs = ShadeInputs {
        vpls: &sv,
        lights: &gl,
        eps: s.gi.distance_epsilon,
    };
    let (mut lit, mut close) = (0, 0);
    for p in 0..(W * H) as usize {
        let g = pos.pixels[p];
        if g[3] == 0.0 {
            continue;
        }
        let xp = Vec3::new(g[0], g[1], g[2]);
        let nx = Vec3::from_slice(&nrm.pixels[p][..3]).normalize();
        let m = mv[2 * p];
        let u = u01(pcg_hash(tree_rng(seed, p as u32, TREE_STREAM_RIS)));
        let r = Reservoir {
            list: &list[p * k..p * k + (m as usize).min(k)],
            m,
            k: k as u32,
        };
        let (want, _) = tree_shade(xp, nx, r, &inputs, u, |i| {
            ism::visible(
                layout,
                &atlas,
                i,
                sv[i as usize].position,
                sv[i as usize].normal,
                xp,
                lc.ism.bias,
            )
        });
        let got = Vec3::from_slice(&raw[p][..3]);
        tally(&mut lit, &mut close, got, want);
    }
    eprintln!("tree with maps: {close} of {lit} lit pixels' shading within 1e-3 of the CPU");
    assert!(lit > 100 && close >= lit * 98 / 100, "{close} of {lit}");
}

/// With `gi.brdf = "Ggx"` (filter radius 0, which GGX requires): every pixel's `raw` is the
/// CPU's `shade_shaded` (each VPL times f(v, l)) on a room of rough dielectrics and satin
/// metals, the image is `raw` itself (no albedo / pi after), and the mean over frames of the
/// stochastic and the tree variant converges to the unshadowed GGX ground truth.
#[test]
fn with_ggx_the_shading_equals_the_cpu_and_the_means_converge_to_the_ggx_truth() {
    use lightcut::reference::brdf::{Shading, Surface};
    use lightcut::reference::light_culling::shade_shaded;
    let Some(ctx) = common::gpu() else { return };
    let mut lc = small(0.002);
    lc.interleave.filter_radius = 0;
    let mut s = settings(lc.clone());
    s.gi.brdf = lightcut::renderer::settings::Brdf::Ggx;
    s.frame.fixed_seed = true;
    let scene = || {
        let mut scene = lightcut::scene::default_scene::build();
        for (i, m) in scene.materials.iter_mut().enumerate() {
            (m.metallic, m.roughness) = if i % 2 == 0 { (0.0, 0.35) } else { (1.0, 0.5) };
        }
        scene
    };
    let mut st = Setup::with_scene(&ctx, scene(), s.clone(), (W, H));
    st.frame();
    let errs = ctx.errors.take();
    assert!(errs.is_empty(), "{errs:?}");
    let vpls = st.r.read_vpls().unwrap();
    let n = vpls.len();
    let gl = gpu_lights(&st, n);
    let grid = LightCulling::grid(&lc, (W, H));
    let il = Interleave::new(lc.interleave.n, n as u32, LightCulling::seed(&s, 0));
    let b = lc_of(&st).buffers();
    let count = gpu_u32(&st, &b.tile_count);
    let lists = gpu_u32(&st, &b.tile_lists);
    let raw: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&read_storage_buffer(&ctx, &b.raw).unwrap());
    let cap = lc.max_lights_per_tile as usize;
    let sv = shade_vpls(&vpls);
    let bvh = Bvh::build(&st.scene.positions, &st.scene.indices);
    let pos = st.r.read(Buffer::Position).unwrap();
    let nrm = st.r.read(Buffer::Normal).unwrap();
    let alb = st.r.read(Buffer::Albedo).unwrap();
    let ind = st.indirect();
    let inputs = ShadeInputs {
        vpls: &sv,
        lights: &gl,
        eps: s.gi.distance_epsilon,
    };
    let eye = st.cam.position;
    let (mut lit, mut close, mut same) = (0, 0, 0);
    for y in 0..H {
        for x in 0..W {
            let k = (y * W + x) as usize;
            let g = pos.pixels[k];
            if g[3] == 0.0 {
                continue;
            }
            let p = Vec3::new(g[0], g[1], g[2]);
            let nx = Vec3::from_slice(&nrm.pixels[k][..3]).normalize();
            let sh = Shading {
                v: (eye - p).normalize(),
                surface: Surface {
                    base: Vec3::from_slice(&alb.pixels[k][..3]),
                    metallic: alb.pixels[k][3],
                    roughness: nrm.pixels[k][3],
                },
            };
            let t = grid.tile_of(x, y) as usize;
            let list = &lists[t * cap..t * cap + count[t] as usize];
            let vis = visible(&bvh, &sv, p, nx, s.gi.ray_offset);
            let cpu = shade_shaded(p, nx, list, &inputs, il, vis, Some(&sh));
            let gpu = Vec3::from_slice(&raw[k][..3]);
            tally(&mut lit, &mut close, gpu, cpu);
            // Filter radius 0: the image is the pixel's own radiance (checked where lit).
            let img = Vec3::from_slice(&ind.pixels[k][..3]);
            if cpu.max_element() > 0.0 {
                same += ((img - gpu).abs().max_element() <= 1e-5 * gpu.max_element().max(1e-6)) as u32;
            }
        }
    }
    eprintln!("GGX shading: {close} of {lit} lit pixels within 1e-3 of the CPU, {same} images equal to raw");
    assert!(lit > 200 && close >= lit * 98 / 100, "{close} of {lit}");
    assert!(same as usize >= lit, "{same} of {lit}");

    // Unbiased over frames, without shadow rays (the unshadowed GGX truth), both variants.
    for method in [light_culling::ID, light_culling::TREE] {
        let mut s = s.clone();
        s.gi.method = method;
        s.gi.shadow_rays = false;
        s.frame.fixed_seed = false;
        let mut st = Setup::with_scene(&ctx, scene(), s, (W, H));
        st.frame();
        let gt = st.ground_truth_of_these_vpls();
        converges(&mut st, &gt, &format!("{method} with GGX"), 0.02);
    }
    assert!(ctx.errors.take().is_empty());
}

//! Lightcut Interpolation (`methods::lightcut_interpolation`): every GPU stage against the CPU
//! reference (`reference::lightcut_interpolation`) on the same frame — record reach,
//! placement, the records' cuts, selection and weights, the interpolated cuts (validity, size,
//! radiance) and the fallback; identical record cuts reproduce full Lightcuts exactly;
//! interpolated visibility traces no rays. Tiny sizes: 256 VPLs, 40 x 24 pixels.

mod common;

use common::Setup;

use glam::Vec3;
use lightcut::{
    base::gpu_layout::GpuVpl,
    methods::{
        lightcut_interpolation::{
            self as li, LightcutInterpolation,
            settings::{LiVisibility, LightcutInterpolationSettings},
        },
        lightcuts::{self, settings::LightcutsSettings},
    },
    metrics,
    reference::{
        lightcut_interpolation::{
            Record, TILE, TILE_CAP, TilePixel, VISIBLE, WeightParams, check_interpolated,
            harmonic_mean_distance, interpolate, pixel_footprint, place_tile, record_radius, select, shade,
            weight,
        },
        lightcuts::{CutInputs, CutParams, lightcut},
    },
    renderer::{
        Buffer, FrameInput,
        context::GpuContext,
        readback::{ImageF32, read_storage_buffer},
        settings::{RenderSettings, Tonemap, ViewBuffer},
    },
    scene::bvh::Bvh,
};

const W: u32 = 40;
const H: u32 = 24;

fn settings(li_s: LightcutInterpolationSettings) -> RenderSettings {
    let mut s = RenderSettings::default();
    s.gi.method = li::ID;
    s.vpl.count = 256;
    s.shadow.resolution = 256;
    s.frame.fixed_seed = true;
    s.set_method(li::ID, &li_s).unwrap();
    s
}

fn setup(ctx: &GpuContext, s: RenderSettings) -> Setup {
    Setup::new(ctx, s, (W, H))
}

fn li(st: &Setup) -> &LightcutInterpolation {
    st.r.method_module::<LightcutInterpolation>()
        .expect("lightcut interpolation is registered")
}

fn stat(st: &mut Setup, name: &str) -> f64 {
    let stats = st.r.method_stats_blocking();
    stats
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, v)| *v)
        .unwrap_or_else(|| panic!("no statistic {name} in {stats:?}"))
}

fn sorted_vpls(st: &Setup) -> Vec<GpuVpl> {
    let (_, tree) = st.r.tree_buffers();
    bytemuck::pod_collect_to_vec(&read_storage_buffer(&st.r.ctx, &tree.sorted_vpls).unwrap())
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() <= 1e-3 * b.max_element() + 1e-7
}

#[test]
fn gpu_records_selection_and_interpolation_equal_the_cpu_reference() {
    let Some(ctx) = common::gpu() else { return };
    let li_s = LightcutInterpolationSettings {
        relative_error: 0.05,
        max_cut: 64,
        ..Default::default()
    };
    let s = settings(li_s.clone());
    let mut st = setup(&ctx, s.clone());
    let traced = (W / 2, H / 2);
    st.r.set_trace_pixel(Some(traced));
    st.frame();
    let (nodes, _) = st.r.read_tree().unwrap();
    let sorted = sorted_vpls(&st);
    let lc = li(&st).read_build(&ctx).unwrap().expect("a build");
    let rec = li(&st).read_records(&ctx).unwrap().expect("records");
    let sel = li(&st).read_selection(&ctx).unwrap().expect("a selection");
    let bvh = Bvh::build(&st.scene.positions, &st.scene.indices);
    let ind = st.indirect();
    let pos = st.r.read(Buffer::Position).unwrap();
    let nrm = st.r.read(Buffer::Normal).unwrap();
    let alb = st.r.read(Buffer::Albedo).unwrap();
    let diag =
        st.r.read_view_buffer(ViewBuffer::Method(li::CUT_SIZE))
            .unwrap()
            .expect("the diagnostics");
    let at = |k: usize| {
        let g = pos.pixels[k];
        (
            g[3] != 0.0,
            Vec3::new(g[0], g[1], g[2]),
            Vec3::from_slice(&nrm.pixels[k][..3]).normalize(),
        )
    };
    let wp = WeightParams::new(li_s.max_angle_deg);
    let tan = (0.5 * st.cam.yfov).tan();

    // 1. Each pixel's reach: the harmonic mean distance over the same hemisphere rays.
    let (mut geo, mut same_reach) = (0, 0);
    for k in 0..(W * H) as usize {
        let (valid, x, n) = at(k);
        if !valid {
            continue;
        }
        geo += 1;
        let hm = harmonic_mean_distance(&bvh, x, n, k as u32, li_s.radius_rays, s.gi.ray_offset);
        let fp = pixel_footprint((x - st.cam.position).dot(st.cam.forward), tan, H);
        let want = record_radius(hm, fp, li_s.r_min_px, li_s.r_max_px);
        same_reach += ((rec.radius[k][0] - want).abs() <= 1e-3 * want) as u32;
    }
    eprintln!("reach: {same_reach} of {geo} pixels equal");
    assert!(geo > 500);
    assert!(same_reach >= geo * 99 / 100, "reach: {same_reach} of {geo}");

    // 2. Placement per tile (from the GPU's reach): the CPU's greedy choice, and every pixel
    //    of a tile below its cap covered by the GPU's records.
    let record_of = |k: usize| {
        let (_, x, n) = at(k);
        Record {
            position: x,
            normal: n,
            radius: rec.radius[k][0],
        }
    };
    let tiles_x = W.div_ceil(TILE);
    let (mut same_tiles, mut uncovered) = (0, 0);
    for (t, gpu) in rec.tiles.iter().enumerate() {
        let (tx, ty) = (t as u32 % tiles_x, t as u32 / tiles_x);
        let mut px = Vec::new();
        let mut index = Vec::new();
        for i in 0..TILE * TILE {
            let (x, y) = (tx * TILE + i % TILE, ty * TILE + i / TILE);
            let inside = x < W && y < H;
            let k = (y * W + x) as usize;
            px.push(TilePixel {
                valid: inside && at(k).0,
                record: if inside {
                    record_of(k)
                } else {
                    Record {
                        position: Vec3::ZERO,
                        normal: Vec3::Z,
                        radius: 0.0,
                    }
                },
            });
            index.push(k as u32);
        }
        let cpu: Vec<u32> = place_tile(&px, li_s.coverage, &wp)
            .into_iter()
            .map(|i| index[i as usize])
            .collect();
        same_tiles += (&cpu == gpu) as u32;
        if (gpu.len() as u32) < TILE_CAP {
            // Covered: a record itself, or by the records' summed weights.
            for (p, _) in px.iter().zip(&index).filter(|(p, k)| p.valid && !gpu.contains(k)) {
                let sum: f32 = gpu
                    .iter()
                    .map(|&r| {
                        weight(p.record.position, p.record.normal, &record_of(r as usize), &wp).max(0.0)
                    })
                    .sum();
                uncovered += (sum < li_s.coverage * (1.0 - 1e-4)) as u32;
            }
        }
    }
    eprintln!(
        "placement: {same_tiles} of {} tiles as the CPU's, {} records, {uncovered} pixels uncovered",
        rec.tiles.len(),
        rec.pixels.len()
    );
    assert!(
        same_tiles as usize >= rec.tiles.len() * 5 / 6,
        "placement differs in too many tiles"
    );
    assert_eq!(uncovered, 0);
    assert_eq!(rec.dropped, 0);
    let flat: Vec<u32> = rec.tiles.iter().flatten().copied().collect();
    assert_eq!(
        flat, rec.pixels,
        "the compacted list is the tiles' records in order"
    );

    // 3. The records' cuts: the CPU's lightcut at each record, sorted left to right.
    let p = CutParams {
        relative_error: li_s.relative_error,
        max_cut: li_s.max_cut,
        eps: s.gi.distance_epsilon,
        shadow_rays: Some(s.gi.ray_offset),
        trace_every_node: true,
    };
    let levels = (nodes.len() as u32 / 2).trailing_zeros();
    let mut same_cuts = 0;
    for (r, &k) in rec.pixels.iter().enumerate() {
        let (_, x, n) = at(k as usize);
        let cut = lightcut(&nodes, &lc, &sorted, &bvh, x, n, &p);
        let mut ids: Vec<u32> = cut
            .cut
            .iter()
            .map(|c| c.node | if c.visible { VISIBLE } else { 0 })
            .collect();
        lightcut::reference::lightcut_interpolation::sort_cut(&mut ids, levels);
        let gpu_ids: Vec<u32> = rec.cuts[r].iter().map(|e| e & !VISIBLE).collect();
        lightcut::reference::lightcuts::check_cut(&nodes, &gpu_ids)
            .unwrap_or_else(|e| panic!("record {r}: {e}"));
        same_cuts += (ids == rec.cuts[r]) as u32;
    }
    eprintln!("record cuts: {same_cuts} of {} equal", rec.pixels.len());
    assert!(same_cuts as usize >= rec.pixels.len() * 97 / 100);

    // 4. Selection and 5. interpolation and shading, per pixel, from the GPU's records.
    let records: Vec<Record> = rec.pixels.iter().map(|&k| record_of(k as usize)).collect();
    let tiles_y = H.div_ceil(TILE);
    let mut offsets = vec![0u32; rec.tiles.len() + 1];
    for (t, v) in rec.tiles.iter().enumerate() {
        offsets[t + 1] = offsets[t] + v.len() as u32;
    }
    let (mut same_sel, mut interp, mut fallback, mut same_size, mut same_rad) = (0, 0, 0, 0, 0);
    let mut traced_cpu = None;
    for y in 0..H {
        for x in 0..W {
            let k = (y * W + x) as usize;
            let (valid, xp, n) = at(k);
            if !valid {
                continue;
            }
            let (tx, ty) = ((x / TILE) as i32, (y / TILE) as i32);
            let mut cands = Vec::new();
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let (cx, cy) = (tx + dx, ty + dy);
                    if cx < 0 || cy < 0 || cx >= tiles_x as i32 || cy >= tiles_y as i32 {
                        continue;
                    }
                    let t = (cy as u32 * tiles_x + cx as u32) as usize;
                    for id in offsets[t]..offsets[t + 1] {
                        cands.push((id, weight(xp, n, &records[id as usize], &wp)));
                    }
                }
            }
            let cpu = select(cands, li_s.epsilon);
            let gpu = sel[k];
            let m = cpu.count as usize;
            let same = gpu.count == cpu.count
                && gpu.ids[..m] == cpu.records[..m]
                && (0..m).all(|i| (gpu.weights[i] - cpu.weights[i]).abs() < 1e-4);
            same_sel += same as u32;
            let albedo = Vec3::from_slice(&alb.pixels[k][..3]);
            let got = Vec3::from_slice(&ind.pixels[k][..3]);
            if gpu.count == 0 {
                fallback += 1;
                assert_eq!(
                    diag.pixels[k][1], -1.0,
                    "pixel ({x}, {y}) is marked as a fallback"
                );
                let want = lightcut(&nodes, &lc, &sorted, &bvh, xp, n, &p).radiance(albedo);
                same_rad += close(got, want) as u32;
                continue;
            }
            interp += 1;
            // Interpolate with the GPU's selection (the selection is compared above).
            let cuts: Vec<&[u32]> = gpu.ids[..gpu.count as usize]
                .iter()
                .map(|&r| rec.cuts[r as usize].as_slice())
                .collect();
            let out = interpolate(&nodes, &cuts, &gpu.weights[..gpu.count as usize]);
            check_interpolated(&nodes, &out.cut).unwrap_or_else(|e| panic!("pixel ({x}, {y}): {e}"));
            same_size += (diag.pixels[k][0] as usize == out.cut.len()) as u32;
            let inputs = CutInputs::perfect(&nodes, &lc, &sorted, &bvh, &p);
            let (sum, _) = shade(&inputs, &out.cut, xp, n, false);
            same_rad += close(got, albedo / std::f32::consts::PI * sum) as u32;
            if (x, y) == traced {
                traced_cpu = Some((gpu, out));
            }
        }
    }
    eprintln!(
        "{geo} pixels: {same_sel} same selection; {interp} interpolated ({same_size} same cut size), \
         {fallback} fallback; {same_rad} same radiance"
    );
    assert!(same_sel >= geo * 99 / 100, "selection: {same_sel} of {geo}");
    assert!(interp > geo * 9 / 10, "{interp} of {geo} pixels interpolated");
    assert!(
        same_size >= interp * 98 / 100,
        "cut sizes: {same_size} of {interp}"
    );
    assert!(same_rad >= geo * 97 / 100, "radiance: {same_rad} of {geo}");

    // 6. The pinned pixel's interpolation as the GPU traced it: valid and the CPU's.
    let tr = li(&st)
        .read_traced(&ctx)
        .unwrap()
        .expect("a traced interpolation");
    let (gsel, cpu) = traced_cpu.expect("the traced pixel is interpolated");
    assert_eq!(tr.pixel, traced.1 * W + traced.0);
    assert_eq!(tr.records, gsel.ids[..gsel.count as usize].to_vec());
    let ids: Vec<u32> = tr.nodes.iter().map(|n| n.0).collect();
    lightcut::reference::lightcuts::check_cut(&nodes, &ids).unwrap();
    assert_eq!(ids, cpu.cut.iter().map(|n| n.node).collect::<Vec<_>>());
    assert!((tr.level_spread - cpu.level_spread).abs() <= 1e-4 * cpu.level_spread.max(1.0));
    assert_eq!(tr.walk_steps, cpu.steps);
    // The story panel's data: the records' cuts, the interpolated cut, the disagreements.
    let story = st.r.read_cut_story().unwrap().expect("a cut story");
    assert_eq!(story.inputs.len(), tr.records.len());
    for (input, &r) in story.inputs.iter().zip(&tr.records) {
        let want: Vec<u32> = rec.cuts[r as usize].iter().map(|e| e & !VISIBLE).collect();
        assert_eq!(input.nodes, want);
    }
    assert_eq!(story.cut.as_ref().map(|c| c.nodes.clone()), Some(ids.clone()));
    assert_eq!(story.disagreements, cpu.disagreements);
    // The records view rings the pinned pixel's records in white (and no other pixel's).
    st.r.render(&FrameInput {
        camera: &st.cam,
        lights: &st.scene.lights,
        view: ViewBuffer::Method(li::RECORDS),
    });
    let (vw, vh, rgba) = st.r.read_view_rgba8().unwrap();
    assert_eq!((vw, vh), (W, H));
    let white = |x: i32, y: i32| {
        if x < 0 || y < 0 || x >= W as i32 || y >= H as i32 {
            return None;
        }
        let i = 4 * (y as usize * W as usize + x as usize);
        Some(rgba[i..i + 3] == [255, 255, 255])
    };
    let ringed: Vec<(i32, i32)> = tr
        .records
        .iter()
        .map(|&r| {
            let k = rec.pixels[r as usize];
            ((k % W) as i32, (k / W) as i32)
        })
        .collect();
    for &(rx, ry) in &ringed {
        let ring: Vec<bool> = (-2..=2)
            .flat_map(|d| {
                [
                    (rx + d, ry - 2),
                    (rx + d, ry + 2),
                    (rx - 2, ry + d),
                    (rx + 2, ry + d),
                ]
            })
            .filter_map(|(x, y)| white(x, y))
            .collect();
        assert!(
            !ring.is_empty() && ring.iter().all(|&w| w),
            "record at ({rx}, {ry}) not ringed"
        );
    }
    let whites = (0..H as i32)
        .flat_map(|y| (0..W as i32).map(move |x| (x, y)))
        .filter(|&(x, y)| white(x, y) == Some(true))
        .filter(|&(x, y)| {
            !ringed
                .iter()
                .any(|&(rx, ry)| (x - rx).abs().max((y - ry).abs()) == 2)
        })
        .count();
    assert_eq!(whites, 0, "white pixels away from the pinned pixel's records");

    // The counters: every walk finished; fallback fraction as counted here.
    assert_eq!(stat(&mut st, "unfinished_walks"), 0.0);
    let frac = stat(&mut st, "fallback_pixel_fraction");
    assert!(
        (frac - fallback as f64 / geo as f64).abs() < 1e-9,
        "fallback fraction {frac}"
    );
    assert!(ctx.errors.take().is_empty());
}

/// Runs `s` as Lightcut Interpolation and as Lightcuts with the same cut settings (fixed
/// seed: the same representatives) and returns both images.
fn li_and_lightcuts(ctx: &GpuContext, li_s: LightcutInterpolationSettings) -> (ImageF32, ImageF32, Setup) {
    let lc_s = LightcutsSettings {
        relative_error: li_s.relative_error,
        max_cut: li_s.max_cut,
    };
    let mut st = setup(ctx, settings(li_s));
    st.frame();
    let a = st.indirect();
    st.set(|s| {
        s.gi.method = lightcuts::ID;
        s.set_method(lightcuts::ID, &lc_s).unwrap();
    });
    st.frame();
    let b = st.indirect();
    (a, b, st)
}

#[test]
fn identical_record_cuts_reproduce_full_lightcuts() {
    let Some(ctx) = common::gpu() else { return };
    // Cuts of every leaf (threshold 0, 256 VPLs, no size limit): every record holds the same
    // cut, so every interpolated cut is that cut and, with a shadow ray per node, the image
    // is Lightcuts' image. (Cuts of the root alone are identical too, but the root's
    // representative, drawn by flux, is on the roof in this scene: a black image.)
    for (relative_error, max_cut) in [(0.0, 1024)] {
        let (a, b, _) = li_and_lightcuts(
            &ctx,
            LightcutInterpolationSettings {
                relative_error,
                max_cut,
                ..Default::default()
            },
        );
        let (mut worst, mut lit) = (0.0f32, 0);
        for (p, q) in a.pixels.iter().zip(&b.pixels) {
            let (p, q) = (Vec3::from_slice(&p[..3]), Vec3::from_slice(&q[..3]));
            if q.max_element() > 1e-6 {
                lit += 1;
                worst = worst.max((p - q).abs().max_element() / q.max_element());
            }
        }
        eprintln!("max cut {max_cut}: worst relative difference {worst:e} over {lit} lit pixels");
        assert!(lit > 500);
        assert!(
            worst < 1e-4,
            "max cut {max_cut}: worst relative difference {worst}"
        );
    }
    assert!(ctx.errors.take().is_empty());
}

#[test]
fn interpolated_visibility_shoots_no_rays_and_stays_close() {
    let Some(ctx) = common::gpu() else { return };
    let base = LightcutInterpolationSettings {
        relative_error: 0.02,
        max_cut: 128,
        ..Default::default()
    };
    let (full, lc_img, mut st) = li_and_lightcuts(&ctx, base.clone());
    st.set(|s| {
        s.gi.method = li::ID;
        s.set_method(
            li::ID,
            &LightcutInterpolationSettings {
                visibility: LiVisibility::Interpolated,
                ..base.clone()
            },
        )
        .unwrap();
    });
    st.frame();
    let iv = st.indirect();
    let stats = st.r.method_stats_blocking();
    let get = |k: &str| stats.iter().find(|(n, _)| *n == k).map(|(_, v)| *v).unwrap();
    let m_full = metrics::compare(&full, &lc_img, 3.0, Tonemap::Aces);
    let m_iv = metrics::compare(&iv, &lc_img, 3.0, Tonemap::Aces);
    eprintln!(
        "vs Lightcuts: full visibility RMSE {:.3e} (mean ratio {:.4}), interpolated {:.3e} ({:.4}); \
         rays per pixel with interpolated visibility {:.2}, records per pixel {:.3}",
        m_full.rmse,
        m_full.mean_ratio,
        m_iv.rmse,
        m_iv.mean_ratio,
        get("shadow_rays_per_pixel"),
        get("records_per_pixel")
    );
    assert_eq!(
        get("interpolation_rays_per_pixel"),
        0.0,
        "interpolated visibility traced rays of its own"
    );
    assert!(get("shadow_rays_per_pixel") > 0.0, "the records trace their rays");
    assert!(
        (m_full.mean_ratio - 1.0).abs() < 0.1,
        "full visibility mean {}",
        m_full.mean_ratio
    );
    assert!(
        (m_iv.mean_ratio - 1.0).abs() < 0.2,
        "interpolated visibility mean {}",
        m_iv.mean_ratio
    );
    assert!(ctx.errors.take().is_empty());
}

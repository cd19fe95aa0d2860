//! Virtual Area Lights' RSM clustering (`renderer::passes::val_cluster`, the VAL paper's
//! section 4) against its CPU reference (`reference::val`) on the default room's RSM: one
//! k-means step cluster by cluster and texel by texel, and after several steps every lit
//! texel in one cluster with the RSM's flux kept and the CPU's assignment followed. Tiny: a
//! 128^2 RSM, 48 clusters, splats of 32 texels.

mod common;

use common::Setup;

use glam::{UVec2, Vec3};
use lightcut::methods::val::{
    self as val_method, Vals,
    settings::{InterleaveSettings, IsmSettings, ValSettings, ValVisibility},
};
use lightcut::reference::interleave::{FilterImage, filter_pixel_window};
use lightcut::reference::ism::{self, IsmLayout, IsmLight};
use lightcut::reference::light_culling::TileCamera;
use lightcut::reference::val::{self, ClusterParams, MetricWeights, NONE, Rsm, RsmTexel};
use lightcut::reference::vpl::{pcg_hash, u01};
use lightcut::renderer::{
    Buffer,
    context::GpuContext,
    gpu_data::light_frustum,
    passes::ism::{bvh_area, cloud_of_bvh},
    passes::val_cluster::{
        ClusterRun, GpuVal, GpuValParams, ValClusterPass, ValSeeds, ValTargets, key_cluster,
    },
    readback::{read_storage_buffer, read_texture_f32},
    settings::RenderSettings,
    timing::GpuTimer,
};
use lightcut::scene::bvh::{Bvh, Ray};

const RES: u32 = 128;

/// The default room's RSM of light 0 (as the renderer drew it) and its raster.
fn rsm(ctx: &GpuContext) -> Rsm {
    let mut s = RenderSettings::default();
    s.shadow.resolution = RES;
    s.vpl.count = 64;
    let mut st = Setup::new(ctx, s, (32, 24));
    st.frame();
    rsm_of(&st, RES)
}

/// Light 0's `res`^2 RSM of the setup's last frame.
fn rsm_of(st: &Setup, res: u32) -> Rsm {
    let read = |b| st.r.read(b).unwrap();
    let (pos, nrm, flux) = (
        read(Buffer::RsmPosition(0)),
        read(Buffer::RsmNormal(0)),
        read(Buffer::RsmFlux(0)),
    );
    let light = &st.scene.lights[0];
    let (view_proj, texel, _) = light_frustum(light.direction, &st.scene.bounds, res);
    let texels = (0..(res * res) as usize)
        .map(|i| RsmTexel {
            position: Vec3::from_slice(&pos.pixels[i][..3]),
            normal: Vec3::from_slice(&nrm.pixels[i][..3]),
            flux: Vec3::from_slice(&flux.pixels[i][..3]),
            valid: pos.pixels[i][3] > 0.0,
        })
        .collect();
    Rsm {
        res,
        texels,
        texel_area: texel * texel,
        light_dir: light.direction.normalize(),
        view_proj,
        areas: Vec::new(),
    }
}

/// The RSM as three one-layer Rgba32Float arrays (the values the CPU twin reads).
fn upload(ctx: &GpuContext, rsm: &Rsm) -> Vec<wgpu::TextureView> {
    let layers: [Vec<[f32; 4]>; 3] = [
        rsm.texels
            .iter()
            .map(|t| {
                [
                    t.position.x,
                    t.position.y,
                    t.position.z,
                    if t.valid { 1.0 } else { 0.0 },
                ]
            })
            .collect(),
        rsm.texels
            .iter()
            .map(|t| t.normal.extend(0.0).to_array())
            .collect(),
        rsm.texels.iter().map(|t| t.flux.extend(1.0).to_array()).collect(),
    ];
    layers
        .iter()
        .map(|data| {
            let tex = ctx.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("test::rsm"),
                size: wgpu::Extent3d {
                    width: rsm.res,
                    height: rsm.res,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba32Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            });
            ctx.queue.write_texture(
                tex.as_image_copy(),
                bytemuck::cast_slice(data),
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(16 * rsm.res),
                    rows_per_image: Some(rsm.res),
                },
                tex.size(),
            );
            tex.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            })
        })
        .collect()
}

/// `n` seeds on lit texels, spread by a hash.
fn seeds(rsm: &Rsm, n: u32) -> Vec<UVec2> {
    let lit: Vec<usize> = (0..rsm.texels.len()).filter(|&i| rsm.lit(i)).collect();
    (0..n)
        .map(|k| {
            let i = lit[(u01(pcg_hash(k ^ 0x5bd1)) * lit.len() as f32) as usize % lit.len()];
            UVec2::new(i as u32 % rsm.res, i as u32 / rsm.res)
        })
        .collect()
}

/// The GPU's clusters and per-texel clusters after `iterations` steps.
fn gpu_cluster(
    ctx: &GpuContext,
    rsm: &Rsm,
    p: &ClusterParams,
    seeds: &[UVec2],
    iterations: u32,
) -> (Vec<val::Val>, Vec<u32>, Vec<u32>) {
    let views = upload(ctx, rsm);
    let pass = ValClusterPass::new(&ctx.device).unwrap();
    let mut t = ValTargets::new(&ctx.device, seeds.len() as u32, rsm.res);
    let params = GpuValParams::new(rsm.view_proj, rsm.light_dir, rsm.texel_area.sqrt(), rsm.res, 0, p);
    let mut timer = GpuTimer::new(&ctx.device, &ctx.queue);
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    let run = ClusterRun {
        name: "val_cluster",
        rsm: [&views[0], &views[1], &views[2]],
        params,
        seeds: ValSeeds::Cpu(seeds),
        iterations,
        carry: false,
    };
    pass.record(&ctx.device, &ctx.queue, &mut enc, &mut timer, run, &mut t)
        .unwrap();
    ctx.queue.submit([enc.finish()]);
    let vals: Vec<GpuVal> = bytemuck::pod_collect_to_vec(&read_storage_buffer(ctx, t.vals()).unwrap());
    let keys: Vec<u32> = bytemuck::pod_collect_to_vec(&read_storage_buffer(ctx, &t.keys).unwrap());
    let list: Vec<u32> = bytemuck::pod_collect_to_vec(&read_storage_buffer(ctx, &t.fallback).unwrap());
    assert!(ctx.errors.take().is_empty());
    (
        vals.into_iter().map(GpuVal::to_val).collect(),
        keys[..(rsm.res * rsm.res) as usize]
            .iter()
            .map(|&k| key_cluster(k))
            .collect(),
        list[1..1 + list[0] as usize].to_vec(),
    )
}

fn params() -> ClusterParams {
    ClusterParams {
        splat: 32,
        weights: MetricWeights {
            position: 0.4,
            normal: 0.3,
            flux: 0.3,
        },
    }
}

#[test]
fn one_clustering_step_equals_the_cpu_reference() {
    let Some(ctx) = common::gpu() else { return };
    let rsm = rsm(&ctx);
    let lit = (0..rsm.texels.len()).filter(|&i| rsm.lit(i)).count();
    assert!(lit > 1000, "the RSM sees the room: {lit} lit texels");
    let p = params();
    let s = seeds(&rsm, 48);
    let (gv, ga, glist) = gpu_cluster(&ctx, &rsm, &p, &s, 1);
    let (cv, ca) = val::cluster(&rsm, &p, &s, 1);
    // The assignment, texel by texel (near-ties of mu may go either way in the two float
    // paths: at most 0.5%).
    let same = (0..ga.len()).filter(|&i| rsm.lit(i) && ga[i] == ca[i]).count();
    assert!(
        (0..ga.len()).all(|i| rsm.lit(i) || (ga[i] == NONE && ca[i] == NONE)),
        "texels without flux belong to no cluster"
    );
    let (_, fallback) = val::map(
        &rsm,
        &p,
        &s.iter().map(|&t| val::seed(&rsm, t)).collect::<Vec<_>>(),
    );
    eprintln!(
        "one step: {same} of {lit} lit texels in the CPU's cluster ({} by the fallback)",
        fallback.len()
    );
    assert!(same * 1000 >= lit * 995, "{same} of {lit}");
    assert!(!fallback.is_empty(), "the fallback is exercised");
    // The fallback list: the texels no splat reached, in texel order (an atomic append gave
    // an order, and so sums over it, that changed from run to run with thread scheduling).
    assert_eq!(
        glist, fallback,
        "the GPU's fallback list is the CPU's, in texel order"
    );
    // The clusters: counts, means, sums, centres.
    let ext = val::extent(&rsm, &p);
    let mut close = 0;
    for (k, (g, c)) in gv.iter().zip(&cv).enumerate() {
        let ok = g.pixels.abs_diff(c.pixels) <= 1 + c.pixels / 100
            && (g.position - c.position).length() <= 1e-3 * ext
            && (g.normal - c.normal).length() <= 1e-3
            && (g.flux - c.flux).abs().max_element() <= 1e-3 * c.flux.max_element().max(1e-12)
            && (g.area - c.area).abs() <= 1e-3 * c.area
            && (g.texel.as_ivec2() - c.texel.as_ivec2()).abs().max_element() <= 1;
        if !ok {
            eprintln!("cluster {k}: GPU {g:?} vs CPU {c:?}");
        }
        close += ok as usize;
    }
    assert!(close * 100 >= gv.len() * 98, "{close} of {} clusters", gv.len());
}

#[test]
fn after_several_steps_every_lit_texel_is_in_one_cluster_and_the_flux_is_kept() {
    let Some(ctx) = common::gpu() else { return };
    let rsm = rsm(&ctx);
    let p = params();
    let s = seeds(&rsm, 48);
    // Every sixth seed repeats an earlier one (VPL seeds are drawn with replacement): empty
    // clusters are re-seeded between steps.
    let mut s = s;
    for k in (5..s.len()).step_by(6) {
        s[k] = s[k - 5];
    }
    let (vals, assignment, _) = gpu_cluster(&ctx, &rsm, &p, &s, 4);
    let lit = (0..rsm.texels.len()).filter(|&i| rsm.lit(i)).count();
    let (mut pixels, mut sum) = (0, Vec3::ZERO);
    for (i, &c) in assignment.iter().enumerate() {
        assert_eq!(c != NONE, rsm.lit(i), "texel {i}");
    }
    for (k, v) in vals.iter().enumerate() {
        let mine = assignment.iter().filter(|&&a| a == k as u32).count();
        // A cluster left empty by the last step is re-seeded (one pixel, its seed's).
        assert!(
            v.pixels as usize == mine || (mine == 0 && v.pixels == 1),
            "cluster {k}"
        );
        if mine > 0 {
            pixels += mine;
            sum += v.flux;
        }
    }
    let total = rsm.total_flux();
    eprintln!("four steps: {pixels} of {lit} lit texels clustered, flux {sum} of {total}");
    assert_eq!(pixels, lit);
    assert!((sum - total).abs().max_element() <= 1e-3 * total.max_element());
    // And the four steps follow the CPU's (float near-ties may move a centre by a texel).
    let (_, cpu) = val::cluster(&rsm, &p, &s, 4);
    let same = (0..cpu.len())
        .filter(|&i| rsm.lit(i) && assignment[i] == cpu[i])
        .count();
    eprintln!("four steps: {same} of {lit} lit texels in the CPU's cluster");
    assert!(same * 100 >= lit * 99, "{same} of {lit}");
}

#[test]
fn a_mismatched_clustering_is_refused() {
    let Some(ctx) = common::gpu() else { return };
    let pass = ValClusterPass::new(&ctx.device).unwrap();
    let mut t = ValTargets::new(&ctx.device, 4, 64);
    let views = upload(
        &ctx,
        &Rsm {
            res: 64,
            texels: vec![RsmTexel::default(); 64 * 64],
            texel_area: 0.01,
            light_dir: -Vec3::Y,
            view_proj: glam::Mat4::IDENTITY,
            areas: Vec::new(),
        },
    );
    let mut timer = GpuTimer::new(&ctx.device, &ctx.queue);
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    let mut run = |res: u32, seeds: &[UVec2]| {
        let p = GpuValParams::new(glam::Mat4::IDENTITY, -Vec3::Y, 0.1, res, 0, &params());
        let run = ClusterRun {
            name: "val_cluster",
            rsm: [&views[0], &views[1], &views[2]],
            params: p,
            seeds: ValSeeds::Cpu(seeds),
            iterations: 1,
            carry: false,
        };
        pass.record(&ctx.device, &ctx.queue, &mut enc, &mut timer, run, &mut t)
    };
    assert!(run(128, &[UVec2::ZERO]).unwrap_err().contains("128"));
    assert!(run(64, &[UVec2::ZERO; 5]).unwrap_err().contains("5 seeds"));
    assert!(run(64, &[]).is_err());
    assert!(run(64, &[UVec2::ZERO; 4]).is_ok());
}

// ---- The VAL method (`methods::val`): seeds, shading, visibility, accumulation ----

const W: u32 = 48;
const H: u32 = 32;
const METHOD_RES: u32 = 256;
/// The clustering RSM of the method tests (4 x 4 RSM texels each).
const CLUSTER_RES: u32 = 64;

/// Tiny VAL settings: 24 VALs on a 64^2 clustering RSM, 2 steps, a 2 x 2 pattern, 64^2 maps
/// in a 512^2 atlas.
fn small() -> ValSettings {
    ValSettings {
        clusters: 24,
        resolution: CLUSTER_RES,
        splat: 16,
        iterations: 2,
        interleave: InterleaveSettings::pattern(2),
        ism: IsmSettings {
            atlas: 512,
            tile: 64,
            points: 1 << 15,
            ..Default::default()
        },
        ..Default::default()
    }
}

fn method_settings(vs: &ValSettings, method: lightcut::methods::MethodId) -> RenderSettings {
    let mut s = RenderSettings::default();
    s.gi.method = method;
    s.vpl.count = 250;
    s.shadow.resolution = METHOD_RES;
    s.frame.fixed_seed = true;
    s.set_method(val_method::ID, vs).unwrap();
    s
}

fn vals_of(st: &Setup) -> &Vals {
    st.r.method_module::<Vals>()
        .expect("the VAL module is registered")
}

fn read_vals(st: &Setup) -> Vec<val::Val> {
    let t = vals_of(st).targets().expect("a VAL frame ran");
    let bytes = read_storage_buffer(&st.r.ctx, t.vals()).unwrap();
    let g: &[GpuVal] = bytemuck::cast_slice(&bytes);
    g[..t.clusters as usize].iter().map(|v| v.to_val()).collect()
}

/// Counts a lit pixel (the CPU's value above 1e-6) and whether the GPU's is within 1e-3 of it.
fn tally(lit: &mut usize, close: &mut usize, gpu: Vec3, cpu: Vec3) {
    if cpu.max_element() > 1e-6 {
        *lit += 1;
        *close += ((gpu - cpu).abs().max_element() <= 1e-3 * cpu.max_element()) as usize;
    }
}

/// The CPU's demodulated raw estimate of every pixel (n^2 x its subset's VALs, each with
/// `vis`) with the frame's interleaving offset.
fn cpu_raw(
    st: &Setup,
    vals: &[val::Val],
    n: u32,
    offset: u32,
    as_point: bool,
    mut vis: impl FnMut(u32, &val::Val, Vec3, Vec3) -> f32,
) -> Vec<Option<Vec3>> {
    let pos = st.r.read(Buffer::Position).unwrap();
    let nrm = st.r.read(Buffer::Normal).unwrap();
    let eps = st.r.settings().gi.distance_epsilon;
    (0..W * H)
        .map(|k| {
            let g = pos.pixels[k as usize];
            if g[3] == 0.0 {
                return None;
            }
            let (x, y) = (k % W, k / W);
            let p = Vec3::new(g[0], g[1], g[2]);
            let nx = Vec3::from_slice(&nrm.pixels[k as usize][..3]).normalize();
            let s = x % n + n * (y % n);
            let sum: Vec3 = val::subset(vals.len() as u32, n, offset, s)
                .map(|i| {
                    let v = &vals[i as usize];
                    let t = val::term(v, as_point, eps, p, nx);
                    if t == Vec3::ZERO { t } else { t * vis(i, v, p, nx) }
                })
                .sum();
            Some(sum * (n * n) as f32)
        })
        .collect()
}

fn gpu_raw(st: &Setup) -> Vec<Vec3> {
    let b = vals_of(st).buffers();
    let raw: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&read_storage_buffer(&st.r.ctx, &b.raw).unwrap());
    raw.iter().map(|r| Vec3::from_slice(&r[..3])).collect()
}

/// (lit pixels, pixels within 1e-3 of the CPU).
fn compare(gpu: &[Vec3], cpu: &[Option<Vec3>]) -> (usize, usize) {
    let (mut lit, mut close) = (0, 0);
    for (g, c) in gpu.iter().zip(cpu) {
        if let Some(c) = c {
            tally(&mut lit, &mut close, *g, *c);
        }
    }
    (lit, close)
}

#[test]
fn seeds_shading_and_pcss_equal_the_cpu_reference() {
    let Some(ctx) = common::gpu() else { return };
    let vs = small();
    let s = method_settings(&vs, val_method::ID);
    let mut st = Setup::new(&ctx, s.clone(), (W, H));
    st.frame();
    assert!(ctx.errors.take().is_empty());

    // Seeds: the GPU's from the frame's VPLs are the CPU twin's.
    let vpls = st.r.read_vpls().unwrap();
    let ids: Vec<u32> = vpls.iter().map(|v| v.id).collect();
    let want = val::seeds_from_vpls(&ids, vs.clusters, 0, METHOD_RES, METHOD_RES / CLUSTER_RES);
    let t = vals_of(&st).targets().unwrap();
    let got: Vec<u32> = bytemuck::pod_collect_to_vec(&read_storage_buffer(&ctx, &t.seeds).unwrap());
    assert_eq!(&got[..vs.clusters as usize], &want[..], "seed texels");

    // The clustering RSM: the GPU's summed-down RSM is the CPU twin's.
    let coarse = val::downsample(&rsm_of(&st, METHOD_RES), CLUSTER_RES);
    let c = vals_of(&st).clustering_rsm().unwrap();
    assert_eq!(c.res, CLUSTER_RES);
    let read = |i: usize| read_texture_f32(&ctx, &c.textures[i], 0).unwrap();
    let (gp, gn, gf) = (read(0), read(1), read(2));
    let mut same = 0;
    for (k, t) in coarse.texels.iter().enumerate() {
        let lit = coarse.lit(k);
        let close =
            |a: Vec3, b: Vec3, tol: f32| (a - b).abs().max_element() <= tol * b.abs().max_element().max(1e-3);
        let ok = if lit {
            gp.pixels[k][3] > 0.0
                && close(Vec3::from_slice(&gp.pixels[k][..3]), t.position, 1e-4)
                && close(Vec3::from_slice(&gn.pixels[k][..3]), t.normal, 1e-4)
                && close(Vec3::from_slice(&gf.pixels[k][..3]), t.flux, 1e-4)
                && (gf.pixels[k][3] - coarse.surface_area(k)).abs() <= 1e-4 * coarse.surface_area(k)
        } else {
            gp.pixels[k][3] == 0.0
        };
        same += ok as usize;
    }
    assert_eq!(same, coarse.texels.len(), "coarse texels equal to the CPU's");

    // The clusters partition the clustering RSM's lit texels and keep the RSM's flux.
    let lit_texels = (0..coarse.texels.len()).filter(|&i| coarse.lit(i)).count() as u32;
    let total = coarse.total_flux();
    let fine_total = rsm_of(&st, METHOD_RES).total_flux();
    assert!(
        (total - fine_total).abs().max_element() <= 1e-3 * total.max_element(),
        "{total} vs {fine_total}"
    );
    let vals = read_vals(&st);
    assert_eq!(vals.iter().map(|v| v.pixels).sum::<u32>(), lit_texels);
    // ... and follow the CPU's clustering of the CPU's coarse RSM from the same seeds.
    let seeds: Vec<UVec2> = want.iter().map(|&p| UVec2::new(p & 0xffff, p >> 16)).collect();
    let (_, assignment) = val::cluster(&coarse, &vs.cluster_params(), &seeds, vs.iterations);
    let keys: Vec<u32> = bytemuck::pod_collect_to_vec(&read_storage_buffer(&ctx, &t.keys).unwrap());
    let agree = (0..coarse.texels.len())
        .filter(|&i| coarse.lit(i) && key_cluster(keys[i]) == assignment[i])
        .count();
    println!("clustering: {agree} of {lit_texels} coarse texels in the CPU's cluster");
    assert!(agree as f64 >= 0.99 * lit_texels as f64, "{agree} / {lit_texels}");
    let vf: Vec3 = vals.iter().filter(|v| v.pixels > 0).map(|v| v.flux).sum();
    assert!(
        (vf - total).abs().max_element() <= 1e-3 * total.max_element(),
        "{vf} vs {total}"
    );
    // Distinct seeds: (almost) every VAL keeps texels.
    let lit_vals = vals.iter().filter(|v| v.pixels > 0).count();
    println!("{lit_vals} of {} VALs lit", vals.len());
    assert!(lit_vals + 1 >= vals.len(), "{lit_vals} VALs lit");

    // The maps' lights are the VALs.
    let (it, maps) = vals_of(&st).ism().expect("PCSS builds the maps");
    assert_eq!(maps, vs.clusters);
    let lights: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&read_storage_buffer(&ctx, &it.lights).unwrap());
    for (i, v) in vals.iter().enumerate() {
        assert_eq!(Vec3::from_slice(&lights[2 * i][..3]), v.position);
        assert_eq!(lights[2 * i][3] > 0.0, v.pixels > 0);
    }
    // The maps equal the CPU twin's: the cloud shared round-robin, points sized by distance
    // (the VAL defaults), pull-push.
    let layout = IsmLayout {
        atlas: vs.ism.atlas,
        tile: vs.ism.tile,
    };
    let bvh_gpu = &st.r.scene_gpu().bvh;
    let points: Vec<Vec3> = cloud_of_bvh(bvh_gpu, vs.ism.points, val_method::ISM_CLOUD_SEED)
        .into_iter()
        .map(|(p, _)| p)
        .collect();
    let radius = vs.ism.point_radius(
        bvh_area(bvh_gpu),
        vs.ism.points_per_map(points.len() as u32, vs.clusters),
    );
    assert!(radius > 0.0, "the VAL maps size their points");
    let ism_lights: Vec<IsmLight> = vals
        .iter()
        .map(|v| IsmLight {
            range: if v.pixels > 0 { f32::MAX.sqrt() } else { 0.0 },
            ..IsmLight::new(v.position, v.normal)
        })
        .collect();
    let mut cpu_atlas = ism::splat_sized(layout, &ism_lights, &points, None, 0, radius);
    let one_texel = ism::splat(layout, &ism_lights, &points, 0);
    let filled = |a: &[f32]| a.iter().filter(|&&d| d < ism::EMPTY).count();
    println!(
        "VAL maps: the sized points fill {} texels, one texel per point {}",
        filled(&cpu_atlas),
        filled(&one_texel)
    );
    assert!(filled(&cpu_atlas) > 2 * filled(&one_texel));
    ism::pull_push(layout, &mut cpu_atlas, vs.clusters, vs.ism.levels());
    let gpu_atlas: Vec<f32> = bytemuck::pod_collect_to_vec(&read_storage_buffer(&ctx, &it.depth).unwrap());
    let texels = (vs.clusters * vs.ism.tile * vs.ism.tile) as usize;
    let same = (0..vs.clusters)
        .flat_map(|m| (0..vs.ism.tile).flat_map(move |v| (0..vs.ism.tile).map(move |u| (m, u, v))))
        .filter(|&(m, u, v)| {
            let k = layout.texel(m, u, v);
            let (a, b) = (gpu_atlas[k], cpu_atlas[k]);
            a == b || (a - b).abs() <= 1e-5 * b.abs()
        })
        .count();
    println!("VAL maps: {same} of {texels} texels equal the CPU's");
    assert!(same * 1000 >= texels * 995, "{same} of {texels}");

    // PCSS shading (the default) against the CPU's lookups in the GPU's atlas.
    let atlas: Vec<f32> = bytemuck::pod_collect_to_vec(&read_storage_buffer(&ctx, &it.depth).unwrap());
    let n = vs.interleave.n;
    let offset = Vals::offset(&s, n, 0);
    let (mut blocked, mut lookups) = (0, 0);
    let bvh = Bvh::build(&st.scene.positions, &st.scene.indices);
    let off = s.gi.ray_offset;
    let ray = |v: &val::Val, p: Vec3, nx: Vec3| {
        let o = p + nx * off;
        let e = v.position + v.normal * off;
        !bvh.any_hit(&Ray {
            origin: o,
            dir: e - o,
            tmin: 1e-4,
            tmax: 1.0 - 1e-4,
        })
    };
    let (mut vis_pcss, mut vis_simple, mut vis_ray) = (0.0f64, 0.0f64, 0.0f64);
    let cpu = cpu_raw(&st, &vals, n, offset, false, |i, v, p, nx| {
        let q = val::pcss(layout, &atlas, i, v, p, vs.ism.bias, &vs.pcss);
        lookups += 1;
        blocked += q.blocked as usize;
        vis_pcss += q.visibility as f64;
        vis_simple += ism::visible(layout, &atlas, i, v.position, v.normal, p, vs.ism.bias) as u32 as f64;
        vis_ray += ray(v, p, nx) as u32 as f64;
        q.visibility
    });
    println!(
        "mean visibility: pcss {:.3}, simple {:.3}, rays {:.3}",
        vis_pcss / lookups as f64,
        vis_simple / lookups as f64,
        vis_ray / lookups as f64
    );
    let (lit, close) = compare(&gpu_raw(&st), &cpu);
    println!(
        "PCSS: {close} of {lit} lit pixels equal the CPU's; {blocked} of {lookups} lookups found blockers"
    );
    assert!(lit > 200 && close as f64 >= 0.99 * lit as f64, "{close} / {lit}");
    assert!(
        blocked > lookups / 20 && blocked < lookups,
        "the search finds some blockers"
    );

    // The paper's n x n filter (from the GPU's raw estimates) x albedo / pi is the indirect
    // image.
    assert!(vs.paper_filter, "the paper's window by default");
    let cam = TileCamera::new(&st.cam, W, H);
    let (pos, nrm) = (
        st.r.read(Buffer::Position).unwrap(),
        st.r.read(Buffer::Normal).unwrap(),
    );
    let surf: Vec<Option<(Vec3, Vec3)>> = (0..(W * H) as usize)
        .map(|k| {
            (pos.pixels[k][3] != 0.0).then(|| {
                (
                    Vec3::from_slice(&pos.pixels[k][..3]),
                    Vec3::from_slice(&nrm.pixels[k][..3]).normalize(),
                )
            })
        })
        .collect();
    let (alb, ind, raw) = (st.r.read(Buffer::Albedo).unwrap(), st.indirect(), gpu_raw(&st));
    let window = lightcut::renderer::passes::interleave_filter::window(vs.interleave.filter_radius, n);
    assert_eq!(window, (-1, 0), "a 2 x 2 pattern: one pixel of each subset");
    let img = FilterImage {
        width: W,
        height: H,
        eye: cam.eye,
        forward: cam.forward,
        surf: &surf,
        raw: &raw,
    };
    let (normal_cos, plane_tolerance) = (
        vs.interleave.filter_normal_cos,
        vs.interleave.filter_plane_tolerance,
    );
    let mut worst = 0.0f32;
    for y in 0..H {
        for x in 0..W {
            let k = (y * W + x) as usize;
            let f = filter_pixel_window(&img, x, y, window, normal_cos, plane_tolerance);
            let want = Vec3::from_slice(&alb.pixels[k][..3]) / std::f32::consts::PI * f;
            let got = Vec3::from_slice(&ind.pixels[k][..3]);
            worst = worst.max((got - want).abs().max_element() / want.max_element().max(1e-4));
        }
    }
    println!("filter: worst relative difference {worst:e}");
    assert!(worst < 1e-3, "filter {worst}");

    // The simple lookup, and the VPL mode with shadow rays.
    st.set(|s| val_method::set_visibility(s, ValVisibility::Ism));
    st.frame();
    let vals = read_vals(&st);
    let (it, _) = vals_of(&st).ism().unwrap();
    let atlas: Vec<f32> = bytemuck::pod_collect_to_vec(&read_storage_buffer(&ctx, &it.depth).unwrap());
    let cpu = cpu_raw(&st, &vals, n, offset, false, |i, v, p, _| {
        ism::visible(layout, &atlas, i, v.position, v.normal, p, vs.ism.bias) as u32 as f32
    });
    let (lit, close) = compare(&gpu_raw(&st), &cpu);
    println!("ISM: {close} of {lit} lit pixels equal the CPU's");
    assert!(lit > 200 && close as f64 >= 0.99 * lit as f64, "{close} / {lit}");

    st.set(|s| {
        s.gi.method = val_method::VPL;
        val_method::set_visibility(s, ValVisibility::Rays);
    });
    st.frame();
    assert!(ctx.errors.take().is_empty());
    assert!(vals_of(&st).ism().is_none(), "rays build no maps");
    let vals = read_vals(&st);
    let cpu = cpu_raw(&st, &vals, n, offset, true, |_, v, p, nx| {
        let o = p + nx * off;
        let e = v.position + v.normal * off;
        let hit = bvh.any_hit(&Ray {
            origin: o,
            dir: e - o,
            tmin: 1e-4,
            tmax: 1.0 - 1e-4,
        });
        if hit { 0.0 } else { 1.0 }
    });
    let (lit, close) = compare(&gpu_raw(&st), &cpu);
    println!("VPL mode with rays: {close} of {lit} lit pixels equal the CPU's");
    assert!(lit > 200 && close as f64 >= 0.99 * lit as f64, "{close} / {lit}");

    // Rays to the disks (exact visibility) against the CPU's rays to `disk_points`.
    st.set(|s| {
        s.gi.method = val_method::ID;
        val_method::set_visibility(s, ValVisibility::Disk);
    });
    st.frame();
    assert!(ctx.errors.take().is_empty());
    let vals = read_vals(&st);
    let cpu = cpu_raw(&st, &vals, n, offset, false, |_, v, p, nx| {
        val::disk_points(v)
            .iter()
            .filter(|&&c| ray(&val::Val { position: c, ..*v }, p, nx))
            .count() as f32
            / 16.0
    });
    let (lit, close) = compare(&gpu_raw(&st), &cpu);
    println!("disk visibility: {close} of {lit} lit pixels equal the CPU's");
    assert!(lit > 200 && close as f64 >= 0.99 * lit as f64, "{close} / {lit}");

    // Carried over (the paper's clustering): one step from the last frame's clusters, as the
    // CPU's step from the same clusters.
    let prev = read_vals(&st);
    st.set(|s| {
        let mut v: ValSettings = s.method(val_method::ID).unwrap();
        v.carry_over = true;
        v.iterations = 1;
        s.set_method(val_method::ID, &v).unwrap();
    });
    st.frame();
    let (want_vals, assignment) = val::cluster_from(&coarse, &vs.cluster_params(), Some(&prev), &seeds, 1);
    let t = vals_of(&st).targets().unwrap();
    let keys: Vec<u32> = bytemuck::pod_collect_to_vec(&read_storage_buffer(&ctx, &t.keys).unwrap());
    let agree = (0..coarse.texels.len())
        .filter(|&i| coarse.lit(i) && key_cluster(keys[i]) == assignment[i])
        .count();
    let got = read_vals(&st);
    let same = got
        .iter()
        .zip(&want_vals)
        .filter(|(g, w)| {
            g.pixels == w.pixels && (g.position - w.position).length() <= 1e-3 * w.position.length().max(1.0)
        })
        .count();
    println!(
        "carried: {agree} of {lit_texels} texels in the CPU's cluster, {same} of {} clusters equal",
        got.len()
    );
    assert!(agree as f64 >= 0.99 * lit_texels as f64, "{agree} / {lit_texels}");
    assert!(same as f64 >= 0.95 * got.len() as f64, "{same}");
    // A carried step moves the clusters on from the last frame's (k-means continues).
    assert!(got.iter().zip(&prev).any(|(g, p)| g.pixels != p.pixels));
}

#[test]
fn the_method_converges_to_its_own_sum_and_its_maps_agree_with_rays() {
    let Some(ctx) = common::gpu() else { return };
    let mut vs = small();
    vs.visibility = ValVisibility::Rays;
    vs.interleave.filter_radius = 0;
    vs.paper_filter = false;
    let mut s = method_settings(&vs, val_method::ID);
    s.frame.fixed_seed = false;
    s.frame.accumulate = true;
    let mut st = Setup::new(&ctx, s.clone(), (W, H));
    let f0 = st.r.frame_index();
    let frames = 12u64;
    for _ in 0..frames {
        st.frame();
    }
    assert!(ctx.errors.take().is_empty());
    assert_eq!(st.r.frames_averaged(), Some(frames as u32));
    let vals = read_vals(&st);
    let n = vs.interleave.n;
    let bvh = Bvh::build(&st.scene.positions, &st.scene.indices);
    let off = s.gi.ray_offset;
    let ray = |v: &val::Val, p: Vec3, nx: Vec3| {
        let o = p + nx * off;
        let e = v.position + v.normal * off;
        !bvh.any_hit(&Ray {
            origin: o,
            dir: e - o,
            tmin: 1e-4,
            tmax: 1.0 - 1e-4,
        })
    };
    // Every offset's estimate; their mean over the pattern is the sum over all VALs.
    let per_offset: Vec<Vec<Option<Vec3>>> = (0..n * n)
        .map(|o| cpu_raw(&st, &vals, n, o, false, |_, v, p, nx| ray(v, p, nx) as u32 as f32))
        .collect();
    let full = |k: usize| -> Option<Vec3> {
        per_offset[0][k]
            .map(|_| per_offset.iter().map(|e| e[k].unwrap_or_default()).sum::<Vec3>() / (n * n) as f32)
    };
    // The frames' mean (GPU, x albedo / pi) against the CPU's mean over the same offsets.
    let albedo = st.r.read(Buffer::Albedo).unwrap();
    let gpu = st.indirect();
    let (mut lit, mut close, mut err_mean, mut err_one, mut norm) = (0, 0, 0.0f64, 0.0f64, 0.0f64);
    #[allow(clippy::needless_range_loop)] // k indexes the images and every offset's estimate
    for k in 0..(W * H) as usize {
        let Some(truth) = full(k) else { continue };
        let a = Vec3::from_slice(&albedo.pixels[k][..3]) / std::f32::consts::PI;
        let mean: Vec3 = (0..frames)
            .map(|i| per_offset[Vals::offset(&s, n, f0 + i) as usize][k].unwrap_or_default())
            .sum::<Vec3>()
            / frames as f32;
        tally(
            &mut lit,
            &mut close,
            Vec3::from_slice(&gpu.pixels[k][..3]),
            mean * a,
        );
        let one = per_offset[Vals::offset(&s, n, f0) as usize][k].unwrap_or_default();
        err_mean += (mean - truth).length_squared() as f64;
        err_one += (one - truth).length_squared() as f64;
        norm += truth.length_squared() as f64;
    }
    println!(
        "accumulated {frames} frames: {close} of {lit} pixels equal the CPU's mean; relative error vs \
         the sum over all VALs {:.4} (one frame {:.4})",
        (err_mean / norm).sqrt(),
        (err_one / norm).sqrt()
    );
    assert!(lit > 200 && close as f64 >= 0.99 * lit as f64, "{close} / {lit}");
    assert!(
        err_mean < 0.5 * err_one,
        "the mean of the frames is nearer the sum over all VALs"
    );

    // The maps against rays over the (pixel, VAL) pairs that light each other, with the
    // simple and the PCSS lookup, for the point sizes and front-face culling.
    let eps = s.gi.distance_epsilon;
    let pos = st.r.read(Buffer::Position).unwrap();
    let nrm = st.r.read(Buffer::Normal).unwrap();
    let mut results = Vec::new();
    let d = IsmSettings::<lightcut::renderer::settings::IsmVal>::default();
    assert_eq!(
        (d.point_size, d.front_face_culling, d.bias),
        (0.5, false, 0.1),
        "the VAL defaults"
    );
    for (point_size, ffc, bias) in [
        (0.5, false, 0.1),
        (0.0, false, 0.1),
        (1.0, false, 0.1),
        (0.5, true, 0.05),
    ] {
        st.set(|s| {
            let mut v: ValSettings = s.method(val_method::ID).unwrap();
            v.visibility = ValVisibility::Ism;
            v.ism.point_size = point_size;
            v.ism.front_face_culling = ffc;
            v.ism.bias = bias;
            s.set_method(val_method::ID, &v).unwrap();
        });
        st.frame();
        let vals = read_vals(&st);
        let (it, _) = vals_of(&st).ism().unwrap();
        let cur: ValSettings = st.r.settings().method(val_method::ID).unwrap();
        let layout = IsmLayout {
            atlas: cur.ism.atlas,
            tile: cur.ism.tile,
        };
        let atlas: Vec<f32> = bytemuck::pod_collect_to_vec(&read_storage_buffer(&ctx, &it.depth).unwrap());
        let (mut simple_disk, mut pcss_disk) = (0.0f64, 0.0f64);
        let (mut pairs, mut agree, mut ray_lit, mut pcss_err) = (0usize, 0usize, 0usize, 0.0f64);
        for k in 0..(W * H) as usize {
            let g = pos.pixels[k];
            if g[3] == 0.0 {
                continue;
            }
            let p = Vec3::new(g[0], g[1], g[2]);
            let nx = Vec3::from_slice(&nrm.pixels[k][..3]).normalize();
            for (i, v) in vals.iter().enumerate() {
                if val::term(v, false, eps, p, nx) == Vec3::ZERO {
                    continue;
                }
                pairs += 1;
                let r = ray(v, p, nx);
                ray_lit += r as usize;
                agree +=
                    (ism::visible(layout, &atlas, i as u32, v.position, v.normal, p, bias) == r) as usize;
                let q = val::pcss(layout, &atlas, i as u32, v, p, bias, &vs.pcss);
                pcss_err += (q.visibility as f64 - r as u32 as f64).abs();
                // The disk's visible fraction: rays to 16 points of the VAL's disk.
                let disk = val::disk_points(v)
                    .iter()
                    .filter(|&&c| ray(&val::Val { position: c, ..*v }, p, nx))
                    .count() as f64
                    / 16.0;
                let simple =
                    ism::visible(layout, &atlas, i as u32, v.position, v.normal, p, bias) as u32 as f64;
                simple_disk += (simple - disk).abs();
                pcss_disk += (q.visibility as f64 - disk).abs();
            }
        }
        let (agree, all_lit) = (agree as f64 / pairs as f64, ray_lit as f64 / pairs as f64);
        println!(
            "point size {point_size}, front-face culling {ffc}, bias {bias}: simple lookups agree with \
             rays on {:.1}% of {pairs} pairs (all lit: {:.1}%), PCSS mean |error| {:.3}; vs the disk's \
             visible fraction: simple {:.3}, PCSS {:.3}",
            100.0 * agree,
            100.0 * all_lit,
            pcss_err / pairs as f64,
            simple_disk / pairs as f64,
            pcss_disk / pairs as f64
        );
        assert!(pairs > 1000);
        results.push((
            agree,
            all_lit,
            simple_disk / pairs as f64,
            pcss_disk / pairs as f64,
        ));
    }
    // The defaults: the maps see shadows, sized points more than one texel per point, and
    // PCSS is nearer the VAL disk's visible fraction than the simple lookup.
    let (agree, all_lit, simple, pcss) = results[0];
    assert!(agree > all_lit, "the maps see shadows");
    assert!(
        agree > results[1].0,
        "sized points agree more often than one texel per point"
    );
    assert!(pcss < simple, "PCSS is nearer the disk's visibility");
}

//! Virtual Area Lights' RSM clustering (`renderer::passes::val_cluster`, the VAL paper's
//! section 4) against its CPU reference (`reference::val`) on the default room's RSM: one
//! k-means step cluster by cluster and texel by texel, and after several steps every lit
//! texel in one cluster with the RSM's flux kept and the CPU's assignment followed. Tiny: a
//! 128^2 RSM, 48 clusters, splats of 32 texels.

mod common;

use common::Setup;

use glam::{UVec2, Vec3};
use lightcut::reference::val::{self, ClusterParams, MetricWeights, NONE, Rsm, RsmTexel};
use lightcut::reference::vpl::{pcg_hash, u01};
use lightcut::renderer::{
    Buffer,
    context::GpuContext,
    gpu_data::light_frustum,
    passes::val_cluster::{GpuVal, GpuValParams, ValClusterPass, ValTargets, key_cluster},
    readback::read_storage_buffer,
    settings::RenderSettings,
    timing::GpuTimer,
};

const RES: u32 = 128;

/// The default room's RSM of light 0 (as the renderer drew it) and its raster.
fn rsm(ctx: &GpuContext) -> Rsm {
    let mut s = RenderSettings::default();
    s.shadow.resolution = RES;
    s.vpl.count = 64;
    let mut st = Setup::new(ctx, s, (32, 24));
    st.frame();
    let read = |b| st.r.read(b).unwrap();
    let (pos, nrm, flux) = (
        read(Buffer::RsmPosition(0)),
        read(Buffer::RsmNormal(0)),
        read(Buffer::RsmFlux(0)),
    );
    let light = &st.scene.lights[0];
    let (view_proj, texel, _) = light_frustum(light.direction, &st.scene.bounds, RES);
    let texels = (0..(RES * RES) as usize)
        .map(|i| RsmTexel {
            position: Vec3::from_slice(&pos.pixels[i][..3]),
            normal: Vec3::from_slice(&nrm.pixels[i][..3]),
            flux: Vec3::from_slice(&flux.pixels[i][..3]),
            valid: pos.pixels[i][3] > 0.0,
        })
        .collect();
    Rsm {
        res: RES,
        texels,
        texel_area: texel * texel,
        light_dir: light.direction.normalize(),
        view_proj,
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
) -> (Vec<val::Val>, Vec<u32>) {
    let views = upload(ctx, rsm);
    let pass = ValClusterPass::new(&ctx.device).unwrap();
    let mut t = ValTargets::new(&ctx.device, seeds.len() as u32, rsm.res);
    let params = GpuValParams::new(rsm.view_proj, rsm.light_dir, rsm.texel_area.sqrt(), rsm.res, 0, p);
    let mut timer = GpuTimer::new(&ctx.device, &ctx.queue);
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    pass.record(
        &ctx.device,
        &ctx.queue,
        &mut enc,
        &mut timer,
        "val_cluster",
        [&views[0], &views[1], &views[2]],
        params,
        seeds,
        iterations,
        &mut t,
    )
    .unwrap();
    ctx.queue.submit([enc.finish()]);
    let vals: Vec<GpuVal> = bytemuck::pod_collect_to_vec(&read_storage_buffer(ctx, t.vals()).unwrap());
    let keys: Vec<u32> = bytemuck::pod_collect_to_vec(&read_storage_buffer(ctx, &t.keys).unwrap());
    assert!(ctx.errors.take().is_empty());
    (
        vals.into_iter().map(GpuVal::to_val).collect(),
        keys[..(rsm.res * rsm.res) as usize]
            .iter()
            .map(|&k| key_cluster(k))
            .collect(),
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
    let (gv, ga) = gpu_cluster(&ctx, &rsm, &p, &s, 1);
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
    eprintln!("one step: {same} of {lit} lit texels in the CPU's cluster ({fallback} by the fallback)");
    assert!(same * 1000 >= lit * 995, "{same} of {lit}");
    assert!(fallback > 0, "the fallback is exercised");
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
    let (vals, assignment) = gpu_cluster(&ctx, &rsm, &p, &s, 4);
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
        },
    );
    let mut timer = GpuTimer::new(&ctx.device, &ctx.queue);
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    let mut run = |res: u32, seeds: &[UVec2]| {
        let p = GpuValParams::new(glam::Mat4::IDENTITY, -Vec3::Y, 0.1, res, 0, &params());
        pass.record(
            &ctx.device,
            &ctx.queue,
            &mut enc,
            &mut timer,
            "val_cluster",
            [&views[0], &views[1], &views[2]],
            p,
            seeds,
            1,
            &mut t,
        )
    };
    assert!(run(128, &[UVec2::ZERO]).unwrap_err().contains("128"));
    assert!(run(64, &[UVec2::ZERO; 5]).unwrap_err().contains("5 seeds"));
    assert!(run(64, &[]).is_err());
    assert!(run(64, &[UVec2::ZERO; 4]).is_ok());
}

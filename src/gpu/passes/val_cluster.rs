//! Virtual Area Lights' clustering of a reflective shadow map (`shaders/val_cluster.wgsl`; the
//! VAL paper's section 4, after Prutkin et al. 2012): clusters seeded at given RSM texels, then
//! k steps of mapping (splat windows with eq. 1's metric, a fallback for texels no splat
//! reaches) and averaging (mean position and normal, summed flux and surface area, the new
//! centre texel), empty clusters re-seeded before the next step. Reads: one layer of the RSM (position, normal,
//! flux), the seeds. Writes: [`ValTargets`] (the clusters, each texel's key). Twin:
//! `reference::val` (docs/val.md).

use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, UVec2, Vec3};

use super::{WG_1D, WG_2D, storage_buffer, uniform_buffer};
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;
use crate::reference::val::{MAX_CLUSTERS, NONE, Val};

/// Twin: `ValParams` in `val_cluster.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuValParams {
    pub view_proj: [[f32; 4]; 4],
    pub light_dir: [f32; 3],
    pub texel_area: f32,
    pub res: u32,
    pub clusters: u32,
    pub splat: u32,
    pub layer: u32,
    pub w_p: f32,
    pub w_n: f32,
    pub w_f: f32,
    /// d_p's unit: splat texels x texel edge (`reference::val::extent`).
    pub extent: f32,
    /// 1: a texel's surface area is its flux's alpha (the method's summed-down RSM,
    /// `reference::val::downsample`); 0: the texel area over the cosine to the light.
    pub area_mode: u32,
    pub _pad: [u32; 3],
}

impl GpuValParams {
    /// The parameters for layer `layer` of a `res`^2 RSM whose raster is `view_proj`, texels of
    /// `texel` metres perpendicular to a light travelling along `light_dir` (the cluster count
    /// is the seeds', set by [`ValClusterPass::record`]).
    pub fn new(
        view_proj: Mat4,
        light_dir: Vec3,
        texel: f32,
        res: u32,
        layer: u32,
        p: &crate::reference::val::ClusterParams,
    ) -> Self {
        Self {
            view_proj: view_proj.to_cols_array_2d(),
            light_dir: light_dir.normalize_or(Vec3::NEG_Y).to_array(),
            texel_area: texel * texel,
            res,
            clusters: 0,
            splat: p.splat,
            layer,
            w_p: p.weights.position,
            w_n: p.weights.normal,
            w_f: p.weights.flux,
            extent: p.splat as f32 * texel,
            area_mode: 0,
            _pad: [0; 3],
        }
    }
}

/// Twin: `Val` in `val_cluster.wgsl` (`reference::val::Val`; the texel packed x | y << 16).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuVal {
    pub position: [f32; 3],
    pub area: f32,
    pub normal: [f32; 3],
    pub pixels: u32,
    pub flux: [f32; 3],
    pub texel: u32,
}

impl GpuVal {
    pub fn to_val(self) -> Val {
        Val {
            position: Vec3::from_array(self.position),
            normal: Vec3::from_array(self.normal),
            flux: Vec3::from_array(self.flux),
            pixels: self.pixels,
            area: self.area,
            texel: UVec2::new(self.texel & 0xffff, self.texel >> 16),
        }
    }
}

/// The cluster of a texel's stored (inverted) key; `NONE` where no cluster took it.
pub fn key_cluster(stored: u32) -> u32 {
    if stored == 0 {
        NONE
    } else {
        (!stored) & (MAX_CLUSTERS - 1)
    }
}

/// The clusters (two buffers: a step reads one and writes the other), the texels' keys, the
/// fallback list and the seeds.
pub struct ValTargets {
    pub clusters: u32,
    pub res: u32,
    vals: [wgpu::Buffer; 2],
    /// Per RSM texel the inverted least key of the last step ([`key_cluster`]).
    pub keys: wgpu::Buffer,
    /// The last step's fallback list: [0] its length, then the texels no splat reached, in
    /// texel order (so a run's sums do not depend on thread scheduling).
    pub fallback: wgpu::Buffer,
    /// Per cluster its seed texel (packed x | y << 16): written by [`ValClusterPass::record`]
    /// from CPU seeds, or by the caller's kernel ([`ValSeeds::Written`]).
    pub seeds: wgpu::Buffer,
    /// Which of `vals` the last run left its clusters in.
    last: usize,
    /// Whether a run left clusters to carry over.
    primed: bool,
}

impl ValTargets {
    pub fn new(device: &wgpu::Device, clusters: u32, res: u32) -> Self {
        let n = clusters.clamp(1, MAX_CLUSTERS) as u64;
        let texels = res as u64 * res as u64;
        let vals = |label| storage_buffer(device, label, n * std::mem::size_of::<GpuVal>() as u64);
        Self {
            clusters: n as u32,
            res,
            vals: [vals("val::clusters_a"), vals("val::clusters_b")],
            keys: storage_buffer(device, "val::keys", 4 * texels),
            fallback: storage_buffer(device, "val::fallback", 4 * (texels + 1)),
            seeds: storage_buffer(device, "val::seeds", 4 * n),
            last: 0,
            primed: false,
        }
    }
    pub fn matches(&self, clusters: u32, res: u32) -> bool {
        self.clusters == clusters && self.res == res
    }
    /// Forget the last run's clusters: the next run with `carry` seeds (a new scene, a reset,
    /// a failed frame).
    pub fn unprime(&mut self) {
        self.primed = false;
    }
    /// The buffer holding the clusters after the last run.
    pub fn vals(&self) -> &wgpu::Buffer {
        &self.vals[self.last]
    }
}

/// One clustering run: its timer name, the RSM's position, normal and flux array views, the
/// parameters, the seeds, the steps and whether it carries the last run's clusters over.
#[derive(Clone, Copy)]
pub struct ClusterRun<'a> {
    pub name: &'a str,
    pub rsm: [&'a wgpu::TextureView; 3],
    pub params: GpuValParams,
    pub seeds: ValSeeds<'a>,
    pub iterations: u32,
    pub carry: bool,
}

/// Where a clustering run's seeds come from.
#[derive(Clone, Copy, Debug)]
pub enum ValSeeds<'a> {
    /// Texels given by the CPU (uploaded into the targets' seeds).
    Cpu(&'a [UVec2]),
    /// This many seeds already written into `ValTargets::seeds` on the GPU earlier in the
    /// same submission (the VAL method's seeds from the frame's VPLs).
    Written(u32),
}

impl ValSeeds<'_> {
    pub fn count(&self) -> usize {
        match self {
            ValSeeds::Cpu(s) => s.len(),
            ValSeeds::Written(n) => *n as usize,
        }
    }
}

pub struct ValClusterPass {
    kernel: Kernel,
    clear: wgpu::ComputePipeline,
    seed: wgpu::ComputePipeline,
    map: wgpu::ComputePipeline,
    list: wgpu::ComputePipeline,
    fallback: wgpu::ComputePipeline,
    average: wgpu::ComputePipeline,
    reseed: wgpu::ComputePipeline,
    params: wgpu::Buffer,
}

impl ValClusterPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(
            device,
            "val_cluster.wgsl",
            &[
                "clear_main",
                "seed_main",
                "map_main",
                "list_main",
                "fallback_main",
                "average_main",
                "reseed_main",
            ],
            KernelOptions::default(),
        )?;
        let pipe = |entry: &str| kernel.compute(device, entry, entry);
        Ok(Self {
            clear: pipe("clear_main"),
            seed: pipe("seed_main"),
            map: pipe("map_main"),
            list: pipe("list_main"),
            fallback: pipe("fallback_main"),
            average: pipe("average_main"),
            reseed: pipe("reseed_main"),
            params: uniform_buffer::<GpuValParams>(device, "val_cluster::params"),
            kernel,
        })
    }

    /// Runs `run`: clusters seeded at `seeds` (one per cluster, at most the targets' clusters; a seed on a
    /// texel without flux gives a cluster of no flux that may still take texels), or with `carry` the clusters the
    /// last run left in `t` (their empty ones re-seeded first; the first run seeds), then
    /// `iterations` steps, in one compute pass timed as `name`: a cluster left empty by a step
    /// is re-seeded before the next; after the last step it stays empty (`pixels` 0). `rsm`:
    /// the position, normal and flux array views. The parameters and seeds live in the pass
    /// and the targets: one `record` per submission. Refused (nothing recorded) when the
    /// targets were made for another resolution or fewer clusters, or without seeds.
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        run: ClusterRun<'_>,
        t: &mut ValTargets,
    ) -> Result<(), String> {
        let ClusterRun {
            name,
            rsm,
            params: p,
            seeds,
            iterations,
            carry,
        } = run;
        if p.res != t.res {
            return Err(format!(
                "VAL clustering: a {0}^2 RSM in targets made for {1}^2",
                p.res, t.res
            ));
        }
        if seeds.count() == 0 || seeds.count() as u32 > t.clusters {
            return Err(format!(
                "VAL clustering: {} seeds for targets of {} clusters",
                seeds.count(),
                t.clusters
            ));
        }
        let n = seeds.count() as u32;
        let p = GpuValParams { clusters: n, ..p };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        if let ValSeeds::Cpu(seeds) = seeds {
            let packed: Vec<u32> = seeds.iter().map(|s| s.x | s.y << 16).collect();
            queue.write_buffer(&t.seeds, 0, bytemuck::cast_slice(&packed));
        }
        // (in, out): 0 -> 1 and 1 -> 0.
        let bind = |i: usize| {
            self.kernel.bind(
                device,
                0,
                &[
                    ("vp", buf(&self.params)),
                    ("rsm_position", tex(rsm[0])),
                    ("rsm_normal", tex(rsm[1])),
                    ("rsm_flux", tex(rsm[2])),
                    ("vals_in", buf(&t.vals[i])),
                    ("vals_out", t.vals[1 - i].as_entire_binding()),
                    ("keys", buf(&t.keys)),
                    ("fallback", buf(&t.fallback)),
                    ("seeds", buf(&t.seeds)),
                ],
            )
        };
        let groups = [bind(0), bind(1)];
        encoder.push_debug_group(name);
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(name),
                timestamp_writes: timer.compute_pass(name),
            });
            {
                let per_cluster = n.div_ceil(WG_1D);
                let texel_groups = (p.res * p.res).div_ceil(WG_1D);
                let (cx, cy) = (texel_groups.min(65535), texel_groups.div_ceil(65535));
                let splat = p.splat.div_ceil(WG_2D);
                // Carried over: the last run's clusters are the first step's input.
                // Else seed into vals[0] (the bind group whose output is 0).
                let carry = carry && t.primed;
                let mut cur = if carry { t.last } else { 0 };
                if !carry {
                    pass.set_bind_group(0, &groups[1], &[]);
                    pass.set_pipeline(&self.seed);
                    pass.dispatch_workgroups(per_cluster, 1, 1);
                }
                for step in 0..iterations.max(1) {
                    if step > 0 || carry {
                        // Re-seed the empty clusters of the step's input (the bind group
                        // whose output is vals[cur]).
                        pass.set_bind_group(0, &groups[1 - cur], &[]);
                        pass.set_pipeline(&self.reseed);
                        pass.dispatch_workgroups(per_cluster, 1, 1);
                    }
                    pass.set_bind_group(0, &groups[cur], &[]);
                    pass.set_pipeline(&self.clear);
                    pass.dispatch_workgroups(cx, cy, 1);
                    pass.set_pipeline(&self.map);
                    pass.dispatch_workgroups(splat, splat, n);
                    // The fallback list in texel order (one workgroup), then its keys.
                    pass.set_pipeline(&self.list);
                    pass.dispatch_workgroups(1, 1, 1);
                    pass.set_pipeline(&self.fallback);
                    pass.dispatch_workgroups(cx, cy, 1);
                    pass.set_pipeline(&self.average);
                    pass.dispatch_workgroups(n, 1, 1);
                    cur = 1 - cur;
                }
                t.last = cur;
                t.primed = true;
            }
        }
        encoder.pop_debug_group();
        Ok(())
    }
}

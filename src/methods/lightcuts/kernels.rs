//! Lightcuts' two kernels, which Lightcut Interpolation builds on too: [`BuildKernel`] (normal
//! cones and representatives per node of the light tree) and [`CutKernel`] (a cut per pixel
//! or per record slot, in slices, with its bindings [`CutBindings`]).

use super::pass::{GpuLcBuildParams, GpuLcParams, MAX_LEVELS, dispatches_per_slice};
use crate::gpu::frame::GbufferTargets;
use crate::gpu::kernel::{Kernel, KernelOptions, buf, tex};
use crate::gpu::passes::sst_build::TreeBuffers;
use crate::gpu::passes::{StridedUniforms, WG_1D};
use crate::gpu::scene_gpu::SceneGpu;
use crate::gpu::shaders;
use crate::gpu::timing::GpuTimer;

/// The per-pixel cut kernel (`lightcuts.wgsl`) in one MODE: 0 the image, 1 Lightcut
/// Interpolation's cache records, 2 its fallback pixels.
pub struct CutKernel {
    mode: u32,
    cut: wgpu::ComputePipeline,
    cut_timed: wgpu::ComputePipeline,
    kernel: Kernel,
    /// Per-dispatch uniforms.
    params: StridedUniforms<GpuLcParams>,
}

/// What the cut kernel binds.
pub struct CutBindings<'a> {
    pub tree: &'a TreeBuffers,
    pub scene: &'a SceneGpu,
    pub gbuffer: &'a GbufferTargets,
    pub cones: &'a wgpu::Buffer,
    pub reps: &'a wgpu::Buffer,
    pub accum: &'a wgpu::Buffer,
    pub diag: &'a wgpu::Buffer,
    pub stats: &'a wgpu::Buffer,
    pub trace: &'a wgpu::Buffer,
    pub scratch: &'a wgpu::Buffer,
    pub state: &'a wgpu::Buffer,
    /// Mode 1: the records' pixels; mode 2: the selection (8 words per pixel).
    pub lanes: &'a wgpu::Buffer,
    pub record_cuts: &'a wgpu::Buffer,
    pub rec_meta: &'a wgpu::Buffer,
}

/// One run of the cut kernel: its timer name, parameters, `items` threads (pixels or record
/// slots) in slices of `slice`, and whether it writes the diagnostics (counters, trace).
pub struct CutRun<'a> {
    pub name: &'a str,
    pub params: GpuLcParams,
    pub items: u32,
    pub slice: u32,
    pub diagnostics: bool,
}

impl CutKernel {
    pub fn new(device: &wgpu::Device, mode: u32, stats_base: u32) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(
            device,
            "methods/lightcuts/lightcuts.wgsl",
            &["main"],
            KernelOptions { dynamic: &["lp"] },
        )?;
        let (mode_f, base_f) = (mode as f64, stats_base as f64);
        let consts = [("MODE", mode_f), ("STATS_BASE", base_f)];
        let timed = [("DIAGNOSTICS", 0.0), ("MODE", mode_f), ("STATS_BASE", base_f)];
        Ok(Self {
            mode,
            cut: kernel.compute_with(device, "lightcuts", "main", &consts),
            cut_timed: kernel.compute_with(device, "lightcuts_timed", "main", &timed),
            kernel,
            params: StridedUniforms::new(device, "lightcuts::params", 1),
        })
    }

    /// Records one compute pass named `name` (one timestamp pair): `items` threads (pixels
    /// or record slots) in slices of `slice`, each slice's dispatches in order (mode 1 adds a
    /// last dispatch that only writes the sorted cuts).
    pub fn record(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        run: CutRun<'_>,
        b: &CutBindings<'_>,
    ) {
        let CutRun {
            name,
            params: p,
            items,
            slice,
            diagnostics,
        } = run;
        let slices = items.div_ceil(slice).max(1);
        let refine = dispatches_per_slice(p.max_cut, b.tree.depth_bound(), p.steps);
        let per_slice = refine + (self.mode == 1) as u32;
        let n = slices * per_slice;
        let mut all = Vec::with_capacity(n as usize);
        for i in 0..slices {
            for j in 0..per_slice {
                let write_out = self.mode == 1 && j == refine;
                let sp = GpuLcParams {
                    first_pixel: i * slice,
                    slice,
                    first: (j == 0) as u32,
                    last: (j + 1 == per_slice) as u32,
                    steps: if write_out { 0 } else { p.steps },
                    ..p
                };
                all.push(sp);
            }
        }
        self.params.write(device, queue, &all);
        let bind = self.kernel.bind(
            device,
            0,
            &[
                ("lp", self.params.binding()),
                ("tree", buf(&b.tree.nodes)),
                ("sorted_vpls", buf(&b.tree.sorted_vpls)),
                ("cones", buf(b.cones)),
                ("reps", buf(b.reps)),
                ("bvh_nodes", buf(&b.scene.bvh_nodes)),
                ("bvh_triangles", buf(&b.scene.bvh_triangles)),
                ("gb_position", tex(&b.gbuffer.position_view)),
                ("gb_normal", tex(&b.gbuffer.normal_view)),
                ("gb_albedo", tex(&b.gbuffer.albedo_view)),
                ("accum", buf(b.accum)),
                ("diag", buf(b.diag)),
                ("stats", buf(b.stats)),
                ("trace", buf(b.trace)),
                ("scratch", buf(b.scratch)),
                ("state", buf(b.state)),
                ("lanes", buf(b.lanes)),
                ("record_cuts", buf(b.record_cuts)),
                ("rec_meta", buf(b.rec_meta)),
                ("tree_links", buf(&b.tree.links)),
            ],
        );
        encoder.push_debug_group(name);
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(name),
                timestamp_writes: timer.compute_pass(name),
            });
            pass.set_pipeline(if diagnostics { &self.cut } else { &self.cut_timed });
            for i in 0..n {
                pass.set_bind_group(0, &bind, &[StridedUniforms::<GpuLcParams>::offset(i)]);
                pass.dispatch_workgroups(slice / WG_1D, 1, 1);
            }
        }
        encoder.pop_debug_group();
    }
}

/// The build kernel (`lc_build.wgsl`): normal cones and representatives, bottom-up, one
/// dispatch per level of the perfect tree; on the radix tree `lc_build_radix.wgsl`, one
/// thread per leaf with arrival counters.
pub struct BuildKernel {
    build: wgpu::ComputePipeline,
    kernel: Kernel,
    radix: wgpu::ComputePipeline,
    radix_kernel: Kernel,
    /// The radix build's arrival counters (one per node; grown on demand).
    counters: Option<wgpu::Buffer>,
    /// One per level.
    params: StridedUniforms<GpuLcBuildParams>,
}

/// One run of the build: its timer name, the frame's seed (representatives), the light tree
/// it reads and the cones and representatives it writes.
pub struct BuildRun<'a> {
    pub name: &'a str,
    pub seed: u32,
    pub tree: &'a TreeBuffers,
    pub cones: &'a wgpu::Buffer,
    pub reps: &'a wgpu::Buffer,
}

impl BuildKernel {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(
            device,
            "methods/lightcuts/lc_build.wgsl",
            &["main"],
            KernelOptions { dynamic: &["bp"] },
        )?;
        let radix_kernel = Kernel::new(
            device,
            "methods/lightcuts/lc_build_radix.wgsl",
            &["main"],
            KernelOptions { dynamic: &["bp"] },
        )?;
        Ok(Self {
            build: kernel.compute(device, "lightcuts_build", "main"),
            radix: radix_kernel.compute(device, "lightcuts_build_radix", "main"),
            params: StridedUniforms::new(device, "lightcuts_build::params", MAX_LEVELS),
            kernel,
            radix_kernel,
            counters: None,
        })
    }

    /// Records the build (one compute pass named `name`) into `cones`, `reps`: the perfect
    /// tree level by level (leaves first, the root last), the radix tree in one dispatch of a
    /// thread per leaf with arrival counters.
    pub fn record(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        run: BuildRun<'_>,
    ) {
        let BuildRun {
            name,
            seed,
            tree,
            cones,
            reps,
        } = run;
        let radix = tree.kind == crate::settings::TreeKind::Lbvh;
        // Per dispatch: its uniforms (the radix build reads only leaves and seed).
        let dispatches: Vec<GpuLcBuildParams> = if radix {
            vec![GpuLcBuildParams {
                first: 0,
                count: tree.leaves,
                leaves: tree.leaves,
                seed,
            }]
        } else {
            (0..tree.levels())
                .rev()
                .map(|level| GpuLcBuildParams {
                    first: 1 << level,
                    count: 1 << level,
                    leaves: tree.leaves,
                    seed,
                })
                .collect()
        };
        self.params.write(device, queue, &dispatches);
        // Both builds read one table; the radix tree's also its links and arrival counters.
        let mut table = vec![
            ("bp", self.params.binding()),
            ("nodes", buf(&tree.nodes)),
            ("sorted_vpls", buf(&tree.sorted_vpls)),
            ("cones", buf(cones)),
            ("reps", buf(reps)),
        ];
        if radix {
            let need = 4 * tree.leaves.max(4) as u64;
            if self.counters.as_ref().is_none_or(|c| c.size() < need) {
                self.counters = Some(crate::gpu::passes::storage_buffer(
                    device,
                    "lightcuts_build_radix::counters",
                    need,
                ));
            }
            let Some(counters) = &self.counters else { return };
            encoder.clear_buffer(counters, 0, None);
            table.extend([
                ("links", buf(&tree.links)),
                ("parents", buf(&tree.parents)),
                ("counters", buf(counters)),
            ]);
        }
        let kernel = if radix { &self.radix_kernel } else { &self.kernel };
        let bind = kernel.bind_table(device, 0, &table);
        let pipeline = if radix { &self.radix } else { &self.build };
        encoder.push_debug_group(name);
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(name),
                timestamp_writes: timer.compute_pass(name),
            });
            pass.set_pipeline(pipeline);
            for (i, bp) in dispatches.iter().enumerate() {
                pass.set_bind_group(0, &bind, &[StridedUniforms::<GpuLcBuildParams>::offset(i as u32)]);
                pass.dispatch_workgroups(bp.count.div_ceil(WG_1D).max(1), 1, 1);
            }
        }
        encoder.pop_debug_group();
    }
}

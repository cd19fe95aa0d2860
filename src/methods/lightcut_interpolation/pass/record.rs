//! [`LiPass`]: its kernels and the passes a frame records (cut walk, records, interpolation,
//! refinement, views).

use super::*;
use crate::methods::{FrameCx, ViewCx};

impl LiPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let dynamic = KernelOptions { dynamic: &["lp"] };
        let records_kernel = Kernel::new(
            device,
            "methods/lightcut_interpolation/li_records.wgsl",
            &["radius_main", "place_main", "compact_main"],
            dynamic,
        )?;
        let select_kernel = Kernel::new(
            device,
            "methods/lightcut_interpolation/li_select.wgsl",
            &["main"],
            dynamic,
        )?;
        let interp_kernel = Kernel::new(
            device,
            "methods/lightcut_interpolation/li_interp.wgsl",
            &["main"],
            dynamic,
        )?;
        let views_kernel = Kernel::new(
            device,
            "methods/lightcut_interpolation/li_views.wgsl",
            &["main"],
            KernelOptions::default(),
        )?;
        Ok(Self {
            build: BuildKernel::new(device)?,
            record_cuts: CutKernel::new(device, 1, 8)?,
            fallback: CutKernel::new(device, 2, 16)?,
            radius: records_kernel.compute(device, "li_radius", "radius_main"),
            place: records_kernel.compute(device, "li_place", "place_main"),
            compact: records_kernel.compute(device, "li_compact", "compact_main"),
            records_kernel,
            select: select_kernel.compute(device, "li_select", "main"),
            select_kernel,
            interp: interp_kernel.compute(device, "li_interp", "main"),
            interp_timed: interp_kernel.compute_with(
                device,
                "li_interp_timed",
                "main",
                &[("DIAGNOSTICS", 0.0)],
            ),
            interp_kernel,
            params: StridedUniforms::new(device, "li::params", 4),
            views: views_kernel.compute(device, "li_views", "main"),
            views_kernel,
            view_params: uniform_buffer::<GpuLiViewParams>(device, "li_views::params"),
            stats: CounterReadback::new(
                device,
                "li::stats_readback",
                (STATS_WORDS * 4) as u64,
                LiStats::from_words,
            ),
        })
    }

    /// Records every pass of a frame (module doc) over the frame's tree, scene and G-buffer
    /// into `cx.gi_accum`, `lc` the lightcut kernel's parameters for the records and the
    /// fallback (its `steps` per dispatch).
    pub fn record(
        &mut self,
        cx: &mut FrameCx<'_>,
        encoder: &mut wgpu::CommandEncoder,
        p: GpuLiParams,
        lc: GpuLcParams,
        seed: u32,
        b: &LiBuffers,
    ) {
        let (diagnostics, device, queue) = (cx.diagnostics, cx.device, cx.queue);
        let targets = cx.targets;
        let f = &FrameInputs {
            tree: cx.tree,
            scene: cx.scene,
            gbuffer: &targets.gbuffer,
            camera: cx.camera,
            accum: cx.gi_accum,
        };
        // Uniforms: 0 the records' and selection's; 1.. the walk's dispatches.
        let walks = walk_dispatches(p.max_cut, f.tree.levels(), p.steps);
        let n = 1 + walks;
        let all: Vec<GpuLiParams> = (0..n)
            .map(|i| {
                if i == 0 {
                    p
                } else {
                    GpuLiParams {
                        first: (i == 1) as u32,
                        last: (i == walks) as u32,
                        ..p
                    }
                }
            })
            .collect();
        self.params.write(device, queue, &all);

        let build = BuildRun {
            name: "li_build",
            seed,
            tree: f.tree,
            cones: &b.cones,
            reps: &b.reps,
        };
        self.build.record(device, queue, encoder, cx.timer, build);

        self.record_records(device, encoder, cx.timer, &p, f, b);

        if diagnostics {
            encoder.clear_buffer(&b.stats, 0, None);
            encoder.clear_buffer(&b.trace, 0, None);
        }
        let rb = cut_bindings(f, b, &b.records);
        let run = CutRun {
            name: "li_record_cuts",
            params: GpuLcParams {
                trace_pixel: u32::MAX,
                accumulate: 0,
                ..lc
            },
            items: b.capacity,
            slice: b.record_slice,
            diagnostics,
        };
        self.record_cuts
            .record(device, queue, encoder, cx.timer, run, &rb);

        self.record_select(device, encoder, cx.timer, &p, f, b);

        // The interpolation from the selected records, one dispatch per walk uniform.
        let ibind = self.interp_bind(device, f, b);
        encoder.push_debug_group("li_interp");
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("li_interp"),
                timestamp_writes: cx.timer.compute_pass("li_interp"),
            });
            pass.set_pipeline(if diagnostics {
                &self.interp
            } else {
                &self.interp_timed
            });
            let (gx, gy) = groups_1d_as_2d((p.width * p.height).div_ceil(WG_1D));
            for i in 1..n {
                pass.set_bind_group(0, &ibind, &[StridedUniforms::<GpuLiParams>::offset(i)]);
                pass.dispatch_workgroups(gx, gy, 1);
            }
        }
        encoder.pop_debug_group();

        let fb = cut_bindings(f, b, &b.sel);
        let run = CutRun {
            name: "li_fallback",
            params: GpuLcParams {
                trace_pixel: u32::MAX,
                ..lc
            },
            items: p.width * p.height,
            slice: b.fallback_slice,
            diagnostics,
        };
        self.fallback.record(device, queue, encoder, cx.timer, run, &fb);
        if diagnostics {
            self.stats
                .record(encoder, &[(&b.stats, 0, 0, 96), (&b.rec_meta, 0, 96, 32)]);
        }
    }

    /// Draws one of the diagnostic views (`p.mode`) into `cx.dst`.
    pub fn record_view(
        &self,
        cx: &mut ViewCx<'_>,
        encoder: &mut wgpu::CommandEncoder,
        p: GpuLiViewParams,
        b: &LiBuffers,
    ) {
        let final_image = &cx.targets.lighting.final_view;
        let gb_position = &cx.targets.gbuffer.position_view;
        let dst = cx.dst;
        cx.queue
            .write_buffer(&self.view_params, 0, bytemuck::bytes_of(&p));
        let bind = self.views_kernel.bind(
            cx.device,
            0,
            &[
                ("vp", buf(&self.view_params)),
                ("final_image", tex(final_image)),
                ("gb_position", tex(gb_position)),
                ("diag", buf(&b.diag)),
                ("sel", buf(&b.sel)),
                ("radius", buf(&b.radius)),
                ("tile_count", buf(&b.tile_count)),
                ("tile_offset", buf(&b.tile_offset)),
                ("records", buf(&b.records)),
                ("rec_meta", buf(&b.rec_meta)),
                ("dst", tex(dst)),
            ],
        );
        run_compute(
            encoder,
            cx.timer,
            "li_views",
            &self.views,
            &bind,
            groups_image(b.size.0, b.size.1),
        );
    }
}

impl LiPass {
    /// The records: each pixel's record radius, the records placed per tile, then compacted.
    fn record_records(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        p: &GpuLiParams,
        f: &FrameInputs<'_>,
        b: &LiBuffers,
    ) {
        let g = f.gbuffer;
        let rbind = self.records_kernel.bind(
            device,
            0,
            &[
                ("lp", self.params.binding()),
                ("gb_position", tex(&g.position_view)),
                ("gb_normal", tex(&g.normal_view)),
                ("camera", buf(f.camera)),
                ("bvh_nodes", buf(&f.scene.bvh_nodes)),
                ("bvh_triangles", buf(&f.scene.bvh_triangles)),
                ("radius", buf(&b.radius)),
                ("tile_count", buf(&b.tile_count)),
                ("tile_recs", buf(&b.tile_recs)),
                ("tile_offset", buf(&b.tile_offset)),
                ("records", buf(&b.records)),
                ("rec_meta", buf(&b.rec_meta)),
            ],
        );
        let tiles = b.tiles.0 * b.tiles.1;
        for (name, pipe, groups) in [
            ("li_radius", &self.radius, groups_image(p.width, p.height)),
            ("li_place", &self.place, {
                let (gx, gy) = groups_1d_as_2d(tiles);
                (gx, gy, 1)
            }),
            ("li_compact", &self.compact, (1, 1, 1)),
        ] {
            encoder.push_debug_group(name);
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(name),
                    timestamp_writes: timer.compute_pass(name),
                });
                pass.set_pipeline(pipe);
                pass.set_bind_group(0, &rbind, &[0]);
                pass.dispatch_workgroups(groups.0, groups.1, groups.2);
            }
            encoder.pop_debug_group();
        }
    }

    /// The selection: each pixel's records to interpolate from.
    fn record_select(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        p: &GpuLiParams,
        f: &FrameInputs<'_>,
        b: &LiBuffers,
    ) {
        let g = f.gbuffer;
        let sbind = self.select_kernel.bind(
            device,
            0,
            &[
                ("lp", self.params.binding()),
                ("gb_position", tex(&g.position_view)),
                ("gb_normal", tex(&g.normal_view)),
                ("radius", buf(&b.radius)),
                ("tile_count", buf(&b.tile_count)),
                ("tile_offset", buf(&b.tile_offset)),
                ("records", buf(&b.records)),
                ("rec_meta", buf(&b.rec_meta)),
                ("sel", buf(&b.sel)),
            ],
        );
        encoder.push_debug_group("li_select");
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("li_select"),
                timestamp_writes: timer.compute_pass("li_select"),
            });
            pass.set_pipeline(&self.select);
            pass.set_bind_group(0, &sbind, &[0]);
            let (x, y, z) = groups_image(p.width, p.height);
            pass.dispatch_workgroups(x, y, z);
        }
        encoder.pop_debug_group();
    }

    /// The interpolation's bind group.
    fn interp_bind(&self, device: &wgpu::Device, f: &FrameInputs<'_>, b: &LiBuffers) -> wgpu::BindGroup {
        let g = f.gbuffer;
        self.interp_kernel.bind(
            device,
            0,
            &[
                ("lp", self.params.binding()),
                ("gb_position", tex(&g.position_view)),
                ("gb_normal", tex(&g.normal_view)),
                ("gb_albedo", tex(&g.albedo_view)),
                ("rec_meta", buf(&b.rec_meta)),
                ("record_cuts", buf(&b.record_cuts)),
                ("sel", buf(&b.sel)),
                ("tree", buf(&f.tree.nodes)),
                ("sorted_vpls", buf(&f.tree.sorted_vpls)),
                ("reps", buf(&b.reps)),
                ("bvh_nodes", buf(&f.scene.bvh_nodes)),
                ("bvh_triangles", buf(&f.scene.bvh_triangles)),
                ("accum", buf(f.accum)),
                ("diag", buf(&b.diag)),
                ("stats", buf(&b.stats)),
                ("trace", buf(&b.trace)),
                ("state", buf(&b.walk_state)),
            ],
        )
    }
}

/// The lightcut kernel's bindings of a frame, `lanes` its per-lane work list.
fn cut_bindings<'a>(f: &FrameInputs<'a>, b: &'a LiBuffers, lanes: &'a wgpu::Buffer) -> CutBindings<'a> {
    CutBindings {
        tree: f.tree,
        scene: f.scene,
        gbuffer: f.gbuffer,
        cones: &b.cones,
        reps: &b.reps,
        accum: f.accum,
        diag: &b.diag,
        stats: &b.stats,
        trace: &b.trace,
        scratch: &b.scratch,
        state: &b.lc_state,
        lanes,
        record_cuts: &b.record_cuts,
        rec_meta: &b.rec_meta,
    }
}

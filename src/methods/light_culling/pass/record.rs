//! [`LcullPass`]: its kernels and the passes a frame records (ranges, lists, shading, the tree
//! variant, the ISM companion, views).

use super::*;
use crate::methods::{FrameCx, ViewCx};

impl LcullPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let ranges_kernel = Kernel::new(
            device,
            "methods/light_culling/lcull_ranges.wgsl",
            &["main"],
            KernelOptions::default(),
        )?;
        let tiles_kernel = Kernel::new(
            device,
            "methods/light_culling/lcull_tiles.wgsl",
            &["main"],
            KernelOptions::default(),
        )?;
        let shade_kernel = Kernel::new(
            device,
            "methods/light_culling/lcull_shade.wgsl",
            &["shade_main"],
            KernelOptions::default(),
        )?;
        let views_kernel = Kernel::new(
            device,
            "methods/light_culling/lcull_views.wgsl",
            &["main"],
            KernelOptions::default(),
        )?;
        let tree_kernel = Kernel::new(
            device,
            "methods/light_culling/lcull_tree.wgsl",
            &["leaves_main", "traverse_main", "shade_main"],
            KernelOptions::default(),
        )?;
        let timed = &[("DIAGNOSTICS", 0.0)];
        Ok(Self {
            params: uniform_buffer::<GpuLcullParams>(device, "lcull::params"),
            companion_params: uniform_buffer::<GpuLcullParams>(device, "lcull::companion_params"),
            ranges: ranges_kernel.compute(device, "lcull_ranges", "main"),
            ranges_kernel,
            tiles: tiles_kernel.compute(device, "lcull_tiles", "main"),
            tiles_timed: tiles_kernel.compute_with(device, "lcull_tiles_timed", "main", timed),
            tiles_kernel,
            shade: shade_kernel.compute(device, "lcull_shade", "shade_main"),
            shade_timed: shade_kernel.compute_with(device, "lcull_shade_timed", "shade_main", timed),
            filter: InterleaveFilter::new(device)?,
            filter_params: FilterUniform::new(device, "lcull::filter_params"),
            companion_filter_params: FilterUniform::new(device, "lcull::companion_filter_params"),
            shade_kernel,
            tree_leaves: tree_kernel.compute(device, "lcull_tree_leaves", "leaves_main"),
            tree_traverse: tree_kernel.compute(device, "lcull_tree_traverse", "traverse_main"),
            tree_traverse_timed: tree_kernel.compute_with(
                device,
                "lcull_tree_traverse_timed",
                "traverse_main",
                timed,
            ),
            tree_shade: tree_kernel.compute(device, "lcull_tree_shade", "shade_main"),
            tree_shade_timed: tree_kernel.compute_with(device, "lcull_tree_shade_timed", "shade_main", timed),
            tree_kernel,
            views: views_kernel.compute(device, "lcull_views", "main"),
            views_kernel,
            view_params: uniform_buffer::<GpuLcullViewParams>(device, "lcull_views::params"),
            stats: CounterReadback::new(
                device,
                "lcull::stats_readback",
                (STATS_WORDS * 4) as u64,
                LcullStats::from_words,
            ),
            ism: IsmPass::new(device)?,
            ism_params: uniform_buffer::<GpuIsmParams>(device, "lcull::ism_params"),
            ism_dummy: [
                storage_buffer(device, "lcull::ism_dummy_depth", 16),
                storage_buffer(device, "lcull::ism_dummy_lights", 32),
            ],
        })
    }

    /// The maps' depth and lights buffers to bind (dummies without maps); writes the lookups'
    /// parameters.
    pub(super) fn ism_bindings<'b>(
        &'b self,
        queue: &wgpu::Queue,
        ism: Option<&'b IsmFrame<'b>>,
    ) -> (&'b wgpu::Buffer, &'b wgpu::Buffer) {
        match ism {
            Some(m) => {
                let p = GpuIsmParams::new(m.targets, m.settings, m.maps, m.points.count);
                queue.write_buffer(&self.ism_params, 0, bytemuck::bytes_of(&p));
                (&m.targets.depth, &m.targets.lights)
            }
            None => (&self.ism_dummy[0], &self.ism_dummy[1]),
        }
    }

    /// Records the frame's passes (module doc) with `frame`'s culling and filter parameters.
    /// `companion`: the other variant for the difference view, into `f.accum` (its own
    /// accumulation), without diagnostics and with its own parameters and timer names;
    /// recorded before the method's own run, which then leaves its lists and counters for
    /// the views.
    pub fn record(
        &mut self,
        cx: &mut FrameCx<'_>,
        encoder: &mut wgpu::CommandEncoder,
        companion: bool,
        frame: LcullFrameParams,
        f: &FrameInputs<'_>,
        b: &LcullBuffers,
    ) {
        let (p, fp, ism) = (frame.cull, frame.filter, f.ism.as_ref());
        let (device, queue) = (cx.device, cx.queue);
        let diagnostics = cx.diagnostics && !companion;
        let (params, filter_params, names) = if companion {
            (
                &self.companion_params,
                &self.companion_filter_params,
                COMPANION_PASSES,
            )
        } else {
            (&self.params, &self.filter_params, OWN_PASSES)
        };
        queue.write_buffer(params, 0, bytemuck::bytes_of(&p));
        let g = f.gbuffer;
        let (ism_depth, ism_lights) = self.ism_bindings(queue, ism);
        let rbind = self.ranges_kernel.bind(
            device,
            0,
            &[
                ("params", buf(params)),
                ("vpls", buf(f.vpls)),
                ("lights", buf(&b.lights)),
                ("ism_lights", buf(ism_lights)),
            ],
        );
        let (gx, gy) = groups_1d_as_2d(p.count.div_ceil(WG_1D).max(1));
        run_compute(encoder, cx.timer, names[0], &self.ranges, &rbind, (gx, gy, 1));
        let sbind = self.shade_bind_group(device, params, f, b, ism_depth);
        if let Some(m) = ism {
            let b = IsmBuild {
                name: names[4],
                settings: m.settings,
                points: m.points,
                targets: m.targets,
            };
            self.ism.record_maps(device, queue, encoder, cx.timer, &b, m.maps);
        }

        if diagnostics {
            encoder.clear_buffer(&b.stats, 0, None);
        }
        let tbind = self.tiles_kernel.bind(
            device,
            0,
            &[
                ("params", buf(params)),
                ("camera", buf(f.camera)),
                ("gb_position", tex(&g.position_view)),
                ("lights", buf(&b.lights)),
                ("tile_count", buf(&b.tile_count)),
                ("tile_lists", buf(&b.tile_lists)),
                ("stats", buf(&b.stats)),
            ],
        );
        let (tx, ty) = groups_1d_as_2d(p.tiles);
        let tiles = if diagnostics {
            &self.tiles
        } else {
            &self.tiles_timed
        };
        run_compute(encoder, cx.timer, names[1], tiles, &tbind, (tx, ty, 1));

        let shade = if diagnostics {
            &self.shade
        } else {
            &self.shade_timed
        };
        let groups = groups_image(p.width, p.height);
        run_compute(encoder, cx.timer, names[2], shade, &sbind, groups);
        self.filter.record(
            device,
            queue,
            encoder,
            cx.timer,
            FilterDispatch {
                name: names[3],
                uniform: filter_params,
                params: fp,
            },
            &f.filter_inputs(b),
        );
        if diagnostics {
            let bytes = (STATS_WORDS * 4) as u64;
            self.stats.record(encoder, &[(&b.stats, 0, 0, bytes)]);
        }
    }

    /// The bind group of `lcull_shade.wgsl` with `params`.
    pub(super) fn shade_bind_group(
        &self,
        device: &wgpu::Device,
        params: &wgpu::Buffer,
        f: &FrameInputs<'_>,
        b: &LcullBuffers,
        ism_depth: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        let g = f.gbuffer;
        self.shade_kernel.bind(
            device,
            0,
            &[
                ("params", buf(params)),
                ("gb_position", tex(&g.position_view)),
                ("gb_normal", tex(&g.normal_view)),
                ("bvh_nodes", buf(&f.scene.bvh_nodes)),
                ("bvh_triangles", buf(&f.scene.bvh_triangles)),
                ("vpls", buf(f.vpls)),
                ("lights", buf(&b.lights)),
                ("tile_count", buf(&b.tile_count)),
                ("tile_lists", buf(&b.tile_lists)),
                ("raw", buf(&b.raw)),
                ("diag", buf(&b.diag)),
                ("stats", buf(&b.stats)),
                ("ism", buf(&self.ism_params)),
                ("ism_depth", buf(ism_depth)),
                ("gb_albedo", tex(&g.albedo_view)),
            ],
        )
    }

    /// Records the tree variant's frame (section 5; `lcull_tree.wgsl`): leaves and node
    /// bounds, the per-pixel traversal, the one-ray shading, then the shared filter
    /// (`frame.filter` with the tree's filter radius) over the frame's light tree.
    pub fn record_tree(
        &mut self,
        cx: &mut FrameCx<'_>,
        encoder: &mut wgpu::CommandEncoder,
        frame: LcullFrameParams,
        f: &FrameInputs<'_>,
        b: &LcullBuffers,
        t: &TreeCullBuffers,
    ) {
        let (p, fp, ism) = (frame.cull, frame.filter, f.ism.as_ref());
        let (diagnostics, device, queue) = (cx.diagnostics, cx.device, cx.queue);
        let light_tree = cx.tree;
        let tree = TreeInputs {
            nodes: &light_tree.nodes,
            sorted_vpls: &light_tree.sorted_vpls,
        };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let (ism_depth, ism_lights) = self.ism_bindings(queue, ism);
        let g = f.gbuffer;
        encoder.clear_buffer(&t.max_range, 0, None);
        if diagnostics {
            encoder.clear_buffer(&b.stats, 0, None);
        }
        let bind = self.tree_kernel.bind(
            device,
            0,
            &[
                ("params", buf(&self.params)),
                ("gb_position", tex(&g.position_view)),
                ("gb_normal", tex(&g.normal_view)),
                ("bvh_nodes", buf(&f.scene.bvh_nodes)),
                ("bvh_triangles", buf(&f.scene.bvh_triangles)),
                ("vpls", buf(tree.sorted_vpls)),
                ("nodes", buf(tree.nodes)),
                ("lights", buf(&t.lights)),
                ("max_range", buf(&t.max_range)),
                ("tree_list", buf(&t.list)),
                ("tree_m", buf(&t.m)),
                ("raw", buf(&b.raw)),
                ("diag", buf(&b.diag)),
                ("stats", buf(&b.stats)),
                ("ism", buf(&self.ism_params)),
                ("ism_depth", buf(ism_depth)),
                ("ism_lights", buf(ism_lights)),
                ("gb_albedo", tex(&g.albedo_view)),
            ],
        );
        let (gx, gy) = groups_1d_as_2d(p.leaves.div_ceil(WG_1D).max(1));
        run_compute(
            encoder,
            cx.timer,
            "lcull_tree_leaves",
            &self.tree_leaves,
            &bind,
            (gx, gy, 1),
        );
        if let Some(m) = ism {
            let b = IsmBuild {
                name: "lcull_ism",
                settings: m.settings,
                points: m.points,
                targets: m.targets,
            };
            self.ism.record_maps(device, queue, encoder, cx.timer, &b, m.maps);
        }
        let groups = groups_image(p.width, p.height);
        let (traverse, shade) = if diagnostics {
            (&self.tree_traverse, &self.tree_shade)
        } else {
            (&self.tree_traverse_timed, &self.tree_shade_timed)
        };
        run_compute(encoder, cx.timer, "lcull_tree_traverse", traverse, &bind, groups);
        run_compute(encoder, cx.timer, "lcull_tree_shade", shade, &bind, groups);
        self.filter.record(
            device,
            queue,
            encoder,
            cx.timer,
            FilterDispatch {
                name: "lcull_filter",
                uniform: &self.filter_params,
                params: fp,
            },
            &f.filter_inputs(b),
        );
        if diagnostics {
            let bytes = (STATS_WORDS * 4) as u64;
            self.stats.record(encoder, &[(&b.stats, 0, 0, bytes)]);
        }
    }

    /// Draws one of the diagnostic views (`p.mode`) into `cx.dst`.
    pub fn record_view(
        &self,
        cx: &mut ViewCx<'_>,
        encoder: &mut wgpu::CommandEncoder,
        p: GpuLcullViewParams,
        own_accum: &wgpu::Buffer,
        b: &LcullBuffers,
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
                ("dst", tex(dst)),
                ("own_accum", buf(own_accum)),
                (
                    "companion_accum",
                    buf(b.companion.as_ref().map_or(&b.dummy[0], |c| &c.accum)),
                ),
                (
                    "difference",
                    buf(b.companion.as_ref().map_or(&b.dummy[1], |c| &c.difference)),
                ),
            ],
        );
        run_compute(
            encoder,
            cx.timer,
            "lcull_views",
            &self.views,
            &bind,
            groups_image(b.size.0, b.size.1),
        );
    }
}

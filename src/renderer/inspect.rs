//! What the workbench reads back from the renderer between frames: pixel values, the pixel
//! story, cuts, the tree, the VPLs, progress, timings and whole buffers (blocking readbacks;
//! none of them is recorded into a frame).

use super::*;

impl Renderer {
    /// Every buffer's value at frame pixel (x, y) (final, direct, GI, G-buffer; the tree
    /// samplers' diagnostics and the comparison ground truth when present), as
    /// (name, RGBA) rows, read with one submission.
    pub fn read_pixel(&self, x: u32, y: u32) -> Result<Vec<(&'static str, [f32; 4])>, GpuError> {
        let t = &self.targets;
        let (x, y) = (x.min(t.size.0 - 1), y.min(t.size.1 - 1));
        let mut names = vec![
            "final",
            "direct",
            "GI",
            "position (w: material + 1)",
            "normal",
            "albedo",
        ];
        let mut texels = vec![
            (&t.lighting.final_, x, y),
            (&t.lighting.direct, x, y),
            (&t.lighting.indirect, x, y),
            (&t.gbuffer.position, x, y),
            (&t.gbuffer.normal, x, y),
            (&t.gbuffer.albedo, x, y),
        ];
        if let Some(c) = self.compare.as_ref().filter(|c| c.targets_size == t.size) {
            names.push("ground truth GI");
            texels.push((&c.targets.indirect, x, y));
        }
        let values = readback::read_texels(&self.ctx, &texels)?;
        let mut rows: Vec<(&'static str, [f32; 4])> = names.into_iter().zip(values).collect();
        if let Some(m) = self.method_instance(self.settings.gi.method) {
            rows.extend(m.pixel_rows(&self.ctx, x, y, t.size)?);
        }
        Ok(rows)
    }

    /// Method views that will be drawn after the coming frames although the frames show
    /// another (`render` writes every view of its method after its image frames): a view
    /// needing work in the frame itself gets it (light culling's clamped-vs-stochastic
    /// difference accumulates its companion image).
    pub fn keep_views(&mut self, views: Vec<methods::MethodView>) {
        self.kept_views = views;
    }

    /// Records the tree samples of frame pixel (x, y) from the next frame on (None: stop).
    pub fn set_trace_pixel(&mut self, pixel: Option<(u32, u32)>) {
        let pixel = pixel.filter(|&(x, y)| x < 8192 && y < 8192);
        if pixel != self.trace_pixel {
            // Its story from the next frame, not the next scheduled diagnostic one.
            self.diagnostic_requested = true;
        }
        self.trace_pixel = pixel;
    }

    /// The pinned pixel's story in the last (diagnostic) frame as the method tells it (None
    /// without a pinned pixel or when it tells none); a cut story carries the radix tree's
    /// links when its cuts are on it.
    pub fn read_story(&self) -> Result<Option<methods::Story>, GpuError> {
        if self.trace_pixel.is_none() {
            return Ok(None);
        }
        let Some(m) = self.method_instance(self.settings.gi.method) else {
            return Ok(None);
        };
        let mut story = m.read_story(&self.ctx)?;
        if let Some(methods::Story::Cuts(s)) = story.as_mut() {
            s.links = self.read_tree_links()?;
        }
        Ok(story)
    }

    /// What the traced pixel's samples did in the last tree-sampling frame (None: no trace,
    /// the pixel saw no geometry, or the method tells no sample story).
    pub fn read_pixel_trace(&self) -> Result<Option<PixelTrace>, GpuError> {
        Ok(match self.read_story()? {
            Some(methods::Story::Samples(t)) => Some(t),
            _ => None,
        })
    }

    /// The pinned pixel's cut story (cut-based methods; None without a pinned pixel).
    pub fn read_cut_story(&self) -> Result<Option<crate::base::story::CutStory>, GpuError> {
        Ok(match self.read_story()? {
            Some(methods::Story::Cuts(s)) => Some(s),
            _ => None,
        })
    }

    /// The method's overlay for the pinned pixel (None without a pinned pixel, without
    /// geometry there, or when the method draws none).
    pub fn read_method_overlay(&self) -> Result<Option<methods::overlay::MethodOverlay>, GpuError> {
        let Some((x, y)) = self.trace_pixel else {
            return Ok(None);
        };
        let t = &self.targets;
        if x >= t.size.0 || y >= t.size.1 {
            return Ok(None);
        }
        let g = readback::read_texels(&self.ctx, &[(&t.gbuffer.position, x, y)])?;
        let Some(g) = g.first().filter(|g| g[3] != 0.0) else {
            return Ok(None);
        };
        match self.method_instance(self.settings.gi.method) {
            Some(m) => m.read_overlay(&self.ctx, (x, y), glam::Vec3::new(g[0], g[1], g[2])),
            None => Ok(None),
        }
    }

    /// Outlines a block in the cut views (None: no outline).
    pub fn select_block(&mut self, block: Option<u32>) {
        self.selected_block = block;
    }

    /// The block under `texel` of the method view `view` and its cut (`Method::pick_block`),
    /// outlined in the cut views from now on; None where the view shows no blocks.
    pub fn pick_block(
        &mut self,
        view: MethodView,
        texel: (u32, u32),
    ) -> Result<Option<crate::base::story::BlockCut>, GpuError> {
        let Some((_, owner)) = view.find() else {
            return Ok(None);
        };
        let Some(m) = self.method_instance(owner) else {
            return Ok(None);
        };
        let picked = m.pick_block(&self.ctx, view, texel)?;
        if let Some(b) = &picked {
            self.selected_block = Some(b.index);
        }
        Ok(picked)
    }

    /// Frames the current method averaged in its image (None: it does not average).
    pub fn frames_averaged(&self) -> Option<u32> {
        self.method_instance(self.settings.gi.method)?.frames_averaged()
    }

    /// Frames summed in the current method's accumulation (0 before the first, or when it
    /// does not average).
    pub fn sampling_frames(&self) -> u32 {
        self.method_instance(self.settings.gi.method)
            .and_then(|m| m.frames_averaged())
            .unwrap_or(0)
    }

    /// The current method's traversal counters of the last diagnostic frame, waiting for
    /// them (`Method::traversal_stats`; None for a method that keeps none).
    pub fn sampling_stats_blocking(&mut self) -> Option<TraversalStats> {
        let _ = self.ctx.device.poll(wgpu::PollType::wait_indefinitely());
        self.sampling_stats()
    }

    /// The current method's traversal counters of a recent frame (non-blocking; None before
    /// the first).
    pub fn sampling_stats(&mut self) -> Option<TraversalStats> {
        let module = self.settings.gi.method.info().module.name;
        let (_, m) = self.methods.iter_mut().find(|(n, _)| *n == module)?;
        m.traversal_stats()
    }

    /// The current method's per-pixel traversal steps and fallback flags of the last
    /// diagnostic frame (`Method::read_traversal_pixels`; None for a method without them).
    pub fn read_traversal_pixels(&self) -> Result<Option<crate::base::traversal::TraversalPixels>, GpuError> {
        match self.method_instance(self.settings.gi.method) {
            Some(m) => m.read_traversal_pixels(&self.ctx),
            None => Ok(None),
        }
    }

    /// One line of the current method's statistics (non-blocking; None before any).
    pub fn method_status(&mut self) -> Option<String> {
        let module = self.settings.gi.method.info().module.name;
        self.methods
            .iter_mut()
            .find(|(n, _)| *n == module)
            .and_then(|(_, m)| m.status())
    }

    /// The current method's named statistics of the last diagnostic frame (waits for the GPU).
    pub fn method_stats_blocking(&mut self) -> Vec<(&'static str, f64)> {
        let _ = self.ctx.device.poll(wgpu::PollType::wait_indefinitely());
        let module = self.settings.gi.method.info().module.name;
        self.methods
            .iter_mut()
            .find(|(n, _)| *n == module)
            .map(|(_, m)| m.stats())
            .unwrap_or_default()
    }

    /// The GPU instance of `method`'s module.
    pub(super) fn method_instance(&self, method: MethodId) -> Option<&dyn Method> {
        let module = method.info().module.name;
        self.methods
            .iter()
            .find(|(n, _)| *n == module)
            .map(|(_, m)| m.as_ref())
    }

    /// The index the next frame records with (`FrameCx::frame_index`: frames rendered so far).
    pub fn frame_index(&self) -> u64 {
        self.frames
    }

    /// Numbers the next frame 0 again: its random numbers (keyed by the frame index) become
    /// those of a fresh renderer, whatever ran before (the harness restarts every
    /// configuration, so a figure's numbers do not depend on the figures before it).
    pub fn restart_frame_index(&mut self) {
        self.frames = 0;
    }

    /// Numbers the next frame `index` (a capture's first image frame, to render it again).
    pub fn set_frame_index(&mut self, index: u64) {
        self.frames = index;
    }

    /// The GPU instance of the method module whose type is `T` (tests and tools that read a
    /// method's own buffers, e.g. `methods::lightcuts::Lightcuts`).
    pub fn method_module<T: Method>(&self) -> Option<&T> {
        self.methods
            .iter()
            .find_map(|(_, m)| (m.as_ref() as &dyn std::any::Any).downcast_ref::<T>())
    }

    /// `method_module`, mutable.
    pub fn method_module_mut<T: Method>(&mut self) -> Option<&mut T> {
        self.methods
            .iter_mut()
            .find_map(|(_, m)| (m.as_mut() as &mut dyn std::any::Any).downcast_mut::<T>())
    }

    /// The linear data behind a method's view (None: nothing rendered yet, or the current
    /// method does not draw it).
    pub(crate) fn read_method_view(&self, view: MethodView) -> Result<Option<ImageF32>, GpuError> {
        let current = self.settings.gi.method;
        if !current.info().views.iter().any(|v| v.name == view.name()) {
            return Ok(None);
        }
        match self.method_instance(current) {
            Some(m) => m.read_view(&self.ctx, view),
            None => Ok(None),
        }
    }

    /// The colour scale of a method's view (None: no legend).
    /// The colour scale of a temporal-stage view (None for its radiance views).
    pub fn temporal_legend(&self, view: TemporalView) -> Option<crate::base::colormap::Legend> {
        self.temporal.legend(view)
    }

    /// The temporal stage's last frame (None when it did not run) and its buffers (tests,
    /// the harness's raw-vs-filtered metrics).
    pub fn temporal(&self) -> &passes::temporal::TemporalPass {
        &self.temporal
    }

    /// Forgets the temporal history (the next frame starts without one).
    pub fn reset_temporal(&mut self) {
        self.temporal.invalidate();
    }

    /// The method's own estimate of the last frame the temporal stage ran (radiance, before
    /// the stage): None when it has not run at the current size.
    pub fn read_temporal_raw(&self) -> Result<Option<ImageF32>, GpuError> {
        match (self.temporal.last_frame(), self.temporal.buffers()) {
            (Some(_), Some(b)) if b.size == self.targets.size => {
                readback::read_vec4_image(&self.ctx, &b.raw, b.size)
            }
            _ => Ok(None),
        }
    }

    pub fn method_legend(&self, view: MethodView) -> Option<crate::base::colormap::Legend> {
        let (_, owner) = view.find()?;
        self.method_instance(owner)?.legend(view, self.tree.levels())
    }

    /// Progress of the progressive GI method: VPLs done (ground truth) or samples per pixel
    /// (reference); None when GI is off.
    pub fn gi_progress(&self) -> Option<GiProgress> {
        self.method_instance(self.settings.gi.method)?.progress()
    }

    /// The VPLs of the last frame (count and per-light ranges).
    pub fn vpl_frame(&self) -> &VplFrame {
        &self.vpl_frame
    }

    /// The light-path pass (`vpl.bounces > 1`): its last starts.
    pub fn light_paths(&self) -> &passes::light_paths::LightPathPass {
        &self.light_paths
    }

    pub fn vpl_buffers(&self) -> &VplBuffers {
        &self.vpl_buffers
    }

    /// Reads a storage buffer of f32 back (pyramids, importance).
    /// The last frame's sorted (key, index) pairs and tree.
    pub fn tree_buffers(&self) -> (&SortBuffers, &TreeBuffers) {
        (&self.sort_buffers, &self.tree)
    }

    /// Reads the last frame's tree back: nodes decoded (2 x leaves, node 0 unused) and the
    /// usable bits.
    pub fn read_tree(&self) -> Result<(Vec<SstNode>, Vec<u32>), GpuError> {
        let nodes = passes::sst_build::read_nodes(&self.ctx, &self.tree)?;
        let flags = passes::sst_build::read_flags(&self.ctx, &self.tree)?;
        Ok((nodes.iter().map(SstNode::decode).collect(), flags))
    }

    /// The radix tree's links (`base::sst_node::Topology::radix`); empty for the perfect tree.
    pub fn read_tree_links(&self) -> Result<Vec<[u32; 4]>, GpuError> {
        match self.tree.kind {
            crate::base::sst_node::TreeKind::Lbvh => passes::lbvh::read_links(&self.ctx, &self.tree),
            crate::base::sst_node::TreeKind::Perfect => Ok(Vec::new()),
        }
    }

    /// Nodes `ids` of the frame's tree (one submission; ids past the tree read as empty)
    /// and the usable flags, without reading the whole tree back.
    pub fn read_tree_nodes(&self, ids: &[u32]) -> Result<(Vec<SstNode>, Vec<u32>), GpuError> {
        const NODE: u64 = std::mem::size_of::<gpu_data::GpuSstNode>() as u64;
        let count = self.tree.nodes.size() / NODE;
        let inside: Vec<u32> = ids.iter().copied().filter(|&i| (i as u64) < count).collect();
        let ranges: Vec<(u64, u64)> = inside.iter().map(|&i| (i as u64 * NODE, NODE)).collect();
        let bytes = readback::read_buffer_ranges(&self.ctx, &self.tree.nodes, &ranges)?;
        let mut decoded = bytes
            .iter()
            .map(|b| SstNode::decode(&bytemuck::pod_read_unaligned(b)));
        let nodes = ids
            .iter()
            .map(|&i| match (i as u64) < count {
                true => decoded.next().unwrap_or(SstNode::EMPTY),
                false => SstNode::EMPTY,
            })
            .collect();
        let flags = passes::sst_build::read_flags(&self.ctx, &self.tree)?;
        Ok((nodes, flags))
    }

    /// Freezes (or thaws) the VPLs and the light tree: while frozen, frames reuse the last
    /// VPLs, sort and tree (the camera can move around them), and a change of v_min /
    /// sigma_max re-runs only the classify pass.
    pub fn set_freeze_tree(&mut self, freeze: bool) {
        if freeze && self.freeze.is_none() {
            self.freeze = Some((self.settings.tree.v_min, self.settings.tree.sigma_max));
        } else if !freeze {
            self.freeze = None;
        }
    }

    pub fn tree_frozen(&self) -> bool {
        self.freeze.is_some()
    }

    /// Re-runs only the classify pass of the last frame's tree with new thresholds (the
    /// settings are not changed).
    pub fn reclassify(&mut self, v_min: f32, sigma_max: f32) {
        let device = self.ctx.device.clone();
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("sst_classify::encoder"),
        });
        let mut timer = GpuTimer::new(&device, &self.ctx.queue);
        let usable = UsableThresholds { v_min, sigma_max };
        self.sst_build
            .record_classify(&device, &self.ctx.queue, &mut enc, &mut timer, &self.tree, usable);
        self.ctx.queue.submit([enc.finish()]);
    }

    pub fn read_f32_buffer(&self, buffer: &wgpu::Buffer) -> Result<Vec<f32>, GpuError> {
        let bytes = readback::read_storage_buffer(&self.ctx, buffer)?;
        Ok(bytemuck::cast_slice(&bytes).to_vec())
    }

    /// Reads the last frame's VPLs back.
    pub fn read_vpls(&self) -> Result<Vec<GpuVpl>, GpuError> {
        let bytes = readback::read_storage_buffer(&self.ctx, &self.vpl_buffers.vpls)?;
        let all: &[GpuVpl] = bytemuck::cast_slice(&bytes);
        Ok(all[..(self.vpl_frame.count as usize).min(all.len())].to_vec())
    }

    /// Picks up finished readbacks (timings, flux total) without blocking; returns the latest
    /// per-pass GPU timings, or None if not (yet) available.
    /// Blocks until the GPU has finished all submitted work (wall-clock timing of frames).
    pub fn wait_idle(&self) {
        let _ = self.ctx.device.poll(wgpu::PollType::wait_indefinitely());
    }

    pub fn poll_timings(&mut self) -> Option<PassTimings> {
        let t = self.timer.collect(&self.ctx.device).cloned();
        self.take_flux_total();
        t
    }

    /// Waits for the GPU and returns the timings of the last timed frame if they came back
    /// since the previous call (None: no timed frame, or no timestamps on this adapter).
    pub fn wait_new_timings(&mut self) -> Option<PassTimings> {
        let t = self.timer.collect_new_blocking(&self.ctx.device);
        self.take_flux_total();
        t
    }

    pub(super) fn take_flux_total(&mut self) {
        if let Some(bytes) = self.flux_readback.try_take() {
            let tops: &[f32] = bytemuck::cast_slice(&bytes);
            self.flux_total = Some(tops.iter().sum());
        }
    }

    /// Total reflected flux of the RSMs (luminance, W) = the expected total VPL flux, from the
    /// flux pyramids' tops of a recent frame (read back without blocking).
    pub fn flux_total(&self) -> Option<f32> {
        self.flux_total
    }

    pub fn timestamps_supported(&self) -> bool {
        self.timer.supported()
    }

    /// Reads a buffer of the last frame back as linear floats.
    pub fn read(&self, buffer: Buffer) -> Result<ImageF32, GpuError> {
        let t = &self.targets;
        match buffer {
            Buffer::Final => readback::read_texture_f32(&self.ctx, &t.lighting.final_, 0),
            Buffer::Direct => readback::read_texture_f32(&self.ctx, &t.lighting.direct, 0),
            Buffer::Indirect => readback::read_texture_f32(&self.ctx, &t.lighting.indirect, 0),
            Buffer::GroundTruthIndirect => match &self.compare {
                Some(c) => readback::read_texture_f32(&self.ctx, &c.targets.indirect, 0),
                None => Ok(ImageF32 {
                    width: 0,
                    height: 0,
                    pixels: Vec::new(),
                }),
            },
            Buffer::Position => readback::read_texture_f32(&self.ctx, &t.gbuffer.position, 0),
            Buffer::Normal => readback::read_texture_f32(&self.ctx, &t.gbuffer.normal, 0),
            Buffer::Albedo => readback::read_texture_f32(&self.ctx, &t.gbuffer.albedo, 0),
            Buffer::Depth => readback::read_texture_f32(&self.ctx, &t.gbuffer.depth, 0),
            Buffer::ShadowMap(layer) => readback::read_texture_f32(&self.ctx, &t.shadow.texture, layer),
            Buffer::RsmPosition(layer) => readback::read_texture_f32(&self.ctx, &t.shadow.position, layer),
            Buffer::RsmNormal(layer) => readback::read_texture_f32(&self.ctx, &t.shadow.normal, layer),
            Buffer::RsmFlux(layer) => readback::read_texture_f32(&self.ctx, &t.shadow.flux, layer),
        }
    }
}

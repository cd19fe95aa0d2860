//! [`LightCulling`]'s own state between frames: its buffers, seeds, tile grid, ISM targets and
//! the radix-tree variant's record.

use super::*;

impl LightCulling {
    pub fn buffers(&self) -> &LcullBuffers {
        &self.buffers
    }
    /// The tree variant's buffers (None before its first frame).
    pub fn tree_buffers(&self) -> Option<&TreeCullBuffers> {
        self.tree.as_ref()
    }
    /// The frame's xi seed (a new one per frame unless `frame.fixed_seed`).
    pub fn seed(s: &RenderSettings, frame_index: u64) -> u32 {
        if s.frame.fixed_seed {
            s.vpl.seed ^ 0x1b87_3593
        } else {
            (s.vpl.seed ^ 0x1b87_3593) ^ (frame_index as u32).wrapping_mul(0x9e37_79b9)
        }
    }
    /// The tile layout of a frame of `size` under `lc`.
    pub fn grid(lc: &LightCullingSettings, size: (u32, u32)) -> TileGrid {
        TileGrid {
            width: size.0,
            height: size.1,
            tile: lc.tile_size,
            n: lc.interleave.n,
        }
    }
    /// Whether the last frame ran the tree variant.
    pub(super) fn is_tree(&self) -> bool {
        self.state.is_some_and(|(_, m, _)| m == TREE)
    }
    /// Decades of a heat-map view's log scale: the tile list's cap, the tree's VPLs (VPLs in
    /// range) or its nodes (nodes visited).
    pub(super) fn view_decades(&self, view: MethodView) -> u32 {
        let leaves = self.tree.as_ref().map_or(2, |t| t.leaves);
        if view == TREE_IN_RANGE {
            decades(leaves)
        } else if view == TREE_VISITED {
            decades(2 * leaves)
        } else {
            decades(self.settings.max_lights_per_tile)
        }
    }
    /// Frames in the difference view's companion image when it matches the method's own
    /// (same key, the other variant); None otherwise.
    pub fn companion_frames(&self) -> Option<u32> {
        let (k, m, _) = self.state?;
        let (ck, cm, n) = self.companion?;
        (ck == k && cm != m && n > 0).then_some(n)
    }
    /// Counters of a recent diagnostic frame (non-blocking).
    pub fn poll_stats(&mut self) -> Option<LcullStats> {
        self.pass.stats.poll()
    }
    /// The imperfect shadow maps of the last frame that built them (None before), and how
    /// many maps it built.
    pub fn ism_targets(&self) -> Option<(&IsmTargets, u32)> {
        self.ism_targets.as_ref().map(|t| (t, self.ism_maps))
    }

    /// The point cloud and the atlas for `s` on the frame's scene (rebuilt when either
    /// changed).
    pub(super) fn ensure_ism(&mut self, cx: &FrameCx<'_>, s: &IsmSettings<IsmAdaptive>) {
        crate::gpu::passes::ism::ensure_maps(
            cx.device,
            cx.queue,
            cx.scene,
            s,
            ISM_CLOUD_SEED,
            &mut self.ism_points,
            &mut self.ism_targets,
        );
    }

    /// The frame's visibility and maps: (GpuLcullParams::shadow_rays, ism_flags, maps to
    /// build); None (reported) when ISM visibility needs more maps than the atlas holds.
    pub(super) fn plan_ism(
        &mut self,
        cx: &FrameCx<'_>,
        lc: &LightCullingSettings,
        maps: u32,
    ) -> Option<(u32, u32, u32)> {
        let on = lc.uses_ism(cx.settings.gi.shadow_rays);
        let shown = cx.diagnostics && cx.views.contains(&ISM_ATLAS);
        let rays = if on {
            VISIBILITY_ISM
        } else {
            cx.settings.gi.shadow_rays as u32
        };
        // Failures leave no maps behind (the view and the counters say none).
        self.ism_on = false;
        self.ism_maps = 0;
        let tree = cx.method == TREE;
        if on && maps > lc.ism.capacity() {
            let what = if tree {
                format!(
                    "a map per leaf of the light tree ({} VPLs in {maps} leaves)",
                    cx.vpl_frame.count
                )
            } else {
                format!("a map per VPL ({maps})")
            };
            cx.errors.report(format!(
                "light culling: ISM visibility needs {what}, but an atlas of {} with {} x {} \
                 maps holds {} (raise methods.light-culling.ism.atlas, lower ism.tile or the VPL \
                 count)",
                lc.ism.atlas,
                lc.ism.tile,
                lc.ism.tile,
                lc.ism.capacity()
            ));
            return None;
        }
        let need = lc.ism.atlas_bytes();
        let limit = cx.device.limits().max_storage_buffer_binding_size;
        if (on || shown) && need > limit {
            cx.errors.report(format!(
                "light culling: an ISM atlas of {0} x {0} needs a {1} MiB buffer; this device \
                 binds at most {2} MiB (lower methods.light-culling.ism.atlas)",
                lc.ism.atlas,
                need >> 20,
                limit >> 20
            ));
            return None;
        }
        self.ism_on = on;
        if !(on || shown) {
            self.ism_maps = 0;
            return Some((rays, 0, 0));
        }
        self.ensure_ism(cx, &lc.ism);
        self.ism_maps = maps.min(lc.ism.capacity());
        Some((rays, 1 | (lc.ism_range_culling as u32) << 1, self.ism_maps))
    }
}

/// What a frame's culling passes read: the frame's scene, G-buffer, camera and VPLs, the
/// accumulation `accum`, and the frame's imperfect shadow maps (`ism_frame`).
pub(super) fn frame_inputs<'s, 'f: 's>(
    cx: &FrameCx<'f>,
    accum: &'s wgpu::Buffer,
    ism: Option<IsmFrame<'s>>,
) -> FrameInputs<'s> {
    let (scene, targets, camera, vpl_buffers) = (cx.scene, cx.targets, cx.camera, cx.vpl_buffers);
    FrameInputs {
        scene,
        gbuffer: &targets.gbuffer,
        camera,
        vpls: &vpl_buffers.vpls,
        accum,
        ism,
    }
}

impl LightCulling {
    /// The tree variant's frame (section 5): `p` is the tiled frame's parameters.
    pub(super) fn record_tree(
        &mut self,
        cx: &mut FrameCx<'_>,
        enc: &mut wgpu::CommandEncoder,
        p: GpuLcullParams,
        fp: GpuFilterParams,
        frames: u32,
    ) -> f32 {
        let lc = &self.settings;
        let leaves = cx.tree.leaves.max(1);
        let k = lc.reservoir_k;
        if !self.tree.as_ref().is_some_and(|t| t.matches(cx.size, leaves, k)) {
            let need = TreeCullBuffers::list_bytes(cx.size, k);
            let limit = cx.device.limits().max_storage_buffer_binding_size;
            if need > limit {
                cx.errors.report(format!(
                    "light culling (tree): {} x {} pixels x k = {k} list entries need a {} MiB \
                     buffer; this device binds at most {} MiB (lower \
                     methods.light-culling.reservoir_k or the resolution)",
                    cx.size.0,
                    cx.size.1,
                    need >> 20,
                    limit >> 20
                ));
                enc.clear_buffer(cx.gi_accum, 0, None);
                self.state = None;
                return 1.0;
            }
            self.tree = Some(TreeCullBuffers::new(cx.device, cx.size, leaves, k));
        }
        let Some(t) = self.tree.as_ref() else {
            return 0.0;
        };
        let tp = GpuLcullParams {
            n: 1,
            cap: k,
            count: leaves,
            mode: 2,
            leaves,
            ..p
        };
        let fp = GpuFilterParams {
            radius: lc.tree_filter_radius,
            ..fp
        };
        let ism = ism_frame(
            &self.settings.ism,
            &self.ism_points,
            &self.ism_targets,
            self.ism_maps,
            tp.ism_flags & 1 != 0,
        );
        let inputs = frame_inputs(cx, cx.gi_accum, ism);
        let frame = LcullFrameParams { cull: tp, filter: fp };
        self.pass.record_tree(cx, enc, frame, &inputs, &self.buffers, t);
        1.0 / frames as f32
    }
}

impl LightCulling {
    /// Sizes the tiled variant's buffers for `tiles` lists of `cap` entries. False (with the
    /// error reported, the accumulation cleared and the history dropped) when the lists would
    /// exceed the device's binding limit.
    pub(super) fn fit_buffers(
        &mut self,
        cx: &mut FrameCx<'_>,
        enc: &mut wgpu::CommandEncoder,
        tiles: u32,
        cap: u32,
    ) -> bool {
        let vpl_capacity = cx.vpl_buffers.capacity;
        if self.buffers.matches(vpl_capacity, cx.size, tiles, cap) {
            return true;
        }
        let need = LcullBuffers::list_bytes(tiles, cap);
        let limit = cx.device.limits().max_storage_buffer_binding_size;
        if need > limit {
            cx.errors.report(format!(
                "light culling: {tiles} tiles x {cap} list entries need a {} MiB buffer; this \
                 device binds at most {} MiB (lower methods.light-culling.max_lights_per_tile \
                 or raise tile_size)",
                need >> 20,
                limit >> 20
            ));
            enc.clear_buffer(cx.gi_accum, 0, None);
            self.state = None;
            self.companion = None;
            return false;
        }
        self.buffers = LcullBuffers::new(cx.device, vpl_capacity, cx.size, tiles, cap);
        self.companion = None;
        true
    }

    /// The difference view's companion: the other tiled variant with the same parameters
    /// `p` / `fp`, into the companion's own accumulation. False when the companion buffers
    /// are missing.
    pub(super) fn record_companion(
        &mut self,
        cx: &mut FrameCx<'_>,
        enc: &mut wgpu::CommandEncoder,
        p: GpuLcullParams,
        fp: GpuFilterParams,
        ism_flags: u32,
    ) -> bool {
        self.buffers.ensure_companion(cx.device);
        let other = if cx.method == CLAMPED { ID } else { CLAMPED };
        let n = match self.companion {
            Some((k, m, n)) if cx.settings.frame.accumulate && k == cx.key && m == other => n + 1,
            _ => 1,
        };
        self.companion = Some((cx.key, other, n));
        let cp = GpuLcullParams {
            mode: (other == CLAMPED) as u32,
            ..p
        };
        let cfp = GpuFilterParams {
            accumulate: (n > 1) as u32,
            ..fp
        };
        let Some(companion) = self.buffers.companion.as_ref() else {
            return false;
        };
        let ism = ism_frame(
            &self.settings.ism,
            &self.ism_points,
            &self.ism_targets,
            self.ism_maps,
            ism_flags & 1 != 0,
        );
        let inputs = frame_inputs(cx, &companion.accum, ism);
        let frame = LcullFrameParams {
            cull: cp,
            filter: cfp,
        };
        self.pass.record(cx, enc, true, frame, &inputs, &self.buffers);
        true
    }
}

//! Drawing views: a buffer with a view's look (display, visualise, a method's own views, A/B
//! comparisons) into a view texture, the VPL overlay, snapshots for A/B.

use super::*;

impl Renderer {
    /// The frame's VPLs as discs over the view texture.
    pub(super) fn record_vpl_overlay(&mut self, enc: &mut wgpu::CommandEncoder, view: ViewBuffer) {
        let device = self.ctx.device.clone();
        let queue = self.ctx.queue.clone();
        let vb = &self.vpl_buffers;
        let (per_layer, offsets) = passes::vpl_gen::pyramid_layout(vb.res);
        let p = GpuSplatParams {
            count: self.vpl_frame.count,
            space: view.is_rsm_space() as u32,
            radius: self.settings.display.vpl_point_size,
            layer: 0,
            rsm_res: vb.res,
            light_count: self.vpl_frame.ranges.len() as u32,
            per_layer,
            top_offset: *offsets.last().unwrap_or(&0),
            color_mode: (self.settings.display.vpl_color == settings::VplColor::Bounce) as u32,
            _pad: [0; 3],
        };
        let inputs = passes::vpl_splat::SplatInputs {
            camera: &self.camera_buf,
            vpls: &vb.vpls,
            flux_pyramid: &vb.flux_pyramid,
            gb_position: &self.targets.gbuffer.position_view,
            dst: &self.targets.view.view,
        };
        self.vpl_splat
            .record(&device, &queue, enc, &mut self.timer, p, &inputs);
    }

    pub(super) fn record_view(&mut self, enc: &mut wgpu::CommandEncoder, spec: &ViewSpec, camera: &Camera) {
        let view = spec.buffer;
        let look = spec.look;
        let ab = spec.effective_ab();
        let want = self.wanted_view_size(view, ab);
        if self.targets.view.size != want {
            self.view_generation += 1;
            self.targets.view = ViewTarget::new(&self.ctx.device, want, self.view_generation);
        }
        if let Some(ab) = ab {
            self.record_ab_view(enc, ab, &look, want);
        } else if view.is_compare_view() {
            self.record_truth_view(enc, view, &look, want);
        } else if let ViewBuffer::Temporal(tv) = view {
            self.record_temporal_view(enc, tv, &look, want);
        } else if let ViewBuffer::Method(view) = view {
            self.record_method_view(enc, view, &look);
        } else {
            self.record_buffer_view(enc, view, &look, want, camera);
        }
    }

    /// The size of the view texture `view` needs (an RSM's, a pyramid level's enlarged, a
    /// method view's, an A/B's).
    fn wanted_view_size(&self, view: ViewBuffer, ab: Option<AbSpec>) -> (u32, u32) {
        let rsm_res = self.targets.shadow.resolution;
        match view {
            ViewBuffer::ShadowMap
            | ViewBuffer::RsmFlux
            | ViewBuffer::RsmNormal
            | ViewBuffer::RsmPosition
            | ViewBuffer::ImportanceRaw
            | ViewBuffer::ImportanceFiltered => (rsm_res, rsm_res),
            ViewBuffer::PdfPyramid => {
                let r = (rsm_res >> self.settings.display.pyramid_level.min(rsm_res.trailing_zeros())).max(1);
                // Small levels are shown enlarged (nearest) so they stay visible.
                let s = (256 / r).max(1);
                (r * s, r * s)
            }
            ViewBuffer::Method(v) => {
                let size = self.targets.size;
                match v.find().and_then(|(_, m)| self.method_instance(m)) {
                    Some(m) => m.view_size(v, size).unwrap_or((1, 1)),
                    None => (1, 1),
                }
            }
            _ => match ab {
                Some(ab) => {
                    let (w, h) = ab_source(&self.targets, self.compare.as_ref(), &self.snapshots, ab.a)
                        .map_or(self.targets.size, |(_, size)| size);
                    if ab.mode == AbMode::SideBySide {
                        (2 * w, h)
                    } else {
                        (w, h)
                    }
                }
                None => self.targets.size,
            },
        }
    }

    /// An A/B comparison of two images (cleared when one does not exist: no comparison
    /// running, snapshot gone).
    fn record_ab_view(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        ab: AbSpec,
        look: &ViewLook,
        want: (u32, u32),
    ) {
        let (device, queue) = (self.ctx.device.clone(), self.ctx.queue.clone());
        let t = &self.targets;
        let dst = &t.view.view;
        let images = (
            ab_source(&self.targets, self.compare.as_ref(), &self.snapshots, ab.a),
            ab_source(&self.targets, self.compare.as_ref(), &self.snapshots, ab.b),
        );
        let (Some((a, _)), Some((b, _))) = images else {
            // An image that does not exist (no comparison running, snapshot gone).
            clear_view(enc, &self.targets.view.view);
            return;
        };
        let p = passes::compare::GpuCmpParams {
            mode: ab.mode.gpu_id(),
            split_x: (ab.split.clamp(0.0, 1.0) * want.0 as f32) as u32,
            exposure: look.exposure_ev.exp2(),
            tonemap: look.tonemap.gpu_id(),
            diff_scale: ab.diff_scale,
            _pad: [0; 3],
        };
        let inputs = passes::compare::CompareInputs {
            method_image: a,
            reference_image: b,
            gb_position: &t.gbuffer.position_view,
            dst,
            size: want,
        };
        self.compare_views
            .record(&device, &queue, enc, &mut self.timer, p, &inputs);
    }

    /// The comparison truth's final or indirect image (cleared without a comparison at this
    /// size).
    fn record_truth_view(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        view: ViewBuffer,
        look: &ViewLook,
        want: (u32, u32),
    ) {
        let (device, queue) = (self.ctx.device.clone(), self.ctx.queue.clone());
        let dst = &self.targets.view.view;
        let Some(cmp) = self
            .compare
            .as_ref()
            .filter(|c| c.targets_size == self.targets.size)
        else {
            // No comparison running (or not at this size): nothing to show.
            clear_view(enc, &self.targets.view.view);
            return;
        };
        let src = if view == ViewBuffer::GroundTruthFinal {
            &cmp.targets.final_view
        } else {
            &cmp.targets.indirect_view
        };
        let inputs = DisplayInputs {
            look,
            src,
            dst,
            size: want,
        };
        self.display
            .record(&device, &queue, enc, &mut self.timer, &inputs);
    }

    /// One of the temporal stage's views (cleared when the stage has not run at this size).
    fn record_temporal_view(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        tv: TemporalView,
        look: &ViewLook,
        want: (u32, u32),
    ) {
        let (device, queue) = (self.ctx.device.clone(), self.ctx.queue.clone());
        let dst = &self.targets.view.view;
        if !self.temporal.has_view(tv, self.targets.size) {
            // The stage has not run at this size (off, or a progressive method).
            clear_view(enc, &self.targets.view.view);
            return;
        }
        let inputs = passes::temporal::TemporalViewInputs {
            view: tv,
            gbuffer: &self.targets.gbuffer,
            camera_buf: &self.camera_buf,
            dst: &self.targets.view.view,
        };
        let shown = self
            .temporal
            .record_view(&device, &queue, enc, &mut self.timer, &inputs);
        if let Some(src) = shown {
            let inputs = DisplayInputs {
                look,
                src,
                dst,
                size: want,
            };
            self.display
                .record(&device, &queue, enc, &mut self.timer, &inputs);
        }
    }

    /// A method's own view, drawn by its owner (cleared without a frame of it at this size).
    fn record_method_view(&mut self, enc: &mut wgpu::CommandEncoder, view: MethodView, look: &ViewLook) {
        let (device, queue) = (self.ctx.device.clone(), self.ctx.queue.clone());
        let frame = self.targets.size;
        let Some((_, owner)) = view.find() else {
            clear_view(enc, &self.targets.view.view);
            return;
        };
        let module = owner.info().module.name;
        let Some((_, m)) = self.methods.iter_mut().find(|(n, _)| *n == module) else {
            clear_view(enc, &self.targets.view.view);
            return;
        };
        if m.view_size(view, frame).is_none() {
            // No frame of the method at this size yet: nothing to show.
            clear_view(enc, &self.targets.view.view);
            return;
        }
        let mut cx = ViewCx {
            scene: &self.scene,
            camera: &self.camera_buf,
            device: &device,
            queue: &queue,
            timer: &mut self.timer,
            look,
            targets: &self.targets,
            tree: &self.tree,
            dst: &self.targets.view.view,
            selected_block: self.selected_block,
        };
        m.record_view(view, &mut cx, enc);
    }

    /// A frame buffer: the lighting images through the display pass, the others (RSM,
    /// pyramid, G-buffer, shadow map) through the visualise pass.
    fn record_buffer_view(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        view: ViewBuffer,
        look: &ViewLook,
        want: (u32, u32),
        camera: &Camera,
    ) {
        let (device, queue) = (self.ctx.device.clone(), self.ctx.queue.clone());
        let t = &self.targets;
        let dst = &t.view.view;
        let b = self.scene.bounds;
        let (bmin, bmax) = if b.is_empty() {
            (Vec3::ZERO, Vec3::ONE)
        } else {
            (b.min, b.max)
        };
        let (mode, src, lo, hi) = match view {
            ViewBuffer::Final | ViewBuffer::Direct | ViewBuffer::Indirect => {
                let src = match view {
                    ViewBuffer::Final => &t.lighting.final_view,
                    ViewBuffer::Direct => &t.lighting.direct_view,
                    _ => &t.lighting.indirect_view,
                };
                let inputs = DisplayInputs {
                    look,
                    src,
                    dst,
                    size: want,
                };
                self.display
                    .record(&device, &queue, enc, &mut self.timer, &inputs);
                return;
            }
            ViewBuffer::RsmFlux => {
                // Flux / (E x texel area) is the albedo the light saw: a readable image.
                let l0 = self.light0_lum;
                let texel = self.lights_texel;
                let scale = 1.0 / (l0 * texel * texel).max(1e-30);
                (
                    VisMode::ArrayColor,
                    VisSource::Array(&t.shadow.flux_array, 0),
                    [0.0; 4],
                    [scale, 0.0, 0.0, 0.0],
                )
            }
            ViewBuffer::RsmNormal => (
                VisMode::ArrayNormal,
                VisSource::Array(&t.shadow.normal_array, 0),
                [0.0; 4],
                [0.0; 4],
            ),
            ViewBuffer::RsmPosition => (
                VisMode::ArrayPosition,
                VisSource::Array(&t.shadow.position_array, 0),
                bmin.extend(0.0).to_array(),
                bmax.extend(1.0).to_array(),
            ),
            ViewBuffer::PdfPyramid => {
                let vb = &self.vpl_buffers;
                let (_, offsets) = passes::vpl_gen::pyramid_layout(vb.res);
                let l = (self.settings.display.pyramid_level as usize).min(offsets.len() - 1);
                let top = *offsets.last().unwrap_or(&0) as f32;
                (
                    VisMode::ScalarLogHeat,
                    VisSource::Scalar(&vb.importance_pyramid, &vb.importance_pyramid),
                    [0.0, top, 0.0, 0.0],
                    [0.0, (vb.res >> l) as f32, offsets[l] as f32, 0.0],
                )
            }
            ViewBuffer::ImportanceRaw | ViewBuffer::ImportanceFiltered => {
                let vb = &self.vpl_buffers;
                let (_, offsets) = passes::vpl_gen::pyramid_layout(vb.res);
                let top = *offsets.last().unwrap_or(&0) as f32;
                let values = if view == ViewBuffer::ImportanceRaw {
                    &vb.importance_raw
                } else {
                    &vb.importance_pyramid
                };
                (
                    VisMode::ScalarLogHeat,
                    VisSource::Scalar(values, &vb.importance_pyramid),
                    [0.0, top, 0.0, 0.0],
                    [0.0, vb.res as f32, 0.0, 0.0],
                )
            }
            ViewBuffer::Albedo => (
                VisMode::Albedo,
                VisSource::Float(&t.gbuffer.albedo_view),
                [0.0; 4],
                [1.0; 4],
            ),
            ViewBuffer::Normal => (
                VisMode::Normal,
                VisSource::Float(&t.gbuffer.normal_view),
                [0.0; 4],
                [1.0; 4],
            ),
            ViewBuffer::Position => (
                VisMode::Position,
                VisSource::Float(&t.gbuffer.position_view),
                bmin.extend(0.0).to_array(),
                bmax.extend(1.0).to_array(),
            ),
            ViewBuffer::Depth => {
                let (near, far) = depth_range(camera, &b);
                (
                    VisMode::Depth,
                    VisSource::Float(&t.gbuffer.position_view),
                    camera.position.extend(near).to_array(),
                    camera.forward.extend(far).to_array(),
                )
            }
            ViewBuffer::MaterialId => (
                VisMode::IdFromW,
                VisSource::Float(&t.gbuffer.position_view),
                [0.0; 4],
                [1.0; 4],
            ),
            ViewBuffer::Method(_)
            | ViewBuffer::Temporal(_)
            | ViewBuffer::GroundTruthIndirect
            | ViewBuffer::GroundTruthFinal
            | ViewBuffer::SplitIndirect
            | ViewBuffer::SideBySide
            | ViewBuffer::RelativeError
            | ViewBuffer::AbCompare => unreachable!("drawn above"),
            ViewBuffer::ShadowMap => (
                VisMode::DepthTexture,
                VisSource::Depth(&t.shadow.array_view, 0),
                [0.0; 4],
                [1.0; 4],
            ),
        };
        let v = VisInputs {
            mode,
            src,
            range_min: lo,
            range_max: hi,
            dst,
            size: want,
        };
        self.visualise.record(&device, &queue, enc, &mut self.timer, v);
    }

    /// The `Rgba8Unorm` texture holding the last rendered view, and its generation (bumped
    /// when the texture is recreated).
    pub fn view_texture(&self) -> (&wgpu::Texture, &wgpu::TextureView, u64) {
        (
            &self.targets.view.texture,
            &self.targets.view.view,
            self.targets.view.generation,
        )
    }

    /// The texture of view `slot` of the last `render_views` (0 = [`Renderer::view_texture`]);
    /// None past the views rendered.
    pub fn view_texture_at(&self, slot: usize) -> Option<(&wgpu::Texture, &wgpu::TextureView, u64)> {
        let t = self.view_target(slot)?;
        Some((&t.texture, &t.view, t.generation))
    }

    pub(super) fn view_target(&self, slot: usize) -> Option<&ViewTarget> {
        match slot {
            0 => Some(&self.targets.view),
            _ => self.extra_views.get(slot - 1),
        }
    }

    /// Reads view `slot` (sRGB-encoded RGBA8, as shown).
    pub fn read_view_rgba8_at(&self, slot: usize) -> Result<(u32, u32, Vec<u8>), GpuError> {
        let t = self
            .view_target(slot)
            .ok_or_else(|| GpuError::Readback(format!("no view {slot}")))?;
        let bytes = readback::read_texture_bytes(&self.ctx, &t.texture, 0)?;
        Ok((t.size.0, t.size.1, bytes))
    }

    /// Copies a live radiance buffer into a new snapshot (replacing the oldest past
    /// [`views::MAX_SNAPSHOTS`]); returns its index.
    pub fn take_snapshot(&mut self, src: AbSource, label: String) -> Result<u32, String> {
        if matches!(src, AbSource::Snapshot(_)) {
            return Err("a snapshot of a snapshot is the snapshot".into());
        }
        let (tex, _, size) = ab_texture(&self.targets, self.compare.as_ref(), &self.snapshots, src)
            .ok_or("the ground-truth comparison is not running")?;
        let device = &self.ctx.device;
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("views::snapshot"),
            size: wgpu::Extent3d {
                width: size.0,
                height: size.1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: tex.format(),
            usage: wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_DST
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let mut enc = device.create_command_encoder(&Default::default());
        enc.copy_texture_to_texture(tex.as_image_copy(), texture.as_image_copy(), tex.size());
        self.ctx.queue.submit([enc.finish()]);
        let snap = views::Snapshot {
            label,
            view: texture.create_view(&Default::default()),
            texture,
            size,
        };
        if self.snapshots.len() >= views::MAX_SNAPSHOTS {
            self.snapshots.remove(0);
        }
        self.snapshots.push(snap);
        Ok(self.snapshots.len() as u32 - 1)
    }

    /// The snapshots' labels, by index.
    pub fn snapshot_labels(&self) -> Vec<String> {
        self.snapshots.iter().map(|s| s.label.clone()).collect()
    }

    pub fn clear_snapshots(&mut self) {
        self.snapshots.clear();
    }

    /// Reads an A/B source back as linear floats (None: it does not exist now).
    pub fn read_ab_source(&self, src: AbSource) -> Result<Option<ImageF32>, GpuError> {
        match ab_texture(&self.targets, self.compare.as_ref(), &self.snapshots, src) {
            Some((tex, _, _)) => readback::read_texture_f32(&self.ctx, tex, 0).map(Some),
            None => Ok(None),
        }
    }

    /// Reads the view texture (sRGB-encoded RGBA8, as shown).
    pub fn read_view_rgba8(&self) -> Result<(u32, u32, Vec<u8>), GpuError> {
        self.read_view_rgba8_at(0)
    }
}

pub(super) fn clear_view(enc: &mut wgpu::CommandEncoder, view: &wgpu::TextureView) {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("view::clear"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            resolve_target: None,
            depth_slice: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
}

/// An A/B source's radiance texture, its view and its size (None: it does not exist now).
/// A free function so that `record_view` can borrow the passes mutably beside it.
pub(super) fn ab_texture<'a>(
    targets: &'a FrameTargets,
    compare: Option<&'a CompareState>,
    snapshots: &'a [views::Snapshot],
    src: AbSource,
) -> Option<(&'a wgpu::Texture, &'a wgpu::TextureView, (u32, u32))> {
    let l = &targets.lighting;
    let cmp = || compare.filter(|c| c.targets_size == targets.size);
    let size = targets.size;
    match src {
        AbSource::Final => Some((&l.final_, &l.final_view, size)),
        AbSource::Direct => Some((&l.direct, &l.direct_view, size)),
        AbSource::Indirect => Some((&l.indirect, &l.indirect_view, size)),
        AbSource::GroundTruthIndirect => cmp().map(|c| (&c.targets.indirect, &c.targets.indirect_view, size)),
        AbSource::GroundTruthFinal => cmp().map(|c| (&c.targets.final_, &c.targets.final_view, size)),
        AbSource::Snapshot(i) => snapshots.get(i as usize).map(|s| (&s.texture, &s.view, s.size)),
    }
}

/// The view and size of an A/B source (see [`ab_texture`]).
pub(super) fn ab_source<'a>(
    targets: &'a FrameTargets,
    compare: Option<&'a CompareState>,
    snapshots: &'a [views::Snapshot],
    src: AbSource,
) -> Option<(&'a wgpu::TextureView, (u32, u32))> {
    ab_texture(targets, compare, snapshots, src).map(|(_, v, size)| (v, size))
}

pub fn depth_range(camera: &Camera, b: &crate::scene::Aabb) -> (f32, f32) {
    if b.is_empty() {
        return (camera.znear, camera.zfar);
    }
    let mut lo = f32::INFINITY;
    let mut hi = 0.0f32;
    for i in 0..8 {
        let p = Vec3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        );
        let d = (p - camera.position).dot(camera.forward);
        lo = lo.min(d);
        hi = hi.max(d);
    }
    (lo.max(0.0), hi.max(lo.max(0.0) + 1e-3))
}

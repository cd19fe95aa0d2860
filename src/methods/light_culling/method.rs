//! The light-culling methods' frame: `Method` for [`LightCulling`] (the passes it records, its
//! views, the pixel rows, the overlay, the legends, the statistics).

use super::*;

impl Method for LightCulling {
    fn record(&mut self, cx: &mut FrameCx<'_>, enc: &mut wgpu::CommandEncoder) -> f32 {
        let s = cx.settings;
        let lc: LightCullingSettings = s.method(ID).unwrap_or_default();
        let grid = Self::grid(&lc, cx.size);
        let (tiles_x, tiles_y) = grid.per_subset();
        // The tree variant uses no tile lists (one entry, never read).
        let tree = cx.method == TREE;
        let (tiles, cap) = if tree {
            (1, 1)
        } else {
            (grid.count(), lc.max_lights_per_tile)
        };
        let vpl_capacity = cx.vpl_buffers.capacity;
        if !self.fit_buffers(cx, enc, tiles, cap) {
            return 1.0;
        }
        let frames = match self.state {
            Some((k, m, n)) if s.frame.accumulate && k == cx.key && m == cx.method => n + 1,
            _ => 1,
        };
        let seed = Self::seed(s, cx.frame_index);
        let count = cx.vpl_frame.count.min(vpl_capacity);
        self.scene_radius = cx.scene_radius;
        let maps = if tree { cx.tree.leaves.max(1) } else { count };
        let Some((visibility, ism_flags, _)) = self.plan_ism(cx, &lc, maps) else {
            enc.clear_buffer(cx.gi_accum, 0, None);
            self.state = None;
            self.companion = None;
            return 1.0;
        };
        self.state = Some((cx.key, cx.method, frames));
        let il = Interleave::new(lc.interleave.n, count, seed);
        let p = GpuLcullParams {
            width: cx.size.0,
            height: cx.size.1,
            tile: lc.tile_size,
            n: lc.interleave.n,
            tiles_x,
            tiles_y,
            tiles,
            cap,
            count,
            offset: il.offset,
            seed,
            mode: (cx.method == CLAMPED) as u32,
            epsilon_max: lc.epsilon_max,
            exposure: s.display.exposure_ev.exp2(),
            eps: s.gi.distance_epsilon,
            ray_offset: s.gi.ray_offset,
            shadow_rays: visibility,
            stride: il.stride,
            leaves: 0,
            ism_flags,
            brdf: cx.brdf.gpu(),
            _pad: [0; 3],
            eye: cx.eye.extend(0.0).to_array(),
        };
        // The filter: raw (before albedo / pi) x albedo / pi into the accumulation; with GGX
        // raw is radiance already (and validation keeps the filter's window to the pixel).
        let glossy = cx.brdf != crate::settings::Brdf::Lambert;
        let fp = GpuFilterParams {
            accumulate: (frames > 1) as u32,
            scale: if glossy { 1.0 } else { std::f32::consts::FRAC_1_PI },
            modulate: (!glossy) as u32,
            ..GpuFilterParams::new(cx.size, &lc.interleave)
        };
        self.settings = lc;
        if cx.method == TREE {
            return self.record_tree(cx, enc, p, fp, frames);
        }
        // The difference view's companion: the other variant with the same settings, in
        // diagnostic frames while the view is drawn, recorded first (the own run then leaves
        // its lists and counters for the other views).
        if cx.diagnostics
            && cx.views.contains(&DIFFERENCE)
            && !self.record_companion(cx, enc, p, fp, ism_flags)
        {
            return 0.0;
        }
        let ism = ism_frame(
            &self.settings.ism,
            &self.ism_points,
            &self.ism_targets,
            self.ism_maps,
            ism_flags & 1 != 0,
        );
        let inputs = super::state::frame_inputs(cx, cx.gi_accum, ism);
        let frame = LcullFrameParams { cull: p, filter: fp };
        self.pass.record(cx, enc, false, frame, &inputs, &self.buffers);
        1.0 / frames as f32
    }

    fn after_submit(&mut self) {
        self.pass.stats.after_submit();
    }

    fn frames_averaged(&self) -> Option<u32> {
        Some(self.state.map_or(0, |(_, _, n)| n))
    }

    fn reset(&mut self) {
        self.state = None;
        self.companion = None;
    }

    fn view_size(&self, view: MethodView, frame: (u32, u32)) -> Option<(u32, u32)> {
        if view == ISM_ATLAS && (self.ism_maps == 0 || self.ism_targets.is_none()) {
            return None;
        }
        (self.buffers.size == frame && self.state.is_some()).then_some(frame)
    }

    fn record_view(&mut self, view: MethodView, cx: &mut ViewCx<'_>, enc: &mut wgpu::CommandEncoder) {
        if view == ISM_ATLAS {
            let size = self.buffers.size;
            if self.ism_view_data.as_ref().is_none_or(|(s, _)| *s != size) {
                let bytes = 16 * size.0 as u64 * size.1 as u64;
                let data = cx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("lcull::ism_view_data"),
                    size: bytes.max(16),
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                });
                self.ism_view_data = Some((size, data));
            }
            if let (Some(t), Some((_, data))) = (self.ism_targets.as_ref(), self.ism_view_data.as_ref()) {
                let r = self.scene_radius;
                let v = crate::gpu::passes::ism::IsmView {
                    maps: self.ism_maps,
                    range: (0.005 * r, 2.0 * r),
                    size,
                    dst: cx.dst,
                    data,
                };
                self.pass
                    .ism
                    .record_view(cx.device, cx.queue, enc, cx.timer, t, &v);
            }
            return;
        }
        let p = GpuLcullViewParams {
            mode: if view == LIST || view == TREE_IN_RANGE {
                0
            } else if view == OVERFLOW {
                1
            } else if view == PATTERN {
                2
            } else if view == IN_RANGE {
                3
            } else if view == DIFFERENCE {
                4
            } else {
                5
            },
            scale_top: 10u32.pow(self.view_decades(view)),
            exposure: cx.look.exposure_ev.exp2(),
            tonemap: cx.look.tonemap.gpu_id(),
            n: self.settings.interleave.n,
            cap: self.settings.max_lights_per_tile,
            own_scale: self.state.map_or(0.0, |(_, _, n)| 1.0 / n.max(1) as f32),
            companion_scale: self.companion_frames().map_or(0.0, |n| 1.0 / n as f32),
            own_is_clamped: self.state.is_some_and(|(_, m, _)| m == CLAMPED) as u32,
            range: DIFFERENCE_RANGE,
            _pad: [0; 2],
        };
        let targets = cx.targets;
        self.pass
            .record_view(cx, enc, p, &targets.lighting.gi_accum, &self.buffers);
    }

    /// Per pixel: tile list length, VPLs in range, VPLs tested, shadow rays; the difference
    /// view: (relative difference, clamped luminance, stochastic luminance, 1 where both
    /// images exist) as last drawn.
    fn read_view(&self, ctx: &GpuContext, view: MethodView) -> Result<Option<ImageF32>, GpuError> {
        if self.state.is_none() {
            return Ok(None);
        }
        if view == ISM_ATLAS {
            return match self.ism_view_data.as_ref() {
                Some((size, data)) if self.ism_maps > 0 => readback::read_vec4_image(ctx, data, *size),
                _ => Ok(None),
            };
        }
        if view == DIFFERENCE {
            return match self.buffers.companion.as_ref() {
                Some(c) if self.companion_frames().is_some() => {
                    readback::read_vec4_image(ctx, &c.difference, self.buffers.size)
                }
                _ => Ok(None),
            };
        }
        readback::read_vec4_image(ctx, &self.buffers.diag, self.buffers.size)
    }

    fn pixel_rows(
        &self,
        ctx: &GpuContext,
        x: u32,
        y: u32,
        frame: (u32, u32),
    ) -> Result<Vec<(&'static str, [f32; 4])>, GpuError> {
        let b = &self.buffers;
        if b.size != frame || x >= frame.0 || y >= frame.1 || self.state.is_none() {
            return Ok(Vec::new());
        }
        let d = readback::read_vec4_pixel(ctx, &b.diag, b.size.0, x, y)?;
        Ok(vec![(
            if self.is_tree() {
                "tree culling (VPLs in range, listed, nodes visited, shadow rays or ISM lookups)"
            } else {
                "light culling (tile list, VPLs in range, VPLs tested, shadow rays or ISM lookups)"
            },
            d,
        )])
    }

    /// The range spheres of the pinned pixel's tile list (the tree variant: of its
    /// reservoir list) in the last frame, those holding the pixel's point first, at most
    /// [`OVERLAY_SPHERES`]. (Its per-pixel counters are the last diagnostic frame's: the
    /// pixel-values window.)
    fn read_overlay(
        &self,
        ctx: &GpuContext,
        pixel: (u32, u32),
        position: glam::Vec3,
    ) -> Result<Option<MethodOverlay>, GpuError> {
        let b = &self.buffers;
        let (x, y) = pixel;
        if self.state.is_none() || x >= b.size.0 || y >= b.size.1 {
            return Ok(None);
        }
        let list = if self.is_tree() {
            self.read_tree_list(ctx, pixel)?
        } else {
            self.read_tile_list(ctx, pixel)?
        };
        Ok(list.map(|(title, rows, spheres)| self.overlay_of(title, rows, spheres, position)))
    }

    fn legend(&self, view: MethodView, _tree_levels: u32) -> Option<Legend> {
        if view == ISM_ATLAS {
            let r = self.scene_radius;
            let tile = self.ism_targets.as_ref().map_or(0, |t| t.layout.tile);
            return Some(Legend {
                title: if self.ism_maps == 0 {
                    "no maps this frame (ISM visibility off and the view not drawn yet, or \
                     refused: see the problems window)"
                        .to_string()
                } else {
                    format!(
                        "distance from the VPL ({} maps of {tile}^2; dim: filled by pull-push; \
                         black: hole)",
                        self.ism_maps
                    )
                },
                lo: (0.005 * r).log10(),
                hi: (2.0 * r).log10(),
                log: true,
            });
        }
        let st = self.pass.stats.last();
        let top = self.view_decades(view) as f32;
        if view == TREE_IN_RANGE {
            return Some(Legend {
                title: match st {
                    Some(st) => format!(
                        "VPLs in range + 1 (mean {:.1}, most {}; {} pixels over k = {})",
                        st.in_range_per_pixel(),
                        st.longest_list,
                        st.overflow_tiles,
                        self.settings.reservoir_k
                    ),
                    None => "VPLs in range + 1".into(),
                },
                lo: 0.0,
                hi: top,
                log: true,
            });
        }
        if view == TREE_VISITED {
            return Some(Legend {
                title: match st {
                    Some(st) => format!("tree nodes visited + 1 (mean {:.1})", st.visited_per_pixel()),
                    None => "tree nodes visited + 1".into(),
                },
                lo: 0.0,
                hi: top,
                log: true,
            });
        }
        if view == LIST {
            Some(Legend {
                title: match st {
                    Some(st) => format!(
                        "lights per tile + 1 (mean {:.1}, longest {}, cap {})",
                        st.mean_list(),
                        st.longest_list,
                        self.settings.max_lights_per_tile
                    ),
                    None => "lights per tile + 1".into(),
                },
                lo: 0.0,
                hi: top,
                log: true,
            })
        } else if view == IN_RANGE {
            Some(Legend {
                title: match st {
                    Some(st) => format!(
                        "share of the list in range ({:.1} of {:.1} VPLs tested per pixel)",
                        st.in_range_per_pixel(),
                        st.tested_per_pixel()
                    ),
                    None => "share of the list in range".into(),
                },
                lo: 0.0,
                hi: 1.0,
                log: false,
            })
        } else if view == DIFFERENCE {
            let own = self.state.map_or(0, |(_, _, n)| n);
            Some(Legend {
                title: match self.companion_frames() {
                    Some(n) => {
                        let own_clamped = self.state.is_some_and(|(_, m, _)| m == CLAMPED);
                        let (c, st) = if own_clamped { (own, n) } else { (n, own) };
                        format!(
                            "(clamped - stochastic) / mean, over {c} clamped and {st} stochastic \
                             frames{}",
                            if own <= 1 {
                                " (accumulate frames to see the bias, not the noise)"
                            } else {
                                ""
                            }
                        )
                    }
                    None => "(clamped - stochastic) / mean: the other variant runs from the next \
                             diagnostic frame"
                        .into(),
                },
                lo: -DIFFERENCE_RANGE,
                hi: DIFFERENCE_RANGE,
                log: false,
            })
        } else {
            None
        }
    }

    fn stats(&mut self) -> Vec<(&'static str, f64)> {
        let tree = self.is_tree();
        match self.pass.stats.poll() {
            Some(st) if tree => vec![
                ("vpls_in_range_per_pixel", st.in_range_per_pixel()),
                ("vpls_listed_per_pixel", st.tested_per_pixel()),
                ("most_vpls_in_range", st.longest_list as f64),
                ("pixels_over_k", st.overflow_tiles as f64),
                ("tree_nodes_visited_per_pixel", st.visited_per_pixel()),
                ("shadow_rays_per_pixel", st.rays_per_pixel()),
                ("epsilon_max", self.settings.epsilon_max as f64),
                ("reservoir_k", self.settings.reservoir_k as f64),
                ("ism_maps", if self.ism_on { self.ism_maps as f64 } else { 0.0 }),
            ],
            Some(st) => vec![
                ("mean_tile_list", st.mean_list()),
                ("longest_tile_list", st.longest_list as f64),
                ("overflow_tiles", st.overflow_tiles as f64),
                ("vpls_tested_per_pixel", st.tested_per_pixel()),
                ("vpls_in_range_per_pixel", st.in_range_per_pixel()),
                ("shadow_rays_per_pixel", st.rays_per_pixel()),
                ("epsilon_max", self.settings.epsilon_max as f64),
                ("interleave", self.settings.interleave.n as f64),
                ("ism_maps", if self.ism_on { self.ism_maps as f64 } else { 0.0 }),
            ],
            None => Vec::new(),
        }
    }

    fn status(&mut self) -> Option<String> {
        let st = self.pass.stats.poll()?;
        let vis = if self.ism_on {
            format!("ISM lookups per pixel ({} maps)", self.ism_maps)
        } else {
            "shadow rays per pixel".to_string()
        };
        if self.is_tree() {
            return Some(format!(
                "tree culling {:.1} VPLs in range per pixel (most {}; {} pixels over k = {}) · \
                 {:.1} nodes visited · {:.2} {vis}",
                st.in_range_per_pixel(),
                st.longest_list,
                st.overflow_tiles,
                self.settings.reservoir_k,
                st.visited_per_pixel(),
                st.rays_per_pixel()
            ));
        }
        Some(format!(
            "culling {:.1} lights per tile (longest {}, {} over the cap of {}) · {:.1} in range \
             per pixel · {:.1} {vis}",
            st.mean_list(),
            st.longest_list,
            st.overflow_tiles,
            self.settings.max_lights_per_tile,
            st.in_range_per_pixel(),
            st.rays_per_pixel()
        ))
    }
}

impl LightCulling {
    /// The pinned pixel's reservoir list (the tree variant): the overlay's title, rows and
    /// the listed VPLs' range spheres.
    fn read_tree_list(&self, ctx: &GpuContext, (x, y): (u32, u32)) -> Result<Option<OverlayList>, GpuError> {
        let b = &self.buffers;
        let Some(t) = self.tree.as_ref().filter(|t| t.size == b.size) else {
            return Ok(None);
        };
        let k = (y * b.size.0 + x) as u64;
        let mv = readback::read_buffer_range(ctx, &t.m, 8 * k, 8)?;
        let [m, visited]: [u32; 2] = bytemuck::pod_read_unaligned(&mv[..8]);
        let listed = m.min(t.k);
        let list: Vec<u32> = if listed > 0 {
            bytemuck::pod_collect_to_vec(&readback::read_buffer_range(
                ctx,
                &t.list,
                4 * k * t.k as u64,
                4 * listed as u64,
            )?)
        } else {
            Vec::new()
        };
        let spheres = read_spheres(ctx, &t.lights, t.leaves, &list)?;
        let rows = vec![
            (
                "VPLs in range (m) / listed (k)".to_string(),
                format!(
                    "{m} / {listed} (k = {}; each kept with probability min(k / m, 1))",
                    t.k
                ),
            ),
            ("tree nodes visited".into(), visited.to_string()),
        ];
        Ok(Some((
            "the range spheres of its reservoir list (bounding-sphere tree, section 5)".to_string(),
            rows,
            spheres,
        )))
    }

    /// The pinned pixel's tile list (the tiled variants): the overlay's title, rows and the
    /// listed VPLs' range spheres.
    fn read_tile_list(&self, ctx: &GpuContext, (x, y): (u32, u32)) -> Result<Option<OverlayList>, GpuError> {
        let b = &self.buffers;
        let grid = Self::grid(&self.settings, b.size);
        let t = grid.tile_of(x, y);
        if t >= b.tiles {
            return Ok(None);
        }
        let count_bytes = readback::read_buffer_range(ctx, &b.tile_count, 4 * t as u64, 4)?;
        let count = bytemuck::pod_read_unaligned::<u32>(&count_bytes[..4]);
        let listed = count.min(b.cap);
        let list: Vec<u32> = if listed > 0 {
            bytemuck::pod_collect_to_vec(&readback::read_buffer_range(
                ctx,
                &b.tile_lists,
                4 * t as u64 * b.cap as u64,
                4 * listed as u64,
            )?)
        } else {
            Vec::new()
        };
        let spheres = read_spheres(ctx, &b.lights, b.vpl_capacity, &list)?;
        let subset = x % grid.n + grid.n * (y % grid.n);
        let rows = vec![
            (
                "tile (interleaving subset)".to_string(),
                format!("{t} (subset {subset} of {})", grid.n * grid.n),
            ),
            (
                "VPLs in the tile's list".into(),
                if count > b.cap {
                    format!(
                        "{count}: over the cap of {}, the pixel tests its whole subset",
                        b.cap
                    )
                } else {
                    count.to_string()
                },
            ),
        ];
        let variant = if self.state.is_some_and(|(_, m, _)| m == CLAMPED) {
            "clamped ranges"
        } else {
            "stochastic ranges of the frame's xi"
        };
        Ok(Some((
            format!("the range spheres of its tile's light list ({variant})"),
            rows,
            spheres,
        )))
    }

    /// The overlay of a pinned pixel at `position` from its list's `title`, `rows` and range
    /// spheres: the spheres holding the point first, at most [`OVERLAY_SPHERES`].
    fn overlay_of(
        &self,
        title: String,
        mut rows: Vec<(String, String)>,
        spheres: Vec<[f32; 4]>,
        position: glam::Vec3,
    ) -> MethodOverlay {
        let holds = |s: &[f32; 4]| glam::Vec3::new(s[0], s[1], s[2]).distance(position) < s[3];
        let mut order: Vec<usize> = (0..spheres.len()).collect();
        order.sort_by_key(|&k| !holds(&spheres[k]));
        let inside = spheres.iter().filter(|s| holds(s)).count();
        let mut prims = Vec::new();
        for &k in order.iter().take(OVERLAY_SPHERES) {
            let s = spheres[k];
            let c = glam::Vec3::new(s[0], s[1], s[2]);
            let color = if holds(&s) {
                crate::methods::overlay::Rgba8::rgb(90, 230, 110)
            } else {
                crate::methods::overlay::Rgba8::rgba(255, 160, 40, 140)
            };
            prims.push(Prim::Sphere {
                center: c,
                radius: s[3].min(1e6),
                color,
            });
            prims.push(Prim::Point(c, color));
        }
        prims.push(Prim::Point(position, crate::methods::overlay::Rgba8::WHITE));
        rows.push((
            "range spheres holding the pixel's point".into(),
            format!("{inside} of {} listed", spheres.len()),
        ));
        let (rmin, rmax) = spheres
            .iter()
            .fold((f32::INFINITY, 0.0f32), |(a, b), s| (a.min(s[3]), b.max(s[3])));
        if !spheres.is_empty() {
            rows.push((
                "range radii of the list (scene units)".into(),
                format!("{rmin:.3} .. {rmax:.3}"),
            ));
        }
        rows.push((
            "spheres drawn".into(),
            format!("{} of {}", spheres.len().min(OVERLAY_SPHERES), spheres.len()),
        ));
        MethodOverlay {
            title,
            rows,
            key: if self.is_tree() {
                "green: the listed VPLs (each range sphere holds the pixel's point; one of them \
             is shaded, resampled by eq. 8); white: the pixel"
                    .into()
            } else {
                "green: listed VPLs whose range sphere holds the pixel's point (the ones that \
             light it); orange: listed for the tile but out of the pixel's range; white: \
             the pixel"
                    .into()
            },
            prims,
        }
    }
}

/// An overlay's title, (what, value) rows and the listed VPLs' range spheres.
type OverlayList = (String, Vec<(String, String)>, Vec<[f32; 4]>);

/// The range spheres (centre, radius) of the VPLs `list` names in `lights` (those below
/// `capacity`).
fn read_spheres(
    ctx: &GpuContext,
    lights: &wgpu::Buffer,
    capacity: u32,
    list: &[u32],
) -> Result<Vec<[f32; 4]>, GpuError> {
    let ranges: Vec<(u64, u64)> = list
        .iter()
        .filter(|&&i| i < capacity)
        .map(|&i| (32 * i as u64, 16))
        .collect();
    Ok(readback::read_buffer_ranges(ctx, lights, &ranges)?
        .iter()
        .map(|v| bytemuck::pod_read_unaligned::<[f32; 4]>(&v[..16]))
        .collect())
}

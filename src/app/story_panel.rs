//! The pixel story of the tree samplers: for the pinned pixel, the 4 surrounding block cuts
//! and their blend weights (or the fallback), and for every sample its traversal path (nodes,
//! child probabilities), where and why it stopped, the sampled light point, the shadow ray and
//! the contribution; a tree view with the paths over the levels (usable fractions per level);
//! world-space overlays (node boxes, 1-sigma ellipses, points, shadow rays) for the camera
//! views. Data: `Renderer::read_pixel_trace` (recorded by `slc_sample` on the GPU).

use glam::Vec3;

use super::image_views::{Prim, rgba8};
use crate::base::sst_node::{SstNode, Topology, basis, flag, luminance};
use crate::base::story::{CutStory, PixelTrace, SampleVisibility, StopReason};
use crate::renderer::Renderer;

/// Colours shared by the window and the overlays.
pub const VISIBLE: egui::Color32 = egui::Color32::from_rgb(90, 230, 120);
pub const BLOCKED: egui::Color32 = egui::Color32::from_rgb(240, 70, 60);
pub const AWAY: egui::Color32 = egui::Color32::from_rgb(150, 150, 150);
pub const NODE: egui::Color32 = egui::Color32::from_rgb(255, 200, 60);
pub const PATH: egui::Color32 = egui::Color32::from_rgb(90, 170, 255);

#[derive(Default)]
pub struct StoryPanel {
    pub show: bool,
    pixel: Option<(u32, u32)>,
    pub trace: Option<PixelTrace>,
    /// The pixel's G-buffer sample, albedo and GI (this frame).
    position: Vec3,
    normal: Vec3,
    albedo: Vec3,
    gi: Vec3,
    /// The nodes on the traced paths (read alone, not the whole tree) and the usable flags.
    nodes: std::collections::HashMap<u32, SstNode>,
    flags: Vec<u32>,
    leaves: u32,
    /// The radix tree's links (empty on the perfect tree): levels are depths there.
    links: Vec<[u32; 4]>,
    /// (nodes, usable) per level (the radix tree: per depth, counts unknown: 0).
    levels: Vec<(u32, u32)>,
    read_at: f64,
    /// The sample whose path is detailed and drawn.
    pub selected: Option<usize>,
    pub overlay: bool,
    /// Why there is no story (shown in the window).
    pub note: String,
    /// The cut-based methods' story (Lightcuts, Lightcut Interpolation) and the tree's leaves.
    pub cut_story: Option<CutStory>,
    /// A method's own overlay of the pixel (light culling: its tile's range spheres).
    pub method_overlay: Option<crate::methods::overlay::MethodOverlay>,
}

impl StoryPanel {
    pub fn new() -> Self {
        Self {
            overlay: true,
            ..Default::default()
        }
    }

    /// Forgets when the story was last read (a new window's clock starts again at 0).
    pub fn forget_read_time(&mut self) {
        self.read_at = f64::NEG_INFINITY;
        self.trace = None;
    }

    /// Traces `pixel` (None: stop) and reads the last frame's story at most twice a second.
    pub fn refresh(&mut self, r: &mut Renderer, pixel: Option<(u32, u32)>, now: f64) -> Result<(), String> {
        let pixel = pixel.filter(|_| self.show);
        r.set_trace_pixel(pixel);
        if pixel.is_none() {
            self.trace = None;
            self.cut_story = None;
            self.method_overlay = None;
            self.pixel = None;
            self.note = "click a camera view to pin a pixel".into();
            return Ok(());
        }
        if !r.settings().gi.method.info().story {
            self.trace = None;
            if pixel == self.pixel && now - self.read_at < 0.5 {
                return Ok(());
            }
            self.pixel = pixel;
            self.read_at = now;
            self.leaves = r.tree_buffers().1.leaves;
            self.method_overlay = None;
            self.cut_story = r.read_cut_story().map_err(|e| e.to_string())?;
            if self.cut_story.is_some() {
                self.method_overlay = None;
                return Ok(());
            }
            self.method_overlay = r.read_method_overlay().map_err(|e| e.to_string())?;
            if self.method_overlay.is_some() {
                return Ok(());
            }
            let tellers: Vec<&str> = crate::methods::REGISTRY
                .iter()
                .filter(|m| m.story)
                .map(|m| m.short)
                .collect();
            self.note = format!(
                "{} tells no sample story (the methods that do: {}); a cut-based method's cut \
                 story needs a diagnostic frame and a pixel with geometry (Lightcut \
                 Interpolation's fallback pixels have none), and light culling's range spheres \
                 a frame and a pixel with geometry",
                r.settings().gi.method.name(),
                tellers.join(", ")
            );
            return Ok(());
        }
        self.cut_story = None;
        self.method_overlay = None;
        if pixel == self.pixel && now - self.read_at < 0.5 {
            return Ok(());
        }
        if pixel != self.pixel {
            self.selected = None;
        }
        self.pixel = pixel;
        self.read_at = now;
        self.trace = r.read_pixel_trace().map_err(|e| e.to_string())?;
        if self.trace.is_none() {
            self.note = "no story: the pixel sees no geometry (or the frame has not run yet)".into();
            return Ok(());
        }
        // Only the nodes the samples visited (a large tree is not read back twice a second).
        let mut ids: Vec<u32> = self
            .trace
            .iter()
            .flat_map(|t| &t.samples)
            .flat_map(|s| std::iter::once(s.start).chain(s.path.iter().map(|p| p.0)))
            .filter(|&n| n != 0)
            .collect();
        ids.sort_unstable();
        ids.dedup();
        let (nodes, flags) = r.read_tree_nodes(&ids).map_err(|e| e.to_string())?;
        self.leaves = r.tree_buffers().1.leaves;
        self.links = r.read_tree_links().map_err(|e| e.to_string())?;
        if self.links.is_empty() {
            let levels = self.leaves.max(1).ilog2() + 1;
            // Per level: its nodes (padding included) and how many are usable.
            self.levels = (0..levels)
                .map(|l| {
                    let usable = ((1u32 << l)..(2u32 << l))
                        .filter(|&n| flag(&flags, n as usize))
                        .count() as u32;
                    (1 << l, usable)
                })
                .collect();
        } else {
            // The radix tree: as many depths as the visited nodes reach (no per-depth counts
            // without reading the whole tree).
            let topo = Topology::of(self.leaves, &self.links);
            let deepest = ids.iter().map(|&n| topo.depth(n)).max().unwrap_or(0);
            self.levels = vec![(0, 0); deepest as usize + 1];
        }
        self.nodes = ids.into_iter().zip(nodes).collect();
        self.flags = flags;
        if let Some((x, y)) = pixel {
            let rows = r.read_pixel(x, y).map_err(|e| e.to_string())?;
            let get = |prefix: &str| {
                rows.iter()
                    .find(|(n, _)| n.starts_with(prefix))
                    .map_or(Vec3::ZERO, |(_, v)| Vec3::new(v[0], v[1], v[2]))
            };
            self.position = get("position");
            self.normal = get("normal");
            self.albedo = get("albedo");
            self.gi = get("GI");
        }
        Ok(())
    }

    fn node(&self, n: u32) -> SstNode {
        self.nodes.get(&n).copied().unwrap_or(SstNode::EMPTY)
    }

    fn leaves(&self) -> u32 {
        self.leaves
    }

    fn usable(&self, n: u32) -> bool {
        flag(&self.flags, n as usize)
    }

    /// World-space overlay primitives for the camera views: every evaluated sample's point
    /// and shadow ray; the selected sample's path as boxes and its end node's 1-sigma
    /// ellipse (without a selection: every end node's ellipse).
    pub fn overlay(&self) -> Vec<Prim> {
        if let Some(m) = self.method_overlay.as_ref().filter(|_| self.overlay && self.show) {
            return m.prims.clone();
        }
        let Some(t) = self.trace.as_ref().filter(|_| self.overlay && self.show) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        let x = self.position + self.normal * 1e-3;
        for (i, s) in t.samples.iter().enumerate() {
            let faint = self.selected.is_some_and(|k| k != i);
            if let Some((p, vis)) = s.point {
                let mut c = match vis {
                    SampleVisibility::Visible => VISIBLE,
                    SampleVisibility::Blocked => BLOCKED,
                    SampleVisibility::FacingAway => AWAY,
                };
                if faint {
                    c = c.gamma_multiply(0.25);
                }
                out.push(Prim::Line(x, p, rgba8(c)));
                out.push(Prim::Point(p, rgba8(c)));
            }
            let show_nodes = self.selected.is_none_or(|k| k == i);
            if show_nodes && s.end != 0 && s.end < self.leaves() {
                let node = self.node(s.end);
                out.push(ellipse(&node, NODE));
            }
            if self.selected == Some(i) {
                for n in std::iter::once(s.start).chain(s.path.iter().map(|p| p.0)) {
                    let node = self.node(n);
                    if !node.is_empty() && n < self.leaves() {
                        out.push(Prim::Box(node.bbox_min, node.bbox_max, rgba8(PATH)));
                    }
                }
            }
        }
        out.push(Prim::Point(self.position, rgba8(egui::Color32::WHITE)));
        out
    }

    /// The story (shown in the tool dock or its floating window).
    pub fn contents(&mut self, ui: &mut egui::Ui) {
        if let Some(story) = &self.cut_story {
            super::cut_story::contents(ui, story, self.leaves);
            return;
        }
        if self.method_overlay.is_some() {
            self.overlay_contents(ui);
            return;
        }
        let Some(t) = self.trace.clone() else {
            ui.label(&self.note);
            return;
        };
        let (x, y) = self.pixel.unwrap_or_default();
        ui.label(format!("Pixel ({x}, {y}) · last frame · {}", t.mode_name()));
        ui.checkbox(&mut self.overlay, "draw the story in the camera views")
            .on_hover_text("points and shadow rays (green visible, red blocked, grey facing away); the selected sample's path boxes (blue) and end node's 1-sigma ellipse (yellow)");
        if t.mode == 0 || t.fell_back {
            blocks_section(ui, &t);
        }
        ui.separator();
        let est = self.albedo / std::f32::consts::PI * t.estimate();
        if t.cells > 1 {
            ui.label(format!(
                "interleaved: subset {} of {} (the cut slots i with (i + the frame's offset) mod {} = {}){}",
                t.subset,
                t.cells,
                t.cells,
                t.subset,
                if t.mode == 2 { "" } else { "; each sample x n^2" },
            ));
        }
        if t.filtered {
            ui.label("the GI buffer holds the geometry-aware filter's mean over the pixel's neighbours on its surface");
        }
        ui.label(format!(
            "{} samples; their estimate = {:.4e} (luminance); the GI buffer holds {:.4e}{}",
            t.samples.len(),
            luminance(est),
            luminance(self.gi),
            if t.taken as usize > t.samples.len() {
                format!(" (story of the first {} of {})", t.samples.len(), t.taken)
            } else {
                String::new()
            }
        ))
        .on_hover_text("with accumulation on, the GI buffer is the mean over frames; the story is one frame");
        let leaves = self.leaves();
        let links = self.links.clone();
        let topo = Topology::of(leaves, &links);
        let level = |n: u32| topo.depth(n.max(1));
        self.samples_table(ui, &t, &level);
        self.selected_path(ui, &t, &level, leaves);
        ui.separator();
        ui.strong("Tree view: the paths over the levels");
        self.tree_view(ui, &t);
    }

    /// A method's overlay story: its table, and the switch that draws it in the views.
    fn overlay_contents(&mut self, ui: &mut egui::Ui) {
        let Some(m) = &self.method_overlay else {
            return;
        };
        let (x, y) = self.pixel.unwrap_or_default();
        ui.label(format!("Pixel ({x}, {y}) · last frame · {}", m.title));
        ui.checkbox(&mut self.overlay, "draw it in the camera views")
            .on_hover_text(&m.key);
        ui.label(egui::RichText::new(&m.key).small());
        egui::Grid::new("method_overlay_rows")
            .striped(true)
            .show(ui, |ui| {
                for (k, v) in &m.rows {
                    ui.label(k);
                    ui.label(v);
                    ui.end_row();
                }
            });
    }

    /// The samples: slot, origin, start and end node, steps, stop, path probability,
    /// shadow ray, contribution; clicking a slot selects it.
    fn samples_table(&mut self, ui: &mut egui::Ui, t: &PixelTrace, level: &dyn Fn(u32) -> u32) {
        egui::ScrollArea::vertical()
            .id_salt("story_samples")
            .max_height(220.0)
            .show(ui, |ui| {
                egui::Grid::new("story_samples_grid")
                    .striped(true)
                    .show(ui, |ui| {
                        for h in [
                            "slot",
                            "from",
                            "start (level)",
                            "end (level)",
                            "steps",
                            "stopped at",
                            "p(path)",
                            "shadow ray",
                            "contribution (lum.)",
                        ] {
                            ui.strong(h);
                        }
                        ui.end_row();
                        for (i, s) in t.samples.iter().enumerate() {
                            let sel = self.selected == Some(i);
                            if ui.selectable_label(sel, s.cut_slot.to_string()).clicked() {
                                self.selected = if sel { None } else { Some(i) };
                            }
                            ui.label(match s.slot {
                                Some(k) => format!("block {}", t.blocks[k]),
                                None => {
                                    ["cut", "mock cut", "root", "own cut"][t.mode.min(3) as usize].to_string()
                                }
                            });
                            ui.label(if s.start == 0 {
                                "–".into()
                            } else {
                                format!("{} ({})", s.start, level(s.start))
                            });
                            ui.label(if s.end == 0 {
                                "–".into()
                            } else {
                                format!("{} ({})", s.end, level(s.end))
                            });
                            ui.label(s.steps.to_string());
                            ui.label(s.stop.name());
                            ui.label(if s.start == 0 {
                                "–".into()
                            } else {
                                format!("{:.3e}", s.prob)
                            });
                            let (txt, c) = match s.point.map(|p| p.1) {
                                Some(SampleVisibility::Visible) => ("visible", VISIBLE),
                                Some(SampleVisibility::Blocked) => ("blocked", BLOCKED),
                                Some(SampleVisibility::FacingAway) => ("facing away", AWAY),
                                None => ("–", AWAY),
                            };
                            ui.colored_label(c, txt);
                            ui.label(format!("{:.4e}", luminance(s.contribution)));
                            ui.end_row();
                        }
                    });
            });
    }

    /// The selected sample's path: a row per step (level, node, p(child), usable, v, σ_z,
    /// flux).
    fn selected_path(&self, ui: &mut egui::Ui, t: &PixelTrace, level: &dyn Fn(u32) -> u32, leaves: u32) {
        if let Some(i) = self.selected
            && let Some(s) = t.samples.get(i)
        {
            ui.separator();
            ui.strong(format!("Slot {}: path from node {}", s.cut_slot, s.start));
            if let Some((p, _)) = s.point {
                ui.label(format!("sampled point ({:.3}, {:.3}, {:.3}) m", p.x, p.y, p.z));
            }
            egui::Grid::new("story_path").striped(true).show(ui, |ui| {
                for h in [
                    "level",
                    "node",
                    "p(child)",
                    "usable",
                    "v",
                    "σ_z (m)",
                    "flux (lum., W)",
                ] {
                    ui.strong(h);
                }
                ui.end_row();
                let rows = std::iter::once((s.start, None)).chain(s.path.iter().map(|&(n, p)| (n, Some(p))));
                for (n, p) in rows {
                    let node = self.node(n);
                    ui.label(level(n).to_string());
                    ui.label(if n >= leaves {
                        format!("{n} (leaf)")
                    } else {
                        n.to_string()
                    });
                    ui.label(p.map_or("start".into(), |p| format!("{p:.4}")));
                    ui.label(if self.usable(n) { "yes" } else { "no" });
                    ui.label(format!("{:.3}", node.v));
                    ui.label(format!("{:.4}", node.sigma_z()));
                    ui.label(format!("{:.5}", luminance(node.intensity)));
                    ui.end_row();
                }
            });
            if s.path.len() < s.steps as usize {
                ui.label(format!(
                    "(the first {} of {} steps are recorded)",
                    s.path.len(),
                    s.steps
                ));
            }
        }
    }

    /// Levels top to bottom (root first), each node at its position within its level; the
    /// samples' paths as lines, start nodes as squares, end nodes as dots (by stop reason),
    /// the usable fraction of each level at the right.
    fn tree_view(&self, ui: &mut egui::Ui, t: &PixelTrace) {
        let levels = self.levels.len().max(1);
        let row = 16.0;
        let width = ui.available_width().clamp(240.0, 900.0);
        let (rect, _) =
            ui.allocate_exact_size(egui::vec2(width, row * levels as f32 + 8.0), egui::Sense::hover());
        let p = ui.painter_at(rect);
        let plot_w = rect.width() - 150.0;
        p.rect_filled(rect, 2.0, egui::Color32::from_gray(20));
        // A node sits at its depth, over the middle of its leaf range (on the perfect tree:
        // its position within its level).
        let topo = Topology::of(self.leaves, &self.links);
        let pos = |n: u32| {
            let n = n.max(1);
            let l = topo.depth(n);
            let (a, b) = topo.leaf_range(n);
            let u = (a + b + 1) as f32 * 0.5 / topo.leaves as f32;
            egui::pos2(
                rect.left() + 4.0 + u * plot_w,
                rect.top() + 4.0 + (l as f32 + 0.5) * row,
            )
        };
        for (l, (count, usable)) in self.levels.iter().enumerate() {
            let y = rect.top() + 4.0 + (l as f32 + 0.5) * row;
            p.line_segment(
                [
                    egui::pos2(rect.left() + 4.0, y),
                    egui::pos2(rect.left() + 4.0 + plot_w, y),
                ],
                egui::Stroke::new(1.0, egui::Color32::from_gray(45)),
            );
            p.text(
                egui::pos2(rect.left() + plot_w + 12.0, y),
                egui::Align2::LEFT_CENTER,
                if *count > 0 {
                    format!("L{l}: {usable}/{count} usable")
                } else {
                    format!("depth {l}")
                },
                egui::FontId::monospace(10.0),
                egui::Color32::from_gray(200),
            );
        }
        for (i, s) in t.samples.iter().enumerate() {
            if s.start == 0 {
                continue;
            }
            let sel = self.selected == Some(i);
            let alpha = if self.selected.is_none() || sel { 1.0 } else { 0.2 };
            let mut prev = pos(s.start);
            for &(n, _) in &s.path {
                let q = pos(n);
                p.line_segment(
                    [prev, q],
                    egui::Stroke::new(if sel { 2.0 } else { 1.0 }, PATH.gamma_multiply(alpha)),
                );
                prev = q;
            }
            p.rect_filled(
                egui::Rect::from_center_size(pos(s.start), egui::vec2(5.0, 5.0)),
                0.0,
                egui::Color32::WHITE.gamma_multiply(alpha),
            );
            if s.end != 0 {
                let c = match s.stop {
                    StopReason::Usable => NODE,
                    StopReason::Leaf => VISIBLE,
                    _ => BLOCKED,
                };
                p.circle_filled(pos(s.end), if sel { 4.0 } else { 3.0 }, c.gamma_multiply(alpha));
            }
        }
        ui.label(
            egui::RichText::new("squares: start nodes (cut or mock cut); dots: stopped at a usable node (yellow) or a leaf (green)")
                .small(),
        );
    }
}

/// The 1-sigma ellipse of a node's substitute distribution in its plane.
fn ellipse(node: &SstNode, color: egui::Color32) -> Prim {
    let (t, b) = basis(node.normal);
    let sx = node.variance.x.max(0.0).sqrt();
    let sy = node.variance.y.max(0.0).sqrt();
    Prim::Ellipse {
        center: node.position,
        axes: [t * sx, b * sy],
        color: rgba8(color),
    }
}

/// The 4 surrounding block cuts of Algorithm 1 (their bilinear weights, similarity, blend
/// weights) and whether the pixel fell back.
fn blocks_section(ui: &mut egui::Ui, t: &PixelTrace) {
    ui.separator();
    ui.strong("The 4 surrounding block cuts (Algorithm 1)");
    egui::Grid::new("story_blocks").striped(true).show(ui, |ui| {
        for h in ["", "block", "bilinear", "similar (S)", "blend weight"] {
            ui.strong(h);
        }
        ui.end_row();
        for i in 0..4 {
            ui.label(["top-left", "top-right", "bottom-left", "bottom-right"][i]);
            ui.label(t.blocks[i].to_string());
            ui.label(format!("{:.3}", t.bilinear[i]));
            ui.label(if t.bilinear[i] <= 0.0 {
                "–"
            } else if t.weights[i] > 0.0 {
                "yes"
            } else {
                "no"
            });
            let w = if t.weight_sum > 0.0 {
                t.weights[i] / t.weight_sum
            } else {
                0.0
            };
            ui.label(format!("{:.3}", w));
            ui.end_row();
        }
    });
    if t.fell_back {
        ui.label(
            egui::RichText::new(format!("no similar cut: fell back to the {}", t.mode_name()))
                .color(ui.visuals().warn_fg_color),
        );
    }
}

//! The light tree (SST) in the workbench: controls in the side panel (thresholds, overlay,
//! freeze) and a statistics window (levels, usable nodes per level, histograms of v and
//! sigma_z with the thresholds marked, GPU times of sort and build).

use egui_plot::{Bar, BarChart, Plot, VLine};

use crate::{
    base::sst_node::{Topology, TreeStats, luminance, stats_on},
    renderer::{
        Renderer,
        settings::{RenderSettings, TreeColor, TreeOverlay},
        timing::PassTimings,
    },
};

/// Trees up to this many leaves are read back for the statistics automatically (twice a
/// second); larger ones on request.
const AUTO_REFRESH_LEAVES: u32 = 1 << 16;

/// Counts of `values` in `bins` equal bins over [lo, hi] (values outside go to the end bins).
pub fn histogram(values: impl IntoIterator<Item = f32>, lo: f32, hi: f32, bins: usize) -> Vec<u32> {
    let mut h = vec![0u32; bins.max(1)];
    let n = h.len();
    for v in values {
        if !v.is_finite() {
            continue;
        }
        let t = ((v - lo) / (hi - lo) * n as f32).floor();
        h[(t.max(0.0) as usize).min(n - 1)] += 1;
    }
    h
}

/// Decades of sigma_z the histogram spans: 0.1 mm .. 10 m (smaller values, exactly flat
/// clusters included, count in the first bin).
const SIGMA_LOG_RANGE: (f32, f32) = (-4.0, 1.0);

#[derive(Default)]
pub struct TreePanel {
    pub show_stats: bool,
    pub freeze: bool,
    stats: Option<TreeStats>,
    last_refresh: f64,
    refresh_requested: bool,
}

impl TreePanel {
    /// Forgets when the statistics were last read (a new window's clock starts again at 0).
    pub fn forget_refresh_time(&mut self) {
        self.last_refresh = f64::NEG_INFINITY;
        self.refresh_requested = true;
    }
    pub fn new(show_stats: bool) -> Self {
        Self {
            show_stats,
            ..Default::default()
        }
    }

    /// Side-panel section. `levels`: the current tree's level count, if any.
    pub fn controls(&mut self, ui: &mut egui::Ui, settings: &mut RenderSettings, levels: Option<u32>) {
        ui.heading("Light tree (SST)");
        let method = settings.gi.method;
        let t = &mut settings.tree;
        egui::ComboBox::from_label("tree")
            .selected_text(t.kind.name())
            .show_ui(ui, |ui| {
                for k in crate::settings::TreeKind::ALL {
                    ui.selectable_value(&mut t.kind, k, k.label());
                }
            })
            .response
            .on_hover_text(
                "the tree the samplers traverse: the thesis's perfect binary tree (VPLs padded to a \
                 power of two, children 2i, 2i+1) or the SST paper's radix tree (Karras 2012: split where \
                 the sorted keys' highest differing bit changes)",
            );
        if let Some(msg) = method.refuses_tree(t.kind) {
            ui.colored_label(
                egui::Color32::YELLOW,
                format!("{msg}: this frame builds the perfect tree"),
            );
        }
        ui.add(egui::Slider::new(&mut t.v_min, 0.0..=1.0).text("v_min"))
            .on_hover_text("least normal similarity v (eq. 4.3) of a node usable for sampling");
        ui.add(
            egui::Slider::new(&mut t.sigma_max, 0.001..=10.0)
                .logarithmic(true)
                .text("σ_max (m)"),
        )
        .on_hover_text("largest standard deviation along the node's normal of a usable node");
        let d = &mut settings.display;
        egui::ComboBox::from_label("tree overlay")
            .selected_text(d.tree_overlay.name())
            .show_ui(ui, |ui| {
                for o in TreeOverlay::ALL {
                    ui.selectable_value(&mut d.tree_overlay, o, o.name());
                }
            });
        if d.tree_overlay != TreeOverlay::Off {
            let max_level = levels.unwrap_or(21).saturating_sub(1).min(47);
            d.tree_level = d.tree_level.min(max_level);
            ui.add(egui::Slider::new(&mut d.tree_level, 0..=max_level).text("tree level"))
                .on_hover_text(format!(
                    "0 = the root. The perfect tree: {max_level} = the leaves (the VPLs); level l has 2^l \
                     nodes. The radix tree: level l is the cut of the nodes at depth l and the leaves \
                     above it (past its deepest leaf, the leaves)."
                ));
            ui.checkbox(&mut d.tree_compare, "both trees side by side")
                .on_hover_text(
                    "the perfect binary tree over the left half of the view, the radix tree (LBVH) over \
                     the right half: the same level of both trees over the same VPLs (the frame builds \
                     the tree it does not sample too, untimed)",
                );
            if d.tree_compare {
                ui.label("left: perfect binary tree · right: radix tree (LBVH)");
            }
            egui::ComboBox::from_label("colour by")
                .selected_text(d.tree_color.name())
                .show_ui(ui, |ui| {
                    for c in TreeColor::ALL {
                        ui.selectable_value(&mut d.tree_color, c, c.name());
                    }
                });
        }
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.freeze, "freeze VPLs and tree")
                .on_hover_text(
                    "keep this frame's VPLs and tree while the camera moves; thresholds still apply",
                );
            ui.checkbox(&mut self.show_stats, "statistics");
        });
    }

    /// Reads the tree back for the statistics when the window is open (throttled).
    pub fn refresh(&mut self, renderer: &Renderer, now: f64) -> Result<(), String> {
        if !self.show_stats {
            return Ok(());
        }
        let leaves = renderer.tree_buffers().1.leaves;
        let due = now - self.last_refresh > 0.5 && leaves <= AUTO_REFRESH_LEAVES;
        if !(due || self.refresh_requested || self.stats.is_none()) {
            return Ok(());
        }
        self.refresh_requested = false;
        self.last_refresh = now;
        let (nodes, flags) = renderer.read_tree().map_err(|e| e.to_string())?;
        let links = renderer.read_tree_links().map_err(|e| e.to_string())?;
        let topo = Topology::of((nodes.len() / 2) as u32, &links);
        self.stats = Some(stats_on(&nodes, &flags, topo));
        Ok(())
    }

    /// The statistics window.
    pub fn window(&mut self, ctx: &egui::Context, settings: &RenderSettings, timings: Option<&PassTimings>) {
        let mut open = self.show_stats;
        // Top right, over the viewport rather than the side panel.
        let right = ctx.content_rect().right();
        egui::Window::new("Light tree statistics")
            .open(&mut open)
            .default_width(360.0)
            .default_pos(egui::pos2(right - 390.0, 30.0))
            .show(ctx, |ui| self.window_contents(ui, settings, timings));
        self.show_stats = open;
    }

    fn window_contents(
        &mut self,
        ui: &mut egui::Ui,
        settings: &RenderSettings,
        timings: Option<&PassTimings>,
    ) {
        let Some(s) = &self.stats else {
            ui.label("no tree yet");
            return;
        };
        ui.label(format!(
            "{} VPLs in {} leaves, {} levels; root flux {:.4} {:.4} {:.4} W (lum. {:.4} W)",
            s.valid_leaves,
            s.leaves,
            s.levels,
            s.root_intensity.x,
            s.root_intensity.y,
            s.root_intensity.z,
            luminance(s.root_intensity)
        ))
        .on_hover_text(
            "the VPLs' total flux: an unbiased estimate of the RSMs' reflected flux (status line)",
        );
        if let Some(t) = timings {
            let get = |n| t.get(n).map_or("–".to_string(), |ms| format!("{ms:.3} ms"));
            let build = match (t.get("sst_build"), t.get("lbvh_build"), t.get("lbvh_nodes")) {
                (Some(ms), _, _) => format!("build {ms:.3} ms"),
                (None, Some(a), Some(b)) => format!("radix build {a:.3} + nodes {b:.3} ms"),
                _ => "build –".to_string(),
            };
            ui.label(format!(
                "GPU: keys {} · sort {} · {build} · classify {}",
                get("sst_keys"),
                get("sst_sort"),
                get("sst_classify")
            ));
        }
        if s.leaves > AUTO_REFRESH_LEAVES && ui.button("Refresh").clicked() {
            self.refresh_requested = true;
        }
        ui.separator();
        let th = &settings.tree;
        ui.label(format!(
            "usable = v ≥ {:.2} and σ_z < {:.3} m (SST paper eq. 3)",
            th.v_min, th.sigma_max
        ));
        egui::ScrollArea::vertical()
            .id_salt("tree_levels")
            .max_height(150.0)
            .show(ui, |ui| {
                egui::Grid::new("tree_levels_grid").striped(true).show(ui, |ui| {
                    ui.strong("level");
                    ui.strong("nodes");
                    ui.strong("usable");
                    ui.strong("share");
                    ui.end_row();
                    for (l, (n, u)) in s.per_level.iter().enumerate() {
                        ui.label(l.to_string());
                        ui.label(n.to_string());
                        ui.label(u.to_string());
                        ui.label(if *n > 0 {
                            format!("{:.1}%", 100.0 * *u as f64 / *n as f64)
                        } else {
                            "–".into()
                        });
                        ui.end_row();
                    }
                });
            });
        ui.separator();
        let inner = s.v.len();
        ui.label(format!("normal similarity v of the {inner} inner nodes"));
        let bins = 20;
        let hv = histogram(s.v.iter().copied(), 0.0, 1.0, bins);
        let bars: Vec<Bar> = hv
            .iter()
            .enumerate()
            .map(|(i, c)| Bar::new((i as f64 + 0.5) / bins as f64, *c as f64).width(1.0 / bins as f64))
            .collect();
        Plot::new("tree_v_hist")
            .height(110.0)
            .allow_scroll(false)
            .allow_zoom(false)
            .allow_drag(false)
            .x_axis_label("v")
            .show(ui, |p| {
                p.bar_chart(BarChart::new("nodes", bars).color(egui::Color32::LIGHT_BLUE));
                p.vline(VLine::new("v_min", th.v_min as f64).color(egui::Color32::YELLOW));
            });
        ui.label("σ_z of the inner nodes (log10 m; the first bin holds all ≤ 0.1 mm)");
        let (lo, hi) = SIGMA_LOG_RANGE;
        let bins = 25;
        let hs = histogram(s.sigma_z.iter().map(|z| z.max(1e-30).log10()), lo, hi, bins);
        let w = (hi - lo) as f64 / bins as f64;
        let bars: Vec<Bar> = hs
            .iter()
            .enumerate()
            .map(|(i, c)| Bar::new(lo as f64 + (i as f64 + 0.5) * w, *c as f64).width(w))
            .collect();
        Plot::new("tree_sigma_hist")
            .height(110.0)
            .allow_scroll(false)
            .allow_zoom(false)
            .allow_drag(false)
            .x_axis_label("log10 σ_z (m)")
            .show(ui, |p| {
                p.bar_chart(BarChart::new("nodes", bars).color(egui::Color32::LIGHT_GREEN));
                p.vline(
                    VLine::new("σ_max", (th.sigma_max.max(1e-30)).log10() as f64)
                        .color(egui::Color32::YELLOW),
                );
            });
    }
}

#[cfg(test)]
mod tests {
    use super::histogram;

    #[test]
    fn histogram_bins_and_clamps() {
        let h = histogram(
            [0.0, 0.05, 0.1, 0.5, 0.99, 1.0, -3.0, 7.0, f32::NAN],
            0.0,
            1.0,
            10,
        );
        assert_eq!(h, vec![3, 1, 0, 0, 0, 1, 0, 0, 0, 3]);
        assert_eq!(h.iter().sum::<u32>(), 8);
    }
}

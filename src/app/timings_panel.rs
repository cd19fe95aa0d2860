//! Per-pass GPU timings: the latest frame as bars and the recent history as lines
//! (egui_plot). Hovering a pass shows that pass's output in the viewport (where the pass has a
//! viewable output; those bars are blue).

use std::collections::VecDeque;

use egui_plot::{Legend, Line, Plot, PlotPoints};

use crate::gpu::timing::PassTimings;
use crate::settings::ViewBuffer;

/// Frames of history kept.
pub const HISTORY: usize = 240;

/// The buffer a pass writes, if it has one the viewport can show.
pub fn pass_output(pass: &str) -> Option<ViewBuffer> {
    Some(match pass {
        "rsm" => ViewBuffer::RsmFlux,
        "gbuffer" => ViewBuffer::Albedo,
        "direct" => ViewBuffer::Direct,
        "brsm_importance" => ViewBuffer::ImportanceRaw,
        "brsm_filter" => ViewBuffer::ImportanceFiltered,
        "pdf_pyramid" => ViewBuffer::PdfPyramid,
        "gi_upsample" => ViewBuffer::Indirect,
        "composite" | "display" => ViewBuffer::Final,
        // A method's pass: the view it declares for it, else its GI.
        p => {
            let m = crate::methods::REGISTRY
                .iter()
                .find(|m| m.timed_passes.contains(&p) || m.views.iter().any(|v| v.passes.contains(&p)))?;
            match m.views.iter().find(|v| v.passes.contains(&p)) {
                Some(v) => ViewBuffer::Method(crate::methods::MethodView::new(v.name)),
                None => ViewBuffer::Indirect,
            }
        }
    })
}

#[derive(Default)]
pub struct TimingsPanel {
    pub show: bool,
    history: VecDeque<PassTimings>,
}

impl TimingsPanel {
    pub fn new(show: bool) -> Self {
        Self {
            show,
            ..Default::default()
        }
    }

    /// Records a frame's timings (repeats of the last one are ignored).
    pub fn push(&mut self, t: &PassTimings) {
        if self.history.back().is_some_and(|l| l.passes == t.passes) {
            return;
        }
        if self.history.len() == HISTORY {
            self.history.pop_front();
        }
        self.history.push_back(t.clone());
    }

    pub fn len(&self) -> usize {
        self.history.len()
    }

    pub fn is_empty(&self) -> bool {
        self.history.is_empty()
    }

    /// The bars and the history; returns the view to show while a bar is hovered.
    pub fn contents(&self, ui: &mut egui::Ui) -> Option<ViewBuffer> {
        let Some(last) = self.history.back() else {
            ui.label(
                "no timed frame yet: every 4th frame records diagnostics untimed, and the \
                 first timestamps arrive a frame or two late (or timestamps are not supported \
                 on this adapter)",
            );
            return None;
        };
        ui.label(format!(
            "last timed frame: {:.3} ms GPU over {} passes (GPU timestamps of frames without diagnostics: every {}th frame records them untimed; the comparison's ground truth is never timed); hover a blue pass to see its output",
            last.total_ms(),
            last.passes.len(),
            super::GUI_DIAGNOSTICS_EVERY
        ));
        // One row per pass: name, a bar to scale, the time; hovering a row shows the pass's
        // output in the viewport.
        let max = last.passes.iter().map(|p| p.1).fold(1e-9, f64::max);
        let mut hovered = None;
        egui::Grid::new("timings_rows").num_columns(3).show(ui, |ui| {
            for (name, ms) in &last.passes {
                let label = ui.label(egui::RichText::new(name).monospace());
                let (rect, bar) = ui.allocate_exact_size(egui::vec2(220.0, 14.0), egui::Sense::hover());
                let w = (rect.width() as f64 * ms / max) as f32;
                let output = pass_output(name);
                let color = if output.is_some() {
                    egui::Color32::from_rgb(90, 160, 230)
                } else {
                    egui::Color32::from_gray(140)
                };
                ui.painter().rect_filled(
                    egui::Rect::from_min_size(rect.min, egui::vec2(w.max(1.0), rect.height())),
                    2.0,
                    color,
                );
                let value = ui.label(egui::RichText::new(format!("{ms:>9.3} ms")).monospace());
                if label.hovered() || bar.hovered() || value.hovered() {
                    hovered = output;
                }
                ui.end_row();
            }
        });
        ui.separator();
        ui.label(format!(
            "history ({} frames): total and the 4 slowest passes",
            self.history.len()
        ));
        let mut top: Vec<(String, f64)> = last.passes.clone();
        top.sort_by(|a, b| b.1.total_cmp(&a.1));
        top.truncate(4);
        Plot::new("timings_history")
            .height(160.0)
            .legend(Legend::default())
            .x_axis_label("frame")
            .y_axis_label("ms")
            .show(ui, |p| {
                let total: PlotPoints = self
                    .history
                    .iter()
                    .enumerate()
                    .map(|(i, t)| [i as f64, t.total_ms()])
                    .collect();
                p.line(Line::new("total", total));
                for (name, _) in &top {
                    let pts: PlotPoints = self
                        .history
                        .iter()
                        .enumerate()
                        .filter_map(|(i, t)| t.get(name).map(|ms| [i as f64, ms]))
                        .collect();
                    p.line(Line::new(name.clone(), pts));
                }
            });
        hovered
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(ms: f64) -> PassTimings {
        PassTimings {
            passes: vec![("rsm".into(), ms), ("gbuffer".into(), 2.0 * ms)],
        }
    }

    #[test]
    fn history_drops_repeats_and_keeps_the_last_frames() {
        let mut p = TimingsPanel::default();
        p.push(&t(1.0));
        p.push(&t(1.0));
        assert_eq!(p.len(), 1);
        for i in 0..HISTORY + 10 {
            p.push(&t(i as f64 + 2.0));
        }
        assert_eq!(p.len(), HISTORY);
        assert_eq!(pass_output("gbuffer"), Some(ViewBuffer::Albedo));
        assert_eq!(pass_output("sst_sort"), None);
    }
}

//! The workbench's inspectors (pixel values, the cut inspector; shown in the tool dock) and
//! small windows and drawing helpers: problems, heat-map legends.

use super::*;

impl WorkbenchApp {
    /// The values of every buffer at the inspected pixel.
    pub(super) fn pixel_contents(&mut self, ui: &mut egui::Ui) {
        let p = &mut self.pixel;
        match p.pixel {
            Some((x, y)) => ui.label(format!(
                "Pixel ({x}, {y}){}",
                if p.pinned { " · pinned" } else { "" }
            )),
            None => ui.label("Pixel values: no pixel yet"),
        };
        ui.checkbox(&mut p.pinned, "pinned (P)");
        if p.rows.is_empty() {
            ui.label("hover the image (camera-space views)");
            return;
        }
        egui::Grid::new("pixel_grid").striped(true).show(ui, |ui| {
            for h in ["buffer", "r / x", "g / y", "b / z", "a / w"] {
                ui.strong(h);
            }
            ui.end_row();
            for (name, v) in &p.rows {
                ui.label(*name);
                for c in v {
                    ui.label(egui::RichText::new(format!("{c:.5e}")).monospace());
                }
                ui.end_row();
            }
        });
    }

    /// The nodes of the clicked block's cut.
    pub(super) fn cut_contents(&mut self, ui: &mut egui::Ui) {
        let Some(ci) = &self.cut_inspect else {
            ui.label("click a block in a cut view (cuts per block, cut depth per block)");
            return;
        };
        ui.label(format!("Cut of block ({}, {})", ci.block.0, ci.block.1));
        if ci.rows.is_empty() {
            ui.label("empty: the block centre sees no geometry, or no node can light it");
            return;
        }
        let total: f32 = ci.rows.iter().map(|r| luminance(r.1.intensity)).sum();
        ui.label(format!(
            "{} nodes; share of the root's flux: {:.1}%",
            ci.rows.len(),
            100.0 * total / ci.root_flux.max(1e-30)
        ));
        egui::Grid::new("cut_grid").striped(true).show(ui, |ui| {
            for h in [
                "slot",
                "node",
                "level",
                "flux (lum., W)",
                "v",
                "σ_z (m)",
                "usable",
            ] {
                ui.strong(h);
            }
            ui.end_row();
            for (i, (n, node, usable)) in ci.rows.iter().enumerate() {
                ui.label(i.to_string());
                ui.label(n.to_string());
                let level = ci.depths.get(i).copied().unwrap_or(0);
                let leaf = *n >= ci.leaves;
                ui.label(if leaf {
                    format!("{level} (leaf)")
                } else {
                    level.to_string()
                });
                ui.label(format!("{:.5}", luminance(node.intensity)));
                ui.label(format!("{:.3}", node.v));
                ui.label(format!("{:.4}", node.sigma_z()));
                ui.label(if *usable { "yes" } else { "no" });
                ui.end_row();
            }
        });
    }

    pub(super) fn error_window(&mut self, ctx: &egui::Context) {
        if self.errors.is_empty() {
            return;
        }
        let mut dismiss = false;
        egui::Window::new("Problems")
            .collapsible(false)
            .default_width(420.0)
            .show(ctx, |ui| {
                for e in &self.errors {
                    ui.label(egui::RichText::new(plain_text(e)).color(ui.visuals().warn_fg_color));
                }
                if ui.button("Dismiss").clicked() {
                    dismiss = true;
                }
            });
        if dismiss {
            self.errors.clear();
        }
    }
}

/// `s` with box-drawing characters (naga's error frames) as ASCII: the GUI's proportional
/// font has none of them, and a missing glyph must not cost the message.
pub(super) fn plain_text(s: &str) -> String {
    s.chars()
        .map(|c| match c {
            '─' | '━' | '═' => '-',
            '│' | '┃' | '║' => '|',
            '\u{2500}'..='\u{257f}' => '+',
            c => c,
        })
        .collect()
}

/// A false-colour legend in the bottom-left corner of `rect`.
/// The VPL overlay's legend when it colours by bounce: a swatch per bounce 1..=`bounces`.
pub(super) fn bounce_legend(painter: &egui::Painter, rect: egui::Rect, bounces: u32) {
    let n = bounces.clamp(1, 8);
    let cell = 26.0;
    let bar = egui::Rect::from_min_size(
        rect.left_bottom() + egui::vec2(12.0, -34.0),
        egui::vec2(cell * n as f32, 12.0),
    );
    painter.rect_filled(
        bar.expand2(egui::vec2(6.0, 22.0))
            .translate(egui::vec2(0.0, -8.0)),
        4.0,
        egui::Color32::from_black_alpha(170),
    );
    let font = egui::FontId::proportional(11.0);
    let text = egui::Color32::from_gray(230);
    painter.text(
        bar.left_top() - egui::vec2(0.0, 3.0),
        egui::Align2::LEFT_BOTTOM,
        "VPL bounce",
        font.clone(),
        text,
    );
    for b in 1..=n {
        let [r, g, bl] = crate::base::colormap::bounce_color(b).map(|v| (v * 255.0) as u8);
        let x0 = bar.left() + cell * (b - 1) as f32;
        let sw = egui::Rect::from_min_size(egui::pos2(x0, bar.top()), egui::vec2(cell - 4.0, 12.0));
        painter.rect_filled(sw, 2.0, egui::Color32::from_rgb(r, g, bl));
        painter.text(
            sw.center_bottom() + egui::vec2(0.0, 2.0),
            egui::Align2::CENTER_TOP,
            b.to_string(),
            font.clone(),
            text,
        );
    }
}

pub(super) fn legend_with(
    painter: &egui::Painter,
    rect: egui::Rect,
    title: &str,
    lo: f32,
    hi: f32,
    scale: Scale,
) {
    let w = 220.0;
    let bar = egui::Rect::from_min_size(rect.left_bottom() + egui::vec2(12.0, -34.0), egui::vec2(w, 12.0));
    painter.rect_filled(
        bar.expand2(egui::vec2(6.0, 22.0))
            .translate(egui::vec2(0.0, -8.0)),
        4.0,
        egui::Color32::from_black_alpha(170),
    );
    let steps = 64;
    for k in 0..steps {
        let t = (k as f32 + 0.5) / steps as f32;
        let c = crate::base::colormap::false_color(t);
        let [r, g, b] = c.map(|v| (v * 255.0) as u8);
        let x0 = bar.left() + w * k as f32 / steps as f32;
        painter.rect_filled(
            egui::Rect::from_min_max(
                egui::pos2(x0, bar.top()),
                egui::pos2(x0 + w / steps as f32 + 0.5, bar.bottom()),
            ),
            0.0,
            egui::Color32::from_rgb(r, g, b),
        );
    }
    let font = egui::FontId::proportional(11.0);
    let text = egui::Color32::from_gray(230);
    painter.text(
        bar.left_top() - egui::vec2(0.0, 3.0),
        egui::Align2::LEFT_BOTTOM,
        title,
        font.clone(),
        text,
    );
    let ticks = match scale {
        Scale::Log10 => (hi - lo).round().max(1.0) as i32,
        Scale::Linear => {
            let span = (hi - lo).max(1e-6);
            let mut n = span.round().max(1.0) as i32;
            while n > 6 {
                n = (n + 1) / 2;
            }
            n
        }
    };
    for d in 0..=ticks {
        let x = bar.left() + w * d as f32 / ticks as f32;
        let label = match scale {
            Scale::Log10 => match lo as i32 + d {
                0 => "1".to_string(),
                e if e > 0 => format!("{}", 10i64.pow(e as u32)),
                e => format!("1e{e}"),
            },
            Scale::Linear => {
                let v = lo + (hi - lo) * d as f32 / ticks as f32;
                if (v - v.round()).abs() < 1e-3 {
                    format!("{}", v.round() as i64)
                } else {
                    format!("{v:.1}")
                }
            }
        };
        painter.text(
            egui::pos2(x, bar.bottom() + 2.0),
            egui::Align2::CENTER_TOP,
            label,
            font.clone(),
            text,
        );
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn shader_error_frames_become_ascii() {
        let naga = "error: bad\n    ┌─ wgsl:190:9\n    │\n190 │     let x";
        assert_eq!(
            super::plain_text(naga),
            "error: bad\n    +- wgsl:190:9\n    |\n190 |     let x"
        );
    }
}

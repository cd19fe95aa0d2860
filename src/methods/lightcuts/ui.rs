//! Lightcuts' settings in the GUI.

use super::settings::LightcutsSettings;
use crate::methods::MethodId;
use crate::reference::lightcuts::MAX_CUT;
use crate::renderer::settings::RenderSettings;

pub fn settings_ui(ui: &mut egui::Ui, method: MethodId, s: &mut RenderSettings) {
    let mut lc: LightcutsSettings = match s.method(method) {
        Ok(v) => v,
        Err(e) => {
            ui.colored_label(egui::Color32::LIGHT_RED, e);
            return;
        }
    };
    let before = lc.clone();
    ui.add(
        egui::Slider::new(&mut lc.relative_error, 0.0..=0.2)
            .logarithmic(true)
            .smallest_positive(1e-4)
            .text("relative error"),
    )
    .on_hover_text(
        "refine while the largest error bound exceeds this fraction of the pixel's estimate \
         (Walter et al. 2%, the interpolation paper 1%)",
    );
    ui.add(
        egui::Slider::new(&mut lc.max_cut, 1..=MAX_CUT)
            .logarithmic(true)
            .text("max cut size"),
    )
    .on_hover_text("nodes per pixel at most; dark pixels reach it first");
    if lc != before {
        // Cannot fail: the struct serialises to a table.
        let _ = s.set_method(method, &lc);
    }
}

//! The converged reference's settings in the GUI.

use crate::methods::MethodId;
use crate::renderer::settings::RenderSettings;

pub fn settings_ui(ui: &mut egui::Ui, _: MethodId, s: &mut RenderSettings) {
    let g = &mut s.gi;
    ui.add(
        egui::Slider::new(&mut g.reference_samples, 16..=65536)
            .logarithmic(true)
            .text("samples per pixel"),
    );
    ui.add(egui::Slider::new(&mut g.reference_spp_per_frame, 1..=64).text("samples / frame"));
    ui.add(egui::Slider::new(&mut g.reference_flux_mix, 0.01..=1.0).text("reference flux mix"))
        .on_hover_text("share of the texel PDF that follows flux (> 0 keeps it unbiased)");
    if s.vpl.bounces > 1 {
        let g = &mut s.gi;
        ui.add(egui::Slider::new(&mut g.reference_paths_per_sample, 1..=64).text("light paths / sample"))
            .on_hover_text("fresh light paths per sample for bounces 2..N, shaded at every pixel");
    }
}

//! The ground truth's settings in the GUI.

use crate::methods::MethodId;
use crate::renderer::settings::RenderSettings;

pub fn settings_ui(ui: &mut egui::Ui, _: MethodId, s: &mut RenderSettings) {
    ui.add(
        egui::Slider::new(&mut s.gi.rays_per_frame, 1 << 14..=1 << 26)
            .logarithmic(true)
            .text("shadow rays / frame"),
    )
    .on_hover_text("more finishes sooner, but each frame takes longer");
}

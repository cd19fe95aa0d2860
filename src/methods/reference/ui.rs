//! The converged reference's settings in the GUI.

use crate::methods::MethodId;
use crate::settings::RenderSettings;

pub fn settings_ui(ui: &mut egui::Ui, _: MethodId, s: &mut RenderSettings) {
    let bounces = s.vpl.bounces;
    for f in super::FIELDS {
        // Light paths only serve bounces 2..N.
        if f.spec.key == "reference_paths_per_sample" && bounces <= 1 {
            continue;
        }
        crate::methods::field_ui::slider(ui, f, &mut s.gi);
    }
}

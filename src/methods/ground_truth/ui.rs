//! The ground truth's settings in the GUI.

use crate::methods::MethodId;
use crate::settings::RenderSettings;

pub fn settings_ui(ui: &mut egui::Ui, _: MethodId, s: &mut RenderSettings) {
    for f in super::FIELDS {
        crate::methods::field_ui::slider(ui, f, &mut s.gi);
    }
}

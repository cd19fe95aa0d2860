//! Lightcut Interpolation's settings in the GUI.

use super::settings::{LiVisibility, LightcutInterpolationSettings};
use crate::methods::MethodId;
use crate::settings::RenderSettings;

pub fn settings_ui(ui: &mut egui::Ui, method: MethodId, s: &mut RenderSettings) {
    let mut li: LightcutInterpolationSettings = match s.method(method) {
        Ok(v) => v,
        Err(e) => {
            ui.colored_label(egui::Color32::LIGHT_RED, e);
            return;
        }
    };
    let before = li.clone();
    egui::ComboBox::from_label("visibility")
        .selected_text(li.visibility.label())
        .show_ui(ui, |ui| {
            for v in [LiVisibility::Full, LiVisibility::Interpolated] {
                ui.selectable_value(&mut li.visibility, v, v.label());
            }
        })
        .response
        .on_hover_text("shadow rays per interpolated node, or the records' visibility interpolated");
    for f in super::settings::FIELDS {
        crate::methods::field_ui::slider(ui, f, &mut li);
    }
    li.r_max_px = li.r_max_px.max(li.r_min_px);
    if li != before {
        // Cannot fail: the struct serialises to a table.
        let _ = s.set_method(method, &li);
    }
}

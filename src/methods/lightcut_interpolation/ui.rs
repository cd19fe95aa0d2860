//! Lightcut Interpolation's settings in the GUI.

use super::settings::{LiVisibility, LightcutInterpolationSettings};
use crate::methods::MethodId;
use crate::reference::lightcuts::MAX_CUT;
use crate::renderer::settings::RenderSettings;

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
    ui.add(
        egui::Slider::new(&mut li.relative_error, 0.0..=0.2)
            .logarithmic(true)
            .smallest_positive(1e-4)
            .text("record relative error"),
    )
    .on_hover_text("the records' (and fallback's) Lightcuts threshold (paper 1%)");
    ui.add(
        egui::Slider::new(&mut li.max_cut, 1..=MAX_CUT)
            .logarithmic(true)
            .text("max cut size"),
    );
    ui.add(
        egui::Slider::new(&mut li.r_min_px, 0.25..=64.0)
            .logarithmic(true)
            .text("R- (pixels)"),
    )
    .on_hover_text("smallest record reach in pixel sizes (paper 4)");
    ui.add(
        egui::Slider::new(&mut li.r_max_px, 0.25..=128.0)
            .logarithmic(true)
            .text("R+ (pixels)"),
    )
    .on_hover_text("largest record reach in pixel sizes (paper 15): fewer records when larger");
    li.r_max_px = li.r_max_px.max(li.r_min_px);
    ui.add(egui::Slider::new(&mut li.max_angle_deg, 1.0..=90.0).text("a+ (degrees)"))
        .on_hover_text("records whose normal deviates more are rejected (paper 15)");
    ui.add(egui::Slider::new(&mut li.epsilon, 0.0..=0.9).text("fallback epsilon"))
        .on_hover_text("pixels whose best record weight is below this compute a full lightcut");
    ui.add(egui::Slider::new(&mut li.coverage, 0.1..=4.0).text("placement coverage"))
        .on_hover_text("a pixel is covered once its tile's records' weights sum to this");
    ui.add(egui::Slider::new(&mut li.radius_rays, 1..=64).text("rays for R"))
        .on_hover_text("hemisphere rays per pixel for the harmonic mean distance");
    if li != before {
        // Cannot fail: the struct serialises to a table.
        let _ = s.set_method(method, &li);
    }
}

//! Lightcut Interpolation's settings in the GUI.

use super::settings::{LiVisibility, LightcutInterpolationSettings};
use crate::base::settings_ui::{SettingsUi, choose, slider};
use crate::methods::MethodId;
use crate::settings::RenderSettings;

pub fn settings_ui(ui: &mut dyn SettingsUi, method: MethodId, s: &mut RenderSettings) {
    let mut li: LightcutInterpolationSettings = match s.method(method) {
        Ok(v) => v,
        Err(e) => {
            ui.error(&e);
            return;
        }
    };
    let before = li.clone();
    choose(
        ui,
        "visibility",
        &mut li.visibility,
        &[LiVisibility::Full, LiVisibility::Interpolated],
        LiVisibility::label,
        "shadow rays per interpolated node, or the records' visibility interpolated",
    );
    for f in super::settings::FIELDS {
        slider(ui, f, &mut li);
    }
    li.r_max_px = li.r_max_px.max(li.r_min_px);
    if li != before {
        // Cannot fail: the struct serialises to a table.
        let _ = s.set_method(method, &li);
    }
}

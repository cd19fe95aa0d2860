//! The converged reference's settings in the GUI.

use crate::base::settings_ui::{SettingsUi, slider};
use crate::methods::MethodId;
use crate::settings::RenderSettings;

pub fn settings_ui(ui: &mut dyn SettingsUi, _: MethodId, s: &mut RenderSettings) {
    let bounces = s.vpl.bounces;
    for f in super::FIELDS {
        // Light paths only serve bounces 2..N.
        if f.spec.key == "reference_paths_per_sample" && bounces <= 1 {
            continue;
        }
        slider(ui, f, &mut s.gi);
    }
}

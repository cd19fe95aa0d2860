//! The ground truth's settings in the GUI.

use crate::base::settings_ui::{SettingsUi, slider};
use crate::methods::MethodId;
use crate::settings::RenderSettings;

pub fn settings_ui(ui: &mut dyn SettingsUi, _: MethodId, s: &mut RenderSettings) {
    for f in super::FIELDS {
        slider(ui, f, &mut s.gi);
    }
}

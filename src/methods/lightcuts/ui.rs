//! Lightcuts' settings in the GUI.

use super::settings::LightcutsSettings;
use crate::base::settings_ui::{SettingsUi, slider};
use crate::methods::MethodId;
use crate::settings::RenderSettings;

pub fn settings_ui(ui: &mut dyn SettingsUi, method: MethodId, s: &mut RenderSettings) {
    let mut lc: LightcutsSettings = match s.method(method) {
        Ok(v) => v,
        Err(e) => {
            ui.error(&e);
            return;
        }
    };
    let before = lc.clone();
    for f in super::settings::FIELDS {
        slider(ui, f, &mut lc);
    }
    if lc != before {
        // Cannot fail: the struct serialises to a table.
        let _ = s.set_method(method, &lc);
    }
}

//! The imperfect shadow maps' settings in the GUI (shared by the methods that build them:
//! light culling's adaptive maps, the VALs' maps).

use crate::base::settings_ui::{SettingsUi, slider_within};
use crate::settings::{IsmDefault, IsmSettings};

/// `m`'s sliders (`IsmSettings::fields`: the ranges validation uses); `light` names what a
/// map belongs to ("VPL", "VAL"), `paper_tile` and `paper_points` the method's paper values.
pub fn settings_ui<D: IsmDefault>(
    ui: &mut dyn SettingsUi,
    m: &mut IsmSettings<D>,
    light: &str,
    paper_tile: &str,
    paper_points: &str,
) {
    ui.text(&format!(
        "a map per {light} (paper: {paper_tile} maps, {paper_points} points each)"
    ));
    for f in IsmSettings::<D>::fields() {
        // The atlas holds at least one map and at most 255 a side (validation's rule).
        let (min, max) = if f.spec.key == "atlas" {
            (m.tile as f64, m.tile as f64 * 255.0)
        } else {
            (f.spec.min, f.spec.max)
        };
        slider_within(ui, &f, m, min, max);
        if f.spec.key == "tile" {
            m.atlas = m.atlas.clamp(m.tile, m.tile << 7);
        }
    }
    ui.text(&format!("{} maps", m.capacity()));
    ui.toggle(
        &mut m.front_face_culling,
        "cull front faces (Program 1)",
        &format!(
            "a map leaves out points whose surface faces its {light} (no self-shadowing of lit surfaces)"
        ),
    );
}

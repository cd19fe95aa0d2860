//! Interleaved sampling's settings in the GUI, shared by the methods that interleave (light
//! culling over its VPLs, the tree samplers over their cut slots). The pattern itself lives
//! in each method's kernel; the filter that undoes it is `renderer::passes::interleave_filter`.

use crate::base::settings_ui::{SettingsUi, slider};
use crate::settings::{InterleaveSettings, PatternDefault};

/// The pattern and filter sliders (`InterleaveSettings::fields`: the ranges validation
/// uses). `lights` names what a pattern pixel takes a share of; `paper` the values the
/// method's paper uses. Turning the pattern on with no filter gives it the paper's filter
/// radius (r = n), so the pattern is undone at once.
pub fn settings_ui<D: PatternDefault>(
    ui: &mut dyn SettingsUi,
    il: &mut InterleaveSettings<D>,
    max_n: u32,
    lights: &str,
    paper: &str,
) {
    let n_before = il.n;
    ui.text(&format!("interleaving over the {lights} ({paper})"));
    for f in InterleaveSettings::<D>::fields(max_n) {
        slider(ui, &f, il);
    }
    if n_before == 1 && il.n > 1 && il.filter_radius == 0 {
        il.filter_radius = il.n;
    }
}

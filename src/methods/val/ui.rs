//! The VAL methods' settings in the GUI (`val` and `val-vpl` share them).

use super::settings::{MAX_INTERLEAVE, ValSettings, ValVisibility};
use crate::base::settings_ui::{SettingsUi, radio, slider, slider_within};
use crate::methods::MethodId;
use crate::settings::RenderSettings;

pub fn settings_ui(ui: &mut dyn SettingsUi, _method: MethodId, s: &mut RenderSettings) {
    let id = super::ID;
    let mut vs: ValSettings = match s.method(id) {
        Ok(v) => v,
        Err(e) => {
            ui.error(&e);
            return;
        }
    };
    let before = vs.clone();
    ui.toggle(
        &mut s.frame.accumulate,
        "accumulate frames while static",
        "average the frames' estimates (new interleaving offsets) while nothing changes",
    );
    let field = |key: &str| crate::base::field::find(super::settings::FIELDS, key);
    for key in ["clusters", "resolution", "splat", "iterations"] {
        slider(ui, field(key), &mut vs);
    }
    ui.toggle(
        &mut vs.carry_over,
        "carry the clusters over frames",
        "the paper's: each frame's steps start from the last frame's clusters (with 1 step: one per frame)",
    );
    for key in ["weights.position", "weights.normal", "weights.flux"] {
        slider(ui, field(key), &mut vs);
    }
    crate::methods::interleave::settings_ui(
        ui,
        &mut vs.interleave,
        MAX_INTERLEAVE,
        "VALs",
        "paper n x m, not given",
    );
    ui.toggle(
        &mut vs.paper_filter,
        "the paper's n x n filter window",
        "one pixel of each subset (section 6); off: the (2r + 1)^2 window of the filter radius, \
         which weights the subsets unevenly (an n-periodic pattern)",
    );
    radio(
        ui,
        "visibility",
        &mut vs.visibility,
        &[
            (
                ValVisibility::Ism,
                "ISM",
                "one lookup in the VAL's imperfect shadow map (section 5)",
            ),
            (
                ValVisibility::Pcss,
                "PCSS",
                "blocker search, eq. 3's penumbra, Poisson PCF in the VAL's map (section 6)",
            ),
            (
                ValVisibility::Rays,
                "ray to centre",
                "a BVH shadow ray to the VAL's centre (a point light's visibility)",
            ),
            (
                ValVisibility::Disk,
                "rays to disk",
                "16 BVH rays to the VAL's disk: its visible fraction, exact visibility (the maps' reference)",
            ),
        ],
        s.gi.shadow_rays,
        "turn shadow rays on to pick how VALs are shadowed",
    );
    if s.gi.shadow_rays && vs.visibility == ValVisibility::Pcss {
        ui.indented("pcss", &mut |ui| {
            for key in ["pcss.blocker_samples", "pcss.pcf_samples", "pcss.max_radius"] {
                slider(ui, field(key), &mut vs);
            }
        });
    }
    ui.section("imperfect shadow maps", &mut |ui| {
        crate::methods::ism_ui::settings_ui(ui, &mut vs.ism, "VAL", "128^2", "the cloud shared");
        let top = vs.clusters.saturating_sub(1) as f64;
        slider_within(ui, field("inspect"), &mut vs, 0.0, top);
    });
    if vs != before {
        // Cannot fail: the struct serialises to a table.
        let _ = s.set_method(id, &vs);
    }
}

//! The VAL methods' settings in the GUI (`val` and `val-vpl` share them).

use super::settings::{MAX_INTERLEAVE, ValSettings, ValVisibility};
use crate::methods::MethodId;
use crate::settings::RenderSettings;

pub fn settings_ui(ui: &mut egui::Ui, _method: MethodId, s: &mut RenderSettings) {
    let id = super::ID;
    let mut vs: ValSettings = match s.method(id) {
        Ok(v) => v,
        Err(e) => {
            ui.colored_label(egui::Color32::LIGHT_RED, e);
            return;
        }
    };
    let before = vs.clone();
    ui.checkbox(&mut s.sampling.accumulate, "accumulate frames while static")
        .on_hover_text("average the frames' estimates (new interleaving offsets) while nothing changes");
    let field = |key: &str| crate::base::field::find(super::settings::FIELDS, key);
    for key in ["clusters", "resolution", "splat", "iterations"] {
        crate::methods::field_ui::slider(ui, field(key), &mut vs);
    }
    ui.checkbox(&mut vs.carry_over, "carry the clusters over frames")
        .on_hover_text("the paper's: each frame's steps start from the last frame's clusters (with 1 step: one per frame)");
    for key in ["weights.position", "weights.normal", "weights.flux"] {
        crate::methods::field_ui::slider(ui, field(key), &mut vs);
    }
    crate::methods::interleave::settings_ui(
        ui,
        &mut vs.interleave,
        MAX_INTERLEAVE,
        "VALs",
        "paper n x m, not given",
    );
    ui.checkbox(&mut vs.paper_filter, "the paper's n x n filter window")
        .on_hover_text(
            "one pixel of each subset (section 6); off: the (2r + 1)^2 window of the filter radius, \
             which weights the subsets unevenly (an n-periodic pattern)",
        );
    ui.add_enabled_ui(s.gi.shadow_rays, |ui| {
        ui.horizontal(|ui| {
            ui.label("visibility");
            ui.radio_value(&mut vs.visibility, ValVisibility::Ism, "ISM")
                .on_hover_text("one lookup in the VAL's imperfect shadow map (section 5)");
            ui.radio_value(&mut vs.visibility, ValVisibility::Pcss, "PCSS")
                .on_hover_text("blocker search, eq. 3's penumbra, Poisson PCF in the VAL's map (section 6)");
            ui.radio_value(&mut vs.visibility, ValVisibility::Rays, "ray to centre")
                .on_hover_text("a BVH shadow ray to the VAL's centre (a point light's visibility)");
            ui.radio_value(&mut vs.visibility, ValVisibility::Disk, "rays to disk")
                .on_hover_text("16 BVH rays to the VAL's disk: its visible fraction, exact visibility (the maps' reference)");
        });
    })
    .response
    .on_disabled_hover_text("turn shadow rays on to pick how VALs are shadowed");
    if s.gi.shadow_rays && vs.visibility == ValVisibility::Pcss {
        ui.indent("pcss", |ui| {
            for key in ["pcss.blocker_samples", "pcss.pcf_samples", "pcss.max_radius"] {
                crate::methods::field_ui::slider(ui, field(key), &mut vs);
            }
        });
    }
    ui.collapsing("imperfect shadow maps", |ui| {
        crate::methods::ism_ui::settings_ui(ui, &mut vs.ism, "VAL", "128^2", "the cloud shared");
        let top = vs.clusters.saturating_sub(1) as f64;
        crate::methods::field_ui::slider_within(ui, field("inspect"), &mut vs, 0.0, top);
    });
    if vs != before {
        // Cannot fail: the struct serialises to a table.
        let _ = s.set_method(id, &vs);
    }
}

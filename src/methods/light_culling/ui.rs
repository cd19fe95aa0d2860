//! Stochastic Light Culling's settings in the GUI (shared by the clamped baseline).

use super::settings::{CullingVisibility, LightCullingSettings, MAX_INTERLEAVE};
use crate::methods::MethodId;
use crate::settings::RenderSettings;

pub fn settings_ui(ui: &mut egui::Ui, method: MethodId, s: &mut RenderSettings) {
    let id = super::ID;
    let mut lc: LightCullingSettings = match s.method(id) {
        Ok(v) => v,
        Err(e) => {
            ui.colored_label(egui::Color32::LIGHT_RED, e);
            return;
        }
    };
    let before = lc.clone();
    ui.checkbox(&mut s.sampling.accumulate, "accumulate frames while static")
        .on_hover_text(
            "average the frames' estimates while the view, lights and settings stay (the \
             clamped-vs-stochastic view then compares converged means)",
        );
    let field = |key: &str| crate::base::field::find(super::settings::FIELDS, key);
    crate::methods::field_ui::slider(ui, field("epsilon_max"), &mut lc);
    if method == super::TREE {
        crate::methods::field_ui::slider(ui, field("reservoir_k"), &mut lc);
        crate::methods::field_ui::slider(ui, field("tree_filter_radius"), &mut lc);
        visibility_ui(ui, &mut lc, s.gi.shadow_rays);
        if lc != before {
            let _ = s.set_method(id, &lc);
        }
        return;
    }
    crate::methods::interleave::settings_ui(ui, &mut lc.interleave, MAX_INTERLEAVE, "VPLs", "paper 8 x 8");
    crate::methods::field_ui::slider(ui, field("tile_size"), &mut lc);
    crate::methods::field_ui::slider(ui, field("max_lights_per_tile"), &mut lc);
    visibility_ui(ui, &mut lc, s.gi.shadow_rays);
    if lc != before {
        // Cannot fail: the struct serialises to a table.
        let _ = s.set_method(id, &lc);
    }
}

/// Visibility (rays or imperfect shadow maps, while shadow rays are on) and the maps' settings.
fn visibility_ui(ui: &mut egui::Ui, lc: &mut LightCullingSettings, shadow_rays: bool) {
    ui.add_enabled_ui(shadow_rays, |ui| {
        ui.horizontal(|ui| {
            ui.label("visibility");
            ui.radio_value(&mut lc.visibility, CullingVisibility::Rays, "shadow rays")
                .on_hover_text("a BVH shadow ray per VPL in range (exact)");
            ui.radio_value(&mut lc.visibility, CullingVisibility::Ism, "ISM")
                .on_hover_text(
                    "a lookup in the VPL's imperfect shadow map (the paper's AISMs, section 4.4; \
                     the ground truth still traces rays, so the comparison shows their error)",
                );
        });
    })
    .response
    .on_disabled_hover_text("turn shadow rays on to pick how VPLs are shadowed");
    if !(shadow_rays && lc.visibility == CullingVisibility::Ism) {
        return;
    }
    ui.indent("ism", |ui| {
        crate::methods::ism_ui::settings_ui(ui, &mut lc.ism, "VPL", "32^2", "8192");
        ui.checkbox(&mut lc.ism_range_culling, "cull points by range (section 4.3)")
            .on_hover_text("a VPL's map leaves out points beyond its range, where it adds nothing");
    });
}

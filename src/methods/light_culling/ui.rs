//! Stochastic Light Culling's settings in the GUI (shared by the clamped baseline).

use super::settings::{CullingVisibility, LightCullingSettings, MAX_INTERLEAVE};
use crate::base::settings_ui::{SettingsUi, radio, slider};
use crate::methods::MethodId;
use crate::settings::RenderSettings;

pub fn settings_ui(ui: &mut dyn SettingsUi, method: MethodId, s: &mut RenderSettings) {
    let id = super::ID;
    let mut lc: LightCullingSettings = match s.method(id) {
        Ok(v) => v,
        Err(e) => {
            ui.error(&e);
            return;
        }
    };
    let before = lc.clone();
    ui.toggle(
        &mut s.frame.accumulate,
        "accumulate frames while static",
        "average the frames' estimates while the view, lights and settings stay (the \
         clamped-vs-stochastic view then compares converged means)",
    );
    let field = |key: &str| crate::base::field::find(super::settings::FIELDS, key);
    slider(ui, field("epsilon_max"), &mut lc);
    if method == super::TREE {
        slider(ui, field("reservoir_k"), &mut lc);
        slider(ui, field("tree_filter_radius"), &mut lc);
        visibility_ui(ui, &mut lc, s.gi.shadow_rays);
        if lc != before {
            let _ = s.set_method(id, &lc);
        }
        return;
    }
    crate::methods::interleave::settings_ui(ui, &mut lc.interleave, MAX_INTERLEAVE, "VPLs", "paper 8 x 8");
    slider(ui, field("tile_size"), &mut lc);
    slider(ui, field("max_lights_per_tile"), &mut lc);
    visibility_ui(ui, &mut lc, s.gi.shadow_rays);
    if lc != before {
        // Cannot fail: the struct serialises to a table.
        let _ = s.set_method(id, &lc);
    }
}

/// Visibility (rays or imperfect shadow maps, while shadow rays are on) and the maps' settings.
fn visibility_ui(ui: &mut dyn SettingsUi, lc: &mut LightCullingSettings, shadow_rays: bool) {
    radio(
        ui,
        "visibility",
        &mut lc.visibility,
        &[
            (
                CullingVisibility::Rays,
                "shadow rays",
                "a BVH shadow ray per VPL in range (exact)",
            ),
            (
                CullingVisibility::Ism,
                "ISM",
                "a lookup in the VPL's imperfect shadow map (the paper's AISMs, section 4.4; \
                 the ground truth still traces rays, so the comparison shows their error)",
            ),
        ],
        shadow_rays,
        "turn shadow rays on to pick how VPLs are shadowed",
    );
    if !(shadow_rays && lc.visibility == CullingVisibility::Ism) {
        return;
    }
    ui.indented("ism", &mut |ui| {
        crate::methods::ism_ui::settings_ui(ui, &mut lc.ism, "VPL", "32^2", "8192");
        ui.toggle(
            &mut lc.ism_range_culling,
            "cull points by range (section 4.3)",
            "a VPL's map leaves out points beyond its range, where it adds nothing",
        );
    });
}

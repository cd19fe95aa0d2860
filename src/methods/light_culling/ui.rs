//! Stochastic Light Culling's settings in the GUI (shared by the clamped baseline).

use super::settings::{
    CullingVisibility, LightCullingSettings, MAX_FILTER_RADIUS, MAX_INTERLEAVE, MAX_LIST, MAX_RESERVOIR,
};
use crate::methods::MethodId;
use crate::renderer::settings::RenderSettings;

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
    ui.add(
        egui::Slider::new(&mut lc.epsilon_max, 1e-5..=0.05)
            .logarithmic(true)
            .text("error bound eps_max"),
    )
    .on_hover_text(
        "largest standard deviation per VPL (stochastic; in the filtered image) or total \
         darkening (clamped) in exposed display units (paper 0.0005); shared by the variants",
    );
    if method == super::TREE {
        ui.add(egui::Slider::new(&mut lc.reservoir_k, 1..=MAX_RESERVOIR).text("light list k"))
            .on_hover_text(
                "per-pixel list filled by reservoir sampling during the tree traversal (paper 32); \
                 one listed VPL is shaded by resampled importance sampling (one shadow ray)",
            );
        ui.add(egui::Slider::new(&mut lc.tree_filter_radius, 0..=MAX_FILTER_RADIUS).text("filter radius"))
            .on_hover_text("geometry-aware filter window (2r+1)^2 (0 = off, as the paper's path tracer)");
        visibility_ui(ui, &mut lc, s.gi.shadow_rays);
        if lc != before {
            let _ = s.set_method(id, &lc);
        }
        return;
    }
    crate::methods::interleave::settings_ui(ui, &mut lc.interleave, MAX_INTERLEAVE, "VPLs", "paper 8 x 8");
    ui.add(egui::Slider::new(&mut lc.tile_size, 4..=32).text("tile size (pixels)"));
    ui.add(
        egui::Slider::new(&mut lc.max_lights_per_tile, 1..=MAX_LIST)
            .logarithmic(true)
            .text("max lights per tile"),
    )
    .on_hover_text("an overflowing tile is shaded by testing all its subset's VPLs (counted, shown)");
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

//! The tree samplers' settings in the GUI (SST hides the cut and blending controls it does
//! not use; RTSLC hides the substitute controls).

use super::settings::{ChildProbability, CutBlending, CutFallback, GlossyWeights, SamplerVisibility};
use super::{RTSLC, SST};
use crate::methods::MethodId;
use crate::settings::RenderSettings;

pub fn settings_ui(ui: &mut egui::Ui, method: MethodId, s: &mut RenderSettings) {
    let sm = &mut s.sampling;
    let field = |key: &str| crate::base::field::find(super::settings::FIELDS, key);
    crate::methods::field_ui::slider(ui, field("cut_size"), sm);
    if method != SST {
        crate::methods::field_ui::slider(ui, field("block_size"), sm);
        egui::ComboBox::from_label("cut blending")
            .selected_text(sm.blending.name())
            .show_ui(ui, |ui| {
                for b in CutBlending::ALL {
                    ui.selectable_value(&mut sm.blending, b, b.name());
                }
            });
        egui::ComboBox::from_label("no similar cut")
            .selected_text(sm.fallback.name())
            .show_ui(ui, |ui| {
                for f in CutFallback::ALL {
                    ui.selectable_value(&mut sm.fallback, f, f.name());
                }
            });
        ui.checkbox(&mut sm.cull_behind, "cull nodes behind the block centre")
            .on_hover_text("thesis 5.1; off keeps every cut complete (unbiased)");
    }
    if method != RTSLC {
        crate::methods::field_ui::slider(ui, field("near_field"), sm);
        crate::methods::field_ui::slider(ui, field("substitute_offset"), sm);
    }
    egui::ComboBox::from_label("child probability")
        .selected_text(sm.child_probability.name())
        .show_ui(ui, |ui| {
            for c in ChildProbability::ALL {
                ui.selectable_value(&mut sm.child_probability, c, c.name());
            }
        })
        .response
        .on_hover_text(
            "how a traversal step picks a child: eq. 5.5's weights with the distance to \
             each child's mean (thesis); RTSLC's average of the closest- and \
             farthest-point box distances; or (default) the thesis's mixed with 20% \
             of the closest-point one, which keeps VPLs next to the point from being \
             drawn rarely (fireflies)",
        );
    if method != RTSLC && s.gi.brdf != crate::settings::Brdf::Lambert {
        egui::ComboBox::from_label("glossy walk weights")
            .selected_text(sm.glossy_weights.name())
            .show_ui(ui, |ui| {
                for g in GlossyWeights::ALL {
                    ui.selectable_value(&mut sm.glossy_weights, g, g.name());
                }
            })
            .response
            .on_hover_text(
                "how a glossy sample's walk to a leaf picks a child: the geometric \
                 weights alone; the SST paper's material term (4.1: the specular BRDF \
                 towards the reflected view direction where it meets the child's box, \
                 else towards its nearest point); or (default) that mixed with 25% of \
                 the geometric choice, so a child the single direction underrates is \
                 still drawn (fewer fireflies)",
            );
    }
    ui.checkbox(
        &mut sm.half_resolution,
        "half-resolution GI (bilateral upsampling)",
    );
    let lights = if method == SST { "samples" } else { "cut slots" };
    crate::methods::interleave::settings_ui(
        ui,
        &mut sm.interleave,
        super::settings::MAX_SLOT_INTERLEAVE,
        lights,
        "RTSLC's code 2 x 2 or 4 x 4",
    );
    ui.checkbox(&mut sm.accumulate, "accumulate frames while static");
    let shadow_rays = s.gi.shadow_rays;
    let sm = &mut s.sampling;
    ui.add_enabled_ui(shadow_rays, |ui| {
        ui.horizontal(|ui| {
            ui.label("visibility");
            ui.radio_value(&mut sm.visibility, SamplerVisibility::Rays, "BVH rays")
                .on_hover_text("a BVH shadow ray per sample (the thesis)");
            ui.radio_value(&mut sm.visibility, SamplerVisibility::Ism, "ISM")
                .on_hover_text(
                    "an imperfect shadow map per light-tree leaf: a leaf sample looks up its VPL's \
                     map, a substitute sample a random leaf's of its node (approximate)",
                );
        });
    })
    .response
    .on_disabled_hover_text("turn shadow rays on to pick how samples are shadowed");
    if shadow_rays && sm.visibility == SamplerVisibility::Ism {
        ui.indent("sampler_ism", |ui| {
            crate::methods::ism_ui::settings_ui(ui, &mut sm.ism, "leaf", "32^2", "8192");
        });
    }
}

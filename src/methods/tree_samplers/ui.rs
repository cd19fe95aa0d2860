//! The tree samplers' settings in the GUI (SST hides the cut and blending controls it does
//! not use; RTSLC hides the substitute controls).

use super::settings::{
    ChildProbability, CutBlending, CutFallback, GlossyWeights, SamplerVisibility, SamplingSettings,
};
use super::{RTSLC, SST};
use crate::base::settings_ui::{SettingsUi, choose, radio, slider};
use crate::methods::MethodId;
use crate::settings::RenderSettings;

pub fn settings_ui(ui: &mut dyn SettingsUi, method: MethodId, s: &mut RenderSettings) {
    // Edited as a copy, stored back only when changed (the table is parsed once per change).
    let before = SamplingSettings::of(s);
    let mut edited = before.clone();
    let sm = &mut edited;
    let field = |key: &str| crate::base::field::find(super::settings::FIELDS, key);
    slider(ui, field("cut_size"), sm);
    if method != SST {
        slider(ui, field("block_size"), sm);
        choose(
            ui,
            "cut blending",
            &mut sm.blending,
            &CutBlending::ALL,
            |b| b.name(),
            "",
        );
        choose(
            ui,
            "no similar cut",
            &mut sm.fallback,
            &CutFallback::ALL,
            |f| f.name(),
            "",
        );
        ui.toggle(
            &mut sm.cull_behind,
            "cull nodes behind the block centre",
            "thesis 5.1; off keeps every cut complete (unbiased)",
        );
    }
    if method != RTSLC {
        slider(ui, field("near_field"), sm);
        slider(ui, field("substitute_offset"), sm);
    }
    choose(
        ui,
        "child probability",
        &mut sm.child_probability,
        &ChildProbability::ALL,
        |c| c.name(),
        "how a traversal step picks a child: eq. 5.5's weights with the distance to \
         each child's mean (thesis); RTSLC's average of the closest- and \
         farthest-point box distances; or (default) the thesis's mixed with 20% \
         of the closest-point one, which keeps VPLs next to the point from being \
         drawn rarely (fireflies)",
    );
    if method != RTSLC && s.gi.brdf != crate::settings::Brdf::Lambert {
        choose(
            ui,
            "glossy walk weights",
            &mut sm.glossy_weights,
            &GlossyWeights::ALL,
            |g| g.name(),
            "how a glossy sample's walk to a leaf picks a child: the geometric \
             weights alone; the SST paper's material term (4.1: the specular BRDF \
             towards the reflected view direction where it meets the child's box, \
             else towards its nearest point); or (default) that mixed with 25% of \
             the geometric choice, so a child the single direction underrates is \
             still drawn (fewer fireflies)",
        );
    }
    ui.toggle(
        &mut sm.half_resolution,
        "half-resolution GI (bilateral upsampling)",
        "",
    );
    let lights = if method == SST { "samples" } else { "cut slots" };
    crate::methods::interleave::settings_ui(
        ui,
        &mut sm.interleave,
        super::settings::MAX_SLOT_INTERLEAVE,
        lights,
        "RTSLC's code 2 x 2 or 4 x 4",
    );
    ui.toggle(&mut s.frame.accumulate, "accumulate frames while static", "");
    let shadow_rays = s.gi.shadow_rays;
    radio(
        ui,
        "visibility",
        &mut sm.visibility,
        &[
            (
                SamplerVisibility::Rays,
                "BVH rays",
                "a BVH shadow ray per sample (the thesis)",
            ),
            (
                SamplerVisibility::Ism,
                "ISM",
                "an imperfect shadow map per light-tree leaf: a leaf sample looks up its VPL's \
                 map, a substitute sample a random leaf's of its node (approximate)",
            ),
        ],
        shadow_rays,
        "turn shadow rays on to pick how samples are shadowed",
    );
    if shadow_rays && sm.visibility == SamplerVisibility::Ism {
        ui.indented("sampler_ism", &mut |ui| {
            crate::methods::ism_ui::settings_ui(ui, &mut sm.ism, "leaf", "32^2", "8192");
        });
    }
    if edited != before {
        SamplingSettings::edit(s, |m| *m = edited);
    }
}

//! The VAL methods' settings in the GUI (`val` and `val-vpl` share them).

use super::settings::{MAX_INTERLEAVE, MAX_ITERATIONS, MAX_SPLAT, ValSettings, ValVisibility};
use crate::methods::MethodId;
use crate::reference::val::{MAX_CLUSTERS, POISSON};
use crate::renderer::settings::RenderSettings;

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
    ui.add(
        egui::Slider::new(&mut vs.clusters, 1..=MAX_CLUSTERS)
            .logarithmic(true)
            .text("VALs"),
    )
    .on_hover_text("clusters of the RSM, one map each (paper: 64 with PCSS, 512 with simple lookups)");
    let mut res_log = vs.resolution.clamp(8, 1024).ilog2();
    if ui
        .add(egui::Slider::new(&mut res_log, 3..=10).text("clustering RSM (log2)"))
        .on_hover_text("the RSM is summed down to 2^k texels a side before clustering (flux and area kept)")
        .changed()
    {
        vs.resolution = 1 << res_log;
    }
    ui.add(
        egui::Slider::new(&mut vs.splat, 1..=MAX_SPLAT)
            .logarithmic(true)
            .text("splat (RSM texels)"),
    )
    .on_hover_text("edge of a cluster's splat window: texels beyond it join a cluster only by the fallback (paper 32 - 128)");
    ui.add(egui::Slider::new(&mut vs.iterations, 1..=MAX_ITERATIONS).text("k-means steps"))
        .on_hover_text(
            "clustering steps per frame, from the frame's seeds or the last frame's clusters (the paper: one per frame, carried over)",
        );
    ui.checkbox(&mut vs.carry_over, "carry the clusters over frames")
        .on_hover_text("the paper's: each frame's steps start from the last frame's clusters (with 1 step: one per frame)");
    ui.horizontal(|ui| {
        ui.label("eq. 1 weights");
        ui.add(
            egui::DragValue::new(&mut vs.weights.position)
                .range(0.0..=1.0)
                .speed(0.01)
                .prefix("pos "),
        );
        ui.add(
            egui::DragValue::new(&mut vs.weights.normal)
                .range(0.0..=1.0)
                .speed(0.01)
                .prefix("normal "),
        );
        ui.add(
            egui::DragValue::new(&mut vs.weights.flux)
                .range(0.0..=1.0)
                .speed(0.01)
                .prefix("flux "),
        );
    });
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
        let n = POISSON.len() as u32;
        ui.indent("pcss", |ui| {
            ui.add(egui::Slider::new(&mut vs.pcss.blocker_samples, 1..=n).text("blocker samples"));
            ui.add(egui::Slider::new(&mut vs.pcss.pcf_samples, 1..=n).text("PCF samples"));
            ui.add(egui::Slider::new(&mut vs.pcss.max_radius, 1.0..=64.0).text("largest filter (texels)"));
        });
    }
    ui.collapsing("imperfect shadow maps", |ui| {
        crate::methods::ism_ui::settings_ui(ui, &mut vs.ism, "VAL", "128^2", "the cloud shared");
        let top = vs.clusters.saturating_sub(1);
        ui.add(egui::Slider::new(&mut vs.inspect, 0..=top).text("VAL inspected"))
            .on_hover_text("the VAL whose map the 'VAL ISM vs true map' view shows");
    });
    if vs != before {
        // Cannot fail: the struct serialises to a table.
        let _ = s.set_method(id, &vs);
    }
}

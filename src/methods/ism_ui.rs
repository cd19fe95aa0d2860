//! The imperfect shadow maps' settings in the GUI (shared by the methods that build them:
//! light culling's adaptive maps, the VALs' maps).

use crate::renderer::settings::{IsmDefault, IsmSettings};

/// `m`'s sliders; `light` names what a map belongs to ("VPL", "VAL"), `paper_tile` and
/// `paper_points` the method's paper values for the hover texts.
pub fn settings_ui<D: IsmDefault>(
    ui: &mut egui::Ui,
    m: &mut IsmSettings<D>,
    light: &str,
    paper_tile: &str,
    paper_points: &str,
) {
    ui.add(
        egui::Slider::new(&mut m.points_per_light, 0..=65536)
            .logarithmic(true)
            .text("points per map"),
    )
    .on_hover_text(format!(
        "points splatted into each {light}'s map (paper {paper_points}; 0 = the cloud shared round-robin)"
    ));
    ui.add(
        egui::Slider::new(&mut m.points, 1024..=1 << 22)
            .logarithmic(true)
            .text("cloud points"),
    )
    .on_hover_text("points sampled once on the scene's triangles, uniform in area");
    let mut tile_log = m.tile.max(8).ilog2();
    if ui
        .add(egui::Slider::new(&mut tile_log, 3..=8).text("map size (log2)"))
        .on_hover_text(format!(
            "one paraboloid map's edge: 2^k texels (paper {paper_tile})"
        ))
        .changed()
    {
        m.tile = 1 << tile_log;
        m.atlas = m.atlas.clamp(m.tile, m.tile << 7);
    }
    // At most 128 x 128 maps (the build's 65535 workgroup layers) and an 8192 atlas.
    let tile_log = m.tile.ilog2();
    let mut atlas_log = m.atlas.max(m.tile).ilog2().min(tile_log + 7);
    if ui
        .add(egui::Slider::new(&mut atlas_log, tile_log..=(tile_log + 7).min(13)).text("atlas size (log2)"))
        .on_hover_text(format!("the atlas holds (atlas / map)^2 maps: one per {light}"))
        .changed()
    {
        m.atlas = 1 << atlas_log;
    }
    ui.label(format!("{} maps", m.capacity()));
    ui.add(egui::Slider::new(&mut m.pull_push_levels, 0..=4).text("pull-push levels"))
        .on_hover_text("hole filling (paper 2)");
    ui.add(egui::Slider::new(&mut m.bias, 0.0..=0.3).text("relative depth bias"));
    ui.add(egui::Slider::new(&mut m.point_size, 0.0..=8.0).text("point size"))
        .on_hover_text(
            "a point's world radius as a multiple of sqrt(scene area / (pi x points per map)): near \
             points cover several texels (the VAL paper's sized points); 0: one texel per point",
        );
    ui.checkbox(&mut m.front_face_culling, "cull front faces (Program 1)")
        .on_hover_text(format!(
            "a map leaves out points whose surface faces its {light} (no self-shadowing of lit surfaces)"
        ));
}

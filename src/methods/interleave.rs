//! Interleaved sampling's settings in the GUI, shared by the methods that interleave (light
//! culling over its VPLs, the tree samplers over their cut slots). The pattern itself lives
//! in each method's kernel; the filter that undoes it is `renderer::passes::interleave_filter`.

use crate::renderer::settings::{InterleaveSettings, MAX_FILTER_RADIUS, PatternDefault};

/// The pattern and filter sliders. `lights` names what a pattern pixel takes a share of;
/// `paper` the values the method's paper uses. Turning the pattern on with no filter gives
/// it the paper's filter radius (r = n), so the pattern is undone at once.
pub fn settings_ui<D: PatternDefault>(
    ui: &mut egui::Ui,
    il: &mut InterleaveSettings<D>,
    max_n: u32,
    lights: &str,
    paper: &str,
) {
    let n_before = il.n;
    ui.add(egui::Slider::new(&mut il.n, 1..=max_n).text("interleave n (n x n)"))
        .on_hover_text(format!(
            "each pixel of an n x n pattern takes a disjoint 1/n^2 of the {lights} (x n^2), the \
             subsets shifted each frame; the filter then averages the pattern ({paper}; 1 = off)"
        ));
    if n_before == 1 && il.n > 1 && il.filter_radius == 0 {
        il.filter_radius = il.n;
    }
    ui.add(egui::Slider::new(&mut il.filter_radius, 0..=MAX_FILTER_RADIUS).text("filter radius"))
        .on_hover_text(
            "geometry-aware filter window (2r+1)^2 (the paper: 17 x 17 for 8 x 8, r = n; 0 = off)",
        );
    ui.add(egui::Slider::new(&mut il.filter_normal_cos, 0.0..=1.0).text("filter normal cos"))
        .on_hover_text("neighbours whose normal is farther from the pixel's than this cosine are skipped");
    ui.add(egui::Slider::new(&mut il.filter_plane_tolerance, 0.0..=0.2).text("filter plane tolerance"))
        .on_hover_text("neighbours farther from the pixel's tangent plane than this x depth are skipped");
}

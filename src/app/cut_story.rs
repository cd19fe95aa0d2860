//! The pixel story of the cut-based methods (Lightcuts, Lightcut Interpolation): the pinned
//! pixel's table (records, weights, cut sizes, counters) and a tree view of its cuts over the
//! light tree's levels: each cut a staircase of segments (a node spans its leaves at its
//! level), the input cuts in colours, the pixel's own cut in white, and where the inputs
//! disagree as a red band under the leaves. Data: `Renderer::read_cut_story`.

use crate::base::sst_node::Topology;
use crate::base::story::CutStory;

/// Colours of up to three input cuts.
const INPUT: [egui::Color32; 3] = [
    egui::Color32::from_rgb(90, 170, 255),
    egui::Color32::from_rgb(255, 170, 60),
    egui::Color32::from_rgb(120, 220, 120),
];

/// The story's table and tree view (`leaves` of the frame's tree).
pub fn contents(ui: &mut egui::Ui, story: &CutStory, leaves: u32) {
    egui::Grid::new("cut_story_rows").striped(true).show(ui, |ui| {
        for (k, v) in &story.rows {
            ui.label(k);
            ui.label(v);
            ui.end_row();
        }
    });
    ui.separator();
    ui.strong("Tree view: the cuts over the levels");
    tree_view(ui, story, leaves);
    let mut legend: Vec<String> = story
        .inputs
        .iter()
        .enumerate()
        .map(|(i, c)| format!("{} {}", ["blue", "orange", "green"][i.min(2)], c.label))
        .collect();
    if let Some(c) = &story.cut {
        legend.push(format!("white {}", c.label));
    }
    if !story.disagreements.is_empty() {
        legend.push("red band: the inputs disagree".into());
    }
    ui.label(egui::RichText::new(legend.join(" · ")).small());
}

fn tree_view(ui: &mut egui::Ui, story: &CutStory, leaves: u32) {
    let leaves = leaves.max(1);
    // Either tree: a node spans its leaf range at its depth (the radix tree's leaves lie at
    // many depths: as many rows as the deepest drawn node needs).
    let topo = Topology::of(leaves, &story.links);
    let valid = |n: u32| n != 0 && n < 2 * leaves;
    let all = story
        .inputs
        .iter()
        .chain(story.cut.iter())
        .flat_map(|c| c.nodes.iter().copied());
    let levels = match topo.links {
        None => leaves.ilog2() + 1,
        Some(_) => all
            .filter(|&n| valid(n))
            .map(|n| topo.depth(n) + 1)
            .max()
            .unwrap_or(1)
            .min(96),
    };
    let row = 14.0;
    let width = ui.available_width().clamp(240.0, 900.0);
    let height = row * levels as f32 + 14.0;
    let (rect, _) = ui.allocate_exact_size(egui::vec2(width, height), egui::Sense::hover());
    let p = ui.painter_at(rect);
    p.rect_filled(rect, 2.0, egui::Color32::from_gray(20));
    let plot_w = rect.width() - 50.0;
    let x_of = |leaf: u32| rect.left() + 4.0 + plot_w * leaf as f32 / leaves as f32;
    let y_of = |level: u32| rect.top() + 4.0 + (level as f32 + 0.5) * row;
    for l in 0..levels {
        let y = y_of(l);
        p.line_segment(
            [egui::pos2(x_of(0), y), egui::pos2(x_of(leaves), y)],
            egui::Stroke::new(1.0, egui::Color32::from_gray(40)),
        );
        p.text(
            egui::pos2(x_of(leaves) + 6.0, y),
            egui::Align2::LEFT_CENTER,
            format!("L{l}"),
            egui::FontId::monospace(10.0),
            egui::Color32::from_gray(170),
        );
    }
    let span = |n: u32| {
        let (first, last) = topo.leaf_range(n);
        (topo.depth(n), first, last + 1)
    };
    let draw = |nodes: &[u32], color: egui::Color32, offset: f32, thick: f32| {
        for &n in nodes {
            if !valid(n) {
                continue;
            }
            let (level, a, b) = span(n);
            let y = y_of(level) + offset;
            p.line_segment(
                [egui::pos2(x_of(a) + 0.5, y), egui::pos2(x_of(b) - 0.5, y)],
                egui::Stroke::new(thick, color),
            );
        }
    };
    for (i, c) in story.inputs.iter().enumerate() {
        draw(&c.nodes, INPUT[i.min(2)], -3.0 + 2.0 * i as f32, 2.0);
    }
    if let Some(c) = &story.cut {
        draw(&c.nodes, egui::Color32::WHITE, 0.0, 1.5);
    }
    let band = rect.bottom() - 6.0;
    for &(a, b) in &story.disagreements {
        p.line_segment(
            [egui::pos2(x_of(a), band), egui::pos2(x_of(b), band)],
            egui::Stroke::new(4.0, egui::Color32::from_rgb(230, 60, 60)),
        );
    }
}

//! The temporal stage's controls in the side panel (`settings.temporal`: off / reprojection /
//! SVGF and their parameters) and the camera path through the bookmarks (the animation
//! section's player).

use crate::scene::camera_path::CameraPath;
use crate::scene::{Camera, Scene};
use crate::settings::temporal::AtrousFilter;
use crate::settings::{MAX_ATROUS_ITERATIONS, TemporalMode, TemporalSettings};

/// The stage's switch and sliders. `per_frame`: whether the current method is one the stage
/// applies to.
pub fn temporal_ui(ui: &mut egui::Ui, t: &mut TemporalSettings, per_frame: bool) {
    egui::ComboBox::from_label("temporal")
        .selected_text(t.mode.label())
        .show_ui(ui, |ui| {
            for m in TemporalMode::ALL {
                ui.selectable_value(&mut t.mode, m, m.label()).on_hover_text(match m {
                    TemporalMode::Off => "the method's estimate as it is",
                    TemporalMode::Reproject => {
                        "motion from the G-buffer and the previous camera; history kept where material, normal and plane agree; exponential history"
                    }
                    TemporalMode::Svgf => {
                        "the history, a per-pixel variance estimate and the variance-guided à-trous filter (Schied et al. 2017)"
                    }
                });
            }
        })
        .response
        .on_hover_text("temporal reuse after a per-frame method (docs/temporal.md)");
    if t.mode == TemporalMode::Off {
        return;
    }
    if !per_frame {
        ui.label(
            egui::RichText::new("(a converging method: the stage waits for a per-frame method)")
                .small()
                .italics(),
        );
    }
    egui::CollapsingHeader::new("temporal parameters")
        .id_salt("temporal_params")
        .show(ui, |ui| {
            ui.add(egui::Slider::new(&mut t.alpha, 0.01..=1.0).logarithmic(true).text("α colour"))
                .on_hover_text("least weight of the new frame (SVGF 0.2): lower = less noise, more lag");
            ui.add(egui::Slider::new(&mut t.moments_alpha, 0.01..=1.0).logarithmic(true).text("α moments"));
            ui.add(egui::Slider::new(&mut t.max_history, 1..=256).logarithmic(true).text("max history"));
            ui.add(egui::Slider::new(&mut t.normal_cos, 0.0..=1.0).text("rejection: normal cos"));
            ui.add(
                egui::Slider::new(&mut t.depth_tolerance, 0.001..=0.2)
                    .logarithmic(true)
                    .text("rejection: plane tolerance (× depth)"),
            );
            if t.mode == TemporalMode::Svgf {
                ui.add(egui::Slider::new(&mut t.iterations, 0..=MAX_ATROUS_ITERATIONS).text("à-trous iterations"))
                    .on_hover_text("steps 1, 2, 4, ... pixels (SVGF 5)");
                egui::ComboBox::from_label("à-trous weights")
                    .selected_text(t.atrous.label())
                    .show_ui(ui, |ui| {
                        for a in AtrousFilter::ALL {
                            ui.selectable_value(&mut t.atrous, a, a.label()).on_hover_text(match a {
                                AtrousFilter::Conserving => {
                                    "symmetric weights: what a pixel takes from a neighbour, the neighbour gives; the image's light stays (3 passes per iteration)"
                                }
                                AtrousFilter::Svgf => {
                                    "the paper's: each pixel normalised by its own weights; darkens under skewed noise (issue 37)"
                                }
                            });
                        }
                    })
                    .response
                    .on_hover_text("temporal.atrous (docs/temporal.md, \"Where SVGF lost light\")");
                t.feedback_iteration = t.feedback_iteration.min(t.iterations);
                ui.add(egui::Slider::new(&mut t.feedback_iteration, 0..=t.iterations).text("history from iteration"))
                    .on_hover_text("SVGF 1; 0 = the unfiltered integrated colour");
                ui.add(egui::Slider::new(&mut t.sigma_l, 0.1..=64.0).logarithmic(true).text("σ luminance"));
                ui.add(egui::Slider::new(&mut t.sigma_n, 1.0..=512.0).logarithmic(true).text("σ normal"));
                ui.add(egui::Slider::new(&mut t.sigma_z, 0.1..=16.0).logarithmic(true).text("σ depth"));
                ui.add(egui::Slider::new(&mut t.spatial_variance_frames, 0..=16).text("spatial variance below (frames)"));
                ui.add(egui::Slider::new(&mut t.view_iteration, 1..=MAX_ATROUS_ITERATIONS).text("iteration view shows"));
            }
            ui.checkbox(&mut t.gradient_reset, "history reset on lighting change (A-SVGF-style)")
                .on_hover_text(
                    "window means of the new frame vs the reprojected history: a difference beyond two standard errors raises the new frame's weight",
                );
            if t.gradient_reset {
                ui.add(egui::Slider::new(&mut t.gradient_scale, 0.1..=20.0).logarithmic(true).text("reset gain"));
            }
        });
}

/// Playing a camera path through the scene's bookmarks, one step per rendered frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PathPlayer {
    /// Frames from the first bookmark to the last.
    pub frames: u32,
    /// The frame being shown (None: not playing).
    pub at: Option<u32>,
    /// Start over at the end.
    pub looped: bool,
}

impl PathPlayer {
    /// The controls; `scene` gives the bookmarks.
    pub fn ui(&mut self, ui: &mut egui::Ui, scene: &Scene) {
        if self.frames == 0 {
            self.frames = 120;
        }
        ui.horizontal(|ui| {
            let enough = scene.cameras.len() >= 2;
            let label = if self.at.is_some() {
                "stop path"
            } else {
                "play path"
            };
            if ui
                .add_enabled(enough, egui::Button::new(label))
                .on_hover_text("a Catmull-Rom spline through the bookmarks, in order, at constant speed")
                .on_disabled_hover_text("needs two or more bookmarks (camera section: save)")
                .clicked()
            {
                self.at = if self.at.is_some() { None } else { Some(0) };
            }
            ui.add(
                egui::DragValue::new(&mut self.frames)
                    .range(2..=10_000)
                    .suffix(" frames"),
            );
            ui.checkbox(&mut self.looped, "loop");
        });
        if let Some(i) = self.at {
            ui.add(
                egui::ProgressBar::new(i as f32 / self.frames.max(2).saturating_sub(1) as f32).text(format!(
                    "path frame {} / {}",
                    i + 1,
                    self.frames
                )),
            );
        }
    }

    /// The camera of this frame and the step to the next (None when not playing or the
    /// bookmarks no longer make a path).
    pub fn step(&mut self, scene: &Scene) -> Option<Camera> {
        let i = self.at?;
        let Ok(path) = CameraPath::through(&scene.cameras) else {
            self.at = None;
            return None;
        };
        let n = self.frames.max(2);
        let cam = path.at(i as f32 / (n - 1) as f32);
        self.at = if i + 1 < n {
            Some(i + 1)
        } else if self.looped {
            Some(0)
        } else {
            None
        };
        Some(cam)
    }
}

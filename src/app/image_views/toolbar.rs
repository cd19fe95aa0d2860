//! A docked view's chrome: its toolbar (drag handle, buffer, look and A/B menus, export) and
//! the colour-scale legend drawn over heat maps.

use super::*;

pub(super) fn view_toolbar(cx: &mut PaneContext<'_>, ui: &mut egui::Ui, pane: &mut ViewPane) -> UiResponse {
    let mut response = UiResponse::None;
    let id = pane.id;
    let spec = &mut pane.spec;
    let pane_hovered = ui.rect_contains_pointer(ui.max_rect());
    ui.horizontal_wrapped(|ui| {
        ui.set_max_width(ui.available_width());
        let handle = ui
            .add(egui::Label::new("::").sense(egui::Sense::drag()))
            .on_hover_text("drag to move this view");
        if handle.drag_started() {
            response = UiResponse::DragStarted;
        }
        egui::ComboBox::new(("view_buffer", id), format!("view {id}"))
            .height(600.0)
            .selected_text(spec.buffer.name())
            .show_ui(ui, |ui| {
                for v in ViewBuffer::all() {
                    ui.selectable_value(&mut spec.buffer, v, v.name());
                }
            });
        if let Some(ab) = (spec.buffer == ViewBuffer::AbCompare).then_some(&mut spec.ab) {
            let sources: Vec<AbSource> = AbSource::LIVE
                .into_iter()
                .chain((0..cx.snapshots.len() as u32).map(AbSource::Snapshot))
                .collect();
            let name = |s: AbSource| match s {
                AbSource::Snapshot(i) => cx
                    .snapshots
                    .get(i as usize)
                    .map_or_else(|| s.name(), |l| format!("{}: {l}", s.name())),
                _ => s.name(),
            };
            for (label, which) in [("A", &mut ab.a), ("B", &mut ab.b)] {
                egui::ComboBox::new(("ab", label, id), label)
                    .selected_text(name(*which))
                    .width(120.0)
                    .truncate()
                    .show_ui(ui, |ui| {
                        for s in &sources {
                            ui.selectable_value(which, *s, name(*s));
                        }
                    });
            }
            egui::ComboBox::new(("ab_mode", id), "mode")
                .selected_text(ab.mode.name())
                .show_ui(ui, |ui| {
                    for m in AbMode::ALL {
                        ui.selectable_value(&mut ab.mode, m, m.name());
                    }
                });
            match ab.mode {
                AbMode::Split => {
                    ui.add(egui::Slider::new(&mut ab.split, 0.0..=1.0).show_value(false))
                        .on_hover_text("divider");
                }
                AbMode::Difference => {
                    ui.add(
                        egui::DragValue::new(&mut ab.diff_scale)
                            .range(1.0..=1.0e4)
                            .prefix("N = ")
                            .speed(0.5),
                    );
                }
                AbMode::A | AbMode::B
                    if ui
                        .button("toggle A/B (T)")
                        .on_hover_text("flip between A and B (T over this view)")
                        .clicked()
                        || (pane_hovered && ui.input(|i| i.key_pressed(egui::Key::T))) =>
                {
                    ab.mode = if ab.mode == AbMode::A {
                        AbMode::B
                    } else {
                        AbMode::A
                    };
                }
                _ => {}
            }
        }
        if pane.rect.is_some() && spec.effective_ab().is_some() && ui.button("clear rectangle").clicked() {
            pane.rect = None;
        }
        ui.menu_button("look", |ui| look_menu(ui, spec));
        ui.menu_button("export", |ui| {
            if ui.button("PNG as displayed").clicked()
                && let Some(slot) = pane.rt.slot
            {
                cx.events.export = Some((slot, *spec, ExportKind::Png));
                ui.close();
            }
            if ui
                .button("EXR of the buffer")
                .on_hover_text("linear, unscaled; an A/B view writes A and B")
                .clicked()
                && let Some(slot) = pane.rt.slot
            {
                cx.events.export = Some((slot, *spec, ExportKind::Exr));
                ui.close();
            }
            ui.separator();
            for s in [AbSource::Final, AbSource::Indirect, AbSource::GroundTruthIndirect] {
                if ui.button(format!("snapshot of {}", s.name())).clicked() {
                    cx.events.snapshot = Some(s);
                    ui.close();
                }
            }
        });
    });
    response
}

pub(super) fn look_menu(ui: &mut egui::Ui, spec: &mut ViewSpec) {
    let l = &mut spec.look;
    ui.add(egui::Slider::new(&mut l.exposure_ev, -10.0..=10.0).text("exposure (EV)"));
    egui::ComboBox::from_label("tonemap ")
        .selected_text(l.tonemap.name())
        .show_ui(ui, |ui| {
            for t in Tonemap::ALL {
                ui.selectable_value(&mut l.tonemap, t, t.name());
            }
        });
    egui::ComboBox::from_label("channel")
        .selected_text(l.channel.name())
        .show_ui(ui, |ui| {
            for c in Channel::ALL {
                ui.selectable_value(&mut l.channel, c, c.name());
            }
        });
    ui.checkbox(&mut l.false_color, "false colour (log10 radiance)");
    if l.false_color {
        ui.add(egui::Slider::new(&mut l.range_log10[0], -8.0..=4.0).text("from 10^"));
        ui.add(egui::Slider::new(&mut l.range_log10[1], -8.0..=4.0).text("to 10^"));
        if l.range_log10[1] <= l.range_log10[0] {
            l.range_log10[1] = l.range_log10[0] + 0.5;
        }
    }
    ui.checkbox(&mut l.nan_highlight, "NaN / Inf in magenta");
    ui.label(
        egui::RichText::new("the look applies to radiance buffers (final, direct, GI, ground truth, A/B)")
            .small(),
    );
}

pub(super) fn draw_legend(cx: &PaneContext<'_>, painter: &egui::Painter, rect: egui::Rect, pane: &ViewPane) {
    use crate::app::{Scale, legend_with};
    let shown = pane.spec.buffer;
    let look = pane.spec.look;
    let radiance = matches!(
        shown,
        ViewBuffer::Final
            | ViewBuffer::Direct
            | ViewBuffer::Indirect
            | ViewBuffer::GroundTruthFinal
            | ViewBuffer::GroundTruthIndirect
    );
    let ab = pane.spec.effective_ab();
    if radiance && look.false_color {
        let what = match look.channel {
            Channel::Rgb | Channel::Luminance => "luminance",
            Channel::R => "red",
            Channel::G => "green",
            Channel::B => "blue",
        };
        legend_with(
            painter,
            rect,
            &format!("{what} radiance, W/(m² sr) (log)"),
            look.range_log10[0],
            look.range_log10[1],
            Scale::Log10,
        );
    } else if let Some(l) = match shown {
        ViewBuffer::Method(v) => cx.renderer.method_legend(v),
        ViewBuffer::Temporal(v) => cx.renderer.temporal_legend(v),
        _ => None,
    } {
        let scale = if l.log { Scale::Log10 } else { Scale::Linear };
        legend_with(painter, rect, &l.title, l.lo, l.hi, scale);
    } else if ab.is_some_and(|a| a.mode == AbMode::RelativeError) {
        legend_with(
            painter,
            rect,
            "relative error |A - B| / B (log)",
            -2.0,
            1.0,
            Scale::Log10,
        );
    } else if shown.is_log_heat() {
        legend_with(painter, rect, "importance / mean (log)", -3.0, 2.0, Scale::Log10);
    } else if cx.display.vpl_overlay && cx.display.vpl_color == crate::settings::VplColor::Bounce {
        crate::app::bounce_legend(painter, rect, cx.renderer.vpl_frame().bounces);
    } else if cx.display.vpl_overlay {
        legend_with(painter, rect, "VPL flux / mean (log)", -2.0, 2.0, Scale::Log10);
    } else if cx.display.tree_overlay != crate::settings::TreeOverlay::Off
        && cx.display.tree_color == crate::settings::TreeColor::Intensity
        && !shown.is_rsm_space()
        && ab.is_none()
    {
        legend_with(
            painter,
            rect,
            "node flux per VPL / mean per VPL (log)",
            -2.0,
            2.0,
            Scale::Log10,
        );
    }
    if let Some(ab) = ab {
        let text = match ab.mode {
            AbMode::Split | AbMode::SideBySide => format!("A: {}  |  B: {}", ab.a.name(), ab.b.name()),
            AbMode::A => format!("A: {}", ab.a.name()),
            AbMode::B => format!("B: {}", ab.b.name()),
            AbMode::Difference => format!("|A - B| x {} ({} vs {})", ab.diff_scale, ab.a.name(), ab.b.name()),
            AbMode::RelativeError => format!("{} vs {}", ab.a.name(), ab.b.name()),
        };
        painter.text(
            rect.left_top() + egui::vec2(6.0, 4.0),
            egui::Align2::LEFT_TOP,
            text,
            egui::FontId::proportional(12.0),
            egui::Color32::from_gray(235),
        );
    }
}

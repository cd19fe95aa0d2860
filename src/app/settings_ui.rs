//! The methods' settings panels drawn with egui: `base::settings_ui::SettingsUi` for
//! `egui::Ui` (the methods describe their controls; only the app knows the toolkit).

use crate::base::settings_ui::{SettingsUi, SliderSpec};

fn hover(r: egui::Response, text: &str) -> egui::Response {
    if text.is_empty() { r } else { r.on_hover_text(text) }
}

impl SettingsUi for egui::Ui {
    fn slider(&mut self, spec: &SliderSpec, value: &mut f64) -> bool {
        let mut s = egui::Slider::new(value, spec.lo..=spec.hi).text(spec.label.as_str());
        if !spec.suffix.is_empty() {
            s = s.suffix(spec.suffix.as_str());
        }
        if spec.integer {
            s = s.integer();
        }
        if spec.logarithmic {
            s = s.logarithmic(true);
        }
        if let Some(p) = spec.smallest_positive {
            s = s.smallest_positive(p);
        }
        hover(self.add(s), &spec.help).changed()
    }

    fn toggle(&mut self, value: &mut bool, label: &str, hover_text: &str) -> bool {
        hover(self.checkbox(value, label), hover_text).changed()
    }

    fn text(&mut self, text: &str) {
        self.label(text);
    }

    fn error(&mut self, text: &str) {
        self.colored_label(egui::Color32::LIGHT_RED, text);
    }

    fn combo(&mut self, label: &str, selected: &mut usize, names: &[&str], hover_text: &str) -> bool {
        let before = *selected;
        let r = egui::ComboBox::from_label(label)
            .selected_text(names.get(*selected).copied().unwrap_or(""))
            .show_ui(self, |ui| {
                for (i, n) in names.iter().enumerate() {
                    ui.selectable_value(selected, i, *n);
                }
            })
            .response;
        hover(r, hover_text);
        *selected != before
    }

    fn radios(
        &mut self,
        label: &str,
        selected: &mut usize,
        options: &[(&str, &str)],
        enabled: bool,
        disabled_hover: &str,
    ) -> bool {
        let before = *selected;
        self.add_enabled_ui(enabled, |ui| {
            ui.horizontal(|ui| {
                ui.label(label);
                for (i, (name, h)) in options.iter().enumerate() {
                    hover(ui.radio_value(selected, i, *name), h);
                }
            });
        })
        .response
        .on_disabled_hover_text(disabled_hover);
        *selected != before
    }

    fn indented(&mut self, id: &str, add: &mut dyn FnMut(&mut dyn SettingsUi)) {
        self.indent(id, |ui| add(ui));
    }

    fn section(&mut self, title: &str, add: &mut dyn FnMut(&mut dyn SettingsUi)) {
        self.collapsing(title, |ui| add(ui));
    }
}

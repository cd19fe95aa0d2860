//! The settings controls a method's GUI panel draws, as a trait the app implements over
//! egui (`app::settings_ui`): methods describe their panel (sliders of declared fields,
//! toggles, choices, nested sections) and never import the UI toolkit. A slider of a
//! declared field (`base::field`) takes its range, scale, label, unit and help from the
//! declaration, so it offers exactly what validation accepts.

use crate::base::field::{Field, Scale};

/// A slider as the toolkit draws it: over `lo..=hi`, the value shown with `suffix`.
#[derive(Clone, Debug, PartialEq)]
pub struct SliderSpec {
    pub label: String,
    pub lo: f64,
    pub hi: f64,
    pub integer: bool,
    pub logarithmic: bool,
    /// A logarithmic slider from 0: its smallest positive value.
    pub smallest_positive: Option<f64>,
    /// After the value (" px"; empty for none).
    pub suffix: String,
    /// The hover text.
    pub help: String,
}

/// The controls of a settings panel. Each returns whether the user changed the value.
/// Hover texts may be empty (none shown).
pub trait SettingsUi {
    fn slider(&mut self, spec: &SliderSpec, value: &mut f64) -> bool;
    fn toggle(&mut self, value: &mut bool, label: &str, hover: &str) -> bool;
    /// A line of text.
    fn text(&mut self, text: &str);
    /// A line saying what is wrong (drawn as an error).
    fn error(&mut self, text: &str);
    /// A drop-down named `label` over `names`; `selected` indexes them.
    fn combo(&mut self, label: &str, selected: &mut usize, names: &[&str], hover: &str) -> bool;
    /// `label` and a row of radio buttons, each (name, hover); greyed out, with
    /// `disabled_hover`, unless `enabled`.
    fn radios(
        &mut self,
        label: &str,
        selected: &mut usize,
        options: &[(&str, &str)],
        enabled: bool,
        disabled_hover: &str,
    ) -> bool;
    /// Controls indented under the last one (`id` keeps their state apart).
    fn indented(&mut self, id: &str, add: &mut dyn FnMut(&mut dyn SettingsUi));
    /// A collapsible section named `title`, closed at first.
    fn section(&mut self, title: &str, add: &mut dyn FnMut(&mut dyn SettingsUi));
}

/// A drop-down over the variants `all` of `value` (named by `name`).
pub fn choose<E: Copy + PartialEq>(
    ui: &mut dyn SettingsUi,
    label: &str,
    value: &mut E,
    all: &[E],
    name: impl Fn(E) -> &'static str,
    hover: &str,
) -> bool {
    let names: Vec<&str> = all.iter().map(|&e| name(e)).collect();
    let mut i = all.iter().position(|&e| e == *value).unwrap_or(0);
    let changed = ui.combo(label, &mut i, &names, hover);
    if changed && let Some(&e) = all.get(i) {
        *value = e;
    }
    changed
}

/// Radio buttons over `options` (value, name, hover) of `value`.
pub fn radio<E: Copy + PartialEq>(
    ui: &mut dyn SettingsUi,
    label: &str,
    value: &mut E,
    options: &[(E, &str, &str)],
    enabled: bool,
    disabled_hover: &str,
) -> bool {
    let named: Vec<(&str, &str)> = options.iter().map(|&(_, n, h)| (n, h)).collect();
    let mut i = options.iter().position(|o| o.0 == *value).unwrap_or(usize::MAX);
    let changed = ui.radios(label, &mut i, &named, enabled, disabled_hover);
    if changed && let Some(o) = options.get(i) {
        *value = o.0;
    }
    changed
}

/// The slider of `f` over `value`'s field; true when it changed the value.
pub fn slider<T>(ui: &mut dyn SettingsUi, f: &Field<T>, value: &mut T) -> bool {
    slider_within(ui, f, value, f.spec.min, f.spec.max)
}

/// [`slider`] over `min..=max` within the declared range: for a field whose acceptable
/// values another field bounds (validation refuses the rest by that rule).
pub fn slider_within<T>(ui: &mut dyn SettingsUi, f: &Field<T>, value: &mut T, min: f64, max: f64) -> bool {
    let before = (f.get)(value);
    match field_slider(f, before, min, max) {
        FieldSlider::Exponent(spec, mut e) => {
            // The exponent moves; the value stays a power of two.
            let changed = ui.slider(&spec, &mut e);
            if changed {
                (f.set)(value, 2f64.powi(e.round() as i32));
            }
            changed
        }
        FieldSlider::Value(spec) => {
            let mut v = before;
            let changed = ui.slider(&spec, &mut v);
            if changed && v != before {
                (f.set)(value, v);
            }
            changed
        }
    }
}

/// What a field's slider moves.
#[derive(Clone, Debug, PartialEq)]
pub enum FieldSlider {
    /// The value itself.
    Value(SliderSpec),
    /// A power of two's exponent (the spec's range), now at the given one.
    Exponent(SliderSpec, f64),
}

/// The slider of field `f` now at `value`, over `min..=max` within its declared range: an
/// open range ends just inside its bound; a power-of-two field moves its exponent.
pub fn field_slider<T>(f: &Field<T>, value: f64, min: f64, max: f64) -> FieldSlider {
    let s = &f.spec;
    let min = min.max(s.min).min(s.max);
    let max = max.min(s.max).max(min);
    // An open range ends just below its maximum.
    let max = if s.max_open && max >= s.max {
        s.max - (s.max - s.min) * 1e-6
    } else {
        max
    };
    let help = format!("{} [{}: {}]", s.help, s.key, s.range_text());
    match s.scale {
        Scale::Pow2 => {
            let e = value.max(1.0).log2().round();
            let spec = SliderSpec {
                label: format!("{} (log2)", s.label),
                lo: min.max(1.0).log2().ceil(),
                hi: max.max(1.0).log2().floor(),
                integer: true,
                logarithmic: false,
                smallest_positive: None,
                suffix: String::new(),
                help: format!("{help}; {} {}", 2f64.powf(e), s.unit),
            };
            FieldSlider::Exponent(spec, e)
        }
        Scale::Linear | Scale::Log => {
            // An open range starts just above its minimum.
            let lo = if s.min_open && min <= s.min {
                open_start(s.min, max)
            } else {
                min
            };
            let logarithmic = s.scale == Scale::Log;
            let smallest_positive =
                (logarithmic && lo <= 0.0).then(|| if s.integer { 1.0 } else { open_start(0.0, max) });
            FieldSlider::Value(SliderSpec {
                label: s.label.to_string(),
                lo,
                hi: max,
                integer: s.integer,
                logarithmic,
                smallest_positive,
                suffix: if s.unit.is_empty() {
                    String::new()
                } else {
                    format!(" {}", s.unit)
                },
                help,
            })
        }
    }
}

/// The first slider value of a range open at `min` (or the smallest positive value of a
/// logarithmic one from 0): five decades below its maximum.
fn open_start(min: f64, max: f64) -> f64 {
    min + (max - min) * 1e-5
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::field::Spec;

    /// A panel recorded as lines, with scripted answers: what a method's panel draws can be
    /// checked without a window.
    #[derive(Default)]
    struct Script {
        lines: Vec<String>,
        slider_to: Option<f64>,
        pick: Option<usize>,
    }

    impl SettingsUi for Script {
        fn slider(&mut self, spec: &SliderSpec, value: &mut f64) -> bool {
            self.lines.push(format!(
                "slider {} {}..{} at {value}",
                spec.label, spec.lo, spec.hi
            ));
            match self.slider_to.take() {
                Some(v) => {
                    *value = v;
                    true
                }
                None => false,
            }
        }
        fn toggle(&mut self, value: &mut bool, label: &str, _: &str) -> bool {
            self.lines.push(format!("toggle {label} {value}"));
            false
        }
        fn text(&mut self, text: &str) {
            self.lines.push(text.into());
        }
        fn error(&mut self, text: &str) {
            self.lines.push(format!("error {text}"));
        }
        fn combo(&mut self, label: &str, selected: &mut usize, names: &[&str], _: &str) -> bool {
            self.lines.push(format!("combo {label} {}", names[*selected]));
            self.pick.take().map(|p| *selected = p).is_some()
        }
        fn radios(
            &mut self,
            label: &str,
            selected: &mut usize,
            o: &[(&str, &str)],
            on: bool,
            _: &str,
        ) -> bool {
            self.lines
                .push(format!("radios {label} {} of {} {on}", selected, o.len()));
            self.pick.take().map(|p| *selected = p).is_some()
        }
        fn indented(&mut self, id: &str, add: &mut dyn FnMut(&mut dyn SettingsUi)) {
            self.lines.push(format!("indent {id}"));
            add(self);
        }
        fn section(&mut self, title: &str, add: &mut dyn FnMut(&mut dyn SettingsUi)) {
            self.lines.push(format!("section {title}"));
            add(self);
        }
    }

    fn spec(scale: Scale, min: f64, max: f64) -> Spec {
        Spec {
            key: "k",
            label: "k",
            help: "h",
            unit: "px",
            min,
            max,
            min_open: false,
            max_open: false,
            integer: true,
            scale,
        }
    }

    #[test]
    fn a_power_of_two_field_moves_its_exponent_and_stays_a_power_of_two() {
        let f = Field::<f64> {
            spec: spec(Scale::Pow2, 16.0, 4096.0),
            get: |v| *v,
            set: |v, x| *v = x,
        };
        let mut v = 256.0;
        let mut ui = Script {
            slider_to: Some(10.4),
            ..Default::default()
        };
        assert!(slider(&mut ui, &f, &mut v));
        assert_eq!(v, 1024.0);
        assert_eq!(ui.lines, ["slider k (log2) 4..12 at 8"]);
    }

    #[test]
    fn an_open_range_starts_inside_it_and_a_bound_narrows_it() {
        let mut s = spec(Scale::Linear, 0.0, 1.0);
        s.min_open = true;
        s.max_open = true;
        s.integer = false;
        let f = Field::<f64> {
            spec: s,
            get: |v| *v,
            set: |v, x| *v = x,
        };
        let FieldSlider::Value(sp) = field_slider(&f, 0.5, 0.0, 1.0) else {
            panic!("a linear field moves its value")
        };
        assert!(sp.lo > 0.0 && sp.hi < 1.0 && sp.suffix == " px", "{sp:?}");
        let FieldSlider::Value(sp) = field_slider(&f, 0.5, 0.2, 0.6) else {
            panic!()
        };
        assert_eq!((sp.lo, sp.hi), (0.2, 0.6));
        // A logarithmic integer field from 0 starts its slider at 1.
        let g = Field::<f64> {
            spec: spec(Scale::Log, 0.0, 64.0),
            get: |v| *v,
            set: |v, x| *v = x,
        };
        let FieldSlider::Value(sp) = field_slider(&g, 4.0, 0.0, 64.0) else {
            panic!()
        };
        assert_eq!(sp.smallest_positive, Some(1.0));
    }

    #[test]
    fn choices_map_variants_to_indices_and_back() {
        #[derive(Clone, Copy, PartialEq, Debug)]
        enum E {
            A,
            B,
            C,
        }
        let mut ui = Script {
            pick: Some(2),
            ..Default::default()
        };
        let mut e = E::B;
        let name = |e: E| match e {
            E::A => "a",
            E::B => "b",
            E::C => "c",
        };
        assert!(choose(&mut ui, "pick", &mut e, &[E::A, E::B, E::C], name, ""));
        assert_eq!(e, E::C);
        ui.pick = Some(0);
        assert!(radio(
            &mut ui,
            "vis",
            &mut e,
            &[(E::A, "a", ""), (E::C, "c", "")],
            false,
            "off"
        ));
        assert_eq!(e, E::A);
        assert_eq!(ui.lines, ["combo pick b", "radios vis 1 of 2 false"]);
    }
}

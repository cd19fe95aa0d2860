//! The GUI's slider of a declared setting (`base::field`): range, scale, label, unit and
//! help from the declaration, so a slider offers exactly what validation accepts.

use crate::base::field::{Field, Scale};

/// The slider of `f` over `value`'s field; true when it changed the value.
pub fn slider<T>(ui: &mut egui::Ui, f: &Field<T>, value: &mut T) -> bool {
    slider_within(ui, f, value, f.spec.min, f.spec.max)
}

/// [`slider`] over `min..=max` within the declared range: for a field whose acceptable
/// values another field bounds (validation refuses the rest by that rule).
pub fn slider_within<T>(ui: &mut egui::Ui, f: &Field<T>, value: &mut T, min: f64, max: f64) -> bool {
    let s = &f.spec;
    let min = min.max(s.min).min(s.max);
    let max = max.min(s.max).max(min);
    // An open range ends just below its maximum.
    let max = if s.max_open && max >= s.max {
        s.max - (s.max - s.min) * 1e-6
    } else {
        max
    };
    let label = s.label.to_string();
    let help = format!("{} [{}: {}]", s.help, s.key, s.range_text());
    let before = (f.get)(value);
    match s.scale {
        Scale::Pow2 => {
            // The exponent moves; the value stays a power of two.
            let mut e = before.max(1.0).log2().round() as i32;
            let lo = min.max(1.0).log2().ceil() as i32;
            let hi = max.max(1.0).log2().floor() as i32;
            let r = ui
                .add(egui::Slider::new(&mut e, lo..=hi).text(format!("{label} (log2)")))
                .on_hover_text(format!("{help}; {} {}", 2f64.powi(e), s.unit));
            if r.changed() {
                (f.set)(value, 2f64.powi(e));
            }
            r.changed()
        }
        Scale::Linear | Scale::Log => {
            let mut v = before;
            // An open range starts just above its minimum.
            let lo = if s.min_open && min <= s.min {
                open_start(s.min, max)
            } else {
                min
            };
            let mut slider = egui::Slider::new(&mut v, lo..=max).text(label);
            if !s.unit.is_empty() {
                slider = slider.suffix(format!(" {}", s.unit));
            }
            if s.integer {
                slider = slider.integer();
            }
            if s.scale == Scale::Log {
                slider = slider.logarithmic(true);
                if lo <= 0.0 {
                    let smallest = if s.integer { 1.0 } else { open_start(0.0, max) };
                    slider = slider.smallest_positive(smallest);
                }
            }
            let r = ui.add(slider).on_hover_text(help);
            if r.changed() && v != before {
                (f.set)(value, v);
            }
            r.changed()
        }
    }
}

/// The first slider value of a range open at `min` (or the smallest positive value of a
/// logarithmic one from 0): five decades below its maximum.
fn open_start(min: f64, max: f64) -> f64 {
    min + (max - min) * 1e-5
}

//! Settings typed once (issue 38): every method's numeric settings are declared
//! (`base::field`), and validation, the GUI's sliders and `--set` read the declaration. A
//! declared range is accepted at both ends and refused beyond them by `--set`'s path, every
//! number in a method's own table is declared, and the methods draw no slider of their own.

use lightcut::base::field::{Scale, Spec};
use lightcut::methods::REGISTRY;
use lightcut::renderer::settings::RenderSettings;

fn text(spec: &Spec, v: f64) -> String {
    if spec.integer {
        format!("{}", v as i64)
    } else {
        format!("{v:?}")
    }
}

/// `--set path=v` then the method's validation: the first refusal.
fn set(m: &lightcut::methods::MethodInfo, path: &str, spec: &Spec, v: f64) -> Result<(), String> {
    let mut s = RenderSettings::default();
    s.set_path(path, &text(spec, v))?;
    (m.validate)(&s)
}

#[test]
fn every_declared_setting_is_accepted_at_its_ends_and_refused_beyond_them_by_name() {
    let mut checked = 0;
    for m in REGISTRY {
        for sec in (m.fields)() {
            for spec in &sec.specs {
                let path = format!("{}.{}", sec.section, spec.key);
                let range_refusal = |e: &str| e.contains(&format!("{path} ")) && e.contains("out of range");
                let step = if spec.integer {
                    1.0
                } else {
                    (spec.max.abs() * 1e-3).max(1e-6)
                };
                let (lo, hi) = if spec.scale == Scale::Pow2 {
                    (spec.min.log2().ceil().exp2(), spec.max.log2().floor().exp2())
                } else if spec.min_open {
                    (spec.min + step, spec.max)
                } else {
                    (spec.min, spec.max)
                };
                let hi = if spec.max_open { hi - step } else { hi };
                for v in [lo, hi] {
                    if let Err(e) = set(m, &path, spec, v) {
                        assert!(!range_refusal(&e), "{}: {path} = {v} is in range but: {e}", m.id);
                    }
                }
                let mut outside = Vec::new();
                // An integer declared up to its type's largest value has no value above it.
                if !(spec.integer && spec.max >= u32::MAX as f64) {
                    outside.push(if spec.scale == Scale::Pow2 {
                        2.0 * spec.max
                    } else {
                        spec.max + step
                    });
                }
                if spec.max_open {
                    outside.push(spec.max);
                }
                if spec.min_open {
                    outside.push(spec.min);
                } else if !(spec.integer && spec.min <= 0.0) {
                    outside.push(spec.min - step);
                }
                if spec.scale == Scale::Pow2 && lo * 3.0 <= spec.max {
                    outside.push(lo * 3.0);
                }
                for v in outside {
                    match set(m, &path, spec, v) {
                        Ok(()) => panic!(
                            "{}: {path} = {v} is out of range ({}) but accepted",
                            m.id,
                            spec.range_text()
                        ),
                        Err(e) => assert!(
                            range_refusal(&e),
                            "{}: {path} = {v} refused without naming it: {e}",
                            m.id
                        ),
                    }
                }
                checked += 1;
            }
        }
    }
    assert!(checked >= 40, "only {checked} declared settings");
}

fn numbers(prefix: &str, t: &toml::Table, out: &mut Vec<String>) {
    for (k, v) in t {
        let p = format!("{prefix}.{k}");
        match v {
            toml::Value::Integer(_) | toml::Value::Float(_) => out.push(p),
            toml::Value::Table(t) => numbers(&p, t, out),
            _ => {}
        }
    }
}

#[test]
fn every_number_in_a_methods_own_table_is_declared() {
    for m in REGISTRY {
        let sections = (m.fields)();
        let declared: Vec<String> = sections
            .iter()
            .flat_map(|s| s.specs.iter().map(move |f| format!("{}.{}", s.section, f.key)))
            .collect();
        for s in &sections {
            let Some(t) = &s.table else { continue };
            let mut leaves = Vec::new();
            numbers(&s.section, t, &mut leaves);
            for l in leaves {
                assert!(
                    declared.contains(&l),
                    "{}: {l} is a number without a declaration",
                    m.id
                );
            }
        }
    }
}

#[test]
fn the_methods_draw_no_slider_of_their_own() {
    // Their sliders are `base::settings_ui::slider`'s, made from the declarations: no method
    // builds a `SliderSpec` or calls the toolkit's slider itself (nor names the toolkit).
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/methods");
    let mut stack = vec![root];
    let mut files = 0;
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                files += 1;
                let text = std::fs::read_to_string(&p).unwrap();
                for (n, line) in text.lines().enumerate() {
                    assert!(
                        !["SliderSpec", ".slider(", "Slider::new(", "DragValue::new("]
                            .iter()
                            .any(|t| line.contains(t)),
                        "{}:{}: a slider not made from a declared setting",
                        p.display(),
                        n + 1
                    );
                }
            }
        }
    }
    assert!(files > 20, "{files} files scanned");
}

#[test]
fn every_methods_settings_panel_draws_its_declared_sliders() {
    // Each method's panel, at its defaults and with every optional part shown (shadow rays
    // with map visibility, several bounces): a slider for a key without a declaration would
    // panic here.
    let ctx = egui::Context::default();
    for m in REGISTRY {
        for variant in 0..2 {
            let mut s = RenderSettings::default();
            if variant == 1 {
                s.gi.shadow_rays = true;
                s.vpl.bounces = 2;
                for key in [
                    "sampling.visibility",
                    "methods.light-culling.visibility",
                    "methods.val.visibility",
                ] {
                    let v = if key.starts_with("methods.val") {
                        "\"pcss\""
                    } else {
                        "\"ism\""
                    };
                    s.set_path(key, v).unwrap();
                }
            }
            let before = s.clone();
            let _ = ctx.run_ui(egui::RawInput::default(), |ui| (m.ui)(ui, m.id, &mut s));
            assert_eq!(s, before, "{}: drawing its panel changed its settings", m.id);
        }
    }
}

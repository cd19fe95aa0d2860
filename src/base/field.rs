//! Numeric settings declared once.
//!
//! A [`Field`] names a setting by its TOML key under its section (`relative_error`,
//! `interleave.n`), gives its range, unit, label and help, and reads and writes it in its
//! settings struct. The settings' validation ([`check`]), the GUI's slider
//! (`base::settings_ui::slider`) and `--set` (the section's TOML path plus the key) all go
//! through it, so a slider cannot offer a value that validation refuses nor stop short of one
//! it accepts. [`Spec`] is the part without the struct's type, which the registry lists for
//! the tests.

/// How a slider moves over the range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    Linear,
    /// Logarithmic (from the smallest positive value when the range starts at 0).
    Log,
    /// Powers of two only (a texture size): the slider moves the exponent.
    Pow2,
}

/// A numeric setting's declaration, without the struct it lives in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spec {
    /// The TOML key under the section (dots for nested tables: `interleave.n`).
    pub key: &'static str,
    /// The slider's label.
    pub label: &'static str,
    /// What it does (the slider's hover text).
    pub help: &'static str,
    /// Its unit ("" for a plain number), shown after the slider's value.
    pub unit: &'static str,
    pub min: f64,
    pub max: f64,
    /// The range excludes `min` (`0 < epsilon`).
    pub min_open: bool,
    /// The range excludes `max` (`bias < 0.5`).
    pub max_open: bool,
    /// Whole numbers only (an integer field).
    pub integer: bool,
    pub scale: Scale,
}

impl Spec {
    /// Whether `v` is in the range (NaN never is).
    pub fn contains(&self, v: f64) -> bool {
        // The fields are f32 or integers: the bounds as f32 (0.99 as f32 is above 0.99).
        let (min, max) = (self.min as f32 as f64, self.max as f32 as f64);
        let above = if self.min_open { v > min } else { v >= min };
        let below = if self.max_open { v < max } else { v <= max };
        let pow2 =
            self.scale != Scale::Pow2 || (v >= 1.0 && (v as u64).is_power_of_two() && v.fract() == 0.0);
        above && below && pow2
    }

    /// The range as validation messages and help texts write it (`0..=1`, `0 < v <= 1`).
    pub fn range_text(&self) -> String {
        if self.scale == Scale::Pow2 {
            format!("a power of two, {}..={}", fmt(self.min), fmt(self.max))
        } else if self.min_open || self.max_open {
            format!(
                "{} {} v {} {}",
                fmt(self.min),
                if self.min_open { "<" } else { "<=" },
                if self.max_open { "<" } else { "<=" },
                fmt(self.max)
            )
        } else {
            format!("{}..={}", fmt(self.min), fmt(self.max))
        }
    }

    /// The message refusing `v` in `section` (`methods.lightcuts.max_cut 0 is out of range
    /// (1..=1024)`).
    pub fn refusal(&self, section: &str, v: f64) -> String {
        format!(
            "{}{}{} {} is out of range ({})",
            section,
            if section.is_empty() { "" } else { "." },
            self.key,
            fmt(v),
            self.range_text()
        )
    }
}

fn fmt(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        // The fields are f32: their shortest text.
        format!("{}", v as f32)
    }
}

/// A numeric setting of the settings struct `T`: its [`Spec`] and its accessors.
pub struct Field<T> {
    pub spec: Spec,
    pub get: fn(&T) -> f64,
    pub set: fn(&mut T, f64),
}

impl<T> Field<T> {
    /// Refuses the value out of range, naming `section.key`.
    pub fn check(&self, section: &str, value: &T) -> Result<(), String> {
        let v = (self.get)(value);
        if self.spec.contains(v) {
            Ok(())
        } else {
            Err(self.spec.refusal(section, v))
        }
    }
}

/// Every field of `fields` in range, or the first refusal (naming `section.key`).
pub fn check<T>(section: &str, fields: &[Field<T>], value: &T) -> Result<(), String> {
    fields.iter().try_for_each(|f| f.check(section, value))
}

/// The field of `fields` with `key` (panics on a key none has: a programming error the
/// settings UI tests find).
pub fn find<'a, T>(fields: &'a [Field<T>], key: &str) -> &'a Field<T> {
    fields
        .iter()
        .find(|f| f.spec.key == key)
        .unwrap_or_else(|| panic!("no declared setting '{key}'"))
}

/// The specs of `fields` (the registry's list for the tests).
pub fn specs<T>(fields: &[Field<T>]) -> Vec<Spec> {
    fields.iter().map(|f| f.spec).collect()
}

/// Declares a [`Field`] of `$t` for the struct path `$($f).+` (a field of type `$ty`):
/// `field!(LightcutsSettings, relative_error: f32, "relative error", "", 0.0, 1.0, Log, "help")`.
/// Options after the help: `open` (the range excludes its minimum), `open_max` (its maximum).
#[macro_export]
macro_rules! field {
    ($t:ty, $($f:ident).+ : $ty:ident, $label:expr, $unit:expr, $min:expr, $max:expr, $scale:ident, $help:expr $(, $opt:ident)*) => {
        $crate::base::field::Field::<$t> {
            spec: $crate::base::field::Spec {
                key: $crate::field!(@key $($f).+),
                label: $label,
                help: $help,
                unit: $unit,
                min: ($min) as f64,
                max: ($max) as f64,
                min_open: $crate::field!(@min $($opt)*),
                max_open: $crate::field!(@max $($opt)*),
                integer: $crate::field!(@int $ty),
                scale: $crate::base::field::Scale::$scale,
            },
            get: |s: &$t| s.$($f).+ as f64,
            set: |s: &mut $t, v: f64| s.$($f).+ = $crate::field!(@from v, $ty),
        }
    };
    (@key $first:ident $(. $rest:ident)*) => { concat!(stringify!($first) $(, ".", stringify!($rest))*) };
    (@min) => { false };
    (@min open $($r:ident)*) => { true };
    (@min open_max $($r:ident)*) => { $crate::field!(@min $($r)*) };
    (@max) => { false };
    (@max open_max $($r:ident)*) => { true };
    (@max open $($r:ident)*) => { $crate::field!(@max $($r)*) };
    (@int f32) => { false };
    (@int f64) => { false };
    (@int $other:ty) => { true };
    (@from $v:ident, f32) => { $v as f32 };
    (@from $v:ident, f64) => { $v };
    (@from $v:ident, $other:ty) => { $v.round().max(0.0) as $other };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Default)]
    struct Inner {
        n: u32,
    }
    #[derive(Default)]
    struct S {
        e: f32,
        inner: Inner,
    }

    static FIELDS: &[Field<S>] = &[
        crate::field!(S, e: f32, "error", "", 0.0, 1.0, Log, "an error bound", open),
        crate::field!(S, inner.n: u32, "n", "px", 1, 16, Linear, "a count"),
    ];

    #[test]
    fn a_declaration_reads_writes_and_checks_its_field() {
        let mut s = S {
            e: 0.5,
            inner: Inner { n: 4 },
        };
        assert_eq!(FIELDS[1].spec.key, "inner.n");
        assert!(FIELDS[1].spec.integer && !FIELDS[0].spec.integer);
        assert!(check("methods.x", FIELDS, &s).is_ok());
        (FIELDS[1].set)(&mut s, 7.6);
        assert_eq!(s.inner.n, 8);
        assert_eq!((FIELDS[1].get)(&s), 8.0);
        (FIELDS[0].set)(&mut s, 0.0);
        assert_eq!(
            check("methods.x", FIELDS, &s).unwrap_err(),
            "methods.x.e 0 is out of range (0 < v <= 1)"
        );
        s.e = f32::NAN;
        assert!(check("methods.x", FIELDS, &s).is_err());
        s.e = 1.0;
        s.inner.n = 17;
        assert_eq!(
            check("methods.x", FIELDS, &s).unwrap_err(),
            "methods.x.inner.n 17 is out of range (1..=16)"
        );
        assert_eq!(specs(FIELDS).len(), 2);
    }
}

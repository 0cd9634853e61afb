//! The text report, written from the typed records: one labelled line per result, integers
//! as integers, and each approximate number rounded to the significant digits its error bound
//! or residual supports (at most [`MAX_DIGITS`]).

use super::{Report, Step};
use std::fmt::Write as _;

pub use mechanica_svg::{MAX_DIGITS, number};

/// How accurate a printed number is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Precision {
    /// Exact, or accurate to rounding: [`MAX_DIGITS`] digits.
    Exact,
    /// |error| ≤ the given absolute bound.
    Absolute(f64),
    /// |error| ≤ the given bound times |value|.
    Relative(f64),
}

impl Precision {
    /// The significant digits `value` supports: 1 + log10(|value| / bound), in 1..=MAX_DIGITS
    /// (a relative bound 1e-6 gives 7 digits).
    pub fn digits(self, value: f64) -> usize {
        let relative = match self {
            Precision::Exact => return MAX_DIGITS,
            Precision::Absolute(bound) if value != 0.0 => bound / value.abs(),
            Precision::Absolute(_) => return MAX_DIGITS,
            Precision::Relative(bound) => bound,
        };
        if relative.is_infinite() {
            return 1;
        }
        if relative.is_nan() || relative <= 0.0 {
            return MAX_DIGITS;
        }
        let digits = 1.0 - relative.log10().ceil();
        digits.clamp(1.0, MAX_DIGITS as f64) as usize
    }
}

/// The JSON name of an enum value (its snake_case tag), with spaces for underscores.
pub fn name_of<T: serde::Serialize>(value: &T) -> String {
    match serde_json::to_value(value) {
        Ok(serde_json::Value::String(name)) => name.replace('_', " "),
        _ => "?".into(),
    }
}

/// A bound or residual itself: two significant digits.
pub fn bound(value: f64) -> String {
    format!("{value:.1e}")
}

/// Lines of the text report under construction.
#[derive(Debug, Default)]
pub struct Text {
    out: String,
}

const LABEL_WIDTH: usize = 44;

impl Text {
    /// A line `label  value` with free text.
    pub fn line(&mut self, label: &str, value: &str) {
        let _ = writeln!(self.out, "  {label:<LABEL_WIDTH$} {value}");
    }

    /// An integer.
    pub fn count(&mut self, label: &str, n: usize) {
        self.line(label, &n.to_string());
    }

    /// One number with its unit and, for an approximate one, its accuracy in words.
    pub fn value(&mut self, label: &str, value: f64, unit: &str, precision: Precision) {
        self.values(label, &[value], unit, precision);
    }

    /// Numbers with a common unit and accuracy.
    pub fn values(&mut self, label: &str, values: &[f64], unit: &str, precision: Precision) {
        let shown: Vec<String> = values.iter().map(|&v| number(v, precision.digits(v))).collect();
        let list = if shown.len() == 1 {
            shown.join("")
        } else {
            format!("[{}]", shown.join(", "))
        };
        self.line(label, &with_unit(&list, unit, precision));
    }

    /// Numbers named one by one (e.g. by coordinate), with a common unit and accuracy.
    pub fn named(&mut self, label: &str, names: &[String], values: &[f64], unit: &str, precision: Precision) {
        if names.len() != values.len() {
            return self.values(label, values, unit, precision);
        }
        let shown: Vec<String> = names
            .iter()
            .zip(values)
            .map(|(name, &v)| format!("{name} = {}", number(v, precision.digits(v))))
            .collect();
        self.line(label, &with_unit(&shown.join(", "), unit, precision));
    }

    /// A remark under the step.
    pub fn note(&mut self, note: &str) {
        let _ = writeln!(self.out, "  → {note}");
    }

    /// The text written.
    pub fn finish(self) -> String {
        self.out
    }
}

fn with_unit(values: &str, unit: &str, precision: Precision) -> String {
    let mut text = values.to_string();
    if !unit.is_empty() {
        text.push(' ');
        text.push_str(unit);
    }
    match precision {
        Precision::Absolute(b) if b > 0.0 => text.push_str(&format!("   (± {})", bound(b))),
        Precision::Relative(b) if b > 0.0 => text.push_str(&format!("   (relative ± {})", bound(b))),
        _ => {}
    }
    text
}

impl Step {
    fn write_text(&self, out: &mut Text) {
        let _ = write!(out.out, "\n## ");
        if let Some(scene) = &self.scene {
            let _ = write!(out.out, "[{scene}] ");
        }
        let _ = writeln!(out.out, "{} ({:.1} µs)", self.title, self.seconds * 1e6);
        self.record.write_text(out);
        for warning in &self.warnings {
            out.note(warning);
        }
        for note in &self.notes {
            out.note(note);
        }
    }
}

impl Report {
    /// The human-readable report.
    pub fn to_text(&self) -> String {
        let mut out = Text::default();
        let _ = writeln!(out.out, "mechanica {} — {}", self.mechanica_version, self.title);
        for step in &self.steps {
            step.write_text(&mut out);
        }
        out.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn digits_follow_the_bound() {
        assert_eq!(Precision::Relative(1e-6).digits(3.0), 7);
        assert_eq!(Precision::Relative(2e-6).digits(3.0), 6);
        assert_eq!(Precision::Relative(1e-17).digits(3.0), MAX_DIGITS);
        assert_eq!(Precision::Exact.digits(3.0), MAX_DIGITS);
        assert_eq!(Precision::Absolute(1e-3).digits(12.0), 5);
        assert_eq!(Precision::Absolute(1.0).digits(0.5), 1);
        assert_eq!(Precision::Relative(f64::INFINITY).digits(1.0), 1);
    }

    #[test]
    fn printed_numbers_are_rounded_at_the_bound_and_no_finer() {
        // A family of values and bounds: the printed value is the true one rounded to d digits
        // (within half a unit of the last digit), that unit is not finer than the bound, and
        // one digit more would be finer than the bound.
        let mut x = 0.123_456_789_f64;
        for k in 0..400 {
            x = (x * 7.31 + 0.17).fract();
            let value = (x - 0.5) * 10f64.powi(k % 15 - 7);
            let relative = 10f64.powi(-(k % 12)) * (0.5 + x);
            let d = Precision::Relative(relative).digits(value);
            let back: f64 = number(value, d).parse().expect("a plain number");
            let unit = 10f64.powf(value.abs().log10().floor() + 1.0 - d as f64);
            assert!(
                (back - value).abs() <= 0.5 * unit * (1.0 + 1e-9),
                "{value} to {d} digits: {back}"
            );
            let unit_relative = 10f64.powf(1.0 - d as f64);
            assert!(
                unit_relative >= relative * (1.0 - 1e-12) || d == 1,
                "{relative}: {d} digits"
            );
            assert!(
                10f64.powf(-(d as f64)) <= relative || d == MAX_DIGITS,
                "{relative}: {d}"
            );
        }
    }
}

//! Numbers printed for people: a given count of significant digits, trailing zeros dropped.

/// The most significant digits printed: an exact value, or one accurate to rounding.
pub const MAX_DIGITS: usize = 10;

/// `value` with `digits` significant digits, trailing zeros dropped: fixed notation for
/// magnitudes in [1e-4, 1e6), scientific otherwise; infinities as ∞.
pub fn number(value: f64, digits: usize) -> String {
    if !value.is_finite() {
        return if value.is_nan() {
            "NaN".into()
        } else if value > 0.0 {
            "∞".into()
        } else {
            "−∞".into()
        };
    }
    if value == 0.0 {
        return "0".into();
    }
    let digits = digits.clamp(1, MAX_DIGITS);
    let scientific = format!("{:.*e}", digits - 1, value);
    let (mantissa, exponent) = scientific.split_once('e').unwrap_or((&scientific, "0"));
    let exponent: i32 = exponent.parse().unwrap_or(0);
    if (-4..6).contains(&exponent) {
        let decimals = (digits as i32 - 1 - exponent).max(0) as usize;
        trim_zeros(&format!("{value:.decimals$}"))
    } else {
        format!("{}e{exponent}", trim_zeros(mantissa))
    }
}

fn trim_zeros(text: &str) -> String {
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_rounded_and_trimmed() {
        assert_eq!(number(3.0, 10), "3");
        assert_eq!(number(2.0 / 3.0, 4), "0.6667");
        assert_eq!(number(1234567.89, 7), "1.234568e6");
        assert_eq!(number(123456.789, 7), "123456.8");
        assert_eq!(number(98765.4321, 7), "98765.43");
        assert_eq!(number(-1.5e-7, 3), "-1.5e-7");
        assert_eq!(number(0.0, 5), "0");
        assert_eq!(number(f64::INFINITY, 5), "∞");
        // Rounding that carries into the next power of ten.
        assert_eq!(number(9.9996, 4), "10");
    }
}

//! Axis ticks: round values 1, 2 or 5 × 10^k on a linear axis, powers of ten on a logarithmic
//! one, each printed with no more digits than it needs.

/// Tick values for a linear axis over [`lo`, `hi`]: multiples of a step 1, 2 or 5 × 10^k
/// chosen for about `count` ticks, each the integer multiple k·step (so that its printed form
/// is short), with the step.
pub fn ticks(lo: f64, hi: f64, count: usize) -> (Vec<f64>, f64) {
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo {
        return (vec![lo], 1.0);
    }
    let raw = (hi - lo) / count.max(1) as f64;
    let decade = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * decade)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * decade);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    ((first..=last).map(|k| k as f64 * step).collect(), step)
}

/// A tick value printed with no more digits than the step needs.
pub fn tick_label(value: f64, step: f64) -> String {
    if value == 0.0 {
        return "0".into();
    }
    let digits = (value.abs().log10().floor() - step.log10().floor()) as usize + 1;
    crate::number(value, digits.clamp(1, 6))
}

/// The powers of ten for a logarithmic axis over [`lo`, `hi`] (both > 0), as their exponents:
/// every decade, or every 2nd, 3rd, … when that keeps the count at most `count`, always at least
/// two (the decades around the range when it holds less than one).
pub fn log_ticks(lo: f64, hi: f64, count: usize) -> Vec<i32> {
    if !(lo > 0.0 && hi >= lo && hi.is_finite()) {
        return vec![0];
    }
    let first = lo.log10().ceil() as i32;
    let last = hi.log10().floor() as i32;
    if last <= first {
        let below = lo.log10().floor() as i32;
        return vec![below, (hi.log10().ceil() as i32).max(below + 1)];
    }
    let span = (last - first) as usize;
    let stride = span.div_ceil(count.max(2) - 1).max(1) as i32;
    let start = first.div_euclid(stride) * stride;
    let start = if start < first { start + stride } else { start };
    (0..).map(|k| start + k * stride).take_while(|&e| e <= last).collect()
}

/// 10 to the power `exponent`, written with superscript digits: "10⁻¹²", "10⁰", "10³".
pub fn power_of_ten(exponent: i32) -> String {
    const SUPERSCRIPTS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut text = String::from("10");
    if exponent < 0 {
        text.push('⁻');
    }
    for digit in exponent.unsigned_abs().to_string().bytes() {
        text.push(SUPERSCRIPTS[usize::from(digit - b'0')]);
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ticks over random ranges (about six per range, so at most three significant digits
    /// each): a 1-2-5 step, inside the range, printed without rounding noise.
    #[test]
    fn ticks_are_round_and_print_cleanly() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut uniform = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..2000 {
            let scale = 10f64.powf(16.0 * uniform() - 8.0);
            let lo = if uniform() < 0.5 { 0.0 } else { -scale * uniform() };
            let hi = lo + scale * (0.1 + uniform());
            let (values, step) = ticks(lo, hi, 6);
            let mantissa = step / 10f64.powf(step.log10().floor());
            assert!(
                [1.0, 2.0, 5.0].iter().any(|m| (mantissa - m).abs() < 1e-9),
                "step {step}"
            );
            assert!((2..=14).contains(&values.len()), "{lo} {hi}: {values:?}");
            for v in &values {
                assert!(*v >= lo - 1e-12 * scale && *v <= hi + 1e-12 * scale);
                let label = tick_label(*v, step);
                let mantissa = label.split('e').next().unwrap_or("").replace(['-', '.'], "");
                let significant = mantissa.trim_start_matches('0').trim_end_matches('0');
                assert!(significant.len() <= 3, "{label} ({v}, step {step})");
                let back: f64 = label.parse().expect("a number");
                assert!((back - v).abs() <= 1e-9 * step, "{label} vs {v}");
            }
        }
    }

    /// Log ticks over random ranges of 10⁻²⁰ to 10²⁰: exponents of ten evenly spaced, inside the
    /// range, at most the count asked, at least two; their labels are "10" and superscript
    /// digits that read back as the exponent (never a decimal expansion such as 9.999…e-13).
    #[test]
    fn log_ticks_are_powers_of_ten_with_clean_labels() {
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut uniform = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let superscript = |c: char| "⁰¹²³⁴⁵⁶⁷⁸⁹".chars().position(|s| s == c);
        for _ in 0..2000 {
            let lo = 10f64.powf(40.0 * uniform() - 20.0);
            let hi = lo * 10f64.powf(25.0 * uniform());
            let count = 3 + (uniform() * 6.0) as usize;
            let exponents = log_ticks(lo, hi, count);
            assert!(exponents.len() >= 2, "{lo} {hi}: {exponents:?}");
            let spans_a_decade = hi.log10().floor() > lo.log10().ceil();
            if spans_a_decade {
                assert!(exponents.len() <= count, "{lo} {hi} {count}: {exponents:?}");
                for e in &exponents {
                    let value = 10f64.powi(*e);
                    assert!(
                        value >= lo * (1.0 - 1e-12) && value <= hi * (1.0 + 1e-12),
                        "{lo} {hi}: {e}"
                    );
                }
            }
            let strides: Vec<i32> = exponents.windows(2).map(|w| w[1] - w[0]).collect();
            assert!(strides.iter().all(|s| *s == strides[0] && *s > 0), "{exponents:?}");
            for e in exponents {
                let label = power_of_ten(e);
                let rest = label.strip_prefix("10").expect("starts with 10");
                let (sign, digits) = match rest.strip_prefix('⁻') {
                    Some(digits) => (-1, digits),
                    None => (1, rest),
                };
                let mut value = 0i32;
                for c in digits.chars() {
                    let d = superscript(c).unwrap_or_else(|| panic!("{label}: not a superscript digit"));
                    value = 10 * value + d as i32;
                }
                assert_eq!(sign * value, e, "{label}");
            }
        }
        assert_eq!(power_of_ten(-12), "10⁻¹²");
        assert_eq!(power_of_ten(0), "10⁰");
        assert_eq!(log_ticks(1e-16, 1e-4, 7), vec![-16, -14, -12, -10, -8, -6, -4]);
    }
}

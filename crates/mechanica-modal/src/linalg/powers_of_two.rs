//! Exact scaling by powers of two: the binary exponent of a double and x·2^e for any e, used to
//! bring pencils, shifts and small blocks near one before they are multiplied.

/// 2^e for −1022 ≤ e ≤ 1023 (a normal double), built from its bits.
fn power_of_two(e: i32) -> f64 {
    debug_assert!((-1022..=1023).contains(&e));
    f64::from_bits(((e + 1023) as u64) << 52)
}

/// The binary exponent e of a finite x ≠ 0, 2^(e−1) ≤ |x| < 2^e (frexp's), read from the
/// exponent field (a subnormal x is first scaled by 2^64, exactly). 0 for x = 0.
pub(crate) fn exponent(x: f64) -> i32 {
    let x = x.abs();
    if x == 0.0 {
        return 0;
    }
    let biased = (x.to_bits() >> 52) as i32;
    if biased == 0 {
        return exponent(x * power_of_two(64)) - 64;
    }
    biased - 1022
}

/// x·2^e, in steps of at most 2^±1000 that move x towards its result: exact whenever the result
/// is a normal double.
pub fn times_power_of_two(x: f64, e: i32) -> f64 {
    let mut value = x;
    let mut remaining = e;
    while remaining != 0 {
        let step = remaining.clamp(-1000, 1000);
        value *= power_of_two(step);
        remaining -= step;
    }
    value
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn powers_of_two_are_exact_over_the_normal_range() {
        let mut expected = 1.0_f64;
        for e in 0..=1023 {
            assert_eq!(power_of_two(e), expected, "2^{e}");
            expected *= 2.0;
        }
        let mut expected = 1.0_f64;
        for e in (-1022..=0).rev() {
            assert_eq!(power_of_two(e), expected, "2^{e}");
            expected /= 2.0;
        }
    }

    #[test]
    fn exponents_bracket_every_magnitude_subnormals_included() {
        let mut samples = vec![f64::MIN_POSITIVE, f64::MAX, 1.0, 0.5, 0.75, 3.0, 4.0];
        let mut x = 5e-324_f64;
        while x.is_finite() {
            samples.extend([x, x * 1.5, x * 1.999_999, -x]);
            x *= 2.0;
        }
        for x in samples.into_iter().filter(|x| x.is_finite() && *x != 0.0) {
            let e = exponent(x);
            // 2^(e−1) ≤ |x| < 2^e, checked by exact halvings and doublings of |x|.
            let scaled = times_power_of_two(times_power_of_two(x.abs(), -e / 2), -(e - e / 2));
            assert!((0.5..1.0).contains(&scaled), "x {x:e}: e {e}, scaled {scaled}");
        }
    }

    #[test]
    fn scaling_by_large_exponents_goes_in_steps() {
        assert_eq!(
            times_power_of_two(f64::MAX, -2046),
            f64::MAX / 2f64.powi(1023) / 2f64.powi(1023)
        );
        assert_eq!(
            times_power_of_two(5e-324, 2100),
            5e-324 * 2f64.powi(1000) * 2f64.powi(1000) * 2f64.powi(100)
        );
        assert_eq!(times_power_of_two(3.0, 0), 3.0);
    }
}

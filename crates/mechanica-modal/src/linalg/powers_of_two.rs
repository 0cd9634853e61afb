//! Exact scaling by powers of two: the binary exponent of a double and x·2^e for any e, used to
//! bring pencils, shifts and small blocks near one before they are multiplied.

/// The binary exponent e of x ≠ 0, 2^(e−1) ≤ |x| < 2^e (frexp's).
pub(crate) fn exponent(x: f64) -> i32 {
    let x = x.abs();
    let mut e = x.log2().floor() as i32 + 1;
    // log2 can be off by one next to powers of two.
    while e > -1073 && times_power_of_two(1.0, e - 1) > x {
        e -= 1;
    }
    while times_power_of_two(x, -e) >= 1.0 {
        e += 1;
    }
    e
}

/// x·2^e, in steps of at most 2^±1000 that move x towards its result: exact whenever the result
/// is a normal double.
pub fn times_power_of_two(x: f64, e: i32) -> f64 {
    let mut value = x;
    let mut remaining = e;
    while remaining != 0 {
        let step = remaining.clamp(-1000, 1000);
        value *= 2f64.powi(step);
        remaining -= step;
    }
    value
}

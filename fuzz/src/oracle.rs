//! Oracles shared by the C-ABI targets.

use mechanica::ffi::{MECH_STATUS_OK, MECH_STATUS_PANIC, mech_status_t};

/// The statuses a call may return (`MECH_STATUS_OK` … `MECH_STATUS_PARSE_ERROR`); anything
/// else, including `MECH_STATUS_PANIC`, is a library bug and aborts the run.
pub fn check_status(call: &str, status: mech_status_t) {
    assert!(
        status != MECH_STATUS_PANIC,
        "{call}: the library panicked: {}",
        last_error()
    );
    // 0 OK through 13 MECH_STATUS_OUT_OF_RANGE (include/mechanica.h).
    assert!((0..=13).contains(&status), "{call}: undocumented status {status}");
}

/// This thread's last error message.
pub fn last_error() -> String {
    let mut buffer = [0u8; 512];
    // SAFETY: the buffer is writable for its full length.
    let length = unsafe { mechanica::ffi::mech_last_error(buffer.as_mut_ptr().cast(), buffer.len()) };
    String::from_utf8_lossy(&buffer[..length.min(buffer.len() - 1)]).into_owned()
}

/// An output value whose bytes start as a fixed pattern, so that a failed call can be checked
/// to have written nothing. `T` must be plain old data (the ABI's structs, doubles, integers).
pub struct Sentinel<T: Copy> {
    pub value: T,
}

const PATTERN: u8 = 0xA5;

impl<T: Copy> Sentinel<T> {
    pub fn new() -> Self {
        let mut value = std::mem::MaybeUninit::<T>::uninit();
        // SAFETY: every bit pattern is a valid value of the ABI's plain-data types.
        let value = unsafe {
            std::ptr::write_bytes(value.as_mut_ptr(), PATTERN, 1);
            value.assume_init()
        };
        Sentinel { value }
    }

    pub fn ptr(&mut self) -> *mut T {
        &mut self.value
    }

    /// Whether no byte changed since [`Sentinel::new`].
    pub fn untouched(&self) -> bool {
        // SAFETY: the value's bytes were all initialised by `new` and are read, not written.
        let bytes =
            unsafe { std::slice::from_raw_parts((&self.value as *const T).cast::<u8>(), std::mem::size_of::<T>()) };
        bytes.iter().all(|&b| b == PATTERN)
    }
}

impl<T: Copy> Default for Sentinel<T> {
    fn default() -> Self {
        Self::new()
    }
}

/// A vector of doubles filled with the sentinel pattern.
pub fn sentinel_doubles(n: usize) -> Vec<f64> {
    vec![f64::from_bits(u64::from_ne_bytes([PATTERN; 8])); n]
}

/// Whether every double in `values` still holds the sentinel pattern.
pub fn doubles_untouched(values: &[f64]) -> bool {
    let pattern = u64::from_ne_bytes([PATTERN; 8]);
    values.iter().all(|v| v.to_bits() == pattern)
}

/// Checks the output contract of one call: on failure nothing was written (`untouched`), on
/// success every number written is finite (`values`).
pub fn check_outputs(call: &str, status: mech_status_t, untouched: bool, values: &[f64]) {
    check_status(call, status);
    if status == MECH_STATUS_OK {
        assert!(finite(values), "{call}: success with a non-finite output {values:?}");
    } else {
        assert!(untouched, "{call}: failed with status {status} but wrote an output");
    }
}

pub fn finite(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite())
}

/// |a − b| ≤ tolerance·scale, with `scale` ≥ |a|, |b| chosen by the caller.
pub fn rel_close(a: f64, b: f64, tolerance: f64, scale: f64) -> bool {
    (a - b).abs() <= tolerance * scale
}

/// The doubles of a plain struct made only of doubles (vec3, mat3, quat, mass properties).
pub fn doubles_of<T: Copy>(value: &T) -> &[f64] {
    assert_eq!(std::mem::size_of::<T>() % 8, 0);
    // SAFETY: the callers pass structs made only of f64 fields (repr(C), no padding).
    unsafe { std::slice::from_raw_parts((value as *const T).cast::<f64>(), std::mem::size_of::<T>() / 8) }
}

/// The e with 2ᵉ ≤ |x| < 2ᵉ⁺¹ (0 for zero or a non-finite x).
pub fn binary_exponent(x: f64) -> i32 {
    if x == 0.0 || !x.is_finite() {
        return 0;
    }
    // log2 rounds up to 1024 next to f64::MAX (and may be off by one next to any power of two).
    let mut e = (x.abs().log2().floor() as i32).min(1023);
    while times_power_of_two(1.0, e) > x.abs() {
        e -= 1;
    }
    while times_power_of_two(1.0, e + 1) <= x.abs() {
        e += 1;
    }
    e
}

/// x·2^e in steps of at most 2^±1000 (any e): exact unless the result is subnormal, where only
/// the last step rounds.
pub fn times_power_of_two(mut x: f64, mut e: i32) -> f64 {
    while e != 0 {
        let step = e.clamp(-1000, 1000);
        x *= 2f64.powi(step);
        e -= step;
    }
    x
}

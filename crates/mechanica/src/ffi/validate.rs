//! Validation of C arguments: pointers, numbers, sizes and caller buffers, each failure with
//! its own status and a message naming the argument. Enum integers are checked in `c_enum`.

use super::boundary::FfiError;
use super::status::*;
use super::types::*;
use std::ptr::NonNull;

/// Fails with NULL_POINTER or MISALIGNED_POINTER unless `ptr` can be dereferenced as a `T`.
pub(crate) fn check_pointer<T>(ptr: *const T, what: &str) -> Result<(), FfiError> {
    if ptr.is_null() {
        return Err(FfiError::new(MECH_STATUS_NULL_POINTER, format!("{what} is NULL")));
    }
    if !ptr.is_aligned() {
        return Err(FfiError::new(
            MECH_STATUS_MISALIGNED_POINTER,
            format!("{what} is not aligned to {} bytes", std::mem::align_of::<T>()),
        ));
    }
    Ok(())
}

/// Copies a required input value out of C memory.
///
/// # Safety
/// A non-NULL `ptr` must point to a readable, initialised `T`.
pub(crate) unsafe fn read<T: Copy>(ptr: *const T, what: &str) -> Result<T, FfiError> {
    check_pointer(ptr, what)?;
    // SAFETY: non-NULL and aligned (checked); readable by the caller's contract.
    Ok(unsafe { ptr.read() })
}

/// Borrows a required input array of `len` elements. `len = 0` gives an empty slice even
/// for NULL.
///
/// # Safety
/// A non-NULL `ptr` must point to `len` readable, initialised elements.
pub(crate) unsafe fn read_slice<'a, T>(ptr: *const T, len: usize, what: &str) -> Result<&'a [T], FfiError> {
    if len == 0 {
        return Ok(&[]);
    }
    check_pointer(ptr, what)?;
    byte_length::<T>(len, what)?;
    // SAFETY: non-NULL, aligned, size fits isize (checked); readable by the caller's contract.
    Ok(unsafe { std::slice::from_raw_parts(ptr, len) })
}

/// A checked output location, written once, after all computation succeeded.
pub(crate) struct Out<T>(NonNull<T>);

impl<T> Out<T> {
    /// Checks a required output pointer without writing to it.
    pub fn new(ptr: *mut T, what: &str) -> Result<Self, FfiError> {
        check_pointer(ptr.cast_const(), what)?;
        NonNull::new(ptr)
            .map(Out)
            .ok_or_else(|| FfiError::new(MECH_STATUS_NULL_POINTER, what))
    }

    /// Checks an optional output pointer: None for NULL.
    pub fn optional(ptr: *mut T, what: &str) -> Result<Option<Self>, FfiError> {
        if ptr.is_null() {
            Ok(None)
        } else {
            Self::new(ptr, what).map(Some)
        }
    }

    /// Writes the result.
    ///
    /// # Safety
    /// The pointer given to [`Out::new`] must be valid for writing a `T`.
    pub unsafe fn write(self, value: T) {
        // SAFETY: non-NULL and aligned (checked in new); writable by the caller's contract.
        unsafe { self.0.as_ptr().write(value) }
    }
}

/// A checked output array of fixed length, written once, after all computation succeeded.
pub(crate) struct OutSlice<T> {
    ptr: NonNull<T>,
    len: usize,
}

impl<T: Copy> OutSlice<T> {
    /// Checks a required output array of `len` elements without writing to it.
    pub fn new(ptr: *mut T, len: usize, what: &str) -> Result<Self, FfiError> {
        if len == 0 {
            return Ok(Self {
                ptr: NonNull::dangling(),
                len,
            });
        }
        check_pointer(ptr.cast_const(), what)?;
        byte_length::<T>(len, what)?;
        let ptr = NonNull::new(ptr).ok_or_else(|| FfiError::new(MECH_STATUS_NULL_POINTER, what))?;
        Ok(Self { ptr, len })
    }

    /// Checks an optional output array: None for NULL.
    pub fn optional(ptr: *mut T, len: usize, what: &str) -> Result<Option<Self>, FfiError> {
        if ptr.is_null() {
            Ok(None)
        } else {
            Self::new(ptr, len, what).map(Some)
        }
    }

    /// Checks a required caller buffer of `capacity` elements that must hold `len`:
    /// BUFFER_TOO_SMALL when it cannot, before the pointer itself is checked.
    pub fn buffer(ptr: *mut T, capacity: usize, len: usize, what: &str) -> Result<Self, FfiError> {
        check_capacity(capacity, len, what)?;
        Self::new(ptr, len, what)
    }

    /// As [`OutSlice::buffer`] for an optional buffer: None for NULL, whatever its capacity.
    pub fn optional_buffer(ptr: *mut T, capacity: usize, len: usize, what: &str) -> Result<Option<Self>, FfiError> {
        if ptr.is_null() {
            Ok(None)
        } else {
            Self::buffer(ptr, capacity, len, what).map(Some)
        }
    }

    /// Copies `values` (exactly `len` of them) into the array.
    ///
    /// # Safety
    /// The pointer given to [`OutSlice::new`] must be valid for writing `len` elements.
    pub unsafe fn write(self, values: &[T]) {
        debug_assert_eq!(values.len(), self.len);
        let n = values.len().min(self.len);
        // SAFETY: the destination holds `len` ≥ n writable elements (caller's contract) and
        // cannot overlap `values`, which Rust owns.
        unsafe { std::ptr::copy_nonoverlapping(values.as_ptr(), self.ptr.as_ptr(), n) }
    }
}

/// Fails with BAD_DIMENSION when `len` elements of `T` would exceed isize::MAX bytes.
fn byte_length<T>(len: usize, what: &str) -> Result<usize, FfiError> {
    len.checked_mul(std::mem::size_of::<T>())
        .filter(|&bytes| bytes <= isize::MAX as usize)
        .ok_or_else(|| FfiError::new(MECH_STATUS_BAD_DIMENSION, format!("{what}: length {len} is too large")))
}

/// Fails with BUFFER_TOO_SMALL when a caller buffer of `capacity` elements cannot hold `needed`.
pub(crate) fn check_capacity(capacity: usize, needed: usize, what: &str) -> Result<(), FfiError> {
    if capacity < needed {
        return Err(FfiError::new(
            MECH_STATUS_BUFFER_TOO_SMALL,
            format!("{what}: capacity {capacity} < {needed} needed"),
        ));
    }
    Ok(())
}

/// The element count a·b of a buffer (e.g. n rows × count columns), failing with BAD_DIMENSION
/// on overflow.
pub(crate) fn product(a: usize, b: usize, what: &str) -> Result<usize, FfiError> {
    a.checked_mul(b)
        .ok_or_else(|| FfiError::new(MECH_STATUS_BAD_DIMENSION, format!("{what}: {a}·{b} overflows")))
}

/// The element count n·n of a square matrix, failing with BAD_DIMENSION for n = 0 or overflow.
pub(crate) fn square_len(n: usize, what: &str) -> Result<usize, FfiError> {
    if n == 0 {
        return Err(FfiError::new(
            MECH_STATUS_BAD_DIMENSION,
            format!("{what}: dimension is 0"),
        ));
    }
    n.checked_mul(n)
        .ok_or_else(|| FfiError::new(MECH_STATUS_BAD_DIMENSION, format!("{what}: {n}×{n} overflows")))
}

/// Values that can be checked for NaN and infinities.
pub(crate) trait Finite {
    /// The first non-finite component, if any.
    fn first_non_finite(&self) -> Option<f64>;
}

impl Finite for f64 {
    fn first_non_finite(&self) -> Option<f64> {
        (!self.is_finite()).then_some(*self)
    }
}
impl Finite for [f64] {
    fn first_non_finite(&self) -> Option<f64> {
        self.iter().copied().find(|v| !v.is_finite())
    }
}
impl Finite for mech_vec3_t {
    fn first_non_finite(&self) -> Option<f64> {
        [self.x, self.y, self.z].first_non_finite()
    }
}
impl Finite for mech_mat3_t {
    fn first_non_finite(&self) -> Option<f64> {
        self.m.first_non_finite()
    }
}
impl Finite for mech_quat_t {
    fn first_non_finite(&self) -> Option<f64> {
        [self.w, self.x, self.y, self.z].first_non_finite()
    }
}

/// Fails with NON_FINITE, naming `what`, if `value` holds NaN or ±∞.
pub(crate) fn finite<T: Finite + ?Sized>(value: &T, what: &str) -> Result<(), FfiError> {
    match value.first_non_finite() {
        Some(bad) => Err(FfiError::new(MECH_STATUS_NON_FINITE, format!("{what} holds {bad}"))),
        None => Ok(()),
    }
}

/// Fails with OUT_OF_RANGE, naming `quantity`, if a computed result holds NaN or ±∞ (it
/// overflowed although every input was finite); checked before any output is written.
pub(crate) fn finite_result<T: Finite + ?Sized>(value: &T, quantity: &str) -> Result<(), FfiError> {
    match value.first_non_finite() {
        Some(bad) => Err(FfiError::new(
            MECH_STATUS_OUT_OF_RANGE,
            format!("the {quantity} is not representable: it overflows the range of double ({bad})"),
        )),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_kind_of_bad_argument_has_its_own_status() {
        // SAFETY: a NULL pointer is never dereferenced by `read`.
        let null = unsafe { read::<f64>(std::ptr::null(), "x") };
        assert_eq!(null.map_err(|e| e.status), Err(MECH_STATUS_NULL_POINTER));
        let words = [0u64; 2];
        let misaligned = words.as_ptr().cast::<u8>().wrapping_add(1).cast::<f64>();
        // SAFETY: a misaligned pointer is rejected before it is dereferenced.
        let mis = unsafe { read::<f64>(misaligned, "x") };
        assert_eq!(mis.map_err(|e| e.status), Err(MECH_STATUS_MISALIGNED_POINTER));
        assert_eq!(
            finite(&f64::NAN, "x").map_err(|e| e.status),
            Err(MECH_STATUS_NON_FINITE)
        );
        assert_eq!(square_len(0, "A").map_err(|e| e.status), Err(MECH_STATUS_BAD_DIMENSION));
        assert_eq!(
            square_len(usize::MAX, "A").map_err(|e| e.status),
            Err(MECH_STATUS_BAD_DIMENSION)
        );
        assert_eq!(
            check_capacity(2, 3, "x").map_err(|e| e.status),
            Err(MECH_STATUS_BUFFER_TOO_SMALL)
        );
        assert_eq!(
            product(usize::MAX, 3, "n").map_err(|e| e.status),
            Err(MECH_STATUS_BAD_DIMENSION)
        );
        assert_eq!(product(4, 3, "n"), Ok(12));
    }
}

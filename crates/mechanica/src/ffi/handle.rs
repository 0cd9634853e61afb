//! Opaque handles: Rust values that C holds by address (a tree, a mechanism, a modal result).
//! One [`Handle`] trait gives every handle type the same creation, borrowing and destruction,
//! with the same checks and status codes.

use super::boundary::{FfiError, boundary};
use super::validate::check_pointer;

/// A Rust value handed to C as an opaque pointer. Each entry point that takes a handle
/// borrows it inside its panic boundary; a NULL handle gives MECH_STATUS_NULL_POINTER and a
/// misaligned one MECH_STATUS_MISALIGNED_POINTER, naming the argument.
pub(crate) trait Handle: Sized {
    /// Moves the value to the heap and returns the address C keeps until it calls the
    /// handle's destroy function. Called last in a create function, once nothing can fail,
    /// so that no error path leaks the value.
    fn into_raw(self) -> *mut Self {
        Box::into_raw(Box::new(self))
    }

    /// Borrows the value behind a handle for reading.
    ///
    /// # Safety
    /// `handle` must be NULL, misaligned, or a live handle from [`Handle::into_raw`].
    unsafe fn borrow<'a>(handle: *const Self, what: &str) -> Result<&'a Self, FfiError> {
        check_pointer(handle, what)?;
        // SAFETY: non-NULL and aligned (checked); live by the caller's contract.
        Ok(unsafe { &*handle })
    }

    /// Borrows the value behind a handle for changing it.
    ///
    /// # Safety
    /// `handle` must be NULL, misaligned, or a live handle from [`Handle::into_raw`] that no
    /// other reference uses during the call.
    unsafe fn borrow_mut<'a>(handle: *mut Self, what: &str) -> Result<&'a mut Self, FfiError> {
        check_pointer(handle.cast_const(), what)?;
        // SAFETY: non-NULL and aligned (checked); live and unaliased by the caller's contract.
        Ok(unsafe { &mut *handle })
    }

    /// Frees the value behind a handle; NULL is ignored. A panic while dropping is caught (its
    /// message is kept for mech_last_error) and does not cross the C boundary.
    ///
    /// # Safety
    /// `handle` must be NULL or a live handle from [`Handle::into_raw`], not used afterwards.
    unsafe fn destroy(handle: *mut Self) {
        if handle.is_null() {
            return;
        }
        let _ = boundary(|| {
            // SAFETY: the handle came from Box::into_raw in into_raw (caller's contract).
            drop(unsafe { Box::from_raw(handle) });
            Ok(())
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ffi::status::*;

    struct Counter(u32);
    impl Handle for Counter {}

    #[test]
    fn a_handle_round_trips_and_bad_handles_have_their_own_status() {
        let raw = Counter(41).into_raw();
        // SAFETY: `raw` is live until the destroy below.
        unsafe {
            Counter::borrow_mut(raw, "counter")
                .map(|c| c.0 += 1)
                .expect("live handle");
            assert_eq!(Counter::borrow(raw, "counter").map(|c| c.0), Ok(42));
            Counter::destroy(raw);
            Counter::destroy(std::ptr::null_mut());
        }
        // SAFETY: NULL and misaligned handles are rejected before any dereference.
        unsafe {
            let null = Counter::borrow(std::ptr::null(), "counter").map(|_| ());
            assert_eq!(null.map_err(|e| e.status), Err(MECH_STATUS_NULL_POINTER));
            let words = [0u64; 2];
            let misaligned = words.as_ptr().cast::<u8>().wrapping_add(1).cast::<Counter>();
            let result = Counter::borrow(misaligned, "counter").map(|_| ());
            assert_eq!(result.map_err(|e| e.status), Err(MECH_STATUS_MISALIGNED_POINTER));
        }
    }
}

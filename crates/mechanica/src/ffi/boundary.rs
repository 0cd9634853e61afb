//! The panic boundary around every entry point, and the per-thread last-error message.

use super::status::*;
use std::cell::RefCell;
use std::ffi::c_char;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// A failed call: the status returned to C and the detailed message kept for
/// [`mech_last_error`].
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FfiError {
    pub status: mech_status_t,
    pub message: String,
}

impl FfiError {
    pub fn new(status: mech_status_t, message: impl Into<String>) -> Self {
        Self {
            status,
            message: message.into(),
        }
    }
}

thread_local! {
    static LAST_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
}

fn set_last_error(message: String) {
    LAST_ERROR.with(|slot| *slot.borrow_mut() = message);
}

/// Runs the body of a C entry point: converts its error into a status (remembering the
/// message for [`mech_last_error`]) and turns a panic into [`MECH_STATUS_PANIC`].
pub(crate) fn boundary(body: impl FnOnce() -> Result<(), FfiError>) -> mech_status_t {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => MECH_STATUS_OK,
        Ok(Err(error)) => {
            set_last_error(error.message);
            error.status
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "non-string panic payload".to_string());
            set_last_error(format!("internal error (panic caught at the C boundary): {what}"));
            MECH_STATUS_PANIC
        }
    }
}

/// Copies the detailed message of this thread's most recent failed call (e.g. "mass must be
/// positive, got -1") into `buffer`, truncated to `capacity − 1` bytes and NUL-terminated.
/// Returns the full message length in bytes, excluding the NUL, as snprintf does; pass
/// `buffer = NULL, capacity = 0` to query the length. The message is empty before any failure.
///
/// # Safety
/// `buffer` must be NULL or point to at least `capacity` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_last_error(buffer: *mut c_char, capacity: usize) -> usize {
    let copy = |message: &String| {
        let bytes = message.as_bytes();
        if !buffer.is_null() && capacity > 0 {
            let n = bytes.len().min(capacity - 1);
            // SAFETY: the caller guarantees `capacity` writable bytes at `buffer`; n < capacity.
            unsafe {
                std::ptr::copy_nonoverlapping(bytes.as_ptr(), buffer.cast::<u8>(), n);
                *buffer.add(n) = 0;
            }
        }
        bytes.len()
    };
    catch_unwind(AssertUnwindSafe(|| LAST_ERROR.with(|slot| copy(&slot.borrow())))).unwrap_or(0)
}

/// Deliberately panics inside the boundary and returns what the boundary made of it. A build
/// whose panics unwind correctly returns MECH_STATUS_PANIC; integrators call this once in their
/// own test suite to check that the library they ship was not built with `panic = "abort"`.
#[unsafe(no_mangle)]
pub extern "C" fn mech_selftest_panic_boundary() -> mech_status_t {
    boundary(|| panic!("mech_selftest_panic_boundary: deliberate panic"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_a_status_and_a_message() {
        assert_eq!(mech_selftest_panic_boundary(), MECH_STATUS_PANIC);
        let mut buf = [0 as c_char; 256];
        // SAFETY: buf has 256 writable bytes.
        let len = unsafe { mech_last_error(buf.as_mut_ptr(), buf.len()) };
        // SAFETY: mech_last_error NUL-terminated the buffer.
        let text = unsafe { std::ffi::CStr::from_ptr(buf.as_ptr()) }.to_string_lossy();
        assert_eq!(len, text.len());
        assert!(text.contains("deliberate panic"), "{text}");
    }

    #[test]
    fn errors_keep_their_status_and_message() {
        let status = boundary(|| Err(FfiError::new(MECH_STATUS_SINGULAR, "pivot 3 = 0")));
        assert_eq!(status, MECH_STATUS_SINGULAR);
        let mut buf = [0 as c_char; 4];
        // SAFETY: buf has 4 writable bytes.
        let len = unsafe { mech_last_error(buf.as_mut_ptr(), buf.len()) };
        assert_eq!(len, "pivot 3 = 0".len());
        // SAFETY: NUL-terminated by mech_last_error.
        assert_eq!(unsafe { std::ffi::CStr::from_ptr(buf.as_ptr()) }.to_bytes(), b"piv");
    }
}

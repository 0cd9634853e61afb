//! `mech_status_t`: the result code of every fallible C entry point.

use std::ffi::c_char;

/// Result code of every fallible call. Fixed width (int32_t); 0 is success.
/// Values are stable across versions and never reused.
pub type mech_status_t = i32;

/// Success.
pub const MECH_STATUS_OK: mech_status_t = 0;
/// A required pointer argument was NULL.
pub const MECH_STATUS_NULL_POINTER: mech_status_t = 1;
/// A pointer argument was not aligned for its type.
pub const MECH_STATUS_MISALIGNED_POINTER: mech_status_t = 2;
/// An input number was NaN or infinite.
pub const MECH_STATUS_NON_FINITE: mech_status_t = 3;
/// A size or dimension argument was wrong (zero, mismatched, or overflowing).
pub const MECH_STATUS_BAD_DIMENSION: mech_status_t = 4;
/// An enum argument held an integer that names no value of the enum.
pub const MECH_STATUS_BAD_ENUM: mech_status_t = 5;
/// An input was finite and well-sized but outside the function's domain
/// (e.g. a negative mass, a non-unit axis, a non-orthogonal rotation matrix).
pub const MECH_STATUS_INVALID_ARGUMENT: mech_status_t = 6;
/// A matrix that must be positive (semi)definite is not.
pub const MECH_STATUS_NOT_POSITIVE_DEFINITE: mech_status_t = 7;
/// The problem is singular at this input (e.g. Euler-rate inversion at gimbal lock).
pub const MECH_STATUS_SINGULAR: mech_status_t = 8;
/// An iterative method did not reach its tolerance.
pub const MECH_STATUS_NOT_CONVERGED: mech_status_t = 9;
/// A caller buffer is too small for the result.
pub const MECH_STATUS_BUFFER_TOO_SMALL: mech_status_t = 10;
/// A file could not be read.
pub const MECH_STATUS_IO_ERROR: mech_status_t = 11;
/// A file or text could not be parsed.
pub const MECH_STATUS_PARSE_ERROR: mech_status_t = 12;
/// The inputs were valid but a result is not representable in double precision: it exceeds
/// the largest double (e.g. the inertia of a sphere of radius 1e308), or a mass computed from
/// a density underflows to zero. No output was written; mech_last_error names the quantity.
pub const MECH_STATUS_OUT_OF_RANGE: mech_status_t = 13;
/// A panic inside the library was caught at the boundary. This is a library bug; please
/// report it with the inputs. No output was written.
pub const MECH_STATUS_PANIC: mech_status_t = 100;

/// The static, NUL-terminated English description of `status`. Unknown values give
/// "unknown status". The pointer is valid for the life of the program; do not free it.
#[unsafe(no_mangle)]
pub extern "C" fn mech_status_str(status: mech_status_t) -> *const c_char {
    let text: &'static std::ffi::CStr = match status {
        MECH_STATUS_OK => c"ok",
        MECH_STATUS_NULL_POINTER => c"a required pointer argument was NULL",
        MECH_STATUS_MISALIGNED_POINTER => c"a pointer argument was misaligned for its type",
        MECH_STATUS_NON_FINITE => c"an input number was NaN or infinite",
        MECH_STATUS_BAD_DIMENSION => c"a size or dimension argument was wrong",
        MECH_STATUS_BAD_ENUM => c"an enum argument held an unknown value",
        MECH_STATUS_INVALID_ARGUMENT => c"an input was outside the function's domain",
        MECH_STATUS_NOT_POSITIVE_DEFINITE => c"a matrix that must be positive definite is not",
        MECH_STATUS_SINGULAR => c"the problem is singular at this input",
        MECH_STATUS_NOT_CONVERGED => c"an iterative method did not converge",
        MECH_STATUS_BUFFER_TOO_SMALL => c"a caller buffer is too small",
        MECH_STATUS_IO_ERROR => c"a file could not be read",
        MECH_STATUS_PARSE_ERROR => c"a file or text could not be parsed",
        MECH_STATUS_OUT_OF_RANGE => c"a result is not representable in double precision",
        MECH_STATUS_PANIC => c"internal error: a panic was caught at the C boundary",
        _ => c"unknown status",
    };
    text.as_ptr()
}

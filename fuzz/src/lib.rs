//! Shared pieces of the fuzz targets: a reader that turns the fuzzer's bytes into numbers
//! (with the awkward values — ±0, subnormals, 1e±308, NaN, ±∞ — reachable in one byte), and
//! the oracles every C-ABI call is held to whatever its arguments:
//!
//! - the status is one of the documented values and never `MECH_STATUS_PANIC` (a panic is a
//!   library bug; under libFuzzer the panic hook aborts before the boundary can catch it);
//! - a failed call leaves every output byte as it was ([`Sentinel`]);
//! - a successful call writes only finite numbers (the ABI turns NaN/∞ results into errors).

#![allow(missing_docs)]

pub mod dynamics;
pub mod input;
pub mod mesh_oracle;
pub mod oracle;
pub mod tree;

pub use input::Input;

/// Whether `MECH_FUZZ_TRACE` is set: targets then print the calls they make (to reproduce a
/// crash as a plain test).
pub fn tracing() -> bool {
    static TRACING: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *TRACING.get_or_init(|| std::env::var_os("MECH_FUZZ_TRACE").is_some())
}

/// `eprintln!` when [`tracing`].
#[macro_export]
macro_rules! trace {
    ($($arg:tt)*) => {
        if $crate::tracing() {
            eprintln!($($arg)*);
        }
    };
}
pub use oracle::{Sentinel, check_status, finite, rel_close};

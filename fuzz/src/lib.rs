//! Shared pieces of the fuzz targets: a reader that turns the fuzzer's bytes into numbers
//! (with the awkward values — ±0, subnormals, 1e±308, NaN, ±∞ — reachable in one byte), and
//! the oracles every C-ABI call is held to whatever its arguments:
//!
//! - the status is one of the documented values and never `MECH_STATUS_PANIC` (a panic is a
//!   library bug; under libFuzzer the panic hook aborts before the boundary can catch it);
//! - a failed call leaves every output byte as it was ([`Sentinel`]);
//! - a successful call writes only finite numbers (the ABI turns NaN/∞ results into errors).

#![allow(missing_docs)]

pub mod input;
pub mod mesh_oracle;
pub mod oracle;
pub mod tree;

pub use input::Input;
pub use oracle::{Sentinel, check_status, finite, rel_close};

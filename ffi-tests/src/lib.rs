//! Drives the C/C++ ffi-tests and the header check from `cargo test`; see `tests/`.

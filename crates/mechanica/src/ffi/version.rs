//! Library and ABI versions, and the features this build contains.

use std::ffi::c_char;

/// Major version of the library (semantic versioning), as in Cargo.toml.
pub const MECH_VERSION_MAJOR: u32 = 0;
/// Minor version of the library, as in Cargo.toml.
pub const MECH_VERSION_MINOR: u32 = 1;
/// Patch version of the library, as in Cargo.toml.
pub const MECH_VERSION_PATCH: u32 = 0;
/// Version of the binary interface. It changes only when a declaration in the header
/// changes incompatibly; compare it with mech_abi_version() at start-up.
pub const MECH_ABI_VERSION: u32 = 1;

/// Bit of mech_features() set when the kinematics functions are compiled in.
pub const MECH_FEATURE_BIT_KINEMATICS: u32 = 1 << 0;
/// Bit of mech_features() set when the mass-properties functions are compiled in.
pub const MECH_FEATURE_BIT_MASS: u32 = 1 << 1;
/// Bit of mech_features() set when the impulse-dynamics functions are compiled in.
pub const MECH_FEATURE_BIT_IMPULSE: u32 = 1 << 2;
/// Bit of mech_features() set when the modal-analysis functions are compiled in.
pub const MECH_FEATURE_BIT_MODAL: u32 = 1 << 3;
/// Bit of mech_features() set when the mechanism functions (potentials, equilibrium, modes) are compiled in.
pub const MECH_FEATURE_BIT_MECHANISM: u32 = 1 << 4;
/// Bit of mech_features() set when the dynamics functions (inverse and forward dynamics, joint
/// reactions) are compiled in.
pub const MECH_FEATURE_BIT_DYNAMICS: u32 = 1 << 5;
/// Bit of mech_features() set when the motion functions (integration in time) are compiled in.
pub const MECH_FEATURE_BIT_MOTION: u32 = 1 << 6;
/// Bit of mech_features() set when the URDF readers (trees and mechanisms from URDF) are
/// compiled in.
pub const MECH_FEATURE_BIT_URDF: u32 = 1 << 7;

/// The library version as a static NUL-terminated string "MAJOR.MINOR.PATCH".
#[unsafe(no_mangle)]
pub extern "C" fn mech_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// The ABI version of the linked library; equals MECH_ABI_VERSION of a matching header.
#[unsafe(no_mangle)]
pub extern "C" fn mech_abi_version() -> u32 {
    MECH_ABI_VERSION
}

/// The MECH_FEATURE_BIT_* bits of the capabilities compiled into the linked library.
#[unsafe(no_mangle)]
pub extern "C" fn mech_features() -> u32 {
    let mut bits = 0;
    if cfg!(feature = "kinematics") {
        bits |= MECH_FEATURE_BIT_KINEMATICS;
    }
    if cfg!(feature = "mass") {
        bits |= MECH_FEATURE_BIT_MASS;
    }
    if cfg!(feature = "impulse") {
        bits |= MECH_FEATURE_BIT_IMPULSE;
    }
    if cfg!(feature = "modal") {
        bits |= MECH_FEATURE_BIT_MODAL;
    }
    if cfg!(feature = "mechanism") {
        bits |= MECH_FEATURE_BIT_MECHANISM;
    }
    if cfg!(feature = "dynamics") {
        bits |= MECH_FEATURE_BIT_DYNAMICS;
    }
    if cfg!(feature = "motion") {
        bits |= MECH_FEATURE_BIT_MOTION;
    }
    if cfg!(feature = "urdf") {
        bits |= MECH_FEATURE_BIT_URDF;
    }
    bits
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn version_macros_match_cargo_toml() {
        let parse = |s: &str| s.parse::<u32>().expect("numeric version component");
        assert_eq!(MECH_VERSION_MAJOR, parse(env!("CARGO_PKG_VERSION_MAJOR")));
        assert_eq!(MECH_VERSION_MINOR, parse(env!("CARGO_PKG_VERSION_MINOR")));
        assert_eq!(MECH_VERSION_PATCH, parse(env!("CARGO_PKG_VERSION_PATCH")));
    }

    #[test]
    fn version_string_is_nul_terminated_and_matches() {
        // SAFETY: mech_version returns a pointer to a static NUL-terminated string.
        let s = unsafe { std::ffi::CStr::from_ptr(mech_version()) };
        assert_eq!(s.to_str().expect("ascii"), env!("CARGO_PKG_VERSION"));
    }
}

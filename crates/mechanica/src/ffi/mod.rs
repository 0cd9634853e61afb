//! The C ABI: status codes, versioning, the panic boundary, input validation and one
//! module of entry points per capability crate.
//!
//! Conventions (the header's file comment states them for C users):
//! - every fallible call returns [`mech_status_t`] and writes its outputs only on success;
//! - enums arriving from C are plain integers and are validated (`c_enum`);
//! - n×n matrices are caller-owned, column-major `double` arrays;
//! - opaque handles share one implementation (`handle`);
//! - no panic crosses the boundary: each entry point runs inside [`boundary`].
#![allow(non_camel_case_types)]
// A build with only some capability features leaves some shared helpers unused; the full
// build (the one linted) still reports dead code.
#![cfg_attr(
    not(all(
        feature = "kinematics",
        feature = "mass",
        feature = "impulse",
        feature = "modal",
        feature = "mechanism",
        feature = "dynamics",
        feature = "motion",
        feature = "urdf"
    )),
    allow(dead_code, unused_imports, unused_macros)
)]

mod boundary;
mod c_enum;
mod handle;
#[cfg(feature = "kinematics")]
mod spatial;
mod status;
mod types;
mod validate;
mod version;

#[cfg(feature = "dynamics")]
mod dynamics;
#[cfg(feature = "impulse")]
mod impulse;
#[cfg(feature = "kinematics")]
mod kinematics;
#[cfg(feature = "mass")]
mod mass;
#[cfg(feature = "mechanism")]
mod mechanism;
#[cfg(feature = "modal")]
mod modal;
#[cfg(feature = "motion")]
mod motion;
#[cfg(feature = "urdf")]
mod urdf;

pub use boundary::*;
pub use status::*;
pub use types::*;
pub use version::*;

#[cfg(feature = "dynamics")]
pub use dynamics::*;
#[cfg(feature = "impulse")]
pub use impulse::*;
#[cfg(feature = "kinematics")]
pub use kinematics::*;
#[cfg(feature = "mass")]
pub use mass::*;
#[cfg(feature = "mechanism")]
pub use mechanism::*;
#[cfg(feature = "modal")]
pub use modal::*;
#[cfg(feature = "motion")]
pub use motion::*;
#[cfg(feature = "urdf")]
pub use urdf::*;

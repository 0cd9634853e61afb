//! mechanica: analytical mechanics for simulators.
//!
//! Rust users reach each capability crate through this facade, one cargo feature each:
//!
//! | feature      | module                   | crate                   |
//! |--------------|--------------------------|-------------------------|
//! | `kinematics` | [`kinematics`]           | `mechanica-kinematics`  |
//! | `mass`       | [`mass`]                 | `mechanica-mass`        |
//! | `impulse`    | [`impulse`]              | `mechanica-impulse`     |
//! | `modal`      | [`modal`]                | `mechanica-modal`       |
//! | `mechanism`  | [`mechanism`]            | `mechanica-mechanism`   |
//! | `dynamics`   | [`dynamics`]             | `mechanica-dynamics`    |
//! | `motion`     | [`motion`]               | `mechanica-motion`      |
//! | `urdf`       | [`urdf`]                 | `mechanica-urdf`        |
//!
//! C and C++ programs use the same capabilities through [`ffi`], declared in the generated
//! header `include/mechanica.h`.

#[cfg(feature = "dynamics")]
pub use mechanica_dynamics as dynamics;
#[cfg(feature = "impulse")]
pub use mechanica_impulse as impulse;
#[cfg(feature = "kinematics")]
pub use mechanica_kinematics as kinematics;
#[cfg(feature = "mass")]
pub use mechanica_mass as mass;
#[cfg(feature = "mechanism")]
pub use mechanica_mechanism as mechanism;
#[cfg(feature = "modal")]
pub use mechanica_modal as modal;
#[cfg(feature = "motion")]
pub use mechanica_motion as motion;
#[cfg(feature = "urdf")]
pub use mechanica_urdf as urdf;

pub mod ffi;

/// The crate version, `MAJOR.MINOR.PATCH`, as in Cargo.toml.
pub fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

//! Kinematics of rigid bodies and mechanisms.
//!
//! Rotations, rigid motion fields, relative motion and kinematic trees, following
//! chapters 1–2 of the syllabus. Equation numbers such as (2.13) are the syllabus numbering,
//! listed in `docs/theory.md`; "EB1911 (13)" is equation (13) of the Britannica article
//! "Mechanics", also defined there.
//!
//! Frames follow the Drake naming style: `p_AB_W` is the position of B relative to A,
//! expressed in frame W. All quantities are SI and `f64`.
//!
//! - [`rotation`]: matrices, quaternions, axis–angle, exp/log of SO(3), re-orthonormalization, Ω = Ṙ Rᵀ.
//! - [`euler`]: Euler angles (EB1911 and the twelve intrinsic sequences), gimbal lock, rate maps.
//! - [`rigid_motion`]: x = R X + c and the velocity/acceleration fields (2.13–2.19).
//! - [`relative_motion`]: drag, Coriolis and relative parts (2.22–2.35).
//! - [`tree`]: kinematic trees, forward kinematics, Jacobians and their rates.
//! - [`scaling`]: exact power-of-two scaling and norms without overflow or underflow.
//!
//! Every function that returns a `Result` checks its outputs: a result that is not
//! representable (it overflows f64) is [`KinematicsError::NonFiniteResult`], never a NaN or
//! an infinity.

pub mod error;
pub mod euler;
pub mod relative_motion;
pub mod rigid_motion;
pub mod rotation;
pub mod scaling;
pub mod tree;

pub use error::KinematicsError;
pub use nalgebra;

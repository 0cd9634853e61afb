//! Kinematics of rigid bodies and mechanisms.
//!
//! Rotations, rigid motion fields, relative motion and kinematic trees, following
//! the syllabus chapters 1–2 (equation numbers refer to `seeds/000`, see THEORY.md).
//!
//! Frames follow the Drake naming style: `p_AB_W` is the position of B relative to A,
//! expressed in frame W. All quantities are SI and `f64`.

pub mod error;
pub mod rotation;

pub use error::KinematicsError;
pub use nalgebra;

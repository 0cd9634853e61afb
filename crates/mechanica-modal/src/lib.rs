//! Small oscillations: A δ̈ + B δ = 0 and det(λA + B) = 0 (8.84–8.92), solved with faer,
//! with every result carrying its own accuracy report.
//!
//! This crate works on bare matrices; it needs no mechanism.

pub mod error;
pub mod problem;

pub use error::ModalError;
pub use faer;
pub use problem::PencilProblem;

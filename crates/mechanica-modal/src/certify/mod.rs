//! How every result knows its own accuracy: the accuracy report ([`AccuracyReport`]) with its
//! backward errors, A-orthogonality and per-mode bounds (first order, a priori, or residual
//! bounds after refinement), the Gaussian sketches that bound residuals at O(n²) cost, the
//! resolution of the data (for the zero classification), and the Sturm checks: inertia counts
//! of B − sA ([`count_below`]) and the bottom-of-spectrum certificate factored on idle time.

pub(crate) mod a_priori;
pub(crate) mod extended_definiteness;
pub(crate) mod forest;
pub(crate) mod idle_certificate;
pub(crate) mod inertia;
pub(crate) mod products;
pub(crate) mod report;
pub(crate) mod residual_bounds;
pub(crate) mod resolution;
pub(crate) mod sketch;
pub(crate) mod sturm;

pub use inertia::{InertiaCount, count_below, proven_definite_with_margin};
pub use products::Residuals;
pub use report::{AccuracyReport, BoundKind};
pub use resolution::{data_resolution, normwise_resolution};
pub use sketch::{FAILURE_PROBABILITY, SKETCH_SIZE};
pub use sturm::InertiaCheck;

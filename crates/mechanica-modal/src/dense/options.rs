//! What a dense solve is asked for: which modes ([`Selection`]), with or without shapes, the
//! refinement policy ([`Refinement`]) and how residuals are measured.

use crate::certify::products::Residuals;
use crate::error::ModalError;

/// Which eigenpairs to return.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Selection {
    /// Every finite mode, plus the infinite (massless) ones when A is singular.
    All,
    /// The k finite modes of lowest ω² (unstable modes count as lowest).
    Lowest(usize),
    /// The finite modes with lower ≤ ω² ≤ upper (rad²/s²).
    Interval {
        /// Lower end of ω².
        lower: f64,
        /// Upper end of ω².
        upper: f64,
    },
}

/// Whether to refine low modes with extended-precision residuals (`crate::refine`). Clusters of
/// nearly equal ω² (up to [`crate::Tuning::max_refined_cluster`] modes) are refined as blocks; a
/// semidefinite A is refined when it is diagonal with exactly zero massless entries (the
/// condensation is then exact), and otherwise keeps its first-order bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refinement {
    /// Refine the selected, simple, finite modes whose first-order error bound from the
    /// reduction exceeds [`AUTO_REFINE_RELATIVE_BOUND`]·|ω²| (stiff and graded problems), from
    /// the lowest up, at most max(64, n/16) of them ([`crate::Tuning::auto_refined_at_least`]);
    /// on a graded pencil whose low modes the reduction cannot resolve, they are first taken
    /// from the reversed pencil (`dense::reversed`, docs/theory.md).
    Auto,
    /// Never refine (the plain reduction; its bounds can then be large on stiff problems).
    Off,
    /// Refine every selected simple finite mode.
    Always,
}

/// Auto refinement starts when the reduction guarantees fewer than 8 digits of a mode's ω².
pub const AUTO_REFINE_RELATIVE_BOUND: f64 = 1e-8;

/// Whether a mode's bound guarantees fewer digits than [`AUTO_REFINE_RELATIVE_BOUND`] asks for.
pub(crate) fn weakly_bounded(bound: f64, omega_sq: f64) -> bool {
    bound > AUTO_REFINE_RELATIVE_BOUND * omega_sq.abs()
}

/// Options of [`crate::solve()`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveOptions {
    /// Which modes.
    pub selection: Selection,
    /// Whether to return mode shapes (eigenvectors). Values only is cheaper.
    pub vectors: bool,
    /// Low-mode refinement policy.
    pub refinement: Refinement,
    /// How the accuracy report measures residuals and orthogonality (exact by default).
    pub residuals: Residuals,
}

impl Default for SolveOptions {
    fn default() -> Self {
        Self {
            selection: Selection::All,
            vectors: true,
            refinement: Refinement::Auto,
            residuals: Residuals::Exact,
        }
    }
}

pub(crate) fn check_interval(selection: Selection) -> Result<(), ModalError> {
    if let Selection::Interval { lower, upper } = selection
        && !(lower.is_finite() && upper.is_finite() && lower <= upper)
    {
        return Err(ModalError::BadInterval { lower, upper });
    }
    Ok(())
}

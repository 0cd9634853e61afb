//! What a sparse solve is asked for: how many modes, the shift, the tolerance and the limits of
//! the Lanczos iteration.

use crate::error::ModalError;

/// Options of [`crate::solve_sparse`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SparseSolveOptions {
    /// Number k of lowest modes wanted (1 ≤ k < n).
    pub count: usize,
    /// Shift σ (rad²/s²) below the lowest mode; None: automatic (see the module documentation).
    pub shift: Option<f64>,
    /// Convergence: Ritz residual ≤ tolerance·θ for each of the k wanted pairs (the buffer
    /// pairs computed above them, only to locate a gap, converge to max(tolerance, 1e-8)).
    pub tolerance: f64,
    /// Maximal number of thick restarts per Lanczos run.
    pub max_restarts: usize,
    /// Seed of the pseudo-random start vectors.
    pub seed: u64,
    /// Block size b of the block Lanczos iteration (≥ 1): b vectors share each pass over the
    /// Cholesky factor, and an eigenvalue of multiplicity ≤ b is seen in one run.
    pub block_size: usize,
    /// Maximal number of Lanczos runs: the first one plus deflated reruns for modes that the
    /// inertia count shows missing (0 is taken as 1). When exhausted the solve fails with
    /// [`ModalError::LanczosNoConvergence`] instead of returning an uncertified result.
    pub max_runs: usize,
}

impl Default for SparseSolveOptions {
    fn default() -> Self {
        Self {
            count: 10,
            shift: None,
            tolerance: 1e-12,
            max_restarts: 300,
            seed: 1,
            block_size: 2,
            max_runs: 6,
        }
    }
}

impl SparseSolveOptions {
    /// [`ModalError::TooManyModes`] unless 1 ≤ k ≤ n, [`ModalError::BadShift`] for a shift that
    /// is not finite, [`ModalError::BadTolerance`] unless 0 < tolerance < 1.
    pub(crate) fn check(&self, n: usize) -> Result<(), ModalError> {
        let k = self.count;
        if k == 0 || k > n {
            return Err(ModalError::TooManyModes {
                requested: k,
                available: n,
            });
        }
        if let Some(s) = self.shift
            && !s.is_finite()
        {
            return Err(ModalError::BadShift(s));
        }
        if !(self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Err(ModalError::BadTolerance(self.tolerance));
        }
        Ok(())
    }
}

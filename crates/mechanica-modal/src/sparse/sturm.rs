//! The Sturm check of a sparse solve: where the inertia shift τ goes (a real gap above the k-th
//! computed mode) and the inertia count of B − τA there.

use crate::error::ModalError;
use crate::sparse::inertia::{SparseInertiaCount, inertia_with, symbolic_supernodal};
use crate::sparse::pencil::Csc;
use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};
use std::time::{Duration, Instant};

/// An inertia count and the wall time it took.
pub(crate) type Counted = (Result<SparseInertiaCount, ModalError>, Duration);

/// Where τ may go among computed ω² (ascending): in a real gap, never inside a numerically
/// repeated eigenvalue, where the count could split the group.
pub(crate) struct TauChoice {
    /// The number k of wanted modes.
    k: usize,
    /// The operator's shift σ.
    sigma: f64,
    /// Relative width below which a gap may lie inside a repeated eigenvalue.
    min_gap: f64,
    /// Absolute floor of a real gap: the rounding level of ω² near zero (rigid-body modes).
    floor: f64,
}

impl TauChoice {
    /// Gaps wider than max(√u, 100·`tolerance`) relative, plus 100·u·‖B‖/‖A‖ (`ratio`), count.
    pub(crate) fn new(k: usize, sigma: f64, tolerance: f64, ratio: f64) -> Self {
        Self {
            k,
            sigma,
            min_gap: f64::EPSILON.sqrt().max(100.0 * tolerance),
            floor: 100.0 * f64::EPSILON * ratio,
        }
    }

    /// Whether the gap between the ω² `below` and `above` is real.
    fn is_real_gap(&self, below: f64, above: f64) -> bool {
        above - below > self.min_gap * below.abs().max(above.abs()) + self.floor
    }

    /// Whether the gap after `omega[j]` is real.
    fn real_gap(&self, omega: &[f64], j: usize) -> bool {
        self.is_real_gap(omega[j], omega[j + 1])
    }

    /// τ in the widest real gap between the k-th mode and the last one found; above the last
    /// one when every gap there is within a cluster.
    pub(crate) fn choose(&self, omega: &[f64]) -> f64 {
        let last = omega.len() - 1;
        let kth = (self.k - 1).min(last);
        match (kth..last)
            .filter(|&j| self.real_gap(omega, j))
            .max_by(|&i, &j| gap(omega, i).total_cmp(&gap(omega, j)))
        {
            Some(j) => 0.5 * (omega[j] + omega[j + 1]),
            None => omega[last] + 0.5 * (omega[last] - self.sigma).abs(),
        }
    }

    /// Whether a τ chosen from rough Ritz values still serves for the final ones: it lies above
    /// the k-th of them and in the middle half of a real gap (or, above the last, a real gap
    /// away).
    pub(crate) fn is_clear(&self, omega: &[f64], tau: f64) -> bool {
        let j = omega.partition_point(|&w| w < tau);
        if j < self.k.min(omega.len()) || j == 0 {
            return false;
        }
        match omega.get(j) {
            Some(&above) => {
                let below = omega[j - 1];
                let quarter = 0.25 * (above - below);
                self.real_gap(omega, j - 1) && tau - below >= quarter && above - tau >= quarter
            }
            None => self.is_real_gap(omega[j - 1], tau),
        }
    }
}

/// ω²_{j+1} − ω²_j relative to max(|ω²_j|, |ω²_{j+1}|) (0 past the end).
fn gap(omega: &[f64], j: usize) -> f64 {
    if j + 1 >= omega.len() {
        return 0.0;
    }
    let scale = omega[j].abs().max(omega[j + 1].abs()).max(f64::MIN_POSITIVE);
    (omega[j + 1] - omega[j]) / scale
}

/// Inertia counts of B − τA on a supernodal analysis of the pattern of B − σA: the Cholesky
/// one when faer chose supernodal (as on large problems), else a forced one.
pub(crate) struct InertiaCounter<'a> {
    symbolic: &'a SymbolicCholesky<usize>,
    forced_supernodal: Option<SymbolicCholesky<usize>>,
    a: &'a Csc,
    b: &'a Csc,
}

impl<'a> InertiaCounter<'a> {
    /// For the pencil (`a`, `b`) whose pattern `pattern` has the Cholesky analysis `symbolic`.
    pub(crate) fn new(
        symbolic: &'a SymbolicCholesky<usize>,
        pattern: &Csc,
        a: &'a Csc,
        b: &'a Csc,
    ) -> Result<Self, ModalError> {
        let forced_supernodal = match symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(_) => None,
            SymbolicCholeskyRaw::Simplicial(_) => Some(symbolic_supernodal(pattern)?),
        };
        Ok(Self {
            symbolic,
            forced_supernodal,
            a,
            b,
        })
    }

    /// The inertia of B − τA, and the time it took.
    pub(crate) fn count_at(&self, tau: f64) -> Counted {
        let symbolic = self.forced_supernodal.as_ref().unwrap_or(self.symbolic);
        let clock = Instant::now();
        let kmat = Csc::combine(1.0, self.b, -tau, self.a);
        (inertia_with(symbolic, &kmat, tau), clock.elapsed())
    }
}

/// The count of a thread that was joined; a panic on the thread (a bug) becomes a typed error.
pub(crate) fn joined(counted: std::thread::Result<Counted>) -> Counted {
    counted.unwrap_or_else(|_| {
        let failure = ModalError::Factorization {
            what: "B − τA",
            detail: "the inertia count failed".into(),
        };
        (Err(failure), Duration::ZERO)
    })
}

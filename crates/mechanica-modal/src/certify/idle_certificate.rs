//! The bottom-of-spectrum certificate of a dense all-modes solve (the Cholesky factorization of
//! B − sA that proves no mode lies below s, the Sturm check of [`super::sturm`]), factored on
//! idle core time ([`crate::runtime::idle_task`]) while the eigenvectors are formed.
//!
//! The task starts when T (the tridiagonal form) is known: the solve takes the shift s = ½λ₁
//! from T's lowest eigenvalue λ₁ (bisection on Sturm counts), and the thread forms the lower
//! triangle of B − sA and factors it by a blocked right-looking Cholesky, one sequential block
//! at a time, with the pivot test of the synchronous certificate. The report certifies at s
//! whenever s is its own rule's shift (half the lowest computed ω²) to 8 digits, with the
//! thread's decision or its own factorization: the reported shift does not depend on which.
//! When the report needs it before the thread is done, the thread hands over its partial factor
//! at the end of its current block and the report factors the remaining columns on all
//! threads: a right-looking factorization past its first third of the columns has done 70 % of
//! its flops. (What this saves is measured in docs/benchmarks.md.)

use crate::PencilProblem;
use crate::certify::inertia::shifted_lower;
use crate::linalg::eigen::ql_values::lowest_eigenvalue;
use crate::linalg::reduce::{check_pivots, factor_block_step, factor_trailing, max_diagonal};
use crate::runtime::idle_task::IdleTask;
use crate::tuning::Tuning;
use faer::{Mat, Par};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Duration;

/// What the thread decided or had done.
pub(crate) enum Outcome {
    /// Factored to the end: whether B − sA is positive definite.
    Decided { positive: bool },
    /// Stopped before the end: the rest is the report's.
    Partial(PartialFactor),
}

/// A blocked right-looking Cholesky of B − sA stopped between two blocks.
pub(crate) struct PartialFactor {
    /// Columns 0..factored hold L; the trailing block holds their Schur complement.
    factor: Mat<f64>,
    factored: usize,
    /// The largest diagonal entry of B − sA (the scale of the pivot test).
    max_diag: f64,
}

impl PartialFactor {
    /// Factors the remaining columns on `par`'s threads: whether B − sA is positive definite.
    pub(crate) fn finish(mut self, par: Par) -> bool {
        let positive = factor_trailing(self.factor.as_mut(), self.factored, self.max_diag, par).is_ok();
        crate::runtime::scratch::give_back(self.factor);
        positive
    }
}

/// A certificate being factored on idle time.
pub(crate) struct IdleCertificate {
    task: IdleTask<Outcome>,
    /// Columns factored so far (published by the thread after every block).
    factored: Arc<AtomicUsize>,
    n: usize,
}

impl IdleCertificate {
    /// What the thread has: its decision when it finished, else (when it is far enough) its
    /// partial factor, after waiting at most one block step for it to stop.
    pub(crate) fn collect(self) -> Option<Outcome> {
        let factored = self.factored.load(Ordering::Acquire).min(self.n);
        if (factored as f64) < Tuning::DEFAULT.handover_from * self.n as f64 {
            return self.task.finished();
        }
        let rest = (self.n - factored) as f64;
        let patience = Duration::from_secs_f64(
            Tuning::DEFAULT.certificate_block as f64 * rest * rest / Tuning::DEFAULT.slowest_block_rate,
        );
        self.task.collect(patience)
    }
}

/// The bottom certificate's shift s = ½λ₁(T), taken on the calling thread (a bisection on
/// Sturm counts, O(n) per step), so that the report certifies the same shift whether or not the
/// thread finished, and the factorization at s begun on idle time.
pub(crate) struct BottomCertificate {
    pub(crate) shift: f64,
    /// None when no thread could be started.
    pub(crate) idle: Option<IdleCertificate>,
}

/// Starts the certificate of the pencil `problem` whose reduced matrix has the tridiagonal form
/// (`diag`, `subdiag`). None when λ₁(T) ≤ 0 (a zero or unstable bottom, whose shift depends on
/// the error bounds, not known yet) or T is not finite.
pub(crate) fn start(problem: &PencilProblem, diag: &[f64], subdiag: &[f64]) -> Option<BottomCertificate> {
    let lowest = lowest_eigenvalue(diag, subdiag).filter(|&l| l > 0.0)?;
    let shift = 0.5 * lowest;
    let problem = problem.clone();
    let factored = Arc::new(AtomicUsize::new(0));
    let progress = Arc::clone(&factored);
    let task = IdleTask::spawn("mechanica-idle-certificate", move |stop| {
        factor_shifted(&problem, shift, stop, &progress)
    });
    Some(BottomCertificate {
        shift,
        idle: task.map(|task| IdleCertificate {
            task,
            factored,
            n: diag.len(),
        }),
    })
}

/// The thread's work: the Cholesky factorization of B − sA by blocks until done or `stop`
/// (then the partial factor); None when stopped before it began.
fn factor_shifted(problem: &PencilProblem, shift: f64, stop: &AtomicBool, factored: &AtomicUsize) -> Option<Outcome> {
    if stop.load(Ordering::Acquire) {
        return None;
    }
    let mut factor = shifted_lower(problem, shift);
    let max_diag = max_diagonal(factor.as_ref());
    let n = factor.nrows();
    let mut done = 0;
    while done < n {
        if stop.load(Ordering::Acquire) {
            return Some(Outcome::Partial(PartialFactor {
                factor,
                factored: done,
                max_diag,
            }));
        }
        let width = Tuning::DEFAULT.certificate_block.min(n - done);
        if factor_block_step(factor.as_mut(), done, width).is_err() {
            crate::runtime::scratch::give_back(factor);
            return Some(Outcome::Decided { positive: false });
        }
        done += width;
        factored.store(done, Ordering::Release);
    }
    let positive = check_pivots(factor.as_ref(), max_diag).is_ok();
    crate::runtime::scratch::give_back(factor);
    Some(Outcome::Decided { positive })
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

    /// The thread's decision once it has returned: whether B − sA is positive definite.
    fn decided(certificate: &IdleCertificate, limit: Duration) -> Option<bool> {
        certificate.task.wait_for_result(limit, |outcome| match outcome {
            Outcome::Decided { positive } => Some(*positive),
            Outcome::Partial(_) => None,
        })?
    }

    #[test]
    fn the_idle_thread_certifies_half_the_lowest_value() {
        let n = 300;
        let (problem, lowest) = fixed_chain(n);
        let bottom = start(&problem, &vec![2.0; n], &vec![-1.0; n - 1]).expect("a positive bottom");
        let certificate = bottom.idle.expect("a thread");
        let positive = decided(&certificate, Duration::from_secs(120)).expect("decided");
        let shift = bottom.shift;
        // Bisection resolves λ₁ to a few u·‖T‖ (‖T‖ ≤ 4).
        assert!(
            (shift - 0.5 * lowest).abs() <= 16.0 * f64::EPSILON,
            "{shift} vs {}",
            0.5 * lowest
        );
        assert!(positive);
        assert_eq!(certificate.factored.load(Ordering::Acquire), n);
        assert!(matches!(
            certificate.collect(),
            Some(Outcome::Decided { positive: true })
        ));
    }

    #[test]
    fn a_shift_above_the_lowest_mode_is_refused() {
        // T claims a lowest eigenvalue 4λ₁: the shift 2λ₁ has one mode below it, so B − sA is
        // indefinite and the factorization must fail.
        let n = 300;
        let (problem, lowest) = fixed_chain(n);
        let bottom = start(&problem, &vec![4.0 * lowest; n], &vec![0.0; n - 1]).expect("a positive bottom");
        let certificate = bottom.idle.expect("a thread");
        let positive = decided(&certificate, Duration::from_secs(120)).expect("decided");
        assert!((bottom.shift - 2.0 * lowest).abs() <= 16.0 * f64::EPSILON);
        assert!(!positive);
    }

    #[test]
    fn a_bottom_at_or_below_zero_is_left_to_the_caller() {
        let n = 50;
        let (problem, _) = fixed_chain(n);
        assert!(start(&problem, &vec![-1.0; n], &vec![0.0; n - 1]).is_none());
        assert!(start(&problem, &vec![0.0; n], &vec![0.0; n - 1]).is_none());
        assert!(start(&problem, &vec![f64::NAN; n], &vec![0.0; n - 1]).is_none());
    }

    /// A factorization stopped after two blocks and finished on two threads decides as a whole
    /// one: positive definite below λ₁ (at ½λ₁), indefinite between λ₁ and λ₂.
    #[test]
    fn a_handed_over_factor_is_finished_on_every_thread() {
        let n = 300;
        let (problem, lowest) = fixed_chain(n);
        let second = 2.0 - 2.0 * (2.0 * std::f64::consts::PI / (n as f64 + 1.0)).cos();
        for (shift, positive) in [(0.5 * lowest, true), (0.5 * (lowest + second), false)] {
            let mut factor = shifted_lower(&problem, shift);
            let max_diag = max_diagonal(factor.as_ref());
            for start in [0, Tuning::DEFAULT.certificate_block] {
                factor_block_step(factor.as_mut(), start, Tuning::DEFAULT.certificate_block)
                    .expect("the leading blocks are definite");
            }
            let partial = PartialFactor {
                factor,
                factored: 2 * Tuning::DEFAULT.certificate_block,
                max_diag,
            };
            assert_eq!(partial.finish(Par::rayon(2)), positive, "shift {shift}");
        }
    }
}

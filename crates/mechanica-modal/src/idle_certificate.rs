//! The bottom-of-spectrum certificate of a dense all-modes solve (the Cholesky factorization of
//! B − sA that proves no mode lies below s, module `solve`'s inertia check), factored on a
//! thread of idle scheduling priority while the eigenvectors are formed.
//!
//! The eigenvector stages leave a core idle for part of their time: divide and conquer between
//! its parallel products, the Householder back-transformation, the report's sketches. Measured
//! on the 2-core host at n = 1000: a thread of idle priority completed 5–6 sequential Cholesky
//! factorizations of order 1000 per solve (each about 17 ms) without slowing the solve, while
//! the certificate, factored after the report on both threads, took 9–11 ms of the 250 ms.
//!
//! The thread starts when T (the tridiagonal form) is known: it takes the shift s = ½λ₁ from
//! T's lowest eigenvalue λ₁ (bisection on Sturm counts), forms the lower triangle of B − sA and
//! factors it by a blocked right-looking Cholesky, one sequential block at a time, with the
//! pivot test of the synchronous certificate. When the report needs the certificate it uses the
//! thread's decision only if the thread has finished; otherwise it stops the thread and factors
//! at its own shift, as without the thread. So the caller never waits for a thread that the
//! scheduler does not run (a machine kept busy by other programs), and such a thread exits as
//! soon as it runs again. Where the scheduling priority cannot be lowered (outside Linux) the
//! thread does nothing.

use crate::PencilProblem;
use crate::inertia::shifted_lower;
use crate::reduce::{check_pivots, factor_block_step, max_diagonal};
use crate::tridiagonal_values::lowest_eigenvalue;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

/// Columns per sequential block (between two looks at the stop flag).
const BLOCK: usize = 64;

/// What the caller and the thread share.
#[derive(Default)]
struct Shared {
    /// Set by the caller: the thread's work is no longer wanted.
    stop: AtomicBool,
    /// Set by the thread when it has finished: (s, whether B − sA is positive definite).
    decision: Mutex<Option<(f64, bool)>>,
}

/// A certificate being factored on idle time (see the module documentation).
pub(crate) struct IdleCertificate {
    shared: Arc<Shared>,
}

impl IdleCertificate {
    /// Starts the thread for the pencil `problem` whose reduced matrix has the tridiagonal form
    /// (`diag`, `subdiag`). None when no thread could be started.
    pub(crate) fn start(problem: &PencilProblem, diag: &[f64], subdiag: &[f64]) -> Option<Self> {
        let shared = Arc::new(Shared::default());
        let (diag, subdiag) = (diag.to_vec(), subdiag.to_vec());
        let (problem, thread_shared) = (problem.clone(), Arc::clone(&shared));
        std::thread::Builder::new()
            .name("mechanica-idle-certificate".into())
            .spawn(move || {
                let decision = lower_own_priority()
                    .then(|| factor_shifted(&problem, &diag, &subdiag, &thread_shared.stop))
                    .flatten();
                if let (Some(decision), Ok(mut slot)) = (decision, thread_shared.decision.lock()) {
                    *slot = Some(decision);
                }
            })
            .ok()?;
        Some(Self { shared })
    }

    /// The thread's decision (s, whether B − sA is positive definite) if it has finished, else
    /// None (and the thread is told to stop).
    pub(crate) fn finished(self) -> Option<(f64, bool)> {
        self.shared.decision.lock().ok()?.take()
    }
}

impl Drop for IdleCertificate {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Release);
    }
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

/// Puts the calling thread in the idle scheduling class (it runs only on a core nothing else
/// wants); false where that is not possible.
#[cfg(target_os = "linux")]
fn lower_own_priority() -> bool {
    let parameters = libc::sched_param { sched_priority: 0 };
    // SAFETY: pid 0 is the calling thread; `parameters` is a valid sched_param for SCHED_IDLE.
    unsafe { libc::sched_setscheduler(0, libc::SCHED_IDLE, &parameters) == 0 }
}

#[cfg(not(target_os = "linux"))]
fn lower_own_priority() -> bool {
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;
    use std::time::{Duration, Instant};

    impl IdleCertificate {
        /// Waits (polling) until the thread has decided, up to `limit`.
        fn wait_for_decision(&self, limit: Duration) -> Option<(f64, bool)> {
            let since = Instant::now();
            while since.elapsed() < limit {
                if let Some(decision) = self.shared.decision.lock().ok().and_then(|slot| *slot) {
                    return Some(decision);
                }
                std::thread::sleep(Duration::from_millis(2));
            }
            None
        }
    }

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
        let certificate = IdleCertificate::start(&problem, &vec![2.0; n], &vec![-1.0; n - 1]).expect("a thread");
        let (shift, positive) = certificate
            .wait_for_decision(Duration::from_secs(120))
            .expect("decided");
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
        let certificate =
            IdleCertificate::start(&problem, &vec![4.0 * lowest; n], &vec![0.0; n - 1]).expect("a thread");
        let (shift, positive) = certificate
            .wait_for_decision(Duration::from_secs(120))
            .expect("decided");
        assert!((shift - 2.0 * lowest).abs() <= 16.0 * f64::EPSILON);
        assert!(!positive);
    }

    #[test]
    fn a_bottom_at_or_below_zero_is_left_to_the_caller() {
        let n = 50;
        let (problem, _) = fixed_chain(n);
        let certificate = IdleCertificate::start(&problem, &vec![-1.0; n], &vec![0.0; n - 1]).expect("a thread");
        assert_eq!(certificate.wait_for_decision(Duration::from_millis(300)), None);
        assert_eq!(certificate.finished(), None);
    }
}

//! A second thread for one tridiagonalization ([`crate::linalg::eigen`]): the panel reduction
//! needs one symmetric matrix-vector product per column, each a few tens of microseconds at
//! orders 1000–2000, and a pool thread that has gone to sleep between them takes about as long
//! to wake. The team's helper waits for the next job by spinning (then parking), and takes one
//! half of each product and of each panel's trailing update ([`SymvTeam::beside`]); a half that
//! it has not claimed yet when the caller's own half is done is run by the caller instead, so a
//! late helper never delays the reduction.

use crate::tuning::Tuning;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::thread::Thread;
use std::time::Instant;

/// A closure lent to the helper by [`SymvTeam::beside`], its lifetime erased: `beside` does not
/// return, nor unwind, before the job is settled (run by the helper, or taken back unstarted).
struct LentTask(*mut (dyn FnMut() + Send + 'static));

// SAFETY: the closure itself is `Send`; the pointer is dereferenced only by the thread that
// claimed the job, while `beside` keeps the closure borrowed.
unsafe impl Send for LentTask {}

/// The state shared by the caller and the helper. Jobs are numbered 1, 2, …; job g is posted
/// when `posted` = g, owned by whoever moves `claimed` from g − 1 to g, and done by the helper
/// when `finished` = g.
pub(crate) struct SymvTeam {
    task: Mutex<Option<LentTask>>,
    posted: AtomicUsize,
    claimed: AtomicUsize,
    finished: AtomicUsize,
    stop: AtomicBool,
    /// Whether the helper's last job completed (false after a panic in it).
    helper_ok: AtomicBool,
}

impl SymvTeam {
    pub(crate) fn new() -> Self {
        Self {
            task: Mutex::new(None),
            posted: AtomicUsize::new(0),
            claimed: AtomicUsize::new(0),
            finished: AtomicUsize::new(0),
            stop: AtomicBool::new(false),
            helper_ok: AtomicBool::new(true),
        }
    }

    /// The helper's loop: run until [`SymvTeam::stop`].
    pub(crate) fn serve(&self) {
        let mut seen = 0;
        loop {
            let since = Instant::now();
            let mut spins = 0_u32;
            let posted = loop {
                if self.stop.load(Ordering::Acquire) {
                    return;
                }
                let posted = self.posted.load(Ordering::Acquire);
                if posted != seen {
                    break posted;
                }
                spins = spins.wrapping_add(1);
                if spins.is_multiple_of(256) && since.elapsed() > Tuning::DEFAULT.symv_spin {
                    std::thread::park();
                } else {
                    std::hint::spin_loop();
                }
            };
            seen = posted;
            if !self.take(posted) {
                continue; // the caller took this job back
            }
            let lent = match self.task.lock() {
                Ok(mut slot) => slot.take(),
                Err(_) => None,
            };
            let ok = match lent {
                Some(LentTask(task)) => {
                    // SAFETY: `beside` lent this closure for job `posted`, which this thread
                    // has claimed, and keeps it borrowed until `finished` reaches the job.
                    let run = || unsafe { (*task)() };
                    std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)).is_ok()
                }
                None => false,
            };
            self.helper_ok.store(ok, Ordering::Release);
            self.finished.store(posted, Ordering::Release);
        }
    }

    /// Ends the helper's loop (`helper` is its thread, which may be parked).
    pub(crate) fn stop(&self, helper: &Thread) {
        self.stop.store(true, Ordering::Release);
        helper.unpark();
    }

    /// A guard that calls [`SymvTeam::stop`] when dropped, so that a panic in the caller's
    /// work cannot leave the helper waiting forever (and the enclosing scope joining it).
    pub(crate) fn stop_on_drop<'a>(&'a self, helper: &'a Thread) -> StopOnDrop<'a> {
        StopOnDrop { team: self, helper }
    }

    /// Runs `here` on this thread and `there` on the helper at the same time, and returns when
    /// both are done; if the helper has not started `there` when `here` is done, `there` runs
    /// here too. The two closures must touch disjoint data, and each must give the same result
    /// whichever thread runs it. A panic in `there` on the helper is raised again here, after
    /// the job is settled.
    pub(crate) fn beside(&self, helper: &Thread, there: &mut (dyn FnMut() + Send), here: impl FnOnce()) {
        let job = self.posted.load(Ordering::Relaxed) + 1;
        let lent: *mut (dyn FnMut() + Send + '_) = there;
        // SAFETY: only the lifetime is erased; `Settle` (or the code after `here`) keeps `there`
        // borrowed until the helper is done with it or it was taken back unstarted.
        let lent: *mut (dyn FnMut() + Send + 'static) = unsafe { std::mem::transmute(lent) };
        match self.task.lock() {
            Ok(mut slot) => *slot = Some(LentTask(lent)),
            Err(_) => {
                // A poisoned slot (a bug): both run here, in turn.
                here();
                return there();
            }
        }
        self.posted.store(job, Ordering::Release);
        helper.unpark();
        let settle = Settle { team: self, job };
        here();
        std::mem::forget(settle);
        if self.take(job) {
            self.clear_task();
            return there();
        }
        self.wait_for(job);
        if !self.helper_ok.load(Ordering::Acquire) {
            panic!("the helper thread's half of a split step failed");
        }
    }

    /// Claims job `job` (for the helper, or back for the caller): true if this call owns it.
    fn take(&self, job: usize) -> bool {
        self.claimed
            .compare_exchange(job - 1, job, Ordering::AcqRel, Ordering::Acquire)
            .is_ok()
    }

    /// Empties the task slot of a job the caller took back.
    fn clear_task(&self) {
        if let Ok(mut slot) = self.task.lock() {
            slot.take();
        }
    }

    /// Waits until the helper has finished job `job` (spinning, yielding now and then).
    fn wait_for(&self, job: usize) {
        let mut spins = 0_u32;
        while self.finished.load(Ordering::Acquire) != job {
            spins = spins.wrapping_add(1);
            if spins.is_multiple_of(4096) {
                std::thread::yield_now();
            } else {
                std::hint::spin_loop();
            }
        }
    }
}

/// Settles a lent job when [`SymvTeam::beside`]'s own half unwinds: the lent closure is taken
/// back if the helper has not started it, else waited for, so that it is never used after its
/// borrow ends.
struct Settle<'a> {
    team: &'a SymvTeam,
    job: usize,
}

impl Drop for Settle<'_> {
    fn drop(&mut self) {
        if self.team.take(self.job) {
            self.team.clear_task();
        } else {
            self.team.wait_for(self.job);
        }
    }
}

/// See [`SymvTeam::stop_on_drop`].
pub(crate) struct StopOnDrop<'a> {
    team: &'a SymvTeam,
    helper: &'a Thread,
}

impl Drop for StopOnDrop<'_> {
    fn drop(&mut self) {
        self.team.stop(self.helper);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    /// Runs `body` with a serving helper (stopped when `body` returns or unwinds).
    fn with_helper(body: impl FnOnce(&SymvTeam, &Thread)) {
        let team = SymvTeam::new();
        std::thread::scope(|scope| {
            let helper = scope.spawn(|| team.serve()).thread().clone();
            let _stop = team.stop_on_drop(&helper);
            body(&team, &helper);
        });
    }

    #[test]
    fn each_lent_half_runs_exactly_once_whoever_takes_it() {
        with_helper(|team, helper| {
            for round in 1..=300_u64 {
                let (mut left, mut right) = (vec![0_u64; 64], vec![0_u64; 64]);
                // Rounds whose own half is slow let the helper take the lent half; in the quick
                // ones the caller often takes it back unstarted.
                team.beside(helper, &mut || right.iter_mut().for_each(|e| *e += round), || {
                    if round % 3 == 0 {
                        std::thread::sleep(Duration::from_micros(300));
                    }
                    left.iter_mut().for_each(|e| *e += round);
                });
                assert!(left.iter().chain(&right).all(|&e| e == round), "round {round}");
            }
        });
    }

    #[test]
    fn a_panic_in_the_own_half_waits_for_the_lent_half_to_end() {
        with_helper(|team, helper| {
            let started = AtomicBool::new(false);
            let mut finished = false;
            let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                team.beside(
                    helper,
                    &mut || {
                        started.store(true, Ordering::Release);
                        std::thread::sleep(Duration::from_millis(20));
                        finished = true;
                    },
                    || {
                        while !started.load(Ordering::Acquire) {
                            std::hint::spin_loop();
                        }
                        panic!("a deliberate failure in the caller's half");
                    },
                )
            }));
            assert!(outcome.is_err());
            // The helper had started the lent half, so the unwinding waited for its end.
            assert!(finished);
            // The team still serves.
            let mut again = 0;
            team.beside(helper, &mut || again += 1, || {});
            assert_eq!(again, 1);
        });
    }

    #[test]
    fn a_panic_in_the_lent_half_reaches_the_caller() {
        with_helper(|team, helper| {
            let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                team.beside(helper, &mut || panic!("a deliberate failure in the lent half"), || {
                    std::thread::sleep(Duration::from_millis(5));
                })
            }));
            assert!(outcome.is_err());
        });
    }

    #[test]
    fn a_panic_in_the_caller_stops_the_helper() {
        // Without the guard the scope would wait forever for the helper; with it the panic
        // comes back out (and this test returns).
        let team = SymvTeam::new();
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            std::thread::scope(|scope| {
                let helper = scope.spawn(|| team.serve()).thread().clone();
                let _stop = team.stop_on_drop(&helper);
                panic!("a deliberate failure in the caller's work");
            })
        }));
        assert!(outcome.is_err());
    }
}

//! Work that a solve needs later, done now on a thread of idle scheduling priority (Linux
//! `SCHED_IDLE`: it runs only on a core nothing else wants).
//!
//! A dense solve leaves a core idle for part of its time (every stage keeps fewer cores busy
//! than it has; measured in docs/benchmarks.md), and a thread of idle priority uses that time
//! without slowing the solve. Work that does not depend on the solve's critical path can run
//! there.
//!
//! The solve uses a task's result only if the task has finished when it is needed, or, for
//! work that can hand over what it has done ([`IdleTask::collect`]), after waiting a bounded
//! time for it to stop; otherwise it tells the thread to stop and does the work itself. So it
//! never waits long for a thread that the scheduler does not run (a machine kept busy by other
//! programs), and such a thread exits when it next runs. Where the priority cannot be lowered
//! (outside Linux) the task does nothing and the solve does all the work itself.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

/// What the solve and the thread share.
struct Shared<T> {
    /// Set by the solve: the result is no longer wanted, or wanted now as it stands.
    stop: AtomicBool,
    /// Filled by the thread when its work returns.
    slot: Mutex<Slot<T>>,
    /// Signalled when the slot is filled.
    answered: Condvar,
}

struct Slot<T> {
    result: Option<T>,
    /// The work has returned (with or without a result).
    returned: bool,
}

/// A result being computed on idle time.
pub(crate) struct IdleTask<T> {
    shared: Arc<Shared<T>>,
}

impl<T: Send + 'static> IdleTask<T> {
    /// Starts `work` on a new thread of idle priority; `work` should look at the flag it is
    /// given between its steps and, once it is set, return what it has (or None). None when no
    /// thread could be started.
    pub(crate) fn spawn(name: &str, work: impl FnOnce(&AtomicBool) -> Option<T> + Send + 'static) -> Option<Self> {
        let shared = Arc::new(Shared {
            stop: AtomicBool::new(false),
            slot: Mutex::new(Slot {
                result: None,
                returned: false,
            }),
            answered: Condvar::new(),
        });
        let thread_shared = Arc::clone(&shared);
        std::thread::Builder::new()
            .name(name.into())
            .spawn(move || {
                let result = lower_own_priority().then(|| work(&thread_shared.stop)).flatten();
                if let Ok(mut slot) = thread_shared.slot.lock() {
                    slot.result = result;
                    slot.returned = true;
                }
                thread_shared.answered.notify_all();
            })
            .ok()?;
        Some(Self { shared })
    }

    /// The result if the thread has finished, else None (and the thread is told to stop).
    pub(crate) fn finished(self) -> Option<T> {
        self.shared.slot.lock().ok()?.result.take()
    }

    /// Tells the thread to stop and waits at most `patience` for what its work returns: the
    /// finished result, or what it had done when it saw the flag. None when it returned nothing
    /// or did not answer in time.
    pub(crate) fn collect(self, patience: Duration) -> Option<T> {
        self.shared.stop.store(true, Ordering::Release);
        let deadline = Instant::now() + patience;
        let mut slot = self.shared.slot.lock().ok()?;
        while !slot.returned {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                break;
            }
            slot = self.shared.answered.wait_timeout(slot, left).ok()?.0;
        }
        slot.result.take()
    }

    /// Waits until the thread's work has returned, up to `limit`, and looks at its result
    /// through `view` (for tests).
    #[cfg(test)]
    pub(crate) fn wait_for_result<R>(&self, limit: Duration, view: impl FnOnce(&T) -> R) -> Option<R> {
        let deadline = Instant::now() + limit;
        let mut slot = self.shared.slot.lock().ok()?;
        while !slot.returned && Instant::now() < deadline {
            let left = deadline.saturating_duration_since(Instant::now());
            slot = self.shared.answered.wait_timeout(slot, left).ok()?.0;
        }
        slot.result.as_ref().map(view)
    }
}

impl<T> Drop for IdleTask<T> {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Release);
    }
}

/// Puts the calling thread in the idle scheduling class; false where that is not possible.
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

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    /// Work that runs until told to stop hands over how far it got.
    #[test]
    fn collect_takes_what_the_work_returns_when_stopped() {
        let task = IdleTask::spawn("test-idle-steps", |stop| {
            let mut steps = 0_usize;
            while !stop.load(Ordering::Acquire) {
                steps += 1;
                std::thread::sleep(Duration::from_millis(1));
            }
            Some(steps)
        })
        .expect("a thread");
        std::thread::sleep(Duration::from_millis(20));
        assert!(task.collect(Duration::from_secs(60)).is_some());
    }

    /// Work that does not look at the flag is not waited for past the patience given.
    #[test]
    fn collect_does_not_wait_past_its_patience() {
        let task = IdleTask::spawn("test-idle-deaf", |_| {
            std::thread::sleep(Duration::from_secs(3));
            Some(1)
        })
        .expect("a thread");
        let clock = Instant::now();
        assert_eq!(task.collect(Duration::from_millis(20)), None);
        assert!(clock.elapsed() < Duration::from_secs(2), "{:?}", clock.elapsed());
    }

    /// A finished result is taken without waiting; an unfinished one is not.
    #[test]
    fn finished_never_waits() {
        let quick = IdleTask::spawn("test-idle-quick", |_| Some(7)).expect("a thread");
        assert_eq!(quick.wait_for_result(Duration::from_secs(60), |v| *v), Some(7));
        assert_eq!(quick.finished(), Some(7));
        let slow = IdleTask::spawn("test-idle-slow", |_| {
            std::thread::sleep(Duration::from_secs(3));
            Some(1)
        })
        .expect("a thread");
        let clock = Instant::now();
        assert_eq!(slow.finished(), None);
        assert!(clock.elapsed() < Duration::from_secs(2));
    }
}

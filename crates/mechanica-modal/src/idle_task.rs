//! Work that a solve needs later, done now on a thread of idle scheduling priority (Linux
//! `SCHED_IDLE`: it runs only on a core nothing else wants).
//!
//! A dense solve leaves a core idle for part of its time: measured on the 2-core host at
//! n = 1000, the factor stage kept 1.67–1.86 cores busy on average, divide and conquer 1.64, the
//! Householder application 1.72, the sketches 1.72 (the threads' scheduler statistics), and a
//! thread of idle priority ran 5–6 sequential Cholesky factorizations of order 1000 per solve
//! (about 90 ms of a core in a 250 ms solve) without slowing it. Work that does not depend on
//! the solve's critical path can run there.
//!
//! The solve uses a task's result only if the task has finished when it is needed; otherwise
//! it tells the thread to stop and does the work itself. So it never waits for a thread that
//! the scheduler does not run (a machine kept busy by other programs), and such a thread exits
//! when it next runs. Where the priority cannot be lowered (outside Linux) the task does
//! nothing and the solve does all the work itself.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

/// What the solve and the thread share.
struct Shared<T> {
    /// Set by the solve: the result is no longer wanted.
    stop: AtomicBool,
    /// Set by the thread when it has finished.
    result: Mutex<Option<T>>,
}

/// A result being computed on idle time.
pub(crate) struct IdleTask<T> {
    shared: Arc<Shared<T>>,
}

impl<T: Send + 'static> IdleTask<T> {
    /// Starts `work` on a new thread of idle priority; `work` should look at the flag it is
    /// given between its steps and return None once it is set. None when no thread could be
    /// started.
    pub(crate) fn spawn(name: &str, work: impl FnOnce(&AtomicBool) -> Option<T> + Send + 'static) -> Option<Self> {
        let shared = Arc::new(Shared {
            stop: AtomicBool::new(false),
            result: Mutex::new(None),
        });
        let thread_shared = Arc::clone(&shared);
        std::thread::Builder::new()
            .name(name.into())
            .spawn(move || {
                let result = lower_own_priority().then(|| work(&thread_shared.stop)).flatten();
                if let (Some(result), Ok(mut slot)) = (result, thread_shared.result.lock()) {
                    *slot = Some(result);
                }
            })
            .ok()?;
        Some(Self { shared })
    }

    /// The result if the thread has finished, else None (and the thread is told to stop).
    pub(crate) fn finished(self) -> Option<T> {
        self.shared.result.lock().ok()?.take()
    }

    /// Waits (polling) until the thread has finished, up to `limit` (for tests).
    #[cfg(test)]
    pub(crate) fn wait_for_result(&self, limit: std::time::Duration) -> Option<T>
    where
        T: Clone,
    {
        let since = std::time::Instant::now();
        while since.elapsed() < limit {
            if let Some(result) = self.shared.result.lock().ok().and_then(|slot| slot.clone()) {
                return Some(result);
            }
            std::thread::sleep(std::time::Duration::from_millis(2));
        }
        None
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

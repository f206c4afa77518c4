//! Long calls that stop on Ctrl-C. The work runs on a scoped thread without the GIL; the
//! calling thread (Python's main thread, where signal handlers run) wakes every
//! [`POLL_INTERVAL`], runs Python's pending signal handlers ([`Python::check_signals`]) and, if
//! one raised (`KeyboardInterrupt` for SIGINT), sets the flag the Rust loop checks, waits for
//! the work to stop and raises that exception. The loops check the flag every
//! [`fado_sim::sim::CANCEL_CHECK_SAMPLES`] samples (about a millisecond), so the call ends
//! well within 0.5 s of the signal. The pattern is PyO3's recommended one for long
//! computations without the GIL (PyO3 guide, "Parallelism", and `Python::check_signals`).

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use pyo3::prelude::*;

/// How often the waiting thread looks for signals.
pub const POLL_INTERVAL: Duration = Duration::from_millis(20);

/// Runs `work` without the GIL on a worker thread, passing it the cancel flag; returns its
/// result, or the exception a signal handler raised meanwhile (the work was told to stop and
/// has stopped). A panic of `work` is resumed on this thread.
pub fn run<R, F>(py: Python<'_>, work: F) -> PyResult<R>
where
    R: Send,
    F: FnOnce(&Arc<AtomicBool>) -> R + Send,
{
    let cancel = Arc::new(AtomicBool::new(false));
    let (result, interrupted) = py.detach(|| {
        std::thread::scope(|scope| {
            let waiter = std::thread::current();
            let cancel = &cancel;
            let worker = scope.spawn(move || {
                let r = work(cancel);
                waiter.unpark();
                r
            });
            let mut interrupted = None;
            while !worker.is_finished() {
                std::thread::park_timeout(POLL_INTERVAL);
                if interrupted.is_none()
                    && !worker.is_finished()
                    && let Err(e) = Python::attach(|py| py.check_signals())
                {
                    cancel.store(true, Ordering::Relaxed);
                    interrupted = Some(e);
                }
            }
            let result = worker
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
            (result, interrupted)
        })
    });
    match interrupted {
        Some(e) => Err(e),
        None => Ok(result),
    }
}

/// A pass over samples that ends early because its call was cancelled (Ctrl-C).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cancelled;

/// Err([`Cancelled`]) once `cancel` is set; a long pass calls it every
/// [`fado_sim::sim::CANCEL_CHECK_SAMPLES`] samples (see [`poll_at`]).
pub fn poll(cancel: Option<&AtomicBool>) -> Result<(), Cancelled> {
    match cancel {
        Some(c) if c.load(Ordering::Relaxed) => Err(Cancelled),
        _ => Ok(()),
    }
}

/// [`poll`] at every [`fado_sim::sim::CANCEL_CHECK_SAMPLES`]-th sample `k` of a pass, Ok
/// at the others (a look at the flag costs an atomic load; one per sample would cost more
/// than some passes' own work).
pub fn poll_at(cancel: Option<&AtomicBool>, k: usize) -> Result<(), Cancelled> {
    if k.is_multiple_of(fado_sim::sim::CANCEL_CHECK_SAMPLES as usize) {
        poll(cancel)
    } else {
        Ok(())
    }
}

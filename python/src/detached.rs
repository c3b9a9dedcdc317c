//! Long work (loading, tracing, optimizing, writing) on a thread of its own: the calling
//! Python thread waits with the GIL released, wakes every [`TICK`] to run Python's signal
//! handlers (Ctrl-C raises `KeyboardInterrupt` there) and the caller's progress report,
//! and turns a panic of the work into an exception instead of a crash.

use crate::BlutraceError;
use blutrace::run::Interrupt;
use pyo3::prelude::*;
use std::time::{Duration, Instant};

/// How often the waiting thread checks for signals and reports progress.
const TICK: Duration = Duration::from_millis(100);

/// Run `work` on a new thread; meanwhile, every [`TICK`], check Python's signals and call
/// `tick`. When either raises, `interrupt` is requested (a run stops after its current
/// chunk), the work is waited for and dropped, and the exception is raised. A panic of
/// the work becomes a `BlutraceError`.
pub fn run_detached<T: Send>(
    py: Python<'_>,
    interrupt: &Interrupt,
    work: impl FnOnce() -> anyhow::Result<T> + Send,
    tick: impl FnMut(Python<'_>) -> PyResult<()>,
) -> PyResult<anyhow::Result<T>> {
    let waited = wait_detached(py, interrupt, work, tick);
    if let Some(e) = waited.stopped {
        return Err(e);
    }
    waited.outcome
}

/// What [`wait_detached`] saw: the exception that stopped the wait, if any, and what the
/// work returned after it (a panic as a `BlutraceError`).
pub struct Waited<T> {
    /// Ctrl-C's `KeyboardInterrupt`, or an exception of `tick`.
    pub stopped: Option<PyErr>,
    /// The work's result.
    pub outcome: PyResult<anyhow::Result<T>>,
}

/// [`run_detached`] that keeps the work's result when an exception stopped the wait: for
/// work that, interrupted, still has something to return (a search's designs so far).
pub fn wait_detached<T: Send>(
    py: Python<'_>,
    interrupt: &Interrupt,
    work: impl FnOnce() -> anyhow::Result<T> + Send,
    mut tick: impl FnMut(Python<'_>) -> PyResult<()>,
) -> Waited<T> {
    std::thread::scope(|s| {
        let handle = s.spawn(work);
        let waited: PyResult<()> = loop {
            py.detach(|| {
                let start = Instant::now();
                while !handle.is_finished() && start.elapsed() < TICK {
                    std::thread::sleep(Duration::from_millis(2));
                }
            });
            if let Err(e) = py.check_signals().and_then(|()| tick(py)) {
                break Err(e);
            }
            if handle.is_finished() {
                break Ok(());
            }
        };
        if waited.is_err() {
            interrupt.request();
        }
        let joined = py.detach(|| handle.join());
        let outcome = joined.map_err(|payload| {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a panic without a message".into());
            BlutraceError::new_err(format!(
                "internal error (a bug in blutrace; please report it): {what}"
            ))
        });
        Waited {
            stopped: waited.err(),
            outcome,
        }
    })
}

/// [`run_detached`] for work that cannot be stopped early and reports no progress.
pub fn detached<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> anyhow::Result<T> + Send,
) -> PyResult<anyhow::Result<T>> {
    run_detached(py, &Interrupt::default(), work, |_| Ok(()))
}

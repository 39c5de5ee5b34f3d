//! Notices an FMU call that does not return. A thread watches the calls' count
//! ([`Activity`]): the same odd count (a call under way) for longer than the timeout means
//! the call hangs. A hung call cannot be taken back from its thread, so what to do is the
//! caller's: the command line reports the run as `timeout` and ends its process.

use std::sync::mpsc::{channel, RecvTimeoutError, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crate::fmi2::Activity;

/// Watches while it lives.
pub struct Watchdog {
    stop: Option<Sender<()>>,
    thread: Option<JoinHandle<()>>,
}

impl Watchdog {
    /// Calls `on_hang` (on the watchdog's thread, once) when one call of `activity` has
    /// been under way for `timeout`; it is noticed within about 1.1 × `timeout`.
    pub fn start(
        activity: Arc<Activity>,
        timeout: Duration,
        on_hang: impl FnOnce() + Send + 'static,
    ) -> Watchdog {
        let (stop, stopped) = channel::<()>();
        let poll = (timeout / 10).clamp(Duration::from_millis(1), Duration::from_millis(200));
        let thread = std::thread::Builder::new()
            .name("contour-cosim watchdog".into())
            .spawn(move || {
                let mut seen = (activity.count(), Instant::now());
                loop {
                    match stopped.recv_timeout(poll) {
                        Err(RecvTimeoutError::Timeout) => {}
                        _ => return,
                    }
                    let count = activity.count();
                    if count != seen.0 {
                        seen = (count, Instant::now());
                    } else if count % 2 == 1 && seen.1.elapsed() >= timeout {
                        on_hang();
                        return;
                    }
                }
            })
            .expect("a thread for the watchdog");
        Watchdog {
            stop: Some(stop),
            thread: Some(thread),
        }
    }
}

/// The exit status of a process a hung FMU call ended ([`Watchdog::ending_process`]).
pub const TIMEOUT_STATUS: i32 = 3;

impl Watchdog {
    /// A watchdog that ends this process with [`TIMEOUT_STATUS`] when a call of
    /// `activity` hangs for `timeout`, saying so on standard error as `program`: the hung
    /// call keeps its thread and may hold locks that exit handlers need, so only ending
    /// the process at once frees it.
    pub fn ending_process(activity: Arc<Activity>, timeout: Duration, program: &str) -> Watchdog {
        let program = program.to_string();
        Watchdog::start(activity, timeout, move || {
            eprintln!(
                "{program}: timeout: an FMU call did not return within {} s",
                timeout.as_secs_f64()
            );
            crate::fmi2::abandon_process(TIMEOUT_STATUS);
        })
    }
}

impl Drop for Watchdog {
    fn drop(&mut self) {
        drop(self.stop.take());
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}
